//! Any bytes as a MATLAB file: the matrix `cal_data` (its size agreeing with its values), or
//! a diagnostic naming the file with a help line; never a panic, never an allocation the
//! file's size does not justify. Seed it with tests/fixtures/import_mat/*.mat:
//! `cargo fuzz run -s none import_mat ../tests/fixtures/import_mat` (from fuzz/... see
//! docs/import.md).
#![no_main]

use libfuzzer_sys::fuzz_target;
use ratecal_import::read_mat;

fuzz_target!(|data: &[u8]| {
    match read_mat(data, "src.mat", "cal_data") {
        Ok(m) => assert_eq!(m.data.len(), m.rows * m.cols),
        Err(e) => assert!(
            !e.help.is_empty() && e.message.starts_with("src.mat: "),
            "{e:?}"
        ),
    }
});
