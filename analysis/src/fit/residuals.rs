//! Residuals of the joint fit on every accumulated segment and channel, from the segment's
//! triangular factors and one-second block sums alone (no second pass over the samples):
//! the mean from the block sums, the spread from the factor's residual sum of squares,
//! the trend from the block means.

use super::AXES;
use super::joint::{Layout, SegAcc, channel, seg_rss};
use crate::results::ResidualStats;
use nalgebra::DVector;
use ratecal_physics::effects::Sensor;

/// Residual statistics of channel `c` of a segment for the global coefficients `theta`.
pub(crate) fn of_segment(
    acc: &SegAcc,
    layout: &Layout,
    c: usize,
    theta: &DVector<f64>,
    id: &str,
) -> ResidualStats {
    let cols = &layout.by_channel[c];
    let block_sum =
        |sx: &[f64], sy: f64| sy - sx.iter().zip(cols).map(|(x, &g)| x * theta[g]).sum::<f64>();
    let n = acc.n as f64;
    let sum: f64 = acc
        .blocks
        .iter()
        .map(|b| block_sum(&b.sx[c], b.sy[c]))
        .sum();
    let mean = if acc.n > 0 { sum / n } else { 0.0 };
    let rss = seg_rss(acc, layout, c, theta);
    let std = if acc.n > 1 {
        ((rss - n * mean * mean).max(0.0) / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    // Trend: the block means against the block times, each block weighted by its samples.
    let tm: f64 = acc.blocks.iter().map(|b| b.t * b.n as f64).sum::<f64>() / n.max(1.0);
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for b in &acc.blocks {
        let w = b.n as f64;
        let m = block_sum(&b.sx[c], b.sy[c]) / w;
        sxx += w * (b.t - tm).powi(2);
        sxy += w * (b.t - tm) * (m - mean);
    }
    let (sensor, ax) = channel(c);
    let (name, unit) = match sensor {
        Sensor::Accel => ("accel", "m/s^2"),
        Sensor::Gyro => ("gyro", "deg/s"),
    };
    ResidualStats {
        segment: id.to_string(),
        sensor: name.into(),
        channel: AXES[ax].into(),
        n: acc.n,
        mean,
        std,
        slope_per_s: if sxx > 0.0 { sxy / sxx } else { 0.0 },
        unit: unit.into(),
    }
}

/// The worst axis's pooled residual standard deviation over residuals of one sensor (all
/// its samples about the model, segment means included), with its standard uncertainty.
pub(crate) fn pooled_worst<'a>(rs: impl Iterator<Item = &'a ResidualStats>) -> (f64, f64) {
    let mut per = [(0.0f64, 0usize); 3];
    for r in rs {
        let ax = AXES.iter().position(|a| *a == r.channel).unwrap_or(0);
        let n = r.n as f64;
        per[ax].0 += (n - 1.0).max(0.0) * r.std * r.std + n * r.mean * r.mean;
        per[ax].1 += r.n;
    }
    per.iter()
        .filter(|(_, n)| *n > 1)
        .map(|&(ss, n)| {
            let sd = (ss / (n - 1) as f64).sqrt();
            (sd, sd / (2.0 * (n - 1) as f64).sqrt())
        })
        .fold((0.0, 0.0), |w, x| if x.0 > w.0 { x } else { w })
}
