//! `check`: from the AST to a [`Plan`], reporting every error at once.
//!
//! The checker resolves parameters and imports, converts every quantity to its internal
//! unit and checks its dimension, expands `for` loops over explicit lists (refusing a nest
//! whose expansion would exceed [`MAX_EXPANDED_ACTIONS`], computed before expanding), keeps
//! `repeat N` as a node, checks names (with did-you-mean), duplicates, station limits and
//! the observability of every fitted parameter, and estimates the duration.
//!
//! Diagnostic codes (stable): `syntax::unexpected`, `check::unknown_name`,
//! `check::unknown_unit`, `check::unit_mismatch`, `check::missing_unit`,
//! `check::type_mismatch`, `check::bad_number`, `check::bad_count`,
//! `check::duplicate_step`, `check::duplicate_segment`, `check::duplicate_param`,
//! `check::segment_in_repeat`, `check::bad_segment_name`, `check::no_segment`,
//! `check::loop_arity`, `check::expansion_too_large`, `check::unobservable`,
//! `check::station_limit`, `check::manual_station`, `check::no_rest`, `check::import`, `check::structure`, `check::missing_runs`,
//! `check::unsettled` (a static acquisition the table may not be settled for, against the
//! attitude abort rules); warning `check::imu_class` (the station's IMU is of a lower
//! grade than `imu class` asks for).

mod accept;
mod header;
mod manual;
mod motion;
mod observe;
mod registry;
mod segments;
mod steps;
mod values;

use ratecal_grammar::ast::{File, Param, ProcItem, Span, TopItem};
use ratecal_grammar::{Diagnostic, Source};
use ratecal_physics::{Geometry, Mat3};
use ratecal_plan::{Plan, Step};
use std::collections::{BTreeMap, HashMap};
use values::RVal;

pub use registry::EffectObservability;
pub use steps::{DEFAULT_MAX_ACCEL_DPS2, DEFAULT_MAX_RATE_DPS};

/// Largest number of actions a nest of `for` loops may expand to.
pub const MAX_EXPANDED_ACTIONS: u64 = 100_000;

/// Where imported files come from: the engine never opens files itself.
pub trait Sources {
    /// Loads `name` as imported by the file displayed as `from`; returns the imported
    /// file's display name and text, or a message saying why it cannot be read.
    fn load(&self, from: &str, name: &str) -> Result<(String, String), String>;
}

/// Sources for self-contained procedures: every import is refused.
pub struct NoImports;

impl Sources for NoImports {
    fn load(&self, _from: &str, name: &str) -> Result<(String, String), String> {
        Err(format!("imports are not available here (`{name}`)"))
    }
}

/// Station and IMU limits the procedure must respect (from a station file).
#[derive(Debug, Clone, PartialEq)]
pub struct StationLimits {
    /// Largest table rate, deg/s.
    pub max_rate_dps: f64,
    /// Largest table angular acceleration, deg/s^2.
    pub max_accel_dps2: f64,
    /// IMU gyro range, deg/s.
    pub gyro_range_dps: f64,
    /// IMU accelerometer range, m/s^2.
    pub accel_range_mps2: f64,
    /// Table and mount geometry.
    pub geometry: Geometry,
    /// Whether the station's table is the operator (`table.driver: manual`): `place` and
    /// `turn` instead of `move` and `spin`.
    pub manual: bool,
    /// Travel of the outer and inner axes, deg (lowest, highest); `None`: the axis turns
    /// without end.
    pub travel_deg: [Option<(f64, f64)>; 2],
    /// The grade of the station's IMU (`tactical`), empty when the station does not say.
    pub imu_grade: String,
}

/// Options of a check.
#[derive(Debug, Clone, Default)]
pub struct CheckOptions {
    /// Station limits, when a station is given.
    pub station: Option<StationLimits>,
}

/// A checked procedure and the warnings found on the way.
#[derive(Debug, Clone)]
pub struct Checked {
    /// The plan.
    pub plan: Plan,
    /// Warnings (the procedure is accepted).
    pub warnings: Vec<Diagnostic>,
    /// The signals at the procedure's sampled instants, from which
    /// [`Checked::observability`] is worked out when it is asked for.
    signals: Vec<ratecal_physics::Signals>,
    observability: std::sync::OnceLock<Vec<EffectObservability>>,
}

impl Checked {
    /// What the procedure's motion lets explain determine of each registry effect that is
    /// not part of the nominal model (worked out on the first call: a run does not ask).
    pub fn observability(&self) -> &[EffectObservability] {
        self.observability
            .get_or_init(|| registry::observe(&self.signals))
    }
}

