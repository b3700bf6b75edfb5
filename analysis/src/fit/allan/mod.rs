//! Overlapping Allan deviation of the gyros over a static block: angle random walk at
//! tau = 1 s and bias instability (minimum of the curve / 0.664).

mod spill;
mod stream;

pub(crate) use spill::Spill;

use super::{AXES, Out};
use crate::results::{AllanCurve, Parameter};
use spill::OnFile;
use std::io;
use std::sync::Arc;

/// Overlapping Allan deviation of `y` sampled every `dt`, at octave cluster sizes
/// `m = 1, 2, 4, ...` up to a quarter of the series: `(tau, adev, clusters)`.
pub fn overlapping_adev(y: &[f64], dt: f64) -> Vec<(f64, f64, usize)> {
    adev_of_rates(vec![y.to_vec()], dt)
}

/// A block's kept gyro samples per axis, in the chunks its windows kept (in order): a
/// long block's windows are passed side by side, and a 1 kHz hour is 29 MB an axis, so
/// the chunks are never copied into one. With a [`Spill`] each chunk goes to the scratch
/// file as it comes (`spill.rs`), and the series holds where.
#[derive(Debug, Clone, Default)]
pub(crate) struct Series {
    chunks: Vec<[Part; 3]>,
    spill: Option<Arc<Spill>>,
}

/// One axis's part of a chunk.
#[derive(Debug, Clone)]
enum Part {
    /// In memory (no scratch file, or a write to it failed).
    Held(Vec<f64>),
    /// `len` values in the scratch file from byte `at`.
    Spilled { at: u64, len: usize },
}

impl Part {
    fn len(&self) -> usize {
        match self {
            Part::Held(v) => v.len(),
            Part::Spilled { len, .. } => *len,
        }
    }
}

impl Series {
    /// An empty series whose chunks go to `spill` (in memory without).
    pub(crate) fn new(spill: Option<Arc<Spill>>) -> Series {
        Series {
            chunks: Vec::new(),
            spill,
        }
    }

    /// A window's kept samples, after those already held.
    pub(crate) fn push(&mut self, chunk: [Vec<f64>; 3]) {
        let spill = self.spill.as_deref();
        self.chunks.push(chunk.map(|c| {
            match spill.filter(|_| !c.is_empty()).and_then(|s| s.write(&c)) {
                Some(at) => Part::Spilled { at, len: c.len() },
                None => Part::Held(c),
            }
        }));
    }

    /// The samples of the windows that follow.
    pub(crate) fn append(&mut self, later: Series) {
        self.chunks.extend(later.chunks);
        self.spill = self.spill.take().or(later.spill);
    }
}

/// The curve of a rate series held in chunks, integrated in their own memory: sample `i`
/// becomes the angle `theta[i + 1]` (`theta[0] = 0` is left implicit, so nothing grows).
fn adev_of_rates(mut chunks: Vec<Vec<f64>>, dt: f64) -> Vec<(f64, f64, usize)> {
    integrate(&mut chunks, dt);
    let c = Chunked::new(&chunks);
    let sums: Vec<f64> = (groups(c.len).into_iter())
        .flat_map(|g| {
            let Ok(s) = group_sums(&c, g);
            s
        })
        .collect();
    curve(c.len, &sums, dt)
}

/// The rates of `chunks` (the empty ones left out) to angles, in place.
fn integrate(chunks: &mut Vec<Vec<f64>>, dt: f64) {
    chunks.retain(|c| !c.is_empty());
    let mut acc = 0.0;
    for v in chunks.iter_mut().flatten() {
        acc += *v * dt;
        *v = acc;
    }
}

/// An integrated series the sums read: value `i` is the angle `theta[i + 1]`.
trait Theta: Sync {
    type Error: Send;

    /// Values in the series.
    fn len(&self) -> usize;

    /// Value `i`.
    fn at(&self, i: usize) -> Result<f64, Self::Error>;

    /// Adds to `s[j]` the squared second differences at cluster size `ms[j]` for `k` in
    /// `[k, end)`, in order of `k`.
    fn sweep<const N: usize>(
        &self,
        ms: [usize; N],
        s: &mut [f64; N],
        k: usize,
        end: usize,
    ) -> Result<(), Self::Error>;
}

/// One series read across its chunks.
struct Chunked<'a> {
    chunks: &'a [Vec<f64>],
    /// Where each chunk starts in the series.
    starts: Vec<usize>,
    len: usize,
}

