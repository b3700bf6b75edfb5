//! The laboratory's logo, drawn in the top margin of every page of the PDF, right-aligned
//! above the header: a JPEG embedded as it is (DCTDecode: only its frame header is read), a
//! PNG decoded by the `png` crate to 8-bit samples, its alpha channel as a soft mask.

use lopdf::{Dictionary, Document, Object, Stream, content::Content, content::Operation};

/// A decoded logo, ready to embed.
#[derive(Debug, Clone)]
pub struct Logo {
    width: u32,
    height: u32,
    image: Stream,
    mask: Option<Stream>,
}

/// The logo's height on the page, pt, and its widest width.
const HEIGHT_PT: f32 = 30.0;
const MAX_WIDTH_PT: f32 = 150.0;
/// Distance of the logo's top from the page's top edge and of its right side from the
/// page's right edge (the page decorator's 15 mm margin), pt.
const TOP_PT: f32 = 8.0;
const RIGHT_PT: f32 = 42.52;

impl Logo {
    /// Reads a PNG or JPEG file's bytes; the error says why it cannot be drawn.
    pub fn from_bytes(bytes: &[u8]) -> Result<Logo, String> {
        if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            png_logo(bytes)
        } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
            jpeg_logo(bytes)
        } else {
            Err("neither a PNG nor a JPEG file".into())
        }
    }

    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}

fn image_dict(width: u32, height: u32, space: &str) -> Dictionary {
    let mut d = Dictionary::new();
    d.set("Type", Object::Name(b"XObject".to_vec()));
    d.set("Subtype", Object::Name(b"Image".to_vec()));
    d.set("Width", i64::from(width));
    d.set("Height", i64::from(height));
    d.set("ColorSpace", Object::Name(space.as_bytes().to_vec()));
    d.set("BitsPerComponent", 8);
    d
}

fn png_logo(bytes: &[u8]) -> Result<Logo, String> {
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
    let (w, h) = (frame.width, frame.height);
    let pixels = &buf[..frame.buffer_size()];
    let (space, channels, alpha) = match frame.color_type {
        png::ColorType::Grayscale => ("DeviceGray", 1, false),
        png::ColorType::GrayscaleAlpha => ("DeviceGray", 1, true),
        png::ColorType::Rgb => ("DeviceRGB", 3, false),
        png::ColorType::Rgba => ("DeviceRGB", 3, true),
        png::ColorType::Indexed => return Err("an indexed PNG that did not expand".into()),
    };
    if frame.bit_depth != png::BitDepth::Eight {
        return Err(format!("a PNG of {:?} bits per sample", frame.bit_depth));
    }
    let stride = channels + usize::from(alpha);
    let (mut color, mut mask) = (Vec::new(), Vec::new());
    for px in pixels.chunks_exact(stride) {
        color.extend_from_slice(&px[..channels]);
        if alpha {
            mask.push(px[channels]);
        }
    }
    let mask = alpha.then(|| Stream::new(image_dict(w, h, "DeviceGray"), mask));
    Ok(Logo {
        width: w,
        height: h,
        image: Stream::new(image_dict(w, h, space), color),
        mask,
    })
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

fn jpeg_logo(bytes: &[u8]) -> Result<Logo, String> {
    let (h, w, n) = jpeg_frame(bytes).ok_or("a JPEG without a readable frame header")?;
    let space = match n {
        1 => "DeviceGray",
        3 => "DeviceRGB",
        4 => "DeviceCMYK",
        n => return Err(format!("a JPEG of {n} colour components")),
    };
    if w == 0 || h == 0 {
        return Err("a JPEG of no pixels".into());
    }
    let mut dict = image_dict(w, h, space);
    dict.set("Filter", Object::Name(b"DCTDecode".to_vec()));
    let image = Stream::new(dict, bytes.to_vec()).with_compression(false);
    Ok(Logo {
        width: w,
        height: h,
        image,
        mask: None,
    })
}

/// Draws `logo` on every page of `doc`: one image object, referenced by each page.
pub(super) fn stamp(doc: &mut Document, logo: &Logo) -> lopdf::Result<()> {
    let mut image = logo.image.clone();
    if let Some(mask) = &logo.mask {
        let id = doc.add_object(mask.clone());
        image.dict.set("SMask", Object::Reference(id));
    }
    let id = doc.add_object(image);
    let aspect = logo.width as f32 / logo.height as f32;
    let (w, h) = if HEIGHT_PT * aspect > MAX_WIDTH_PT {
        (MAX_WIDTH_PT, MAX_WIDTH_PT / aspect)
    } else {
        (HEIGHT_PT * aspect, HEIGHT_PT)
    };
    let pages: Vec<lopdf::ObjectId> = doc.get_pages().into_values().collect();
    for page in pages {
        let (pw, ph) = page_size(doc, page);
        doc.add_xobject(page, "RcLogo", id)?;
        let ops = vec![
            Operation::new("q", vec![]),
            Operation::new(
                "cm",
                vec![
                    w.into(),
                    0.into(),
                    0.into(),
                    h.into(),
                    (pw - RIGHT_PT - w).into(),
                    (ph - TOP_PT - h).into(),
                ],
            ),
            Operation::new("Do", vec![Object::Name(b"RcLogo".to_vec())]),
            Operation::new("Q", vec![]),
        ];
        doc.add_to_page_content(page, Content { operations: ops })?;
    }
    Ok(())
}

/// A page's MediaBox width and height, pt (A4 when it has none).
fn page_size(doc: &Document, page: lopdf::ObjectId) -> (f32, f32) {
    let number = |o: &Object| {
        o.as_float()
            .ok()
            .or_else(|| o.as_i64().ok().map(|v| v as f32))
    };
    doc.get_object(page)
        .and_then(Object::as_dict)
        .and_then(|d| d.get(b"MediaBox"))
        .and_then(Object::as_array)
        .ok()
        .and_then(|b| {
            Some((
                number(b.get(2)?)? - number(b.first()?)?,
                number(b.get(3)?)? - number(b.get(1)?)?,
            ))
        })
        .unwrap_or((595.28, 841.89))
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
        assert_eq!(
            logo.image.dict.get(b"Filter").unwrap().as_name().unwrap(),
            b"DCTDecode"
        );
        assert_eq!(jpeg_frame(&j[..20]), None);
        let scan_first = [0xff, 0xd8, 0xff, 0xda, 0, 8, 0, 0, 0, 0, 0, 0];
        assert!(Logo::from_bytes(&scan_first).is_err());
    }
}
