//! The table stream from the lab's own feedback file: read through its map like the IMU's
//! sources (any delimiter, a time column or a rate, its units), put on the IMU's clock
//! (`offset_s` added), converted to deg and deg/s exactly, and checked against the
//! segments (`check::feedback`).

use super::{FileHash, Res, out_error};
use crate::check::feedback::Turns;
use crate::error::{ErrorKind, ImportError, Say};
use crate::map::{ImportMap, TableFeed, TimeSpec};
use crate::read::Rows;
use ratecal_recording::{RecordingWriter, Segment, TableSample};
use std::path::{Path, PathBuf};

/// The feedback file `feed.file` names: relative to the first source's folder.
pub fn path(feed: &TableFeed, sources: &[PathBuf]) -> PathBuf {
    let f = Path::new(&feed.file);
    if f.is_absolute() {
        return f.to_path_buf();
    }
    let dir = sources
        .first()
        .and_then(|s| s.parent())
        .unwrap_or(Path::new(""));
    dir.join(f)
}

/// Streams the feedback into `writer`; its sample count and hash.
pub fn stream(
    map: &ImportMap,
    feed: &TableFeed,
    sources: &[PathBuf],
    segs: &[Segment],
    writer: &mut RecordingWriter,
    out: &Path,
) -> Res<(u64, FileHash)> {
    let file = path(feed, sources);
    if !file.is_file() {
        return Err(ImportError::in_text(
            ErrorKind::Io,
            &map.file,
            &map.text,
            feed.file_at.clone(),
            Say {
                what: &format!("no table feedback file {}", file.display()),
                label: "this file",
                help: "table.file is relative to the first source's folder (or absolute)",
            },
        ));
    }
    let mut cols: Vec<&crate::map::Col> = feed.columns.iter().collect();
    if let TimeSpec::Column { col, .. } = &feed.time {
        cols.push(col);
    }
    let mut rows = Rows::open(&[file.as_path()], &feed.source, map, &cols)?;
    let mut cells = [0f64; 5];
    let mut last: Option<f64> = None;
    let mut turns = Turns::new(segs);
    let mut n = 0u64;
    let (a, r) = (feed.angle.factor, feed.rate.factor);
    while let Some(at) = rows.next(&mut cells)? {
        let t = match &feed.time {
            TimeSpec::Rate(hz) => at.sample as f64 / hz,
            TimeSpec::Column { to_s, .. } => cells[4] * to_s,
        } + feed.offset_s;
        if let Some(l) = last
            && t <= l
        {
            let what = if t == l {
                format!("table time repeats: t = {t} s twice")
            } else {
                format!("table time goes backwards: t = {t} s after {l} s")
            };
            return Err(rows.cell_error(
                4.min(cols.len() - 1),
                ErrorKind::Time,
                &what,
                "feedback times must increase strictly; nothing is reordered or dropped",
            ));
        }
        last = Some(t);
        let s = TableSample {
            t,
            outer_deg: cells[0] * a,
            inner_deg: cells[1] * a,
            outer_rate_dps: cells[2] * r,
            inner_rate_dps: cells[3] * r,
            ambient_c: None,
            t_host: None,
        };
        writer
            .write_table(&[s])
            .map_err(|e| out_error(out, &format!("cannot write: {e}")))?;
        turns.add(&s);
        n += 1;
    }
    let sha256 = rows.finish().pop().unwrap_or_default();
    turns.check(map, feed)?;
    Ok((
        n,
        FileHash {
            file: file.display().to_string(),
            sha256,
        },
    ))
}