impl<'a> Chunked<'a> {
    fn new(chunks: &'a [Vec<f64>]) -> Self {
        let mut starts = Vec::with_capacity(chunks.len());
        let mut len = 0;
        for c in chunks {
            starts.push(len);
            len += c.len();
        }
        Chunked {
            chunks,
            starts,
            len,
        }
    }

    /// The series from index `i` to the end of the chunk that holds it.
    fn from(&self, i: usize) -> &'a [f64] {
        let c = self.starts.partition_point(|&s| s <= i) - 1;
        &self.chunks[c][i - self.starts[c]..]
    }
}

impl Theta for Chunked<'_> {
    type Error = std::convert::Infallible;

    fn len(&self) -> usize {
        self.len
    }

    fn at(&self, i: usize) -> Result<f64, Self::Error> {
        Ok(self.from(i)[0])
    }

    /// A run at a time within which no sample read leaves its chunk.
    fn sweep<const N: usize>(
        &self,
        ms: [usize; N],
        s: &mut [f64; N],
        mut k: usize,
        end: usize,
    ) -> Result<(), Self::Error> {
        while k < end {
            let a = self.from(k - 1);
            let b: [&[f64]; N] = std::array::from_fn(|j| self.from(k + ms[j] - 1));
            let e: [&[f64]; N] = std::array::from_fn(|j| self.from(k + 2 * ms[j] - 1));
            let lens = b.iter().chain(&e).map(|x| x.len());
            let run = lens.fold((end - k).min(a.len()), usize::min);
            add_run(&a[..run], b.map(|x| &x[..run]), e.map(|x| &x[..run]), s);
            k += run;
        }
        Ok(())
    }
}

/// Adds to `s[j]` the squared second differences `e[j][i] - 2 b[j][i] + a[i]`, in order of
/// `i` (the slices are as long as `a`).
fn add_run<const N: usize>(a: &[f64], b: [&[f64]; N], e: [&[f64]; N], s: &mut [f64; N]) {
    let b = b.map(|x| &x[..a.len()]);
    let e = e.map(|x| &x[..a.len()]);
    for (i, a) in a.iter().enumerate() {
        for j in 0..N {
            let d = e[j][i] - 2.0 * b[j][i] + a;
            s[j] += d * d;
        }
    }
}

/// Cluster sizes swept together over the series: each sum is a chain of additions that
/// waits on the one before, so four independent ones keep the adder busy.
const SWEPT: usize = 4;

/// The octave cluster sizes `m = 1, 2, 4, ...` up to a quarter of `n` samples.
fn sizes(n: usize) -> Vec<usize> {
    std::iter::successors(Some(1usize), |m| Some(m * 2))
        .take_while(|m| 4 * m <= n)
        .collect()
}

/// The cluster sizes of a series of `n` samples in the groups swept together: each group's
/// sums are independent of the others' (a task of their own).
fn groups(n: usize) -> Vec<Vec<usize>> {
    sizes(n).chunks(SWEPT).map(<[usize]>::to_vec).collect()
}

/// Terms of the sum at cluster size `m` over `n` samples.
fn terms(n: usize, m: usize) -> usize {
    n + 1 - 2 * m
}

/// The sums of squared second differences of the integrated angle `theta[k] = c[k - 1]`
/// (`theta[0] = 0`) at the cluster sizes of `group`.
fn group_sums<T: Theta>(c: &T, group: Vec<usize>) -> Result<Vec<f64>, T::Error> {
    let mut s = first_terms(c, &group)?;
    add_terms(c, &group, &mut s, 1, terms(c.len(), group[0]))?;
    Ok(s)
}

/// The terms at `k = 0` of the sums of `group`'s sizes, where `theta[k]` is the implicit zero.
fn first_terms<T: Theta>(c: &T, group: &[usize]) -> Result<Vec<f64>, T::Error> {
    let term = |m: usize| -> Result<f64, T::Error> {
        let d0 = c.at(2 * m - 1)? - 2.0 * c.at(m - 1)?;
        Ok(d0 * d0)
    };
    group.iter().map(|&m| term(m)).collect()
}

