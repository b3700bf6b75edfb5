//! The station file's `driver:` values are parsed against the registry: every kind it
//! lists, and nothing else; a wrong name or setting is refused on its line.

use ratecal_drivers::station::Station;
use ratecal_drivers::{DEFAULT_STATION_YAML, DRIVERS, DriverSpec, registry};

fn render(err: &ratecal_drivers::StationError) -> String {
    let mut out = String::new();
    miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
        .render_report(&mut out, err)
        .unwrap();
    out
}

/// The default station with the table's driver written `table` and the IMU's `imu`.
fn with_drivers(table: &str, imu: &str) -> String {
    let t = "driver: sim\n  model: simulated";
    let i = "  driver: sim\n  model: SIM";
    assert!(DEFAULT_STATION_YAML.contains(t) && DEFAULT_STATION_YAML.contains(i));
    DEFAULT_STATION_YAML
        .replacen(t, &format!("driver: {table}\n  model: simulated"), 1)
        .replacen(i, &format!("  driver: {imu}\n  model: SIM"), 1)
}

fn table_driver_line() -> usize {
    DEFAULT_STATION_YAML
        .lines()
        .position(|l| l.contains("driver: sim"))
        .unwrap()
        + 1
}

#[test]
fn every_registered_kind_parses_from_its_name() {
    let settings = |name: &str| match name {
        "sim" => "sim".to_string(),
        "tcp" => "{ tcp: { address: \"127.0.0.1:9\", timeout: 1 s } }".into(),
        "serial" => "{ serial: { port: /dev/ttyUSB0, baud: 115200 } }".into(),
        "replay" => "{ replay: { recording: runs/a } }".into(),
        "manual" => "manual".into(),
        "hand" => "hand".into(),
        other => panic!("a kind this test does not know: {other}"),
    };
    for k in DRIVERS {
        // The operator kinds are tables only: their IMU is another driver.
        let imu = if matches!(k.name, "sim" | "manual" | "hand") {
            "sim".into()
        } else {
            settings(k.name)
        };
        let text = with_drivers(&settings(k.name), &imu);
        let st = Station::from_yaml(&text, "lab.yaml").unwrap_or_else(|e| panic!("{}", render(&e)));
        assert_eq!(st.table.driver.kind.name, k.name);
        assert_eq!(registry::simulated(&st), k.simulated);
        // Written back, it reads the same.
        let again = serde_saphyr::to_string(&st.table.driver).unwrap();
        let back: DriverSpec = serde_saphyr::from_str(&again).unwrap();
        assert_eq!(back, st.table.driver, "{again}");
    }
    let serial = Station::from_yaml(&with_drivers(&settings("serial"), "sim"), "l.yaml").unwrap();
    assert_eq!(serial.table.driver.settings.baud(), 115_200);
    assert_eq!(serial.table.driver.link_timeout_s(), Some(2.0));
    assert_eq!(DriverSpec::sim().link_timeout_s(), None);
}

#[test]
fn an_unknown_kind_is_refused_on_its_line_with_the_closest_name() {
    let text = with_drivers("{ tpc: { address: \"a:1\" } }", "sim");
    let err = Station::from_yaml(&text, "lab.yaml").unwrap_err();
    let shown = render(&err);
    let line = table_driver_line();
    assert_eq!(err.line, Some(line), "{shown}");
    assert!(shown.contains(&format!("lab.yaml:{line}:")), "{shown}");
    assert!(shown.contains("unknown driver `tpc`"), "{shown}");
    assert!(shown.contains("did you mean `tcp`?"), "{shown}");

    let err = Station::from_yaml(&with_drivers("simm", "sim"), "lab.yaml").unwrap_err();
    let shown = render(&err);
    assert_eq!(err.line, Some(line), "{shown}");
    assert!(shown.contains("did you mean `sim`?"), "{shown}");
}

#[test]
fn settings_a_kind_does_not_take_or_needs_are_refused() {
    for (table, needle) in [
        (
            "{ tcp: { port: /dev/x } }",
            "unknown field `port` of the `tcp` driver",
        ),
        (
            "{ tcp: { timeout: 1 s } }",
            "the `tcp` driver needs `address`",
        ),
        ("tcp", "the `tcp` driver needs `address`"),
        (
            "{ serial: { port: /dev/x, adress: a } }",
            "did you mean `address`?",
        ),
    ] {
        let err = Station::from_yaml(&with_drivers(table, "sim"), "lab.yaml").unwrap_err();
        let shown = render(&err);
        assert_eq!(err.line, Some(table_driver_line()), "{table}: {shown}");
        assert!(shown.contains(needle), "{table}: {shown}");
    }
}
