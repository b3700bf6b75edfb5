//! Acceptance checks: the quantity (a computed quantity, a calibrated parameter or a
//! function of parameters, `plan::derived`), its bound (`<= 80 mg`, `within +-1 mrad`), the
//! decision rule; and, once every fit is known, whether the fits' models give the
//! parameters the checks name.

use super::Ck;
use super::header::cmp;
use super::values::suggest;
use ratecal_grammar::Diagnostic;
use ratecal_grammar::ast::{self, AcceptBound, Span};
use ratecal_plan::derived::{self, DerivedError, FUNCTIONS};
use ratecal_plan::{Accept, Cmp, DecisionRule, Dim, FitModel, Plan};

/// A check on calibrated parameters, held until every fit of the procedure is known.
#[derive(Debug, Clone)]
pub(crate) struct FittedCheck {
    /// The parameters it reads.
    pub parameters: Vec<String>,
    /// The checked expression.
    pub span: Span,
}

impl Ck<'_> {
    pub(crate) fn accept(&mut self, a: &ast::Accept, step: Option<String>) -> Option<Accept> {
        let (quantity, dim) = self.checked(&a.checked)?;
        let (op, value, within) = match &a.bound {
            AcceptBound::Cmp(op, v) => (cmp(op.node), v, false),
            AcceptBound::Within(v) => (Cmp::Le, v, true),
        };
        let limit = self.quantity(value, dim, "this limit")?;
        if within && limit.value < 0.0 {
            self.err(
                Diagnostic::error("check::bad_limit", "a `within` limit cannot be negative")
                    .label(value.span, "a negative half-width")
                    .help("write the half-width of the band, e.g. `within +-1 mrad`"),
            );
            return None;
        }
        let over_runs = match &a.runs {
            Some(n) => match n.node.parse::<u32>() {
                Ok(k) if k >= 2 => Some(k),
                _ => {
                    self.err(
                        Diagnostic::error(
                            "check::bad_count",
                            "repeatability needs at least 2 runs",
                        )
                        .label(n.span, "here"),
                    );
                    return None;
                }
            },
            None => None,
        };
        if quantity == "repeatability.cv" && over_runs.is_none() {
            self.err(
                Diagnostic::error(
                    "check::missing_runs",
                    "repeatability needs a number of runs",
                )
                .label(a.checked.span, "over how many runs?")
                .help("write e.g. `accept repeatability.cv <= 1 % over 3 runs`"),
            );
            return None;
        }
        let rule = if a.guarded {
            DecisionRule::GuardBanded
        } else {
            DecisionRule::Simple
        };
        Some(Accept {
            step,
            quantity,
            op,
            limit,
            over_runs,
            rule,
            within,
        })
    }

    /// The plan's name of a checked expression and its dimension.
    fn checked(&mut self, c: &ast::Checked) -> Option<(String, Dim)> {
        let Some(func) = &c.func else {
            let (name, dim) = self.named(&c.name)?;
            if let Ok(d) = derived::derived(None, &name) {
                self.fitted_checks.push(FittedCheck {
                    parameters: d.parameters,
                    span: c.name.span,
                });
            }
            return Some((name, dim));
        };
        match derived::derived(Some(&func.node), &c.name.node) {
            Ok(d) => {
                self.fitted_checks.push(FittedCheck {
                    parameters: d.parameters,
                    span: c.name.span,
                });
                Some((c.text(), d.dim))
            }
            Err(e) => {
                let arg = &c.name.node;
                let (code, msg, label, help, span) = match e {
                    DerivedError::UnknownFunction => (
                        "check::unknown_name",
                        format!("unknown function `{}`", func.node),
                        "not a function of the language".to_string(),
                        suggest(&func.node, FUNCTIONS),
                        func.span,
                    ),
                    DerivedError::AbsOfVector => (
                        "check::not_scalar",
                        format!("`abs` of a triad: `{arg}` has three or more components"),
                        "a vector".to_string(),
                        format!(
                            "take one component (`abs({arg}.x)`) or the vector's length (`norm({arg})`)"
                        ),
                        c.name.span,
                    ),
                    DerivedError::NormOfScalar => (
                        "check::not_vector",
                        format!("`norm` of one parameter: `{arg}` is a scalar"),
                        "a scalar".to_string(),
                        "use `abs(...)` for one parameter; `norm` takes a triad (`norm(accel.bias)`, `norm(accel.misalignment.x)`)".to_string(),
                        c.name.span,
                    ),
                    DerivedError::UnknownArgument => (
                        "check::unknown_name",
                        format!("unknown parameter `{arg}`"),
                        "not a calibrated parameter or triad".to_string(),
                        "name a fitted parameter (`gyro.scale.x`) or triad (`accel.bias`, `gyro.misalignment`, `gyro.misalignment.x`); docs/language.md lists them".to_string(),
                        c.name.span,
                    ),
                };
                self.err(Diagnostic::error(code, msg).label(span, label).help(help));
                None
            }
        }
    }

    /// Every check on calibrated parameters names parameters some fit of the procedure
    /// gives: a misalignment needs a full model, a gyro scale a scale or full gyro fit.
    /// A procedure without fit statements leaves the model to the analysis (chosen by the
    /// segments' kinds), so there is nothing to check against here.
    pub(crate) fn fitted_against_model(&mut self, plan: &Plan) {
        if plan.fits.is_empty() {
            self.fitted_checks.clear();
            return;
        }
        let given: Vec<&str> = plan
            .fits
            .iter()
            .flat_map(|f| families(&f.model))
            .copied()
            .collect();
        for c in std::mem::take(&mut self.fitted_checks) {
            let missing: Vec<&String> = c
                .parameters
                .iter()
                .filter(|p| {
                    let family = p.rsplit_once('.').map_or(p.as_str(), |x| x.0);
                    !given.contains(&family)
                })
                .collect();
            let Some(first) = missing.first() else {
                continue;
            };
            let family = first.rsplit_once('.').map_or(first.as_str(), |x| x.0);
            let fit = match family {
                "accel.misalignment" => "fit accel full from ...",
                "gyro.misalignment" => "fit gyro full from ...",
                "gyro.scale" => "fit gyro scale from ...` or `fit gyro full from ...",
                "gyro.bias" => "fit gyro bias from ...",
                _ => "fit accel bias_scale from ...",
            };
            self.err(
                Diagnostic::error(
                    "check::not_fitted",
                    format!("no fit of this procedure gives `{first}`"),
                )
                .label(c.span, "not in any fit's model")
                .help(format!(
                    "add a fit whose model has it (`{fit}`), or check a parameter the fits give"
                )),
            );
        }
    }
}

/// The parameter families (`accel.bias`) a fit model gives.
fn families(m: &FitModel) -> &'static [&'static str] {
    match m {
        FitModel::AccelBiasScale => &["accel.bias", "accel.scale"],
        FitModel::AccelFull => &["accel.bias", "accel.scale", "accel.misalignment"],
        FitModel::GyroBias => &["gyro.bias"],
        FitModel::GyroScale => &["gyro.bias", "gyro.scale"],
        FitModel::GyroFull => &["gyro.bias", "gyro.scale", "gyro.misalignment"],
        FitModel::TempCompensation | FitModel::Allan | FitModel::SizeEffect => &[],
    }
}