/// Adds to `s` (the sums of `group`'s sizes) their terms of `k` in `[a, b)`: the sizes swept
/// together up to the largest size's last term, then each size's own tail. Every sum adds
/// its terms in the order of `k`, whichever sizes are swept beside it, and whether `[1,
/// end)` is added at once or block by block in order (a block's swept part comes before its
/// tails, which start after the swept part ends).
fn add_terms<T: Theta>(
    c: &T,
    group: &[usize],
    s: &mut [f64],
    a: usize,
    b: usize,
) -> Result<(), T::Error> {
    let n = c.len();
    let common = terms(n, group[group.len() - 1]);
    let swept = (a, b.min(common));
    if swept.0 < swept.1 {
        match <[usize; SWEPT]>::try_from(group) {
            Ok(g) => {
                let four = <&mut [f64; SWEPT]>::try_from(&mut s[..]).expect("four sums");
                c.sweep(g, four, swept.0, swept.1)?;
            }
            Err(_) => {
                for (s, &m) in s.iter_mut().zip(group) {
                    c.sweep([m], std::array::from_mut(s), swept.0, swept.1)?;
                }
            }
        }
    }
    for (s, &m) in s.iter_mut().zip(group) {
        let (a, b) = (a.max(common), b.min(terms(n, m)));
        if a < b {
            c.sweep([m], std::array::from_mut(s), a, b)?;
        }
    }
    Ok(())
}

/// The curve of a series of `n` samples from its sums (in the order of [`sizes`]).
fn curve(n: usize, sums: &[f64], dt: f64) -> Vec<(f64, f64, usize)> {
    let ms = sizes(n);
    let curve = ms.iter().zip(sums).map(|(&m, &s)| {
        let tau = m as f64 * dt;
        let adev = (s / (2.0 * tau * tau * terms(n, m) as f64)).sqrt();
        (tau, adev, n / m)
    });
    curve.collect()
}

/// The three gyro curves of a block, `(tau, adev, clusters)` per octave cluster size.
pub(crate) type Curves = Vec<Vec<(f64, f64, usize)>>;

/// The three gyro curves of a block from its kept samples per axis (treated as
/// contiguous), sampled every `dt`: the costly part of the Allan analysis, free of `Out`
/// so that it can run while the fits do, the three axes side by side. In memory each
/// series is integrated in place, so a long 1 kHz block holds its three series and nothing
/// more; spilled, it is integrated into the scratch file and read back a block at a time
/// (`spill.rs`), and a failed read or write of the file is returned.
pub(crate) fn curves(series: Series, dt: f64) -> io::Result<Curves> {
    curves_in_blocks(series, dt, spill::BLOCK)
}

/// [`curves`], a spilled series read `block` samples at a time.
fn curves_in_blocks(series: Series, dt: f64, block: usize) -> io::Result<Curves> {
    use rayon::prelude::*;
    let mut axes: [Vec<Part>; 3] = Default::default();
    for chunk in series.chunks {
        for (ax, p) in axes.iter_mut().zip(chunk) {
            ax.push(p);
        }
    }
    let spilled = axes
        .iter()
        .flatten()
        .any(|p| matches!(p, Part::Spilled { .. }));
    let spill = match series.spill {
        Some(spill) if spilled => spill,
        _ => {
            let mut held = axes.map(|parts| {
                (parts.into_iter())
                    .filter_map(|p| match p {
                        Part::Held(v) => Some(v),
                        Part::Spilled { .. } => None,
                    })
                    .collect::<Vec<_>>()
            });
            held.par_iter_mut().for_each(|chunks| integrate(chunks, dt));
            let series: Vec<Chunked> = held.iter().map(|a| Chunked::new(a)).collect();
            let Ok(curves) = curves_of(&series, dt);
            return Ok(curves);
        }
    };
    // The groups whose offsets fit in a stream's ring are summed as each axis is read
    // back; the farther ones (a long recording's largest sizes) from the angles it writes.
    let lens = axes
        .each_ref()
        .map(|parts| parts.iter().map(Part::len).sum::<usize>());
    let split = |n: usize| -> (Vec<Vec<usize>>, Vec<Vec<usize>>) {
        (groups(n).into_iter()).partition(|g| 2 * g[g.len() - 1] <= spill::SLIDE * block)
    };
    let streamed = (axes.par_iter().zip(&lens))
        .map(|(parts, &n)| {
            let (near, far) = split(n);
            stream::stream(&spill, parts, dt, &near, !far.is_empty(), block)
        })
        .collect::<io::Result<Vec<_>>>()?;
    // What a failed write left in memory has been read.
    drop(axes);
    let tasks: Vec<(usize, Vec<usize>, spill::Angles)> = (streamed.iter().enumerate())
        .filter_map(|(ax, (_, angles))| Some((ax, (*angles)?)))
        .flat_map(|(ax, angles)| split(lens[ax]).1.into_iter().map(move |g| (ax, g, angles)))
        .collect();
    let far: Vec<(usize, Vec<f64>)> = tasks
        .into_par_iter()
        .map(|(ax, g, angles)| {
            let on_file = OnFile {
                spill: &spill,
                angles,
                block,
            };
            Ok((ax, group_sums(&on_file, g)?))
        })
        .collect::<io::Result<_>>()?;
    let curves = (streamed.into_iter().enumerate()).map(|(ax, (near, _))| {
        let far = far.iter().filter(|(a, _)| *a == ax).flat_map(|(_, s)| s);
        let s: Vec<f64> = near.into_iter().flatten().chain(far.copied()).collect();
        curve(lens[ax], &s, dt)
    });
    Ok(curves.collect())
}

