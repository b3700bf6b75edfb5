//! Time series of a few representative segments: the recording's output, the twin's
//! prediction as it is and updated, each as the IMU model's part of the output (the output
//! minus the ideal input the table feedback gives), in one-second means.
//!
//! Read from explain's single pass: every segment keeps its one-second block sums of the
//! observations and of every column's regressor, so the prediction of a block is its
//! regressor sums times the twin's coefficients, with no second pass over the samples.

use super::output::{Prediction, Series};
use crate::explain::data::Data;
use crate::fit::joint::CHANNELS;
use crate::recording::Manifest;
use nalgebra::DVector;

/// Segments shown per kind.
const PER_KIND: usize = 3;
/// Points per series at most: one-second blocks merged beyond it.
const POINTS: usize = 240;

/// The series of the segments where the twin disagrees most: for each segment kind among
/// `before.disagree`, its worst segments (at most three), each on its worst channel.
pub(super) fn pick(
    m: &Manifest,
    data: &Data,
    before: &Prediction,
    th_before: &DVector<f64>,
    th_after: &DVector<f64>,
) -> Vec<Series> {
    let mut chosen: Vec<(&str, &str, &str)> = Vec::new();
    for d in &before.disagree {
        let of_kind = chosen.iter().filter(|c| c.1 == d.kind).count();
        if of_kind < PER_KIND && !chosen.iter().any(|c| c.0 == d.segment) {
            chosen.push((&d.segment, &d.kind, &d.channel));
        }
    }
    // Kinds in the order their worst segment disagrees, segments worst first.
    let mut kinds: Vec<&str> = Vec::new();
    for c in &chosen {
        if !kinds.contains(&c.1) {
            kinds.push(c.1);
        }
    }
    let mut out = Vec::new();
    for kind in kinds {
        for (seg, _, ch) in chosen.iter().filter(|c| c.1 == kind) {
            let Some(c) = CHANNELS.iter().position(|x| x == ch) else {
                continue;
            };
            let Some(acc) = data.accs.iter().find(|a| m.segments[a.seg].id == *seg) else {
                continue;
            };
            out.push(of_segment(m, data, acc, c, th_before, th_after));
        }
    }
    out
}

/// One segment's channel `c`: its one-second blocks merged to at most [`POINTS`].
fn of_segment(
    m: &Manifest,
    data: &Data,
    acc: &crate::fit::joint::SegAcc,
    c: usize,
    th_before: &DVector<f64>,
    th_after: &DVector<f64>,
) -> Series {
    let seg = &m.segments[acc.seg];
    let cols = &data.layout.by_channel[c];
    let predicted = |sx: &[f64], th: &DVector<f64>| -> f64 {
        sx.iter().zip(cols).map(|(x, &g)| x * th[g]).sum()
    };
    let per = acc.blocks.len().div_ceil(POINTS).max(1);
    let mut s = Series {
        segment: seg.id.clone(),
        kind: super::predict::kind_name(seg.kind).into(),
        channel: CHANNELS[c].into(),
        t_s: Vec::new(),
        real: Vec::new(),
        before: Vec::new(),
        after: Vec::new(),
    };
    for bins in acc.blocks.chunks(per) {
        let n: usize = bins.iter().map(|b| b.n).sum();
        if n == 0 {
            continue;
        }
        let nf = n as f64;
        let t: f64 = bins.iter().map(|b| b.t * b.n as f64).sum::<f64>() / nf;
        let real: f64 = bins.iter().map(|b| b.sy[c]).sum::<f64>() / nf;
        let before: f64 = bins
            .iter()
            .map(|b| predicted(&b.sx[c], th_before))
            .sum::<f64>()
            / nf;
        let after: f64 = bins
            .iter()
            .map(|b| predicted(&b.sx[c], th_after))
            .sum::<f64>()
            / nf;
        s.t_s.push(t - seg.t_start);
        s.real.push(real);
        s.before.push(before);
        s.after.push(after);
    }
    s
}
