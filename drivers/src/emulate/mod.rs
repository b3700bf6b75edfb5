//! The hardware emulator behind `ratecal emulate`: the simulated station of a station file,
//! run in real time, served over the two hardware protocols (`docs/protocols.md`): the
//! table's line protocol and the IMU's binary frames, on TCP or pseudo-terminals. It serves
//! one session after another: a session (a fresh simulated world, clock at 0) starts with
//! the first connection and ends when the client has closed every link it opened, or when
//! a new client connects (`session.rs` tells a reconnect from a new client). The
//! station file's link faults (a dropped connection, a stall, corrupted frames, the table's
//! fault flag, IMU saturation) are played on their session's clock, the simulator's own
//! faults by the simulator.

mod faults;
mod imu;
mod session;
mod station;
mod table;

pub use station::{Served, connecting_station};

use crate::station::{LinkName, Station};
use faults::LinkFaults;
use session::Session;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use tokio::io::{AsyncRead, AsyncWrite};
use tokio::net::TcpListener;

/// How a served link ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    /// The client closed it.
    Client,
    /// A rehearsed fault dropped it.
    Dropped,
    /// Its session ended under it (a new client took over).
    Ended,
}

/// The emulator: a station, a seed, and the session being served.
pub struct Emulator {
    station: Station,
    seed: u64,
    faults: Arc<LinkFaults>,
    current: Mutex<Option<Arc<Session>>>,
    sessions: Mutex<u64>,
    log: bool,
}

impl Emulator {
    /// An emulator of `station` (its drivers are ignored: the station is simulated), seeded;
    /// with `log`, sessions and played faults are reported on standard error.
    pub fn new(station: Station, seed: u64, log: bool) -> Arc<Self> {
        let faults = Arc::new(LinkFaults::of(&station));
        Arc::new(Emulator {
            station,
            seed,
            faults,
            current: Mutex::new(None),
            sessions: Mutex::new(0),
            log,
        })
    }

    /// Sessions started so far.
    pub fn sessions(&self) -> u64 {
        self.sessions.lock().map_or(0, |n| *n)
    }

    fn note(&self, text: &str) {
        if self.log {
            eprintln!("emulate: {text}");
        }
    }

    /// A fresh session (the next number).
    fn fresh(&self) -> Arc<Session> {
        let mut n = self.sessions.lock().expect("emulator state");
        *n += 1;
        self.note(&format!("session {} starts", *n));
        let imu = &self.station.imu;
        Arc::new(Session::new(
            *n,
            crate::sim::build(&self.station, self.seed),
            self.faults.clone(),
            (imu.accel_range.0, imu.gyro_range.0),
        ))
    }

    /// The session a new connection of `which` belongs to, with one more link open: the
    /// current one if it admits the link (`session.rs`), else a fresh one, the current one
    /// ended (its links closed).
    fn join(&self, which: LinkName) -> Arc<Session> {
        let mut cur = self.current.lock().expect("emulator state");
        if let Some(old) = cur.take_if(|s| !s.admits(which)) {
            self.note(&format!(
                "session {} ends at t = {:.3} s: a new client connected",
                old.number,
                old.now()
            ));
            old.end();
        }
        let s = cur.get_or_insert_with(|| {
            let s = self.fresh();
            s.admits(which);
            s
        });
        s.open.fetch_add(1, Ordering::SeqCst);
        s.clone()
    }

    /// A link of `s` closed; the session ends when the client closed its last link.
    fn leave(&self, s: &Arc<Session>, end: End) {
        let mut cur = self.current.lock().expect("emulator state");
        let left = s.open.fetch_sub(1, Ordering::SeqCst) - 1;
        if end == End::Dropped {
            self.note(&format!(
                "session {}: link dropped (fault) at t = {:.3} s",
                s.number,
                s.now()
            ));
        }
        if left == 0 && end == End::Client && cur.as_ref().is_some_and(|c| Arc::ptr_eq(c, s)) {
            self.note(&format!(
                "session {} ends at t = {:.3} s",
                s.number,
                s.now()
            ));
            *cur = None;
        }
    }

    /// Serves one accepted link of `which` kind until it ends.
    async fn serve<S: AsyncRead + AsyncWrite + Unpin + Send>(&self, which: LinkName, stream: S) {
        let s = self.join(which);
        if let Some(until) = self.faults.outage(which, s.now()) {
            // Refused: the link is down for a while (a dropped connection that stays down).
            s.disturb(which, until);
            self.leave(&s, End::Dropped);
            return;
        }
        let end = match which {
            LinkName::Table => table::serve(stream, &s).await,
            LinkName::Imu => imu::serve(stream, &s, false).await,
        };
        self.leave(&s, end);
    }

    /// Serves the table on `table` and the IMU on `imu` (TCP) until the task is dropped.
    pub async fn serve_tcp(self: Arc<Self>, table: TcpListener, imu: TcpListener) {
        loop {
            let (which, accepted) = tokio::select! {
                r = table.accept() => (LinkName::Table, r),
                r = imu.accept() => (LinkName::Imu, r),
            };
            let Ok((stream, _)) = accepted else { continue };
            let _ = stream.set_nodelay(true);
            let me = self.clone();
            tokio::spawn(async move { me.serve(which, stream).await });
        }
    }

    /// Serves both devices on pseudo-terminals; returns the table's and the IMU's device
    /// paths and the task serving them. Over a pseudo-terminal nothing tells sessions apart:
    /// one session runs from the call on, and fault times count from then.
    #[cfg(unix)]
    pub fn serve_pty(
        self: Arc<Self>,
    ) -> std::io::Result<(String, String, tokio::task::JoinHandle<()>)> {
        use tokio_serial::{SerialPort, SerialStream};
        let (table_master, table_slave) = SerialStream::pair().map_err(std::io::Error::from)?;
        let (imu_master, imu_slave) = SerialStream::pair().map_err(std::io::Error::from)?;
        let name = |s: &SerialStream| s.name().unwrap_or_default();
        let (table_path, imu_path) = (name(&table_slave), name(&imu_slave));
        let task = tokio::spawn(async move {
            // The emulator keeps the slave ends open, so that a client closing its end
            // does not end the terminal.
            let _keep = (table_slave, imu_slave);
            let s = self.fresh();
            let me = self.clone();
            let s2 = s.clone();
            let t = tokio::spawn(async move {
                let _ = table::serve(table_master, &s2).await;
                drop(me);
            });
            let _ = imu::serve(imu_master, &s, true).await;
            let _ = t.await;
        });
        Ok((table_path, imu_path, task))
    }
}
