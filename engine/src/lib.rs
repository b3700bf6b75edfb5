//! ratecal's stages, each a function from one data type to the next:
//! `check` (AST -> Plan), `run` (Plan + drivers -> Recording), `fit` (Recording ->
//! Results), `render` (Results -> report), `audit` (Plan vs Plan, run folders).
//! Only `run` awaits; the engine does IO only through what it is handed.

pub mod audit;
pub mod check;
pub mod explain;
pub mod fit;
pub mod measured;
pub mod plan;
/// The recording format lives in its own crate; `crate::recording` names it here.
pub use ratecal_recording as recording;
pub mod render;
pub mod results;
pub mod run;
