//! Issuing a certificate of a run folder (`ratecal certificate`): the laboratory's file read
//! and checked, the run's results, manifest, plan and station copy read through the folder
//! reader, the traceability rules applied (the table's calibration stated and not expired on
//! the date of calibration, unless the issuer allows it, which the certificate then says),
//! the number taken from the archive's sequence (the same on reissue, the next with
//! `amend`) and the approval taken from the seal.

use crate::number::{self, Doc};
pub use crate::number::{Format, Issued};
use crate::{ApprovalBlock, Certificate, Input, Lab, ReferenceStandard, StationId, render};
use miette::{Diagnostic, NamedSource, SourceSpan};
use ratecal_analysis::results::Results;
use ratecal_archive::{Archive, Location, days_from_iso};
use ratecal_drivers::Station;
use ratecal_folder::RunFolder;
use std::path::{Path, PathBuf};

/// What a certificate is issued from, and the choices the issuer made.
#[derive(Debug, Clone, Default)]
pub struct Request {
    /// Run folder (sealed, approved, archived).
    pub run_dir: PathBuf,
    /// The laboratory's file.
    pub lab: PathBuf,
    /// The customer, as the certificate names them.
    pub customer: Option<String>,
    /// The customer's order reference.
    pub order: Option<String>,
    /// The customer's address.
    pub customer_address: Option<String>,
    /// Date of receipt of the item, YYYY-MM-DD.
    pub received: Option<String>,
    /// Condition of the item on receipt.
    pub condition: Option<String>,
    /// The archive holding the run and the number sequence.
    pub archive: Option<String>,
    /// An amended certificate: a new number that names the one it replaces.
    pub amend: bool,
    /// Why it is amended (required with `amend`), printed beside the replaced number.
    pub reason: Option<String>,
    /// Issue although the table's calibration had expired (printed).
    pub allow_expired: bool,
    /// Issue although the station states no calibration of the table (printed).
    pub allow_untraceable: bool,
}

/// A refusal located in a YAML file.
#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("{message}")]
#[diagnostic(code(certificate::refused))]
struct Located {
    message: String,
    #[source_code]
    src: NamedSource<String>,
    #[label("{label}")]
    span: SourceSpan,
    label: String,
    #[help]
    help: String,
}

/// The span of `key: value` in YAML `text`, searched after the key `after` (block or flow
/// style): enough to point at a key of a small hand-written file.
fn key_span(text: &str, after: Option<&str>, key: &str) -> SourceSpan {
    let from = after.and_then(|a| find_key(text, 0, a)).unwrap_or(0);
    let Some(start) = find_key(text, from, key) else {
        return (from, 0).into();
    };
    let len = text[start..]
        .find(['\n', ',', '}'])
        .unwrap_or(text.len() - start);
    (start, text[start..start + len].trim_end().len()).into()
}

/// Where `key:` starts at or after byte `from`, as a key (after indentation, `{` or `,`).
fn find_key(text: &str, from: usize, key: &str) -> Option<usize> {
    let pat = format!("{key}:");
    let mut at = from;
    while let Some(i) = text[at..].find(&pat) {
        let s = at + i;
        let before = text[..s].chars().next_back();
        if before.is_none_or(|c| c == ' ' || c == '\n' || c == '{' || c == ',') {
            return Some(s);
        }
        at = s + pat.len();
    }
    None
}

fn io(path: &Path, e: impl std::fmt::Display, help: &str) -> miette::Report {
    miette::miette!(
        code = "certificate::io",
        help = help.to_string(),
        "cannot read {}: {e}",
        path.display()
    )
}

fn read_text(path: &Path, help: &str) -> miette::Result<String> {
    std::fs::read_to_string(path).map_err(|e| io(path, e, help))
}

fn read_lab(path: &Path) -> miette::Result<(Lab, String)> {
    let text = read_text(
        path,
        "give the laboratory's file (docs/examples/lab.yaml shows one)",
    )?;
    let name = path.display().to_string();
    let lab: Lab = serde_saphyr::from_str(&text).map_err(|e| {
        let span = e
            .location()
            .filter(|l| l.line() > 0)
            .map(|l| ratecal_drivers::yaml_offset(&text, l.line(), l.column()))
            .unwrap_or(0);
        Located {
            message: format!("{name} is not a laboratory file"),
            src: NamedSource::new(name.clone(), text.clone()),
            span: (span, 0).into(),
            label: e.to_string().lines().next().unwrap_or("here").to_string(),
            help: "keys: name, address, accreditation, certificate_prefix, signers, \
                   optional logo and template (docs/certificate.md)"
                .into(),
        }
    })?;
    let p = &lab.certificate_prefix;
    if p.is_empty() || !p.chars().all(|c| c.is_ascii_alphanumeric() || c == '-') {
        return Err(Located {
            message: format!("certificate_prefix `{p}` cannot start a certificate number"),
            span: key_span(&text, None, "certificate_prefix"),
            src: NamedSource::new(name, text),
            label: "letters, digits and dashes only".into(),
            help: "e.g. `certificate_prefix: RCL`: numbers read RCL-2026-000001".into(),
        }
        .into());
    }
    if let Some(logo) = &lab.logo {
        let file = path.parent().unwrap_or(Path::new(".")).join(logo);
        if let Err(why) = logo_kind(&file) {
            return Err(Located {
                message: format!("the logo `{logo}` cannot be used"),
                span: key_span(&text, None, "logo"),
                src: NamedSource::new(name, text),
                label: why,
                help: "a PNG or JPEG file, its path relative to the laboratory file; or \
                       remove the key"
                    .into(),
            }
            .into());
        }
    }
    if let Some(template) = &lab.template {
        let file = path.parent().unwrap_or(Path::new(".")).join(template);
        if let Err(e) = std::fs::read_to_string(&file) {
            return Err(Located {
                message: format!("the template `{template}` cannot be read"),
                span: key_span(&text, None, "template"),
                src: NamedSource::new(name, text),
                label: format!("{}: {e}", file.display()),
                help: "a Typst file (UTF-8), its path relative to the laboratory file: copy \
                       certificate/templates/certificate.typ to start; or remove the key"
                    .into(),
            }
            .into());
        }
    }
    Ok((lab, text))
}

