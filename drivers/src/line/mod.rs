//! A table driven over the ratecal line protocol, generic over any async byte stream (TCP,
//! serial, an in-memory pipe). The protocol is documented in `docs/protocols.md`:
//!
//! ```text
//! -> MOVE <outer_deg> <inner_deg>            <- OK | ERR <code> <message>
//! -> RATE <OUTER|INNER> <dps>                <- OK | ERR ...
//! -> STOP <OUTER|INNER>                      <- OK | ERR ...
//! -> OSC <OUTER|INNER> <center> <amp> <period_s>  <- OK | ERR ...
//! -> SAFE                                    <- OK | ERR ...
//! -> STATUS?                                 <- STATUS OK | STATUS FAULT <message>
//! -> FEED?                                   <- F <t> <outer> <inner> <outer_rate> <inner_rate> [<ambient>]
//!                                               ... (zero or more) then END | ERR ...
//! ```
//!
//! `ERR RANGE ...` means the command is outside what the table can do
//! (`InvalidCommand`); any other `ERR` is an instrument fault (`Instrument`). A silent
//! instrument is a `Timeout`; a closed or garbled link is a `Transport` failure.

use crate::link::ClockMap;
use crate::{
    DriverError, DriverErrorKind, TableAxisId, TableCommand, TableDriver, TableInfo, TableSample,
};
use async_trait::async_trait;
use std::time::Duration;
use tokio::io::{AsyncBufReadExt, AsyncRead, AsyncWrite, AsyncWriteExt, BufStream};
use tokio::time::{Instant, timeout};

fn axis_name(axis: TableAxisId) -> &'static str {
    match axis {
        TableAxisId::Outer => "OUTER",
        TableAxisId::Inner => "INNER",
    }
}

/// The request line for a command (without the newline).
pub fn encode(cmd: &TableCommand) -> String {
    match cmd {
        TableCommand::MoveTo {
            outer_deg,
            inner_deg,
        } => format!("MOVE {outer_deg} {inner_deg}"),
        TableCommand::Rate { axis, rate_dps } => format!("RATE {} {rate_dps}", axis_name(*axis)),
        TableCommand::Stop { axis } => format!("STOP {}", axis_name(*axis)),
        TableCommand::Oscillate {
            axis,
            center_deg,
            amplitude_deg,
            period_s,
        } => {
            format!(
                "OSC {} {center_deg} {amplitude_deg} {period_s}",
                axis_name(*axis)
            )
        }
        TableCommand::SafeStop => "SAFE".into(),
    }
}

fn axis_of(word: Option<&str>) -> Option<TableAxisId> {
    match word? {
        "OUTER" => Some(TableAxisId::Outer),
        "INNER" => Some(TableAxisId::Inner),
        _ => None,
    }
}

/// The command of a request line (the inverse of [`encode`]); `None` for anything else.
pub fn decode(line: &str) -> Option<TableCommand> {
    let mut w = line.split_whitespace();
    let verb = w.next()?;
    let mut num = || -> Option<f64> { w.next()?.parse().ok().filter(|v: &f64| v.is_finite()) };
    let cmd = match verb {
        "MOVE" => TableCommand::MoveTo {
            outer_deg: num()?,
            inner_deg: num()?,
        },
        "SAFE" => TableCommand::SafeStop,
        _ => {
            let mut w = line.split_whitespace().skip(1);
            let axis = axis_of(w.next())?;
            let mut num =
                || -> Option<f64> { w.next()?.parse().ok().filter(|v: &f64| v.is_finite()) };
            match verb {
                "RATE" => TableCommand::Rate {
                    axis,
                    rate_dps: num()?,
                },
                "STOP" => TableCommand::Stop { axis },
                "OSC" => TableCommand::Oscillate {
                    axis,
                    center_deg: num()?,
                    amplitude_deg: num()?,
                    period_s: num()?,
                },
                _ => return None,
            }
        }
    };
    Some(cmd)
}

fn transport(msg: impl Into<String>) -> DriverError {
    DriverError::new(DriverErrorKind::Transport, msg)
}

/// An `ERR <code> <message>` reply as a driver error.
fn instrument_error(rest: &str) -> DriverError {
    let kind = if rest.starts_with("RANGE") {
        DriverErrorKind::InvalidCommand
    } else {
        DriverErrorKind::Instrument
    };
    DriverError::new(kind, format!("table reported: {rest}"))
}

/// A table on a line-protocol link over `S`.
#[derive(Debug)]
pub struct LineTable<S> {
    io: BufStream<S>,
    info: TableInfo,
    timeout: Duration,
    start: Instant,
    /// Instrument time onto local time (anchored on the first feedback reply).
    clock: ClockMap,
    broken: bool,
    line: String,
}

