//! A swaying experiment generated straight from the physics crate (no interpreter): three
//! cycles (Z, X tilted 5 deg, Y up), each an alignment at rest and sways at two periods,
//! sensed by a navigation-grade IMU with lever arms, instrumental errors and noise.

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use ratecal_physics::{AxisMotion, DEG, Geometry, ImuErrors, Mat3, Site, TableState, Vec3};
use ratecal_recording::{
    ImuStream, Manifest, ManifestStation, Mount, Recording, Segment, SegmentKind, TableAxes,
    TableStream,
};
use std::f64::consts::PI;

pub const SITE: Site = Site {
    latitude_deg: 55.7,
    gravity_mps2: 9.8156,
};

/// True coordinates r_ij (mm), order rxy, rxz, ryx, ryz, rzx, rzy.
pub const TRUTH_MM: [f64; 6] = [4.1, -2.7, 3.3, 5.2, -6.1, 2.4];

/// The IMU's centre, m from the table axes' intersection (body axes).
const P: [f64; 3] = [0.02, -0.01, 0.015];

/// Columns are the body axes in P: the mount that brings body axis `k` up.
pub fn mount_up(k: usize) -> Mat3 {
    match k {
        0 => Mat3::new(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0),
        1 => Mat3::new(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0),
        _ => Mat3::identity(),
    }
}

/// Sensing points `R_i` (rows, m) for coordinates `r_mm`.
pub fn lever(r_mm: &[f64; 6]) -> Mat3 {
    let r = r_mm.map(|v| v * 1e-3);
    Mat3::new(
        P[0],
        r[0] + P[1],
        r[1] + P[2],
        r[2] + P[0],
        P[1],
        r[3] + P[2],
        r[4] + P[0],
        r[5] + P[1],
        P[2],
    )
}

/// A navigation-grade IMU: 0.005 deg/h drifts, 50 ug biases, 50/10 ppm scale, 10 arcsec
/// misalignments.
pub fn nav_grade(r_mm: &[f64; 6]) -> ImuErrors {
    let mis = 4.8e-5;
    ImuErrors {
        k_a: Mat3::new(
            1.0 + 5e-5,
            mis,
            -mis,
            -0.7 * mis,
            1.0 - 4e-5,
            0.6 * mis,
            0.9 * mis,
            -mis,
            1.0 + 3e-5,
        ),
        b_a: Vec3::new(4.9e-4, -3.4e-4, 5.5e-4),
        k_g: Mat3::new(
            1.0 + 1e-5,
            -mis,
            0.8 * mis,
            mis,
            1.0 - 1.2e-5,
            -0.5 * mis,
            0.6 * mis,
            mis,
            1.0 + 0.8e-5,
        ),
        b_g: Vec3::new(1.4e-6, -1.1e-6, 0.9e-6),
        lever_m: lever(r_mm),
        ..Default::default()
    }
}

/// Smooth sway `th0 + A e(s) sin(w s)`, the envelope rising over the first period and
/// falling over the last of `n` periods.
fn sway(th0: f64, a: f64, period: f64, n: f64, s: f64) -> AxisMotion {
    let w = 2.0 * PI / period;
    let total = n * period;
    let (e, de, dde) = if s < period {
        let x = s / period;
        (
            3.0 * x * x - 2.0 * x.powi(3),
            (6.0 * x - 6.0 * x * x) / period,
            (6.0 - 12.0 * x) / period.powi(2),
        )
    } else if s > total - period {
        let x = (total - s) / period;
        (
            3.0 * x * x - 2.0 * x.powi(3),
            -(6.0 * x - 6.0 * x * x) / period,
            (6.0 - 12.0 * x) / period.powi(2),
        )
    } else {
        (1.0, 0.0, 0.0)
    };
    let (sn, cs) = (w * s).sin_cos();
    AxisMotion {
        angle: th0 + a * e * sn,
        rate: a * (de * sn + e * w * cs),
        accel: a * (dde * sn + 2.0 * de * w * cs - e * w * w * sn),
    }
}

/// Options of the simulated experiment.
pub struct Experiment {
    pub periods_s: Vec<f64>,
    pub sway_s: f64,
    pub hz: f64,
    pub seed: u64,
    pub noise: bool,
}

