//! A change point as a discovered finding: a bias step at an instant inside a segment,
//! with its instant's uncertainty from the profile, in the form a draft effect file takes
//! (`(sign(t_s - at) + 1) / 2`, docs/user-effects.md).

use super::change::ChangePoint;
use super::data::Data;
use super::output::{Evidence, Finding, Located, Rms, Term};
use super::probe::Form;
use crate::fit::joint::{CHANNELS, channel};
use crate::recording::Manifest;
use crate::results::Parameter;
use ratecal_physics::effects::Sensor;
use std::collections::BTreeMap;

/// The size of a jump in the library step's unit (ug or deg/h) from the output's unit.
fn in_step_unit(sensor: Sensor, v: f64, g: f64) -> f64 {
    match sensor {
        Sensor::Accel => v / (1e-6 * g),
        Sensor::Gyro => v * 3600.0,
    }
}

/// The finding of change point `cp`, or why it is not plausible (`max_abs`: the step's
/// range for the grade, in the step's unit).
pub(crate) fn finding(
    m: &Manifest,
    data: &Data,
    cp: &ChangePoint,
    alpha: f64,
    max_abs: f64,
    rms_now: Rms,
) -> Result<Finding, String> {
    let (sensor, ax) = channel(cp.channel);
    let g = m.station.site.gravity_mps2;
    let form = Form::Step {
        at: (cp.at_s * 100.0).round() / 100.0,
    };
    let unit = form.unit(sensor).to_string();
    let (value, u) = (
        in_step_unit(sensor, cp.size, g),
        in_step_unit(sensor, cp.u_size, g).abs(),
    );
    let name = CHANNELS[cp.channel];
    if value.abs() > max_abs {
        return Err(format!(
            "a jump on {name} at t = {:.1} s of {value:.4e} {unit} is outside what a real part shows (|value| <= {max_abs:.4e} {unit})",
            cp.at_s
        ));
    }
    let seg = &m.segments[data.accs[cp.acc].seg];
    let mut parameters = BTreeMap::new();
    parameters.insert(
        "at_s".to_string(),
        Parameter::estimate(cp.at_s, cp.u_at_s, "s"),
    );
    parameters.insert(format!("k_{name}"), Parameter::estimate(value, u, &unit));
    Ok(Finding {
        effect: format!("discovered_{name}_step_{:.0}s", cp.at_s),
        explanation: format!(
            "the bias jumps inside segment {} at t = {:.1} +- {:.1} s: a bias step",
            seg.id, cp.at_s, cp.u_at_s
        ),
        located: vec![Located {
            segment: seg.id.clone(),
            channel: name.to_string(),
            t_start: seg.t_start,
            t_end: seg.t_end,
            rms_before: cp.size.abs(),
            rms_after: cp.u_size,
            correlates_with: "a level that changes inside the segment".into(),
            held_out: data.held.contains(&cp.acc),
        }],
        residuals: Vec::new(),
        parameters,
        evidence: Evidence {
            chi2: cp.z * cp.z,
            dof: 1,
            p_value: cp.p,
            alpha,
            holdout_rms_before: rms_now,
            holdout_rms_after: rms_now,
            not_separable_from: Vec::new(),
        },
        rms_after: rms_now,
        defined_in: None,
        alternatives: Vec::new(),
        separate_by: None,
        station_side: false,
        discovered: true,
        terms: vec![Term {
            channel: name.to_string(),
            expression: form.expression(sensor, ax),
            value,
            u,
            unit,
            needs: "a segment long enough to see the level before and after".into(),
            max_abs: Some(max_abs),
        }],
        alternative_fits: Vec::new(),
    })
}