/// The curves of integrated series, one per axis.
fn curves_of<T: Theta>(series: &[T], dt: f64) -> Result<Curves, T::Error> {
    use rayon::prelude::*;
    // Every axis's groups of cluster sizes as tasks of their own: three axes on two cores
    // would leave one core idle for the last axis.
    let tasks: Vec<(usize, Vec<usize>)> = (series.iter().enumerate())
        .flat_map(|(ax, c)| groups(c.len()).into_iter().map(move |g| (ax, g)))
        .collect();
    let sums: Vec<(usize, Vec<f64>)> = tasks
        .into_par_iter()
        .map(|(ax, g)| Ok((ax, group_sums(&series[ax], g)?)))
        .collect::<Result<_, _>>()?;
    let curves = (series.iter().enumerate()).map(|(ax, c)| {
        let s: Vec<f64> = (sums.iter().filter(|(a, _)| *a == ax))
            .flat_map(|(_, s)| s.iter().copied())
            .collect();
        curve(c.len(), &s, dt)
    });
    Ok(curves.collect())
}

/// The Allan parameters of block `id` when its series could not be read back from its
/// scratch file (`e`): unobservable, with a warning.
pub(crate) fn unreadable(id: &str, e: &io::Error, out: &mut Out) {
    let why = format!("the Allan series of {id} could not be read back from its scratch file: {e}");
    for ax in AXES {
        out.unobservable(&format!("gyro.arw.{ax}"), &why);
        out.unobservable(&format!("gyro.bias_instability.{ax}"), &why);
    }
    out.warnings.push(why);
}

/// Allan analysis of the block's gyros from its `curves`: angle random walk at tau = 1 s,
/// bias instability.
pub(crate) fn analyse(id: &str, curves: &Curves, out: &mut Out) -> Option<AllanCurve> {
    let mut taus = Vec::new();
    let mut adev: [Vec<f64>; 3] = Default::default();
    for (ax, curve) in curves.iter().enumerate() {
        if curve.len() < 2 {
            return None;
        }
        taus = curve.iter().map(|c| c.0).collect();
        adev[ax] = curve.iter().map(|c| c.1).collect();
        let name = AXES[ax];
        // Relative uncertainty of an Allan deviation with K clusters: about 1/sqrt(2(K-1)).
        let rel = |k: usize| 1.0 / (2.0 * (k.max(2) - 1) as f64).sqrt();
        match curve.windows(2).find(|w| w[0].0 <= 1.0 && w[1].0 >= 1.0) {
            Some(w) => {
                let f = (1.0f64.ln() - w[0].0.ln()) / (w[1].0.ln() - w[0].0.ln());
                let a1 = (w[0].1.ln() + f * (w[1].1.ln() - w[0].1.ln())).exp();
                // deg/s at tau = 1 s is deg/sqrt(s); x 60 gives deg/sqrt(h).
                out.params.insert(
                    format!("gyro.arw.{name}"),
                    Parameter::estimate(a1 * 60.0, a1 * 60.0 * rel(w[0].2), "deg/sqrt(h)"),
                );
            }
            None => out.unobservable(
                &format!("gyro.arw.{name}"),
                "the static block does not span tau = 1 s",
            ),
        }
        let (i, min) = curve
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
            .map(|(i, c)| (i, c.1))?;
        let bi = min / 0.664 * 3600.0;
        // A curve still falling at its longest tau has not reached its floor: the minimum
        // bounds the bias instability from above and is no estimate of it.
        let falling = i + 1 == curve.len();
        let p = match falling {
            false => Parameter::estimate(bi, bi * rel(curve[i].2), "deg/h"),
            true => Parameter::UpperBound {
                upper_bound: bi,
                unit: "deg/h".into(),
                why: format!(
                    "the Allan deviation of {id} still falls at its longest tau ({:.0} s)",
                    curve[i].0
                ),
            },
        };
        out.params
            .insert(format!("gyro.bias_instability.{name}"), p);
        if falling && ax == 0 {
            out.warnings.push(format!(
                "Allan deviation of {} still falls at its longest tau ({:.0} s): the bias instability is only bounded from above (no value is given)",
                id,
                curve[i].0
            ));
        }
    }
    Some(AllanCurve {
        segment: id.to_string(),
        tau_s: taus,
        adev_dps: adev,
    })
}

