//! The size effect on recordings written here by a second, deliberately simple
//! implementation of spec/physics.md (closed forms, not `ratecal_physics`'s kinematics):
//! the attitude of a sinusoidal sway about a vertical axis, `C_LB = R_x(tilt) R_z(th) C_PB`,
//! and the specific force `C_LB^T [0, 0, g] + dw x rho + w x (w x rho)` at each sensing
//! point `rho = p + r_i`, written as `imu.csv`, `table.csv` and `manifest.yaml` and read
//! back. Geometry the shared example does not have: the sway is about the table's inner
//! axis (vertical at outer 0), -X is brought up by a remount tilted +87 deg, the cycles run
//! Y, X, Z, and the reference centre sits 40 mm off along X, -30 along Y, 70 along Z.

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use ratecal_analysis::fit::size_effect::{COORDS, SizeEffect, estimate};
use ratecal_recording::{self as recording, SegmentKind};
use std::f64::consts::PI;
use std::fmt::Write as _;

type V = [f64; 3];
type M = [[f64; 3]; 3];

const LAT_DEG: f64 = 31.0;
const G: f64 = 9.7935;
const HZ: f64 = 100.0;
/// Truth, mm: rxy, rxz, ryx, ryz, rzx, rzy (r_ii = 0).
const R_MM: [f64; 6] = [3.1, -4.4, 2.2, -5.0, 6.3, 1.7];
/// The reference centre from the table axes, body axes, mm.
const P_MM: V = [40.0, -30.0, 70.0];

