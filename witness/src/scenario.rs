//! A [`Scenario`]: station, plan, IMU, hidden effects, sampling and seed; and its noise-free
//! closed forms, which [`crate::write`] samples and tests check against.

use crate::hidden::Hidden;
use crate::imu::Imu;
use crate::motion::{Plan, Timeline};
use crate::rot::{self, V3};
use crate::station::{Instant, Station};

/// The IMU's internal temperature: `start_c + rise_c (1 - exp(-t / tau_s))` (no effect on
/// the outputs unless a hidden effect uses it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thermal {
    /// At power-on, degC.
    pub start_c: f64,
    /// Rise towards equilibrium, degC.
    pub rise_c: f64,
    /// Time constant, s.
    pub tau_s: f64,
}

/// Everything a witness recording is made of.
#[derive(Debug)]
pub struct Scenario {
    /// Name (the manifest's IMU serial and the truth's name).
    pub name: String,
    /// Seed of every random draw (noise, wandering bias, table feedback noise).
    pub seed: u64,
    /// Site, table axes, mount.
    pub station: Station,
    /// The motion.
    pub plan: Plan,
    /// The IMU's nominal errors and noise.
    pub imu: Imu,
    /// Extra physics added to the outputs.
    pub hidden: Vec<Hidden>,
    /// IMU sample rate on the IMU's clock, Hz.
    pub imu_rate_hz: f64,
    /// Table feedback rate, Hz.
    pub table_rate_hz: f64,
    /// First IMU time stamp, s (the streams are sampled at different instants).
    pub imu_t0_s: f64,
    /// White noise of the table's angle feedback, deg.
    pub table_angle_noise_deg: f64,
    /// White noise of the table's rate feedback, deg/s.
    pub table_rate_noise_dps: f64,
    /// The IMU's internal temperature.
    pub thermal: Thermal,
}

impl Scenario {
    /// The standard procedure's shape with a 300 s gyro-bias block, a tactical IMU
    /// ([`Imu::tactical`]) on the seed station at latitude 40 deg, IMU 100 Hz, table 50 Hz,
    /// nothing hidden.
    pub fn standard(name: &str, seed: u64) -> Scenario {
        Scenario {
            name: name.into(),
            seed,
            station: Station::default(),
            plan: Plan::standard(300.0),
            imu: Imu::tactical(),
            hidden: Vec::new(),
            imu_rate_hz: 100.0,
            table_rate_hz: 50.0,
            imu_t0_s: 0.0037,
            table_angle_noise_deg: 0.0003,
            table_rate_noise_dps: 0.002,
            thermal: Thermal {
                start_c: 22.0,
                rise_c: 3.0,
                tau_s: 600.0,
            },
        }
    }

    /// Unit number `n` of a fleet of one model: [`Scenario::standard`] named `serial` with
    /// a `gyro_bias_s` gyro-bias block, its biases and scale factors its own (drawn from
    /// `n`, within a tactical unit's spread: 20 mm/s^2, 1000 ppm, 0.05 deg/s, 1500 ppm), the
    /// noise from `seed`.
    pub fn fleet_unit(serial: &str, n: u64, seed: u64, gyro_bias_s: f64) -> Scenario {
        let mut s = Scenario::standard(serial, seed);
        s.plan = Plan::standard(gyro_bias_s);
        let r = |k: u64| (((n * 7 + k) * 2_654_435_761) % 1000) as f64 / 1000.0 - 0.5;
        s.imu.accel_bias_mps2 = [0.04 * r(1), 0.04 * r(2), 0.04 * r(3)];
        s.imu.accel_scale_ppm = [2000.0 * r(4), 2000.0 * r(5), 2000.0 * r(6)];
        s.imu.gyro_bias_dps = [0.1 * r(7), 0.1 * r(8), 0.1 * r(9)];
        s.imu.gyro_scale_ppm = [3000.0 * r(10), 3000.0 * r(11), 3000.0 * r(12)];
        s
    }

    /// Adds a hidden effect.
    pub fn with(mut self, hidden: Hidden) -> Scenario {
        self.hidden.push(hidden);
        self
    }

    /// No random part at all: no white noise, no wandering bias, exact table feedback.
    pub fn quiet(mut self) -> Scenario {
        self.imu.accel_noise_mps2 = 0.0;
        self.imu.gyro_noise_dps = 0.0;
        self.imu.gyro_bias_walk_dps_per_sqrt_s = 0.0;
        self.table_angle_noise_deg = 0.0;
        self.table_rate_noise_dps = 0.0;
        self
    }

    /// The plan laid out in time.
    pub fn timeline(&self) -> Timeline {
        Timeline::new(&self.plan)
    }

    /// Table time of the motion that the IMU sample stamped `t_stamp` measured:
    /// `t_stamp / (1 + eps) - tau` under [`Hidden::ClockRate`] and [`Hidden::TimeOffset`].
    pub fn table_time(&self, t_stamp: f64) -> f64 {
        let mut eps = 0.0;
        let mut tau = 0.0;
        for h in &self.hidden {
            match h {
                Hidden::ClockRate { ppm } => eps += ppm * 1e-6,
                Hidden::TimeOffset { tau_ms } => tau += tau_ms * 1e-3,
                _ => {}
            }
        }
        t_stamp / (1.0 + eps) - tau
    }

    /// The IMU temperature at table time `t`, degC.
    pub fn temp_c(&self, t: f64) -> f64 {
        let th = &self.thermal;
        th.start_c + th.rise_c * (1.0 - (-t / th.tau_s).exp())
    }

    /// What an ideal IMU senses for the sample stamped `t_stamp`: the plan is what the
    /// table reports; the table's own errors ([`Hidden::TableEncoderEccentricity`],
    /// [`Hidden::TableWobble`]) make the IMU's motion differ from it.
    pub fn instant(&self, timeline: &Timeline, t_stamp: f64) -> Instant {
        let t = self.table_time(t_stamp);
        let axes = (self.hidden.iter()).fold(timeline.state(t), |a, h| h.true_axes(a));
        let inst = self.station.instant(t, t_stamp, self.temp_c(t), axes);
        (self.hidden.iter()).fold(inst, |i, h| h.tilt(&self.station, i, &axes))
    }

    /// The outputs without noise and without the wandering bias: (accel m/s^2, gyro deg/s),
    /// `a = K_a s + b_a + hidden`, `w = K_g w_ib + b_g + hidden`.
    pub fn outputs(&self, inst: &Instant) -> (V3, V3) {
        let mut s = inst.f_b;
        for h in &self.hidden {
            s = rot::add(s, h.accel_input(inst));
        }
        let mut a = rot::add(rot::mul_v(&self.imu.k_a(), s), self.imu.accel_bias_mps2);
        let mut w = rot::add(
            rot::mul_v(&self.imu.k_g(), inst.w_ib_dps),
            self.imu.gyro_bias_dps,
        );
        for h in &self.hidden {
            let (da, dw) = h.outputs(inst);
            a = rot::add(a, da);
            w = rot::add(w, dw);
        }
        (a, w)
    }
}
