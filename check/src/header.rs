//! Procedure-level entries: header, requirements, environment, abort rules, acceptance,
//! verification points and fit statements.

use super::Ck;
use super::steps::FitCheck;
use super::values::{did_you_mean, suggest};
use ratecal_grammar::ast::{self, Cond, EnvBound, ProcItem, Span};
use ratecal_grammar::{Diagnostic, format_abort};
use ratecal_plan::derived::parameter_dim;
use ratecal_plan::{
    AbortAction, AbortCondition, AbortRule, Accept, Axis, Cmp, DecisionRule, Dim, EnvCondition,
    FitModel, FitSpec, Outliers, Plan, Quantity, Requirement, Signal, Verification, VerifyPoint,
};

/// Requirement names per subject, with their dimension.
const REQUIREMENTS: &[(&str, &str, Dim)] = &[
    ("table", "position_accuracy", Dim::Angle),
    ("table", "perpendicularity", Dim::Angle),
    ("table", "levelness", Dim::Angle),
    ("table", "rate_stability", Dim::Rate),
    ("table", "rate_accuracy", Dim::Rate),
    ("table", "max_rate", Dim::Rate),
    ("imu", "warm_up", Dim::Time),
    ("imu", "alignment", Dim::Angle),
    ("daq", "sample_rate", Dim::Frequency),
    ("daq", "resolution", Dim::Number),
    ("daq", "sync_error", Dim::Time),
    ("power", "voltage_stability", Dim::Ratio),
];

/// Environment conditions and their dimension.
const ENVIRONMENT: &[(&str, Dim)] = &[
    ("temperature", Dim::Temperature),
    ("temperature_drift", Dim::TemperatureRate),
    ("humidity", Dim::Ratio),
    ("pressure", Dim::Pressure),
    ("vibration", Dim::Accel),
];

/// Live signals abort rules may watch.
const SIGNALS: &[(&str, Signal, Dim)] = &[
    ("table.attitude_error", Signal::AttitudeError, Dim::Angle),
    ("table.rate_error", Signal::RateError, Dim::Rate),
    (
        "ambient.temperature",
        Signal::AmbientTemperature,
        Dim::Temperature,
    ),
    ("ambient.drift", Signal::AmbientDrift, Dim::TemperatureRate),
    ("imu.temperature", Signal::ImuTemperature, Dim::Temperature),
    ("accel", Signal::Accel, Dim::Accel),
    ("gyro", Signal::Gyro, Dim::Rate),
];

/// Quantities acceptance and verification limits may name.
pub(super) const ACCEPTS: &[(&str, Dim)] = &[
    ("accel.residual.std", Dim::Accel),
    ("accel.residual.mean", Dim::Accel),
    ("accel.error", Dim::Accel),
    ("gyro.residual.std", Dim::Rate),
    ("gyro.residual.mean", Dim::Rate),
    ("gyro.error", Dim::Rate),
    ("gyro.bias.std", Dim::Rate),
    ("gyro.noise.std", Dim::Rate),
    ("repeatability.cv", Dim::Ratio),
];

/// Quantities the language once named that no fit computes: a check on one could never be
/// evaluated, so it is refused here rather than leaving every run incomplete.
pub(super) const NOT_COMPUTED: &[(&str, &str)] = &[("size_effect.uncertainty", "accel.error")];

/// Fit models: (sensor, model word) -> model.
const MODELS: &[(&str, &str, FitModel)] = &[
    ("accel", "bias_scale", FitModel::AccelBiasScale),
    ("accel", "full", FitModel::AccelFull),
    ("gyro", "bias", FitModel::GyroBias),
    ("gyro", "scale", FitModel::GyroScale),
    ("gyro", "full", FitModel::GyroFull),
    ("gyro", "allan", FitModel::Allan),
    ("temperature", "compensation", FitModel::TempCompensation),
    ("size_effect", "", FitModel::SizeEffect),
];

pub(super) fn cmp(c: ast::Cmp) -> Cmp {
    match c {
        ast::Cmp::Le => Cmp::Le,
        ast::Cmp::Lt => Cmp::Lt,
        ast::Cmp::Ge => Cmp::Ge,
        ast::Cmp::Gt => Cmp::Gt,
    }
}