#[cfg(test)]
mod tests {
    use super::{Arc, Out, Parameter, Part, Spill, analyse, overlapping_adev};

    /// The textbook sum, one cluster size at a time over one contiguous angle series.
    fn textbook(y: &[f64], dt: f64) -> Vec<(f64, f64, usize)> {
        let mut theta = vec![0.0];
        for v in y {
            theta.push(theta[theta.len() - 1] + v * dt);
        }
        let n = y.len();
        let mut out = Vec::new();
        let mut m = 1;
        while 4 * m <= n {
            let (tau, terms) = (m as f64 * dt, n + 1 - 2 * m);
            let mut s = 0.0;
            for k in 0..terms {
                let d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
                s += d * d;
            }
            out.push((tau, (s / (2.0 * tau * tau * terms as f64)).sqrt(), n / m));
            m *= 2;
        }
        out
    }

    /// A deterministic rate series of `n` samples, chaotic enough that no two sums agree by
    /// chance.
    fn rates(n: usize) -> Vec<f64> {
        let mut x = 0.37f64;
        (0..n)
            .map(|i| {
                x = (x * 3.9 * (1.0 - x)).clamp(1e-9, 1.0 - 1e-9);
                0.2 + 1e-3 * (x - 0.5) + 1e-7 * i as f64
            })
            .collect()
    }

    /// Uneven cuts of a series of 20 011 samples, empty chunks among them.
    const CUTS: [usize; 8] = [0, 3, 3, 1_000, 7_777, 7_778, 15_000, 20_011];

    /// `y` (plus the axis's index on each axis) in the chunks of [`CUTS`].
    fn chunked(y: &[f64], spill: Option<Arc<Spill>>) -> super::Series {
        let mut series = super::Series::new(spill);
        for w in CUTS.windows(2) {
            series.push(std::array::from_fn(|ax| {
                y[w[0]..w[1]].iter().map(|v| v + ax as f64).collect()
            }));
        }
        series
    }

    /// The textbook curve of each axis of [`chunked`].
    fn textbooks(y: &[f64], dt: f64) -> Vec<Vec<(f64, f64, usize)>> {
        let axis = |ax: usize| y.iter().map(|v| v + ax as f64).collect::<Vec<_>>();
        (0..3).map(|ax| textbook(&axis(ax), dt)).collect()
    }

    /// Held in uneven chunks (empty ones among them) and swept four sizes at a time, the
    /// curve is the textbook one to the last bit: every sum adds the same terms in the
    /// same order.
    #[test]
    fn chunked_and_swept_curve_is_the_textbook_one_to_the_bit() {
        let y = rates(CUTS[CUTS.len() - 1]);
        let want = textbooks(&y, 0.01);
        let got = super::curves(chunked(&y, None), 0.01).unwrap();
        assert_eq!(got, want);
        assert_eq!(got[0].len(), 13);
        assert_eq!(overlapping_adev(&y, 0.01), want[0]);
    }

