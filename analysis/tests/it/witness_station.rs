//! The table's own (station-side) errors on recordings written by `ratecal-witness` from
//! docs/effects.md's words, not from the physics crate: for each station-side effect of
//! the registry, explain names it as the table's, with every parameter within 3 u of what
//! was put in, and credits nothing to the IMU. (A table error that no registry holds:
//! tests/it/witness_table_unknown.rs.)

use ratecal_analysis::explain::{self, Explanation, NominalModel, Options, Parameter};
use ratecal_recording as recording;
use ratecal_witness::{Hidden, Scenario, Truth, write};

fn explain_witness(s: &Scenario) -> (Explanation, Truth) {
    let dir = tempfile::tempdir().unwrap();
    let truth = write(dir.path(), s).unwrap();
    let rec = recording::read(dir.path()).unwrap();
    let x = explain::explain(&rec, &NominalModel::seed(), &Options::default());
    (x, truth)
}

fn eccentric(name: &str, seed: u64, e_arcsec: [f64; 2], phi_deg: [f64; 2]) -> Scenario {
    Scenario::standard(name, seed).with(Hidden::TableEncoderEccentricity { e_arcsec, phi_deg })
}

/// The finding `id` is the table's, and each of its parameters lies within 3 u of the
/// truth's (both axes: an exact axis must read zero).
fn named_with_truth(x: &Explanation, truth: &Truth, what: &str) {
    let h = &truth.hidden[0];
    let f = (x.findings.iter().find(|f| f.effect == h.id)).unwrap_or_else(|| {
        panic!(
            "{what}: {} not named; found {:?}; rejected {:?}; unexplained {:?}",
            h.id,
            x.findings.iter().map(|f| &f.effect).collect::<Vec<_>>(),
            x.rejected.get(&h.id),
            x.unexplained
        )
    });
    assert!(f.station_side, "{what}: not marked as the station's");
    let want = h.parameters.as_object().unwrap();
    assert_eq!(f.parameters.len(), want.len(), "{what}: {:?}", f.parameters);
    for (name, truth) in want {
        let truth = truth.as_f64().unwrap();
        let Some(Parameter::Estimate { value, u, .. }) = f.parameters.get(name) else {
            panic!("{what}: {name} not estimated: {:?}", f.parameters.get(name));
        };
        eprintln!("| {what} | {name} | {value:.2} | {u:.2} | {truth:.2} |");
        assert!(
            (value - truth).abs() <= 3.0 * u,
            "{what}: {name} = {value} +- {u}, truth {truth} ({:.1} u)",
            (value - truth) / u
        );
    }
}

/// Nothing is credited to the IMU (the Earth's rate is the site's, in every recording),
/// and nothing is left unexplained.
fn nothing_else(x: &Explanation, what: &str) {
    for f in x.findings.iter().filter(|f| !f.station_side) {
        assert_eq!(f.effect, "earth_rate", "{what}: an IMU-side finding");
    }
    assert!(x.unexplained.is_empty(), "{what}: {:?}", x.unexplained);
}

#[test]
fn an_eccentric_inner_encoder_is_named_as_the_tables_with_its_values() {
    let s = eccentric("ecc-inner", 1, [0.0, 40.0], [0.0, 30.0]);
    let (x, truth) = explain_witness(&s);
    named_with_truth(&x, &truth, "inner 40 arcsec at 30 deg");
    nothing_else(&x, "inner");
}

#[test]
fn an_eccentric_outer_encoder_is_named_as_the_tables_with_its_values() {
    let s = eccentric("ecc-outer", 4, [50.0, 0.0], [-60.0, 0.0]);
    let (x, truth) = explain_witness(&s);
    named_with_truth(&x, &truth, "outer 50 arcsec at -60 deg");
    nothing_else(&x, "outer");
}

#[test]
fn both_eccentric_encoders_are_named_with_their_values() {
    let s = eccentric("ecc-both", 5, [30.0, 25.0], [120.0, -100.0]);
    let (x, truth) = explain_witness(&s);
    named_with_truth(&x, &truth, "outer 30 at 120, inner 25 at -100");
    nothing_else(&x, "both");
}
