//! Station files edited in their own text (`station::edit`): values replaced where they
//! stand in the unit they are written in, missing ones added beside their neighbours, the
//! comments kept, and the result a station file that parses to the values asked for.

use ratecal_drivers::DEFAULT_STATION_YAML;
use ratecal_drivers::station::{SetValue, Station, edit, locate};

fn set(effect: &str, param: &str, value: f64, u: f64) -> SetValue {
    SetValue {
        effect: effect.into(),
        param: param.into(),
        value,
        u,
        file: None,
    }
}

const ALL: &str = include_str!("../../stations/all-effects.yaml");

#[test]
fn values_change_where_they_stand_in_their_own_units() {
    let sets = [
        set("accel_bias", "y", -0.00981, 0.00001),
        set("gyro_scale", "z", 301.4, 1.2),
        set("lever_arm", "rzz_mm", 31.23, 0.3),
        set("table_encoder_eccentricity", "inner_cos_arcsec", 7.0, 0.5),
    ];
    let out = edit(ALL, &sets).unwrap();
    let st = Station::from_yaml(&out, "out.yaml").unwrap();
    assert!((st.imu.accel_bias[1].0 + 0.00981).abs() < 1e-5 * 0.5);
    assert!((st.imu.gyro_scale[2].0 - 301.4e-6).abs() < 1e-10);
    assert_eq!(st.imu.effects.value("lever_arm", "rzz_mm"), 31.23);
    assert_eq!(
        st.table
            .effects
            .0
            .value("table_encoder_eccentricity", "inner_cos_arcsec"),
        7.0
    );
    // The unit as written (mg), the digits of u, everything else as it was.
    assert!(
        out.contains("accel_bias: [1.2 mg, -1.0003 mg, 2.1 mg]"),
        "{out}"
    );
    assert!(
        out.contains("gyro_scale: [420 ppm, -310 ppm, 301.4 ppm]"),
        "{out}"
    );
    let changed: Vec<(&str, &str)> = ALL
        .lines()
        .zip(out.lines())
        .filter(|(a, b)| a != b)
        .collect();
    assert_eq!(changed.len(), 4, "{changed:?}");
    assert_eq!(ALL.lines().count(), out.lines().count());
}

#[test]
fn missing_values_are_added_beside_their_neighbours() {
    // An effect under an empty flow map, a parameter into an existing effect, a station-side
    // effect into a table without `effects:`.
    let sets = [
        set("lever_arm", "rzz_mm", 25.04, 0.02),
        set("lever_arm", "rxx_mm", -4.0, 0.02),
        set("table_encoder_eccentricity", "outer_sin_arcsec", 60.0, 0.0),
    ];
    let out = edit(DEFAULT_STATION_YAML, &sets).unwrap();
    assert!(
        out.contains("  effects: { lever_arm: { rxx_mm: -4.000, rzz_mm: 25.040 } }"),
        "{out}"
    );
    assert!(out.contains("  feedback_rate: 50 Hz\n  effects:\n    table_encoder_eccentricity: { outer_sin_arcsec: 60 }\nmount:"), "{out}");
    let st = Station::from_yaml(&out, "out.yaml").unwrap();
    assert_eq!(st.imu.effects.value("lever_arm", "rzz_mm"), 25.04);
    // A block map of effects gains a line at its indentation; an existing flow map a pair.
    let block = DEFAULT_STATION_YAML.replace(
        "effects: {}",
        "effects:\n    # measured 2026-10\n    time_offset:\n      tau_ms: 2.5\n    lever_arm: { rzz_mm: 25 }",
    );
    let sets = [
        set("clock_rate", "ppm", 20.0, 1.0),
        set("time_offset", "tau_ms", 2.61, 0.05),
        set("lever_arm", "ryy_mm", 14.0, 0.1),
    ];
    let out = edit(&block, &sets).unwrap();
    assert!(out.contains("    # measured 2026-10\n    time_offset:\n      tau_ms: 2.610\n    lever_arm: { rzz_mm: 25, ryy_mm: 14.00 }\n    clock_rate: { ppm: 20.0 }\ntemperature:"), "{out}");
    let st = Station::from_yaml(&out, "out.yaml").unwrap();
    assert_eq!(st.imu.effects.value("clock_rate", "ppm"), 20.0);
}

#[test]
fn values_are_located_for_errors() {
    let (at, n) = locate(DEFAULT_STATION_YAML, "site", "latitude_deg").unwrap();
    assert!(DEFAULT_STATION_YAML[at..at + n].starts_with("55.70"));
    let (at, _) = locate(DEFAULT_STATION_YAML, "table", "outer_axis").unwrap();
    assert!(DEFAULT_STATION_YAML[at..].starts_with("[0, -1, 0]"));
    assert_eq!(locate(DEFAULT_STATION_YAML, "site", "nothing"), None);
}

