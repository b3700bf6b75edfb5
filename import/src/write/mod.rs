//! The import itself: stream the sources through the conversion into a staging folder
//! beside `--out`, follow or detect the segments, check the data against the map, then
//! synthesize the table stream, write the manifest with its provenance and move the folder
//! into place. A refusal removes the staging folder: nothing is written.

mod feedback;
mod provenance;

pub use provenance::{Conversion, FileHash, Provenance};

use crate::check;
use crate::error::{ErrorKind, ImportError};
use crate::map::{ImportMap, RateAxis, Segments, TimeSpec, Up};
use crate::read::Rows;
use crate::segment::table::{Pose, synthesize};
use crate::segment::{Found, Stretch, Tracker, face_up, turn};
use ratecal_recording::{
    Attitude, Columns, FORMAT, ImuSample, Manifest, ManifestStation, RecordingWriter, Segment,
    SegmentKind, TableAxes, WrittenFile,
};
use std::path::{Path, PathBuf};

pub(crate) type Res<T> = Result<T, Box<ImportError>>;

/// What an import wrote (printed for the engineer to confirm).
#[derive(Debug, Clone)]
pub struct Summary {
    /// The recording folder.
    pub out: PathBuf,
    /// IMU samples.
    pub samples: u64,
    /// First and last time, s.
    pub t: (f64, f64),
    /// The manifest's segments.
    pub segments: Vec<Found>,
    /// The static segments whose attitude is unknown (`attitude: unknown`: hand-held
    /// poses, which the six-position fits skip).
    pub oblique: Vec<Found>,
    /// The static segments made `attitude: nominal` within the import's own check of `up`
    /// ([`crate::UP_TOLERANCE_DEG`]) because the map gave no attitude.
    pub nominal_by_default: Vec<String>,
    /// Whether the segments were detected.
    pub detected: bool,
    /// Table samples synthesized or read from the feedback file.
    pub table_samples: u64,
    /// The data files as written (name, SHA-256, length), for the seal of the new folder
    /// (`ratecal_recording::hash_folder_known`).
    pub files: Vec<WrittenFile>,
}

/// Removes the staging folder unless the import completed.
struct Staging(Option<PathBuf>);

impl Drop for Staging {
    fn drop(&mut self) {
        if let Some(p) = self.0.take() {
            let _ = std::fs::remove_dir_all(p);
        }
    }
}

pub(crate) fn out_error(out: &Path, what: &str) -> Box<ImportError> {
    ImportError::in_file(
        ErrorKind::Io,
        &out.display().to_string(),
        what,
        "--out names a new folder (or an empty one) in a writable directory",
    )
}

