//! Calibration sessions without a table, from closed forms: a unit placed by hand on the
//! six faces of a fixture (each face tilted by a random few tenths of a degree) and turned
//! by hand about each body axis (Ferraris), or held in random attitudes separated by
//! uneven hand turns (Tedaldi). The attitude is written out as rotations of the body
//! (Rodrigues), the outputs as physics.md's measurement model; the manifest says which
//! attitudes are `nominal` and which `unknown`, as spec/recording-format.md does.

use crate::rot::{self, M3, V3};
use crate::station::OMEGA_E;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io;
use std::path::Path;

/// Which session.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ManualKind {
    /// Six nominal faces and a turn of -360 deg about each body axis.
    SixFace,
    /// An initial rest, then `poses` hand-held poses of unknown attitude between turns.
    MultiPose {
        /// Poses after the initial rest.
        poses: usize,
    },
}

/// A manual session: the IMU's truth and how the hand moved it.
#[derive(Debug, Clone)]
pub struct ManualSession {
    /// Which session.
    pub kind: ManualKind,
    /// Seed of every random part.
    pub seed: u64,
    /// Placement tilt of each face (standard deviation per axis across it), deg; the
    /// manifest's `tolerance_deg`.
    pub tilt_deg: f64,
    /// White noise of the accelerometers, m/s^2 per sample, and of the gyros, deg/s.
    pub noise: (f64, f64),
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Site gravity, m/s^2, and latitude, deg.
    pub site: (f64, f64),
}

impl ManualSession {
    /// A consumer-grade session of `kind` with seed `seed`.
    pub fn consumer(kind: ManualKind, seed: u64) -> Self {
        ManualSession {
            kind,
            seed,
            tilt_deg: 0.5,
            noise: (0.02, 0.05),
            rate_hz: 100.0,
            site: (9.80160, 40.0),
        }
    }
}

/// What the session holds: results.json's keys and values (`accel.bias.x` in m/s^2,
/// `*.scale.*` in ppm, `*.misalignment.*` in mrad, `gyro.bias.*` in deg/s).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct ManualTruth {
    /// Parameter values by results.json key.
    pub parameters: BTreeMap<String, f64>,
}

/// One stretch of motion: the attitude at its start, the body axis it turns about and by
/// how much (0 for a rest), its duration, and the segment it is (if any).
struct Piece {
    c0: M3,
    axis: V3,
    angle: f64,
    dur: f64,
    seg: Option<String>,
}

/// The angle turned after `s` (0..1) of a turn: a hand's uneven move (ends at rest).
fn profile(s: f64, uneven: f64) -> f64 {
    let base = s - (2.0 * std::f64::consts::PI * s).sin() / (2.0 * std::f64::consts::PI);
    base + uneven * (1.0 - (4.0 * std::f64::consts::PI * s).cos()) * s * (1.0 - s)
}

/// d(profile)/ds.
fn profile_rate(s: f64, uneven: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let base = 1.0 - (2.0 * pi * s).cos();
    let dg = 4.0 * pi * (4.0 * pi * s).sin() * s * (1.0 - s)
        + (1.0 - (4.0 * pi * s).cos()) * (1.0 - 2.0 * s);
    base + uneven * dg
}

