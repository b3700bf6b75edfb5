//! Any bytes as a recording folder: the input is split at `\0\0` into manifest.yaml,
//! imu.csv and table.csv (missing parts are empty files). Reading ends in a recording that
//! keeps the format's promises, which the analysis takes without panicking, or in a
//! located diagnostic; never a panic. Run with `cargo fuzz run -s none recording_read`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use miette::Diagnostic;
use ratecal_recording::{self as recording, RecordingError};

fuzz_target!(|data: &[u8]| {
    let mut parts = split(data);
    let dir = tempfile::tempdir().expect("temp dir");
    for name in ["manifest.yaml", "imu.csv", "table.csv"] {
        let part = parts.next().unwrap_or(&[]);
        std::fs::write(dir.path().join(name), part).expect("write");
    }
    match recording::read(dir.path()) {
        Ok(rec) => {
            for t in [&rec.imu.t, &rec.table.t] {
                assert!(t.len() >= 2 && t.windows(2).all(|w| w[1] > w[0]));
            }
            assert!(rec.imu.accel.iter().flatten().all(|x| x.is_finite()));
            assert!(rec.imu.gyro.iter().flatten().all(|x| x.is_finite()));
            for s in &rec.manifest.segments {
                assert!(s.t_start.is_finite() && s.t_end > s.t_start);
                assert!(rec.imu.t.iter().any(|&t| t >= s.t_start && t <= s.t_end));
            }
            let _ = ratecal_analysis::fit::analyze(&rec, None);
        }
        Err(RecordingError::Io { .. }) => {}
        Err(e) => {
            assert!(e.help().is_some(), "{e:?}");
            let mut out = String::new();
            miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
                .render_report(&mut out, &e)
                .expect("renders");
            let dir = dir.path().display().to_string();
            let located = out.match_indices(&dir).any(|(i, _)| {
                let rest = &out[i + dir.len()..];
                let mut p = rest.splitn(4, ':');
                p.next();
                p.next().is_some_and(|l| l.parse::<u64>().is_ok())
                    && p.next()
                        .is_some_and(|c| c.bytes().next().is_some_and(|b| b.is_ascii_digit()))
            });
            assert!(located, "{out}");
        }
    }
});

/// The parts of `data` between `\0\0` separators.
fn split(data: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut rest = Some(data);
    std::iter::from_fn(move || {
        let r = rest?;
        match r.windows(2).position(|w| w == b"\0\0") {
            Some(p) => {
                rest = Some(&r[p + 2..]);
                Some(&r[..p])
            }
            None => {
                rest = None;
                Some(r)
            }
        }
    })
}
