//! MATLAB v5 binary files (`save -v6`, `-v7`: MATLAB's default, compressed): the one
//! numeric matrix the map names, rows as samples, columns by 0-based index. A small focused
//! reader: the `matfile` crate prints to stdout/stderr on input it skips, drops character,
//! cell and struct variables without a trace (so a wrong class reads as "missing") and
//! locates nothing. v7.3 files are HDF5 and are refused with what to do. Every refusal
//! names the file, the byte offset (and the variable) with a help line.

use crate::error::{ErrorKind, ImportError};
use flate2::read::ZlibDecoder;
use std::io::Read;

type Res<T> = Result<T, Box<ImportError>>;

/// The matrix read: `rows` samples of `cols` channels, column-major as MATLAB stores it.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    /// Rows (samples).
    pub rows: usize,
    /// Columns (channels).
    pub cols: usize,
    /// `data[c * rows + r]`.
    pub data: Vec<f64>,
    /// MATLAB class name (`double`, `int16`...).
    pub class: &'static str,
}

/// A variable seen in the file: name and class (for "not found" and "not numeric").
#[derive(Debug, Clone)]
struct Seen {
    name: String,
    class: &'static str,
}

const CLASSES: [&str; 16] = [
    "?", "cell", "struct", "object", "char", "sparse", "double", "single", "int8", "uint8",
    "int16", "uint16", "int32", "uint32", "int64", "uint64",
];
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
/// Largest matrix header read (elements): 2^31; beyond it the header is damaged.
const MAX_ELEMENTS: u64 = 1 << 31;
/// The memory budget of the matrix read (its values as f64, bytes): 40 MiB, 5,242,880
/// values (750,000 samples of 7 channels, 2 h at 100 Hz). The matrix is inflated no
/// further than its declared dimensions allow, so the import stays well under 100 MB
/// whatever the file claims; a larger session is imported in parts or as CSV (streamed).
pub const MATRIX_BUDGET_BYTES: u64 = 40 << 20;

fn class_name(c: u32) -> &'static str {
    CLASSES.get(c as usize).copied().unwrap_or("unknown")
}

/// Why a MATLAB file cannot be read, at byte `at`.
fn bad(name: &str, at: usize, what: &str, help: &str) -> Box<ImportError> {
    ImportError::in_file(ErrorKind::Format, name, &format!("byte {at}: {what}"), help)
}

const RESAVE: &str = "save it again from MATLAB with `save(\"data.mat\", \"cal_data\", \"-v7\")`, \
                      or export it as text: `writematrix(cal_data, \"data.csv\")`";

/// Reads `variable` from the MATLAB file `bytes` named `name`.
pub fn read_mat(bytes: &[u8], name: &str, variable: &str) -> Res<Matrix> {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(116)]);
    if text.starts_with("MATLAB 7.3 MAT-file") || bytes.get(512..520) == Some(b"\x89HDF\r\n\x1a\n")
    {
        return Err(bad(
            name,
            0,
            "a MATLAB v7.3 file (HDF5): not supported",
            &format!(
                "save with -v7 (MATLAB's default, compressed, read here): \
                 `save(\"data.mat\", \"{variable}\", \"-v7\")`"
            ),
        ));
    }
    if bytes.starts_with(b"\x89HDF") {
        return Err(bad(name, 0, "an HDF5 file, not a MATLAB v5 file", RESAVE));
    }
    if bytes.len() < 128 || !text.starts_with("MATLAB 5.0 MAT-file") {
        return Err(bad(
            name,
            0,
            "not a MATLAB v5 binary file (no `MATLAB 5.0 MAT-file` header)",
            "a text file named .mat (imu_tk's are) is read with `source: { format: csv, \
             header: none }`",
        ));
    }
    let le = match &bytes[126..128] {
        b"IM" => true,
        b"MI" => false,
        _ => {
            return Err(bad(
                name,
                126,
                "the endian indicator is not `IM` or `MI`",
                RESAVE,
            ));
        }
    };
    let r = Reader { name, le };
    let mut seen = Vec::new();
    let mut at = 128;
    while at + 8 <= bytes.len() {
        let (ty, n, body) = r.tag(bytes, at)?;
        let data = r.slice(bytes, body, n)?;
        let found = match ty {
            MI_MATRIX => r.matrix(data, body, variable)?,
            MI_COMPRESSED => r.compressed(data, body, variable)?,
            _ => None,
        };
        match found {
            Some(Found::Matrix(m)) => return Ok(m),
            Some(Found::Other(s)) => seen.push(s),
            None => {}
        }
        at = body + if ty == MI_COMPRESSED { n } else { pad8(n) };
    }
    if let Some(s) = seen.iter().find(|s| s.name == variable) {
        return Err(bad(
            name,
            0,
            &format!(
                "variable `{variable}` is a {} array, not a numeric matrix",
                s.class
            ),
            "save the samples as one numeric matrix (double, single or integer), one row \
             per sample",
        ));
    }
    let list: Vec<String> = seen
        .iter()
        .map(|s| format!("{} ({})", s.name, s.class))
        .collect();
    Err(ImportError::in_file(
        ErrorKind::Format,
        name,
        &format!("has no variable `{variable}`"),
        &if list.is_empty() {
            "the file holds no variables; check the file".to_string()
        } else {
            format!("set source.variable to one of: {}", list.join(", "))
        },
    ))
}

