//! The table feedback against its map: over each rate segment the angle must turn at the
//! rate the rate column reads (else the angle column is not in its declared unit), and the
//! rate column must read the segment's declared rate (else the rate column is not); each
//! segment must have feedback samples (else the clocks do not meet: `offset_s`).

use super::{RATE_RATIO, at_map, likely_unit};
use crate::error::{ErrorKind, ImportError};
use crate::map::{ImportMap, TableFeed};
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
                    &format!(
                        "segment `{}` ({span}) has no table feedback sample",
                        seg.id
                    ),
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
            if mean.abs() >= MIN_RATE_DPS && !ratio_ok(turned, mean) {
                let looks = likely_unit(turned.abs() / feed.angle.factor, mean.abs(), Dim::Angle);
                let help = match looks {
                    Some(u) if u != feed.angle.unit => format!(
                        "the angle columns look like {u}, not {}: set table.units.angle",
                        feed.angle.unit
                    ),
                    _ => "check table.units.angle and table.units.rate, and that the columns \
                          are the table's angle and rate"
                        .into(),
                };
                return Err(at_map(
                    map,
                    feed.angle.at.clone(),
                    ErrorKind::Units,
                    &format!(
                        "rate segment `{}` ({span}): the {axis} angle turns at {turned:.4} \
                         deg/s, but the {axis} rate column reads {mean:.4} deg/s",
                        seg.id
                    ),
                    &help,
                ));
            }
            if let Some(declared) = seg.rate_dps.filter(|r| r.abs() >= MIN_RATE_DPS)
                && !ratio_ok(mean, declared)
            {
                let looks = likely_unit(mean.abs() / feed.rate.factor, declared.abs(), Dim::Rate);
                let help = match looks {
                    Some(u) if u != feed.rate.unit => format!(
                        "the rate columns look like {u}, not {}: set table.units.rate",
                        feed.rate.unit
                    ),
                    _ => "check table.units.rate, the segment's axis (outer or inner) and its \
                          rate_dps"
                        .into(),
                };
                return Err(at_map(
                    map,
                    feed.rate.at.clone(),
                    ErrorKind::Units,
                    &format!(
                        "rate segment `{}` ({span}): the {axis} rate column reads {mean:.4} \
                         deg/s, the map declares {declared} deg/s",
                        seg.id
                    ),
                    &help,
                ));
            }
        }
        Ok(())
    }
}

fn ratio_ok(a: f64, b: f64) -> bool {
    let r = a / b;
    (RATE_RATIO.0..=RATE_RATIO.1).contains(&r)
}
