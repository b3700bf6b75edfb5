//! At rest the three channels of a sensor fold the same few functions of time: a decay or a
//! drift is one value on all three axes, and a thermal or scale-drift term is a constant
//! multiple of one (the attitude's specific force or rate times the temperature or the
//! time) while the attitude holds. A stretch of rows at rest is folded once per sensor, over
//! those functions and the three observations, and each channel's factor is recovered from
//! the sensor's when the stretch ends: the factor of chosen columns of a matrix, each scaled,
//! is the triangle of the same columns of its factor, scaled.
//!
//! Which function each channel's column is a multiple of is read from the first rows of a
//! stretch ([`PROBE_ROWS`], folded channel by channel) and checked on every row after it: a
//! row whose columns are not those multiples (to a few units in the last place) ends the
//! stretch, and rows go channel by channel again until the next one is found. So the factor
//! is that of the rows, whatever the effects are.

use super::tri::{Tri, triangle};
use nalgebra::DMatrix;

/// Rows at rest read before a stretch's functions are chosen.
const PROBE_ROWS: usize = 8;

/// Largest difference, relative to the column's value, between a column and its multiple of
/// a shared function: the rounding of a product and of the ratio that found it.
const TOL: f64 = 16.0 * f64::EPSILON;

/// One sensor's channels at rest: the stretch being folded, the rows read to find the next
/// one, and per channel the factor of the stretches folded so far.
#[derive(Debug, Default)]
pub(super) struct Rest {
    /// Per channel, per moving position (the observation left out), its values in the rows
    /// read so far.
    probe: [Vec<Vec<f64>>; 3],
    probed: usize,
    stretch: Option<Stretch>,
    /// Whether the rows read showed nothing to share: tried again after the motion changes.
    hopeless: bool,
    done: [Option<DMatrix<f64>>; 3],
}

/// The channels' row positions: per channel, those that change at rest (the observation
/// last) and those that keep their value.
pub(super) struct Positions<'a> {
    pub moving: &'a [Vec<usize>],
    pub resting: &'a [Vec<usize>],
}

impl<'a> Positions<'a> {
    /// Sensor `s`'s three channels' positions, of the six channels' `moving` and `resting`.
    pub(super) fn sensor(
        moving: &'a [Vec<usize>; 6],
        resting: &'a [Vec<usize>; 6],
        s: usize,
    ) -> Self {
        let ch = 3 * s..3 * s + 3;
        Positions {
            moving: &moving[ch.clone()],
            resting: &resting[ch],
        }
    }
}

#[derive(Debug)]
struct Stretch {
    /// `(channel, position)` whose value each shared function takes, after the ones column.
    basis: Vec<(usize, usize)>,
    /// Per channel, per moving position (the observation left out): the shared column (0 is
    /// the ones column) and the multiple of it the position holds.
    map: [Vec<(usize, f64)>; 3],
    /// Per channel, the values of its resting positions through the stretch.
    still: [Vec<f64>; 3],
    /// What [`Stretch::fits`] checks, flat.
    checks: Vec<Check>,
    tri: Tri,
    row: Vec<f64>,
}

/// A moving position that must hold its multiple of a shared function.
#[derive(Debug)]
struct Check {
    channel: usize,
    position: usize,
    multiple: f64,
    /// The shared function's channel and position (`None`: the ones column).
    of: Option<(usize, usize)>,
}

impl Rest {
    /// A row at rest (`rows`: the sensor's three channels' rows, the observation last):
    /// `true` when the stretch took it, `false` when the channels fold it themselves.
    pub(super) fn take(&mut self, rows: &[Vec<f64>], at: &Positions) -> bool {
        if let Some(st) = &mut self.stretch {
            if st.fits(rows) {
                st.push(rows, at.moving);
                return true;
            }
            self.close(at);
        }
        if self.hopeless {
            return false;
        }
        for (l, probe) in self.probe.iter_mut().enumerate() {
            let m = &at.moving[l];
            probe.resize(m.len() - 1, Vec::new());
            for (i, &k) in m[..m.len() - 1].iter().enumerate() {
                probe[i].push(rows[l][k]);
            }
        }
        self.probed += 1;
        if self.probed == PROBE_ROWS {
            self.stretch = Stretch::find(&self.probe, rows, at);
            self.hopeless = self.stretch.is_none();
            self.reset_probe();
        }
        false
    }

