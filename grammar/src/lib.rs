//! The ratecal procedure language: a pest grammar, a spanned AST, comments kept for the
//! canonical formatter, and diagnostics rendered with miette.
//!
//! ```
//! let text = "procedure demo version 1.0.0 {\n  title \"Demo\"\n}\n";
//! let file = ratecal_grammar::parse(text).unwrap();
//! assert_eq!(ratecal_grammar::format(&file), text);
//! let canon = ratecal_grammar::canonical(text).unwrap();
//! assert_eq!(canon.sha256.len(), 64);
//! ```

pub mod ast;
mod comments;
mod diag;
pub mod effect;
mod fmt;
mod lower;
mod syntax;

pub use diag::{Diagnostic, Severity, Source, source};
pub use fmt::{format_abort, format_value};

use sha2::{Digest, Sha256};

/// Parses a procedure (or definitions) file; comments are attached to the AST.
/// The diagnostic has no source attached: callers add theirs with `with_source`.
pub fn parse(text: &str) -> Result<ast::File, Diagnostic> {
    let mut file = lower::parse_file(text)?;
    comments::attach(&mut file, comments::scan(text), text);
    Ok(file)
}

/// Renders a parsed file in canonical layout.
pub fn format(file: &ast::File) -> String {
    fmt::format_file(file)
}

/// A file's canonical text and the lowercase hex SHA-256 of that text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Canonical {
    /// Canonical text.
    pub text: String,
    /// SHA-256 of `text` (UTF-8 bytes), lowercase hex.
    pub sha256: String,
}

/// Parses and formats a text, and hashes the canonical form (for `versions.lock`,
/// manifests and reports: two texts that differ only in layout hash the same).
pub fn canonical(text: &str) -> Result<Canonical, Diagnostic> {
    let file = parse(text)?;
    let text = format(&file);
    let sha256 = sha256_hex(text.as_bytes());
    Ok(Canonical { text, sha256 })
}

/// Lowercase hex SHA-256 of bytes.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex::encode(Sha256::digest(bytes))
}
