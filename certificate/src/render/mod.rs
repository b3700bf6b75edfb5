//! Renderers: Markdown and HTML walk the same blocks ([`doc::blocks`]); the PDF is the
//! certificate's JSON typeset by Typst through a template ([`typeset`]).

pub mod doc;
mod html;
mod logo;
mod md;
pub mod typeset;

pub use html::html;
pub use logo::Logo;
pub use md::markdown;
pub use typeset::{DEFAULT_TEMPLATE, Template, TemplateError, pdf};
