//! Observability: every parameter a fit declares must be excited by the planned motion.
//! Projections come from `ratecal_physics` (the same kinematics as the simulator and the
//! analysis), on the station's geometry or, without a station, the procedure's.

use super::Ck;
use super::steps::{FitCheck, SegInfo};
use super::values::did_you_mean;
use ratecal_grammar::Diagnostic;
use ratecal_grammar::ast::Span;
use ratecal_physics::{Site, TableState, Vec3};
use ratecal_plan::{Axis, FitModel, Plan, segment_matches};

const AXES: [&str; 3] = ["X", "Y", "Z"];
/// Smallest spread of projected rates (deg/s) that excites a gyro scale factor.
const MIN_RATE_SPREAD_DPS: f64 = 1.0;

/// Gravity projection (in g) on the body axes of a static segment.
fn gravity_b(ck: &Ck, s: &SegInfo) -> Option<Vec3> {
    let m = &s.motion;
    let state = TableState::at_rest_deg(m.outer?, m.inner?);
    let site = Site {
        latitude_deg: 0.0,
        gravity_mps2: 1.0,
    };
    Some(state.f_b(&ck.geometry.with_mount(m.mount), &site, &Vec3::zeros()))
}

/// Body rates (deg/s) a rotating segment exposes: the constant rate, or both peaks of an
/// oscillation.
fn rates_b(ck: &Ck, s: &SegInfo) -> Vec<Vec3> {
    let m = &s.motion;
    let geo = ck.geometry.with_mount(m.mount);
    let body = |outer_rate: f64, inner_rate: f64| {
        let mut st = TableState::at_rest_deg(m.outer.unwrap_or(0.0), m.inner.unwrap_or(0.0));
        st.outer.rate = outer_rate.to_radians();
        st.inner.rate = inner_rate.to_radians();
        st.w_b(&geo).map(f64::to_degrees)
    };
    let mut out = vec![body(m.outer_rate, m.inner_rate)];
    if let Some((ax, amp, period)) = m.osc {
        let peak = amp * 2.0 * std::f64::consts::PI / period;
        for p in [peak, -peak] {
            out.push(match ax {
                Axis::Outer => body(p, 0.0),
                Axis::Inner => body(0.0, p),
            });
        }
    }
    out
}

fn attitude_text(s: &SegInfo) -> String {
    let m = &s.motion;
    let (a, b) = if m.pitch_roll {
        ("pitch", "roll")
    } else {
        ("outer", "inner")
    };
    format!(
        "{a} {} deg, {b} {} deg",
        m.outer.unwrap_or(0.0),
        m.inner.unwrap_or(0.0)
    )
}

