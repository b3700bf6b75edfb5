//! Calibration certificates a laboratory can sign and send (ISO/IEC 17025, 7.8): the data
//! model, the GUM uncertainty budget (Type A from the fit, Type B from what the station file
//! states, Welch-Satterthwaite, Student's t) and the renderers.
//!
//! ```text
//! results.json, manifest, plan, station facts, LAB.yaml, number, approval
//!   ─ build::build ─► Certificate ─ render::{markdown, html, pdf} / serde_json
//! ```
//!
//! [`issue`] is where a certificate is issued: it reads the laboratory's file and the run
//! folder (through `ratecal-folder`'s reader), applies the traceability rules and takes the
//! number from the archive; everything below it is handed its data.

mod build;
mod conformity;
pub mod issue;
mod model;
mod number;
mod points;
pub mod render;
mod signers;
mod stated;
pub mod units;

pub use build::{Input, build, gum_text};
pub use model::{
    ApprovalBlock, Certificate, Conformity, ConformityCheck, END_MARK, FORMAT, ITEM_ONLY,
    Identification, Lab, MeasurementPoint, Method, ProcedureId, REPRODUCTION, ReferenceStandard,
    ResultLine, SPECIMEN, Signer, StationId, Traceability,
};
pub use number::{json, verify};
/// The GUM budget, computed by the analysis (results.json `budgets`).
pub use ratecal_analysis::budget;
pub use ratecal_analysis::budget::{terms, type_a_dof};
pub use stated::{stated, stated_of_folder};
