//! The IMU over a binary frame stream (`docs/protocols.md`). A task of its own reads the
//! link as bytes arrive (so arrival times are the host's, not the control loop's), decodes
//! frames in place, and rebuilds a link that closed or went silent; `read` drains what it
//! gathered. A link that is not back within the timeout is a `Transport` error.

use super::{ClockMap, Endpoint, connect};
use crate::frame::{FLAG_ACCEL_SATURATED, FLAG_GYRO_SATURATED, Frame, FrameReader};
use crate::{DriverError, DriverErrorKind, ImuDriver, ImuInfo, ImuSample, LinkStats};
use async_trait::async_trait;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::io::AsyncReadExt;
use tokio::time::Instant;

#[derive(Debug, Default)]
struct Shared {
    samples: Vec<ImuSample>,
    clock: ClockMap,
    error: Option<DriverError>,
}

/// An IMU streaming binary frames over TCP or a serial port.
#[derive(Debug)]
pub struct FramedImu {
    info: ImuInfo,
    shared: Arc<Mutex<Shared>>,
    task: tokio::task::JoinHandle<()>,
}

impl FramedImu {
    /// Starts reading `endpoint` (on the current tokio runtime), arrival times counted from
    /// `start`; `timeout` is both the silence after which the link is rebuilt and the time
    /// it has to come back.
    pub fn spawn(endpoint: Endpoint, info: ImuInfo, timeout: Duration, start: Instant) -> Self {
        let shared = Arc::new(Mutex::new(Shared::default()));
        let task = tokio::spawn(pump(endpoint, timeout, shared.clone(), start));
        FramedImu { info, shared, task }
    }
}

impl Drop for FramedImu {
    fn drop(&mut self) {
        self.task.abort();
    }
}

/// One decoded frame: device time (s), counter, and the sample with device time as `t`. A
/// saturated channel group is not a measurement (NaN: not recorded, and `imu.output
/// abnormal` sees it).
fn decode(f: &Frame<'_>) -> (u32, ImuSample) {
    let nan_if = |flag: u16, v: [f64; 3]| {
        if f.flags() & flag != 0 {
            [f64::NAN; 3]
        } else {
            v
        }
    };
    let s = ImuSample {
        t: f.time_ns() as f64 * 1e-9,
        accel: nan_if(FLAG_ACCEL_SATURATED, f.accel()),
        gyro: nan_if(FLAG_GYRO_SATURATED, f.gyro()),
        temp_c: f.temp_c(),
        t_host: None,
    };
    (f.counter(), s)
}

async fn pump(endpoint: Endpoint, timeout: Duration, shared: Arc<Mutex<Shared>>, start: Instant) {
    let mut reader = FrameReader::new();
    let mut counter: Option<u32> = None;
    let mut batch: Vec<(u32, ImuSample)> = Vec::new();
    let mut lost_at = Instant::now();
    let mut first = true;
    loop {
        let mut stream = match connect(&endpoint, timeout).await {
            Ok(s) => s,
            Err(e) => {
                if lost_at.elapsed() >= timeout {
                    let msg =
                        format!("IMU link ({endpoint}) lost and not back within {timeout:?}: {e}");
                    if let Ok(mut sh) = shared.lock() {
                        sh.error = Some(DriverError::new(DriverErrorKind::Transport, msg));
                    }
                    return;
                }
                tokio::time::sleep(Duration::from_millis(50)).await;
                continue;
            }
        };
        if !first && let Ok(mut sh) = shared.lock() {
            sh.clock.stats.reconnects += 1;
        }
        first = false;
        reader.clear();
        loop {
            match tokio::time::timeout(timeout, stream.read_buf(reader.buffer())).await {
                Ok(Ok(n)) if n > 0 => {}
                _ => break,
            }
            let host = start.elapsed().as_secs_f64();
            batch.clear();
            let before = reader.corrupted;
            reader.frames(|f| batch.push(decode(&f)));
            let Ok(mut sh) = shared.lock() else { return };
            let Shared { samples, clock, .. } = &mut *sh;
            clock.stats.corrupted += reader.corrupted - before;
            let Some(&(_, newest)) = batch.last() else {
                continue;
            };
            clock.arrival(newest.t, host, batch.len() as u64);
            lost_at = Instant::now();
            for (c, s) in &batch {
                if let Some(prev) = counter {
                    let gap = c.wrapping_sub(prev);
                    if gap > 1 && gap < u32::MAX / 2 {
                        clock.stats.lost += u64::from(gap - 1);
                    }
                }
                counter = Some(*c);
                // Every frame of a read arrived with it: the read's instant is theirs.
                samples.push(ImuSample {
                    t: clock.map(s.t),
                    t_host: Some(host),
                    ..*s
                });
            }
        }
        if lost_at.elapsed() >= timeout {
            fail(
                &shared,
                format!("IMU link ({endpoint}) silent for {timeout:?}"),
            );
            return;
        }
        // One attempt per 50 ms: a device that accepts and closes at once is not hammered.
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

fn fail(shared: &Mutex<Shared>, msg: String) {
    if let Ok(mut sh) = shared.lock() {
        sh.error = Some(DriverError::new(DriverErrorKind::Transport, msg));
    }
}

#[async_trait]
impl ImuDriver for FramedImu {
    fn info(&self) -> ImuInfo {
        self.info.clone()
    }

    async fn read(&mut self, out: &mut Vec<ImuSample>) -> Result<(), DriverError> {
        let mut sh = self
            .shared
            .lock()
            .map_err(|_| DriverError::new(DriverErrorKind::Transport, "IMU link reader failed"))?;
        out.append(&mut sh.samples);
        match &sh.error {
            Some(e) if out.is_empty() => Err(e.clone()),
            _ => Ok(()),
        }
    }

    fn link_stats(&self) -> Option<LinkStats> {
        self.shared.lock().ok().map(|s| s.clock.stats.clone())
    }
}