#[test]
fn effects_and_user_effects_added_at_the_end_of_the_imu_stay_in_their_blocks() {
    // `imu.effects` is the last key of `imu` here: its end is where `imu.user_effects`
    // goes too.
    let text = include_str!("../../stations/with-lever-arm.yaml");
    let mut user = set("discovered_ax_drift", "k_ax", 3.0, 0.1);
    user.file = Some("discovered_ax_drift.effect".into());
    let sets = [
        set("clock_rate", "ppm", 50.0, 0.1),
        user,
        set("time_offset", "tau_ms", 5.0, 0.01),
    ];
    let out = edit(text, &sets).unwrap();
    let st = Station::from_yaml(&out, "out.yaml").unwrap_or_else(|e| panic!("{e:?}\n{out}"));
    assert_eq!(st.imu.effects.value("clock_rate", "ppm"), 50.0, "{out}");
    assert_eq!(st.imu.effects.value("time_offset", "tau_ms"), 5.0, "{out}");
    assert_eq!(st.imu.effects.value("lever_arm", "rzz_mm"), 25.0, "{out}");
    assert_eq!(text.lines().count() + 4, out.lines().count(), "{out}");
    let u = &st.imu.user_effects["discovered_ax_drift"];
    assert_eq!(u.file, "discovered_ax_drift.effect");
    // In the order asked for, each in its block.
    let at = |s: &str| out.find(s).unwrap_or_else(|| panic!("{s}\n{out}"));
    assert!(at("lever_arm") < at("clock_rate") && at("clock_rate") < at("time_offset"));
    assert!(at("time_offset") < at("user_effects"), "{out}");
}

#[test]
fn two_effects_added_to_an_empty_flow_map_are_both_in_it() {
    assert!(DEFAULT_STATION_YAML.contains("effects: {}"));
    let sets = [
        set("time_offset", "tau_ms", 4.0, 0.01),
        set("clock_rate", "ppm", 60.0, 0.001),
    ];
    let out = edit(DEFAULT_STATION_YAML, &sets).unwrap();
    let st = Station::from_yaml(&out, "out.yaml").unwrap_or_else(|e| panic!("{e:?}\n{out}"));
    assert_eq!(st.imu.effects.value("time_offset", "tau_ms"), 4.0, "{out}");
    assert_eq!(st.imu.effects.value("clock_rate", "ppm"), 60.0, "{out}");
    assert_eq!(DEFAULT_STATION_YAML.lines().count(), out.lines().count());
}

#[test]
fn two_user_effects_added_to_a_file_without_any_share_one_block() {
    let file = |id: &str| {
        let mut v = set(id, "k_gx", 1.5, 0.1);
        v.file = Some(format!("{id}.effect"));
        v
    };
    let sets = [file("discovered_a"), file("discovered_b")];
    let out = edit(DEFAULT_STATION_YAML, &sets).unwrap();
    let st = Station::from_yaml(&out, "out.yaml").unwrap_or_else(|e| panic!("{e:?}\n{out}"));
    for id in ["discovered_a", "discovered_b"] {
        assert_eq!(
            st.imu.user_effects[id].file,
            format!("{id}.effect"),
            "{out}"
        );
    }
    assert_eq!(out.matches("user_effects:").count(), 1, "{out}");
}

#[test]
fn two_effects_added_to_a_file_without_an_effects_key_share_one_block() {
    let text = DEFAULT_STATION_YAML.replace("  effects: {}\n", "");
    assert!(!text.contains("effects"));
    let sets = [
        set("time_offset", "tau_ms", 4.0, 0.01),
        set("lever_arm", "rzz_mm", 25.0, 0.1),
        set("table_encoder_eccentricity", "outer_sin_arcsec", 3.0, 0.5),
        set("table_encoder_eccentricity", "inner_cos_arcsec", -2.0, 0.5),
    ];
    let out = edit(&text, &sets).unwrap();
    let st = Station::from_yaml(&out, "out.yaml").unwrap_or_else(|e| panic!("{e:?}\n{out}"));
    assert_eq!(st.imu.effects.value("time_offset", "tau_ms"), 4.0, "{out}");
    assert_eq!(st.imu.effects.value("lever_arm", "rzz_mm"), 25.0, "{out}");
    let table = &st.table.effects.0;
    assert_eq!(
        table.value("table_encoder_eccentricity", "outer_sin_arcsec"),
        3.0
    );
    assert_eq!(
        table.value("table_encoder_eccentricity", "inner_cos_arcsec"),
        -2.0
    );
    // One `effects:` under the imu, one under the table.
    assert_eq!(out.matches("effects:").count(), 2, "{out}");
}