fn mul(a: &M, b: &M) -> M {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}
fn mv(a: &M, v: &V) -> V {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}
fn tr(a: &M) -> M {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}
fn cross(a: &V, b: &V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn rx(t: f64) -> M {
    let (s, c) = t.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}
fn ry(t: f64) -> M {
    let (s, c) = t.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}
fn rz(t: f64) -> M {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// One stretch of the experiment: the outer tilt (about East), the mount, and the inner
/// axis's motion (`None` at rest at 0, or a sway with its period and steady periods).
struct Phase {
    id: Option<String>,
    tilt_deg: f64,
    mount: M,
    sway: Option<(f64, f64)>,
    rest_s: f64,
}

/// `th, th', th''` of a sway of 90 deg ramped up over two periods, `n` steady, two down.
fn sway(period: f64, n: f64, s: f64) -> [f64; 3] {
    let (a, w) = (PI / 2.0, 2.0 * PI / period);
    let ramp = 2.0 * period;
    let total = n * period + 2.0 * ramp;
    // Smoothstep envelope and its derivatives.
    let env = |x: f64| (x * x * (3.0 - 2.0 * x), 6.0 * x * (1.0 - x), 6.0 - 12.0 * x);
    let (e, de, dde) = if s < ramp {
        let (e, d, dd) = env(s / ramp);
        (e, d / ramp, dd / ramp / ramp)
    } else if s > total - ramp {
        let (e, d, dd) = env((total - s) / ramp);
        (e, -d / ramp, dd / ramp / ramp)
    } else {
        (1.0, 0.0, 0.0)
    };
    let (sn, cs) = (w * s).sin_cos();
    [
        a * e * sn,
        a * (de * sn + e * w * cs),
        a * (dde * sn + 2.0 * de * w * cs - e * w * w * sn),
    ]
}

/// Writes the recording into `dir`: a navigation-grade IMU (biases, scale errors, white
/// noise) at 100 Hz, the table at 50 Hz.
fn write(dir: &std::path::Path, phases: &[Phase], seed: u64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let lat = LAT_DEG.to_radians();
    let omega_l = [0.0, lat.cos() * 7.292115e-5, lat.sin() * 7.292115e-5];
    let r = R_MM.map(|v| v * 1e-3);
    let p = P_MM.map(|v| v * 1e-3);
    let sens: [V; 3] = [
        [p[0], p[1] + r[0], p[2] + r[1]],
        [p[0] + r[2], p[1], p[2] + r[3]],
        [p[0] + r[4], p[1] + r[5], p[2]],
    ];
    let (b_a, s_a) = ([3e-4, -4e-4, 2.5e-4], [40e-6, -30e-6, 25e-6]);
    let (b_g, s_g) = (
        [0.004 / 3600.0, -0.003 / 3600.0, 0.005 / 3600.0],
        [8e-6, -6e-6, 5e-6],
    );
    let mut imu = String::from("t,ax,ay,az,gx,gy,gz\n");
    let mut table = String::from("t,outer,inner,outer_rate,inner_rate\n");
    let mut segs = String::new();
    let fmt_m = |m: &M| format!("[{:?}, {:?}, {:?}]", m[0], m[1], m[2]);
    let mut k_total = 0usize;
    let mut t0 = 0.0;
    for ph in phases {
        let (dur, n) = match ph.sway {
            Some((period, n)) => ((n + 4.0) * period, n),
            None => (ph.rest_s, 0.0),
        };
        let steps = (dur * HZ).round() as usize;
        for k in 0..steps {
            let s = k as f64 / HZ;
            let t = t0 + s;
            let [th, dth, ddth] = ph.sway.map_or([0.0; 3], |(period, _)| sway(period, n, s));
            let c_lb = mul(&mul(&rx(ph.tilt_deg.to_radians()), &rz(th)), &ph.mount);
            let c_bl = tr(&c_lb);
            // The inner axis is P's z: w_B = C_PB^T z th', dw_B = C_PB^T z th''.
            let axis_b = mv(&tr(&ph.mount), &[0.0, 0.0, 1.0]);
            let w = axis_b.map(|a| a * dth);
            let dw = axis_b.map(|a| a * ddth);
            let grav = mv(&c_bl, &[0.0, 0.0, G]);
            let earth = mv(&c_bl, &omega_l);
            let mut row = format!("{:.5}", t + 0.0037);
            let mut acc = [0.0; 3];
            for i in 0..3 {
                let rho = sens[i];
                let a_pt = cross(&dw, &rho);
                let c_pt = cross(&w, &cross(&w, &rho));
                let f = grav[i] + a_pt[i] + c_pt[i];
                let noise: f64 = rng.sample::<f64, _>(StandardNormal) * 2e-3;
                acc[i] = (1.0 + s_a[i]) * f + b_a[i] + noise;
            }
            for v in acc {
                write!(row, ",{v:.8}").unwrap();
            }
            for i in 0..3 {
                let noise: f64 = rng.sample::<f64, _>(StandardNormal) * 3e-4;
                let g = ((1.0 + s_g[i]) * (w[i] + earth[i])).to_degrees() + b_g[i] + noise;
                write!(row, ",{g:.9}").unwrap();
            }
            imu.push_str(&row);
            imu.push('\n');
            if k_total.is_multiple_of(2) {
                writeln!(
                    table,
                    "{t:.5},{:.6},{:.6},0,{:.5}",
                    ph.tilt_deg,
                    th.to_degrees(),
                    dth.to_degrees()
                )
                .unwrap();
            }
            k_total += 1;
        }
        if let Some(id) = &ph.id {
            let mount = fmt_m(&ph.mount);
            match ph.sway {
                Some((period, n)) => {
                    let start = t0 + 2.0 * period;
                    writeln!(
                        segs,
                        "  - {{ id: \"{id}\", kind: oscillation, axis: inner, amplitude_deg: 90, period_s: {period}, center_deg: 0, t_start: {start}, t_end: {}, mount: {{ rotation: {mount} }} }}",
                        start + n * period
                    )
                    .unwrap();
                }
                None => writeln!(
                    segs,
                    "  - {{ id: \"{id}\", kind: static, t_start: {}, t_end: {}, mount: {{ rotation: {mount} }} }}",
                    t0 + 2.0,
                    t0 + dur - 2.0
                )
                .unwrap(),
            }
        }
        t0 += steps as f64 / HZ;
    }
    let manifest = format!(
        "format: ratecal-recording/1\nstation:\n  site: {{ latitude_deg: {LAT_DEG}, gravity_mps2: {G} }}\n  table:\n    outer_axis: [1, 0, 0]\n    inner_axis: [0, 0, 1]\nimu: {{ model: closed-form, serial: \"1\", grade: navigation }}\nsegments:\n{segs}"
    );
    std::fs::write(dir.join("manifest.yaml"), manifest).unwrap();
    std::fs::write(dir.join("imu.csv"), imu).unwrap();
    std::fs::write(dir.join("table.csv"), table).unwrap();
}

const ID: M = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// One cycle: alignment at rest, the two sways with rests between and after.
fn cycle(name: &str, tilt_deg: f64, mount: M, periods: &[(f64, f64)]) -> Vec<Phase> {
    let mut v = vec![Phase {
        id: Some(format!("align/{name}")),
        tilt_deg,
        mount,
        sway: None,
        rest_s: 64.0,
    }];
    for &(period, n) in periods {
        v.push(Phase {
            id: Some(format!("sway/{name}/{period}")),
            tilt_deg,
            mount,
            sway: Some((period, n)),
            rest_s: 0.0,
        });
        v.push(Phase {
            id: None,
            tilt_deg,
            mount,
            sway: None,
            rest_s: 40.0,
        });
    }
    v
}

fn check(est: &SizeEffect, tol_mm: f64) {
    for (m, (_, _, name)) in COORDS.iter().enumerate() {
        let (v, u) = est.coords_m[m].unwrap_or_else(|| panic!("{name} unobservable"));
        let err = v * 1e3 - R_MM[m];
        eprintln!(
            "{name}: {:.3} mm (truth {}, error {err:+.3}, u {:.3})",
            v * 1e3,
            R_MM[m],
            u * 1e3
        );
        assert!(err.abs() < tol_mm, "{name}: {} mm vs {}", v * 1e3, R_MM[m]);
    }
}

fn sways(rec: &recording::Recording) -> Vec<usize> {
    let segs = &rec.manifest.segments;
    (0..segs.len())
        .filter(|&i| segs[i].kind == SegmentKind::Oscillation)
        .collect()
}

/// -X up: a remount tilted +87 deg about North (X at 3 deg from the downward vertical).
fn x_down() -> M {
    ry(87f64.to_radians())
}

/// Y up: a remount a quarter turn about X.
fn y_up() -> M {
    rx(PI / 2.0)
}

#[test]
fn inner_axis_sway_remount_tilted_plus_87_and_an_offset_centre() {
    let tmp = tempfile::tempdir().unwrap();
    let periods = [(5.0, 48.0), (10.0, 24.0)];
    let mut phases = cycle("y", 0.0, y_up(), &periods);
    phases.extend(cycle("x", 0.0, x_down(), &periods));
    phases.extend(cycle("z", 0.0, ID, &periods));
    write(tmp.path(), &phases, 7);
    let rec = recording::read(tmp.path()).unwrap();
    let est = estimate(&rec, &sways(&rec));
    assert!(est.left_out.is_empty(), "{:?}", est.left_out);
    let ups: Vec<(usize, usize)> = est.drifts.iter().map(|d| (d.group, d.up_axis.0)).collect();
    assert_eq!(ups, vec![(0, 1), (0, 1), (1, 0), (1, 0), (2, 2), (2, 2)]);
    check(&est, 0.3);
    // The periods' difference, with what explains it, per cycle.
    let cycles = est.cycle_reports();
    assert_eq!(cycles.len(), 3);
    for c in &cycles {
        for k in 0..2 {
            assert!(c.residual_mps2[k].abs() < 3.0 * c.u_mps2[k] + 1e-6, "{c:?}");
        }
    }
}

#[test]
fn unusable_cycles_are_named_and_left_out_without_harm() {
    let tmp = tempfile::tempdir().unwrap();
    let periods = [(5.0, 48.0), (10.0, 24.0)];
    let mut phases = cycle("z", 0.0, ID, &periods);
    // The inner axis tilted 30 deg by the outer one: its sway is not about the vertical.
    phases.extend(cycle("tilted", 30.0, ID, &periods));
    phases.extend(cycle("x", 0.0, x_down(), &periods));
    // Three periods only.
    phases.extend(cycle("short", 0.0, ID, &[(5.0, 3.0)]));
    phases.extend(cycle("y", 0.0, y_up(), &periods));
    write(tmp.path(), &phases, 11);
    let rec = recording::read(tmp.path()).unwrap();
    let est = estimate(&rec, &sways(&rec));
    let left: Vec<(&str, &str)> = est
        .left_out
        .iter()
        .map(|l| (l.segment.as_str(), l.reason.as_str()))
        .collect();
    eprintln!("{left:#?}");
    assert_eq!(left.len(), 3, "{left:?}");
    for (seg, why) in &left {
        if seg.starts_with("sway/tilted/") {
            assert!(why.contains("30.0 deg from the vertical"), "{why}");
        } else {
            assert_eq!(*seg, "sway/short/5", "{why}");
            assert!(why.contains("too short"), "{why}");
        }
    }
    assert!(
        est.drifts
            .iter()
            .all(|d| !d.id.contains("tilted") && !d.id.contains("short"))
    );
    check(&est, 0.3);
    // Without the Y cycle, rxz and rzx are not observable and say what they need.
    let no_y: Vec<usize> = sways(&rec)
        .into_iter()
        .filter(|&i| !rec.manifest.segments[i].id.starts_with("sway/y/"))
        .collect();
    let est = estimate(&rec, &no_y);
    for m in [1, 4] {
        assert!(est.coords_m[m].is_none(), "{}", COORDS[m].2);
        assert!(
            est.unobservable[m].contains("Y up"),
            "{}",
            est.unobservable[m]
        );
    }
}
