//! Parsing `manifest.yaml`, located errors included.

// A refused manifest is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use crate::error::{RecordingError, line_col, yaml_offset};
use crate::excerpt::Excerpt;
use crate::{FORMAT, Manifest};

/// Parses manifest text (`file` names it in errors).
pub fn parse_manifest(file: &str, text: &str) -> Result<Manifest, RecordingError> {
    let manifest: Manifest = serde_saphyr::from_str(text).map_err(|e| {
        let (offset, len, line, column) = match e.location() {
            // The parser's line and column locate the error; its span's byte offset is
            // absent at some scanner errors (the snippet then showed line 1), so it is
            // used only when it points where they do.
            Some(loc) if loc.line() > 0 => {
                let off = yaml_offset(text, loc.line(), loc.column());
                let len = match loc.span().byte_offset() {
                    Some(o) if o as usize == off => loc.span().byte_len().unwrap_or(1) as usize,
                    _ => 1,
                };
                (off, len, loc.line(), loc.column())
            }
            _ => (0, 0, 1, 1),
        };
        let message = e.to_string();
        let message = message.lines().next().unwrap_or("invalid manifest");
        // The parser's message repeats the location we print already.
        let message = message.strip_prefix("error: ").unwrap_or(message);
        let message = match message
            .strip_prefix("line ")
            .and_then(|m| m.split_once(": "))
        {
            Some((_, rest)) => rest.to_string(),
            None => message.to_string(),
        };
        RecordingError::Manifest {
            file: file.to_string(),
            line,
            column,
            message,
            src: Excerpt::around(file, text.as_bytes(), offset, offset + len).0,
            span: Excerpt::around(file, text.as_bytes(), offset, offset + len).1,
        }
    })?;
    if manifest.format != FORMAT {
        let offset = text
            .find(&manifest.format)
            .or_else(|| text.find("format"))
            .unwrap_or(0);
        let (line, column) = line_col(text, offset);
        return Err(RecordingError::UnknownFormat {
            file: file.to_string(),
            line,
            column,
            found: manifest.format.clone(),
            src: Excerpt::around(
                file,
                text.as_bytes(),
                offset,
                offset + manifest.format.len().max(1),
            )
            .0,
            span: Excerpt::around(
                file,
                text.as_bytes(),
                offset,
                offset + manifest.format.len().max(1),
            )
            .1,
        });
    }
    super::validate::manifest(file, text, &manifest)?;
    Ok(manifest)
}
