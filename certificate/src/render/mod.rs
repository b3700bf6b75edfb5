//! Renderers: every format walks the same blocks ([`doc::blocks`]).

pub mod doc;
mod html;
mod logo;
mod md;
mod pdf;

pub use html::html;
pub use logo::Logo;
pub use md::markdown;
pub use pdf::{PdfError, pdf};
