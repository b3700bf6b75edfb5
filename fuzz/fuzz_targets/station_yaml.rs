//! Any bytes as a station file: a station, or a diagnostic that names the file, a line and a
//! column, with a help line; never a panic. Run with `cargo fuzz run -s none station_yaml`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ratecal_drivers::Station;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    match Station::from_yaml(&text, "fuzz.yaml") {
        Ok(station) => {
            // Building the drivers touches no clock and no file for the simulated station.
            if ratecal_drivers::registry::simulated(&station) {
                let _ = ratecal_drivers::build(&station, 0);
            }
        }
        Err(e) => {
            assert!(e.line.is_some() && e.column.is_some(), "{e:?}");
            assert!(e.span.is_some() && !e.help.is_empty(), "{e:?}");
            let mut out = String::new();
            miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
                .render_report(&mut out, e.as_ref())
                .expect("renders");
            assert!(out.contains("fuzz.yaml:"), "{out}");
        }
    }
});
