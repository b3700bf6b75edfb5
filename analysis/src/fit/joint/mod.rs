//! One joint least-squares over every output channel, built from the effect registry.
//!
//! A [`Layout`] lists the terms that may enter a model (registry effects) and gives each
//! parameter a column. An [`Accumulator`] passes once over a segment's samples and keeps, per
//! output channel, the triangular factor of `[X y]` over that channel's columns plus short
//! block sums for the noise analysis. Any model (a subset of columns) over any set of
//! segments is then solved from those factors alone ([`solve`]): forward selection and
//! held-out checks refit the whole model at each step without touching the samples again.

mod accumulate;
mod noise;
mod rest;
mod solve;
mod terms;
mod tri;

pub(crate) use accumulate::{Accumulator, SegAcc, seg_rss};
pub(crate) use noise::Whitener;
pub(crate) use solve::{Fit, FitRequest, Pooled, WanderRule, rss_on, solve};
pub(crate) use terms::{Terms, excitation, excites, fit_terms, fit_terms_merged, latitude_of};

use ratecal_physics::effects::{Effect, Param, Sensor};

/// The six output channels: `ax ay az gx gy gz`.
pub(crate) const CHANNELS: [&str; 6] = ["ax", "ay", "az", "gx", "gy", "gz"];

/// Sensor and axis of channel `c`.
pub(crate) fn channel(c: usize) -> (Sensor, usize) {
    if c < 3 {
        (Sensor::Accel, c)
    } else {
        (Sensor::Gyro, c - 3)
    }
}

/// One column: a parameter of one effect of the layout.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Col {
    /// Index into [`Layout::effects`].
    pub effect: usize,
    /// Index into the effect's parameters.
    pub param: usize,
}

/// The terms a set of fits may use, and where each parameter sits.
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    /// Effects in column order.
    pub effects: Vec<&'static dyn Effect>,
    /// Every column.
    pub cols: Vec<Col>,
    /// For each channel, the global columns that act on it (ascending).
    pub by_channel: [Vec<usize>; 6],
    /// First column of each effect.
    pub first: Vec<usize>,
}

impl Layout {
    /// Columns for these effects.
    pub(crate) fn new(effects: Vec<&'static dyn Effect>) -> Self {
        let mut cols = Vec::new();
        let mut first = Vec::new();
        let mut by_channel: [Vec<usize>; 6] = Default::default();
        for (e, fx) in effects.iter().enumerate() {
            first.push(cols.len());
            for (p, prm) in fx.params().iter().enumerate() {
                let g = cols.len();
                cols.push(Col {
                    effect: e,
                    param: p,
                });
                for (c, list) in by_channel.iter_mut().enumerate() {
                    if acts_on(*fx, prm, c) {
                        list.push(g);
                    }
                }
            }
        }
        Layout {
            effects,
            cols,
            by_channel,
            first,
        }
    }

    /// The columns of one effect of the layout.
    pub(crate) fn columns_of(&self, e: usize) -> std::ops::Range<usize> {
        let a = self.first[e];
        a..a + self.effects[e].params().len()
    }

    /// The layout index of an effect id.
    pub(crate) fn index(&self, id: &str) -> Option<usize> {
        self.effects.iter().position(|e| e.id() == id)
    }

    /// The parameter of a column.
    pub(crate) fn param(&self, g: usize) -> &'static Param {
        let c = self.cols[g];
        &self.effects[c.effect].params()[c.param]
    }
}

fn acts_on(fx: &dyn Effect, p: &Param, c: usize) -> bool {
    let (s, ax) = channel(c);
    match p.channel {
        Some((ps, pa)) => ps == s && pa == ax,
        None => fx.sensors().contains(&s),
    }
}
