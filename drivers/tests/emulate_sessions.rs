//! Session boundaries of the emulator over real loopback sockets (`docs/protocols.md`, "The
//! emulator"): a new client's connection starts a fresh session even when the emulator has
//! not seen the old client's links close, while a link's reconnect after a rehearsed fault
//! (a dropped or stalled link) continues the run's session.

use ratecal_drivers::emulate::Emulator;
use ratecal_drivers::{DEFAULT_STATION_YAML, Station};
use std::sync::Arc;
use std::time::Duration;
use tokio::io::{AsyncBufReadExt, AsyncReadExt, AsyncWriteExt, BufReader};
use tokio::net::{TcpListener, TcpStream};
use tokio::time::{Instant, sleep, timeout};

/// An emulator of the default station with `faults` (YAML list items), serving on free
/// loopback ports; returns it and the table's and the IMU's addresses.
async fn emulator(faults: &str) -> (Arc<Emulator>, String, String) {
    let yaml = DEFAULT_STATION_YAML.replace("faults: []", &format!("faults:\n{faults}"));
    let station = Station::from_yaml(&yaml, "emulated.yaml").expect("station");
    let emu = Emulator::new(station, 1, false);
    let table = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let imu = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addrs = (
        table.local_addr().unwrap().to_string(),
        imu.local_addr().unwrap().to_string(),
    );
    tokio::spawn(emu.clone().serve_tcp(table, imu));
    (emu, addrs.0, addrs.1)
}

/// A table link: one request, one reply (a `FEED?` reply up to its `END`).
struct Table(BufReader<TcpStream>);

impl Table {
    async fn connect(addr: &str) -> Self {
        Table(BufReader::new(TcpStream::connect(addr).await.unwrap()))
    }

    /// The reply lines to `request` (a `FEED?` reply up to its `END`); `None` when the
    /// link closed.
    async fn ask(&mut self, request: &str) -> Option<Vec<String>> {
        let line = format!("{request}\n");
        self.0.get_mut().write_all(line.as_bytes()).await.ok()?;
        let mut lines = Vec::new();
        loop {
            let mut line = String::new();
            if self.0.read_line(&mut line).await.unwrap_or(0) == 0 {
                return None;
            }
            let line = line.trim().to_string();
            let last = request != "FEED?" || line == "END" || line.starts_with("ERR");
            lines.push(line);
            if last {
                return Some(lines);
            }
        }
    }

    /// The feedback `(t, outer_deg)` of one `FEED?`; `None` when the link closed.
    async fn feedback(&mut self) -> Option<Vec<(f64, f64)>> {
        let lines = self.ask("FEED?").await?;
        Some(
            lines
                .iter()
                .filter_map(|l| {
                    let mut w = l.strip_prefix("F ")?.split_whitespace();
                    Some((w.next()?.parse().ok()?, w.next()?.parse().ok()?))
                })
                .collect(),
        )
    }

    /// The newest feedback `(t, outer_deg)`, waiting for one; `None` when the link closed.
    async fn newest(&mut self) -> Option<(f64, f64)> {
        loop {
            if let Some(&last) = self.feedback().await?.last() {
                return Some(last);
            }
            sleep(Duration::from_millis(20)).await;
        }
    }
}