/// Removes the staging folders `.NAME.import-PID` that killed imports into `NAME` left in
/// `parent` (their process gone): up to gigabytes no later import would otherwise remove.
fn sweep_stale(parent: &Path, name: &str) {
    let prefix = format!(".{name}.import-");
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for e in entries.flatten() {
        let file = e.file_name();
        let Some(pid) = file.to_str().and_then(|f| f.strip_prefix(&prefix)) else {
            continue;
        };
        let is_dir = e.file_type().is_ok_and(|t| t.is_dir());
        if is_dir && pid.parse::<u32>().is_ok() && !alive(pid) {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

/// Whether process `pid` still runs (where the system says; elsewhere assumed so, and its
/// staging folder kept).
fn alive(pid: &str) -> bool {
    let proc = Path::new("/proc");
    !proc.join("self").exists() || proc.join(pid).exists()
}

/// Samples after which a time column's implied sampling rate is checked.
const RATE_PROBE: u64 = 64;

/// Refuses a time column whose first [`RATE_PROBE`] samples (from `t0` to `t`, s) imply no
/// IMU's sampling rate: a unit slip (microseconds declared as milliseconds makes a pose
/// held for hours), caught before more rows are written.
fn implied_rate(rows: &Rows, t0: f64, t: f64) -> Res<()> {
    use crate::map::{MAX_RATE_HZ, MIN_RATE_HZ};
    let rate = (RATE_PROBE - 1) as f64 / (t - t0);
    if (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate) {
        return Ok(());
    }
    Err(rows.cell_error(
        6,
        ErrorKind::Time,
        &format!(
            "the time column gives {rate:.4} Hz over the first {RATE_PROBE} samples: no \
             IMU's sampling rate (between {MIN_RATE_HZ} Hz and {MAX_RATE_HZ} Hz)"
        ),
        "check imu.time's unit (s, ms or us): a unit 1000 times too large or too small \
         makes the span of the recording absurd",
    ))
}

/// Imports `sources` with `map` into the new recording folder `out`.
pub fn import(sources: &[PathBuf], map: &ImportMap, out: &Path) -> Res<Summary> {
    if out.exists() {
        let empty = out.is_dir() && std::fs::read_dir(out).is_ok_and(|mut d| d.next().is_none());
        if !empty {
            return Err(out_error(out, "already exists"));
        }
    }
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = out
        .file_name()
        .map_or("import".into(), |n| n.to_string_lossy().into_owned());
    sweep_stale(parent, &name);
    let stage = parent.join(format!(".{name}.import-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&stage);
    let mut guard = Staging(Some(stage.clone()));
    let io = |e: std::io::Error| out_error(out, &format!("cannot write: {e}"));

    let mut writer = RecordingWriter::create_exact_unchained(
        &stage,
        manifest(map, Vec::new()),
        Columns::default(),
    )
    .map_err(io)?;
    let mut cols: Vec<&crate::map::Col> = map.columns.iter().collect();
    if let TimeSpec::Column { col, .. } = &map.time {
        cols.push(col);
    }
    let paths: Vec<&Path> = sources.iter().map(PathBuf::as_path).collect();
    let mut rows = Rows::open(&paths, &map.source, map, &cols)?;
    let mut tracker = Tracker::new(map);
    let mut all = Stretch::default();
    let mut cells = [0f64; 7];
    let mut last_t: Option<f64> = None;
    let mut first_t: Option<f64> = None;
    let (a, g) = (&map.accel, &map.gyro);
    while let Some(at) = rows.next(&mut cells)? {
        let t = match &map.time {
            TimeSpec::Rate(hz) => at.sample as f64 / hz,
            TimeSpec::Column { to_s, .. } => {
                let t = cells[6] * to_s;
                if let Some(l) = last_t
                    && t <= l
                {
                    let what = if t == l {
                        format!("time repeats: t = {t} s twice")
                    } else {
                        format!("time goes backwards: t = {t} s after {l} s")
                    };
                    return Err(rows.cell_error(
                        6,
                        ErrorKind::Time,
                        &what,
                        "sample times must increase strictly; nothing is reordered or dropped",
                    ));
                }
                t
            }
        };
        last_t = Some(t);
        if let TimeSpec::Column { .. } = &map.time {
            first_t.get_or_insert(t);
            if at.sample + 1 == RATE_PROBE {
                implied_rate(&rows, first_t.unwrap_or(t), t)?;
            }
        }
        let s_f: [f64; 3] = std::array::from_fn(|k| (cells[k] - a.zero[k]) * a.factor);
        let s_w: [f64; 3] = std::array::from_fn(|k| (cells[3 + k] - g.zero[k]) * g.factor);
        let f: [f64; 3] = std::array::from_fn(|b| map.axes[b].1 * s_f[map.axes[b].0]);
        let w: [f64; 3] = std::array::from_fn(|b| map.axes[b].1 * s_w[map.axes[b].0]);
        writer
            .write_imu(&[ImuSample {
                t,
                accel: f,
                gyro: w,
                temp_c: None,
                t_host: None,
            }])
            .map_err(io)?;
        tracker.add(at, t, &f, &w);
        all.add(at.sample, at.line, t, &f, &w);
    }
    if all.n < 2 {
        return Err(ImportError::in_file(
            ErrorKind::Cell,
            rows.name(),
            &format!("holds {} samples", all.n),
            "check source.skip_lines and source.header",
        ));
    }
    let hashes = rows.finish();
    let found = tracker.finish(map, &all)?;
    check::check(map, &found, rows.name())?;
    let feedback = map.table.is_some();
    // Poses of unknown attitude stay among the segments, marked `attitude: unknown`; the
    // summary lists them apart.
    let oblique: Vec<Found> = found
        .iter()
        .filter(|f| {
            f.kind == SegmentKind::Static && attitude_of(f, feedback) == Some(Attitude::Unknown)
        })
        .cloned()
        .collect();
    let nominal_by_default: Vec<String> = found
        .iter()
        .filter(|f| f.kind == SegmentKind::Static && f.attitude.is_none() && !feedback)
        .filter(|f| matches!(f.up, Some(Up::Axis(..))) && f.decl.is_some())
        .map(|f| f.id.clone())
        .collect();
    let kept = found;

    let (poses, segments) = poses(&kept, feedback);
    let mut table_samples = 0u64;
    let mut table_file = None;
    if let Some(feed) = &map.table {
        let (n, hash) = feedback::stream(map, feed, sources, &segments, &mut writer, out)?;
        table_samples = n;
        table_file = Some(hash);
    } else {
        let mut werr = None;
        synthesize(&poses, all.t.0, all.t.1, |s| {
            table_samples += 1;
            if let Err(e) = writer.write_table(&[s]) {
                werr.get_or_insert(e);
            }
        });
        if let Some(e) = werr {
            return Err(io(e));
        }
    }
    writer.manifest_mut().segments = segments;
    writer.finish().map_err(io)?;
    if let Some(f) = writer.write_failure() {
        return Err(out_error(
            out,
            &format!("cannot write {}: {}", f.file, f.error),
        ));
    }
    let files = writer.written().to_vec();
    let m = writer.manifest().clone();
    let dropped = writer.close();
    if dropped > 0 {
        return Err(out_error(
            out,
            &format!("{dropped} samples could not be written (internal error)"),
        ));
    }
    let _ = std::fs::remove_file(stage.join("journal.jsonl"));
    let prov = Provenance {
        tool: format!("ratecal import {}", env!("CARGO_PKG_VERSION")),
        imported: ratecal_recording::rfc3339(std::time::SystemTime::now()),
        map: FileHash {
            file: map.file.clone(),
            sha256: map.sha256.clone(),
        },
        sources: sources
            .iter()
            .zip(hashes)
            .map(|(p, h)| FileHash {
                file: p.display().to_string(),
                sha256: h,
            })
            .collect(),
        conversion: Conversion::of(map, all.n),
        table: if map.table.is_some() {
            "feedback"
        } else {
            "synthesized"
        }
        .into(),
        table_file,
        table_conversion: map.table.as_ref().map(provenance::table_conversion),
        segments: match map.segments {
            Segments::None => "none",
            Segments::List(_) => "declared",
            Segments::Detect(_) => "detected",
        }
        .into(),
    };
    let mut text = ratecal_recording::manifest_yaml(&m).map_err(io)?;
    text.push_str(&provenance::yaml(&prov).map_err(|e| out_error(out, &e))?);
    ratecal_recording::commit::write_nofollow(&stage.join("manifest.yaml"), text.as_bytes())
        .map_err(io)?;
    if out.exists() {
        std::fs::remove_dir(out).map_err(io)?;
    }
    std::fs::rename(&stage, out).map_err(io)?;
    guard.0 = None;
    Ok(Summary {
        out: out.to_path_buf(),
        samples: all.n,
        t: all.t,
        segments: kept,
        oblique,
        nominal_by_default,
        detected: matches!(map.segments, Segments::Detect(_)),
        table_samples,
        files,
    })
}

/// The manifest before its segments.
fn manifest(map: &ImportMap, segments: Vec<Segment>) -> Manifest {
    Manifest {
        format: FORMAT.to_string(),
        station: ManifestStation {
            site: map.site,
            table: match &map.table {
                Some(f) => TableAxes {
                    outer_axis: f.outer_axis,
                    inner_axis: f.inner_axis,
                    model: Some(format!("feedback: {} (ratecal import)", f.file)),
                },
                None => TableAxes {
                    outer_axis: [0.0, -1.0, 0.0],
                    inner_axis: [1.0, 0.0, 0.0],
                    model: Some("none: synthesized by ratecal import from the segments".into()),
                },
            },
            mount: None,
        },
        imu: map.device.clone(),
        procedure: None,
        segments,
        environment: None,
        run: None,
    }
}

/// The manifest's attitude of a static segment: the map's, else (without feedback) a
/// declared face is nominal within the import's check of `up` and any other pose unknown.
fn attitude_of(f: &Found, feedback: bool) -> Option<Attitude> {
    let face = matches!(f.up, Some(Up::Axis(..)));
    match f.attitude {
        Some(crate::map::Attitude::Feedback) => None,
        Some(crate::map::Attitude::Nominal(_)) if !face => Some(Attitude::Unknown),
        Some(crate::map::Attitude::Nominal(_)) => Some(Attitude::Nominal),
        Some(crate::map::Attitude::Unknown) => Some(Attitude::Unknown),
        None if feedback => None,
        None if face && f.decl.is_some() => Some(Attitude::Nominal),
        None => Some(Attitude::Unknown),
    }
}

/// The tolerance of a nominal attitude, deg.
fn tolerance_of(f: &Found) -> f64 {
    match f.attitude {
        Some(crate::map::Attitude::Nominal(t)) => t,
        _ => crate::UP_TOLERANCE_DEG,
    }
}

/// The table attitude of each kept segment and its manifest entry.
fn poses(kept: &[Found], feedback: bool) -> (Vec<Pose>, Vec<Segment>) {
    let mut poses = Vec::with_capacity(kept.len());
    let mut segs = Vec::with_capacity(kept.len());
    let mut last = (0.0, 0.0);
    for f in kept {
        let (t0, t1) = f.stretch.t;
        let mut seg = Segment::new(f.id.clone(), f.kind, t0, t1);
        seg.up = match (f.kind, f.up) {
            (SegmentKind::Static, Some(u @ Up::Axis(..))) => Some(u.name()),
            _ => None,
        };
        if f.kind == SegmentKind::Static {
            seg.attitude = attitude_of(f, feedback);
            if seg.attitude == Some(Attitude::Nominal) {
                seg.tolerance_deg = Some(tolerance_of(f));
            }
        }
        if let Some(t) = f.turn {
            seg.axis = t.axis.map(|(k, s)| RateAxis::Body(k, s).name());
            seg.angle_deg = t.angle_deg;
        }
        let pose = match (f.up, f.rate) {
            (up, Some((axis, rate))) => {
                // A turn starts from its own `up` when the map gives one.
                let from = match up {
                    Some(Up::Axis(k, s)) => face_up(k, s),
                    _ => last,
                };
                let (att, outer, r) = turn(axis, rate, from);
                seg.axis = Some(if outer { "outer" } else { "inner" }.into());
                seg.rate_dps = Some(r);
                Pose {
                    t0,
                    t1,
                    att,
                    turn: Some((outer, r)),
                }
            }
            (Some(Up::Axis(k, s)), None) => {
                last = face_up(k, s);
                Pose {
                    t0,
                    t1,
                    att: last,
                    turn: None,
                }
            }
            _ => Pose {
                t0,
                t1,
                att: last,
                turn: None,
            },
        };
        poses.push(pose);
        segs.push(seg);
    }
    (poses, segs)
}
