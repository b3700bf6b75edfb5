//! `table:` with a feedback file: where its time, angles and rates are and in which units,
//! and how its clock meets the IMU's (`offset_s`, added to its time; 0: the same clock).

use super::raw::RawFeed;
use super::resolve::{HELP, Res, Resolver};
use super::*;
use ratecal_physics::units::Dim;
use serde_saphyr::Spanned;

/// The table's feedback file and its map.
#[derive(Debug, Clone)]
pub struct TableFeed {
    /// As written in the map (relative to the first source's folder).
    pub file: String,
    /// Where `file:` is in the map.
    pub file_at: Range<usize>,
    /// How to read it (default: CSV, delimiter found from the file).
    pub source: SourceSpec,
    /// Its time.
    pub time: TimeSpec,
    /// Added to its time, s.
    pub offset_s: f64,
    /// `outer inner outer_rate inner_rate`, in that order.
    pub columns: [Col; 4],
    /// Angle columns to deg.
    pub angle: Scale,
    /// Rate columns to deg/s.
    pub rate: Scale,
    /// The station's table axes (IMU body axes at zero angles), for the manifest.
    pub outer_axis: [f64; 3],
    /// Inner axis.
    pub inner_axis: [f64; 3],
    /// Where `table:` is in the map.
    pub at: Range<usize>,
}

impl Resolver<'_> {
    pub(super) fn feed(&self, f: &RawFeed, at: Range<usize>) -> Res<TableFeed> {
        let source = match &f.source {
            Some(s) => self.source(s)?,
            None => SourceSpec {
                format: Format::Csv,
                encoding: encoding_rs::UTF_8,
                skip_lines: 0,
                header: true,
                delimiter: Delimiter::Auto,
            },
        };
        let time = self.time(&f.time)?;
        let c = &f.columns;
        let columns = [
            self.col(&c.outer)?,
            self.col(&c.inner)?,
            self.col(&c.outer_rate)?,
            self.col(&c.inner_rate)?,
        ];
        let named = |col: &Col| matches!(col.col, ColRef::Name(_));
        if (source.format != Format::Csv || !source.header)
            && let Some(col) = columns.iter().find(|c| named(c))
        {
            return Err(self.err(
                col.at.clone(),
                "a column is named, but the table's source has no header",
                "give columns by 0-based index (header: none, or a MATLAB matrix)",
            ));
        }
        let unit = |u: &Spanned<String>, dim: Dim| -> Res<Scale> {
            let at = self.at(&u.referenced);
            let factor = scale_of(&u.value, dim).map_err(|m| {
                self.err(
                    at.clone(),
                    &m,
                    "table.units: angle in deg, rad, mrad...; rate in deg/s, rad/s...",
                )
            })?;
            Ok(Scale {
                factor,
                zero: [0.0; 3],
                unit: u.value.clone(),
                at,
            })
        };
        let angle = unit(&f.units.angle, Dim::Angle)?;
        let rate = unit(&f.units.rate, Dim::Rate)?;
        let offset_s = match &f.offset_s {
            Some(o) if !o.value.is_finite() => {
                return Err(self.err(self.at(&o.referenced), "offset_s must be finite", HELP));
            }
            Some(o) => o.value,
            None => 0.0,
        };
        let axis = |a: &Option<Spanned<[f64; 3]>>, default: [f64; 3]| -> Res<[f64; 3]> {
            let Some(a) = a else { return Ok(default) };
            let n = a.value.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !n.is_finite() || (n - 1.0).abs() > 1e-6 {
                return Err(self.err(
                    self.at(&a.referenced),
                    "a table axis is a unit vector in the IMU's body axes",
                    "e.g. outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] (the seed station's)",
                ));
            }
            Ok(a.value)
        };
        if f.file.value.trim().is_empty() {
            return Err(self.err(
                self.at(&f.file.referenced),
                "table.file is empty",
                "name the feedback file (relative to the first source's folder)",
            ));
        }
        Ok(TableFeed {
            file: f.file.value.clone(),
            file_at: self.at(&f.file.referenced),
            source,
            time,
            offset_s,
            columns,
            angle,
            rate,
            outer_axis: axis(&f.outer_axis, [0.0, -1.0, 0.0])?,
            inner_axis: axis(&f.inner_axis, [1.0, 0.0, 0.0])?,
            at,
        })
    }
}
