//! Where a finding shows (segments, channels, spans, what the residual follows), and which
//! other candidates the data cannot tell apart from it.

use super::data::Data;
use super::model::{Terms, fit};
use super::output::{Located, SegmentRms};
use super::select::Step;
use crate::fit::joint::{CHANNELS, seg_rss};
use crate::recording::Manifest;

/// Most entries reported per finding.
const MOST: usize = 8;

/// The segments and channels whose residual the effect reduced most, in units of the
/// channel's noise (a reduction under 9, three standard deviations, is not listed unless
/// nothing reaches it).
pub(crate) fn locate(m: &Manifest, data: &Data, step: &Step) -> Vec<Located> {
    let mut rows: Vec<(f64, Located)> = rows(m, data, step)
        .into_iter()
        .filter(|r| r.0 > 0.0)
        .collect();
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    let strong = rows.iter().filter(|r| r.0 >= 9.0).count().max(1);
    rows.into_iter()
        .take(strong.min(MOST))
        .map(|r| r.1)
        .collect()
}

/// Residual RMS before and after the step on every segment and channel with data, in
/// recording order (the finding's figure).
pub(crate) fn per_segment(m: &Manifest, data: &Data, step: &Step) -> Vec<SegmentRms> {
    rows(m, data, step)
        .into_iter()
        .map(|(_, l)| SegmentRms {
            segment: l.segment,
            channel: l.channel,
            rms_before: l.rms_before,
            rms_after: l.rms_after,
            held_out: l.held_out,
        })
        .collect()
}

/// Every segment and channel with data: the residual sum of squares the step removed, in
/// units of the channel's noise variance, and the entry.
fn rows(m: &Manifest, data: &Data, step: &Step) -> Vec<(f64, Located)> {
    let fx = data.layout.effects[step.effect];
    let mut rows = Vec::new();
    for (i, acc) in data.accs.iter().enumerate() {
        for c in 0..6 {
            let sig = step.after.noise[c].sigma;
            if sig <= 0.0 || acc.n == 0 {
                continue;
            }
            let before = seg_rss(acc, &data.layout, c, &step.before.theta);
            let after = seg_rss(acc, &data.layout, c, &step.after.theta);
            let seg = &m.segments[acc.seg];
            rows.push((
                (before - after) / (sig * sig),
                Located {
                    segment: seg.id.clone(),
                    channel: CHANNELS[c].into(),
                    t_start: seg.t_start,
                    t_end: seg.t_end,
                    rms_before: (before / acc.n as f64).sqrt(),
                    rms_after: (after / acc.n as f64).sqrt(),
                    correlates_with: fx.follows().into(),
                    held_out: data.held.contains(&i),
                },
            ));
        }
    }
    rows
}

/// Candidates that, fitted beside `effect`, lose parameters to it (or it to them): their
/// columns are (nearly) collinear with its own, so this recording cannot tell the two
/// apart.
pub(crate) fn confusions(data: &Data, terms: &Terms, effect: usize) -> Vec<String> {
    let lay = &data.layout;
    let work = data.working();
    let mut without = terms.clone();
    without.effects.retain(|e| *e != effect);
    let mine: Vec<usize> = lay.columns_of(effect).collect();
    let mut out = Vec::new();
    for &e in &data.candidates {
        if terms.effects.contains(&e) {
            continue;
        }
        let theirs: Vec<usize> = lay.columns_of(e).collect();
        let mut alone = without.clone();
        alone.effects.push(e);
        let (_, un_alone) = fit(data, &alone, &work, &work);
        let mut both = terms.clone();
        both.effects.push(e);
        let (f, un) = fit(data, &both, &work, &work);
        let lost = theirs
            .iter()
            .any(|g| un.contains(g) && !un_alone.contains(g));
        let tight = mine.iter().any(|&g| {
            theirs
                .iter()
                .any(|&h| f.estimated.contains(&h) && f.corr(g, h).abs() > 0.95)
        });
        if lost || tight {
            out.push(lay.effects[e].id().to_string());
        }
    }
    out
}