    /// Spilled to a scratch file as it comes and read back in blocks from 5 samples (the
    /// large sizes' offsets read each on its own, the small sizes' through the sliding
    /// window, blocks and integration pieces ending everywhere) to the whole series at
    /// once, the curve is the textbook one to the bit; so it is with some chunks left in
    /// memory among the spilled ones.
    #[test]
    fn spilled_curve_is_the_textbook_one_to_the_bit() {
        let y = rates(CUTS[CUTS.len() - 1]);
        let want = textbooks(&y, 0.01);
        for block in [5, 64, 1_000, super::spill::BLOCK] {
            let spill = Arc::new(Spill::new(tempfile::tempfile().unwrap()));
            let mut series = chunked(&y, Some(spill));
            let spilled = series.chunks.iter().flatten();
            assert!(
                spilled
                    .clone()
                    .all(|p| matches!(p, Part::Spilled { .. }) || p.len() == 0)
            );
            if block == 64 {
                // Chunks written before a failure, then one kept in memory, then spilled.
                let held = series.chunks.remove(3).map(|p| match p {
                    Part::Spilled { at, len } => {
                        let mut v = vec![0.0; len];
                        let s = series.spill.as_ref().unwrap();
                        s.read_at(&mut v, at, &mut Vec::new()).unwrap();
                        Part::Held(v)
                    }
                    held => held,
                });
                series.chunks.insert(3, held);
            }
            let got = super::curves_in_blocks(series, 0.01, block).unwrap();
            assert_eq!(got, want, "blocks of {block}");
        }
    }

    /// A scratch file that cannot be written leaves the series in memory (the same curve);
    /// one that cannot be read back is an error, not a panic.
    #[test]
    fn a_scratch_file_that_fails_leaves_the_series_in_memory_or_says_so() {
        let y = rates(CUTS[CUTS.len() - 1]);
        let named = tempfile::NamedTempFile::new().unwrap();
        let open =
            |o: &mut std::fs::OpenOptions| Arc::new(Spill::new(o.open(named.path()).unwrap()));
        let read_only = chunked(&y, Some(open(std::fs::OpenOptions::new().read(true))));
        assert!(
            read_only
                .chunks
                .iter()
                .flatten()
                .all(|p| matches!(p, Part::Held(_)))
        );
        assert_eq!(super::curves(read_only, 0.01).unwrap(), textbooks(&y, 0.01));
        let write_only = chunked(&y, Some(open(std::fs::OpenOptions::new().write(true))));
        assert!(super::curves(write_only, 0.01).is_err());
    }

    /// A curve with its floor inside gives a value with an uncertainty; one still falling at
    /// its longest tau gives only the bound, no value beside its own bound.
    #[test]
    fn a_curve_still_falling_bounds_the_instability_and_gives_no_value() {
        let curve = |floor: bool| -> Vec<(f64, f64, usize)> {
            let taus = [0.5, 1.0, 2.0, 4.0, 8.0];
            let at = |t: f64| {
                if floor && t > 3.0 {
                    1e-3 * t / 4.0
                } else {
                    1e-3 / t.sqrt()
                }
            };
            taus.iter()
                .map(|&t| (t, at(t), (64.0 / t) as usize))
                .collect()
        };
        for floor in [true, false] {
            let mut out = Out::default();
            analyse("gyro_bias", &vec![curve(floor); 3], &mut out).unwrap();
            let p = &out.params["gyro.bias_instability.x"];
            match (floor, p) {
                (true, Parameter::Estimate { value, .. }) => {
                    assert!(
                        (value - 1e-3 / 2f64.sqrt() / 0.664 * 3600.0).abs() < 1e-9,
                        "{value}"
                    )
                }
                (false, Parameter::UpperBound { upper_bound, .. }) => {
                    let b = 1e-3 / 8f64.sqrt() / 0.664 * 3600.0;
                    assert!((upper_bound - b).abs() < 1e-9, "{upper_bound}");
                    assert!(out.warnings[0].contains("bounded from above"));
                }
                (floor, p) => panic!("floor {floor}: {p:?}"),
            }
            assert_eq!(out.warnings.is_empty(), floor);
        }
    }

    #[test]
    fn white_noise_falls_as_one_over_sqrt_tau() {
        // A deterministic +-1 alternating sequence is "white" enough at m = 1 and averages
        // to zero at every even cluster size: closed forms for both.
        let y: Vec<f64> = (0..4096)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let c = overlapping_adev(&y, 1.0);
        // m = 1: differences of consecutive samples are +-2, adev^2 = 4/2 = 2.
        assert!((c[0].1 - 2f64.sqrt()).abs() < 1e-12);
        assert!(c[1].1 < 1e-12);
    }
}