/// Parses and checks a procedure text; `name` is how diagnostics name the file.
/// Returns the plan and warnings, or every diagnostic (errors and warnings) found.
pub fn check_text(
    name: &str,
    text: &str,
    sources: &dyn Sources,
    opts: &CheckOptions,
) -> Result<Checked, Vec<Diagnostic>> {
    let src = ratecal_grammar::source(name, text);
    let file = ratecal_grammar::parse(text).map_err(|d| vec![d.with_source(&src)])?;
    check(&file, &src, sources, opts)
}

/// Checks a parsed file whose text is `src`.
pub fn check(
    file: &File,
    src: &Source,
    sources: &dyn Sources,
    opts: &CheckOptions,
) -> Result<Checked, Vec<Diagnostic>> {
    let mut ck = Ck::new(src.clone(), sources, opts);
    let plan = ck.file(file);
    let signals = ck.sample_signals(&ck.walk.segments);
    let mut diags = std::mem::take(&mut ck.diags);
    dedup(&mut diags);
    match plan {
        Some(plan) if !diags.iter().any(Diagnostic::is_error) => Ok(Checked {
            plan,
            warnings: diags,
            signals,
            observability: Default::default(),
        }),
        _ => {
            if !diags.iter().any(Diagnostic::is_error) {
                diags.push(
                    Diagnostic::error("check::internal", "the checker could not build a plan")
                        .with_source(src),
                );
            }
            Err(diags)
        }
    }
}

fn dedup(diags: &mut Vec<Diagnostic>) {
    let mut seen = std::collections::HashSet::new();
    diags.retain(|d| seen.insert((d.code, d.message.clone(), d.labels.first().map(|l| l.0))));
}

/// The checker's state while it walks one procedure.
pub(crate) struct Ck<'a> {
    src: Source,
    sources: &'a dyn Sources,
    pub(crate) diags: Vec<Diagnostic>,
    /// Parameters: value and whether it came from an imported file.
    pub(crate) params: HashMap<String, (RVal, bool)>,
    /// Loop variables, innermost last.
    pub(crate) scopes: Vec<Vec<(String, RVal)>>,
    pub(crate) station: Option<StationLimits>,
    pub(crate) geometry: Geometry,
    pub(crate) walk: steps::Walk,
    /// Checks on calibrated parameters, matched against the fits at the end.
    pub(crate) fitted_checks: Vec<accept::FittedCheck>,
    import_stack: Vec<String>,
}

impl<'a> Ck<'a> {
    fn new(src: Source, sources: &'a dyn Sources, opts: &CheckOptions) -> Self {
        let geometry = opts
            .station
            .as_ref()
            .map_or_else(Geometry::seed, |s| s.geometry);
        let max_list_len = src.inner().matches(',').count() as u64 + 1;
        Ck {
            src,
            sources,
            diags: Vec::new(),
            params: HashMap::new(),
            scopes: Vec::new(),
            station: opts.station.clone(),
            geometry,
            // A bound on any list's length (for `for` loops over loop variables).
            walk: steps::Walk {
                max_list_len,
                ..Default::default()
            },
            fitted_checks: Vec::new(),
            import_stack: Vec::new(),
        }
    }

    /// Records a diagnostic in the current file.
    pub(crate) fn err(&mut self, d: Diagnostic) {
        let d = d.with_source(&self.src);
        self.diags.push(d);
    }

    fn file(&mut self, file: &File) -> Option<Plan> {
        let mut procs = Vec::new();
        for item in &file.body.items {
            match &item.node {
                TopItem::Import(name) => self.import(&name.node, name.span),
                TopItem::Param(p) => self.param(p, false),
                TopItem::Procedure(p) => procs.push((p, item.span)),
            }
        }
        let Some(&(proc_, _)) = procs.first() else {
            self.err(
                Diagnostic::error("check::structure", "no procedure in this file")
                    .label(Span::new(0, 0), "expected `procedure <name> version <x.y.z> { ... }`")
                    .help("a procedure file holds one `procedure` block; definitions-only files are imported"),
            );
            return None;
        };
        for (_, span) in procs.iter().skip(1) {
            self.err(
                Diagnostic::error("check::structure", "more than one procedure in this file")
                    .label(*span, "second procedure")
                    .help("keep one procedure per file (one file per version)"),
            );
        }
        let mut plan = Plan {
            name: proc_.name.node.clone(),
            version: proc_.version.node.clone(),
            title: String::new(),
            references: Vec::new(),
            imu_class: None,
            meta: BTreeMap::new(),
            requirements: Vec::new(),
            environment: Vec::new(),
            aborts: Vec::new(),
            steps: Vec::new(),
            fits: Vec::new(),
            accepts: Vec::new(),
            verifications: Vec::new(),
            estimated_duration_s: 0.0,
        };
        // Parameters and geometry first: they may be used before the line defining them.
        for item in &proc_.body.items {
            match &item.node {
                ProcItem::Param(p) => self.param(p, false),
                ProcItem::Geometry(g) => self.geometry_item(g, &mut plan),
                _ => {}
            }
        }
        let mut step_names: HashMap<String, Span> = HashMap::new();
        for item in &proc_.body.items {
            match &item.node {
                ProcItem::Step(s) => {
                    if let Some(first) = step_names.get(&s.name.node) {
                        let first = *first;
                        self.err(
                            Diagnostic::error(
                                "check::duplicate_step",
                                format!("step `{}` is defined twice", s.name.node),
                            )
                            .label(s.name.span, "second definition")
                            .label(first, "first defined here")
                            .help("give each step its own name"),
                        );
                    }
                    step_names.insert(s.name.node.clone(), s.name.span);
                    let step: Step = self.step(s, &mut plan);
                    plan.steps.push(step);
                }
                other => self.header_item(other, &mut plan),
            }
        }
        self.finish_segments();
        self.fitted_against_model(&plan);
        self.observability(&plan);
        self.settles_against_aborts(&plan);
        plan.estimated_duration_s = plan.steps.iter().map(|s| s.estimated_duration_s).sum();
        Some(plan)
    }

