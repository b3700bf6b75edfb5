//! ratecal's analysis stages, each a function from one data type to the next:
//! `fit` (Recording + Plan -> Results: the joint fit, acceptance, verdict) and `explain`
//! (Recording -> findings: which physics the nominal model left out). Nothing here runs a
//! table or opens a socket: the recording comes in through [`fit::Source`], and the CLI
//! hands in what it read.

pub mod budget;
pub mod explain;
pub mod fit;
pub mod measured;
/// The checked procedure lives in its own crate; `crate::plan` names it here.
pub use ratecal_plan as plan;
/// The recording format lives in its own crate; `crate::recording` names it here.
pub use ratecal_recording as recording;
pub mod results;
pub mod twin;
