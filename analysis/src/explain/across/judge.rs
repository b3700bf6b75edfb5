//! The verdict per pooled parameter (docs/explain.md, "Across recordings"):
//! - `unit`: significant in every recording of one serial that has at least two, and in no
//!   recording of another serial;
//! - `model`: significant pooled (outliers left out), in at least one recording of the
//!   fleet, over at least two serials, and consistent (Cochran's Q does not reject
//!   homogeneity at `alpha`);
//! - `pooled_only`: significant pooled (outliers left out) while no recording of the fleet
//!   is;
//! - `occasional`: significant in some recordings, none of the above;
//! - `none`: significant nowhere.
//!
//! A recording's value is significant when its two-sided p-value is below `alpha` over the
//! number of parameters pooled (Bonferroni over what each recording is asked); the pool's
//! significance is controlled by Benjamini-Hochberg at `alpha` over every parameter pooled.

use super::pool::{Obs, Pooled, benjamini_hochberg, dersimonian_laird, p_normal};
use super::{Member, Outlier, PerRecording, PooledOut};
use std::collections::BTreeMap;

/// One recording's value of one parameter.
#[derive(Debug, Clone)]
struct Row {
    run: String,
    serial: String,
    value: f64,
    u: f64,
    found: bool,
}

impl Row {
    fn obs(&self) -> Obs {
        Obs {
            y: self.value,
            u: self.u,
        }
    }
}

/// Every (effect, parameter) of the members' profiles: its unit, its channel and its rows.
type Table = BTreeMap<(String, String), (String, Option<String>, Vec<Row>)>;

fn collect(members: &[Member]) -> Table {
    let mut t: Table = BTreeMap::new();
    for m in members {
        for f in &m.explanation.profile {
            let e = t
                .entry((f.effect.clone(), f.parameter.clone()))
                .or_insert_with(|| (f.unit.clone(), f.channel.clone(), Vec::new()));
            e.2.push(Row {
                run: m.run.clone(),
                serial: m.serial.clone(),
                value: f.value,
                u: f.u,
                found: f.found,
            });
        }
    }
    t
}

/// The pooled parameters worth naming (every verdict but `none`, and those of an effect
/// some recording reported), most recurring first, and the outliers.
pub(super) fn judge(members: &[Member], alpha: f64) -> (Vec<PooledOut>, Vec<Outlier>) {
    let table = collect(members);
    let m = table.len().max(1) as f64;
    let n_serials = distinct(members.iter().map(|m| m.serial.as_str()))
        .len()
        .max(1) as f64;
    let a_rec = alpha / m;
    let a_out = alpha / (m * n_serials);
    let mut work: Vec<Work> = Vec::new();
    for (key, (unit, channel, rows)) in table {
        let outliers = outliers(&rows, a_out);
        let kept: Vec<Obs> = rows
            .iter()
            .filter(|r| outliers.iter().all(|o| o.0 != r.serial))
            .map(Row::obs)
            .collect();
        let all_obs: Vec<Obs> = rows.iter().map(Row::obs).collect();
        let (Some(clean), Some(all)) = (dersimonian_laird(&kept), dersimonian_laird(&all_obs))
        else {
            continue;
        };
        work.push(Work {
            key,
            unit,
            channel,
            rows,
            outliers,
            clean,
            all,
        });
    }
    let p: Vec<f64> = work
        .iter()
        .map(|w| p_normal(w.clean.mean / w.clean.u))
        .collect();
    let sig = benjamini_hochberg(&p, alpha);
    let mimic = mimics(&work);
    let mut verdicts: Vec<&'static str> = Vec::new();
    for (w, &sig) in work.iter().zip(&sig) {
        verdicts.push(verdict(w, sig, a_rec, alpha));
    }
    // A mimic of a parameter with a verdict is that parameter's shadow, not physics.
    for (i, m) in mimic.iter().enumerate() {
        if let Some(j) = m
            && verdicts[*j] != "none"
        {
            verdicts[i] = "none";
        }
    }
    let mut effects = Vec::new();
    let mut outliers = Vec::new();
    for (w, verdict) in work.into_iter().zip(verdicts) {
        let out_serial = |r: &Row| w.outliers.iter().any(|o| o.0 == r.serial);
        for (serial, value, u) in &w.outliers {
            outliers.push(Outlier {
                serial: serial.clone(),
                effect: w.key.0.clone(),
                parameter: w.key.1.clone(),
                value: *value,
                u: *u,
            });
        }
        if verdict == "none" && !w.rows.iter().any(|r| r.found) {
            continue;
        }
        let leaves = matches!(verdict, "model" | "pooled_only");
        let pool = if leaves { w.clean } else { w.all };
        effects.push(PooledOut {
            effect: w.key.0,
            parameter: w.key.1,
            pooled: pool.mean,
            u: pool.u,
            spread: pool.tau,
            i2: pool.i2,
            verdict: verdict.into(),
            left_out: match leaves {
                true => w
                    .rows
                    .iter()
                    .filter(|r| out_serial(r))
                    .map(|r| r.run.clone())
                    .collect(),
                false => Vec::new(),
            },
            per_recording: w
                .rows
                .iter()
                .map(|r| PerRecording {
                    run: r.run.clone(),
                    serial: r.serial.clone(),
                    value: r.value,
                    u: r.u,
                })
                .collect(),
            unit: w.unit,
        });
    }
    effects.sort_by_key(|e| rank(&e.verdict));
    (effects, outliers)
}

