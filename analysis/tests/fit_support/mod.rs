//! Test-only recording generator: the seed station, an IMU with known errors measured
//! through `ratecal_physics` at static attitudes and constant rates, seeded white noise
//! and a random-walk gyro bias, written as a recording folder in the spec format.
#![allow(dead_code)]

use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use ratecal_physics::{AxisMotion, DEG, Geometry, ImuErrors, Site, TableState, Vec3};
use std::fmt::Write as _;
use std::path::Path;

/// What to simulate.
#[derive(Debug, Clone)]
pub struct SimSpec {
    /// Seed.
    pub seed: u64,
    /// Length of the static gyro block, s.
    pub block_s: f64,
    /// IMU rate, Hz.
    pub imu_hz: f64,
    /// Table feedback rate, Hz.
    pub table_hz: f64,
    /// White noise, accel m/s^2 and gyro deg/s.
    pub noise: (f64, f64),
    /// Gyro bias random walk, deg/s per sqrt(s).
    pub bias_walk: f64,
    /// Errors.
    pub errors: ImuErrors,
    /// IMU temperature column: start and slope per hour.
    pub temp: Option<(f64, f64)>,
    /// Recorded time before each window (moving and settling), s.
    pub settle_s: f64,
}

pub const SITE: Site = Site {
    latitude_deg: 55.7,
    gravity_mps2: 9.8156,
};

impl SimSpec {
    /// A tactical IMU with per-axis biases and scale factors drawn from the seed.
    pub fn tactical(seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
        let u = Normal::new(0.0, 1.0).unwrap();
        let mut e = ImuErrors::default();
        for i in 0..3 {
            e.b_a[i] = 0.02 * u.sample(&mut rng);
            e.k_a[(i, i)] = 1.0 + 800e-6 * u.sample(&mut rng);
            e.b_g[i] = 0.05 * u.sample(&mut rng);
            e.k_g[(i, i)] = 1.0 + 1000e-6 * u.sample(&mut rng);
        }
        SimSpec {
            seed,
            block_s: 120.0,
            imu_hz: 100.0,
            table_hz: 50.0,
            noise: (0.0025, 0.004),
            bias_walk: 5e-6,
            errors: e,
            temp: None,
            settle_s: 2.0,
        }
    }
}

/// One planned window.
#[derive(Debug, Clone)]
pub struct Window {
    pub id: String,
    pub kind: &'static str,
    pub outer_deg: f64,
    pub inner_deg: f64,
    /// (axis 0 = outer / 1 = inner, rate deg/s) for a rate window.
    pub rate: Option<(usize, f64)>,
    pub dur: f64,
}

/// The standard plan's windows: six attitudes, the static block, rate points about both axes.
pub fn standard_windows(block_s: f64) -> Vec<Window> {
    let mut w = Vec::new();
    for (n, (p, r)) in [
        (0.0, 0.0),
        (0.0, 180.0),
        (90.0, 0.0),
        (-90.0, 0.0),
        (0.0, 90.0),
        (0.0, -90.0),
    ]
    .iter()
    .enumerate()
    {
        w.push(Window {
            id: format!("accel_static/{}", n + 1),
            kind: "static",
            outer_deg: *p,
            inner_deg: *r,
            rate: None,
            dur: 10.0,
        });
    }
    w.push(Window {
        id: "gyro_bias".into(),
        kind: "static",
        outer_deg: 0.0,
        inner_deg: 0.0,
        rate: None,
        dur: block_s,
    });
    for (ax, name) in [(0usize, "outer"), (1, "inner")] {
        for rate in [-100.0, -50.0, 0.0, 50.0, 100.0] {
            w.push(Window {
                id: format!("gyro_scale/{name}/{rate:+}"),
                kind: "rate",
                outer_deg: 0.0,
                inner_deg: 0.0,
                rate: Some((ax, rate)),
                dur: 10.0,
            });
        }
    }
    w
}

/// Truth the test compares with: the nominal errors, and the random-walk part of the gyro
/// bias averaged over the static block (a wandering bias has no other true value: the
/// calibration measures it when it measures it).
pub struct Truth {
    pub errors: ImuErrors,
    pub block_walk: Vec3,
}

