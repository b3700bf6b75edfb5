//! The simulated IMU: `ratecal_physics` applied to the table's true motion at the table
//! time of each stamp (`t / (1 + eps) - tau`: the clock rate and the time offset), plus
//! white noise, a wandering gyro bias, thermal drift, saturation and dropouts. The
//! table's profile is its encoder angle (its servo follows the encoder); the IMU turns
//! with the true angle, which differs by the encoder's eccentricity.

use super::{SharedWorld, Temperatures, lock};
use crate::station::{DropoutMode, FaultSpec, Station};
use crate::{DriverError, ImuDriver, ImuInfo, ImuSample};
use async_trait::async_trait;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use ratecal_physics::effects::EncoderError;
use ratecal_physics::{AxisMotion, DEG, Geometry, ImuModel, Mat3, Signals, Site, TableState, Vec3};

/// The gyro bias wander is stepped at least this often (s); between steps it holds.
const BIAS_STEP_S: f64 = 0.01;

/// The last physics evaluation: table state, temperature and what they gave.
#[derive(Debug, Clone, Copy)]
struct Cache {
    state: TableState,
    signals: Signals,
    temp: f64,
    outputs: (Vec3, Vec3),
}

/// The simulated IMU (a real driver: used for dry runs and tests).
#[derive(Debug)]
pub struct SimImu {
    world: SharedWorld,
    info: ImuInfo,
    geo: Geometry,
    site: Site,
    /// The IMU's error model: registry terms (spec/physics.md), the Earth's rate among them.
    model: ImuModel,
    /// The table's encoder errors: the profile is the encoder's angle, not the true one.
    encoder: EncoderError,
    /// Whether a term is a user effect, which may read the time stamp: every sample is
    /// then evaluated at its own stamp, never reused from a hold.
    timed: bool,
    next_k: u64,
    hints: [usize; 2],
    cache: Option<Cache>,
    /// IMU internal temperature, stepped with the bias wander.
    temp: f64,
    rng: ChaCha8Rng,
    sigma_a: f64,
    sigma_g: f64,
    /// Gauss-Markov bias, its per-step decay and drive; random-walk bias and its drive.
    gm: [f64; 3],
    gm_phi: f64,
    gm_drive: f64,
    rw: [f64; 3],
    rw_drive: f64,
    bias_every: u64,
    temps: Temperatures,
    temp_noise: f64,
    dropouts: Vec<(f64, f64, DropoutMode)>,
    last_good: Option<ImuSample>,
    pending: Vec<ImuSample>,
}

