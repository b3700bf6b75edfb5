//! Assembling a certificate from what the CLI read: the run's results, manifest and plan,
//! the station's facts, the laboratory, the number the archive issued, the approval.

use crate::budget::{Budget, COVERAGE};
use crate::conformity::conformity;
use crate::model::{
    ApprovalBlock, Certificate, FORMAT, Identification, Lab, MeasurementPoint, Method, ProcedureId,
    ReferenceStandard, ResultLine, StationId, Traceability,
};
use crate::terms::Stated;
use ratecal_analysis::budget::budgets;
use ratecal_analysis::results::Results;
use ratecal_plan::Plan;
use ratecal_recording::Manifest;

/// Everything a certificate is made of.
pub struct Input<'a> {
    /// The number issued (`PREFIX-YYYY-NNNNNN`); `None` for a draft or a specimen.
    pub number: Option<String>,
    /// The certificate it amends, if any.
    pub replaces: Option<String>,
    /// Why it amends it.
    pub amend_reason: Option<String>,
    /// Date of issue, YYYY-MM-DD.
    pub issue_date: String,
    /// Date of calibration, YYYY-MM-DD: the run's start (an import's: the date of import).
    pub calibration_date: String,
    /// The laboratory.
    pub lab: Lab,
    /// Customer and order reference.
    pub customer: Option<String>,
    /// The customer's order.
    pub order: Option<String>,
    /// The customer's address.
    pub customer_address: Option<String>,
    /// Date of receipt of the item, YYYY-MM-DD.
    pub received: Option<String>,
    /// Condition of the item on receipt.
    pub condition: Option<String>,
    /// The run's results.json.
    pub results: &'a Results,
    /// The run's manifest.
    pub manifest: &'a Manifest,
    /// The run's plan.json, when it has one.
    pub plan: Option<&'a Plan>,
    /// The archive's id of the run.
    pub archive_id: String,
    /// The station's identity.
    pub station: StationId,
    /// The budget's Type B figures.
    pub stated: Stated,
    /// The reference standards, the table first.
    pub references: Vec<ReferenceStandard>,
    /// The measurement points.
    pub points: Vec<MeasurementPoint>,
    /// Notes from refusals overridden (`--allow-expired`, `--allow-untraceable`).
    pub notes: Vec<String>,
    /// The refusals overridden (`--allow-*`), as deviations; the run's warnings join them.
    pub deviations: Vec<String>,
    /// The approval, `None` for a draft.
    pub approval: Option<ApprovalBlock>,
}

/// `value ± U unit (k = 2.05, 95 %)`, `U` to two significant digits and the value to
/// the same decimal place.
pub fn gum_text(value: f64, expanded: f64, k: f64, unit: &str) -> String {
    let decimals = if expanded > 0.0 && expanded.is_finite() {
        (1 - expanded.log10().floor() as i32).max(0) as usize
    } else {
        6
    };
    let u = crate::units::pretty(unit);
    format!(
        "{value:.decimals$} ± {expanded:.decimals$} {u} (k = {k:.2}, {:.0} %)",
        COVERAGE * 100.0
    )
}

/// Builds the certificate.
pub fn build(input: Input<'_>) -> Certificate {
    let r = input.results;
    let m = input.manifest;
    let mut notes = input.notes;
    // The analysis's budgets, which its verdict used; a results file written before the
    // analysis computed them gets them now, and its checks keep the run's Type A U.
    let budgets: Vec<Budget> = if r.budgets.is_empty() {
        if !r.acceptance.is_empty() {
            notes.push(
                "The run was analysed without the station's Type B figures: its statements of \
                 conformity use the fit's Type A uncertainty (k = 2); `ratecal analyze` the \
                 run again to judge with the full budget."
                    .into(),
            );
        }
        budgets(r, &input.stated)
    } else {
        r.budgets.clone()
    };
    let results = budgets
        .iter()
        .map(|b| ResultLine {
            quantity: b.quantity.clone(),
            value: b.value,
            expanded: b.expanded,
            k: b.k,
            p: COVERAGE,
            unit: b.unit.clone(),
            text: gum_text(b.value, b.expanded, b.k, &b.unit),
        })
        .collect();
    let incomplete: Vec<&str> = budgets
        .iter()
        .filter(|b| !b.complete)
        .map(|b| b.quantity.as_str())
        .collect();
    if !incomplete.is_empty() {
        notes.push(format!(
            "The station file does not state every figure the budget needs (terms marked \
             \"not stated\"): the expanded uncertainty of {} covers the stated terms only.",
            incomplete.join(", ")
        ));
    }
    if m.run.as_ref().is_some_and(|run| run.dry_run) {
        notes.push(
            "Measured on the simulated station (a dry run): a specimen, not a calibration of a \
             real item; it takes no certificate number."
                .into(),
        );
    }
    let run = m.run.as_ref();
    let calibration_date = input.calibration_date;
    let procedure = m.procedure.as_ref().map(|p| ProcedureId {
        name: p.name.clone(),
        version: p.version.clone(),
        sha256: p.sha256.clone(),
        title: input.plan.map(|pl| pl.title.clone()),
    });
    let steps = input
        .plan
        .map(|pl| {
            pl.steps
                .iter()
                .map(|s| match &s.title {
                    Some(t) => format!("{t} (step “{}”)", s.name),
                    None => format!("step “{}”", s.name),
                })
                .collect()
        })
        .unwrap_or_default();
    let site = &m.station.site;
    let statements = conformity(r);
    let method = Method {
        steps,
        temperature_c: r
            .environment
            .ambient
            .as_ref()
            .map(|a| [a.mean_c, a.min_c, a.max_c]),
        imu_temperature_c: r.environment.imu_temp_range_c,
        gravity_mps2: site.gravity_mps2,
        gravity_u_mps2: input.stated.gravity_u_mps2,
        gravity_source: "the station file (site.gravity_mps2)".into(),
        latitude_deg: site.latitude_deg,
        latitude_source: "the station file (site.latitude_deg)".into(),
    };
    let statement = statement(&input.references);
    let table = input.references.first();
    let (certificate, issued_by, due) = (
        table.and_then(|t| t.certificate.clone()),
        table.and_then(|t| t.issued_by.clone()),
        table.and_then(|t| t.due.clone()),
    );
    let mut deviations = input.deviations;
    deviations.extend(
        r.warnings
            .iter()
            .map(|w| format!("Warning of the run: {w}")),
    );
    deviations.extend(
        r.sanity
            .iter()
            .filter(|c| c.status == ratecal_analysis::results::SanityStatus::Fail)
            .map(|c| format!("Sanity check {} failed: {}", c.check, c.detail)),
    );
    Certificate {
        format: FORMAT.into(),
        number: input.number,
        replaces: input.replaces,
        amend_reason: input.amend_reason,
        draft: input.approval.is_none(),
        specimen: m.run.as_ref().is_some_and(|run| run.dry_run),
        identification: Identification {
            customer: input.customer,
            order: input.order,
            customer_address: input.customer_address,
            item_received: input.received,
            item_condition: input.condition,
            item_model: m.imu.get("model").cloned().unwrap_or_default(),
            item_serial: m.imu.get("serial").cloned().unwrap_or_default(),
            item_grade: m.imu.get("grade").cloned().unwrap_or_default(),
            procedure,
            station: input.station,
            run: run.map(|r| r.id.clone()).unwrap_or_default(),
            archive_id: input.archive_id,
            calibration_date,
            issue_date: input.issue_date,
            location: format!(
                "{} (latitude {:.4}°)",
                input.lab.address.replace('\n', ", ").trim(),
                site.latitude_deg
            ),
        },
        lab: input.lab,
        method,
        model_equation: equation(r),
        results,
        measurement_points: input.points,
        budget: budgets,
        conformity: statements,
        traceability: Traceability {
            certificate,
            issued_by,
            due,
            statement,
            references: input.references,
        },
        approval: input.approval,
        notes,
        deviations,
    }
}

