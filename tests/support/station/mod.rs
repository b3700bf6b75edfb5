//! A tiny fake station for interpreter tests: a rate- and acceleration-limited two-axis
//! table with deterministic feedback, an ideal IMU reading the seed geometry's closed forms,
//! and switchable faults. Time is the tokio clock (paused in tests).

#![allow(dead_code)]

pub mod explain;
pub mod plans;
pub mod sim;

use async_trait::async_trait;
use ratecal_drivers::{
    DriverError, DriverErrorKind, ImuDriver, ImuInfo, ImuSample, TableAxisId, TableCommand,
    TableDriver, TableInfo, TableSample,
};
use ratecal_recording::{Manifest, ManifestStation, ProcedureRef, RunInfo, TableAxes};
use std::sync::{Arc, Mutex};
use tokio::time::Instant;

pub const G: f64 = 9.81;
pub const MAX_RATE: f64 = 20.0;
pub const MAX_ACCEL: f64 = 40.0;
pub const TABLE_HZ: f64 = 50.0;
pub const IMU_HZ: f64 = 100.0;

#[derive(Debug, Clone, Copy)]
enum Mode {
    Hold(f64),
    Rate(f64),
    Osc {
        center: f64,
        amp: f64,
        period: f64,
        t0: f64,
    },
}

#[derive(Debug, Clone, Copy)]
struct AxisState {
    angle: f64,
    rate: f64,
    mode: Mode,
}

impl AxisState {
    /// One 1 ms step: position moves approach the target at a limited rate with a
    /// proportional final approach; rates ramp at the acceleration limit.
    fn step(&mut self, t: f64, dt: f64) {
        let want_rate = match self.mode {
            Mode::Hold(target) => (2.0 * (target - self.angle)).clamp(-MAX_RATE, MAX_RATE),
            Mode::Rate(w) => w,
            Mode::Osc {
                center,
                amp,
                period,
                t0,
            } => {
                let w = 2.0 * std::f64::consts::PI / period;
                let want_angle = center + amp * (w * (t - t0)).sin();
                amp * w * (w * (t - t0)).cos() + 5.0 * (want_angle - self.angle)
            }
        };
        let dr = (want_rate - self.rate).clamp(-MAX_ACCEL * dt, MAX_ACCEL * dt);
        self.rate += dr;
        self.angle += self.rate * dt;
    }
}

/// Faults a test can switch on (station times, s).
#[derive(Debug, Clone, Default)]
pub struct Faults {
    /// The table reports an instrument fault from this time on.
    pub table_fault_at: Option<f64>,
    /// The IMU stops delivering samples from this time on.
    pub imu_dropout_at: Option<f64>,
    /// The IMU repeats its last sample from this time on.
    pub imu_stuck_at: Option<f64>,
    /// Ambient temperature `(from, to, value)`; 20 degC otherwise.
    pub ambient_excursion: Option<(f64, f64, f64)>,
}

pub struct Station {
    origin: Instant,
    t: f64,
    outer: AxisState,
    inner: AxisState,
    faults: Faults,
    table_next: u64,
    imu_next: u64,
    commands: Vec<TableCommand>,
    last_imu: Option<ImuSample>,
}

impl Station {
    fn now(&self) -> f64 {
        (Instant::now() - self.origin).as_secs_f64()
    }

    /// Advances the physics to station time `t` in 1 ms steps.
    fn advance(&mut self, t: f64) {
        while self.t + 1e-4 < t {
            let dt = 1e-3_f64.min(t - self.t);
            self.t += dt;
            self.outer.step(self.t, dt);
            self.inner.step(self.t, dt);
        }
    }
}

pub type Shared = Arc<Mutex<Station>>;

pub struct FakeTable(pub Shared);
pub struct FakeImu(pub Shared);