    /// The motion changed (or the rows end): the stretch, if any, is folded into the
    /// channels' factors.
    pub(super) fn interrupt(&mut self, at: &Positions) {
        self.close(at);
        self.reset_probe();
        self.hopeless = false;
    }

    fn reset_probe(&mut self) {
        self.probed = 0;
        for p in self.probe.iter_mut().flatten() {
            p.clear();
        }
    }

    fn close(&mut self, at: &Positions) {
        let Some(st) = self.stretch.take() else {
            return;
        };
        for (l, f) in st.factors(at).into_iter().enumerate() {
            self.done[l] = Some(match self.done[l].take() {
                None => f,
                Some(d) => stack(&d, &f),
            });
        }
    }

    /// Channel `l`'s factor of every row folded in stretches, if there were any.
    pub(super) fn factor(&self, l: usize) -> Option<&DMatrix<f64>> {
        self.done[l].as_ref()
    }
}

/// The factor of the rows of two factors stacked.
pub(super) fn stack(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let w = a.ncols();
    let mut m = DMatrix::zeros(a.nrows() + b.nrows(), w);
    m.view_mut((0, 0), a.shape()).copy_from(a);
    m.view_mut((a.nrows(), 0), b.shape()).copy_from(b);
    triangle(m, w)
}

/// The multiple of `w` that `v` is, to [`TOL`] in every row, if it is one.
fn multiple(v: &[f64], w: &[f64]) -> Option<f64> {
    let (r, wr) = w
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
    if *wr == 0.0 {
        return v.iter().all(|x| *x == 0.0).then_some(0.0);
    }
    let a = v[r] / wr;
    v.iter().zip(w).all(|(v, w)| close(*v, a * w)).then_some(a)
}

/// Whether `v` is `aw` to within [`TOL`] of `v` (exactly, when `v` is zero).
fn close(v: f64, aw: f64) -> bool {
    (v - aw).abs() <= TOL * v.abs()
}

impl Stretch {
    /// The shared functions of the rows read (`probe`), if sharing them folds fewer
    /// products than the channels do apart; `rows` is the last row read.
    fn find(probe: &[Vec<Vec<f64>>; 3], rows: &[Vec<f64>], at: &Positions) -> Option<Stretch> {
        let ones = vec![1.0; PROBE_ROWS];
        let mut basis: Vec<(usize, usize)> = Vec::new();
        let mut map: [Vec<(usize, f64)>; 3] = Default::default();
        for (l, cols) in probe.iter().enumerate() {
            for (i, v) in cols.iter().enumerate() {
                let found = std::iter::once(&ones)
                    .chain(basis.iter().map(|&(bl, bi)| &probe[bl][bi]))
                    .enumerate()
                    .find_map(|(b, w)| multiple(v, w).map(|a| (b, a)));
                map[l].push(found.unwrap_or_else(|| {
                    basis.push((l, i));
                    (basis.len(), 1.0)
                }));
            }
        }
        let apart: usize = (0..3).map(|l| (probe[l].len() + 2).pow(2)).sum();
        let width = basis.len() + 4;
        if width * width >= apart {
            return None;
        }
        let basis: Vec<(usize, usize)> = basis
            .into_iter()
            .map(|(l, i)| (l, at.moving[l][i]))
            .collect();
        let checks = (0..3)
            .flat_map(|l| {
                map[l]
                    .iter()
                    .zip(&at.moving[l])
                    .map(move |(&(b, a), &k)| (l, k, b, a))
            })
            .filter(|&(l, k, b, a)| b == 0 || basis[b - 1] != (l, k) || a != 1.0)
            .map(|(l, k, b, a)| Check {
                channel: l,
                position: k,
                multiple: a,
                of: b.checked_sub(1).map(|j| basis[j]),
            })
            .collect();
        Some(Stretch {
            basis,
            checks,
            map,
            still: std::array::from_fn(|l| at.resting[l].iter().map(|&k| rows[l][k]).collect()),
            tri: Tri::new(width),
            row: vec![0.0; width],
        })
    }

    /// Whether every moving column of `rows` is its multiple of its shared function.
    fn fits(&self, rows: &[Vec<f64>]) -> bool {
        self.checks.iter().all(|c| {
            let w = c.of.map_or(1.0, |(l, k)| rows[l][k]);
            close(rows[c.channel][c.position], c.multiple * w)
        })
    }

