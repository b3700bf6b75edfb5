//! The manual fits against a second implementation: `ratecal-witness` writes six-face
//! (nominal faces, placement tilts, hand turns about each axis) and multi-pose (unknown
//! attitudes, random hand turns) sessions from closed forms with their truth; over 20
//! seeds each, the fits' values lie within 3 u of the truth for at least 95 % of the
//! parameters they state (an uncertainty is a promise).

use ratecal_analysis::fit::{Options, Streamed, analyze_source};
use ratecal_analysis::results::Parameter;
use ratecal_witness::{ManualKind, ManualSession, write_manual};

/// (inside 3u, stated) over the seeds of `kind`, and the worst |error| / u.
fn coverage(kind: ManualKind, seeds: std::ops::Range<u64>) -> (usize, usize, f64) {
    let (mut inside, mut stated, mut worst) = (0, 0, 0.0f64);
    for seed in seeds {
        let dir = tempfile::tempdir().unwrap();
        let truth = write_manual(dir.path(), &ManualSession::consumer(kind, seed)).unwrap();
        let src = Streamed::open(dir.path()).unwrap();
        let res = analyze_source(&src, None, &Options::default()).unwrap();
        let man = res
            .manual
            .as_ref()
            .expect("a manual recording is analysed as one");
        // The calibrated poses read gravity (a six-face bias carries the faces' tilts: a
        // few hundredths of m/s^2), and the raw ones did not.
        assert!(
            man.gravity_rms_calibrated_mps2 < 0.1,
            "seed {seed}: {man:?}"
        );
        assert!(man.gravity_rms_raw_mps2 > 2.0 * man.gravity_rms_calibrated_mps2);
        for (key, want) in &truth.parameters {
            let Some(Parameter::Estimate { value, u, .. }) = res.parameters.get(key) else {
                continue;
            };
            stated += 1;
            let z = (value - want).abs() / u;
            worst = worst.max(z);
            if z <= 3.0 {
                inside += 1;
            } else {
                println!(
                    "{kind:?} seed {seed}: {key} = {value:.4} +- {u:.4}, truth {want:.4} ({z:.1} u)"
                );
            }
        }
    }
    (inside, stated, worst)
}

#[test]
fn six_face_sessions_recover_the_truth_within_3u() {
    let (inside, stated, worst) = coverage(ManualKind::SixFace, 0..20);
    let share = inside as f64 / stated as f64;
    println!(
        "six_face: {inside} of {stated} parameters within 3 u ({:.1} %), worst {worst:.1} u",
        100.0 * share
    );
    // Bias, scale and misalignment of both sensors: 24 a seed.
    assert_eq!(stated, 20 * 24);
    assert!(share >= 0.95, "{share}");
}

#[test]
fn multi_pose_sessions_recover_the_truth_within_3u() {
    let (inside, stated, worst) = coverage(ManualKind::MultiPose { poses: 20 }, 0..20);
    let share = inside as f64 / stated as f64;
    println!(
        "multi_pose: {inside} of {stated} parameters within 3 u ({:.1} %), worst {worst:.1} u",
        100.0 * share
    );
    // The convention fixes three accelerometer misalignments: 21 a seed.
    assert_eq!(stated, 20 * 21);
    assert!(share >= 0.95, "{share}");
}