fn unit(v: V3) -> V3 {
    rot::scale(v, 1.0 / rot::dot(v, v).sqrt())
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

/// A random unit vector.
fn random_axis(rng: &mut ChaCha8Rng) -> V3 {
    unit([gauss(rng), gauss(rng), gauss(rng)])
}

/// The body attitude (C_LB) with body axis `j` (sign `s`) up.
fn face(j: usize, s: f64) -> M3 {
    // The rotation that takes body e_j*s to lab up [0, 0, 1].
    let e: V3 = std::array::from_fn(|k| if k == j { s } else { 0.0 });
    let up = [0.0, 0.0, 1.0];
    let c = rot::dot(e, up);
    if c > 0.999 {
        return rot::rodrigues([1.0, 0.0, 0.0], 0.0);
    }
    if c < -0.999 {
        return rot::rodrigues([1.0, 0.0, 0.0], std::f64::consts::PI);
    }
    rot::rodrigues(unit(rot::cross(e, up)), c.acos())
}

/// The pieces of a session and the truth of its IMU.
fn plan(s: &ManualSession, rng: &mut ChaCha8Rng) -> (Vec<Piece>, String) {
    let mut pieces = Vec::new();
    let mut segs = String::new();
    let tol = s.tilt_deg;
    match s.kind {
        ManualKind::SixFace => {
            let mut c = face(2, 1.0);
            for j in 0..3 {
                for sign in [1.0, -1.0] {
                    let tilt = rot::rodrigues(
                        unit([gauss(rng), gauss(rng), 0.0]),
                        s.tilt_deg.to_radians() * (gauss(rng).powi(2) + gauss(rng).powi(2)).sqrt()
                            / 2f64.sqrt(),
                    );
                    let target = rot::mul(&tilt, &face(j, sign));
                    move_to(&mut pieces, &mut c, target, 3.0);
                    let id = format!(
                        "{}_{}",
                        ["x", "y", "z"][j],
                        if sign > 0.0 { "up" } else { "down" }
                    );
                    let _ = writeln!(
                        segs,
                        "  - {{ id: {id}, kind: static, up: {}{}, attitude: nominal, tolerance_deg: {tol}, T }}",
                        if sign > 0.0 { "+" } else { "-" },
                        ["x", "y", "z"][j]
                    );
                    pieces.push(Piece {
                        c0: c,
                        axis: [0.0, 0.0, 1.0],
                        angle: 0.0,
                        dur: 6.0,
                        seg: Some(id.clone()),
                    });
                    if sign > 0.0 {
                        // A turn about the lab's vertical, the face's axis within its tilt.
                        let axis = rot::mul_tv(&c, [0.0, 0.0, 1.0]);
                        let angle = (-360.0 + tol * gauss(rng)).to_radians();
                        let rid = format!("{}_rot", ["x", "y", "z"][j]);
                        let _ = writeln!(
                            segs,
                            "  - {{ id: {rid}, kind: turn, axis: {}, angle_deg: -360, T }}",
                            ["x", "y", "z"][j]
                        );
                        pieces.push(Piece {
                            c0: c,
                            axis,
                            angle,
                            dur: 4.0,
                            seg: Some(rid),
                        });
                        c = rot::mul(&c, &rot::rodrigues(axis, angle));
                        pieces.push(Piece {
                            c0: c,
                            axis: [0.0, 0.0, 1.0],
                            angle: 0.0,
                            dur: 1.0,
                            seg: None,
                        });
                    }
                }
            }
        }
        ManualKind::MultiPose { poses } => {
            let mut c = rot::rodrigues(random_axis(rng), rng.random::<f64>() * 3.0);
            for k in 0..=poses {
                let id = format!("pose/{k:02}");
                let dur = if k == 0 {
                    30.0
                } else {
                    4.0 + 2.0 * rng.random::<f64>()
                };
                let _ = writeln!(
                    segs,
                    "  - {{ id: {id}, kind: static, attitude: unknown, T }}"
                );
                pieces.push(Piece {
                    c0: c,
                    axis: [0.0, 0.0, 1.0],
                    angle: 0.0,
                    dur,
                    seg: Some(id),
                });
                if k < poses {
                    let axis = random_axis(rng);
                    let angle = (50.0 + 100.0 * rng.random::<f64>()).to_radians()
                        * if rng.random::<bool>() { 1.0 } else { -1.0 };
                    let _ = writeln!(segs, "  - {{ id: turn/{:02}, kind: turn, T }}", k + 1);
                    pieces.push(Piece {
                        c0: c,
                        axis,
                        angle,
                        dur: 2.0 + 2.0 * rng.random::<f64>(),
                        seg: Some(format!("turn/{:02}", k + 1)),
                    });
                    c = rot::mul(&c, &rot::rodrigues(axis, angle));
                }
            }
        }
    }
    (pieces, segs)
}

/// Appends the move from `c` to `target` (a turn about their relative rotation's axis).
fn move_to(pieces: &mut Vec<Piece>, c: &mut M3, target: M3, dur: f64) {
    let rel = rot::mul(&rot::transpose(c), &target);
    let tr = rel[0][0] + rel[1][1] + rel[2][2];
    let angle = ((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos();
    if angle < 1e-9 {
        return;
    }
    let axis = if angle > std::f64::consts::PI - 1e-6 {
        // Half a turn: the axis is the column of rel + I with the largest norm.
        let k = (0..3)
            .max_by(|a, b| rel[*a][*a].total_cmp(&rel[*b][*b]))
            .unwrap_or(0);
        unit(std::array::from_fn(|i| {
            rel[i][k] + if i == k { 1.0 } else { 0.0 }
        }))
    } else {
        unit([
            rel[2][1] - rel[1][2],
            rel[0][2] - rel[2][0],
            rel[1][0] - rel[0][1],
        ])
    };
    pieces.push(Piece {
        c0: *c,
        axis,
        angle,
        dur,
        seg: None,
    });
    *c = target;
}

/// An IMU with consumer-grade errors: biases of tenths of m/s^2 and deg/s, scale errors
/// of thousands of ppm, misalignments of mrad; `upper` makes `K_a` upper triangular (the
/// convention of an unknown attitude).
fn imu(rng: &mut ChaCha8Rng, upper: bool) -> (M3, V3, M3, V3) {
    let mut k = |scale: f64, mis: f64, upper: bool| -> M3 {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                if i == j {
                    1.0 + scale * gauss(rng)
                } else if upper && i > j {
                    0.0
                } else {
                    mis * gauss(rng)
                }
            })
        })
    };
    let k_a = k(0.01, 0.01, upper);
    let k_g = k(0.01, 0.01, false);
    let b_a = [0.3 * gauss(rng), 0.3 * gauss(rng), 0.3 * gauss(rng)];
    let b_g = [0.5 * gauss(rng), 0.5 * gauss(rng), 0.5 * gauss(rng)];
    (k_a, b_a, k_g, b_g)
}

