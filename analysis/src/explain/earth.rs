//! The Earth's rate as explain tries it: physics it already knows, not a free vector.
//!
//! The Earth turns at 15.041 deg/h about its axis and the manifest gives the site's
//! latitude, so the only legitimate unknown is the table's true heading (the azimuth of
//! its axes, which a lab may not know to the degree). The candidate has two columns: the
//! Earth's rate at the manifest's latitude as the station believes it is oriented (its
//! coefficient `scale` is 1 when the physics holds) and the rate along the lab's East axis
//! (`east_dph`), which a heading error turns the horizontal component into. A `scale` far
//! from 1 means the gyros see an attitude-dependent rate that is not the Earth's; the final
//! model then holds the Earth's rate at its physical value, and what mimics it is left to
//! the tests for what remains unexplained.

use ratecal_physics::DEG;
use ratecal_physics::effects::{EarthRate, Effect, Param, Partials, Sensor, Signals};

/// The candidate (its id is the registry's `earth_rate`).
#[derive(Debug)]
pub(crate) struct EarthHeld;

/// The instance explain adds to its layout.
pub(crate) static EARTH_HELD: EarthHeld = EarthHeld;

static PARAMS: [Param; 2] = [
    Param {
        name: "scale",
        unit: "1",
        channel: None,
        needs: "static attitudes that turn the Earth's axis through the gyro axes",
        // Judged against 1 by explain itself, not by a magnitude.
        max_abs: f64::INFINITY,
    },
    Param {
        name: "east_dph",
        unit: "deg/h",
        channel: None,
        needs: "static attitudes that turn the lab's East axis through the gyro axes",
        // No component of the Earth's rate exceeds it.
        max_abs: ratecal_physics::EARTH_RATE_RADPS / DEG * 3600.0,
    },
];

impl Effect for EarthHeld {
    fn varies_at_rest(&self) -> bool {
        false
    }

    fn id(&self) -> &'static str {
        "earth_rate"
    }

    fn explanation(&self) -> &'static str {
        ratecal_physics::effect("earth_rate").map_or("", |e| e.explanation())
    }

    fn follows(&self) -> &'static str {
        ratecal_physics::effect("earth_rate").map_or("", |e| e.follows())
    }

    fn params(&self) -> &'static [Param] {
        &PARAMS
    }

    fn sensors(&self) -> &'static [Sensor] {
        &[Sensor::Gyro]
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        out[0] = Partials {
            gyro: s.earth_b / DEG,
            ..Default::default()
        };
        out[1] = Partials {
            gyro: s.c_bl.column(0) / 3600.0,
            ..Default::default()
        };
    }
}

/// The horizontal and vertical components of the Earth's rate at a latitude, deg/h.
pub(crate) fn components(latitude_deg: f64) -> (f64, f64) {
    let [n, u] = EarthRate::values(latitude_deg);
    (n, u)
}

/// The heading (deg) a fitted East component gives, with its u: the lab's North axis
/// points `heading` east of true north, so true north has an East component of
/// `-h sin(heading)` in lab axes. `None` when the component exceeds the horizontal rate
/// itself by more than its uncertainty allows.
pub(crate) fn heading_deg(east_dph: f64, u_dph: f64, latitude_deg: f64) -> Option<(f64, f64)> {
    let (h, _) = components(latitude_deg);
    if h <= 0.0 {
        return None;
    }
    let x = -east_dph / h;
    if x.abs() > 1.0 + 3.0 * u_dph / h {
        return None;
    }
    let x = x.clamp(-1.0, 1.0);
    let psi = x.asin();
    let u = u_dph / (h * psi.cos().max(1e-3));
    Some((psi / DEG, u / DEG))
}

/// The Earth's rate held at its physical value in a final model.
#[derive(Debug, Clone)]
pub(crate) struct Held {
    /// The candidate's `scale` when it was free (1 when the physics holds), with its u.
    pub scale: (f64, f64),
    /// The fitted heading (deg) and its u, when the motion determines it.
    pub heading: Option<(f64, f64)>,
}

