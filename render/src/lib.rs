//! The render stage: results.json and the run's context (manifest, plan, temperatures) ->
//! report text through minijinja templates. The bundled templates (`templates/` at the
//! workspace root, embedded in the binary) can be overridden file by file by a lab's own
//! template directory. No IO here: the caller reads files and hands their text in.
//!
//! ```
//! use ratecal_render::{Format, ReportInput, Templates, render};
//! let input = ReportInput {
//!     results: serde_json::json!({ "parameters": {}, "acceptance": [] }),
//!     ratecal_version: "0.1.0".into(),
//!     ..ReportInput::default()
//! };
//! let md = render(&input, &Templates::bundled(), Format::Markdown).unwrap();
//! assert!(md.contains("Calibration report"));
//! ```

mod axis;
mod context;
mod error;
pub mod filters;
mod finding;
mod forest;
mod plots;
mod process;
pub mod svg;
mod twin;
mod views;

pub use context::CONTEXT_FORMAT;
pub use error::{RenderError, TemplateError};
pub use finding::{explain_figures, figure};
pub use forest::{across_page, forest};
pub use twin::{twin_figures, twin_residual_figure};

use minijinja::{Environment, UndefinedBehavior, Value};
use ratecal_analysis::fit::Source;
use ratecal_plan::Plan;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Everything a report is made from. Owned, so a caller can build it from files or from a
/// run in memory (`serde_json::to_value(&results)`, `serde_json::to_value(&manifest)`).
#[derive(Debug, Clone, Default)]
pub struct ReportInput {
    /// results.json as JSON (`format`, `parameters`, `acceptance`, ...).
    pub results: serde_json::Value,
    /// manifest.yaml as JSON (all keys, including ones the typed manifest ignores), if any.
    pub manifest: Option<serde_json::Value>,
    /// The checked procedure, for the process description, if known.
    pub plan: Option<Plan>,
    /// Temperature series for the temperature plot and conditions summary.
    pub temperature: TemperatureSeries,
    /// Version of ratecal rendering the report.
    pub ratecal_version: String,
    /// explain.json (`ratecal-explain/1`) when `ratecal explain` was run on the folder.
    pub explain: Option<serde_json::Value>,
    /// The unit's trend across the calibrations the lab's archive holds
    /// (`ratecal archive trend SERIAL --format json`), when an archive is configured and
    /// holds any.
    pub archive_trend: Option<serde_json::Value>,
}

impl ReportInput {
    /// The input for a run in memory, as `ratecal run` has it after the analysis.
    pub fn from_run(
        results: &ratecal_analysis::results::Results,
        manifest: &ratecal_recording::Manifest,
        plan: Option<&Plan>,
        temperature: TemperatureSeries,
        ratecal_version: &str,
    ) -> Self {
        ReportInput {
            results: serde_json::to_value(results).unwrap_or_default(),
            manifest: serde_json::to_value(manifest).ok(),
            plan: plan.cloned(),
            temperature,
            ratecal_version: ratecal_version.to_string(),
            explain: None,
            archive_trend: None,
        }
    }
}

/// Most points a temperature series keeps (the plot needs the shape, not every sample).
pub const TEMPERATURE_POINTS: usize = 2000;

impl TemperatureSeries {
    /// The IMU `temp` column and the table's `ambient` column, thinned to at most
    /// [`TEMPERATURE_POINTS`] each.
    pub fn from_recording(rec: &ratecal_recording::Recording) -> Self {
        let Ok(series) = Self::from_source(rec);
        series
    }

    /// The same from a recording read a window at a time, or only its `t` and `temp` cells
    /// (the kept rows are every n-th of the whole stream, as in memory).
    pub fn from_source<S: Source>(src: &S) -> Result<Self, S::Error> {
        let step = |n: usize| n.div_ceil(TEMPERATURE_POINTS).max(1);
        let imu = src.temp_every(step(src.imu_rows()))?;
        let tab = src.table();
        let ambient = tab
            .ambient
            .as_deref()
            .map(|v| {
                let n = tab.t.len().min(v.len());
                (0..n).step_by(step(n)).map(|i| (tab.t[i], v[i])).collect()
            })
            .unwrap_or_default();
        Ok(TemperatureSeries { imu, ambient })
    }
}

/// Temperature samples `(t, degC)` on the stream clock, thinned or not.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TemperatureSeries {
    /// IMU internal temperature (imu.csv `temp`).
    pub imu: Vec<(f64, f64)>,
    /// Lab ambient temperature (table.csv `ambient`).
    pub ambient: Vec<(f64, f64)>,
}

/// A bundled report format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// `report.md`.
    Markdown,
    /// `report.html`, self-contained with inline SVG plots.
    Html,
}

impl Format {
    /// Template name and output file name (`report.md`, `report.html`).
    pub fn file_name(self) -> &'static str {
        match self {
            Format::Markdown => "report.md",
            Format::Html => "report.html",
        }
    }

    /// Both formats, in the order `ratecal run` writes them.
    pub const ALL: [Format; 2] = [Format::Markdown, Format::Html];
}

/// One template file: its text and the label diagnostics show for it.
#[derive(Debug, Clone, PartialEq)]
pub struct TemplateFile {
    /// Source text.
    pub text: String,
    /// Path as the user knows it (`lab/report.html`, `templates/report.md (bundled)`).
    pub origin: String,
}