impl<S: AsyncRead + AsyncWrite + Unpin + Send> LineTable<S> {
    /// Wraps a connected stream; `timeout` bounds every request-reply exchange.
    pub fn new(stream: S, info: TableInfo, timeout: Duration) -> Self {
        LineTable {
            io: BufStream::new(stream),
            info,
            timeout,
            start: Instant::now(),
            clock: ClockMap::default(),
            broken: false,
            line: String::new(),
        }
    }

    async fn read_line(&mut self) -> Result<&str, DriverError> {
        self.line.clear();
        let n = self
            .io
            .read_line(&mut self.line)
            .await
            .map_err(|e| transport(format!("table link: {e}")))?;
        if n == 0 {
            return Err(transport("table link closed"));
        }
        Ok(self.line.trim())
    }

    async fn send(&mut self, request: &str) -> Result<(), DriverError> {
        let io = async {
            self.io.write_all(request.as_bytes()).await?;
            self.io.write_all(b"\n").await?;
            self.io.flush().await
        };
        io.await.map_err(|e| transport(format!("table link: {e}")))
    }

    /// Runs one exchange under the timeout; after a timeout or a transport failure the
    /// link is out of step and every later call fails until it is rebuilt.
    async fn exchange<T>(
        &mut self,
        f: impl AsyncFnOnce(&mut Self) -> Result<T, DriverError>,
    ) -> Result<T, DriverError> {
        if self.broken {
            return Err(transport("table link out of step after an earlier failure"));
        }
        let limit = self.timeout;
        let out = match timeout(limit, f(self)).await {
            Ok(r) => r,
            Err(_) => Err(DriverError::new(
                DriverErrorKind::Timeout,
                format!("table did not answer within {} s", limit.as_secs_f64()),
            )),
        };
        if let Err(e) = &out
            && matches!(
                e.kind(),
                DriverErrorKind::Timeout | DriverErrorKind::Transport
            )
        {
            self.broken = true;
        }
        out
    }

    /// Whether the link failed and must be rebuilt.
    pub fn is_broken(&self) -> bool {
        self.broken
    }

    /// The clock map and link statistics (kept across a rebuilt link).
    pub fn clock(&self) -> &ClockMap {
        &self.clock
    }

    /// Takes over the clock map of an earlier link to the same table, and the host
    /// clock's origin `start` it maps onto.
    pub fn set_clock(&mut self, clock: ClockMap, start: Instant) {
        self.clock = clock;
        self.start = start;
    }

    fn parse_feedback(&self, line: &str) -> Result<TableSample, DriverError> {
        let fields: Vec<f64> = line[1..]
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map_err(|_| transport(format!("garbled feedback line `{line}`")))?;
        if !(5..=6).contains(&fields.len()) {
            return Err(transport(format!(
                "feedback line `{line}` has {} fields, expected 5 or 6",
                fields.len()
            )));
        }
        Ok(TableSample {
            t: fields[0],
            outer_deg: fields[1],
            inner_deg: fields[2],
            outer_rate_dps: fields[3],
            inner_rate_dps: fields[4],
            ambient_c: fields.get(5).copied(),
            t_host: None,
        })
    }
}

#[async_trait]
impl<S: AsyncRead + AsyncWrite + Unpin + Send> TableDriver for LineTable<S> {
    fn info(&self) -> TableInfo {
        self.info.clone()
    }

    async fn command(&mut self, cmd: TableCommand) -> Result<(), DriverError> {
        let request = encode(&cmd);
        self.exchange(async move |me: &mut Self| {
            me.send(&request).await?;
            let reply = me.read_line().await?;
            match reply.split_once(' ').map_or((reply, ""), |(a, b)| (a, b)) {
                ("OK", _) => Ok(()),
                ("ERR", rest) => Err(instrument_error(rest)),
                _ => Err(transport(format!(
                    "unexpected reply `{reply}` to `{request}`"
                ))),
            }
        })
        .await
    }

    async fn read(&mut self, out: &mut Vec<TableSample>) -> Result<(), DriverError> {
        let got = self
            .exchange(async |me: &mut Self| {
                me.send("FEED?").await?;
                let mut got = Vec::new();
                loop {
                    let line = me.read_line().await?.to_string();
                    if line == "END" {
                        return Ok(got);
                    } else if let Some(rest) = line.strip_prefix("ERR ") {
                        return Err(instrument_error(rest));
                    } else if line.starts_with('F') {
                        // Arrival: when the line came off the link (the lines of a reply
                        // over a slow serial port arrive one by one).
                        let host = me.start.elapsed().as_secs_f64();
                        got.push(TableSample {
                            t_host: Some(host),
                            ..me.parse_feedback(&line)?
                        });
                    } else {
                        return Err(transport(format!("unexpected reply `{line}` to `FEED?`")));
                    }
                }
            })
            .await?;
        if let Some(newest) = got.last() {
            let host = self.start.elapsed().as_secs_f64();
            self.clock.arrival(newest.t, host, got.len() as u64);
        }
        out.extend(got.into_iter().map(|s| TableSample {
            t: self.clock.map(s.t),
            ..s
        }));
        Ok(())
    }
}
