//! The Earth's rate in explain's final model: when the candidate ([`candidate`]) is
//! selected, it is replaced by the registry's `earth_rate` held at the manifest's
//! latitude with only the heading free, and its free scale tells whether what the gyros
//! saw was the Earth's rate at all.
//!
//! The candidate lives in a module of its own because the recording's accumulation
//! ([`super::data`]) adds it to the layout, while holding it needs the models fitted
//! over that accumulation.

pub(crate) mod candidate;

use super::data::Data;
use super::model::{Terms, fit};
use super::stats::p_value;
use crate::results::Parameter;
use candidate::{components, heading_deg};
use ratecal_physics::DEG;

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
pub(crate) fn hold(data: &Data, terms: &mut Terms, latitude_deg: f64) -> Option<Held> {
    let lay = &data.layout;
    if !terms.effects.contains(&data.earth) {
        return None;
    }
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let gs = lay.first[data.earth];
    let ge = gs + 1;
    let free = fit(data, terms, &all, &all).0;
    let scale = (free.theta[gs], free.u(gs));
    let reg = lay.index("earth_rate")?;
    let (h, v) = components(latitude_deg);
    terms.skip.push(gs);
    terms.fixed.push((reg, vec![h, v]));
    let mut heading = None;
    for _ in 0..2 {
        let f = fit(data, terms, &all, &all).0;
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
    ) -> std::collections::BTreeMap<String, Parameter> {
        let (h, v) = components(latitude_deg);
        let est = Parameter::estimate;
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
        let p = p_value(z * z, 1);
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
pub(crate) fn names(data: &Data, terms: &Terms) -> Vec<String> {
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
