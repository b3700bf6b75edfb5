//! One emulated session: a simulated world from its first connection on, and what tells a
//! client's reconnect from a new client. A driver opens a second link of a kind only after
//! it lost the first (`docs/protocols.md`); in the emulator a link is lost only to a
//! rehearsed fault (a drop, a refusal, a stall the client gives up on). So a connection
//! continues the session when the session has no link of its kind yet, or when a fault
//! disturbed that link lately; any other connection is a new client's, and the session
//! ends (its links closed) for a fresh one, whether or not its old links were seen to close.

use super::faults::LinkFaults;
use crate::sim::{SimImu, SimTable};
use crate::station::LinkName;
use std::sync::atomic::{AtomicU32, AtomicU64, AtomicUsize};
use std::sync::{Arc, Mutex};
use tokio::sync::watch;
use tokio::time::Instant;

/// How long after a fault's end a new link of the kind it disturbed is still the client's
/// reconnect, s. A driver reconnects within its timeout of the loss, which a drop or a
/// stall covers: it gives up on a stalled link during the stall, and is refused until a
/// drop's outage ends, then retries within 50 ms. The second is slack for a loaded host.
pub(super) const RECONNECT_GRACE_S: f64 = 1.0;

/// What the session knows of its links of one kind.
#[derive(Debug, Default, Clone, Copy)]
struct LinkState {
    /// A link of this kind joined the session.
    joined: bool,
    /// Until when (session time, s) a rehearsed fault disturbs it.
    disturbed_until: Option<f64>,
}

/// One session: a simulated world from its first connection on.
pub(super) struct Session {
    pub number: u64,
    pub start: Instant,
    pub table: tokio::sync::Mutex<SimTable>,
    pub imu: tokio::sync::Mutex<SimImu>,
    /// Frame counter, kept across reconnects.
    pub counter: AtomicU32,
    /// The newest IMU link's number: an older link still being served (its client gone,
    /// not yet noticed) stops before taking another sample, so that it never takes samples
    /// from between the ones the newest link sends (they were lost frames on that link).
    pub imu_link: AtomicU64,
    pub faults: Arc<LinkFaults>,
    /// Drops already played.
    fired: Mutex<Vec<bool>>,
    pub open: AtomicUsize,
    pub ranges: (f64, f64),
    /// Table and IMU links.
    links: Mutex<[LinkState; 2]>,
    /// Set when the session is ended under its links (a new client took over).
    ended: watch::Sender<bool>,
}

fn slot(link: LinkName) -> usize {
    match link {
        LinkName::Table => 0,
        LinkName::Imu => 1,
    }
}

impl Session {
    /// A fresh session numbered `number`, its clock starting now.
    pub fn new(
        number: u64,
        (table, imu): (SimTable, SimImu),
        faults: Arc<LinkFaults>,
        ranges: (f64, f64),
    ) -> Self {
        Session {
            number,
            start: Instant::now(),
            table: tokio::sync::Mutex::new(table),
            imu: tokio::sync::Mutex::new(imu),
            counter: AtomicU32::new(0),
            imu_link: AtomicU64::new(0),
            fired: Mutex::new(vec![false; faults.drops.len()]),
            faults,
            open: AtomicUsize::new(0),
            ranges,
            links: Mutex::new([LinkState::default(); 2]),
            ended: watch::Sender::new(false),
        }
    }

    /// Session time, s.
    pub fn now(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// Whether a drop of `link` is due now (each drop plays once); a due drop disturbs the
    /// link until its outage ends.
    pub fn take_drop(&self, link: LinkName, t: f64) -> bool {
        let Ok(mut fired) = self.fired.lock() else {
            return false;
        };
        for (i, d) in self.faults.drops.iter().enumerate() {
            if d.link == link && t >= d.at && !fired[i] {
                fired[i] = true;
                drop(fired);
                self.disturb(link, d.at + d.duration);
                return true;
            }
        }
        false
    }

    /// A rehearsed fault disturbs `link` until `until` (session time, s).
    pub fn disturb(&self, link: LinkName, until: f64) {
        if let Ok(mut links) = self.links.lock() {
            let d = &mut links[slot(link)].disturbed_until;
            *d = Some(d.map_or(until, |u| u.max(until)));
        }
    }

    /// Whether a new connection of `link` now continues this session (and joins it, if so):
    /// the session has no link of that kind yet, or a fault disturbed it lately.
    pub fn admits(&self, link: LinkName) -> bool {
        let t = self.now();
        let Ok(mut links) = self.links.lock() else {
            return false;
        };
        let l = &mut links[slot(link)];
        let ok = !l.joined
            || l.disturbed_until
                .is_some_and(|u| t <= u + RECONNECT_GRACE_S);
        if ok {
            l.joined = true;
        }
        ok
    }

    /// Ends the session under its links: every link still served stops.
    pub fn end(&self) {
        self.ended.send_replace(true);
    }

    /// Resolves when the session was ended under its links.
    pub async fn ended(&self) {
        let mut rx = self.ended.subscribe();
        // The sender lives as long as the session: an error cannot happen while we wait.
        let _ = rx.wait_for(|e| *e).await;
    }
}