/// The template `LAB.yaml` names (its path as the name diagnostics show), else the
/// default one.
pub fn lab_template(lab_file: &Path, lab: &Lab) -> miette::Result<render::Template> {
    let Some(t) = &lab.template else {
        return Ok(render::Template::default());
    };
    let file = lab_file.parent().unwrap_or(Path::new(".")).join(t);
    let text = read_text(&file, "name a Typst file relative to the laboratory file")?;
    Ok(render::Template {
        name: file.display().to_string(),
        text,
    })
}

/// The logo `file`, read and decoded (a PNG or JPEG), or why it cannot be drawn.
fn logo_kind(file: &Path) -> Result<render::Logo, String> {
    let bytes = std::fs::read(file).map_err(|e| format!("{}: {e}", file.display()))?;
    render::Logo::from_bytes(&bytes).map_err(|why| format!("{}: {why}", file.display()))
}

/// The laboratory's logo, when `LAB.yaml` names one (checked by [`read_lab`]).
pub fn lab_logo(lab_file: &Path, lab: &Lab) -> Option<render::Logo> {
    let logo = lab.logo.as_ref()?;
    logo_kind(&lab_file.parent().unwrap_or(Path::new(".")).join(logo)).ok()
}

/// The date (YYYY-MM-DD) of an import, from its manifest's `provenance.imported` (empty
/// when the manifest has none).
fn imported_on(manifest_text: &str) -> String {
    #[derive(serde::Deserialize)]
    struct Provenance {
        imported: String,
    }
    #[derive(serde::Deserialize)]
    struct Imported {
        provenance: Option<Provenance>,
    }
    serde_saphyr::from_str::<Imported>(manifest_text)
        .ok()
        .and_then(|m| m.provenance)
        .map(|p| p.imported.chars().take(10).collect())
        .unwrap_or_default()
}

