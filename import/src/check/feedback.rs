//! The table feedback against its map: over each rate segment the angle must turn at the
//! rate the rate column reads (else the angle column is not in its declared unit), and the
//! rate column must read the segment's declared rate (else the rate column is not); each
//! segment must have feedback samples (else the clocks do not meet: `offset_s`).

use super::{RATE_RATIO, at_map, likely_unit};
use crate::error::{ErrorKind, ImportError};
use crate::map::{ImportMap, Scale, TableFeed};
use ratecal_physics::units::Dim;
use ratecal_recording::{Segment, SegmentKind, TableSample};

type Res<T> = Result<T, Box<ImportError>>;

/// Below this the mean rate of a segment says nothing about the units, deg/s.
const MIN_RATE_DPS: f64 = 1.0;

#[derive(Debug, Clone, Copy, Default)]
struct Acc {
    n: u64,
    first: (f64, f64),
    last: (f64, f64),
    sum_rate: f64,
}

/// The feedback samples of each segment, gathered as the stream goes by.
pub struct Turns<'a> {
    segs: &'a [Segment],
    acc: Vec<Acc>,
    next: usize,
}

impl<'a> Turns<'a> {
    /// For the manifest's segments (in time order).
    pub fn new(segs: &'a [Segment]) -> Self {
        Turns {
            segs,
            acc: vec![Acc::default(); segs.len()],
            next: 0,
        }
    }

    /// One feedback sample (times increasing).
    pub fn add(&mut self, s: &TableSample) {
        while self.next < self.segs.len() && self.segs[self.next].t_end < s.t {
            self.next += 1;
        }
        let Some(seg) = self.segs.get(self.next) else {
            return;
        };
        if s.t < seg.t_start {
            return;
        }
        let outer = seg.axis.as_deref() != Some("inner");
        let (angle, rate) = if outer {
            (s.outer_deg, s.outer_rate_dps)
        } else {
            (s.inner_deg, s.inner_rate_dps)
        };
        let a = &mut self.acc[self.next];
        if a.n == 0 {
            a.first = (s.t, angle);
        }
        a.last = (s.t, angle);
        a.n += 1;
        a.sum_rate += rate;
    }

    /// Refuses the first segment the feedback contradicts.
    pub fn check(&self, map: &ImportMap, feed: &TableFeed) -> Res<()> {
        for (seg, a) in self.segs.iter().zip(&self.acc) {
            let span = format!("t {} to {} s", seg.t_start, seg.t_end);
            if a.n == 0 {
                return Err(at_map(
                    map,
                    feed.at.clone(),
                    ErrorKind::Segment,
                    &format!("segment `{}` ({span}) has no table feedback sample", seg.id),
                    "the feedback's time must cover the segments on the IMU's clock: check \
                     table.time and table.offset_s (added to the feedback's time)",
                ));
            }
            if seg.kind != SegmentKind::Rate || a.n < 2 {
                continue;
            }
            let axis = seg.axis.as_deref().unwrap_or("outer");
            let mean = a.sum_rate / a.n as f64;
            let turned = (a.last.1 - a.first.1) / (a.last.0 - a.first.0);
            // The declared rate says which column is off; without one, the angle is blamed
            // against the rate column.
            let declared = seg.rate_dps.filter(|r| r.abs() >= MIN_RATE_DPS);
            let reference = declared.unwrap_or(mean);
            if reference.abs() >= MIN_RATE_DPS && !ratio_ok(turned, reference) {
                let against = match declared {
                    Some(d) => format!("the map declares {d} deg/s"),
                    None => format!("the {axis} rate column reads {mean:.4} deg/s"),
                };
                return Err(unit_error(
                    map,
                    &feed.angle,
                    Dim::Angle,
                    (turned, reference),
                    &format!(
                        "rate segment `{}` ({span}): the {axis} angle turns at {turned:.4} \
                         deg/s, {against}",
                        seg.id
                    ),
                    "table.units.angle",
                ));
            }
            if let Some(d) = declared
                && !ratio_ok(mean, d)
            {
                return Err(unit_error(
                    map,
                    &feed.rate,
                    Dim::Rate,
                    (mean, d),
                    &format!(
                        "rate segment `{}` ({span}): the {axis} rate column reads {mean:.4} \
                         deg/s, the map declares {d} deg/s",
                        seg.id
                    ),
                    "table.units.rate",
                ));
            }
        }
        Ok(())
    }
}

/// A unit refusal at `scale`'s place in the map, naming the unit that would fit.
fn unit_error(
    map: &ImportMap,
    scale: &Scale,
    dim: Dim,
    (got, want): (f64, f64),
    what: &str,
    key: &str,
) -> Box<ImportError> {
    let help = match likely_unit(got.abs() / scale.factor, want.abs(), dim) {
        Some(u) if u != scale.unit => format!(
            "the {} columns look like {u}, not {}: set {key}",
            if dim == Dim::Angle { "angle" } else { "rate" },
            scale.unit
        ),
        _ => format!(
            "check {key}, the segment's axis (outer or inner) and its rate_dps, and that the \
             columns are the table's angles and rates"
        ),
    };
    at_map(map, scale.at.clone(), ErrorKind::Units, what, &help)
}

fn ratio_ok(a: f64, b: f64) -> bool {
    let r = a / b;
    (RATE_RATIO.0..=RATE_RATIO.1).contains(&r)
}
