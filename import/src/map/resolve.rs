//! From the map's text to an [`ImportMap`]: serde-saphyr's errors and every value check
//! become diagnostics located in the map file.

use super::raw::{RawCol, RawMap, RawSegments, RawSource, RawTable, RawTime, RawTriple};
use super::*;
use crate::error::{ErrorKind, ImportError, Say};
use ratecal_physics::units::{Dim, parse_quantity};
use ratecal_recording::yaml_offset;
use serde_saphyr::{Location, Spanned};

/// The slowest sampling rate an import accepts, Hz: slower, a calibration's static poses
/// would hold a handful of samples, and the span of a file would be days.
pub const MIN_RATE_HZ: f64 = 1.0;
/// The fastest, Hz (1 MHz: beyond any IMU's output data rate).
pub const MAX_RATE_HZ: f64 = 1.0e6;

pub(super) const HELP: &str = "docs/import.md lists every key of an import map";

/// Reads and checks a map; `file` names it in diagnostics.
pub fn load_map(text: &str, file: &str) -> Result<ImportMap, Box<ImportError>> {
    let raw: RawMap = serde_saphyr::from_str(text).map_err(|e| yaml_error(&e, text, file))?;
    Resolver { text, file }.map(raw)
}

pub(super) struct Resolver<'a> {
    pub(super) text: &'a str,
    pub(super) file: &'a str,
}

pub(super) type Res<T> = Result<T, Box<ImportError>>;

