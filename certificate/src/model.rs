//! What a certificate holds, in its order (`docs/certificate.md`): one data model, rendered
//! as Markdown, HTML and PDF, and written whole by `--format json` (its keys are a stable
//! interface).

use crate::budget::Budget;
use serde::{Deserialize, Serialize};

/// The format tag of `ratecal certificate --format json`.
pub const FORMAT: &str = "ratecal-certificate/1";

/// The laboratory, from `LAB.yaml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lab {
    /// The laboratory's name.
    pub name: String,
    /// Its postal address (one line or several).
    pub address: String,
    /// Its accreditation (body, number, scope).
    pub accreditation: String,
    /// The certificate numbers' prefix (`PREFIX-YYYY-NNNNNN`): letters, digits and dashes.
    pub certificate_prefix: String,
    /// A logo image file (PNG or JPEG), relative to `LAB.yaml`: drawn in the top margin of
    /// every page of the PDF.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logo: Option<String>,
    /// A Typst template file, relative to `LAB.yaml`, that typesets the PDF in place of the
    /// default one (`certificate/templates/certificate.typ` is the default, to copy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub template: Option<String>,
    /// The authorised signers: an approved run's certificate is issued only when its
    /// approval key is one of theirs (not written into the certificate's JSON).
    #[serde(default, skip_serializing)]
    pub signers: Vec<Signer>,
}

/// An authorised signer (`LAB.yaml` `signers`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Signer {
    /// Their name.
    pub name: String,
    /// Their role.
    pub role: String,
    /// The `.pub` file `ratecal key new` wrote, relative to `LAB.yaml`.
    pub public_key: String,
}

/// A calibration certificate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Certificate {
    /// `ratecal-certificate/1`.
    pub format: String,
    /// `PREFIX-YYYY-NNNNNN`; `None` for a draft or a dry run's specimen, which take no
    /// number.
    pub number: Option<String>,
    /// The number of the certificate this one amends and replaces.
    pub replaces: Option<String>,
    /// Why it amends the one it replaces.
    pub amend_reason: Option<String>,
    /// True until the run is approved (`ratecal approve`): every page says DRAFT.
    pub draft: bool,
    /// True for a dry run (a simulated station): a specimen, "DRY RUN - SPECIMEN" on every
    /// page.
    pub specimen: bool,
    /// The laboratory.
    pub lab: Lab,
    /// Identification of the calibration.
    pub identification: Identification,
    /// Method and conditions.
    pub method: Method,
    /// The model equation the parameters belong to.
    pub model_equation: Vec<String>,
    /// Each calibrated parameter: value +- U (k, 95 %).
    pub results: Vec<ResultLine>,
    /// Each rate point and attitude: the reference, the IMU's reading, the error, U and
    /// the verdict (empty: not stated).
    pub measurement_points: Vec<MeasurementPoint>,
    /// Uncertainty budget: one entry per reported quantity.
    pub budget: Vec<Budget>,
    /// Statements of conformity, when the procedure has acceptance checks.
    pub conformity: Option<Conformity>,
    /// Traceability to the reference standards.
    pub traceability: Traceability,
    /// Who approved the results, `None` for a draft.
    pub approval: Option<ApprovalBlock>,
    /// Notes printed on the certificate (incomplete budgets, overridden refusals).
    pub notes: Vec<String>,
    /// Deviations from the procedure's normal course: every `--allow-*` the issuer gave
    /// and every warning of the run.
    pub deviations: Vec<String>,
}

/// One measurement point: a rate point or an attitude of the procedure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeasurementPoint {
    /// The segment (step) it was measured in.
    pub segment: String,
    /// `static` (an attitude) or `rate` (a rate point).
    pub kind: String,
    /// The sensor and axis compared (`accel.z`, `gyro.x`).
    pub channel: String,
    /// What the table applied, in words (`+z up`, `outer axis at 100 deg/s`).
    pub condition: String,
    /// The reference value on that channel.
    pub reference: f64,
    /// The IMU's reading: the segment's mean raw output on that channel.
    pub reading: f64,
    /// `reading - reference`.
    pub error: f64,
    /// The expanded uncertainty of the mean reading (k below), from its scatter.
    #[serde(rename = "U")]
    pub expanded: f64,
    /// The coverage factor of `U`.
    pub k: f64,
    /// Unit of reference, reading, error and U.
    pub unit: String,
    /// `consistent` when the calibrated model explains the reading within U (its
    /// residual), else `inconsistent`.
    pub verdict: String,
}

/// A reference standard the measurement traces to.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceStandard {
    /// What it is: `rate table`, `DAQ timebase`, `gravity survey`, `thermometer`.
    pub standard: String,
    /// Its calibration certificate's number (`None`: not stated).
    pub certificate: Option<String>,
    /// Who issued it.
    pub issued_by: Option<String>,
    /// When it is due, YYYY-MM-DD.
    pub due: Option<String>,
    /// Whether it was in date on the date of calibration (`None`: not stated).
    pub valid: Option<bool>,
}

