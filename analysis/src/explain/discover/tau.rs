//! A discovered decay's time constant from the profile of the misfit (docs/explain.md,
//! "Discovered"): the model is refitted with the decay at every time constant of a dense
//! grid in `ln tau`, the misfit measured in units of the honest noise (white noise with its
//! correlation and the wandering bias), and `tau_s` is where it is least, its uncertainty
//! where it has risen by one.
//!
//! A decay at an arbitrary time constant is not a column the samples were accumulated
//! with, so the refit works on the one-second blocks: per block the means of the channel's
//! regressors and output, and the decay's value at the block's mean stamp (the grid
//! decay's block mean rescaled, `exp(-(t - t0) (1/tau - 1/tau_grid))`). Within a block of
//! one second the decay changes by `1/tau`, so the approximation's relative error is about
//! `1 / (24 tau^2)`: below 1e-4 from 15 s on. The wandering bias makes the block means'
//! covariance dense; a Kalman filter ([`Whitener`]) whitens them in one pass.

use super::super::data::Data;
use super::super::model::{Terms, fit};
use super::super::probe::{Form, Probe};
use super::{Refined, channel_of};
use crate::fit::joint::{Fit, Whitener};

/// Step of the profile's grid in `ln tau`.
const STEP: f64 = 0.02;
/// The profile reaches down to this fraction of the library's shortest time constant ...
const SHORTEST: f64 = 0.5;
/// ... and up to this multiple of the recording's span (beyond it a decay is a drift).
const LONGEST: f64 = 10.0;

/// One kept channel: its block means whitened by the honest noise, the model's other
/// columns projected out.
struct Channel {
    whiten: Whitener,
    /// Block mean stamps less the decay's `t0`, s.
    t: Vec<f64>,
    /// The grid decay's block means (its scale included).
    grid: Vec<f64>,
    /// Its time constant, s.
    tau_grid: f64,
    /// Orthonormal basis of the whitened columns of the rest of the model.
    basis: Vec<Vec<f64>>,
    /// The whitened output, the rest of the model projected out.
    y: Vec<f64>,
    /// Its sum of squares: the misfit with no decay.
    yy: f64,
}

/// What one channel's decay at a time constant does: (drop of the misfit, amplitude, its u
/// with the time constant known).
type At = (f64, f64, f64);

impl Channel {
    /// The channel of decay column `g` (of effect `best`, time constant `tau_grid`) over
    /// the working segments `work`, the rest of `center`'s model around it, whitened by
    /// `noise`'s honest noise.
    fn new(
        data: &Data,
        (center, noise): (&Fit, &Fit),
        work: &[usize],
        best: usize,
        g: usize,
        t0: f64,
    ) -> Self {
        let lay = &data.layout;
        let c = channel_of(data, g);
        let cols = &lay.by_channel[c];
        let own = lay.columns_of(best);
        let k_dec = cols
            .iter()
            .position(|&h| h == g)
            .expect("the decay's channel");
        // Free: the model's columns of this channel alone; shared ones are held.
        let free: Vec<usize> = (0..cols.len())
            .filter(|&k| center.estimated.contains(&cols[k]) && !own.contains(&cols[k]))
            .filter(|&k| lay.param(cols[k]).channel.is_some())
            .collect();
        let held: Vec<(usize, f64)> = (0..cols.len())
            .filter(|&k| !free.contains(&k) && !own.contains(&cols[k]))
            .map(|k| (k, center.theta[cols[k]]))
            .filter(|&(_, th)| th != 0.0)
            .collect();
        let mut blocks: Vec<_> = work.iter().flat_map(|&i| &data.accs[i].blocks).collect();
        blocks.sort_by(|a, b| a.t.total_cmp(&b.t));
        let mean = |sx: &[f64], n: usize, k: usize| sx[k] / n.max(1) as f64;
        let ts: Vec<f64> = blocks.iter().map(|b| b.t).collect();
        let ns: Vec<usize> = blocks.iter().map(|b| b.n).collect();
        let whiten = Whitener::new(&ts, &ns, &noise.noise[c]);
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for &k in &free {
            let x: Vec<f64> = blocks.iter().map(|b| mean(&b.sx[c], b.n, k)).collect();
            add_to_basis(&mut basis, whiten.apply(&x));
        }
        let y: Vec<f64> = blocks
            .iter()
            .map(|b| b.sy[c] - held.iter().map(|&(k, th)| b.sx[c][k] * th).sum::<f64>())
            .zip(&ns)
            .map(|(s, &n)| s / n.max(1) as f64)
            .collect();
        let y = project(&basis, whiten.apply(&y));
        let yy = y.iter().map(|v| v * v).sum();
        let tau_grid = match data.probe(best).map(|p| p.form) {
            Some(Form::Decay { tau, .. }) => tau,
            _ => f64::INFINITY,
        };
        Channel {
            whiten,
            t: ts.iter().map(|t| t - t0).collect(),
            grid: blocks.iter().map(|b| mean(&b.sx[c], b.n, k_dec)).collect(),
            tau_grid,
            basis,
            y,
            yy,
        }
    }