/// A station at rest at (0, 0) with the given faults; the station clock starts now.
pub fn station(faults: Faults) -> (FakeTable, FakeImu, Shared) {
    let axis = AxisState {
        angle: 0.0,
        rate: 0.0,
        mode: Mode::Hold(0.0),
    };
    let s = Arc::new(Mutex::new(Station {
        origin: Instant::now(),
        t: 0.0,
        outer: axis,
        inner: axis,
        faults,
        table_next: 0,
        imu_next: 0,
        commands: Vec::new(),
        last_imu: None,
    }));
    (FakeTable(s.clone()), FakeImu(s.clone()), s)
}

/// Commands the table received.
pub fn commands(s: &Shared) -> Vec<TableCommand> {
    s.lock().unwrap().commands.clone()
}

/// Both axes' rates now.
pub fn rates(s: &Shared) -> (f64, f64) {
    let st = s.lock().unwrap();
    (st.outer.rate, st.inner.rate)
}

fn fault(t: f64) -> DriverError {
    DriverError::new(
        DriverErrorKind::Instrument,
        format!("servo amplifier fault at {t:.3} s"),
    )
}

#[async_trait]
impl TableDriver for FakeTable {
    fn info(&self) -> TableInfo {
        TableInfo {
            model: "fake".into(),
            max_rate_dps: MAX_RATE,
            max_accel_dps2: MAX_ACCEL,
            feedback_hz: TABLE_HZ,
            simulated: true,
        }
    }

    async fn command(&mut self, cmd: TableCommand) -> Result<(), DriverError> {
        let mut s = self.0.lock().unwrap();
        let now = s.now();
        s.advance(now);
        s.commands.push(cmd.clone());
        if s.faults.table_fault_at.is_some_and(|f| now >= f) && cmd != TableCommand::SafeStop {
            return Err(fault(now));
        }
        let t = s.t;
        match cmd {
            TableCommand::MoveTo {
                outer_deg,
                inner_deg,
            } => {
                s.outer.mode = Mode::Hold(outer_deg);
                s.inner.mode = Mode::Hold(inner_deg);
            }
            TableCommand::Rate { axis, rate_dps } => {
                axis_mut(&mut s, axis).mode = Mode::Rate(rate_dps)
            }
            TableCommand::Stop { axis } => {
                let a = axis_mut(&mut s, axis);
                // Hold where a deceleration at the limit ends.
                let stop = a.angle + a.rate * a.rate.abs() / (2.0 * MAX_ACCEL);
                a.mode = Mode::Hold(stop);
            }
            TableCommand::Oscillate {
                axis,
                center_deg,
                amplitude_deg,
                period_s,
            } => {
                axis_mut(&mut s, axis).mode = Mode::Osc {
                    center: center_deg,
                    amp: amplitude_deg,
                    period: period_s,
                    t0: t,
                }
            }
            TableCommand::SafeStop => {
                let st = &mut *s;
                for a in [&mut st.outer, &mut st.inner] {
                    let stop = a.angle + a.rate * a.rate.abs() / (2.0 * MAX_ACCEL);
                    a.mode = Mode::Hold(stop);
                }
            }
        }
        Ok(())
    }

    async fn read(&mut self, out: &mut Vec<TableSample>) -> Result<(), DriverError> {
        let mut s = self.0.lock().unwrap();
        let now = s.now();
        if s.faults.table_fault_at.is_some_and(|f| now >= f) {
            // The fault stops the axes where they are (brakes) and is reported.
            s.outer.rate = 0.0;
            s.inner.rate = 0.0;
            s.outer.mode = Mode::Hold(s.outer.angle);
            s.inner.mode = Mode::Hold(s.inner.angle);
        }
        loop {
            let t = s.table_next as f64 / TABLE_HZ;
            if t > now + 1e-9 {
                break;
            }
            s.advance(t);
            s.table_next += 1;
            let ambient = match s.faults.ambient_excursion {
                Some((a, b, v)) if t >= a && t < b => v,
                _ => 20.0,
            };
            // Deterministic encoder dither of +-0.2 arcsec.
            let dither = if s.table_next.is_multiple_of(2) {
                0.2 / 3600.0
            } else {
                -0.2 / 3600.0
            };
            out.push(TableSample {
                t,
                outer_deg: s.outer.angle + dither,
                inner_deg: s.inner.angle - dither,
                outer_rate_dps: s.outer.rate,
                inner_rate_dps: s.inner.rate,
                ambient_c: Some(ambient),
                t_host: None,
            });
        }
        if s.faults.table_fault_at.is_some_and(|f| now >= f) {
            return Err(fault(now));
        }
        Ok(())
    }
}

