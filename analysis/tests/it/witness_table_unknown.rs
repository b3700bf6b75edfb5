//! A table error that no registry holds, written by `ratecal-witness`: the outer bearing
//! wobbles, tilting the gimbal about `a_o x up` by `w sin(2 th_o)` while the encoders read
//! the angles exactly (zero at the static attitudes, whose outer angles are 0 and +-90 deg:
//! only the outer spins see it). Issue 35 item 7: it must come out as `unexplained` on the
//! sensors and segments where it acts, never as an IMU term (a registry effect of the IMU
//! or a discovered form, both `station_side: false`).
//! Today explain reports it as a discovered `ay ~ f_b.x f_b.z` form: this test fails until
//! explain's discovery tells a table error from an IMU term (docs/validation.md).

use ratecal_analysis::explain::{self, Explanation, NominalModel, Options};
use ratecal_recording as recording;
use ratecal_witness::{Hidden, Scenario, write};

fn explain_witness(s: &Scenario) -> Explanation {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), s).unwrap();
    let rec = recording::read(dir.path()).unwrap();
    explain::explain(&rec, &NominalModel::seed(), &Options::default())
}

#[test]
fn an_unregistered_table_wobble_is_unexplained_never_an_imu_term() {
    for (seed, w_arcsec) in [(1, 40.0), (3, -30.0)] {
        let s = Scenario::standard("wobble", seed).with(Hidden::TableWobble {
            w_arcsec,
            phi_deg: 0.0,
        });
        let x = explain_witness(&s);
        let imu: Vec<String> = (x.findings.iter())
            .filter(|f| !f.station_side && f.effect != "earth_rate")
            .map(|f| {
                format!(
                    "{} {:?}",
                    f.effect,
                    f.terms.iter().map(|t| &t.expression).collect::<Vec<_>>()
                )
            })
            .collect();
        assert!(
            imu.is_empty(),
            "seed {seed}: IMU-side findings {imu:?}; unexplained {:?}",
            x.unexplained
        );
        // The tilt turns gravity into body Y during the outer spins.
        let ay = (x.unexplained.iter())
            .find(|u| u.sensor == "accel" && u.channels.iter().any(|c| c == "ay"))
            .unwrap_or_else(|| panic!("seed {seed}: ay not unexplained: {:?}", x.unexplained));
        assert!(
            ay.segments
                .iter()
                .all(|s| s.starts_with("gyro_scale/outer/")),
            "seed {seed}: located {:?}",
            ay.segments
        );
    }
}
