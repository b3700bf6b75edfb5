//! A certificate as a sequence of blocks, in its order: each renderer (Markdown, HTML,
//! PDF) walks the same blocks, so the formats hold the same content.

use crate::budget::TermStatus;
use crate::model::{Certificate, END_MARK, ITEM_ONLY, REPRODUCTION};
use crate::units::with_unit;

/// One block of the certificate's body.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// A section heading.
    Heading(String),
    /// A paragraph.
    Para(String),
    /// Label and value pairs.
    Fields(Vec<(String, String)>),
    /// A table: header and rows.
    Table(Vec<String>, Vec<Vec<String>>),
}

/// The page header's lines: lab name, address, accreditation, the number (the page count
/// is the renderer's).
pub fn header(c: &Certificate) -> Vec<String> {
    vec![
        c.lab.name.clone(),
        c.lab.address.replace('\n', ", ").trim().to_string(),
        c.lab.accreditation.clone(),
        format!("Certificate No. {}", c.number_text()),
    ]
}

/// A number as a reader wants it: up to 6 significant digits, no trailing zeros.
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let mag = x.abs().log10().floor() as i32;
    if (-4..6).contains(&mag) {
        let decimals = (5 - mag).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.4e}")
    }
}

fn or_not_stated(v: &Option<String>) -> String {
    v.clone()
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "not stated".into())
}

