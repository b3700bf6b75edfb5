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