    fn param(&mut self, p: &Param, imported: bool) {
        // A procedure may override an imported definition, not one of its own.
        if !imported
            && self
                .params
                .get(&p.name.node)
                .is_some_and(|(_, was_imported)| !was_imported)
        {
            self.err(
                Diagnostic::error(
                    "check::duplicate_param",
                    format!("parameter `{}` is defined twice", p.name.node),
                )
                .label(p.name.span, "defined again here")
                .help("give each parameter its own name"),
            );
            return;
        }
        if let Some(v) = self.resolve(&p.value, None) {
            self.params.insert(p.name.node.clone(), (v, imported));
        }
    }

    fn import(&mut self, name: &str, span: Span) {
        let from = self.src.name().to_string();
        if self.import_stack.iter().any(|n| n == name) || self.import_stack.len() > 16 {
            self.err(
                Diagnostic::error("check::import", format!("`{name}` imports itself"))
                    .label(span, "circular import")
                    .help("remove one of the imports in the cycle"),
            );
            return;
        }
        let (disp, text) = match self.sources.load(&from, name) {
            Ok(x) => x,
            Err(why) => {
                self.err(
                    Diagnostic::error("check::import", format!("cannot import `{name}`"))
                        .label(span, why)
                        .help("imports are resolved relative to the importing file"),
                );
                return;
            }
        };
        let sub = ratecal_grammar::source(&disp, &text);
        let file = match ratecal_grammar::parse(&text) {
            Ok(f) => f,
            Err(d) => {
                self.diags.push(d.with_source(&sub));
                return;
            }
        };
        let saved = std::mem::replace(&mut self.src, sub);
        self.import_stack.push(name.to_string());
        for item in &file.body.items {
            match &item.node {
                TopItem::Import(n) => self.import(&n.node, n.span),
                TopItem::Param(p) => self.param(p, true),
                TopItem::Procedure(p) => self.err(
                    Diagnostic::error(
                        "check::import",
                        "an imported file may not define a procedure",
                    )
                    .label(p.name.span, "procedure in an imported file")
                    .help("imported files hold `param` definitions only"),
                ),
            }
        }
        self.import_stack.pop();
        self.src = saved;
    }

    fn geometry_item(&mut self, g: &ratecal_grammar::ast::Ident, plan: &mut Plan) {
        let geo = match g.node.as_str() {
            "seed" => Geometry::seed(),
            "vertical_outer" => Geometry::vertical_outer(),
            other => {
                self.err(
                    Diagnostic::error(
                        "check::unknown_name",
                        format!("unknown table geometry `{other}`"),
                    )
                    .label(g.span, "not a geometry")
                    .help(values::suggest(other, &["seed", "vertical_outer"])),
                );
                return;
            }
        };
        if let Some(st) = &self.station {
            let same = (st.geometry.outer_axis - geo.outer_axis).norm() < 1e-6
                && (st.geometry.inner_axis - geo.inner_axis).norm() < 1e-6;
            if !same {
                self.err(
                    Diagnostic::error(
                        "check::station_limit",
                        format!(
                            "the station's table axes do not match geometry `{}`",
                            g.node
                        ),
                    )
                    .label(g.span, "the procedure needs this geometry")
                    .help("run it on a station with that axis layout"),
                );
            }
        } else {
            self.geometry = geo;
        }
        plan.meta.insert("geometry".to_string(), g.node.clone());
    }
}

/// The mount rotation `C_PB` that brings body axis `axis` (0 = x) up along platform Z,
/// keeping a right-handed cyclic order of the axes.
pub(crate) fn mount_up(axis: usize) -> Mat3 {
    match axis {
        // columns are the body axes in P: x up -> X_b = Z_p, Y_b = X_p, Z_b = Y_p
        0 => Mat3::new(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0),
        1 => Mat3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0),
        _ => Mat3::identity(),
    }
}
