//! The IMU in the simulated operator's hand: the station's error model
//! (`ratecal_physics`, the simulator's) applied to the hand's motion, plus white noise.

use super::SharedHand;
use crate::sim::Temperatures;
use crate::station::Station;
use crate::{DriverError, DriverErrorKind, ImuDriver, ImuInfo, ImuSample};
use async_trait::async_trait;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use ratecal_physics::{ImuModel, Signals, Site, TableState, Vec3};

/// The simulated IMU of a manual station.
#[derive(Debug)]
pub struct HandImu {
    hand: SharedHand,
    info: ImuInfo,
    site: Site,
    model: ImuModel,
    temps: Temperatures,
    rng: ChaCha8Rng,
    sigma_a: f64,
    sigma_g: f64,
    next_k: u64,
    hint: usize,
}

impl HandImu {
    /// The simulated IMU of a station, in the simulated hand; `simulated` as the table's.
    pub fn new(station: &Station, hand: SharedHand, seed: u64, simulated: bool) -> Self {
        let imu = &station.imu;
        let fs = imu.sample_rate.0;
        HandImu {
            hand,
            info: imu.info(simulated),
            site: station.site(),
            model: station.imu_model(),
            temps: Temperatures::new(station),
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x4A4D_1000_0000_0002),
            sigma_a: imu.accel_noise_density.0 * fs.sqrt(),
            sigma_g: imu.gyro_noise_density.0 * fs.sqrt(),
            next_k: 0,
            hint: 0,
        }
    }

    fn signals(&self, t: f64, c_bl: ratecal_physics::Mat3, w_b: Vec3, dw_b: Vec3) -> Signals {
        let f_b = c_bl * Vec3::new(0.0, 0.0, self.site.gravity_mps2);
        let earth_b = c_bl * self.site.earth_rate_l();
        Signals {
            f_b,
            w_b,
            dw_b,
            c_bl,
            earth_b,
            df_b: -w_b.cross(&f_b),
            dw_ib: dw_b - w_b.cross(&earth_b),
            dtemp_c: self.temps.imu(t) - self.model.t_ref_c,
            g: self.site.gravity_mps2,
            t_s: t,
            table: TableState::default(),
            outer_b: Vec3::zeros(),
            inner_b: Vec3::zeros(),
        }
    }
}

#[async_trait]
impl ImuDriver for HandImu {
    fn info(&self) -> ImuInfo {
        self.info.clone()
    }

    async fn read(&mut self, out: &mut Vec<ImuSample>) -> Result<(), DriverError> {
        let hand = self.hand.clone();
        let w = hand.lock().map_err(|_| {
            DriverError::new(DriverErrorKind::Instrument, "simulated hand state poisoned")
        })?;
        let now = w.now();
        let dt = 1.0 / self.info.sample_hz;
        let (ra, rg) = (self.info.accel_range_mps2, self.info.gyro_range_dps);
        loop {
            let t = self.next_k as f64 * dt;
            if t > now {
                break;
            }
            self.next_k += 1;
            let st = w.state(t - self.model.delay_at_s(t), &mut self.hint);
            let (a, g) = self
                .model
                .outputs(&self.signals(t, st.c_bl, st.w_b, st.dw_b));
            let mut s = ImuSample {
                t,
                accel: [0.0; 3],
                gyro: [0.0; 3],
                temp_c: Some(self.temps.imu(t)),
                t_host: None,
            };
            for j in 0..3 {
                let na: f64 = self.rng.sample(StandardNormal);
                let ng: f64 = self.rng.sample(StandardNormal);
                s.accel[j] = (a[j] + self.sigma_a * na).clamp(-ra, ra);
                s.gyro[j] = (g[j] + self.sigma_g * ng).clamp(-rg, rg);
            }
            out.push(s);
        }
        Ok(())
    }
}
