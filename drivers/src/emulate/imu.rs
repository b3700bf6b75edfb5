//! The emulated IMU: streams the simulated IMU's samples as binary frames, every 2 ms.

use super::{End, Session};
use crate::ImuDriver;
use crate::frame::{FLAG_ACCEL_SATURATED, FLAG_GYRO_SATURATED, FrameFields, encode};
use crate::station::LinkName;
use std::sync::atomic::Ordering;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};

const PERIOD: Duration = Duration::from_millis(2);
/// Byte of the payload flipped in a corrupted frame (inside the accelerometer x value).
const CORRUPT_AT: usize = 3 + 12 + 2;

/// Streams frames until the client closes the link (seen as soon as its end reads as
/// closed, not at the next failed write), a newer IMU link of the session takes over, or
/// a fault drops it. On a pseudo-terminal nobody may be reading: frames that cannot be
/// written within 200 ms are dropped, as a device does, rather than queued (and never end
/// the link).
pub(super) async fn serve<S: AsyncRead + AsyncWrite>(stream: S, s: &Session, pty: bool) -> End {
    let link = s.imu_link.fetch_add(1, Ordering::SeqCst) + 1;
    let (mut rx, mut stream) = tokio::io::split(stream);
    let mut tick = tokio::time::interval(PERIOD);
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut samples = Vec::new();
    let mut buf = Vec::new();
    let mut incoming = [0u8; 64];
    let (accel_range, gyro_range) = s.ranges;
    loop {
        tokio::select! {
            _ = tick.tick() => {}
            // The client sends nothing on this link: a read ends only when it closed.
            r = rx.read(&mut incoming), if !pty => match r {
                Ok(n) if n > 0 => continue,
                _ => return End::Client,
            },
            () = s.ended() => return End::Ended,
        }
        if s.take_drop(LinkName::Imu, s.now()) {
            return End::Dropped;
        }
        samples.clear();
        {
            // Checked under the IMU's lock: once a newer link counted itself, this one
            // takes no sample, so the newer link's counter runs without gaps.
            let mut imu = s.imu.lock().await;
            if s.imu_link.load(Ordering::SeqCst) != link {
                return End::Client;
            }
            if imu.read(&mut samples).await.is_err() {
                continue;
            }
        }
        buf.clear();
        for smp in &samples {
            let counter = s.counter.fetch_add(1, Ordering::Relaxed);
            if let Some(end) = s.faults.stall_end(LinkName::Imu, smp.t) {
                // Silent: the client gives up on the link and reconnects within the session.
                s.disturb(LinkName::Imu, end);
                continue;
            }
            let mut f = FrameFields {
                counter,
                time_ns: (smp.t.max(0.0) * 1e9).round() as u64,
                accel: smp.accel,
                gyro: smp.gyro,
                temp_c: smp.temp_c.unwrap_or(f64::NAN),
                flags: 0,
            };
            if f.accel.iter().any(|v| v.abs() >= accel_range) {
                f.flags |= FLAG_ACCEL_SATURATED;
            }
            if s.faults.saturated(smp.t) {
                f.gyro[0] = gyro_range.copysign(f.gyro[0]);
            }
            if f.gyro.iter().any(|v| v.abs() >= gyro_range) {
                f.flags |= FLAG_GYRO_SATURATED;
            }
            let at = buf.len();
            encode(&f, &mut buf);
            if s.faults
                .corrupt_every(smp.t)
                .is_some_and(|n| counter.is_multiple_of(n))
            {
                buf[at + CORRUPT_AT] ^= 0x5A;
            }
        }
        if buf.is_empty() {
            continue;
        }
        let write = stream.write_all(&buf);
        if pty {
            // A timed-out write is dropped (nobody reads); so is a failed one: a terminal
            // has no connection to end, the device keeps sending.
            let _ = tokio::time::timeout(Duration::from_millis(200), write).await;
        } else if write.await.is_err() {
            return End::Client;
        }
    }
}