/// The traceability statement: a claim only through the references in date on the date
/// of calibration, the table's first (without it nothing is claimed).
fn statement(refs: &[ReferenceStandard]) -> String {
    let cite = |r: &ReferenceStandard| {
        format!(
            "the {}'s calibration, certificate {}{}{}",
            r.standard,
            r.certificate.as_deref().unwrap_or_default(),
            r.issued_by
                .as_deref()
                .map(|b| format!(" issued by {b}"))
                .unwrap_or_default(),
            r.due
                .as_deref()
                .map(|d| format!(", due {d}"))
                .unwrap_or_default()
        )
    };
    let Some(table) = refs.first().filter(|t| t.certificate.is_some()) else {
        return "No reference calibration is stated for the rate table: the results are not \
                shown to be traceable."
            .into();
    };
    let expired: Vec<&ReferenceStandard> = refs.iter().filter(|r| r.valid == Some(false)).collect();
    let mut s = if table.valid == Some(false) {
        format!(
            "The rate table's calibration, certificate {}, was due {} before the date of \
             calibration: the results are not shown to be traceable to the SI.",
            table.certificate.as_deref().unwrap_or_default(),
            table.due.as_deref().unwrap_or("not stated")
        )
    } else {
        let through: Vec<String> = refs
            .iter()
            .filter(|r| r.valid == Some(true))
            .map(cite)
            .collect();
        format!(
            "The results are traceable to the SI through {}.",
            through.join("; and through ")
        )
    };
    for r in expired.iter().filter(|r| r.standard != table.standard) {
        s.push_str(&format!(
            " The {}'s calibration, certificate {}, was due {} before the date of \
             calibration: the traceability does not extend through it.",
            r.standard,
            r.certificate.as_deref().unwrap_or_default(),
            r.due.as_deref().unwrap_or("not stated")
        ));
    }
    s
}

/// The model equation the parameters belong to (spec/physics.md).
fn equation(r: &Results) -> Vec<String> {
    let full = r.parameters.keys().any(|n| n.contains(".misalignment."));
    if full {
        vec![
            "a = K_a s + b_a (m/s^2), w = K_g w_ib + b_g (deg/s)".into(),
            "K = I + diag(scale) + misalignment (off-diagonal); b = bias; s, w_ib = the \
             specific force and angular rate the table applies"
                .into(),
        ]
    } else {
        vec![
            "a_i = (1 + scale_i) a_ref,i + bias_i (m/s^2), w_i = (1 + scale_i) w_ref,i + bias_i \
             (deg/s), i = x, y, z"
                .into(),
            "scale in ppm (1e-6); bias = the output at zero input; a_ref, w_ref = the specific \
             force and angular rate the table applies"
                .into(),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_are_rounded_to_two_significant_digits_of_u() {
        assert_eq!(
            gum_text(-653.123, 11.74, 2.048, "ppm"),
            "-653 ± 12 ppm (k = 2.05, 95 %)"
        );
        assert_eq!(
            gum_text(0.0120023, 0.0000371, 1.96, "m/s^2"),
            "0.012002 ± 0.000037 m/s² (k = 1.96, 95 %)"
        );
    }
}
