//! Writing a scenario as a recording folder (spec/recording-format.md) with std formatting,
//! and its `truth.json` beside.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::Path;

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use serde::Serialize;

use crate::hidden::HiddenTruth;
use crate::motion::Timeline;
use crate::rot::{M3, V3};
use crate::scenario::Scenario;

/// What was put in a recording (`truth.json`, not part of the format).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Truth {
    /// The scenario's name.
    pub name: String,
    /// Its seed.
    pub seed: u64,
    /// Who wrote it.
    pub written_by: String,
    /// Site latitude, deg.
    pub latitude_deg: f64,
    /// Local gravity, m/s^2.
    pub gravity_mps2: f64,
    /// True azimuth of the table's nominal North, deg (not in the manifest).
    pub heading_deg: f64,
    /// The nominal model's parameters, as results.json reports them.
    pub nominal: Nominal,
    /// The noise.
    pub noise: Noise,
    /// The hidden effects.
    pub hidden: Vec<HiddenTruth>,
    /// The end of both streams, s.
    pub duration_s: f64,
    /// The realised wandering part of the gyro bias, averaged over each segment's IMU
    /// samples (by time stamp), deg/s: the bias a fit of that segment sees is
    /// `nominal.gyro_bias_dps` plus this.
    pub gyro_walk_mean_dps: BTreeMap<String, V3>,
}

/// The nominal parameters: biases as outputs at zero input, scales as `K_ii - 1`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Nominal {
    /// m/s^2.
    pub accel_bias: V3,
    /// ppm.
    pub accel_scale_ppm: V3,
    /// `K_a[i][j]`, mrad (diagonal 0).
    pub accel_misalignment_mrad: M3,
    /// deg/s (the wandering part starts at zero at t = 0).
    pub gyro_bias_dps: V3,
    /// ppm.
    pub gyro_scale_ppm: V3,
    /// `K_g[i][j]`, mrad (diagonal 0).
    pub gyro_misalignment_mrad: M3,
}

/// The random part.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Noise {
    /// White noise per accelerometer sample, m/s^2.
    pub accel_mps2: f64,
    /// White noise per gyro sample, deg/s.
    pub gyro_dps: f64,
    /// Gyro bias random walk, deg/s per sqrt(s).
    pub gyro_bias_walk_dps_per_sqrt_s: f64,
}

fn off_diagonal(m: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 0.0 } else { m[i][j] }))
}

impl Truth {
    fn of(s: &Scenario, timeline: &Timeline, walk: BTreeMap<String, V3>) -> Truth {
        let imu = &s.imu;
        Truth {
            name: s.name.clone(),
            seed: s.seed,
            written_by: format!("ratecal-witness {}", env!("CARGO_PKG_VERSION")),
            latitude_deg: s.station.latitude_deg,
            gravity_mps2: s.station.gravity_mps2,
            heading_deg: s.station.heading_deg,
            nominal: Nominal {
                accel_bias: imu.accel_bias_mps2,
                accel_scale_ppm: imu.accel_scale_ppm,
                accel_misalignment_mrad: off_diagonal(&imu.accel_misalignment_mrad),
                gyro_bias_dps: imu.gyro_bias_dps,
                gyro_scale_ppm: imu.gyro_scale_ppm,
                gyro_misalignment_mrad: off_diagonal(&imu.gyro_misalignment_mrad),
            },
            noise: Noise {
                accel_mps2: imu.accel_noise_mps2,
                gyro_dps: imu.gyro_noise_dps,
                gyro_bias_walk_dps_per_sqrt_s: imu.gyro_bias_walk_dps_per_sqrt_s,
            },
            hidden: s.hidden.iter().map(|h| h.truth()).collect(),
            duration_s: timeline.duration_s,
            gyro_walk_mean_dps: walk,
        }
    }
}

/// Writes `scenario` as a recording folder `dir` (created if absent): `manifest.yaml`,
/// `imu.csv`, `table.csv`, and `truth.json` beside them; returns the truth.
pub fn write(dir: &Path, scenario: &Scenario) -> io::Result<Truth> {
    fs::create_dir_all(dir)?;
    let timeline = scenario.timeline();
    fs::write(dir.join("manifest.yaml"), manifest(scenario, &timeline))?;
    let walk = write_imu(&dir.join("imu.csv"), scenario, &timeline)?;
    write_table(&dir.join("table.csv"), scenario, &timeline)?;
    let truth = Truth::of(scenario, &timeline, walk);
    let json = serde_json::to_string_pretty(&truth).map_err(io::Error::other)?;
    fs::write(dir.join("truth.json"), json + "\n")?;
    Ok(truth)
}