fn axis_mut(s: &mut Station, a: TableAxisId) -> &mut AxisState {
    match a {
        TableAxisId::Outer => &mut s.outer,
        TableAxisId::Inner => &mut s.inner,
    }
}

#[async_trait]
impl ImuDriver for FakeImu {
    fn info(&self) -> ImuInfo {
        ImuInfo {
            model: "fake".into(),
            serial: "0".into(),
            grade: "tactical".into(),
            sample_hz: IMU_HZ,
            accel_range_mps2: 16.0 * G,
            gyro_range_dps: 400.0,
            simulated: true,
        }
    }

    async fn read(&mut self, out: &mut Vec<ImuSample>) -> Result<(), DriverError> {
        let mut s = self.0.lock().unwrap();
        let now = s.now();
        loop {
            let t = (s.imu_next as f64 + 0.5) / IMU_HZ;
            if t > now + 1e-9 {
                break;
            }
            s.imu_next += 1;
            if s.faults.imu_dropout_at.is_some_and(|f| t >= f) {
                continue;
            }
            s.advance(t);
            let (th, ph) = (s.outer.angle.to_radians(), s.inner.angle.to_radians());
            // Seed geometry closed forms (physics.md), tiny deterministic wobble.
            let wob = 1e-5 * ((s.imu_next % 7) as f64 - 3.0);
            let mut sample = ImuSample {
                t,
                accel: [
                    G * th.sin() + wob,
                    G * th.cos() * ph.sin() - wob,
                    G * th.cos() * ph.cos() + wob,
                ],
                gyro: [
                    s.inner.rate + wob,
                    -s.outer.rate * ph.cos() - wob,
                    s.outer.rate * ph.sin() + wob,
                ],
                temp_c: Some(25.0),
                t_host: None,
            };
            if s.faults.imu_stuck_at.is_some_and(|f| t >= f)
                && let Some(last) = s.last_imu
            {
                sample = ImuSample { t, ..last };
            }
            s.last_imu = Some(sample);
            out.push(sample);
        }
        Ok(())
    }
}

/// A manifest for a fresh run.
pub fn manifest(name: &str) -> Manifest {
    Manifest {
        format: String::new(),
        station: ManifestStation {
            site: ratecal_physics::Site {
                latitude_deg: 55.7,
                gravity_mps2: G,
            },
            table: TableAxes {
                outer_axis: [0.0, -1.0, 0.0],
                inner_axis: [1.0, 0.0, 0.0],
                model: None,
            },
            mount: None,
        },
        imu: [("model".to_string(), "fake".to_string())]
            .into_iter()
            .collect(),
        procedure: Some(ProcedureRef {
            name: name.into(),
            version: "1.0.0".into(),
            sha256: "0".repeat(64),
        }),
        segments: Vec::new(),
        environment: None,
        run: Some(RunInfo {
            id: "test".into(),
            ratecal_version: "test".into(),
            dry_run: true,
            started: "2026-01-01T00:00:00Z".into(),
            ended: None,
            status: "running".into(),
            abort: None,
            operator: None,
            seed: None,
            station_sha256: None,
            files_sha256: Default::default(),
            failure: None,
            resumes: Vec::new(),
            changed_after_release: None,
            draft_procedure: None,
            sync: None,
            write_failure: None,
        }),
    }
}

/// Rows of a CSV file as numbers (header dropped).
pub fn csv_rows(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}