impl Resolver<'_> {
    pub(super) fn at(&self, loc: &Location) -> Range<usize> {
        if loc.line() == 0 {
            return 0..0;
        }
        let start = yaml_offset(self.text, loc.line(), loc.column());
        let len = loc
            .span()
            .byte_len()
            .filter(|_| loc.span().byte_offset().map(|o| o as usize) == Some(start))
            .unwrap_or(1) as usize;
        start..(start + len).min(self.text.len())
    }

    pub(super) fn err(&self, at: Range<usize>, what: &str, help: &str) -> Box<ImportError> {
        ImportError::in_text(
            ErrorKind::Map,
            self.file,
            self.text,
            at,
            Say {
                what,
                label: "here",
                help,
            },
        )
    }

    fn map(&self, raw: RawMap) -> Res<ImportMap> {
        let source = self.source(&raw.source)?;
        let time = self.time(&raw.imu.time)?;
        let c = &raw.imu.columns;
        let columns = [
            self.col(&c.ax)?,
            self.col(&c.ay)?,
            self.col(&c.az)?,
            self.col(&c.gx)?,
            self.col(&c.gy)?,
            self.col(&c.gz)?,
        ];
        if source.format != Format::Csv || !source.header {
            for col in columns.iter().chain(match &time {
                TimeSpec::Column { col, .. } => Some(col),
                TimeSpec::Rate(_) => None,
            }) {
                if let ColRef::Name(n) = &col.col {
                    return Err(self.err(
                        col.at.clone(),
                        &format!("column `{n}` is named, but this source has no header"),
                        "give columns by 0-based index (header: none, or a MATLAB matrix)",
                    ));
                }
            }
        }
        let zero = raw.imu.zero.as_ref();
        let accel = self.scale(
            &raw.imu.units.accel,
            Dim::Accel,
            zero.and_then(|z| z.accel.clone()),
        )?;
        let gyro = self.scale(
            &raw.imu.units.gyro,
            Dim::Rate,
            zero.and_then(|z| z.gyro.clone()),
        )?;
        let axes = self.axes(raw.imu.axes.as_ref())?;
        let site = self.site(&raw)?;
        let table = match &raw.table {
            Some(t) => match &t.value {
                RawTable::None => None,
                RawTable::Feed(f) => Some(self.feed(f, self.at(&t.referenced))?),
            },
            None => None,
        };
        let segments = match &raw.segments {
            None => Segments::None,
            Some(s) => match &s.value {
                RawSegments::List(v) => Segments::List(self.segments(v, table.is_some())?),
                RawSegments::Detect(d) => {
                    let static_min_s = self.time_q(&d.static_min)?;
                    let window_s = match &d.window {
                        Some(w) => self.time_q(w)?,
                        None => 0.5,
                    };
                    let threshold = d.threshold.as_ref().map_or(Ok(6.0), |t| {
                        if t.value.is_finite() && t.value > 1.0 {
                            Ok(t.value)
                        } else {
                            Err(self.err(
                                self.at(&t.referenced),
                                "threshold must be above 1",
                                "a multiple of the noise variance of the quietest windows (default 6)",
                            ))
                        }
                    })?;
                    let attitude = self.detect_attitude(d, table.is_some())?;
                    Segments::Detect(Detect {
                        static_min_s,
                        threshold,
                        window_s,
                        attitude,
                        at: self.at(&s.referenced),
                    })
                }
            },
        };
        Ok(ImportMap {
            file: self.file.to_string(),
            text: self.text.to_string(),
            sha256: ratecal_recording::sha256_hex(self.text.as_bytes()),
            source,
            time,
            columns,
            accel,
            gyro,
            axes,
            segments,
            site,
            table,
            device: raw.device,
        })
    }

    /// `time:` (of the IMU or of the table feedback).
    ///
    /// A `rate_hz` is refused outside [`MIN_RATE_HZ`, `MAX_RATE_HZ`].
    pub(super) fn time(&self, t: &Spanned<RawTime>) -> Res<TimeSpec> {
        Ok(match (&t.value.rate_hz, &t.value.column) {
            (Some(r), None) if (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&r.value) => {
                TimeSpec::Rate(r.value)
            }
            (Some(r), None) if r.value.is_finite() && r.value > 0.0 => {
                // A slip (1e-300, 1e300, a period given for a rate) would make the span of
                // the recording absurd, and the synthesized table with it.
                return Err(self.err(
                    self.at(&r.referenced),
                    &format!(
                        "rate_hz {} is no IMU's sampling rate (between {MIN_RATE_HZ} Hz and \
                         {MAX_RATE_HZ} Hz)",
                        r.value
                    ),
                    "rate_hz is the IMU's output data rate in Hz (e.g. 100, 102.4, 400); \
                     a period in seconds is its inverse",
                ));
            }
            (Some(r), None) => {
                return Err(self.err(self.at(&r.referenced), "rate_hz must be above 0", HELP));
            }
            (None, Some(c)) => {
                let to_s = match &t.value.unit {
                    None => 1.0,
                    Some(u) => seconds_per(&u.value).ok_or_else(|| {
                        self.err(
                            self.at(&u.referenced),
                            &format!("`{}` is not a time unit", u.value),
                            "a time column's unit is s, ms or us",
                        )
                    })?,
                };
                TimeSpec::Column {
                    col: self.col(c)?,
                    to_s,
                }
            }
            _ => {
                return Err(self.err(
                    self.at(&t.referenced),
                    "imu.time needs either `rate_hz` or `column` (and only one)",
                    "write `time: { rate_hz: 100 }` or `time: { column: \"Time [s]\", unit: s }`",
                ));
            }
        })
    }

    pub(super) fn source(&self, s: &RawSource) -> Res<SourceSpec> {
        let format = match s.format.value.as_str() {
            "csv" => Format::Csv,
            "mat" => Format::Mat {
                variable: s
                    .variable
                    .as_ref()
                    .map(|v| v.value.clone())
                    .ok_or_else(|| {
                        self.err(
                            self.at(&s.format.referenced),
                            "a MATLAB source needs `variable:` (the matrix to read)",
                            "write `source: { format: mat, variable: cal_data }`",
                        )
                    })?,
            },
            other => {
                return Err(self.err(
                    self.at(&s.format.referenced),
                    &format!("unknown source format `{other}`"),
                    "source.format is `csv` (any delimiter or whitespace) or `mat` (MATLAB v5)",
                ));
            }
        };
        let encoding = match &s.encoding {
            None => encoding_rs::UTF_8,
            Some(e) => {
                // WHATWG labels, plus the spelling people write (`latin-1` for `latin1`).
                let label = e.value.trim();
                let found = encoding_rs::Encoding::for_label(label.as_bytes()).or_else(|| {
                    encoding_rs::Encoding::for_label(label.replace('-', "").as_bytes())
                });
                match found {
                    Some(enc) if enc.is_ascii_compatible() => enc,
                    _ => {
                        return Err(self.err(
                            self.at(&e.referenced),
                            &format!("unknown or unsupported encoding `{}`", e.value),
                            "an ASCII-compatible WHATWG label: utf-8, latin-1, windows-1252, \
                             shift_jis...",
                        ));
                    }
                }
            }
        };
        let header = match &s.header {
            None => true,
            Some(h) if h.value == "none" => false,
            Some(h) if h.value == "first" => true,
            Some(h) => {
                return Err(self.err(
                    self.at(&h.referenced),
                    &format!("header `{}`", h.value),
                    "source.header is `none` (columns by index) or absent (the first line \
                     after the skipped ones names the columns)",
                ));
            }
        };
        let delimiter = match s.delimiter.as_ref().map(|d| d.value.as_str()) {
            None | Some("auto") => Delimiter::Auto,
            Some("whitespace") => Delimiter::Whitespace,
            Some("tab" | "\t") => Delimiter::Byte(b'\t'),
            Some(d) if d.len() == 1 && d != "\"" && d != "\n" && d != "\r" => {
                Delimiter::Byte(d.as_bytes()[0])
            }
            Some(d) => {
                let at = s
                    .delimiter
                    .as_ref()
                    .map_or(0..0, |d| self.at(&d.referenced));
                return Err(self.err(
                    at,
                    &format!("delimiter `{d}`"),
                    "source.delimiter is one ASCII character, `tab` or `whitespace` (default: \
                     found from the file)",
                ));
            }
        };
        Ok(SourceSpec {
            format,
            encoding,
            skip_lines: s.skip_lines.unwrap_or(0),
            header,
            delimiter,
        })
    }

    pub(super) fn col(&self, c: &Spanned<RawCol>) -> Res<Col> {
        let at = self.at(&c.referenced);
        let col = match &c.value {
            RawCol::Index(i) => ColRef::Index(usize::try_from(*i).unwrap_or(usize::MAX)),
            RawCol::Name(n) if n.trim().is_empty() => {
                return Err(self.err(at, "an empty column name", "name a header column"));
            }
            RawCol::Name(n) => ColRef::Name(n.clone()),
        };
        Ok(Col { col, at })
    }

    fn scale(&self, u: &Spanned<String>, dim: Dim, zero: Option<Spanned<RawTriple>>) -> Res<Scale> {
        let at = self.at(&u.referenced);
        let factor = scale_of(&u.value, dim).map_err(|m| {
            self.err(
                at.clone(),
                &m,
                "any unit of the procedure language (g, mg, m/s^2, deg/s, rad/s...) or counts",
            )
        })?;
        let zero = match zero {
            None => [0.0; 3],
            Some(z) => {
                let v = match z.value {
                    RawTriple::One(x) => [x; 3],
                    RawTriple::Three(v) => v,
                };
                if !v.iter().all(|x| x.is_finite()) {
                    return Err(self.err(self.at(&z.referenced), "zero must be finite", HELP));
                }
                v
            }
        };
        Ok(Scale {
            factor,
            zero,
            unit: u.value.clone(),
            at,
        })
    }

    fn axes(&self, axes: Option<&Spanned<Vec<Spanned<String>>>>) -> Res<[(usize, f64); 3]> {
        let Some(axes) = axes else {
            return Ok([(0, 1.0), (1, 1.0), (2, 1.0)]);
        };
        let help = "axes lists, for body x, y, z, the sensor axis with its sign: [x, -y, -z]";
        if axes.value.len() != 3 {
            return Err(self.err(self.at(&axes.referenced), "axes needs three entries", help));
        }
        let mut out = [(0, 1.0); 3];
        for (k, a) in axes.value.iter().enumerate() {
            out[k] = signed_axis(&a.value).ok_or_else(|| {
                self.err(
                    self.at(&a.referenced),
                    &format!("`{}` is not an axis", a.value),
                    help,
                )
            })?;
        }
        let mut seen = [false; 3];
        for (k, (i, _)) in out.iter().enumerate() {
            if std::mem::replace(&mut seen[*i], true) {
                return Err(self.err(
                    self.at(&axes.value[k].referenced),
                    &format!("sensor axis {} is used twice", AXES[*i]),
                    help,
                ));
            }
        }
        Ok(out)
    }

    fn site(&self, raw: &RawMap) -> Res<Site> {
        let (lat, g) = (&raw.site.latitude_deg, &raw.site.gravity_mps2);
        if !(-90.0..=90.0).contains(&lat.value) {
            return Err(self.err(
                self.at(&lat.referenced),
                "latitude_deg must lie in -90..90",
                "the site's geodetic latitude, degrees north",
            ));
        }
        if !(9.7..=9.9).contains(&g.value) {
            return Err(self.err(
                self.at(&g.referenced),
                &format!("gravity_mps2 {} is not a gravity on Earth", g.value),
                "the local gravity in m/s^2 (9.78 to 9.84 at sea level)",
            ));
        }
        Ok(Site {
            latitude_deg: lat.value,
            gravity_mps2: g.value,
        })
    }

    fn time_q(&self, q: &Spanned<String>) -> Res<f64> {
        match parse_quantity(&q.value) {
            Some((Dim::Time, v)) if v > 0.0 && v.is_finite() => Ok(v),
            _ => Err(self.err(
                self.at(&q.referenced),
                &format!("`{}` is not a positive time", q.value),
                "write a time with its unit, e.g. \"2 s\"",
            )),
        }
    }
}

/// Turns a serde-saphyr error into a located diagnostic naming the map file.
fn yaml_error(err: &serde_saphyr::Error, text: &str, file: &str) -> Box<ImportError> {
    let (line, column) = match err.location() {
        Some(l) if l.line() > 0 => (l.line(), l.column()),
        _ => (1, 1),
    };
    let at = yaml_offset(text, line, column);
    let msg = err.without_snippet().to_string();
    let first = msg.lines().next().unwrap_or("").trim();
    let what = first.find(" at line ").map_or(first, |i| &first[..i]);
    let help = if what.contains("unknown field") {
        format!(
            "{}; {HELP}",
            what.split_once("expected ").map_or("", |x| x.1)
        )
    } else {
        HELP.to_string()
    };
    ImportError::in_text(
        ErrorKind::Map,
        file,
        text,
        at..at + 1,
        Say {
            what,
            label: "here",
            help: &help,
        },
    )
}