fn vector(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

/// The manifest, in the block and flow styles of the shared examples.
pub(crate) fn manifest(s: &Scenario, timeline: &Timeline) -> String {
    let st = &s.station;
    let mut out = String::new();
    let m = st.mount;
    // Writing to a String cannot fail.
    let _ = write!(
        out,
        "format: ratecal-recording/1\nstation:\n  site: {{ latitude_deg: {:.4}, gravity_mps2: {:.5} }}\n  \
         table:\n    outer_axis: {}\n    inner_axis: {}\n  mount:\n    rotation: [{}, {}, {}]\n\
         imu: {{ model: \"ratecal-witness\", serial: \"{}\", grade: tactical }}\nsegments:\n",
        st.latitude_deg,
        st.gravity_mps2,
        vector(st.outer_axis),
        vector(st.inner_axis),
        vector(m[0]),
        vector(m[1]),
        vector(m[2]),
        s.name,
    );
    for seg in &timeline.segments {
        let _ = write!(
            out,
            "  - {{\"id\": \"{}\", \"kind\": \"{}\", \"t_start\": {:.4}, \"t_end\": {:.4}",
            seg.id,
            if seg.rate.is_some() { "rate" } else { "static" },
            seg.t_start,
            seg.t_end
        );
        if let Some((pitch, roll)) = seg.attitude_deg {
            let _ = write!(out, ", \"pitch_deg\": {pitch:?}, \"roll_deg\": {roll:?}");
        }
        if let Some((axis, rate)) = seg.rate {
            let _ = write!(
                out,
                ", \"axis\": \"{}\", \"rate_dps\": {rate:?}",
                axis.name()
            );
        }
        out.push_str("}\n");
    }
    out
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

/// Writes imu.csv; returns the wandering bias's mean over each segment.
fn write_imu(path: &Path, s: &Scenario, timeline: &Timeline) -> io::Result<BTreeMap<String, V3>> {
    let segs = &timeline.segments;
    let mut sums = vec![([0.0f64; 3], 0.0f64); segs.len()];
    let mut f = BufWriter::new(File::create(path)?);
    writeln!(f, "t,ax,ay,az,gx,gy,gz,temp")?;
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    let dt = 1.0 / s.imu_rate_hz;
    let walk_step = s.imu.gyro_bias_walk_dps_per_sqrt_s * dt.sqrt();
    let mut walk = [0.0; 3];
    // Bias instability (Gauss-Markov), started from its stationary distribution; drawn
    // only when the scenario asks, so that other scenarios' samples stay as they were.
    let gm = [s.imu.accel_bias_gm, s.imu.gyro_bias_gm];
    let mut gm_x = [[0.0f64; 3]; 2];
    for (x, p) in gm_x.iter_mut().zip(&gm) {
        if let Some(p) = p {
            *x = std::array::from_fn(|_| p.sigma * normal(&mut rng));
        }
    }
    for k in 0u64.. {
        let t_stamp = s.imu_t0_s + k as f64 * dt;
        if t_stamp > timeline.duration_s {
            break;
        }
        let inst = s.instant(timeline, t_stamp);
        for (seg, (sum, n)) in segs.iter().zip(sums.iter_mut()) {
            if (seg.t_start..=seg.t_end).contains(&t_stamp) {
                *sum = std::array::from_fn(|i| sum[i] + walk[i]);
                *n += 1.0;
            }
        }
        let (mut a, mut w) = s.outputs(&inst);
        for i in 0..3 {
            a[i] += s.imu.accel_noise_mps2 * normal(&mut rng);
            w[i] += walk[i] + s.imu.gyro_noise_dps * normal(&mut rng);
            walk[i] += walk_step * normal(&mut rng);
        }
        for (j, p) in gm.iter().enumerate() {
            let Some(p) = p else { continue };
            let (decay, kick) = p.step(dt);
            for i in 0..3 {
                if j == 0 {
                    a[i] += gm_x[j][i];
                } else {
                    w[i] += gm_x[j][i];
                }
                gm_x[j][i] = decay * gm_x[j][i] + kick * normal(&mut rng);
            }
        }
        writeln!(
            f,
            "{t_stamp:.5},{:.6},{:.6},{:.6},{:.7},{:.7},{:.7},{:.3}",
            a[0], a[1], a[2], w[0], w[1], w[2], inst.temp_c
        )?;
    }
    f.flush()?;
    Ok(segs
        .iter()
        .zip(sums)
        .map(|(seg, (sum, n))| (seg.id.clone(), sum.map(|v| v / n.max(1.0))))
        .collect())
}

fn write_table(path: &Path, s: &Scenario, timeline: &Timeline) -> io::Result<()> {
    let mut f = BufWriter::new(File::create(path)?);
    writeln!(f, "t,outer,inner,outer_rate,inner_rate")?;
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed ^ 0x7AB1_E5EE_D000_0001);
    for k in 0u64.. {
        let t = k as f64 / s.table_rate_hz;
        if t > timeline.duration_s {
            break;
        }
        let [o, i] = timeline.state(t);
        let mut n = || normal(&mut rng);
        writeln!(
            f,
            "{t:.5},{:.6},{:.6},{:.5},{:.5}",
            o[0] + s.table_angle_noise_deg * n(),
            i[0] + s.table_angle_noise_deg * n(),
            o[1] + s.table_rate_noise_dps * n(),
            i[1] + s.table_rate_noise_dps * n(),
        )?;
    }
    f.flush()
}
