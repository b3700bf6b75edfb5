//! MATLAB files: the 128-byte header says which kind. v7.3 is HDF5 and is declined; v5
//! binaries are not read yet (export the matrix as text: `writematrix(cal_data, "x.csv")`).
//! A `.mat` that is plain text (imu_tk's) is read as `format: csv`.

use crate::error::{ErrorKind, ImportError};
use std::io::Read;
use std::path::Path;

/// Refuses a MATLAB source with the reason and what to do.
pub fn check_mat(path: &Path, variable: &str) -> Result<(), Box<ImportError>> {
    let name = path.display().to_string();
    let mut head = [0u8; 128];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut head))
        .map_err(|e| super::io_error(&name, &e))?;
    let head = &head[..n];
    let text = String::from_utf8_lossy(head);
    let (what, help) = if text.starts_with("MATLAB 7.3 MAT-file") || head.starts_with(b"\x89HDF") {
        (
            "a MATLAB v7.3 file (HDF5): not supported".to_string(),
            format!(
                "save it as v5 text or CSV from MATLAB: `writematrix({variable}, \"data.csv\")`, \
                 then import with `source: {{ format: csv }}`"
            ),
        )
    } else if text.starts_with("MATLAB 5.0 MAT-file") {
        (
            "a MATLAB v5 binary file: not read yet".to_string(),
            format!(
                "export the matrix as text from MATLAB: `writematrix({variable}, \"data.csv\")`, \
                 then import with `source: {{ format: csv, header: none }}`"
            ),
        )
    } else {
        (
            "not a MATLAB binary file (no `MATLAB ... MAT-file` header)".to_string(),
            "a text file named .mat (imu_tk's are) is read with `source: { format: csv, \
             header: none }`"
                .to_string(),
        )
    };
    Err(ImportError::in_file(ErrorKind::Format, &name, &what, &help))
}