enum Found {
    Matrix(Matrix),
    Other(Seen),
}

struct Reader<'a> {
    name: &'a str,
    le: bool,
}

fn pad8(n: usize) -> usize {
    n.div_ceil(8).saturating_mul(8)
}

impl Reader<'_> {
    fn u32(&self, b: &[u8], at: usize) -> Res<u32> {
        let w: [u8; 4] = b
            .get(at..at.saturating_add(4))
            .and_then(|s| s.try_into().ok())
            .ok_or_else(|| bad(self.name, at, "the file ends inside an element", RESAVE))?;
        Ok(if self.le {
            u32::from_le_bytes(w)
        } else {
            u32::from_be_bytes(w)
        })
    }

    /// A data element's tag at `at`: (type, byte count, offset of its data).
    fn tag(&self, b: &[u8], at: usize) -> Res<(u32, usize, usize)> {
        let first = self.u32(b, at)?;
        if first >> 16 != 0 {
            // Small data element: type and size in one word, data in the next four bytes.
            let n = (first >> 16) as usize;
            if n > 4 {
                return Err(bad(
                    self.name,
                    at,
                    "a small data element longer than 4 bytes",
                    RESAVE,
                ));
            }
            return Ok((first & 0xffff, n, at + 4));
        }
        Ok((first, self.u32(b, at + 4)? as usize, at + 8))
    }

    fn slice<'b>(&self, b: &'b [u8], at: usize, n: usize) -> Res<&'b [u8]> {
        b.get(at..at.saturating_add(n)).ok_or_else(|| {
            bad(
                self.name,
                at,
                &format!("an element of {n} bytes runs past the end of the file"),
                "the file is truncated or damaged; copy it again",
            )
        })
    }

    /// A zlib-compressed element (`base` is its offset in the file, for errors).
    fn compressed(&self, data: &[u8], base: usize, variable: &str) -> Res<Option<Found>> {
        let damaged = |e: std::io::Error| {
            bad(
                self.name,
                base,
                &format!("a compressed variable does not inflate: {e}"),
                "the file is truncated or damaged; copy it again",
            )
        };
        // Its head first: flags, dimensions and name, to skip other variables cheaply.
        let mut head = Vec::new();
        ZlibDecoder::new(data)
            .take(4096)
            .read_to_end(&mut head)
            .map_err(damaged)?;
        let (ty, _, body) = self.tag(&head, 0)?;
        if ty != MI_MATRIX {
            return Ok(None);
        }
        let h = self.header(&head, body, base)?;
        if h.name != variable || !(6..=15).contains(&h.class) {
            return Ok(Some(Found::Other(Seen {
                name: h.name,
                class: class_name(h.class),
            })));
        }
        self.within_budget(&h, base, variable)?;
        // Deflate expands at most 1032:1: a stream cannot hold more (a damaged header
        // claiming a huge matrix does not make us allocate it).
        let limit = h
            .elements
            .saturating_mul(8)
            .min((data.len() as u64).saturating_mul(1032))
            .saturating_add(1 << 16);
        let mut all = Vec::new();
        ZlibDecoder::new(data)
            .take(limit)
            .read_to_end(&mut all)
            .map_err(damaged)?;
        let (_, n, body) = self.tag(&all, 0)?;
        let n = n.min(all.len().saturating_sub(body));
        self.matrix(self.slice(&all, body, n)?, base, variable)
    }

    /// An miMATRIX element's contents.
    fn matrix(&self, d: &[u8], base: usize, variable: &str) -> Res<Option<Found>> {
        let h = self.header(d, 0, base)?;
        if h.name != variable || !(6..=15).contains(&h.class) {
            return Ok(Some(Found::Other(Seen {
                name: h.name,
                class: class_name(h.class),
            })));
        }
        self.within_budget(&h, base, variable)?;
        if h.complex {
            return Err(bad(
                self.name,
                base,
                &format!("variable `{variable}` is complex"),
                "save the real samples: `cal_data = real(cal_data)`",
            ));
        }
        if h.dims.len() != 2 {
            return Err(bad(
                self.name,
                base,
                &format!(
                    "variable `{variable}` has {} dimensions; a matrix of one row per sample \
                     is read",
                    h.dims.len()
                ),
                "reshape it to samples x channels before saving",
            ));
        }
        let (rows, cols) = (h.dims[0] as usize, h.dims[1] as usize);
        let (ty, n, body) = self.tag(d, h.next)?;
        let data = self.slice(d, body, n)?;
        let values = self.numbers(ty, data, base + body)?;
        if values.len() as u64 != h.elements {
            return Err(bad(
                self.name,
                base + body,
                &format!(
                    "variable `{variable}` is {rows} x {cols} but holds {} values",
                    values.len()
                ),
                "the file is damaged; save it again",
            ));
        }
        Ok(Some(Found::Matrix(Matrix {
            rows,
            cols,
            data: values,
            class: class_name(h.class),
        })))
    }

    /// Refuses the variable read when its declared values exceed [`MATRIX_BUDGET_BYTES`]
    /// as f64: before it is inflated or converted.
    fn within_budget(&self, h: &Header, base: usize, variable: &str) -> Res<()> {
        let budget = MATRIX_BUDGET_BYTES / 8;
        if h.elements <= budget {
            return Ok(());
        }
        let dims: Vec<String> = h.dims.iter().map(u32::to_string).collect();
        Err(bad(
            self.name,
            base,
            &format!(
                "variable `{variable}` is {}: {} values, more than the {budget} an import \
                 of a MATLAB matrix holds in memory ({} MiB)",
                dims.join(" x "),
                h.elements,
                MATRIX_BUDGET_BYTES >> 20
            ),
            "import the session in parts (split the matrix by time and import each), or \
             export it as CSV, which is read a line at a time",
        ))
    }

    /// Array flags, dimensions and name at `at` of `d`.
    fn header(&self, d: &[u8], at: usize, base: usize) -> Res<Header> {
        let (ty, n, body) = self.tag(d, at)?;
        if ty != 6 || n != 8 {
            return Err(bad(
                self.name,
                base + at,
                "a matrix without its array flags",
                RESAVE,
            ));
        }
        let flags = self.u32(d, body)?;
        let (ty, n, body) = self.tag(d, body + 8)?;
        if ty != 5 || n % 4 != 0 {
            return Err(bad(
                self.name,
                base + at,
                "a matrix without its dimensions",
                RESAVE,
            ));
        }
        let dims: Vec<u32> = (0..n / 4)
            .map(|k| self.u32(d, body + 4 * k))
            .collect::<Res<_>>()?;
        let elements = dims
            .iter()
            .try_fold(1u64, |p, &x| p.checked_mul(u64::from(x)))
            .filter(|&e| e <= MAX_ELEMENTS)
            .ok_or_else(|| bad(self.name, base + body, "a matrix of absurd size", RESAVE))?;
        let at = body + pad8(n);
        let (ty, n, body) = self.tag(d, at)?;
        if ty != 1 {
            return Err(bad(
                self.name,
                base + at,
                "a matrix without its name",
                RESAVE,
            ));
        }
        let name = String::from_utf8_lossy(self.slice(d, body, n)?).into_owned();
        let next = if body == at + 4 {
            at + 8
        } else {
            body + pad8(n)
        };
        Ok(Header {
            class: flags & 0xff,
            complex: flags & 0x800 != 0,
            dims,
            elements,
            name,
            next,
        })
    }

    /// The values of a numeric element of MATLAB type `ty` (MATLAB may store a double
    /// matrix in a narrower integer type when its values fit).
    fn numbers(&self, ty: u32, d: &[u8], at: usize) -> Res<Vec<f64>> {
        macro_rules! conv {
            ($t:ty, $n:expr) => {
                d.chunks_exact($n)
                    .map(|c| {
                        let w = c.try_into().unwrap_or([0; $n]);
                        (if self.le {
                            <$t>::from_le_bytes(w)
                        } else {
                            <$t>::from_be_bytes(w)
                        }) as f64
                    })
                    .collect()
            };
        }
        Ok(match ty {
            1 => d.iter().map(|&b| f64::from(b as i8)).collect(),
            2 => d.iter().map(|&b| f64::from(b)).collect(),
            3 => conv!(i16, 2),
            4 => conv!(u16, 2),
            5 => conv!(i32, 4),
            6 => conv!(u32, 4),
            7 => conv!(f32, 4),
            9 => conv!(f64, 8),
            12 => conv!(i64, 8),
            13 => conv!(u64, 8),
            _ => {
                return Err(bad(
                    self.name,
                    at,
                    &format!("matrix data of MATLAB type {ty}, not a number type"),
                    RESAVE,
                ));
            }
        })
    }
}

