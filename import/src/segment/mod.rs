//! Segments: the declared ones followed while the samples stream past, or the static
//! intervals found from the signal ([`detect`]); then the table stream synthesized from
//! their attitudes ([`table`]).

mod attitude;
pub mod detect;
mod stats;
pub mod table;

pub use attitude::{face_up, turn};
pub use stats::{Stretch, Thinned, norm};

use crate::error::{ErrorKind, ImportError, Say};
use crate::map::{Attitude, DeclSegment, ImportMap, RateAxis, SegRange, Segments, Turn, Up};
use crate::read::RowAt;
use ratecal_recording::SegmentKind;

/// A segment with the samples it took.
#[derive(Debug, Clone)]
pub struct Found {
    /// Id.
    pub id: String,
    /// Kind.
    pub kind: SegmentKind,
    /// Its samples.
    pub stretch: Stretch,
    /// Up axis (static).
    pub up: Option<Up>,
    /// Axis and rate (rate).
    pub rate: Option<(RateAxis, f64)>,
    /// Axis and nominal angle (turn).
    pub turn: Option<Turn>,
    /// The attitude the map declared (static; `None`: the default, see the write).
    pub attitude: Option<Attitude>,
    /// Index of the declaring entry in the map (`None` when detected).
    pub decl: Option<usize>,
}

/// Follows the map's segments over the stream.
pub struct Tracker {
    decl: Vec<DeclSegment>,
    stats: Vec<Stretch>,
    cur: usize,
    blocks: Option<detect::Blocks>,
}

impl Tracker {
    /// For the map's segments (declared or to be detected).
    pub fn new(map: &ImportMap) -> Self {
        let (decl, blocks) = match &map.segments {
            Segments::None => (Vec::new(), None),
            Segments::List(v) => (v.clone(), None),
            Segments::Detect(d) => (Vec::new(), Some(detect::Blocks::new(d.window_s))),
        };
        Tracker {
            stats: vec![Stretch::default(); decl.len()],
            decl,
            cur: 0,
            blocks,
        }
    }

    /// One converted sample.
    #[inline]
    pub fn add(&mut self, at: RowAt, t: f64, f: &[f64; 3], w: &[f64; 3]) {
        if let Some(b) = &mut self.blocks {
            b.add(at, t, f, w);
            return;
        }
        let (i, n) = (at.sample, self.decl.len());
        while self.cur < n && past(&self.decl[self.cur].range, i, t) {
            self.cur += 1;
        }
        if self.cur < n && contains(&self.decl[self.cur].range, i, t) {
            self.stats[self.cur].add(i, at.line, t, f, w);
        }
    }

    /// The segments found, in time order; a declared segment outside the data or
    /// overlapping another is refused, located in the map.
    pub fn finish(self, map: &ImportMap, all: &Stretch) -> Result<Vec<Found>, Box<ImportError>> {
        if let (Some(b), Segments::Detect(d)) = (self.blocks, &map.segments) {
            return Ok(b.detect(d));
        }
        let mut out: Vec<Found> = Vec::with_capacity(self.decl.len());
        for (k, (d, s)) in self.decl.iter().zip(self.stats).enumerate() {
            let outside = match d.range {
                SegRange::Samples(_, to) => to > all.n,
                SegRange::Time(t0, t1) => all.n == 0 || t0 < all.t.0 || t1 > all.t.1 + span_dt(all),
            };
            if outside || s.n == 0 {
                let data = if all.n == 0 {
                    "the sources hold no samples".to_string()
                } else {
                    format!(
                        "the data hold samples 0..{} (t = {} to {} s)",
                        all.n, all.t.0, all.t.1
                    )
                };
                let what = if outside {
                    format!("segment `{}` lies outside the data: {data}", d.id)
                } else {
                    format!(
                        "segment `{}` takes no sample: it overlaps another ({data})",
                        d.id
                    )
                };
                return Err(seg_error(map, d, &what));
            }
            if let Some(prev) = out.last()
                && prev.stretch.samples.1 >= s.samples.0
            {
                let what = format!("segment `{}` overlaps `{}`", d.id, prev.id);
                return Err(seg_error(map, d, &what));
            }
            out.push(Found {
                id: d.id.clone(),
                kind: d.kind,
                stretch: s,
                up: d.up,
                rate: d.rate,
                turn: d.turn,
                attitude: d.attitude,
                decl: Some(k),
            });
        }
        Ok(out)
    }
}

/// A typical sample interval of the whole stream (for a time range's end).
fn span_dt(all: &Stretch) -> f64 {
    if all.n < 2 {
        0.0
    } else {
        (all.t.1 - all.t.0) / (all.n - 1) as f64
    }
}

fn seg_error(map: &ImportMap, d: &DeclSegment, what: &str) -> Box<ImportError> {
    ImportError::in_text(
        ErrorKind::Segment,
        &map.file,
        &map.text,
        d.range_at.clone(),
        Say {
            what,
            label: "this range",
            help: "samples: [from, to) counts 0-based samples after the header; time: [t0, t1) \
                   is in seconds of the stream's clock; segments may not overlap",
        },
    )
}

#[inline]
fn past(r: &SegRange, i: u64, t: f64) -> bool {
    match *r {
        SegRange::Samples(_, to) => i >= to,
        SegRange::Time(_, t1) => t >= t1,
    }
}

#[inline]
fn contains(r: &SegRange, i: u64, t: f64) -> bool {
    match *r {
        SegRange::Samples(from, to) => from <= i && i < to,
        SegRange::Time(t0, t1) => t0 <= t && t < t1,
    }
}