/// Customer, item, procedure, station, dates, place.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identification {
    /// The customer.
    pub customer: Option<String>,
    /// The customer's order reference.
    pub order: Option<String>,
    /// IMU model.
    pub item_model: String,
    /// IMU serial number.
    pub item_serial: String,
    /// IMU grade.
    pub item_grade: String,
    /// Procedure name, version and canonical SHA-256.
    pub procedure: Option<ProcedureId>,
    /// The station: table model, manufacturer, serial, accuracy class.
    pub station: StationId,
    /// The run's id (its folder name) and its archive id.
    pub run: String,
    /// The archive's content address of the run.
    pub archive_id: String,
    /// Date of calibration (YYYY-MM-DD, the run's start).
    pub calibration_date: String,
    /// Date of issue (YYYY-MM-DD).
    pub issue_date: String,
    /// The customer's address (`--customer-address`).
    pub customer_address: Option<String>,
    /// Date of receipt of the item (`--received`, YYYY-MM-DD).
    pub item_received: Option<String>,
    /// Condition of the item on receipt (`--condition`).
    pub item_condition: Option<String>,
    /// Where: the laboratory's address and the site's latitude.
    pub location: String,
}

/// A procedure's identity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProcedureId {
    /// Name.
    pub name: String,
    /// Version.
    pub version: String,
    /// SHA-256 of its canonical text.
    pub sha256: String,
    /// Its title.
    pub title: Option<String>,
}

/// The rate table as the station file names it.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StationId {
    /// The station's name.
    pub name: String,
    /// The table's model.
    pub table_model: String,
    /// Its manufacturer (`not stated` when absent).
    pub manufacturer: Option<String>,
    /// Its serial number.
    pub serial: Option<String>,
    /// Its accuracy class.
    pub accuracy_class: Option<String>,
}

/// What was done and under which conditions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Method {
    /// The procedure's steps in an engineer's words (`title`: what it does).
    pub steps: Vec<String>,
    /// Ambient temperature during the measurement: mean, min, max (degC), when recorded.
    pub temperature_c: Option<[f64; 3]>,
    /// The IMU's own (internal) temperature range during the measurement: min, max
    /// (degC), when recorded.
    pub imu_temperature_c: Option<[f64; 2]>,
    /// The site's gravity, m/s^2, and where the figure comes from.
    pub gravity_mps2: f64,
    /// Its standard uncertainty, when stated.
    pub gravity_u_mps2: Option<f64>,
    /// The gravity's source.
    pub gravity_source: String,
    /// The site's latitude, deg.
    pub latitude_deg: f64,
    /// The latitude's source.
    pub latitude_source: String,
}

/// One calibrated parameter as the certificate states it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResultLine {
    /// As results.json names it.
    pub quantity: String,
    /// Value.
    pub value: f64,
    /// Expanded uncertainty.
    #[serde(rename = "U")]
    pub expanded: f64,
    /// Coverage factor.
    pub k: f64,
    /// Coverage probability (0.95).
    pub p: f64,
    /// Unit.
    pub unit: String,
    /// `value +- U unit (k = 2.05, 95 %)`, rounded to U's two significant digits.
    pub text: String,
}

/// Conformity statements (ILAC-G8).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Conformity {
    /// The decision rule, named.
    pub rule: String,
    /// Each acceptance check.
    pub checks: Vec<ConformityCheck>,
}

/// One acceptance check's statement.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConformityCheck {
    /// The check as written.
    pub name: String,
    /// The value found, when evaluated.
    pub value: Option<f64>,
    /// `<=`, `<`, `>=`, `>`, `within`.
    pub op: String,
    /// Its limit.
    pub limit: f64,
    /// Unit of value, limit and U.
    pub unit: String,
    /// The expanded uncertainty of the value.
    #[serde(rename = "U")]
    pub expanded: Option<f64>,
    /// The coverage factor of `U` (the budget's for a calibrated parameter; 2 for the
    /// run's Type A uncertainty).
    pub k: Option<f64>,
    /// `simple` or `guarded` (ILAC-G8).
    pub rule: String,
    /// The guard band applied (`guarded` rule), in the unit.
    pub guard_band: Option<f64>,
    /// `pass`, `fail`, `indeterminate`, `not_evaluated`...
    pub verdict: String,
    /// The sentence the certificate prints.
    pub statement: String,
}

/// The reference standards and the traceability statement.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Traceability {
    /// The table's own calibration certificate number.
    pub certificate: Option<String>,
    /// Who issued it.
    pub issued_by: Option<String>,
    /// When it is due (YYYY-MM-DD).
    pub due: Option<String>,
    /// The statement printed.
    pub statement: String,
    /// Every reference standard (the table first), stated or not.
    pub references: Vec<ReferenceStandard>,
}

/// The signature block.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ApprovalBlock {
    /// The approver's name.
    pub signer: String,
    /// Role.
    pub role: String,
    /// When approved (RFC 3339).
    pub time: String,
    /// The approver's key fingerprint.
    pub key_fingerprint: String,
}

impl Certificate {
    /// The number as printed: `DRAFT` or `SPECIMEN` when it has none.
    pub fn number_text(&self) -> &str {
        match &self.number {
            Some(n) => n,
            None if self.draft => "DRAFT",
            None => "SPECIMEN",
        }
    }

    /// The markings every page carries: `DRY RUN - SPECIMEN`, `DRAFT - not approved`.
    pub fn markings(&self) -> Vec<&'static str> {
        let mut m = Vec::new();
        if self.specimen {
            m.push(SPECIMEN);
        }
        if self.draft {
            m.push("DRAFT - not approved");
        }
        m
    }
}

/// The marking of a dry run's certificate.
pub const SPECIMEN: &str = "DRY RUN - SPECIMEN";

/// The sentence every certificate ends with.
pub const REPRODUCTION: &str = "This certificate shall not be reproduced except in full \
without the written approval of the laboratory.";

/// What the results are of (ISO/IEC 17025, 7.8.2.1 k).
pub const ITEM_ONLY: &str = "The results relate only to the item calibrated.";

/// The end-of-certificate mark.
pub const END_MARK: &str = "End of certificate";
