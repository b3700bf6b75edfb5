//! The laboratory's logo, checked before anything is typeset: a PNG that the `png` crate
//! decodes (8-bit samples after expansion) or a JPEG with a readable frame header. The
//! template draws it (`image(sys.inputs.logo)`) in the top margin of every page, 30 pt
//! high, right-aligned.

use super::typeset::LogoFile;

/// A logo that can be drawn.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Logo {
    width: u32,
    height: u32,
    file: LogoFile,
}

impl Logo {
    /// Reads a PNG or JPEG file's bytes; the error says why it cannot be drawn.
    pub fn from_bytes(bytes: &[u8]) -> Result<Logo, String> {
        let (width, height, extension) = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            let (w, h) = png_size(bytes)?;
            (w, h, "png")
        } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
            let (h, w, n) = jpeg_frame(bytes).ok_or("a JPEG without a readable frame header")?;
            if !matches!(n, 1 | 3 | 4) {
                return Err(format!("a JPEG of {n} colour components"));
            }
            (w, h, "jpg")
        } else {
            return Err("neither a PNG nor a JPEG file".into());
        };
        if width == 0 || height == 0 {
            return Err("an image of no pixels".into());
        }
        Ok(Logo {
            width,
            height,
            file: LogoFile {
                bytes: bytes.to_vec(),
                extension,
            },
        })
    }

    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The file as the template reads it.
    pub fn file(&self) -> &LogoFile {
        &self.file
    }
}

/// Decodes the PNG's first frame (a logo that does not decode is refused here, not left
/// to fail in the typesetter).
fn png_size(bytes: &[u8]) -> Result<(u32, u32), String> {
    let bad = |e: png::DecodingError| format!("not a readable PNG: {e}");
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(bad)?;
    let size = reader
        .output_buffer_size()
        .ok_or("the PNG is too large to decode")?;
    if size > 64 << 20 {
        return Err("the PNG is larger than 64 MiB decoded: use a smaller logo".into());
    }
    let mut buf = vec![0; size];
    let frame = reader.next_frame(&mut buf).map_err(bad)?;
    Ok((frame.width, frame.height))
}

/// The frame header (SOFn) of a JPEG: height, width, components.
fn jpeg_frame(bytes: &[u8]) -> Option<(u32, u32, u8)> {
    let mut i = 2;
    while i + 4 <= bytes.len() {
        if bytes[i] != 0xff {
            return None;
        }
        let marker = bytes[i + 1];
        if marker == 0xff {
            i += 1; // fill byte
            continue;
        }
        if marker == 0x01 || (0xd0..=0xd7).contains(&marker) {
            i += 2; // no length
            continue;
        }
        let len = usize::from(u16::from_be_bytes([bytes[i + 2], bytes[i + 3]]));
        let sof = (0xc0..=0xcf).contains(&marker) && ![0xc4, 0xc8, 0xcc].contains(&marker);
        if sof {
            let f = bytes.get(i + 4..i + 10)?;
            let height = u32::from(u16::from_be_bytes([f[1], f[2]]));
            let width = u32::from(u16::from_be_bytes([f[3], f[4]]));
            return Some((height, width, f[5]));
        }
        if marker == 0xda || len < 2 {
            return None; // scan data before any frame header
        }
        i += 2 + len;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A JPEG's frame header found past an APP0 segment and fill bytes; scan data before
    /// any frame header, or a truncated file, is refused.
    #[test]
    fn a_jpeg_frame_header_gives_its_size_and_components() {
        let mut j = vec![0xff, 0xd8, 0xff, 0xe0, 0, 16];
        j.extend_from_slice(b"JFIF\0\x01\x01\0\0\x01\0\x01\0\0");
        j.extend_from_slice(&[0xff, 0xff, 0xc2, 0, 17, 8, 0, 48, 1, 44, 3]);
        j.extend_from_slice(&[0; 9]);
        assert_eq!(jpeg_frame(&j), Some((48, 300, 3)));
        let logo = Logo::from_bytes(&j).unwrap();
        assert_eq!(logo.size(), (300, 48));
        assert_eq!(logo.file().extension, "jpg");
        assert_eq!(jpeg_frame(&j[..20]), None);
        let scan_first = [0xff, 0xd8, 0xff, 0xda, 0, 8, 0, 0, 0, 0, 0, 0];
        assert!(Logo::from_bytes(&scan_first).is_err());
    }
}