impl SimImu {
    pub(crate) fn new(station: &Station, world: SharedWorld, seed: u64) -> Self {
        let imu = &station.imu;
        let fs = imu.sample_rate.0;
        let bias_every = ((BIAS_STEP_S * fs).floor() as u64).max(1);
        let step = bias_every as f64 / fs;
        let sigma_gm = imu.gyro_bias_markov_sigma.0;
        let gm_phi = (-step / imu.gyro_bias_correlation_time.0).exp();
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x1_0000_0000_1A1B);
        // Start the Gauss-Markov bias in its stationary distribution.
        let gm = [0; 3].map(|_| sigma_gm * rng.sample::<f64, _>(StandardNormal));
        let model = station.imu_model();
        let dropouts = station
            .faults
            .iter()
            .filter_map(|f| match f {
                FaultSpec::ImuDropout { at, duration, mode } => {
                    Some((at.0, at.0 + duration.0, *mode))
                }
                _ => None,
            })
            .collect();
        SimImu {
            world,
            info: imu.info(true),
            geo: station.geometry(),
            site: station.site(),
            encoder: station.encoder_error(),
            timed: model
                .terms
                .iter()
                .any(|t| ratecal_physics::effect(t.effect.id()).is_none()),
            model,
            next_k: 0,
            hints: [0; 2],
            cache: None,
            temp: 0.0,
            rng,
            sigma_a: imu.accel_noise_density.0 * fs.sqrt(),
            sigma_g: imu.gyro_noise_density.0 * fs.sqrt(),
            gm,
            gm_phi,
            gm_drive: sigma_gm * (1.0 - gm_phi * gm_phi).sqrt(),
            rw: [0.0; 3],
            rw_drive: imu.gyro_bias_random_walk.0 * step.sqrt(),
            bias_every,
            temps: Temperatures::new(station),
            temp_noise: station.temperature.imu.noise.0,
            dropouts,
            last_good: None,
            pending: Vec::new(),
        }
    }

    /// Generates every sample stamped <= `now` into `out`.
    fn generate(&mut self, out: &mut Vec<ImuSample>) -> Result<(), DriverError> {
        let mut w = lock(&self.world)?;
        let now = w.now();
        w.advance(now);
        let dt = 1.0 / self.info.sample_hz;
        let (ra, rg) = (self.info.accel_range_mps2, self.info.gyro_range_dps);
        out.reserve(((now - self.next_k as f64 * dt) / dt).max(0.0) as usize + 1);
        loop {
            let k = self.next_k;
            let t = k as f64 * dt;
            if t > now {
                break;
            }
            self.next_k += 1;
            if k.is_multiple_of(self.bias_every) {
                // Temperature moves slowly: it too is stepped with the bias wander.
                self.temp = self.temps.imu(t);
            }
            if k.is_multiple_of(self.bias_every) && k > 0 {
                for i in 0..3 {
                    let n1: f64 = self.rng.sample(StandardNormal);
                    let n2: f64 = self.rng.sample(StandardNormal);
                    self.gm[i] = self.gm_phi * self.gm[i] + self.gm_drive * n1;
                    self.rw[i] += self.rw_drive * n2;
                }
            }
            let te = t - self.model.delay_at_s(t);
            let o = w.axes[0].eval(te, &mut self.hints[0]);
            let i = w.axes[1].eval(te, &mut self.hints[1]);
            let reported = TableState {
                outer: AxisMotion {
                    angle: o.angle * DEG,
                    rate: o.rate * DEG,
                    accel: o.accel * DEG,
                },
                inner: AxisMotion {
                    angle: i.angle * DEG,
                    rate: i.rate * DEG,
                    accel: i.accel * DEG,
                },
            };
            let state = self.encoder.true_motion(&reported);
            // Holds are bit-for-bit constant: reuse the physics while nothing changes.
            let temp = self.temp;
            if self.timed {
                self.cache = None;
            }
            let (a, g) = match &self.cache {
                Some(c) if c.state == state && c.temp == temp => c.outputs,
                Some(c) if c.state == state => {
                    let mut signals = c.signals;
                    signals.dtemp_c = temp - self.model.t_ref_c;
                    let outputs = self.model.outputs(&signals);
                    self.cache = Some(Cache {
                        temp,
                        outputs,
                        ..*c
                    });
                    outputs
                }
                _ => {
                    let snap = state.snapshot(&self.geo, &self.site);
                    // Only user effects read the stamp (the registry's clock rate re-times
                    // the motion instead).
                    let stamp = if self.timed { t } else { 0.0 };
                    let signals =
                        Signals::new(&snap, &self.site, temp - self.model.t_ref_c).at(stamp);
                    let outputs = self.model.outputs(&signals);
                    self.cache = Some(Cache {
                        state,
                        signals,
                        temp,
                        outputs,
                    });
                    outputs
                }
            };
            let mut s = ImuSample {
                t,
                accel: [0.0; 3],
                gyro: [0.0; 3],
                temp_c: None,
                t_host: None,
            };
            for j in 0..3 {
                let na: f64 = self.rng.sample(StandardNormal);
                let ng: f64 = self.rng.sample(StandardNormal);
                s.accel[j] = (a[j] + self.sigma_a * na).clamp(-ra, ra);
                s.gyro[j] = (g[j] + self.gm[j] + self.rw[j] + self.sigma_g * ng).clamp(-rg, rg);
            }
            let nt: f64 = if self.temp_noise > 0.0 {
                self.rng.sample(StandardNormal)
            } else {
                0.0
            };
            s.temp_c = Some(temp + self.temp_noise * nt);
            match self.dropout(t) {
                None => {
                    self.last_good = Some(s);
                    out.push(s);
                }
                Some(DropoutMode::Missing) => {}
                Some(DropoutMode::Nan) => out.push(ImuSample {
                    t,
                    accel: [f64::NAN; 3],
                    gyro: [f64::NAN; 3],
                    temp_c: s.temp_c,
                    t_host: None,
                }),
                Some(DropoutMode::Stuck) => {
                    let last = self.last_good.unwrap_or(s);
                    out.push(ImuSample { t, ..last });
                }
            }
        }
        Ok(())
    }

    fn dropout(&self, t: f64) -> Option<DropoutMode> {
        self.dropouts
            .iter()
            .find(|(t0, t1, _)| t >= *t0 && t < *t1)
            .map(|d| d.2)
    }
}

#[async_trait]
impl ImuDriver for SimImu {
    fn info(&self) -> ImuInfo {
        self.info.clone()
    }

    async fn read(&mut self, out: &mut Vec<ImuSample>) -> Result<(), DriverError> {
        out.append(&mut self.pending);
        self.generate(out)
    }

    async fn remount(&mut self, rotation: [[f64; 3]; 3]) -> Result<(), DriverError> {
        // Samples up to now were taken with the old mount.
        let mut before = std::mem::take(&mut self.pending);
        self.generate(&mut before)?;
        self.pending = before;
        self.geo.c_pb = Mat3::from_fn(|i, j| rotation[i][j]);
        self.cache = None;
        Ok(())
    }
}
