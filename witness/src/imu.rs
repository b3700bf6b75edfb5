//! The IMU of physics.md's measurement model, in closed form: per-axis bias and scale,
//! misalignment, white noise and a wandering gyro bias.

use serde::Serialize;

use crate::rot::{M3, V3};

/// The IMU's nominal errors and noise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Imu {
    /// `b_a`, the accelerometer output at zero input, m/s^2.
    pub accel_bias_mps2: V3,
    /// `K_a[i][i] - 1`, ppm.
    pub accel_scale_ppm: V3,
    /// `K_a[i][j] * 1000` for i != j, mrad (the diagonal is ignored).
    pub accel_misalignment_mrad: M3,
    /// `b_g`, the gyro output at zero input, deg/s (the wandering part starts at zero).
    pub gyro_bias_dps: V3,
    /// `K_g[i][i] - 1`, ppm.
    pub gyro_scale_ppm: V3,
    /// `K_g[i][j] * 1000` for i != j, mrad (the diagonal is ignored).
    pub gyro_misalignment_mrad: M3,
    /// White noise of each accelerometer sample, standard deviation, m/s^2.
    pub accel_noise_mps2: f64,
    /// White noise of each gyro sample, standard deviation, deg/s.
    pub gyro_noise_dps: f64,
    /// Gyro bias random walk: the bias's standard deviation grows by this times sqrt(t s),
    /// deg/s per sqrt(s).
    pub gyro_bias_walk_dps_per_sqrt_s: f64,
    /// Gyro bias instability as a first-order Gauss-Markov process (deg/s), on each axis.
    pub gyro_bias_gm: Option<GaussMarkov>,
    /// Accelerometer bias instability as a first-order Gauss-Markov process (m/s^2).
    pub accel_bias_gm: Option<GaussMarkov>,
}

/// A first-order Gauss-Markov process: stationary standard deviation `sigma`, correlation
/// time `tau_s`; `x(t + dt) = exp(-dt/tau) x(t) + sigma sqrt(1 - exp(-2 dt/tau)) n`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GaussMarkov {
    /// Stationary standard deviation (the output's unit).
    pub sigma: f64,
    /// Correlation time, s.
    pub tau_s: f64,
}

impl GaussMarkov {
    /// The factors `(exp(-dt/tau), sigma sqrt(1 - exp(-2 dt/tau)))` of one step of `dt`.
    pub fn step(&self, dt: f64) -> (f64, f64) {
        let a = (-dt / self.tau_s).exp();
        (a, self.sigma * (1.0 - a * a).sqrt())
    }
}

impl Imu {
    /// A perfect IMU: no error, no noise.
    pub fn ideal() -> Imu {
        Imu {
            accel_bias_mps2: [0.0; 3],
            accel_scale_ppm: [0.0; 3],
            accel_misalignment_mrad: [[0.0; 3]; 3],
            gyro_bias_dps: [0.0; 3],
            gyro_scale_ppm: [0.0; 3],
            gyro_misalignment_mrad: [[0.0; 3]; 3],
            accel_noise_mps2: 0.0,
            gyro_noise_dps: 0.0,
            gyro_bias_walk_dps_per_sqrt_s: 0.0,
            gyro_bias_gm: None,
            accel_bias_gm: None,
        }
    }

    /// A tactical-grade IMU like the shared open-* examples' (noise 0.003 m/s^2 and
    /// 0.005 deg/s per sample, a bias wandering about 1 deg/h over a run), with the
    /// biases and scales of `standard-with-lever-arm` and no misalignment.
    pub fn tactical() -> Imu {
        Imu {
            accel_bias_mps2: [-0.012, 0.027, -0.019],
            accel_scale_ppm: [-650.0, 930.0, 410.0],
            gyro_bias_dps: [-0.042, 0.061, 0.025],
            gyro_scale_ppm: [-1200.0, 700.0, 1100.0],
            accel_noise_mps2: 0.003,
            gyro_noise_dps: 0.005,
            gyro_bias_walk_dps_per_sqrt_s: 1.0e-5,
            ..Imu::ideal()
        }
    }

    /// `K_a`.
    pub fn k_a(&self) -> M3 {
        sensitivity(self.accel_scale_ppm, &self.accel_misalignment_mrad)
    }

    /// `K_g`.
    pub fn k_g(&self) -> M3 {
        sensitivity(self.gyro_scale_ppm, &self.gyro_misalignment_mrad)
    }
}

fn sensitivity(scale_ppm: V3, misalignment_mrad: &M3) -> M3 {
    let mut k = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            k[i][j] = if i == j {
                1.0 + scale_ppm[i] * 1e-6
            } else {
                misalignment_mrad[i][j] * 1e-3
            };
        }
    }
    k
}
