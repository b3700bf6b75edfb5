//! Any bytes as an import map: a map, or a diagnostic naming the file, a line and a column,
//! with a help line; never a panic. Run with `cargo fuzz run -s none import_map`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Err(e) = ratecal_import::load_map(&text, "fuzz.yaml") {
        assert!(e.line.is_some() && e.column.is_some(), "{e:?}");
        assert!(e.span.is_some() && !e.help.is_empty(), "{e:?}");
        let mut out = String::new();
        miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
            .render_report(&mut out, e.as_ref())
            .expect("renders");
        assert!(out.contains("fuzz.yaml:"), "{out}");
    }
});
