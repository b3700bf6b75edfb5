//! The line-protocol table driver against an in-memory fake instrument.

use ratecal_drivers::line::LineTable;
use ratecal_drivers::{DriverErrorKind, TableAxisId, TableCommand, TableDriver, TableInfo};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::io::{AsyncBufReadExt, AsyncWriteExt, BufReader, DuplexStream};

fn info() -> TableInfo {
    TableInfo {
        model: "fake".into(),
        max_rate_dps: 500.0,
        max_accel_dps2: 200.0,
        feedback_hz: 50.0,
        simulated: false,
    }
}

/// A fake table: logs requests; answers by a script keyed on the request's first word.
async fn fake(stream: DuplexStream, log: Arc<Mutex<Vec<String>>>) {
    let (r, mut w) = tokio::io::split(stream);
    let mut lines = BufReader::new(r).lines();
    while let Ok(Some(line)) = lines.next_line().await {
        log.lock().unwrap().push(line.clone());
        let reply = match line.split_whitespace().next().unwrap_or("") {
            "FEED?" => {
                "F 100.00 1.5 -2.0 0.1 0.0 20.1\nF 100.02 1.6 -2.0 0.1 0.0\nEND\n".to_string()
            }
            "RATE" if line.ends_with(" 900") => "ERR RANGE rate above 500 deg/s\n".into(),
            "MOVE" if line.contains("666") => "ERR AMP inner amplifier overheated\n".into(),
            "STOP" if line.contains("INNER") => continue, // never answers
            "OSC" => "WHAT\n".into(),
            _ => "OK\n".into(),
        };
        if w.write_all(reply.as_bytes()).await.is_err() {
            return;
        }
    }
}

fn table() -> (LineTable<DuplexStream>, Arc<Mutex<Vec<String>>>) {
    let (a, b) = tokio::io::duplex(4096);
    let log = Arc::new(Mutex::new(Vec::new()));
    tokio::spawn(fake(b, log.clone()));
    (LineTable::new(a, info(), Duration::from_secs(1)), log)
}

#[tokio::test(start_paused = true)]
async fn commands_and_feedback_follow_the_protocol() {
    let (mut t, log) = table();
    t.command(TableCommand::MoveTo {
        outer_deg: 90.0,
        inner_deg: -180.0,
    })
    .await
    .unwrap();
    t.command(TableCommand::Rate {
        axis: TableAxisId::Outer,
        rate_dps: -50.5,
    })
    .await
    .unwrap();
    t.command(TableCommand::SafeStop).await.unwrap();
    let mut fb = Vec::new();
    t.read(&mut fb).await.unwrap();
    assert_eq!(
        *log.lock().unwrap(),
        ["MOVE 90 -180", "RATE OUTER -50.5", "SAFE", "FEED?"]
    );
    assert_eq!(fb.len(), 2);
    assert_eq!(
        (fb[0].outer_deg, fb[0].inner_deg, fb[0].ambient_c),
        (1.5, -2.0, Some(20.1))
    );
    assert_eq!(fb[1].ambient_c, None);
    // The instrument clock is mapped onto the host clock at the newest sample of the first
    // reply (the least delayed one).
    assert!((fb[0].t + 0.02).abs() < 1e-9 && fb[1].t.abs() < 1e-9);
}

#[tokio::test(start_paused = true)]
async fn instrument_faults_are_kept_apart_from_link_failures() {
    let (mut t, _) = table();
    let e = t
        .command(TableCommand::Rate {
            axis: TableAxisId::Outer,
            rate_dps: 900.0,
        })
        .await
        .unwrap_err();
    assert_eq!(e.kind(), DriverErrorKind::InvalidCommand);
    let e = t
        .command(TableCommand::MoveTo {
            outer_deg: 666.0,
            inner_deg: 0.0,
        })
        .await
        .unwrap_err();
    assert_eq!(e.kind(), DriverErrorKind::Instrument);
    assert!(e.message.contains("amplifier"));
    // Instrument faults leave the link usable.
    t.command(TableCommand::Stop {
        axis: TableAxisId::Outer,
    })
    .await
    .unwrap();

    let osc = TableCommand::Oscillate {
        axis: TableAxisId::Inner,
        center_deg: 0.0,
        amplitude_deg: 5.0,
        period_s: 2.0,
    };
    assert_eq!(
        t.command(osc).await.unwrap_err().kind(),
        DriverErrorKind::Transport
    );
    assert!(t.is_broken());
}

#[tokio::test(start_paused = true)]
async fn silence_is_a_timeout() {
    let (mut t, _) = table();
    let e = t
        .command(TableCommand::Stop {
            axis: TableAxisId::Inner,
        })
        .await
        .unwrap_err();
    assert_eq!(e.kind(), DriverErrorKind::Timeout);
    let e = t.command(TableCommand::SafeStop).await.unwrap_err();
    assert_eq!(
        e.kind(),
        DriverErrorKind::Transport,
        "the link is out of step after a timeout"
    );
}

#[test]
fn requests_decode_to_the_commands_they_encode() {
    use ratecal_drivers::line::{decode, encode};
    for c in [
        TableCommand::MoveTo {
            outer_deg: 90.0,
            inner_deg: -0.125,
        },
        TableCommand::Rate {
            axis: TableAxisId::Inner,
            rate_dps: 1e-3,
        },
        TableCommand::Stop {
            axis: TableAxisId::Outer,
        },
        TableCommand::Oscillate {
            axis: TableAxisId::Outer,
            center_deg: 0.0,
            amplitude_deg: 10.0,
            period_s: 2.5,
        },
        TableCommand::SafeStop,
    ] {
        assert_eq!(decode(&encode(&c)), Some(c));
    }
    for bad in [
        "",
        "MOVE 1",
        "RATE SIDEWAYS 3",
        "OSC OUTER 1 2",
        "MOVE nan 0",
        "HELLO",
    ] {
        assert_eq!(decode(bad), None, "{bad}");
    }
}

#[tokio::test(start_paused = true)]
async fn a_closed_link_is_a_transport_failure() {
    let (a, b) = tokio::io::duplex(64);
    drop(b);
    let mut t = LineTable::new(a, info(), Duration::from_secs(1));
    let e = t.command(TableCommand::SafeStop).await.unwrap_err();
    assert_eq!(e.kind(), DriverErrorKind::Transport);
}

#[tokio::test]
#[ignore = "needs a table on 127.0.0.1:5025 (hardware)"]
async fn real_table_answers() {
    let text = ratecal_drivers::DEFAULT_STATION_YAML
        .replace(
            "driver: sim\n  model: simulated",
            "driver: { tcp: { address: \"127.0.0.1:5025\" } }\n  model: simulated",
        )
        .replace(
            "  driver: sim\n  model: SIM",
            "  driver: { replay: { recording: . } }\n  model: SIM",
        );
    let s = ratecal_drivers::Station::from_yaml(&text, "hw.yaml").unwrap();
    let (mut t, _) = ratecal_drivers::build(&s, 1).unwrap();
    let mut fb = Vec::new();
    t.read(&mut fb).await.unwrap();
}