struct Header {
    class: u32,
    complex: bool,
    dims: Vec<u32>,
    elements: u64,
    name: String,
    /// Offset of the real part's tag.
    next: usize,
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn element(ty: u32, body: &[u8], claimed: Option<u32>) -> Vec<u8> {
        let mut e = ty.to_le_bytes().to_vec();
        e.extend(claimed.unwrap_or(body.len() as u32).to_le_bytes());
        e.extend(body);
        e.resize(8 + pad8(body.len()).max(body.len()), 0);
        e
    }

    /// A compressed `rows x cols` double matrix `cal_data` whose data (of MATLAB type
    /// `data_ty`) is `zeros` zero bytes while its tag claims them all: a decompression bomb.
    fn bomb(rows: u32, cols: u32, data_ty: u32, zeros: usize) -> Vec<u8> {
        let mut m = element(6, &[6, 0, 0, 0, 0, 0, 0, 0], None);
        let dims: Vec<u8> = [rows, cols].iter().flat_map(|d| d.to_le_bytes()).collect();
        m.extend(element(5, &dims, None));
        m.extend(element(1, b"cal_data", None));
        let mut data = data_ty.to_le_bytes().to_vec();
        data.extend(u32::MAX.to_le_bytes());
        data.extend(vec![0u8; zeros]);
        m.extend(data);
        let matrix = element(MI_MATRIX, &m, Some(u32::MAX));
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
        z.write_all(&matrix).unwrap();
        let packed = z.finish().unwrap();
        let mut file = b"MATLAB 5.0 MAT-file, bomb".to_vec();
        file.resize(124, b' ');
        file.extend([0, 1, b'I', b'M']);
        file.extend(element(MI_COMPRESSED, &packed, None));
        file
    }