/// Whether the peer closed `stream` within `within` (bytes it still sends are read and
/// dropped).
async fn closed_within(stream: &mut TcpStream, within: Duration) -> bool {
    let mut buf = [0u8; 4096];
    let until = Instant::now() + within;
    loop {
        match timeout(
            until.saturating_duration_since(Instant::now()),
            stream.read(&mut buf),
        )
        .await
        {
            Ok(Ok(0)) | Ok(Err(_)) => return true,
            Ok(Ok(_)) => {}
            Err(_) => return false,
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_new_client_starts_a_fresh_session_while_the_old_links_still_look_open() {
    let (emu, table_addr, imu_addr) = emulator("  []").await;
    // Client A: moves the table and reads the IMU; it never closes its links (a client
    // whose close the emulator has not seen, or a host that vanished from the network).
    let mut a = Table::connect(&table_addr).await;
    let mut a_imu = TcpStream::connect(&imu_addr).await.unwrap();
    assert_eq!(a.ask("MOVE 30 0").await, Some(vec!["OK".to_string()]));
    sleep(Duration::from_millis(1500)).await;
    let (t_a, outer_a) = a.newest().await.expect("feedback for A");
    assert!(
        t_a > 1.0 && outer_a > 20.0,
        "A's session ran and moved: t {t_a} s, outer {outer_a} deg"
    );
    assert_eq!(emu.sessions(), 1);

    // Client B connects its table link: a new session, a fresh world at clock 0.
    let mut b = Table::connect(&table_addr).await;
    let (t_b, outer_b) = b.newest().await.expect("feedback for B");
    assert_eq!(emu.sessions(), 2, "B joined A's session");
    assert!(
        t_b < 0.5 && outer_b.abs() < 1.0,
        "B sees A's world (t {t_b} s, outer {outer_b} deg; A saw t {t_a} s, outer {outer_a} deg)"
    );
    // A's session is over: the emulator closed its links.
    assert!(
        closed_within(a.0.get_mut(), Duration::from_secs(2)).await,
        "A's table link is still served"
    );
    assert!(
        closed_within(&mut a_imu, Duration::from_secs(2)).await,
        "A's IMU link is still served"
    );
    // B's session goes on.
    assert!(b.newest().await.is_some(), "B's session stopped");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_new_imu_link_of_a_new_client_does_not_join_the_old_session() {
    let (emu, table_addr, imu_addr) = emulator("  []").await;
    let mut a = Table::connect(&table_addr).await;
    let _a_imu = TcpStream::connect(&imu_addr).await.unwrap();
    assert_eq!(a.ask("MOVE 30 0").await, Some(vec!["OK".to_string()]));
    sleep(Duration::from_millis(1200)).await;
    // A driver opens its IMU link first (it streams unasked), then the table's.
    let _b_imu = TcpStream::connect(&imu_addr).await.unwrap();
    sleep(Duration::from_millis(100)).await;
    let mut b = Table::connect(&table_addr).await;
    let (t_b, outer_b) = b.newest().await.expect("feedback for B");
    assert_eq!(emu.sessions(), 2, "B joined A's session");
    assert!(
        t_b < 0.6 && outer_b.abs() < 1.0,
        "B sees A's world: t {t_b} s, outer {outer_b} deg"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_link_back_after_a_rehearsed_drop_continues_the_session() {
    let (emu, table_addr, imu_addr) =
        emulator("  - link_drop: { at: 0.5 s, link: table, duration: 0.3 s }").await;
    let _imu = TcpStream::connect(&imu_addr).await.unwrap();
    let mut a = Table::connect(&table_addr).await;
    assert_eq!(a.ask("MOVE 30 0").await, Some(vec!["OK".to_string()]));
    // Polled as a driver does until the emulator drops the link.
    let start = Instant::now();
    let mut last_t = 0.0;
    while let Some(fb) = a.feedback().await {
        if let Some(&(t, _)) = fb.last() {
            last_t = t;
        }
        assert!(
            start.elapsed() < Duration::from_secs(3),
            "the link was not dropped"
        );
        sleep(Duration::from_millis(20)).await;
    }
    assert!(last_t > 0.3, "dropped before its time: {last_t} s");
    // Reconnects (refused during the outage) until the link is back, as the driver does.
    let (t, outer) = loop {
        let mut again = Table::connect(&table_addr).await;
        if let Some(newest) = again.newest().await {
            break newest;
        }
        assert!(
            start.elapsed() < Duration::from_secs(3),
            "the link did not come back"
        );
        sleep(Duration::from_millis(50)).await;
    };
    assert_eq!(emu.sessions(), 1, "the reconnect started a new session");
    assert!(
        t > last_t && t > 0.75 && outer > 5.0,
        "the session's clock and motion went on: t {t} s after {last_t} s, outer {outer} deg"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_link_given_up_during_a_rehearsed_stall_continues_the_session() {
    let (emu, table_addr, _) =
        emulator("  - stall: { at: 0.5 s, link: table, duration: 1.5 s }").await;
    let mut a = Table::connect(&table_addr).await;
    assert_eq!(a.ask("MOVE 30 0").await, Some(vec!["OK".to_string()]));
    sleep(Duration::from_millis(600)).await;
    // Unanswered: the client gives up after its timeout and opens a new link, which the
    // emulator sees while the old one (stalled, not read) still looks open.
    assert!(
        timeout(Duration::from_millis(600), a.feedback())
            .await
            .is_err(),
        "the stalled table answered"
    );
    let mut again = Table::connect(&table_addr).await;
    let (t, _) = again.newest().await.expect("feedback after the stall");
    assert_eq!(emu.sessions(), 1, "the reconnect started a new session");
    assert!(
        t > 1.9,
        "answered after the stall, on the session's clock: {t} s"
    );
}
