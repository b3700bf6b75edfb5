//! A MATLAB source as rows: the matrix read whole (`mat.rs`), served one sample at a time
//! through the same [`Rows`] the text sources use; columns by 0-based index.

use super::{Matrix, Res, RowAt, Rows, io_error, map_error, read_mat};
use crate::error::{ErrorKind, ImportError};
use crate::map::{Col, ColRef, ImportMap};
use std::path::Path;

/// A MATLAB matrix read whole, served a row at a time.
pub(super) struct MatRows {
    pub(super) name: String,
    pub(super) variable: String,
    pub(super) m: Matrix,
    pub(super) sha256: String,
}

impl Rows {
    /// One MATLAB file's matrix; the map's columns are 0-based indices into it.
    pub(super) fn open_mat(
        paths: &[&Path],
        map: &ImportMap,
        variable: &str,
        cols: &[&Col],
    ) -> Res<Rows> {
        let [path] = paths else {
            return Err(ImportError::in_file(
                ErrorKind::Format,
                &paths
                    .first()
                    .map_or(String::new(), |p| p.display().to_string()),
                &format!("{} MATLAB files given; one is read", paths.len()),
                "import one .mat file (put the channels side by side in one matrix)",
            ));
        };
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| io_error(&name, &e))?;
        let m = read_mat(&bytes, &name, variable)?;
        let mut slots = Vec::with_capacity(cols.len());
        for c in cols {
            let ColRef::Index(i) = c.col else {
                // The map loader refuses names for a MATLAB source.
                return Err(map_error(
                    map,
                    c,
                    "a MATLAB matrix's columns are 0-based indices",
                    "",
                ));
            };
            if i >= m.cols {
                let help = if m.rows <= i {
                    format!(
                        "one row per sample is read; if `{variable}` holds the samples as \
                         columns, save its transpose: `{variable} = {variable}.'`"
                    )
                } else {
                    format!("`{variable}` has columns 0 to {}", m.cols.saturating_sub(1))
                };
                return Err(map_error(
                    map,
                    c,
                    &format!(
                        "column {i}, but `{variable}` in {name} is {} x {} ({})",
                        m.rows, m.cols, m.class
                    ),
                    &help,
                ));
            }
            slots.push(i);
        }
        Ok(Rows {
            sources: Vec::new(),
            local: slots.iter().map(|&g| (0, g)).collect(),
            slots,
            sample: 0,
            mat: Some(MatRows {
                name,
                variable: variable.to_string(),
                m,
                sha256: ratecal_recording::sha256_hex(&bytes),
            }),
        })
    }

    /// The next row of a MATLAB matrix.
    pub(super) fn next_mat(&mut self, out: &mut [f64]) -> Res<Option<RowAt>> {
        let Some(mr) = &self.mat else {
            return Ok(None);
        };
        let r = self.sample as usize;
        if r >= mr.m.rows {
            return Ok(None);
        }
        for (slot, &c) in self.slots.iter().enumerate() {
            let v = mr.m.data[c * mr.m.rows + r];
            if !v.is_finite() {
                return Err(mat_cell_error(
                    mr,
                    r,
                    c,
                    "not a finite number (NaN or infinite)",
                    "the importer does not fill gaps: remove or repair the row in the source",
                ));
            }
            out[slot] = v;
        }
        self.sample += 1;
        Ok(Some(RowAt {
            sample: r as u64,
            line: r as u64 + 1,
        }))
    }
}

/// An error at row `r`, column `c` (0-based) of a MATLAB matrix.
pub(super) fn mat_cell_error(
    m: &MatRows,
    r: usize,
    c: usize,
    what: &str,
    help: &str,
) -> Box<ImportError> {
    ImportError::in_file(
        ErrorKind::Cell,
        &m.name,
        &format!(
            "row {} (sample {r}), column {c} of `{}`: {what}",
            r + 1,
            m.variable
        ),
        help,
    )
}