/// When `terms` holds the candidate, replaces it by the Earth's rate at the manifest's
/// latitude (the registry's `earth_rate`, fixed) with only the East component free (the
/// heading), in two passes so that a heading of tens of degrees is exact.
pub(crate) fn hold(
    data: &super::data::Data,
    terms: &mut super::model::Terms,
    latitude_deg: f64,
) -> Option<Held> {
    let lay = &data.layout;
    if !terms.effects.contains(&data.earth) {
        return None;
    }
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let gs = lay.first[data.earth];
    let ge = gs + 1;
    let free = super::model::fit(data, terms, &all, &all).0;
    let scale = (free.theta[gs], free.u(gs));
    let reg = lay.index("earth_rate")?;
    let (h, v) = components(latitude_deg);
    terms.skip.push(gs);
    terms.fixed.push((reg, vec![h, v]));
    let mut heading = None;
    for _ in 0..2 {
        let f = super::model::fit(data, terms, &all, &all).0;
        if !f.estimated.contains(&ge) {
            heading = None;
            break;
        }
        heading = heading_deg(f.theta[ge], f.u(ge), latitude_deg);
        let Some((psi, _)) = heading else { break };
        if let Some(last) = terms.fixed.last_mut() {
            last.1 = vec![h * (psi * DEG).cos(), v];
        }
    }
    let mut held = Held { scale, heading };
    // A heading fitted to a rate that is not the Earth's means nothing.
    if held.mimic(1.0).is_some() {
        held.heading = None;
    }
    Some(held)
}

impl Held {
    /// The finding's parameters: the physical components at the manifest's latitude (u 0)
    /// and the fitted heading.
    pub(crate) fn parameters(
        &self,
        latitude_deg: f64,
    ) -> std::collections::BTreeMap<String, super::ParamOut> {
        use super::ParamOut::Estimate;
        let (h, v) = components(latitude_deg);
        let est = |value: f64, u: f64, unit: &str| Estimate {
            value,
            u,
            unit: unit.into(),
        };
        let mut p = std::collections::BTreeMap::new();
        p.insert("latitude_deg".into(), est(latitude_deg, 0.0, "deg"));
        p.insert("north_dph".into(), est(h, 0.0, "deg/h"));
        p.insert("up_dph".into(), est(v, 0.0, "deg/h"));
        if let Some((psi, u)) = self.heading {
            p.insert("heading_deg".into(), est(psi, u, "deg"));
        }
        p
    }

    /// An `unexplained` entry when the free scale says the attitude-dependent rate is not
    /// the Earth's (off by more than 10 % and five standard errors).
    pub(crate) fn mimic(&self, alpha: f64) -> Option<super::Unexplained> {
        let (s, u) = self.scale;
        let z = if u > 0.0 { (s - 1.0).abs() / u } else { 0.0 };
        let p = super::select::p_value(z * z, 1);
        if (s - 1.0).abs() <= 0.1 || z < 5.0 || p >= alpha {
            return None;
        }
        Some(super::Unexplained {
            sensor: "gyro".into(),
            channels: vec!["gx".into(), "gy".into(), "gz".into()],
            segments: Vec::new(),
            p_value: p,
            standard_errors: z,
            signature: vec![super::Signature {
                expression: "earth_b.x / deg".into(),
                share: 1.0,
                channel: "gx".into(),
                reading: format!(
                    "an attitude-dependent rate {s:.2} times the Earth's at the site's latitude"
                ),
                in_time: false,
            }],
            note: Some(
                "the gyros see an attitude-dependent rate that is not the Earth's: something mimics it".into(),
            ),
        })
    }
}

/// The final model's term names, the Earth's rate said once.
pub(crate) fn names(data: &super::data::Data, terms: &super::model::Terms) -> Vec<String> {
    let held =
        terms.effects.contains(&data.earth) && terms.skip.contains(&data.layout.first[data.earth]);
    terms
        .names(&data.layout)
        .into_iter()
        .filter(|n| !(held && n == "earth_rate (fixed)"))
        .map(|n| {
            if held && n == "earth_rate" {
                "earth_rate (latitude held, heading fitted)".to_string()
            } else {
                n
            }
        })
        .collect()
}