/// The template set: bundled templates, overridden by name by a lab's files.
#[derive(Debug, Clone, PartialEq)]
pub struct Templates {
    files: BTreeMap<String, TemplateFile>,
}

const BUNDLED: [(&str, &str); 3] = [
    ("report.md", include_str!("../../templates/report.md")),
    ("report.html", include_str!("../../templates/report.html")),
    ("report.css", include_str!("../../templates/report.css")),
];

impl Templates {
    /// The templates embedded in the binary.
    pub fn bundled() -> Self {
        let files = BUNDLED
            .iter()
            .map(|(n, t)| {
                let f = TemplateFile {
                    text: t.to_string(),
                    origin: format!("templates/{n} (bundled)"),
                };
                (n.to_string(), f)
            })
            .collect();
        Templates { files }
    }

    /// Adds or replaces the template `name` (a lab's file, read by the caller).
    pub fn insert(&mut self, name: &str, text: String, origin: String) {
        self.files
            .insert(name.to_string(), TemplateFile { text, origin });
    }

    /// The template `name`, if known.
    pub fn get(&self, name: &str) -> Option<&TemplateFile> {
        self.files.get(name)
    }

    /// Names of every template, sorted.
    pub fn names(&self) -> Vec<&str> {
        self.files.keys().map(String::as_str).collect()
    }
}

/// A rendered report: the file name it is meant for and its text.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// `report.md`, `report.html`, or the lab template's name.
    pub file_name: String,
    /// Text.
    pub text: String,
}

/// Renders one bundled format (or the lab's override of it).
pub fn render(
    input: &ReportInput,
    templates: &Templates,
    format: Format,
) -> Result<String, RenderError> {
    render_template(input, templates, format.file_name())
}

/// Renders the template `name` from `templates`.
pub fn render_template(
    input: &ReportInput,
    templates: &Templates,
    name: &str,
) -> Result<String, RenderError> {
    let Some(file) = templates.get(name) else {
        return Err(RenderError::NoTemplate {
            name: name.into(),
            available: templates.names().join(", "),
        });
    };
    let env = environment(templates);
    let lookup = |n: &str| templates.get(n).map(|f| (f.origin.clone(), f.text.clone()));
    let fail = |e: minijinja::Error| error::from_minijinja(&e, name, lookup);
    let tmpl = env.get_template(name).map_err(fail)?;
    let text = tmpl.render(context(input, name)).map_err(fail)?;
    if text.trim().is_empty() {
        return Err(RenderError::Empty {
            file: file.origin.clone(),
        });
    }
    Ok(text)
}

/// Renders both formats (`report.md` and `report.html`), as `ratecal run` writes them into
/// the run folder; the caller writes the files.
pub fn render_all(input: &ReportInput, templates: &Templates) -> Result<Vec<Report>, RenderError> {
    Format::ALL
        .iter()
        .map(|f| {
            Ok(Report {
                file_name: f.file_name().into(),
                text: render(input, templates, *f)?,
            })
        })
        .collect()
}

/// The data model a template sees, as JSON, without `plots` and `template` (which hold
/// SVG markup and the template's name). Documented in `docs/report-templates.md`.
pub fn context_json(input: &ReportInput) -> serde_json::Value {
    context::build(input)
}

fn environment(templates: &Templates) -> Environment<'static> {
    let mut env = Environment::new();
    env.set_debug(true);
    // Optional sections may be missing from older or foreign results: `a.b.c` on a missing
    // `a` is undefined (prints nothing, is falsy) rather than an error.
    env.set_undefined_behavior(UndefinedBehavior::Chainable);
    if let Ok(syntax) = minijinja::syntax::SyntaxConfig::builder()
        .trim_blocks(true)
        .lstrip_blocks(true)
        .keep_trailing_newline(true)
        .build()
    {
        env.set_syntax(syntax);
    }
    filters::register(&mut env);
    let files: Arc<BTreeMap<String, String>> = Arc::new(
        templates
            .files
            .iter()
            .map(|(n, f)| (n.clone(), f.text.clone()))
            .collect(),
    );
    env.set_loader(move |name| Ok(files.get(name).cloned()));
    env
}

fn context(input: &ReportInput, template: &str) -> Value {
    let json = context::build(input);
    let mut map: BTreeMap<String, Value> = match json {
        serde_json::Value::Object(m) => m
            .into_iter()
            .map(|(k, v)| (k, Value::from(minijinja::value::Serde(&v))))
            .collect(),
        _ => BTreeMap::new(),
    };
    let plots = plots::draw(input);
    let safe = |s: Option<String>| s.map(Value::from_safe_string).unwrap_or(Value::from(()));
    let mut p: BTreeMap<String, Value> = plots
        .named
        .into_iter()
        .map(|(k, v)| (k.to_string(), safe(v)))
        .collect();
    p.insert(
        "findings".into(),
        Value::from(plots.findings.into_iter().map(safe).collect::<Vec<_>>()),
    );
    p.insert(
        "explain".into(),
        Value::from(plots.explain.into_iter().map(safe).collect::<Vec<_>>()),
    );
    p.insert(
        "twin".into(),
        Value::from(
            plots
                .twin
                .into_iter()
                .map(|s| safe(Some(s)))
                .collect::<Vec<_>>(),
        ),
    );
    map.insert("plots".into(), Value::from(p));
    map.insert("template".into(), Value::from(template));
    Value::from(map)
}
