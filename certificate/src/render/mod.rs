//! Renderers: every format walks the same blocks ([`doc::blocks`]).

pub mod doc;
mod html;
mod md;

pub use html::html;
pub use md::markdown;