/// One parameter's rows, outliers and pools.
struct Work {
    key: (String, String),
    unit: String,
    channel: Option<String>,
    rows: Vec<Row>,
    outliers: Vec<(String, f64, f64)>,
    clean: Pooled,
    all: Pooled,
}

/// The verdict of `w` (`sig`: the pool is significant; `a_rec`: a recording's threshold).
fn verdict(w: &Work, sig: bool, a_rec: f64, alpha: f64) -> &'static str {
    let passes = |r: &Row| p_normal(r.value / r.u) < a_rec;
    let out_serial = |r: &Row| w.outliers.iter().any(|o| o.0 == r.serial);
    let kept: Vec<&Row> = w.rows.iter().filter(|r| !out_serial(r)).collect();
    let kept_pass = kept.iter().any(|r| passes(r));
    let kept_serials = distinct(kept.iter().map(|r| r.serial.as_str()));
    let consistent =
        w.clean.dof == 0 || super::super::stats::p_value(w.clean.q, w.clean.dof) >= alpha;
    if is_unit(&w.rows, &passes) {
        "unit"
    } else if sig && kept_pass && kept_serials.len() >= 2 && consistent {
        "model"
    } else if sig && !kept_pass {
        "pooled_only"
    } else if w.rows.iter().any(passes) {
        "occasional"
    } else {
        "none"
    }
}

/// Recordings in common below which two parameters are not compared.
const MIMIC_COMMON: usize = 4;
/// Correlation of the standardized values at and above which one parameter mimics another.
const MIMIC_CORR: f64 = 0.9;

/// How much stronger (pooled |z|) a parameter must be to take the verdict of one that
/// mimics it; between these two, both keep theirs: the recordings cannot tell them apart.
const MIMIC_STRONGER: f64 = 1.5;
/// Correlation at and above which a library form is the same as a registry effect (its
/// column: `form_accel_f2` and `accel_second_order`), which then takes the verdict.
const SAME_CORR: f64 = 0.99;

/// For each parameter, the parameter it mimics, if any: on the same channel, its
/// standardized values (value / u) over the recordings both have, neither found there,
/// correlate with the other's by [`MIMIC_CORR`] or more (where one is in the final model,
/// the other, fitted beside it, is left nothing), and the other's pool stands out
/// [`MIMIC_STRONGER`] times more (a K2 and a scale asymmetry on attitudes of +-1 g and
/// 0 g); or it is a library form the same as a registry effect ([`SAME_CORR`]).
fn mimics(work: &[Work]) -> Vec<Option<usize>> {
    let strength = |w: &Work| (w.clean.mean / w.clean.u).abs();
    let form = |w: &Work| w.key.0.starts_with("form_");
    let zs: Vec<BTreeMap<&str, f64>> = work
        .iter()
        .map(|w| {
            (w.rows.iter())
                .filter(|r| !r.found)
                .map(|r| (r.run.as_str(), r.value / r.u))
                .collect()
        })
        .collect();
    (0..work.len())
        .map(|i| {
            (0..work.len())
                .filter(|&j| {
                    j != i && work[i].channel.is_some() && work[i].channel == work[j].channel
                })
                .filter(|&j| {
                    let Some(c) = correlation(&zs[i], &zs[j]) else {
                        return false;
                    };
                    let (si, sj) = (strength(&work[i]), strength(&work[j]));
                    (c >= MIMIC_CORR && sj >= MIMIC_STRONGER * si)
                        || (c >= SAME_CORR && form(&work[i]) && !form(&work[j]))
                })
                .max_by(|&a, &b| strength(&work[a]).total_cmp(&strength(&work[b])))
        })
        .collect()
}

