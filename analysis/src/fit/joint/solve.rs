//! Solving a model over a set of segments from the segments' triangular factors: the
//! channels stacked with weights `1 / sigma^2`, a rank-revealing QR to find what the data
//! cannot determine, back substitution, and the covariance with correlated noise.

use super::accumulate::{SegAcc, seg_rss};
use super::noise::{self, ChannelNoise};
use super::tri::triangle;
use super::{Layout, channel};
use nalgebra::{DMatrix, DVector};
use ratecal_physics::effects::Sensor;

/// A model and the data to fit it to.
#[derive(Debug, Clone)]
pub(crate) struct FitRequest<'a> {
    /// The layout the segments were accumulated with.
    pub layout: &'a Layout,
    /// Fitted columns (global indices).
    pub cols: Vec<usize>,
    /// Columns held at known values (subtracted from the observations).
    pub fixed: Vec<(usize, f64)>,
    /// Segments fitted for the accelerometers.
    pub accel: Vec<&'a SegAcc>,
    /// Segments fitted for the gyros.
    pub gyro: Vec<&'a SegAcc>,
    /// What every fit over exactly these segments shares, when the caller keeps it
    /// ([`Pooled`]): many models over the same segments then share one merge.
    pub merged: Option<&'a Pooled>,
    /// How the covariance takes the wandering bias.
    pub wander: WanderRule,
}

/// How a fit's covariance takes the wandering bias.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum WanderRule {
    /// As the residuals estimate it (pooled per sensor).
    Estimated,
    /// Left out (white noise only): a cheap screen of many models, never a reported
    /// uncertainty.
    WhiteOnly,
}

/// A solved model.
#[derive(Debug, Clone)]
pub(crate) struct Fit {
    /// Global coefficients: estimates, fixed values, zero elsewhere.
    pub theta: DVector<f64>,
    /// Global covariance (zero rows for columns not estimated).
    pub cov: DMatrix<f64>,
    /// Columns asked for that the data cannot determine.
    pub unobservable: Vec<usize>,
    /// Estimated columns.
    pub estimated: Vec<usize>,
    /// Noise of each channel's residuals.
    pub noise: [ChannelNoise; 6],
}

impl Fit {
    /// Standard uncertainty of column `g`.
    pub(crate) fn u(&self, g: usize) -> f64 {
        self.cov[(g, g)].max(0.0).sqrt()
    }

    /// Correlation of two columns.
    pub(crate) fn corr(&self, a: usize, b: usize) -> f64 {
        let d = (self.cov[(a, a)] * self.cov[(b, b)]).sqrt();
        if d > 0.0 { self.cov[(a, b)] / d } else { 0.0 }
    }
}

impl FitRequest<'_> {
    fn segs(&self, c: usize) -> &[&SegAcc] {
        match channel(c).0 {
            Sensor::Accel => &self.accel,
            Sensor::Gyro => &self.gyro,
        }
    }
}

/// What every fit over one set of segments shares ([`FitRequest::merged`]): each
/// channel's factor over them, and the random walk's Gram over all of a channel's columns
/// (made at the first fit that asks for it), of which a model's is a part.
#[derive(Debug)]
pub(crate) struct Pooled {
    factors: Vec<DMatrix<f64>>,
    walks: std::sync::OnceLock<Vec<DMatrix<f64>>>,
}

impl Pooled {
    /// The request's segments merged per channel.
    pub(crate) fn of(req: &FitRequest) -> Self {
        Pooled {
            factors: (0..6)
                .map(|c| merged(req.segs(c), c, req.layout.by_channel[c].len() + 1))
                .collect(),
            walks: Default::default(),
        }
    }

    /// Every channel's walk Gram (lower triangle) over the request's segments (those the
    /// pool was made of).
    fn walks(&self, req: &FitRequest) -> &[DMatrix<f64>] {
        self.walks.get_or_init(|| {
            let one = |c: usize| {
                let all: Vec<usize> = (0..req.layout.by_channel[c].len()).collect();
                noise::walk_lower(req.segs(c), c, &all)
            };
            // The sensors on both cores: the fits that wait for the Gram are blocked, and
            // plain threads (not the fits' pool) cannot be handed a fit that waits for it.
            std::thread::scope(|s| {
                let gyro = s.spawn(|| (3..6).map(one).collect::<Vec<_>>());
                let mut all: Vec<DMatrix<f64>> = (0..3).map(one).collect();
                all.extend(gyro.join().expect("the Gram does not panic"));
                all
            })
        })
    }
}

/// The channel's factor over a set of segments.
fn merged(segs: &[&SegAcc], c: usize, width: usize) -> DMatrix<f64> {
    if segs.len() == 1 {
        return segs[0].r[c].clone();
    }
    let rows: usize = segs.iter().map(|s| s.r[c].nrows()).sum();
    let mut m = DMatrix::zeros(rows.max(width), width);
    let mut at = 0;
    for s in segs {
        let k = s.r[c].nrows();
        m.view_mut((at, 0), (k, width)).copy_from(&s.r[c]);
        at += k;
    }
    triangle(m, width)
}