/// Issues the certificate of `args.run_dir` in `format`: a draft or a dry run's specimen
/// without a number; otherwise the run's number when the content is the one issued under
/// it, a new number (in the transaction that records the document) for a first issue or an
/// amendment. `deliver` is handed the document before its number is recorded (to write it
/// aside); an error from it releases the number.
pub async fn issue(
    args: &Request,
    format: Format,
    deliver: &mut dyn FnMut(&Certificate, &[u8]) -> miette::Result<()>,
) -> miette::Result<Issued> {
    let dir = &args.run_dir;
    if let Some(d) = &args.received
        && days_from_iso(d).is_none()
    {
        return Err(miette::miette!(
            code = "certificate::received",
            help = "give the date the item was received as YYYY-MM-DD: --received 2026-11-20",
            "--received `{d}` is not a date"
        ));
    }
    let (lab, lab_text) = read_lab(&args.lab)?;
    let run = RunFolder::new(dir);
    let results: Results = run.results()?;
    let (manifest_text, manifest) = run.manifest("give the folder `ratecal run` wrote")?;
    let plan = run.plan();
    // An imported recording (no `run` in its manifest) has a station file only when
    // `ratecal import --station` copied one in.
    let imported = manifest.run.is_none();
    if imported && !run.path(ratecal_folder::names::STATION).exists() {
        return Err(miette::miette!(
            code = "certificate::no_station",
            help = format!(
                "import the recording again with the station it was measured on: `ratecal \
                 import ... --station S.yaml --out {}` copies the station file into the \
                 folder and seals it (its table's calibration and Type B figures); then \
                 analyze, approve and archive it",
                ratecal_folder::shell::quoted(dir)
            ),
            "{} is an imported recording without a station file: its traceability and \
             uncertainty budget cannot be stated",
            dir.display()
        ));
    }
    let (station_name, station_text) = run.station_text()?;
    let station =
        Station::from_yaml(&station_text, &station_name).map_err(|e| miette::Report::new(*e))?;
    let mut notes = Vec::new();
    let calibration_date: String = match &manifest.run {
        Some(r) => r.started.chars().take(10).collect(),
        None => {
            let date = imported_on(&manifest_text);
            notes.push(format!(
                "An imported recording (ratecal import): it states no date of measurement, so \
                 the date of calibration is the date of its import, {date}."
            ));
            date
        }
    };
    let located =
        |message: String, after: Option<&str>, key: &str, label: &str, help: &str| Located {
            message,
            span: key_span(&station_text, after, key),
            src: NamedSource::new(station_name.clone(), station_text.clone()),
            label: label.into(),
            help: help.into(),
        };
    let cal = station.table.calibration.clone();
    let mut deviations = Vec::new();
    if cal.is_none() {
        if !args.allow_untraceable {
            return Err(located(
                "the station states no calibration of the rate table: the results would not be traceable".into(),
                None,
                "table",
                "no `calibration: { certificate, issued_by, due }` here",
                "state the table's calibration certificate in the station file, or give \
                 --allow-untraceable (printed on the certificate)",
            )
            .into());
        }
        let note = "Issued with --allow-untraceable: the station states no calibration of the \
                    rate table; the results are not shown to be traceable.";
        notes.push(note.to_string());
        deviations.push(note.to_string());
    }
    // Every reference standard, the table first: its calibration in date on the date of
    // calibration, unless the issuer allows it (printed, and no claim through it).
    let r = &station.references;
    let stated = [
        ("rate table", "calibration", cal),
        ("DAQ timebase", "daq_timebase", r.daq_timebase.clone()),
        ("gravity survey", "gravity_survey", r.gravity_survey.clone()),
        ("thermometer", "thermometer", r.thermometer.clone()),
    ];
    let mut references = Vec::new();
    for (standard, key, c) in stated {
        let Some(c) = c else {
            references.push(ReferenceStandard {
                standard: standard.into(),
                certificate: None,
                issued_by: None,
                due: None,
                valid: None,
            });
            continue;
        };
        let expired = match (days_from_iso(&c.due), days_from_iso(&calibration_date)) {
            (Some(d), Some(o)) => o > d,
            _ => true,
        };
        if expired && !args.allow_expired {
            return Err(located(
                format!(
                    "the {standard}'s calibration ({}) was due {}, before the calibration date {calibration_date}",
                    c.certificate, c.due
                ),
                Some(key),
                "due",
                "expired on the date of calibration",
                &format!(
                    "recalibrate the {standard} and state its new certificate, or give \
                     --allow-expired (printed on the certificate)"
                ),
            )
            .into());
        }
        if expired {
            let note = format!(
                "Issued with --allow-expired: the {standard}'s calibration {} was due {}, \
                 before the date of calibration.",
                c.certificate, c.due
            );
            notes.push(note.clone());
            deviations.push(note);
        }
        references.push(ReferenceStandard {
            standard: standard.into(),
            certificate: Some(c.certificate),
            issued_by: Some(c.issued_by),
            due: Some(c.due),
            valid: Some(!expired),
        });
    }
    // The archive must hold this very folder (its content address).
    let folder = ratecal_archive::read_folder(dir)?;
    let loc = Location::resolve(args.archive.as_deref(), None);
    let archive = Archive::open_existing(&loc).await?;
    if !archive.exists(&folder.facts.id).await? {
        return Err(miette::miette!(
            code = "certificate::not_archived",
            help = format!(
                "add it first: `ratecal archive add {}` (after `ratecal approve`)",
                ratecal_folder::shell::quoted(dir)
            ),
            "{} (archive id {}) is not in the archive {}",
            dir.display(),
            folder.facts.id,
            archive.location()
        ));
    }
    let approval = run.seal().and_then(|s| s.approval).map(|a| ApprovalBlock {
        signer: a.signer,
        role: a.role,
        time: a.time,
        key_fingerprint: a.key_fingerprint,
    });
    if let Some(a) = &approval {
        crate::signers::authorised(&args.lab, &lab_text, &lab, a)?;
    }
    let t = &station.table;
    let template = lab_template(&args.lab, &lab)?;
    let logo = lab_logo(&args.lab, &lab);
    let stated = crate::stated(&station, manifest.station.site.gravity_mps2);
    let input = Input {
        number: None,
        replaces: None,
        amend_reason: None,
        issue_date: String::new(),
        calibration_date: calibration_date.clone(),
        lab,
        customer: args.customer.clone(),
        order: args.order.clone(),
        customer_address: args.customer_address.clone(),
        received: args.received.clone(),
        condition: args.condition.clone(),
        results: &results,
        manifest: &manifest,
        plan: plan.as_ref(),
        archive_id: folder.facts.id.clone(),
        station: StationId {
            name: station.name.clone(),
            table_model: t.model.clone(),
            manufacturer: t.manufacturer.clone(),
            serial: t.serial.clone(),
            accuracy_class: t.accuracy_class.clone(),
        },
        points: crate::points::points(dir, &manifest, &results, &stated),
        stated,
        references,
        notes,
        deviations,
        approval,
    };
    let doc = Doc {
        base: crate::build(input),
        template,
        logo,
        format,
    };
    let issued = number::issue(&archive, args, &folder.facts.id, &doc, deliver).await;
    archive.close().await;
    issued
}