/// Writes `dir/{manifest.yaml, imu.csv, table.csv, truth.json}` for `s`.
pub fn write_manual(dir: &Path, s: &ManualSession) -> io::Result<ManualTruth> {
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    let (k_a, b_a, k_g, b_g) = imu(&mut rng, matches!(s.kind, ManualKind::MultiPose { .. }));
    let (pieces, segs) = plan(s, &mut rng);
    let (g, lat) = s.site;
    let omega_l = rot::scale(
        [0.0, lat.to_radians().cos(), lat.to_radians().sin()],
        OMEGA_E,
    );
    let dt = 1.0 / s.rate_hz;
    let mut imu_csv = String::from("t,ax,ay,az,gx,gy,gz\n");
    let mut times: Vec<(String, f64, f64)> = Vec::new();
    let mut t0 = 0.0;
    let mut n = 0u64;
    for p in &pieces {
        let t1 = t0 + p.dur;
        let first = n;
        while (n as f64) * dt < t1 - 1e-9 {
            let t = n as f64 * dt;
            let sfrac = ((t - t0) / p.dur).clamp(0.0, 1.0);
            let th = p.angle * profile(sfrac, 0.15);
            let rate = p.angle * profile_rate(sfrac, 0.15) / p.dur;
            let c = rot::mul(&p.c0, &rot::rodrigues(p.axis, th));
            let f_b = rot::mul_tv(&c, [0.0, 0.0, g]);
            let w_ib = rot::add(rot::scale(p.axis, rate), rot::mul_tv(&c, omega_l));
            let a = rot::add(rot::mul_v(&k_a, f_b), b_a);
            let w = rot::add(
                rot::mul_v(&k_g, rot::scale(w_ib, 180.0 / std::f64::consts::PI)),
                b_g,
            );
            let _ = writeln!(
                imu_csv,
                "{t:.4},{},{},{},{},{},{}",
                a[0] + s.noise.0 * gauss(&mut rng),
                a[1] + s.noise.0 * gauss(&mut rng),
                a[2] + s.noise.0 * gauss(&mut rng),
                w[0] + s.noise.1 * gauss(&mut rng),
                w[1] + s.noise.1 * gauss(&mut rng),
                w[2] + s.noise.1 * gauss(&mut rng)
            );
            n += 1;
        }
        if let Some(id) = &p.seg {
            // A turn's window holds the rest sample before and after it.
            let (a, b) = if p.angle != 0.0 {
                ((first as f64 - 1.0).max(0.0) * dt, n as f64 * dt)
            } else {
                (first as f64 * dt, (n - 1) as f64 * dt)
            };
            times.push((id.clone(), a, b));
        }
        t0 = t1;
    }
    // A last rest so that a turn's closing sample exists.
    for _ in 0..10 {
        let _ = writeln!(imu_csv, "{:.4},0,0,{g},0,0,0", n as f64 * dt);
        n += 1;
    }
    let t_end = (n - 1) as f64 * dt;
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join("imu.csv"), imu_csv)?;
    let mut table = String::from("t,outer,inner,outer_rate,inner_rate\n");
    let mut t = 0.0;
    while t <= t_end + 1e-9 {
        let _ = writeln!(table, "{t:.4},0,0,0,0");
        t += 0.02;
    }
    std::fs::write(dir.join("table.csv"), table)?;
    std::fs::write(dir.join("manifest.yaml"), manifest(&segs, &times, s))?;
    let truth = truth(&k_a, b_a, &k_g, b_g);
    std::fs::write(
        dir.join("truth.json"),
        serde_json::to_string_pretty(&truth).unwrap_or_default(),
    )?;
    Ok(truth)
}