/// Writes the recording to `dir`.
pub fn write(dir: &Path, spec: &SimSpec, windows: &[Window]) -> Truth {
    let geo = Geometry::seed();
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let na = Normal::new(0.0, spec.noise.0).unwrap();
    let ng = Normal::new(0.0, spec.noise.1).unwrap();
    let nt = Normal::new(0.0, 1e-4).unwrap();
    let dt_i = 1.0 / spec.imu_hz;
    let step = spec.bias_walk * dt_i.sqrt();
    let nw = Normal::new(0.0, step.max(1e-300)).unwrap();
    let settle = spec.settle_s;
    // Timeline: each window preceded by `settle` seconds in the same state.
    let mut spans = Vec::new();
    let mut t = 0.0;
    for w in windows {
        spans.push((t, t + settle + w.dur, w));
        t += settle + w.dur;
    }
    let end = t;
    let state_at = |t: f64| -> TableState {
        let (t0, _, w) = spans
            .iter()
            .find(|s| t < s.1)
            .copied()
            .unwrap_or(*spans.last().unwrap());
        let mut s = TableState::at_rest_deg(w.outer_deg, w.inner_deg);
        if let Some((ax, r)) = w.rate {
            let m = AxisMotion {
                angle: (if ax == 0 { w.outer_deg } else { w.inner_deg } + r * (t - t0)) * DEG,
                rate: r * DEG,
                accel: 0.0,
            };
            if ax == 0 { s.outer = m } else { s.inner = m }
        }
        s
    };
    let mut imu = String::from(if spec.temp.is_some() {
        "t,ax,ay,az,gx,gy,gz,temp\n"
    } else {
        "t,ax,ay,az,gx,gy,gz\n"
    });
    let mut walk = Vec3::zeros();
    let block = spans
        .iter()
        .find(|s| s.2.id == "gyro_bias")
        .map(|s| (s.0 + settle, s.1 - 0.05));
    let (mut wsum, mut wn) = (Vec3::zeros(), 0.0);
    let n_imu = (end * spec.imu_hz) as usize;
    for k in 0..n_imu {
        let t = 0.003 + k as f64 * dt_i;
        if t >= end {
            break;
        }
        let temp_c = spec
            .temp
            .map_or(spec.errors.t_ref_c, |(t0, slope)| t0 + slope * t / 3600.0);
        let (a, g) = spec.errors.measure(&state_at(t), &geo, &SITE, temp_c);
        for i in 0..3 {
            walk[i] += nw.sample(&mut rng);
        }
        if block.is_some_and(|(b0, b1)| t >= b0 && t <= b1) {
            wsum += walk;
            wn += 1.0;
        }
        let a = a + Vec3::from_fn(|_, _| na.sample(&mut rng));
        let g = g + walk + Vec3::from_fn(|_, _| ng.sample(&mut rng));
        let _ = write!(
            imu,
            "{t:.5},{:.6},{:.6},{:.6},{:.7},{:.7},{:.7}",
            a.x, a.y, a.z, g.x, g.y, g.z
        );
        if spec.temp.is_some() {
            let _ = write!(imu, ",{temp_c:.3}");
        }
        imu.push('\n');
    }
    let mut table = String::from("t,outer,inner,outer_rate,inner_rate\n");
    let n_tab = (end * spec.table_hz) as usize + 1;
    for k in 0..n_tab {
        let t = k as f64 / spec.table_hz;
        let s = state_at(t.min(end - 1e-9));
        let _ = writeln!(
            table,
            "{t:.5},{:.6},{:.6},{:.5},{:.5}",
            s.outer.angle / DEG + nt.sample(&mut rng),
            s.inner.angle / DEG + nt.sample(&mut rng),
            s.outer.rate / DEG + nt.sample(&mut rng),
            s.inner.rate / DEG + nt.sample(&mut rng)
        );
    }
    let mut m = String::from(
        "format: ratecal-recording/1\nstation:\n  site: { latitude_deg: 55.7, gravity_mps2: 9.8156 }\n  table: { outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }\nimu: { model: sim, serial: test }\nsegments:\n",
    );
    for (t0, t1, w) in &spans {
        let extra = match w.rate {
            Some((ax, r)) => format!(
                ", axis: {}, rate_dps: {r:.1}",
                if ax == 0 { "outer" } else { "inner" }
            ),
            None => String::new(),
        };
        let _ = writeln!(
            m,
            "  - {{ id: \"{}\", kind: {}, t_start: {:.3}, t_end: {:.3}{extra} }}",
            w.id,
            w.kind,
            t0 + settle,
            t1 - 0.05
        );
    }
    std::fs::write(dir.join("manifest.yaml"), m).unwrap();
    std::fs::write(dir.join("imu.csv"), imu).unwrap();
    std::fs::write(dir.join("table.csv"), table).unwrap();
    Truth {
        errors: spec.errors.clone(),
        block_walk: if wn > 0.0 { wsum / wn } else { Vec3::zeros() },
    }
}

/// The truth in results.json's names and units (biases as outputs at zero input, scale as
/// K - 1 in ppm).
pub fn truth_params(truth: &Truth) -> Vec<(String, f64)> {
    let e = &truth.errors;
    let mut v = Vec::new();
    for (i, ax) in ["x", "y", "z"].iter().enumerate() {
        v.push((format!("accel.bias.{ax}"), e.b_a[i]));
        v.push((format!("accel.scale.{ax}"), (e.k_a[(i, i)] - 1.0) * 1e6));
        v.push((format!("gyro.bias.{ax}"), e.b_g[i] + truth.block_walk[i]));
        v.push((format!("gyro.scale.{ax}"), (e.k_g[(i, i)] - 1.0) * 1e6));
    }
    v
}

/// The benches' recording (`benches/analyze.rs`, `benches/explain.rs`): the standard plan
/// with a 15-minute gyro block at 100 Hz, about 28 minutes with settling, written to `dir`
/// once.
pub fn bench_recording(dir: &Path) {
    if !dir.join("manifest.yaml").exists() {
        std::fs::create_dir_all(dir).unwrap();
        let mut spec = SimSpec::tactical(42);
        spec.block_s = 900.0;
        spec.temp = Some((22.0, 1.5));
        spec.settle_s = 40.0;
        let windows = standard_windows(spec.block_s);
        write(dir, &spec, &windows);
    }
}