impl Ck<'_> {
    pub(crate) fn header_item(&mut self, item: &ProcItem, plan: &mut Plan) {
        match item {
            ProcItem::Title(t) => plan.title = t.node.clone(),
            ProcItem::ImuClass(c) => {
                self.imu_class(c);
                plan.imu_class = Some(c.node.clone());
            }
            ProcItem::Reference(r) => plan.references.push(r.node.clone()),
            ProcItem::Meta(k, v) => {
                plan.meta.insert(k.node.clone(), v.node.clone());
            }
            ProcItem::Param(_) | ProcItem::Geometry(_) | ProcItem::Step(_) => {}
            ProcItem::Requires { subject, body } => {
                for l in &body.items {
                    self.requirement(subject, &l.node, plan);
                }
            }
            ProcItem::Environment(b) => {
                for e in &b.items {
                    if let Some(c) = self.env(&e.node) {
                        plan.environment.push(c);
                    }
                }
            }
            ProcItem::Abort(a) => {
                if let Some(r) = self.abort(a) {
                    plan.aborts.push(r);
                }
            }
            ProcItem::Accept(a) => {
                if let Some(a) = self.accept(a, None) {
                    plan.accepts.push(a);
                }
            }
            ProcItem::Verify(v) => {
                if let Some(v) = self.verify(v) {
                    plan.verifications.push(v);
                }
            }
        }
    }

    fn requirement(&mut self, subject: &ast::Ident, l: &ast::Limit, plan: &mut Plan) {
        let subjects = ["table", "imu", "daq", "power"];
        if !subjects.contains(&subject.node.as_str()) {
            self.err(
                Diagnostic::error(
                    "check::unknown_name",
                    format!("unknown requirement subject `{}`", subject.node),
                )
                .label(subject.span, "not a subject")
                .help(suggest(&subject.node, &subjects)),
            );
            return;
        }
        let names: Vec<&str> = REQUIREMENTS
            .iter()
            .filter(|r| r.0 == subject.node)
            .map(|r| r.1)
            .collect();
        let Some(&(_, name, dim)) = REQUIREMENTS
            .iter()
            .find(|r| r.0 == subject.node && r.1 == l.name.node)
        else {
            self.err(
                Diagnostic::error(
                    "check::unknown_name",
                    format!("unknown {} requirement `{}`", subject.node, l.name.node),
                )
                .label(l.name.span, "not a requirement ratecal knows")
                .help(suggest(&l.name.node, &names)),
            );
            return;
        };
        if let Some(q) = self.quantity(&l.value, dim, "this requirement") {
            plan.requirements.push(Requirement {
                name: format!("{}.{name}", subject.node),
                op: cmp(l.op.node),
                limit: q,
            });
        }
    }

    fn env(&mut self, e: &ast::EnvItem) -> Option<EnvCondition> {
        let names: Vec<&str> = ENVIRONMENT.iter().map(|x| x.0).collect();
        let Some(&(name, dim)) = ENVIRONMENT.iter().find(|x| x.0 == e.name.node) else {
            self.err(
                Diagnostic::error(
                    "check::unknown_name",
                    format!("unknown environment condition `{}`", e.name.node),
                )
                .label(e.name.span, "not a condition ratecal knows")
                .help(suggest(&e.name.node, &names)),
            );
            return None;
        };
        let (min, max) = match &e.bound {
            EnvBound::Cmp(op, v) => {
                let q = self.quantity(v, dim, "this condition")?;
                match op.node {
                    ast::Cmp::Le | ast::Cmp::Lt => (None, Some(q)),
                    _ => (Some(q), None),
                }
            }
            EnvBound::Range(a, b) => {
                let lo = self.quantity(a, dim, "the lower end");
                let hi = self.quantity(b, dim, "the upper end");
                (Some(lo?), Some(hi?))
            }
            EnvBound::Tol(a, b) => {
                let c = self.quantity(a, dim, "the nominal value");
                let t = self.tolerance(b, dim);
                let (c, t) = (c?, t?);
                let at = |written: f64, value: f64| Quantity {
                    written,
                    unit: c.unit.clone(),
                    dim,
                    value,
                };
                // The band is written in the nominal value's unit.
                let tw = t.value / ratecal_physics::units::unit(&c.unit).map_or(1.0, |u| u.1);
                (
                    Some(at(c.written - tw, c.value - t.value)),
                    Some(at(c.written + tw, c.value + t.value)),
                )
            }
        };
        Some(EnvCondition {
            name: name.to_string(),
            min,
            max,
        })
    }

    /// A tolerance or difference: a temperature in K is a difference here, not absolute.
    fn tolerance(&mut self, v: &ast::Value, dim: Dim) -> Option<Quantity> {
        let mut q = self.quantity(v, dim, "a tolerance")?;
        if q.unit == "K" {
            q.value = q.written;
        }
        Some(q)
    }

    fn signal(&mut self, path: &ast::Ident) -> Option<(Signal, Dim)> {
        match SIGNALS.iter().find(|s| s.0 == path.node) {
            Some(&(_, s, d)) => Some((s, d)),
            None => {
                let mut names: Vec<&str> = SIGNALS.iter().map(|s| s.0).collect();
                names.push("imu.output (abnormal)");
                self.err(
                    Diagnostic::error(
                        "check::unknown_name",
                        format!("unknown signal `{}`", path.node),
                    )
                    .label(path.span, "not a live signal")
                    .help(suggest(&path.node, &names)),
                );
                None
            }
        }
    }

    pub(crate) fn abort(&mut self, a: &ast::Abort) -> Option<AbortRule> {
        let mut unit = String::new();
        let condition = match &a.cond {
            Cond::Cmp(p, op, v) => {
                let (signal, dim) = self.signal(p)?;
                if matches!(op.node, ast::Cmp::Lt | ast::Cmp::Le) {
                    self.err(
                        Diagnostic::error("check::structure", "abort rules fire above a limit")
                            .label(op.span, "use `>` (or `outside lo .. hi`)")
                            .help("write `abort when signal > limit` or `abort when signal outside lo .. hi`"),
                    );
                    return None;
                }
                let q = self.quantity(v, dim, "an abort limit")?;
                unit = q.unit;
                AbortCondition::Above {
                    signal,
                    limit: q.value,
                }
            }
            Cond::Outside(p, lo, hi) => {
                let (signal, dim) = self.signal(p)?;
                let lo = self.quantity(lo, dim, "the lower end");
                let hi = self.quantity(hi, dim, "the upper end");
                let (lo, hi) = (lo?, hi?);
                if lo.unit == hi.unit {
                    unit = lo.unit;
                }
                AbortCondition::Outside {
                    signal,
                    lo: lo.value,
                    hi: hi.value,
                }
            }
            Cond::Drifts(p, _, v) => {
                let (signal, dim) = self.signal(p)?;
                let q = self.tolerance(v, dim)?;
                // A temperature difference in K is one in degC: say it in degC.
                if q.unit != "K" {
                    unit = q.unit;
                }
                AbortCondition::Drifts {
                    signal,
                    limit: q.value,
                }
            }
            Cond::Abnormal(p) => {
                if p.node != "imu.output" && p.node != "imu" {
                    self.err(
                        Diagnostic::error(
                            "check::unknown_name",
                            format!("`{}` has no abnormal state", p.node),
                        )
                        .label(p.span, "not a signal with an abnormal state")
                        .help("write `imu.output abnormal`"),
                    );
                    return None;
                }
                AbortCondition::ImuAbnormal
            }
        };
        let persistence_s = match &a.persist {
            Some(v) => self.quantity(v, Dim::Time, "a persistence time")?.value,
            None => 0.0,
        };
        let action = match a.action.as_ref().map(|x| x.node.as_str()) {
            None | Some("abort") => AbortAction::Abort,
            Some("warn") => AbortAction::Warn,
            Some(other) => {
                let span = a.action.as_ref().map_or(Span::default(), |x| x.span);
                self.err(
                    Diagnostic::error(
                        "check::unknown_name",
                        format!("unknown abort action `{other}`"),
                    )
                    .label(span, "not an action")
                    .help(suggest(other, &["abort", "warn"])),
                );
                return None;
            }
        };
        Some(AbortRule {
            text: format_abort(a),
            condition,
            persistence_s,
            action,
            unit,
        })
    }

    fn limit(&mut self, l: &ast::Limit) -> Option<(String, Cmp, Quantity)> {
        let (name, dim) = self.named(&l.name)?;
        let q = self.quantity(&l.value, dim, "this limit")?;
        Some((name, cmp(l.op.node), q))
    }

    /// A quantity a limit may name (a computed quantity or a calibrated parameter) and its
    /// dimension; a located error when it is none.
    pub(super) fn named(&mut self, name: &ast::Ident) -> Option<(String, Dim)> {
        let names: Vec<&str> = ACCEPTS.iter().map(|x| x.0).collect();
        if let Some((_, instead)) = NOT_COMPUTED.iter().find(|x| x.0 == name.node) {
            self.err(
                Diagnostic::error(
                    "check::not_computed",
                    format!("no fit computes `{}`", name.node),
                )
                .label(name.span, "this check could never be evaluated")
                .help(format!(
                    "check a quantity the analysis computes, e.g. `{instead}` (docs/language.md lists them)"
                )),
            );
            return None;
        }
        let found = ACCEPTS
            .iter()
            .find(|x| x.0 == name.node)
            .map(|&(n, d)| (n.to_string(), d))
            .or_else(|| parameter_dim(&name.node).map(|d| (name.node.clone(), d)));
        if found.is_none() {
            // Suggest from the namespace the name is shaped like: a parameter
            // (`accel.bais.x`) among parameters, a computed quantity among those.
            let params = ratecal_plan::derived::parameter_names();
            let param_refs: Vec<&str> = params.iter().map(String::as_str).collect();
            let (label, help) = if ratecal_plan::derived::looks_like_parameter(&name.node) {
                let help = match did_you_mean(&name.node, param_refs.iter().copied()) {
                    Some(c) => format!("did you mean the parameter `{c}`?"),
                    None => "name a calibrated parameter (`accel.bias.x`, `gyro.scale.y`, `gyro.misalignment.xy`); docs/language.md lists them".to_string(),
                };
                ("not a calibrated parameter", help)
            } else {
                (
                    "not a quantity ratecal computes",
                    suggest(&name.node, &names),
                )
            };
            self.err(
                Diagnostic::error(
                    "check::unknown_name",
                    format!("unknown quantity `{}`", name.node),
                )
                .label(name.span, label)
                .help(help),
            );
        }
        found
    }

    /// `imu class C` on a station whose IMU is of a lower grade: a warning (the procedure's
    /// limits were written for a better IMU).
    fn imu_class(&mut self, c: &ast::Ident) {
        let Some(grade) = self.station.as_ref().map(|s| s.imu_grade.clone()) else {
            return;
        };
        let (Some(asked), Some(has)) = (grade_rank(&c.node), grade_rank(&grade)) else {
            return;
        };
        if has < asked {
            self.err(
                Diagnostic::warning(
                    "check::imu_class",
                    format!(
                        "the procedure is for a {} IMU; the station's IMU is {grade}",
                        c.node
                    ),
                )
                .label(c.span, format!("asks for {} grade", c.node))
                .help(format!(
                    "its limits were written for a {} IMU: a {grade} one may fail them; use a procedure for {grade} IMUs or a station with a {} IMU",
                    c.node, c.node
                )),
            );
        }
    }

    pub(crate) fn verify(&mut self, v: &ast::Verify) -> Option<Verification> {
        let point = match &v.point {
            ast::VerifyPoint::Attitude(angles) => {
                let (mut outer, mut inner) = (0.0, 0.0);
                for a in angles {
                    let q = self.quantity(&a.value, Dim::Angle, "a verification angle")?;
                    match a.axis.node.as_str() {
                        "pitch" | "outer" => outer = q.value,
                        "roll" | "inner" => inner = q.value,
                        other => {
                            self.err(
                                Diagnostic::error(
                                    "check::unknown_name",
                                    format!("unknown table angle `{other}`"),
                                )
                                .label(a.axis.span, "not an angle name")
                                .help(suggest(other, &["pitch", "roll", "outer", "inner"])),
                            );
                            return None;
                        }
                    }
                }
                VerifyPoint::Attitude {
                    outer_deg: outer,
                    inner_deg: inner,
                }
            }
            ast::VerifyPoint::Rate { axis, rate } => {
                let axis: Axis = self.axis(axis)?;
                let r = self.quantity(rate, Dim::Rate, "a verification rate")?;
                VerifyPoint::Rate {
                    axis,
                    rate_dps: r.value,
                }
            }
        };
        let mut limits = Vec::new();
        for l in &v.limits.items {
            let (quantity, op, limit) = self.limit(&l.node)?;
            limits.push(Accept {
                step: None,
                quantity,
                op,
                limit,
                over_runs: None,
                rule: DecisionRule::Simple,
                within: false,
            });
        }
        self.walk.verify_from.extend(v.from.iter().cloned());
        Some(Verification {
            point,
            limits,
            segments: v.from.iter().map(|p| p.node.clone()).collect(),
        })
    }

    pub(crate) fn fit(&mut self, f: &ast::Fit, span: Span, plan: &mut Plan) {
        let model_word = f.model.as_ref().map_or("", |m| m.node.as_str());
        let Some((_, _, model)) = MODELS
            .iter()
            .find(|m| m.0 == f.sensor.node && m.1 == model_word)
        else {
            let names: Vec<String> = MODELS
                .iter()
                .map(|m| format!("{} {}", m.0, m.1).trim().to_string())
                .collect();
            let refs: Vec<&str> = names.iter().map(String::as_str).collect();
            let written = format!("{} {}", f.sensor.node, model_word)
                .trim()
                .to_string();
            let at = f
                .model
                .as_ref()
                .map_or(f.sensor.span, |m| f.sensor.span.join(m.span));
            self.err(
                Diagnostic::error(
                    "check::unknown_name",
                    format!("unknown fit model `{written}`"),
                )
                .label(at, "not an error model ratecal fits")
                .help(suggest(&written, &refs)),
            );
            return;
        };
        let mut axes = Vec::new();
        match &f.axes {
            Some(list) => {
                for a in list {
                    match a.node.as_str() {
                        "x" => axes.push((0, a.span)),
                        "y" => axes.push((1, a.span)),
                        "z" => axes.push((2, a.span)),
                        other => self.err(
                            Diagnostic::error(
                                "check::unknown_name",
                                format!("unknown body axis `{other}`"),
                            )
                            .label(a.span, "not a body axis")
                            .help(suggest(other, &["x", "y", "z"])),
                        ),
                    }
                }
            }
            None => axes = (0..3).map(|i| (i, f.sensor.span)).collect(),
        }
        for e in &f.with {
            let known = ratecal_physics::effects::catalogue().any(|x| x.id() == e.node);
            if !known {
                let ids: Vec<&str> = ratecal_physics::effects::catalogue()
                    .map(|x| x.id())
                    .collect();
                self.err(
                    Diagnostic::error(
                        "check::unknown_effect",
                        format!("unknown effect `{}`", e.node),
                    )
                    .label(e.span, "not an effect of the catalogue")
                    .help(suggest(&e.node, &ids)),
                );
            }
        }
        let (mut outliers, mut lowpass) = (None, None);
        for o in f.options.iter().flat_map(|b| &b.items) {
            match &o.node {
                ast::FitOpt::Sigma(n) => match n.node.parse::<f64>() {
                    Ok(k) if k > 0.0 && k.is_finite() => outliers = Some(Outliers::Sigma(k)),
                    _ => self.err(
                        Diagnostic::error(
                            "check::bad_number",
                            "the outlier threshold must be positive",
                        )
                        .label(n.span, "here"),
                    ),
                },
                ast::FitOpt::Grubbs(alpha) => {
                    let a = alpha.as_ref().map_or(Ok(0.05), |a| a.node.parse::<f64>());
                    match a {
                        Ok(a) if a > 0.0 && a < 1.0 => outliers = Some(Outliers::Grubbs(a)),
                        _ => self.err(
                            Diagnostic::error(
                                "check::bad_number",
                                "alpha must lie between 0 and 1",
                            )
                            .label(o.span, "here"),
                        ),
                    }
                }
                ast::FitOpt::Lowpass { order, cutoff } => {
                    let c = self.quantity(cutoff, Dim::Frequency, "a cutoff frequency");
                    match (order.node.parse::<u32>(), c) {
                        (Ok(n), Some(c)) if (1..=12).contains(&n) && c.value > 0.0 => {
                            lowpass = Some((n, c.value))
                        }
                        (Ok(_), Some(_)) | (Err(_), _) => self.err(
                            Diagnostic::error(
                                "check::bad_number",
                                "the filter order must be 1 to 12 and the cutoff positive",
                            )
                            .label(o.span, "here"),
                        ),
                        _ => {}
                    }
                }
            }
        }
        let index = plan.fits.len();
        plan.fits.push(FitSpec {
            step: self.walk.step.clone(),
            model: model.clone(),
            axes: axes.iter().map(|a| a.0).collect(),
            segments: f.from.iter().map(|p| p.node.clone()).collect(),
            outliers,
            lowpass,
            using: f.using.as_ref().map(|u| u.node.clone()),
            effects: f.with.iter().map(|e| e.node.clone()).collect(),
        });
        // Labels go on the fit's head (`fit accel bias_scale`), not its whole block.
        let head = f
            .model
            .as_ref()
            .map_or(f.sensor.span, |m| f.sensor.span.join(m.span));
        let _ = span;
        self.walk.fits.push(FitCheck {
            index,
            span: head,
            axes,
            from: f.from.clone(),
            using: f.using.clone(),
        });
    }
}

/// IMU grades from the lowest: a class's rank, `None` for a name not in the scale.
const GRADES: [&str; 5] = [
    "consumer",
    "industrial",
    "tactical",
    "navigation",
    "strategic",
];

fn grade_rank(name: &str) -> Option<usize> {
    let n = name.trim().to_ascii_lowercase();
    GRADES
        .iter()
        .position(|g| n == *g || n == format!("{g}-grade"))
}