/// Pearson correlation over the keys both maps hold (`None` under [`MIMIC_COMMON`] of
/// them, or without variation).
fn correlation(a: &BTreeMap<&str, f64>, b: &BTreeMap<&str, f64>) -> Option<f64> {
    let pairs: Vec<(f64, f64)> = a
        .iter()
        .filter_map(|(k, x)| b.get(k).map(|y| (*x, *y)))
        .collect();
    if pairs.len() < MIMIC_COMMON {
        return None;
    }
    let n = pairs.len() as f64;
    let (mx, my) = pairs
        .iter()
        .fold((0.0, 0.0), |s, p| (s.0 + p.0 / n, s.1 + p.1 / n));
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (x, y) in &pairs {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

/// Most recurring first.
fn rank(verdict: &str) -> usize {
    ["model", "unit", "pooled_only", "occasional", "none"]
        .iter()
        .position(|v| *v == verdict)
        .unwrap_or(5)
}

/// The distinct values, in order of first appearance.
pub(super) fn distinct<'a>(it: impl Iterator<Item = &'a str>) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for s in it {
        if !out.contains(&s) {
            out.push(s);
        }
    }
    out
}

/// Whether one serial with at least two recordings passes in every one of them, and no
/// recording of another serial passes.
fn is_unit(rows: &[Row], passes: &dyn Fn(&Row) -> bool) -> bool {
    let serials = distinct(rows.iter().map(|r| r.serial.as_str()));
    serials.iter().any(|s| {
        let own: Vec<&Row> = rows.iter().filter(|r| r.serial == *s).collect();
        own.len() >= 2
            && own.iter().all(|r| passes(r))
            && rows.iter().filter(|r| r.serial != *s).all(|r| !passes(r))
    })
}

/// A serial's value: its recordings' weighted mean and its u.
fn serial_value(rows: &[&Row]) -> (f64, f64) {
    let w: f64 = rows.iter().map(|r| 1.0 / (r.u * r.u)).sum();
    let y = rows.iter().map(|r| r.value / (r.u * r.u)).sum::<f64>() / w;
    (y, (1.0 / w).sqrt())
}

/// The serials whose value lies outside the spread of the others (leave one serial out:
/// its distance from the others' pool over its u, their pool's u and their spread,
/// two-sided p below `a`), worst first, one at a time, at most a third of the serials;
/// a fleet of fewer than three serials has none. (serial, value, u).
fn outliers(rows: &[Row], a: f64) -> Vec<(String, f64, f64)> {
    let serials = distinct(rows.iter().map(|r| r.serial.as_str()));
    let mut out: Vec<(String, f64, f64)> = Vec::new();
    while serials.len() >= 3 && out.len() < serials.len() / 3 {
        let live = |r: &&Row| out.iter().all(|o| o.0 != r.serial);
        let worst = serials
            .iter()
            .filter(|s| out.iter().all(|o| o.0 != **s))
            .filter_map(|s| {
                let own: Vec<&Row> = rows.iter().filter(|r| r.serial == *s).collect();
                let others: Vec<Obs> = (rows.iter().filter(live))
                    .filter(|r| r.serial != *s)
                    .map(Row::obs)
                    .collect();
                let pool = dersimonian_laird(&others)?;
                let (y, u) = serial_value(&own);
                let z = (y - pool.mean) / (u * u + pool.u * pool.u + pool.tau * pool.tau).sqrt();
                z.is_finite().then_some((s.to_string(), y, u, z.abs()))
            })
            .max_by(|a, b| a.3.total_cmp(&b.3));
        match worst {
            Some((s, y, u, z)) if p_normal(z) < a => out.push((s, y, u)),
            _ => break,
        }
    }
    out
}