/// The recording of the experiment with the given IMU.
pub fn record(x: &Experiment, imu: &ImuErrors) -> Recording {
    let mut rng = ChaCha8Rng::seed_from_u64(x.seed);
    let mut t_now = 0.0;
    let mut rec_imu = ImuStream::default();
    let mut table = TableStream::default();
    let mut segments = Vec::new();
    let (sa, sg) = if x.noise {
        (2e-4 * x.hz.sqrt(), 3.3e-5 * x.hz.sqrt())
    } else {
        (0.0, 0.0)
    };
    // Gyro outputs carry a wandering bias too: a random walk of 1e-7 deg/s/rts.
    let mut wander = Vec3::zeros();
    let dt = 1.0 / x.hz;
    for (axis, tilt_deg) in [(2, 0.0), (0, 5.0), (1, 0.0)] {
        let geo = Geometry::vertical_outer().with_mount(mount_up(axis));
        let mount = Mount {
            rotation: std::array::from_fn(|i| std::array::from_fn(|j| mount_up(axis)[(i, j)])),
        };
        let inner = AxisMotion {
            angle: tilt_deg * DEG,
            rate: 0.0,
            accel: 0.0,
        };
        let mut phases: Vec<(f64, Option<f64>)> = vec![(60.0, None)];
        for &p in &x.periods_s {
            phases.push((((x.sway_s / p).round() + 2.0) * p, Some(p)));
            phases.push((5.0, None));
        }
        let mut first = true;
        for (dur, period) in phases {
            let t0 = t_now;
            let n = (dur * x.hz).round() as usize;
            for k in 0..n {
                let t = t0 + k as f64 * dt;
                let s = t - t0;
                let outer = match period {
                    Some(p) => sway(0.0, PI / 2.0, p, dur / p, s),
                    None => AxisMotion::default(),
                };
                let state = TableState { outer, inner };
                let (a, g) = imu.measure(&state, &geo, &SITE, 20.0);
                if x.noise {
                    wander += Vec3::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal))
                        * 1e-7
                        * dt.sqrt();
                }
                let na = Vec3::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal)) * sa;
                let ng = Vec3::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal)) * sg;
                rec_imu.t.push(t);
                for c in 0..3 {
                    rec_imu.accel[c].push(a[c] + na[c]);
                    rec_imu.gyro[c].push(g[c] + ng[c] + wander[c]);
                }
                if k % 2 == 0 {
                    table.t.push(t);
                    table.outer.push(outer.angle / DEG);
                    table.inner.push(tilt_deg);
                    table.outer_rate.push(outer.rate / DEG);
                    table.inner_rate.push(0.0);
                }
            }
            t_now = t0 + n as f64 * dt;
            let name = ["x", "y", "z"][axis];
            let mut seg = Segment::new(String::new(), SegmentKind::Static, t0 + 1.0, t_now - 1.0);
            seg.mount = first.then_some(mount);
            match period {
                None if first => seg.id = format!("align/{name}"),
                None => continue,
                Some(p) => {
                    seg.id = format!("sway/{name}/{p}");
                    seg.kind = SegmentKind::Oscillation;
                    seg.axis = Some("outer".into());
                    seg.amplitude_deg = Some(90.0);
                    seg.period_s = Some(p);
                    seg.center_deg = Some(0.0);
                    seg.t_start = t0 + 1.5 * p;
                    seg.t_end = t_now - 1.5 * p;
                }
            }
            first = false;
            segments.push(seg);
        }
    }
    let v = |a: Vec3| [a.x, a.y, a.z];
    let geo = Geometry::vertical_outer();
    Recording {
        manifest: Manifest {
            format: "ratecal-recording/1".into(),
            station: ManifestStation {
                site: SITE,
                table: TableAxes {
                    outer_axis: v(geo.outer_axis),
                    inner_axis: v(geo.inner_axis),
                    model: None,
                },
                mount: None,
            },
            imu: Default::default(),
            procedure: None,
            segments,
            environment: None,
            run: None,
        },
        imu: rec_imu,
        table,
    }
}

/// Indices of the oscillation segments whose period is in `periods`.
pub fn sways(rec: &Recording, periods: &[f64]) -> Vec<usize> {
    (0..rec.manifest.segments.len())
        .filter(|&i| {
            let s = &rec.manifest.segments[i];
            s.kind == SegmentKind::Oscillation && periods.iter().any(|p| Some(*p) == s.period_s)
        })
        .collect()
}