/// Solves the request. Columns that are not excited, or not separable from the others,
/// are left out of the estimate and listed as unobservable.
pub(crate) fn solve(req: &FitRequest) -> Fit {
    let lay = req.layout;
    let ncol = lay.cols.len();
    let mut theta = DVector::zeros(ncol);
    for &(g, v) in &req.fixed {
        theta[g] = v;
    }
    let n: [usize; 6] = std::array::from_fn(|c| req.segs(c).iter().map(|s| s.n).sum());
    let mut cols: Vec<usize> = req.cols.clone();
    cols.retain(|g| !req.fixed.iter().any(|f| f.0 == *g));
    // Per channel: the factor over the fitted segments, reduced to the model's columns and
    // the observations net of fixed terms.
    let facs: Vec<Reduced> = (0..6)
        .map(|c| {
            let w = lay.by_channel[c].len() + 1;
            match req.merged {
                Some(m) => Reduced::of(&m.factors[c], lay, c, &cols, &theta),
                None => Reduced::of(&merged(req.segs(c), c, w), lay, c, &cols, &theta),
            }
        })
        .collect();
    let mut unobservable = Vec::new();
    // Weights: equal first, then 1 / sigma^2 from the first solution.
    let mut w = [1.0f64; 6];
    let mut noise = [ChannelNoise::default(); 6];
    let mut rss = [0.0; 6];
    let mut bread = DMatrix::zeros(0, 0);
    for pass in 0..2 {
        let stack = |cols: &[usize]| stacked(&facs, cols, &w);
        let mut r = stack(&cols);
        let dropped = rank_deficient(&r, cols.len());
        if !dropped.is_empty() {
            for &d in dropped.iter().rev() {
                unobservable.push(cols.remove(d));
            }
            r = stack(&cols);
        }
        let p = cols.len();
        let rp = r.view((0, 0), (p, p)).clone_owned();
        let z = r.view((0, p), (p, 1)).clone_owned();
        let est: DVector<f64> = rp
            .solve_upper_triangular(&z)
            .map_or_else(|| DVector::zeros(p), |m| m.column(0).into_owned());
        let inv = rp
            .solve_upper_triangular(&DMatrix::identity(p, p))
            .unwrap_or_else(|| DMatrix::zeros(p, p));
        bread = &inv * inv.transpose();
        let mut full = theta.clone();
        for (l, &g) in cols.iter().enumerate() {
            full[g] = est[l];
        }
        for c in 0..6 {
            let f = &facs[c];
            let k = f.cols.len();
            let mut v = DVector::zeros(k + 1);
            for (i, g) in f.cols.iter().enumerate() {
                if cols.contains(g) {
                    v[i] = full[*g];
                }
            }
            v[k] = -1.0;
            rss[c] = (&f.r * v).norm_squared();
            let pc = f.cols.iter().filter(|g| cols.contains(g)).count();
            let dof = n[c].saturating_sub(pc).max(1) as f64;
            let sigma = (rss[c] / dof).sqrt();
            // The first pass only weighs the channels: their noise is the second's.
            if pass == 1 {
                let theta_c: Vec<f64> = lay.by_channel[c].iter().map(|&g| full[g]).collect();
                let wander = req.wander != WanderRule::WhiteOnly;
                noise[c] = noise::estimate(req.segs(c), c, &theta_c, sigma, wander);
            }
            if pass == 0 {
                w[c] = if sigma > 0.0 {
                    1.0 / (sigma * sigma)
                } else {
                    1.0
                };
            }
        }
        // The three axes of a sensor share one wander intensity: each channel alone sees
        // too few long lags to estimate it (a zero would make slow regressors look exact).
        for sensor in [0..3, 3..6] {
            let q = sensor.clone().map(|c| noise[c].q).sum::<f64>() / 3.0;
            for c in sensor {
                noise[c].q = q;
            }
        }
        if pass == 1 {
            theta = full;
        }
    }
    // Sandwich: bread (in weighted units) around the white and random-walk parts.
    let p = cols.len();
    let mut meat = DMatrix::zeros(p, p);
    for c in 0..6 {
        if n[c] == 0 {
            continue;
        }
        let local: Vec<Option<usize>> = lay.by_channel[c]
            .iter()
            .map(|g| cols.iter().position(|x| x == g))
            .collect();
        let f = &facs[c];
        let mut xl = DMatrix::zeros(f.r.nrows(), p);
        for (i, g) in f.cols.iter().enumerate() {
            if let Some(l) = cols.iter().position(|x| x == g) {
                xl.set_column(l, &f.r.column(i));
            }
        }
        let nz = &noise[c];
        let white = nz.sigma * nz.sigma * nz.phi;
        meat += (xl.transpose() * &xl) * (w[c] * w[c] * white);
        if nz.q > 0.0 && req.wander != WanderRule::WhiteOnly {
            let m = match req.merged {
                Some(pool) => {
                    let full = &pool.walks(req)[c];
                    noise::scatter_lower(full, &noise::used_columns(&local), p)
                }
                None => noise::random_walk_gram(req.segs(c), c, &local, p),
            };
            meat += m * (w[c] * w[c] * nz.q);
        }
    }
    let cov_l = &bread * meat * &bread;
    let mut cov = DMatrix::zeros(ncol, ncol);
    for (a, &ga) in cols.iter().enumerate() {
        for (b, &gb) in cols.iter().enumerate() {
            cov[(ga, gb)] = cov_l[(a, b)];
        }
    }
    unobservable.sort_unstable();
    Fit {
        theta,
        cov,
        unobservable,
        estimated: cols,
        noise,
    }
}