    /// The decay at time constant `tau`, s, refitted with the rest of the model.
    fn at(&self, tau: f64) -> At {
        let rate = 1.0 / tau - 1.0 / self.tau_grid;
        let d: Vec<f64> = (self.t.iter().zip(&self.grid))
            .map(|(t, g)| g * (-t * rate).exp())
            .collect();
        let d = project(&self.basis, self.whiten.apply(&d));
        let dd: f64 = d.iter().map(|v| v * v).sum();
        if dd <= 0.0 || !dd.is_finite() {
            return (0.0, 0.0, f64::INFINITY);
        }
        let dy: f64 = d.iter().zip(&self.y).map(|(a, b)| a * b).sum();
        (dy * dy / dd, dy / dd, 1.0 / dd.sqrt())
    }
}

/// `v` less its projection on the orthonormal `basis`.
fn project(basis: &[Vec<f64>], mut v: Vec<f64>) -> Vec<f64> {
    for q in basis {
        let a: f64 = q.iter().zip(&v).map(|(x, y)| x * y).sum();
        v.iter_mut().zip(q).for_each(|(x, y)| *x -= a * y);
    }
    v
}

/// Adds `v` to the orthonormal `basis` (Gram-Schmidt twice), unless the basis already
/// holds it (a column the block means cannot tell from the others).
fn add_to_basis(basis: &mut Vec<Vec<f64>>, v: Vec<f64>) {
    let norm0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let v = project(basis, project(basis, v));
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if norm > 1e-9 * norm0 && norm > 0.0 {
        basis.push(v.into_iter().map(|x| x / norm).collect());
    }
}

/// The profile: per point of the grid in `ln tau`, the misfit in units of the honest noise
/// (up to a constant).
struct Profile {
    x: Vec<f64>,
    misfit: Vec<f64>,
}

impl Profile {
    fn new(channels: &[Channel], lo: f64, hi: f64) -> Self {
        let n = ((hi - lo) / STEP).ceil().max(2.0) as usize;
        let x: Vec<f64> = (0..=n).map(|i| lo + i as f64 * STEP).collect();
        let misfit = (x.iter())
            .map(|x| -channels.iter().map(|ch| ch.at(x.exp()).0).sum::<f64>())
            .collect();
        Profile { x, misfit }
    }

    /// The profile from half the library's shortest time constant on `probe`'s sensor to
    /// ten times the recording's span.
    fn over_limits(data: &Data, probe: &Probe, channels: &[Channel]) -> Self {
        let (shortest, span) = limits(data, probe, channels);
        Profile::new(channels, (SHORTEST * shortest).ln(), (LONGEST * span).ln())
    }

    /// The least misfit: its `ln tau` (a parabola through the grid's neighbours) and value.
    fn least(&self) -> (usize, f64) {
        let i = (0..self.x.len())
            .min_by(|&a, &b| self.misfit[a].total_cmp(&self.misfit[b]))
            .expect("a grid");
        if i == 0 || i + 1 == self.x.len() {
            return (i, self.x[i]);
        }
        let (a, b, c) = (self.misfit[i - 1], self.misfit[i], self.misfit[i + 1]);
        let curv = a - 2.0 * b + c;
        let shift = if curv > 0.0 {
            0.5 * (a - c) / curv
        } else {
            0.0
        };
        (i, self.x[i] + shift.clamp(-0.5, 0.5) * STEP)
    }

