//! The bundled procedures parse and are in canonical layout.

use std::path::Path;

fn procedure_files() -> Vec<std::path::PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../procedures");
    let mut out = Vec::new();
    for dir in std::fs::read_dir(root).expect("procedures/") {
        let dir = dir.expect("entry").path();
        for f in std::fs::read_dir(&dir).expect("procedure folder") {
            let f = f.expect("entry").path();
            if f.extension().is_some_and(|e| e == "rcal") {
                out.push(f);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn bundled_procedures_are_canonical() {
    let files = procedure_files();
    assert!(!files.is_empty());
    for f in files {
        let text = std::fs::read_to_string(&f).expect("read");
        let canon =
            ratecal_grammar::canonical(&text).unwrap_or_else(|e| panic!("{}: {e:?}", f.display()));
        assert_eq!(
            canon.text,
            text,
            "{} is not in canonical layout",
            f.display()
        );
    }
}
