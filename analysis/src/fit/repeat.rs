//! Repeatability over complete runs: each run analysed alone, then the spread of every
//! parameter (coefficient of variation, or the standard deviation where the parameter is
//! near zero and a CV would be meaningless).

use super::accept::{judge, not_evaluated};
use super::{Options, Source, analyze_source};
use crate::plan::Plan;
use crate::results::{Parameter, RepeatParameter, Repeatability, Results};

/// Analyses several runs of the same procedure: parameters are the runs' means, each
/// run's checks are listed (named `[run k]`), and repeatability thresholds are evaluated.
/// `runs` pairs each recording with the name (folder) it is reported under.
pub fn analyze_runs<S: Source>(
    runs: &[(String, S)],
    plan: Option<&Plan>,
    opts: &Options,
) -> Result<Results, S::Error> {
    let each: Vec<Results> = runs
        .iter()
        .map(|(p, r)| {
            analyze_source(
                r,
                plan,
                &Options {
                    path: p.clone(),
                    ..opts.clone()
                },
            )
        })
        .collect::<Result<_, _>>()?;
    let mut res = each[0].clone();
    if each.len() == 1 {
        return Ok(res);
    }
    res.recording.paths = runs.iter().map(|(p, _)| p.clone()).collect();
    let n = each.len() as f64;
    let mut rep = Vec::new();
    for (name, p0) in &each[0].parameters {
        let vals: Option<Vec<(f64, f64)>> = each.iter().map(|r| r.value(name)).collect();
        let (Some(vals), Some(unit)) = (vals, p0.unit()) else {
            res.parameters
                .insert(name.clone(), Parameter::unobservable());
            continue;
        };
        let mean = vals.iter().map(|v| v.0).sum::<f64>() / n;
        let u = vals.iter().map(|v| v.1 * v.1).sum::<f64>().sqrt() / n;
        res.parameters
            .insert(name.clone(), Parameter::estimate(mean, u, unit));
        let std = (vals.iter().map(|v| (v.0 - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        // A scale is reported as K - 1 (ppm): its CV is that of K itself.
        let (cv, measure) = if name.contains(".scale.") {
            (Some(std * 1e-6 / (1.0 + mean * 1e-6).abs()), "cv")
        } else if name.contains(".bias.")
            || name.contains(".misalignment.")
            || mean.abs() <= 3.0 * std
        {
            (None, "std")
        } else {
            (Some(std / mean.abs()), "cv")
        };
        rep.push(RepeatParameter {
            name: name.clone(),
            values: vals.iter().map(|v| v.0).collect(),
            mean,
            std,
            cv,
            measure: measure.into(),
            unit: unit.into(),
        });
    }
    res.acceptance.clear();
    for (k, r) in each.iter().enumerate() {
        for a in &r.acceptance {
            if a.quantity == "repeatability.cv" {
                continue;
            }
            let mut a = a.clone();
            a.name = format!("{} [run {}]", a.name, k + 1);
            res.acceptance.push(a);
        }
    }
    if let Some(plan) = plan {
        for a in plan
            .accepts
            .iter()
            .filter(|a| a.quantity == "repeatability.cv")
        {
            let need = a.over_runs.unwrap_or(3) as usize;
            let worst = rep
                .iter()
                .filter(|p| p.cv.is_some() && p.name.contains(".scale."))
                .max_by(|x, y| x.cv.partial_cmp(&y.cv).expect("finite"));
            res.acceptance.push(match worst {
                _ if each.len() < need => not_evaluated(a, &format!("needs {need} runs, {} given", each.len())),
                None => not_evaluated(a, "no scale factor was determined in every run"),
                Some(w) => {
                    let cv = w.cv.expect("filtered");
                    let mut j = judge(a, cv, cv / (2.0 * (n - 1.0)).sqrt(), 2.0, None);
                    j.reason = Some(format!(
                        "CV of the scale factors K (largest: {}); noise figures are not calibration parameters; biases and misalignments are near zero, where a CV is meaningless: their standard deviations are in `repeatability`",
                        w.name
                    ));
                    j
                }
            });
        }
    }
    res.warnings = each
        .iter()
        .enumerate()
        .flat_map(|(k, r)| {
            r.warnings
                .iter()
                .map(move |w| format!("run {}: {w}", k + 1))
        })
        .collect();
    let sanity: Vec<&[crate::results::SanityCheck]> =
        each.iter().map(|r| r.sanity.as_slice()).collect();
    res.sanity = super::sanity::merge(&sanity);
    res.repeatability = Some(Repeatability {
        runs: each.len(),
        parameters: rep,
    });
    res.decide(
        runs.iter()
            .any(|(_, r)| crate::results::ended_early(r.manifest())),
    );
    Ok(res)
}