/// The manifest: the seed station's axes (no table: its stream is zeros), the segments
/// with their times in place of `T`.
fn manifest(segs: &str, times: &[(String, f64, f64)], s: &ManualSession) -> String {
    let mut out = format!(
        "format: ratecal-recording/1\nstation:\n  site: {{ latitude_deg: {}, gravity_mps2: {} }}\n  table:\n    outer_axis: [0, -1, 0]\n    inner_axis: [1, 0, 0]\n    model: \"none: a hand (ratecal-witness)\"\nimu: {{ model: witness consumer, serial: \"seed {}\" }}\nsegments:\n",
        s.site.1, s.site.0, s.seed
    );
    for (line, (_, a, b)) in segs.lines().zip(times) {
        let _ = writeln!(
            out,
            "{}",
            line.replace(" T }", &format!(" t_start: {a:.4}, t_end: {b:.4} }}"))
        );
    }
    out
}

fn truth(k_a: &M3, b_a: V3, k_g: &M3, b_g: V3) -> ManualTruth {
    let ax = ["x", "y", "z"];
    let mut p = BTreeMap::new();
    for (sensor, k, b) in [("accel", k_a, b_a), ("gyro", k_g, b_g)] {
        for i in 0..3 {
            p.insert(format!("{sensor}.bias.{}", ax[i]), b[i]);
            for j in 0..3 {
                if i == j {
                    p.insert(format!("{sensor}.scale.{}", ax[i]), (k[i][i] - 1.0) * 1e6);
                } else {
                    p.insert(
                        format!("{sensor}.misalignment.{}{}", ax[i], ax[j]),
                        k[i][j] * 1e3,
                    );
                }
            }
        }
    }
    ManualTruth { parameters: p }
}
