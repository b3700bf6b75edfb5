//! Station files: the default parses; unknown keys and wrong units are located errors.

use ratecal_drivers::DEFAULT_STATION_YAML;
use ratecal_drivers::station::Station;

fn render(err: &ratecal_drivers::StationError) -> String {
    let mut out = String::new();
    miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
        .render_report(&mut out, err)
        .unwrap();
    out
}

fn with(from: &str, to: &str) -> String {
    assert!(DEFAULT_STATION_YAML.contains(from), "{from}");
    DEFAULT_STATION_YAML.replacen(from, to, 1)
}

#[test]
fn default_station_parses() {
    let s = Station::default_sim();
    assert_eq!(s.site.latitude_deg, 55.70);
    assert_eq!(s.imu.sample_rate.0, 100.0);
    assert!((s.table.position_noise.0 - 0.5 / 3600.0).abs() < 1e-15);
}

#[test]
fn unknown_key_is_located() {
    let text = with("  rate_ripple:", "  rate_rippel:");
    let err = Station::from_yaml(&text, "lab.yaml").unwrap_err();
    let shown = render(&err);
    eprintln!("{shown}");
    assert!(shown.contains("lab.yaml"), "{shown}");
    assert!(shown.contains("rate_rippel"), "{shown}");
    assert_eq!(err.line, Some(15));
}

#[test]
fn wrong_unit_is_located() {
    let text = with("max_rate: 500 deg/s", "max_rate: 500 arcsec");
    let err = Station::from_yaml(&text, "lab.yaml").unwrap_err();
    let shown = render(&err);
    eprintln!("{shown}");
    assert!(shown.contains("unit of angle"), "{shown}");
    assert_eq!(err.line, Some(12));
}

#[test]
fn every_example_station_parses_and_builds() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("stations");
    // Hardware links (the manual station's serial IMU) start their readers on a runtime.
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let _inside = rt.enter();
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let s = Station::from_yaml(&text, &path.display().to_string())
            .unwrap_or_else(|e| panic!("{}", render(&e)));
        ratecal_drivers::build(&s, 0).unwrap();
        n += 1;
    }
    assert!(n >= 6);
}

#[test]
fn effects_map_to_the_physics_parameters() {
    let text = with(
        "  effects: {}",
        "  effects:\n    accel_misalignment: { xy_mrad: 0.4, zx_mrad: -0.6 }\n    gyro_misalignment: { yz_mrad: 2 }\n    g_sensitivity: { xz_dps_per_g: 0.0098156 }\n    lever_arm: { ryx_mm: 3 }\n    time_offset: { tau_ms: 2.5 }\n    gyro_scale_nonlinearity: { y: 7 }",
    );
    let s = Station::from_yaml(&text, "lab.yaml").unwrap();
    let m = s.imu_model();
    let of = |id: &str| {
        m.terms
            .iter()
            .find(|t| t.effect.id() == id)
            .unwrap_or_else(|| panic!("{id} missing"))
            .values
            .clone()
    };
    // Each effect's values in the registry's parameter order, in its units.
    assert_eq!(of("accel_misalignment"), [0.4, 0.0, 0.0, 0.0, -0.6, 0.0]);
    assert_eq!(of("gyro_misalignment"), [0.0, 0.0, 0.0, 2.0, 0.0, 0.0]);
    assert_eq!(of("g_sensitivity")[2], 0.0098156);
    assert_eq!(of("lever_arm")[3], 3.0);
    assert_eq!(of("time_offset"), [2.5]);
    assert_eq!(of("gyro_scale_nonlinearity"), [0.0, 7.0, 0.0]);
    assert!((of("accel_scale")[0] - 350.0).abs() < 1e-9);
    assert!((of("gyro_scale")[1] + 310.0).abs() < 1e-9);
    assert!((of("accel_bias")[0] - 1.2e-3 * 9.80665).abs() < 1e-15);
    // The Earth's rate at the site is a term like the others; effects absent are absent.
    assert_eq!(
        of("earth_rate"),
        ratecal_physics::effects::EarthRate::values(55.70)
    );
    assert!(
        m.terms
            .iter()
            .all(|t| t.effect.id() != "lever_arm" || t.values.len() == 9)
    );
    assert!(
        m.terms
            .iter()
            .all(|t| t.effect.id() != "gyro_thermal_drift")
    );
    assert_eq!(s.time_offset_s(), 0.0025);
}