impl Ck<'_> {
    pub(crate) fn observability(&mut self, plan: &Plan) {
        let fits = std::mem::take(&mut self.walk.fits);
        if self.walk.incomplete {
            // One error per cause: the statement that failed has been reported.
            self.walk.verify_from.clear();
            return;
        }
        let segs = self.walk.segments.clone();
        for fc in &fits {
            let Some(spec) = plan.fits.get(fc.index) else {
                continue;
            };
            let mut matched: Vec<&SegInfo> = Vec::new();
            let mut missing = false;
            for p in &fc.from {
                let hits: Vec<&SegInfo> = segs
                    .iter()
                    .filter(|s| segment_matches(&p.node, &s.id))
                    .collect();
                if hits.is_empty() {
                    self.no_segment(&p.node, p.span, &segs);
                    missing = true;
                }
                matched.extend(hits);
            }
            if let Some(u) = &fc.using {
                let is_step = plan.steps.iter().any(|s| s.name == u.node);
                if !is_step && !segs.iter().any(|s| segment_matches(&u.node, &s.id)) {
                    self.no_segment(&u.node, u.span, &segs);
                }
            }
            if missing {
                continue;
            }
            match spec.model {
                FitModel::AccelBiasScale | FitModel::AccelFull => {
                    self.accel_observable(fc, &matched)
                }
                FitModel::GyroScale | FitModel::GyroFull => self.gyro_observable(fc, &matched),
                FitModel::GyroBias | FitModel::Allan => {
                    if !matched.iter().any(|s| s.motion.is_static()) {
                        self.err(
                            Diagnostic::error(
                                "check::unobservable",
                                "a gyro bias needs a static segment",
                            )
                            .label(fc.span, "none of its segments is recorded at rest")
                            .help("record the bias with the table still at a known attitude"),
                        );
                    }
                }
                FitModel::SizeEffect => {
                    if !matched.iter().any(|s| s.motion.osc.is_some()) {
                        self.err(
                            Diagnostic::error(
                                "check::unobservable",
                                "the size effect needs oscillation segments",
                            )
                            .label(
                                fc.span,
                                "none of its segments is recorded while the table oscillates",
                            )
                            .help("acquire while an `oscillate` motion runs"),
                        );
                    }
                }
                FitModel::TempCompensation => {}
            }
        }
        let verify_from = std::mem::take(&mut self.walk.verify_from);
        for p in &verify_from {
            if !segs.iter().any(|s| segment_matches(&p.node, &s.id)) {
                self.no_segment(&p.node, p.span, &segs);
            }
        }
    }

    fn no_segment(&mut self, pattern: &str, span: Span, segs: &[SegInfo]) {
        let ids: Vec<&str> = segs.iter().map(|s| s.id.as_str()).collect();
        let help = match did_you_mean(pattern, ids.iter().copied()) {
            Some(c) => format!("did you mean `{c}`?"),
            None if ids.is_empty() => "no segment is recorded before this point".to_string(),
            None => format!(
                "recorded segments include: {}",
                ids.iter().take(6).copied().collect::<Vec<_>>().join(", ")
            ),
        };
        self.err(
            Diagnostic::error(
                "check::no_segment",
                format!("no segment matches `{pattern}`"),
            )
            .label(span, "matches nothing the procedure records")
            .help(help),
        );
    }

    fn accel_observable(&mut self, fc: &FitCheck, matched: &[&SegInfo]) {
        let statics: Vec<(&SegInfo, Vec3)> = matched
            .iter()
            .filter(|s| s.motion.is_static())
            .filter_map(|s| Some((*s, gravity_b(self, s)?)))
            .collect();
        if statics.is_empty() {
            self.err(
                Diagnostic::error(
                    "check::unobservable",
                    "an accelerometer fit needs static segments",
                )
                .label(
                    fc.span,
                    "none of its segments is recorded at rest at a known attitude",
                )
                .help("acquire after `move to` and `settle`, with no axis spinning"),
            );
            return;
        }
        for &(i, axis_span) in &fc.axes {
            let p: Vec<f64> = statics.iter().map(|(_, g)| g[i]).collect();
            let (lo, hi) = p
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                    (l.min(x), h.max(x))
                });
            // Bias and scale separate cleanly when the axis sees gravity both ways (or a
            // wide spread): with one sign only, a scale error looks like a bias.
            if (hi >= 0.5 && lo <= -0.5) || hi - lo >= 1.5 {
                continue;
            }
            let seen = distinct(&p)
                .iter()
                .map(|v| format!("{v:+.0} g"))
                .collect::<Vec<_>>()
                .join(", ");
            let down = if hi >= 0.5 {
                "a negative"
            } else {
                "a positive"
            };
            let msg = format!(
                "accelerometer {} bias and scale are not observable: {} never reads {} gravity projection",
                AXES[i], AXES[i], down
            );
            let fix = self.suggest_attitude(i, hi < 0.5, statics[0].0);
            // Point at an attitude that repeats an earlier one's gravity projection.
            let dup = statics.iter().enumerate().find_map(|(k, (s, g))| {
                statics[..k]
                    .iter()
                    .find(|(t, h)| {
                        (g - h).norm() < 1e-6
                            && (s.motion.outer != t.motion.outer
                                || s.motion.inner != t.motion.inner)
                    })
                    .map(|(t, _)| (*s, *t))
            });
            let mut d = Diagnostic::error("check::unobservable", msg);
            if let Some((s, t)) = dup {
                d = d
                    .label(s.motion.origin, format!("{} gives the same gravity projection as {} ({} reads {:+.0} g in both)", attitude_text(s), attitude_text(t), AXES[i], gravity_b(self, s).map_or(0.0, |g| g[i])))
                    .label(fc.span, "this fit declares it");
            } else {
                d = d.label(
                    axis_span,
                    format!(
                        "{} reads only {seen} in this fit's static segments",
                        AXES[i]
                    ),
                );
            }
            self.err(d.help(format!(
                "{} reads only {seen}, so its bias and scale cannot be separated; {fix}",
                AXES[i]
            )));
        }
    }

    /// An attitude (multiples of 90 deg) that points body axis `i` the missing way.
    fn suggest_attitude(&self, i: usize, want_up: bool, like: &SegInfo) -> String {
        let angles = [0.0, 90.0, -90.0, 180.0];
        for o in angles {
            for n in angles {
                let mut s = like.clone();
                s.motion.outer = Some(o);
                s.motion.inner = Some(n);
                if let Some(g) = gravity_b(self, &s)
                    && ((want_up && g[i] > 0.99) || (!want_up && g[i] < -0.99))
                {
                    {
                        return format!(
                            "add an attitude with {} {}, e.g. {}",
                            AXES[i],
                            if want_up { "up" } else { "down" },
                            attitude_text(&s)
                        );
                    }
                }
            }
        }
        format!("add an attitude that turns {} the other way", AXES[i])
    }

    fn gyro_observable(&mut self, fc: &FitCheck, matched: &[&SegInfo]) {
        let rates: Vec<Vec3> = matched.iter().flat_map(|s| rates_b(self, s)).collect();
        for &(i, axis_span) in &fc.axes {
            let mut p: Vec<f64> = rates.iter().map(|w| w[i]).collect();
            if fc.using.is_some() {
                p.push(0.0);
            }
            let (lo, hi) = p
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                    (l.min(x), h.max(x))
                });
            if hi - lo >= MIN_RATE_SPREAD_DPS {
                continue;
            }
            self.err(
                Diagnostic::error("check::unobservable", format!("gyro {} scale is not observable: no planned rotation turns about {}", AXES[i], AXES[i]))
                    .label(axis_span, format!("no rate segment of this fit has a component on {}", AXES[i]))
                    .help(format!("spin an axis that projects on body {} (or remount the IMU), or leave {} out of the fit's axes", AXES[i], AXES[i].to_lowercase())),
            );
        }
    }
}

fn distinct(p: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for &x in p {
        let x = if x.abs() < 1e-9 { 0.0 } else { x };
        if !out.iter().any(|y| (y - x).abs() < 1e-6) {
            out.push(x);
        }
    }
    out.sort_by(|a, b| b.total_cmp(a));
    out
}
