//! The emulated table: answers the line protocol from the simulated table.

use super::{End, Session};
use crate::station::LinkName;
use crate::{DriverErrorKind, TableCommand, TableDriver};
use std::fmt::Write as _;
use tokio::io::{AsyncBufReadExt, AsyncRead, AsyncWrite, AsyncWriteExt, BufStream};

const FAULT: &str = "ERR FAULT amplifier fault (emulated): only SAFE is accepted\n";

/// Serves requests until the client closes the link or a fault drops it.
pub(super) async fn serve<S: AsyncRead + AsyncWrite + Unpin>(stream: S, s: &Session) -> End {
    let mut io = BufStream::new(stream);
    let mut line = String::new();
    let mut reply = String::new();
    loop {
        line.clear();
        tokio::select! {
            r = io.read_line(&mut line) => match r {
                Ok(0) | Err(_) => return End::Client,
                Ok(_) => {}
            },
            () = s.ended() => return End::Ended,
        }
        let t = s.now();
        if s.take_drop(LinkName::Table, t) {
            return End::Dropped;
        }
        if let Some(end) = s.faults.stall_end(LinkName::Table, t) {
            // A stalled table answers late (after the stall), if the client still listens;
            // a client that gave up meanwhile reconnects within the session.
            s.disturb(LinkName::Table, end);
            let until = s.start + std::time::Duration::from_secs_f64(end);
            tokio::select! {
                () = tokio::time::sleep_until(until) => {}
                () = s.ended() => return End::Ended,
            }
        }
        reply.clear();
        answer(line.trim(), s, &mut reply).await;
        if io.write_all(reply.as_bytes()).await.is_err() || io.flush().await.is_err() {
            return End::Client;
        }
    }
}

async fn answer(request: &str, s: &Session, out: &mut String) {
    let flagged = s.faults.flagged(s.now());
    match request {
        "FEED?" if flagged => out.push_str(FAULT),
        "FEED?" => {
            let mut samples = Vec::new();
            if let Err(e) = s.table.lock().await.read(&mut samples).await {
                let _ = writeln!(out, "ERR FAULT {e}");
                return;
            }
            for f in samples {
                let _ = write!(
                    out,
                    "F {} {} {} {} {}",
                    f.t, f.outer_deg, f.inner_deg, f.outer_rate_dps, f.inner_rate_dps
                );
                if let Some(a) = f.ambient_c {
                    let _ = write!(out, " {a}");
                }
                out.push('\n');
            }
            out.push_str("END\n");
        }
        "STATUS?" if flagged => out.push_str("STATUS FAULT amplifier fault (emulated)\n"),
        "STATUS?" => out.push_str("STATUS OK\n"),
        _ => match crate::line::decode(request) {
            None => {
                let _ = writeln!(out, "ERR SYNTAX cannot read `{request}`");
            }
            Some(cmd) if flagged && cmd != TableCommand::SafeStop => out.push_str(FAULT),
            Some(cmd) => match s.table.lock().await.command(cmd).await {
                Ok(()) => out.push_str("OK\n"),
                Err(e) if e.kind() == DriverErrorKind::InvalidCommand => {
                    let _ = writeln!(out, "ERR RANGE {e}");
                }
                Err(e) => {
                    let _ = writeln!(out, "ERR FAULT {e}");
                }
            },
        },
    }
}