#[test]
fn earth_rate_is_not_an_imu_defect() {
    let text = with(
        "  effects: {}",
        "  effects: { earth_rate: { latitude_deg: 40 } }",
    );
    let err = Station::from_yaml(&text, "lab.yaml").unwrap_err();
    assert!(err.help.contains("site physics"), "{}", render(&err));
}

/// The default station with `from` replaced by `to` is refused on the line of `from`, the
/// report saying `needle` and naming `lab.yaml:LINE:`.
fn assert_refused_at_its_line(from: &str, to: &str, needle: &str) {
    let line = DEFAULT_STATION_YAML
        .lines()
        .position(|l| l.contains(from))
        .unwrap()
        + 1;
    let err = Station::from_yaml(&with(from, to), "lab.yaml").unwrap_err();
    let shown = render(&err);
    assert_eq!(err.line, Some(line), "{shown}");
    assert!(
        shown.contains(needle) && shown.contains(&format!("lab.yaml:{line}:")),
        "{shown}"
    );
}

#[test]
fn bad_values_are_located() {
    for (from, to, needle) in [
        (
            "outer_axis: [0, -1, 0]",
            "outer_axis: [0, -2, 0]",
            "unit vector",
        ),
        ("sample_rate: 100 Hz", "sample_rate: 100", "no unit"),
        (
            "gyro_noise_density: 0.0003 deg/s/rtHz",
            "gyro_noise_density: 0.0003 deg/s",
            "/rtHz",
        ),
        ("feedback_rate: 50 Hz", "feedback_rate: -50 Hz", "positive"),
        (
            "  imu: { warmup_offset: 4 degC",
            "  imu: { warmup_offset: 4 degC/h",
            "temperature rate",
        ),
    ] {
        assert_refused_at_its_line(from, to, needle);
    }
}

#[test]
fn describe_gives_the_manifest_facts() {
    let info = Station::default_sim().describe();
    assert_eq!(info.geometry, ratecal_physics::Geometry::seed());
    assert_eq!(info.site.latitude_deg, 55.70);
    assert_eq!(info.imu.grade, "tactical");
    let env = info.environment.unwrap();
    assert!((env.humidity_pct.unwrap() - 45.0).abs() < 1e-12);
    assert!((env.vibration_g.unwrap() - 0.002).abs() < 1e-15);
    assert!(info.simulated);
}

/// Values the loader fuzzing (`station_garbage.rs`) found accepted although the simulated
/// station then panicked or put out NaN; each is now refused where it is written.
#[test]
fn fuzzed_values_are_located() {
    for (from, to, needle) in [
        // A quantity past f64's range was infinite: NaN gyro outputs.
        (
            "gyro_bias_random_walk: 1e-6 deg/s/rts",
            "gyro_bias_random_walk: 1e400 deg/s/rts",
            "out of range",
        ),
        // NaN slipped through the orthonormality test.
        (
            "rotation: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]",
            "rotation: [[.nan, 0, 0], [0, 1, 0], [0, 0, 1]]",
            "orthonormal",
        ),
        // Bare numbers took .nan and .inf; gravity 0 divided the g-sensitivity by zero.
        ("latitude_deg: 55.70", "latitude_deg: .nan", "finite"),
        ("gravity_mps2: 9.8156", "gravity_mps2: 0", "positive"),
        (
            "  effects: {}",
            "  effects: { gyro_misalignment: { xy_mrad: .inf } }",
            "finite",
        ),
        // A servo at 1e-300 Hz: wn^2 underflows to 0, NaN angles.
        (
            "natural_frequency: 5 Hz",
            "natural_frequency: 1e-300 Hz",
            "between 0.001 Hz and 1000 kHz",
        ),
        // 1e300 Hz: the first read asked for usize::MAX + 1 samples (overflow panic).
        (
            "sample_rate: 100 Hz",
            "sample_rate: 1e300 Hz",
            "between 0.001 Hz and 1000 kHz",
        ),
        (
            "feedback_rate: 50 Hz",
            "feedback_rate: 5e-324 Hz",
            "between",
        ),
        // damping^2 overflowed: NaN angles.
        ("damping: 0.6", "damping: 1e300", "at most 100"),
        // The motion evaluated at -1e297 s: s^2 overflowed, NaN outputs.
        (
            "  effects: {}",
            "  effects: { time_offset: { tau_ms: 1e300 } }",
            "within a minute",
        ),
    ] {
        assert_refused_at_its_line(from, to, needle);
    }
}