/// The body's blocks, in the certificate's order.
pub fn blocks(c: &Certificate) -> Vec<Block> {
    let id = &c.identification;
    let mut b = vec![Block::Heading("Calibration certificate".into())];
    b.push(Block::Para(format!("Certificate No. {}", c.number_text())));
    if let Some(r) = &c.replaces {
        b.push(Block::Para(format!(
            "This certificate amends and replaces certificate No. {r}{}.",
            c.amend_reason
                .as_ref()
                .map(|why| format!(" (reason: {why})"))
                .unwrap_or_default()
        )));
    }
    if c.specimen {
        b.push(Block::Para(
            "DRY RUN - SPECIMEN: measured on a simulated station; not a calibration of a real \
             item and not a valid certificate."
                .into(),
        ));
    }
    if c.draft {
        b.push(Block::Para(
            "DRAFT: the results have not been approved (ratecal approve); this is not a valid \
             certificate."
                .into(),
        ));
    }
    b.push(Block::Heading("Identification".into()));
    let proc = id
        .procedure
        .as_ref()
        .map(|p| {
            format!(
                "{} version {}{} (sha256 {})",
                p.name,
                p.version,
                p.title
                    .as_deref()
                    .map(|t| format!(", \"{t}\""))
                    .unwrap_or_default(),
                p.sha256
            )
        })
        .unwrap_or_else(|| "none".into());
    let st = &id.station;
    b.push(Block::Fields(vec![
        ("Customer".into(), or_not_stated(&id.customer)),
        (
            "Customer address".into(),
            or_not_stated(&id.customer_address),
        ),
        ("Order".into(), or_not_stated(&id.order)),
        ("Item".into(), format!("IMU {}", id.item_model)),
        ("Serial number".into(), id.item_serial.clone()),
        ("Grade".into(), id.item_grade.clone()),
        ("Date of receipt".into(), or_not_stated(&id.item_received)),
        (
            "Condition on receipt".into(),
            or_not_stated(&id.item_condition),
        ),
        ("Procedure".into(), proc),
        (
            "Station".into(),
            format!(
                "{}: rate table {}, manufacturer {}, serial {}, accuracy class {}",
                st.name,
                st.table_model,
                or_not_stated(&st.manufacturer),
                or_not_stated(&st.serial),
                or_not_stated(&st.accuracy_class)
            ),
        ),
        (
            "Run".into(),
            format!("{} (archive id {})", id.run, id.archive_id),
        ),
        ("Date of calibration".into(), id.calibration_date.clone()),
        ("Date of issue".into(), id.issue_date.clone()),
        ("Location".into(), id.location.clone()),
    ]));
    let m = &c.method;
    b.push(Block::Heading("Method and conditions".into()));
    let mut steps = String::from("The procedure ran these steps, in order: ");
    steps.push_str(&m.steps.join("; "));
    steps.push('.');
    b.push(Block::Para(steps));
    let temp = m
        .temperature_c
        .map(|[mean, lo, hi]| {
            format!(
                "mean {}, range {} to {}",
                with_unit(&num(mean), "degC"),
                with_unit(&num(lo), "degC"),
                with_unit(&num(hi), "degC")
            )
        })
        .unwrap_or_else(|| "not recorded".into());
    let imu_temp = m
        .imu_temperature_c
        .map(|[lo, hi]| {
            format!(
                "range {} to {}",
                with_unit(&num(lo), "degC"),
                with_unit(&num(hi), "degC")
            )
        })
        .unwrap_or_else(|| "not stated".into());
    b.push(Block::Fields(vec![
        ("Ambient temperature".into(), temp),
        ("IMU temperature".into(), imu_temp),
        (
            "Gravity".into(),
            format!(
                "{}{} (source: {})",
                with_unit(&num(m.gravity_mps2), "m/s^2"),
                m.gravity_u_mps2
                    .map(|u| format!(", standard uncertainty {}", with_unit(&num(u), "m/s^2")))
                    .unwrap_or_else(|| ", uncertainty not stated".into()),
                m.gravity_source
            ),
        ),
        (
            "Latitude".into(),
            format!(
                "{} (source: {})",
                with_unit(&num(m.latitude_deg), "deg"),
                m.latitude_source
            ),
        ),
    ]));
    b.push(Block::Heading("Results".into()));
    b.push(Block::Para(format!(
        "Model: {}",
        c.model_equation.join(". ")
    )));
    b.push(Block::Para(
        "Each result is stated as value ± U, the expanded uncertainty with the coverage factor \
         k for a coverage probability of about 95 % (GUM, JCGM 100:2008)."
            .into(),
    ));
    b.push(Block::Table(
        vec!["Parameter".into(), "Result".into()],
        c.results
            .iter()
            .map(|r| vec![r.quantity.clone(), r.text.clone()])
            .collect(),
    ));
    b.push(Block::Heading("Measurement points".into()));
    if c.measurement_points.is_empty() {
        b.push(Block::Para("Measurement points: not stated.".into()));
    } else {
        b.push(Block::Para(
            "At each attitude and rate point: the reference the table applied on the IMU's \
             principal channel, the IMU's mean raw reading, the error (reading - reference) \
             and its expanded uncertainty U (k = 2: the reading's scatter and the reference's \
             stated uncertainty); consistent when the calibrated model explains the reading \
             within U."
                .into(),
        ));
        b.push(Block::Table(
            [
                "Point",
                "Channel",
                "Reference",
                "Reading",
                "Error",
                "U",
                "Verdict",
            ]
            .map(String::from)
            .to_vec(),
            c.measurement_points
                .iter()
                .map(|p| {
                    vec![
                        format!("{} ({})", p.segment, p.condition),
                        p.channel.clone(),
                        with_unit(&num(p.reference), &p.unit),
                        with_unit(&num(p.reading), &p.unit),
                        with_unit(&num(p.error), &p.unit),
                        with_unit(&num(p.expanded), &p.unit),
                        p.verdict.replace('_', " "),
                    ]
                })
                .collect(),
        ));
    }
    if let Some(conf) = &c.conformity {
        b.push(Block::Heading("Statements of conformity".into()));
        b.push(Block::Para(format!("Decision rule: {}.", conf.rule)));
        b.push(Block::Table(
            ["Check", "Value", "Limit", "U", "Verdict"]
                .map(String::from)
                .to_vec(),
            conf.checks
                .iter()
                .map(|k| {
                    vec![
                        k.name.clone(),
                        k.value
                            .map(|v| with_unit(&num(v), &k.unit))
                            .unwrap_or_else(|| "-".into()),
                        match k.op.as_str() {
                            "within" => format!("within ±{}", with_unit(&num(k.limit), &k.unit)),
                            op => format!("{op} {}", with_unit(&num(k.limit), &k.unit)),
                        },
                        k.expanded
                            .map(|u| with_unit(&num(u), &k.unit))
                            .unwrap_or_else(|| "-".into()),
                        k.statement.clone(),
                    ]
                })
                .collect(),
        ));
    }
    let t = &c.traceability;
    b.push(Block::Heading("Traceability".into()));
    b.push(Block::Table(
        [
            "Reference standard",
            "Certificate",
            "Issued by",
            "Due",
            "Status",
        ]
        .map(String::from)
        .to_vec(),
        t.references
            .iter()
            .map(|r| {
                vec![
                    if r.standard == "rate table" {
                        format!("rate table {}", c.identification.station.table_model)
                    } else {
                        r.standard.clone()
                    },
                    or_not_stated(&r.certificate),
                    or_not_stated(&r.issued_by),
                    r.due
                        .as_ref()
                        .map(|d| format!("due {d}"))
                        .unwrap_or_else(|| "not stated".into()),
                    match r.valid {
                        Some(true) => "in date".into(),
                        Some(false) => "expired".into(),
                        None => "not stated".into(),
                    },
                ]
            })
            .collect(),
    ));
    b.push(Block::Para(t.statement.clone()));
    b.push(Block::Heading("Deviations".into()));
    if c.deviations.is_empty() {
        b.push(Block::Para(
            "None: the run gave no warning and no refusal was overridden.".into(),
        ));
    } else {
        for d in &c.deviations {
            b.push(Block::Para(d.clone()));
        }
    }
    if !c.notes.is_empty() {
        b.push(Block::Heading("Notes".into()));
        for n in &c.notes {
            b.push(Block::Para(n.clone()));
        }
    }
    b.push(Block::Heading("Approval".into()));
    match &c.approval {
        Some(a) => b.push(Block::Fields(vec![
            ("Approved by".into(), a.signer.clone()),
            ("Role".into(), a.role.clone()),
            ("Date".into(), a.time.clone()),
            // A space after the scheme: the hex alone fits a narrow column.
            (
                "Signature key".into(),
                a.key_fingerprint.replacen("SHA256:", "SHA256: ", 1),
            ),
        ])),
        None => b.push(Block::Para("Not approved: DRAFT (no signature).".into())),
    }
    b.push(Block::Heading("Annex: uncertainty budget".into()));
    for bu in &c.budget {
        b.push(Block::Para(format!(
            "{} = {}: u_c = {}, ν_eff = {}, k = {:.2}, U = {}",
            bu.quantity,
            with_unit(&num(bu.value), &bu.unit),
            with_unit(&num(bu.u_c), &bu.unit),
            nu_eff_text(bu.nu_eff),
            bu.k,
            with_unit(&num(bu.expanded), &bu.unit)
        )));
        b.push(Block::Table(
            [
                "Source",
                "Type",
                "Distribution",
                "Stated",
                "Sensitivity",
                "u",
                "dof",
            ]
            .map(String::from)
            .to_vec(),
            bu.terms
                .iter()
                .map(|t| {
                    vec![
                        t.source.clone(),
                        format!("{:?}", t.evaluation),
                        t.distribution.clone(),
                        t.stated
                            .as_deref()
                            .map(crate::units::pretty)
                            .unwrap_or_else(|| "-".into()),
                        crate::units::pretty(&t.sensitivity),
                        match (t.status, t.u) {
                            (TermStatus::Stated, Some(u)) => with_unit(&num(u), &bu.unit),
                            _ => "not stated".into(),
                        },
                        t.dof
                            .map(|d| format!("{d:.0}"))
                            .unwrap_or_else(|| "∞".into()),
                    ]
                })
                .collect(),
        ));
    }
    b.push(Block::Para(ITEM_ONLY.into()));
    b.push(Block::Para(REPRODUCTION.into()));
    b.push(Block::Para(format!("{END_MARK} {}", c.number_text())));
    b
}

/// Effective degrees of freedom as a metrologist writes them: "∞" above 1000 (k no longer
/// depends on them) and when infinite, else to one decimal. The JSON keeps the number.
pub(crate) fn nu_eff_text(nu: Option<f64>) -> String {
    match nu {
        Some(n) if n <= NU_EFF_INFINITE => format!("{n:.1}"),
        _ => "∞".into(),
    }
}

/// Above this many effective degrees of freedom they are printed as infinite.
pub(crate) const NU_EFF_INFINITE: f64 = 1000.0;

#[cfg(test)]
mod nu_eff_tests {
    #[test]
    fn large_degrees_of_freedom_read_as_infinite() {
        assert_eq!(super::nu_eff_text(Some(2527562934.9)), "∞");
        assert_eq!(super::nu_eff_text(Some(1000.0)), "1000.0");
        assert_eq!(super::nu_eff_text(Some(12.34)), "12.3");
        assert_eq!(super::nu_eff_text(None), "∞");
    }
}