    /// Where the misfit has risen by `rise` above `floor`, walking from point `i` in
    /// direction `dir` (the grid's end when it never does).
    fn rises(&self, i: usize, dir: isize, floor: f64, rise: f64) -> f64 {
        let mut j = i;
        loop {
            let next = j as isize + dir;
            if next < 0 || next as usize >= self.x.len() {
                return self.x[j];
            }
            let k = next as usize;
            if self.misfit[k] >= floor + rise {
                let (m0, m1) = (self.misfit[j], self.misfit[k]);
                let w = ((floor + rise - m0) / (m1 - m0)).clamp(0.0, 1.0);
                return self.x[j] + w * (self.x[k] - self.x[j]);
            }
            j = k;
        }
    }
}

/// A decay found at a grid time constant (effect `best`, channels `keep`, `terms` the model
/// with it): the time constant and the amplitudes from the profile of the misfit over the
/// time constant. The amplitudes' uncertainty holds the time constant's: how far each
/// moves between the ends of the time constant's interval.
pub(super) fn refine(
    data: &Data,
    terms: &Terms,
    best: usize,
    keep: &[usize],
    probe: &Probe,
) -> Option<Refined> {
    let Form::Decay { t0, .. } = probe.form else {
        return None;
    };
    let work = data.working();
    let (center, _) = fit(data, terms, &work, &work);
    let channels: Vec<Channel> = keep
        .iter()
        .map(|&g| Channel::new(data, (&center, &center), &work, best, g, t0))
        .collect();
    let profile = Profile::over_limits(data, probe, &channels);
    let (i, x) = profile.least();
    let floor = profile.misfit[i];
    let (lo, hi) = (
        profile.rises(i, -1, floor, 1.0),
        profile.rises(i, 1, floor, 1.0),
    );
    let tau_s = x.exp();
    let u_s = (tau_s - lo.exp()).max(hi.exp() - tau_s);
    let amplitudes = channels
        .iter()
        .map(|ch| {
            let (_, a, u) = ch.at(tau_s);
            let moved = [lo, hi].map(|x| (ch.at(x.exp()).1 - a).abs());
            (a, u.hypot(moved[0].max(moved[1])))
        })
        .collect();
    Some(Refined {
        tau_s,
        u_s,
        amplitudes,
    })
}

/// How much misfit (chi2, in units of the honest noise) the terms `with` remove beyond
/// `without` on the channels of decay `d` (found earlier, at a grid time constant), its
/// time constant profiled afresh in each: a later term must pay beyond the refinement of
/// the decay already held, or it is only the mismatch of the decay's grid time constant
/// (a sum of exponentials standing in for one).
pub(super) fn beyond(data: &Data, without: &Fit, with: &Fit, d: &super::Discovery) -> f64 {
    let Form::Decay { t0, .. } = d.probe.form else {
        return f64::INFINITY;
    };
    let work = data.working();
    let least = |center: &Fit| {
        let channels: Vec<Channel> = (d.columns.iter())
            .map(|&g| Channel::new(data, (center, without), &work, d.step.effect, g, t0))
            .collect();
        let profile = Profile::over_limits(data, d.probe, &channels);
        let (i, _) = profile.least();
        channels.iter().map(|ch| ch.yy).sum::<f64>() + profile.misfit[i]
    };
    least(without) - least(with)
}

/// The library's shortest time constant on the probe's sensor, and the recording's span
/// (from the decays' `t0` to the last block), s.
fn limits(data: &Data, probe: &Probe, channels: &[Channel]) -> (f64, f64) {
    let shortest = data
        .probes
        .iter()
        .filter(|(_, p)| p.sensor == probe.sensor)
        .filter_map(|(_, p)| match p.form {
            Form::Decay { tau, .. } => Some(tau),
            _ => None,
        })
        .fold(f64::INFINITY, f64::min);
    let span = channels
        .iter()
        .flat_map(|ch| ch.t.last().copied())
        .fold(1.0, f64::max);
    (shortest.min(span), span)
}