/// One channel's factor over the fitted segments reduced to the model's columns (`cols`,
/// global, in the channel's order) and the observation net of the fixed terms, last: the
/// factor of those columns of the rows, so a model of a few columns is solved from a few
/// rows per channel, not from the layout's width.
struct Reduced {
    r: DMatrix<f64>,
    cols: Vec<usize>,
}

impl Reduced {
    fn of(f: &DMatrix<f64>, lay: &Layout, c: usize, model: &[usize], theta: &DVector<f64>) -> Self {
        let by = &lay.by_channel[c];
        let k = by.len();
        let keep: Vec<usize> = (0..k).filter(|&i| model.contains(&by[i])).collect();
        let mut m = DMatrix::zeros(f.nrows(), keep.len() + 1);
        for (j, &i) in keep.iter().enumerate() {
            m.set_column(j, &f.column(i));
        }
        let mut y = f.column(k).into_owned();
        for (i, &g) in by.iter().enumerate() {
            if theta[g] != 0.0 {
                y -= f.column(i) * theta[g];
            }
        }
        m.set_column(keep.len(), &y);
        Reduced {
            r: triangle(m, keep.len() + 1),
            cols: keep.into_iter().map(|i| by[i]).collect(),
        }
    }
}

/// The weighted stack of every channel's factor over `cols`, triangulated.
fn stacked(facs: &[Reduced], cols: &[usize], w: &[f64; 6]) -> DMatrix<f64> {
    let p = cols.len();
    let rows: usize = facs.iter().map(|f| f.r.nrows()).sum();
    let mut m = DMatrix::zeros(rows.max(p + 1), p + 1);
    let mut at = 0;
    for c in 0..6 {
        let f = &facs[c];
        let k = f.cols.len();
        let s = w[c].sqrt();
        for (i, g) in f.cols.iter().enumerate() {
            if let Some(l) = cols.iter().position(|x| x == g) {
                for r in 0..f.r.nrows() {
                    m[(at + r, l)] = f.r[(r, i)] * s;
                }
            }
        }
        for r in 0..f.r.nrows() {
            m[(at + r, p)] = f.r[(r, k)] * s;
        }
        at += f.r.nrows();
    }
    triangle(m, p + 1)
}

/// Local indices of the columns of a factor that are zero or linearly dependent on the
/// columns before them (after scaling every column to unit norm), in ascending order. The
/// order matters: a term added to a model is the one found wanting, never the model's own.
fn rank_deficient(r: &DMatrix<f64>, p: usize) -> Vec<usize> {
    if p == 0 {
        return Vec::new();
    }
    let rp = r.view((0, 0), (p, p)).clone_owned();
    let norms: Vec<f64> = (0..p).map(|j| rp.column(j).norm()).collect();
    let mut bad: Vec<usize> = (0..p)
        .filter(|&j| norms[j].is_nan() || norms[j] <= 1e-300)
        .collect();
    let good: Vec<usize> = (0..p).filter(|j| !bad.contains(j)).collect();
    if !good.is_empty() {
        let scaled = DMatrix::from_fn(p, good.len(), |i, j| rp[(i, good[j])] / norms[good[j]]);
        // Without pivoting, R[i][i] is what column i adds beyond the columns before it.
        let rr = scaled.qr().r();
        let k = rr.nrows().min(rr.ncols());
        for (i, &g) in good.iter().enumerate() {
            let d = if i < k { rr[(i, i)].abs() } else { 0.0 };
            if d < 1e-7 {
                bad.push(g);
            }
        }
    }
    bad.sort_unstable();
    bad.dedup();
    bad
}

/// Residual sum of squares of channel `c` over some segments for a fit's coefficients.
pub(crate) fn rss_on(fit: &Fit, lay: &Layout, segs: &[&SegAcc], c: usize) -> (f64, usize) {
    segs.iter().fold((0.0, 0), |(s, n), a| {
        (s + seg_rss(a, lay, c, &fit.theta), n + a.n)
    })
}