    fn push(&mut self, rows: &[Vec<f64>], moving: &[Vec<usize>]) {
        let nb = self.basis.len() + 1;
        self.row[0] = 1.0;
        for (j, &(l, k)) in self.basis.iter().enumerate() {
            self.row[j + 1] = rows[l][k];
        }
        for l in 0..3 {
            self.row[nb + l] = rows[l][*moving[l].last().expect("the observation")];
        }
        self.tri.push_changed(&self.row, None);
    }

    /// Per channel, the factor of the stretch's rows over the channel's columns.
    fn factors(self, at: &Positions) -> [DMatrix<f64>; 3] {
        let nb = self.basis.len() + 1;
        let f = self.tri.finish();
        std::array::from_fn(|l| {
            let (moving, resting) = (&at.moving[l], &at.resting[l]);
            let w = moving.len() + resting.len();
            let mut m = DMatrix::zeros(f.nrows(), w);
            for (&k, &v) in resting.iter().zip(&self.still[l]) {
                m.set_column(k, &(f.column(0) * v));
            }
            for (&k, &(b, a)) in moving.iter().zip(&self.map[l]) {
                m.set_column(k, &(f.column(b) * a));
            }
            m.set_column(w - 1, &f.column(nb + l));
            triangle(m, w)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows of three channels at rest: two resting columns, a decay and a drift shared by
    /// all three, a thermal term that is a different multiple of the temperature on each
    /// (zero on one), and a column that keeps its multiple until row 300 and then leaves
    /// it. The factors (the stretches' and the rows the channels folded themselves) hold
    /// the rows' Gram matrix.
    #[test]
    fn stretches_fold_what_the_rows_fold() {
        let moving: Vec<Vec<usize>> = vec![vec![2, 3, 4, 5, 6]; 3];
        let resting: Vec<Vec<usize>> = vec![vec![0, 1]; 3];
        let at = Positions {
            moving: &moving,
            resting: &resting,
        };
        let mut rest = Rest::default();
        let mut tris: Vec<Tri> = (0..3).map(|_| Tri::new(7)).collect();
        let mut all: [Vec<f64>; 3] = Default::default();
        let f = [0.3, -1.7, 0.0];
        let mut shared = 0;
        for i in 0..1000 {
            let t = i as f64 * 0.01;
            let dt = 0.2 * (t * 0.9).sin() + 1e-3 * ((i * 7919) % 13) as f64;
            let rows: Vec<Vec<f64>> = (0..3)
                .map(|l| {
                    let late = if i < 300 { 2.0 * t } else { t * t };
                    let y = 0.1 * l as f64 + 1e-3 * t + 1e-4 * ((i * 31 + l * 17) % 11) as f64;
                    vec![9.81 * f[l], 1.0, (-t / 30.0).exp(), t, f[l] * dt, late, y]
                })
                .collect();
            if rest.take(&rows, &at) {
                shared += 1;
            } else {
                for (tri, row) in tris.iter_mut().zip(&rows) {
                    tri.push(row);
                }
            }
            for (a, row) in all.iter_mut().zip(&rows) {
                a.extend_from_slice(row);
            }
        }
        rest.interrupt(&at);
        assert!(shared > 900, "{shared} rows shared");
        for (l, tri) in tris.into_iter().enumerate() {
            let r = stack(&tri.finish(), rest.factor(l).expect("stretches"));
            let x = DMatrix::from_row_slice(1000, 7, &all[l]);
            let (g, h) = (x.transpose() * &x, r.transpose() * &r);
            assert!((&g - &h).norm() <= 1e-12 * g.norm(), "channel {l}: {g} {h}");
        }
    }

    #[test]
    fn a_multiple_is_found_to_the_last_places_only() {
        let w = [1.0, 2.0, 3.0, -4.0];
        assert_eq!(multiple(&[2.0, 4.0, 6.0, -8.0], &w), Some(2.0));
        assert_eq!(multiple(&[0.0; 4], &[0.0; 4]), Some(0.0));
        assert_eq!(multiple(&[0.0, 0.0, 1e-300, 0.0], &[0.0; 4]), None);
        assert_eq!(multiple(&[2.0, 4.0, 6.0 * (1.0 + 1e-13), -8.0], &w), None);
        assert_eq!(multiple(&[f64::NAN, 4.0, 6.0, -8.0], &w), None);
    }
}
