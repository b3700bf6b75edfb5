//! ratecal's stages, each a function from one data type to the next:
//! `check` (AST -> Plan), `run` (Plan + drivers -> Recording), `render` (Results -> report),
//! `audit` (Plan vs Plan, run folders). The plan and the analysis (`fit`, `explain`,
//! `results`) live in crates of their own (`ratecal-plan`, `ratecal-analysis`) and are
//! re-exported here under their stage names. Only `run` awaits; the engine does IO only
//! through what it is handed.

pub mod audit;
pub mod check;
pub use ratecal_analysis::{explain, fit, measured, results, twin};
pub use ratecal_plan as plan;
/// The recording format lives in its own crate; `crate::recording` names it here.
pub use ratecal_recording as recording;
pub mod render;
pub mod run;