/// After a bare CR the parser's span pointed at the end of the text while its line and
/// column were right: the snippet now shows where the message says.
#[test]
fn errors_after_a_bare_cr_are_located_where_the_message_says() {
    let err = Station::from_yaml("\r{\0", "lab.yaml").unwrap_err();
    let shown = render(&err);
    assert_eq!((err.line, err.column), (Some(2), Some(2)), "{shown}");
    assert!(shown.contains("lab.yaml:2:2"), "{shown}");
}

#[test]
fn the_ieee_terms_map_to_the_model_and_the_encoder_error_to_the_table() {
    let text = with(
        "  effects: {}",
        "  effects:\n    accel_second_order: { x: 150 }\n    clock_rate: { ppm: 60 }\n    gyro_scale_asymmetry: { z: -40 }",
    )
    .replace(
        "feedback_rate: 50 Hz",
        "feedback_rate: 50 Hz\n  effects: { table_encoder_eccentricity: { outer_sin_arcsec: 36, inner_cos_arcsec: -18 } }",
    );
    let s = Station::from_yaml(&text, "lab.yaml").unwrap();
    let m = s.imu_model();
    let values = |id: &str| {
        m.terms
            .iter()
            .find(|t| t.effect.id() == id)
            .map(|t| t.values.clone())
    };
    assert_eq!(values("accel_second_order"), Some(vec![150.0, 0.0, 0.0]));
    assert_eq!(values("clock_rate"), Some(vec![60.0]));
    assert_eq!(values("gyro_scale_asymmetry"), Some(vec![0.0, 0.0, -40.0]));
    // A station error is not the IMU's: the table carries it.
    assert_eq!(values("table_encoder_eccentricity"), None);
    let e = s.encoder_error();
    let arcsec = ratecal_physics::DEG / 3600.0;
    assert!((e.outer[0] - 36.0 * arcsec).abs() < 1e-18 && e.outer[1] == 0.0);
    assert!((e.inner[1] + 18.0 * arcsec).abs() < 1e-18 && e.inner[0] == 0.0);
    // The clock's lag grows with the stamp: 60 ppm of 1000 s.
    assert!((m.delay_at_s(1000.0) - 1000.0 * 60e-6 / (1.0 + 60e-6)).abs() < 1e-12);
}

#[test]
fn each_effect_goes_in_its_own_block() {
    assert_refused_at_its_line(
        "  effects: {}",
        "  effects: { table_encoder_eccentricity: { outer_sin_arcsec: 10 } }",
        "write it under `table.effects`",
    );
    assert_refused_in_the_table_block("clock_rate: { ppm: 10 }", "write it under `imu.effects`");
}

/// The default station with `table.effects: { block }` is refused on that block's line.
fn assert_refused_in_the_table_block(block: &str, needle: &str) {
    let line = DEFAULT_STATION_YAML
        .lines()
        .position(|l| l.contains("feedback_rate: 50 Hz"))
        .unwrap()
        + 2;
    let text = with(
        "feedback_rate: 50 Hz",
        &format!("feedback_rate: 50 Hz\n  effects: {{ {block} }}"),
    );
    let err = Station::from_yaml(&text, "lab.yaml").unwrap_err();
    let shown = render(&err);
    assert_eq!(err.line, Some(line), "{shown}");
    assert!(shown.contains(needle), "{shown}");
}

#[test]
fn retiming_values_the_simulator_cannot_evaluate_are_refused() {
    // 1 + eps = 0 stops the IMU's clock; an encoder error of radians has no inverse.
    assert_refused_at_its_line(
        "  effects: {}",
        "  effects: { clock_rate: { ppm: -1e6 } }",
        "within 10 %",
    );
    assert_refused_in_the_table_block(
        "table_encoder_eccentricity: { inner_sin_arcsec: 1e6 }",
        "within a degree",
    );
}