    #[test]
    fn a_matrix_beyond_the_memory_budget_is_refused_before_it_is_inflated() {
        // 85M x 6 zeros (the probe's 7.98 GB bomb, its data cut to 4 MB of zeros), and
        // int8 data declared a 4000 x 6000 double matrix.
        for (rows, cols, ty) in [(85_000_000, 6, 9), (4000, 6000, 1)] {
            let file = bomb(rows, cols, ty, 4 << 20);
            assert!(file.len() < 64 << 10, "{} bytes", file.len());
            let Err(e) = read_mat(&file, "bomb.mat", "cal_data") else {
                panic!("refused");
            };
            let text = format!("{e:?}");
            assert!(text.contains("holds in memory (40 MiB)"), "{text}");
            assert!(text.contains(&format!("is {rows} x {cols}")), "{text}");
        }
    }

    #[test]
    fn a_matrix_within_the_budget_is_inflated_no_further_than_its_dimensions() {
        // 10 x 6 declared, 4 MB of zeros behind it: refused as damaged, not read whole.
        let file = bomb(10, 6, 9, 4 << 20);
        let Err(e) = read_mat(&file, "bomb.mat", "cal_data") else {
            panic!("refused");
        };
        assert!(!format!("{e:?}").contains("memory"), "{e:?}");
    }
}
