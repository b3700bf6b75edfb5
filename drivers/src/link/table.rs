//! The table of a station over TCP or a serial port: connects on first use, rebuilds a
//! link that failed, and keeps the run going when it is back within the timeout (feedback
//! reads report a `Timeout` meanwhile, which the interpreter tolerates; a command is sent
//! again on the new link).

use super::{BoxStream, ClockMap, Endpoint, connect};
use crate::line::LineTable;
use crate::{
    DriverError, DriverErrorKind, LinkStats, TableCommand, TableDriver, TableInfo, TableSample,
};
use async_trait::async_trait;
use std::time::Duration;
use tokio::time::Instant;

/// A line-protocol table behind a link that is rebuilt after failures.
pub struct LinkTable {
    endpoint: Endpoint,
    info: TableInfo,
    timeout: Duration,
    start: Instant,
    link: Option<LineTable<BoxStream>>,
    clock: ClockMap,
    /// When the link was found broken (the reconnect window runs from there).
    lost_at: Option<Instant>,
    connected_once: bool,
    last_attempt: Option<Instant>,
}

impl std::fmt::Debug for LinkTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "LinkTable({})", self.endpoint)
    }
}

fn lost(e: &DriverError) -> bool {
    matches!(
        e.kind(),
        DriverErrorKind::Timeout | DriverErrorKind::Transport
    )
}

impl LinkTable {
    /// A table at `endpoint`; nothing is opened until the first call. Feedback times are
    /// mapped onto the host clock counted from `start`.
    pub fn new(endpoint: Endpoint, info: TableInfo, timeout_s: f64, start: Instant) -> Self {
        LinkTable {
            endpoint,
            info,
            timeout: Duration::from_secs_f64(timeout_s),
            start,
            link: None,
            clock: ClockMap::default(),
            lost_at: None,
            connected_once: false,
            last_attempt: None,
        }
    }

    /// The open link, rebuilt if it broke. Within the reconnect window a failure to
    /// connect is a `Timeout`; after it, the error itself.
    async fn link(&mut self) -> Result<&mut LineTable<BoxStream>, DriverError> {
        if let Some(l) = self.link.take_if(|l| l.is_broken()) {
            self.clock = l.clock().clone();
            self.lost_at.get_or_insert_with(Instant::now);
        }
        if self.link.is_none() {
            // At most one connection attempt per 50 ms: a device that accepts and closes at
            // once must not be hammered.
            if let Some(at) = self.last_attempt
                && at.elapsed() < Duration::from_millis(50)
            {
                tokio::time::sleep_until(at + Duration::from_millis(50)).await;
            }
            self.last_attempt = Some(Instant::now());
            match connect(&self.endpoint, self.timeout).await {
                Ok(stream) => {
                    let mut l = LineTable::new(stream, self.info.clone(), self.timeout);
                    if self.connected_once {
                        self.clock.stats.reconnects += 1;
                    }
                    l.set_clock(self.clock.clone(), self.start);
                    self.connected_once = true;
                    self.link = Some(l);
                }
                Err(e) => {
                    let since = *self.lost_at.get_or_insert_with(Instant::now);
                    if since.elapsed() < self.timeout {
                        tokio::time::sleep(Duration::from_millis(20)).await;
                        return Err(DriverError::new(DriverErrorKind::Timeout, e.message));
                    }
                    return Err(DriverError::new(
                        e.kind(),
                        format!(
                            "table link lost and not back within {:?}: {}",
                            self.timeout, e.message
                        ),
                    ));
                }
            }
        }
        Ok(self.link.as_mut().expect("just connected"))
    }
}

#[async_trait]
impl TableDriver for LinkTable {
    fn info(&self) -> TableInfo {
        self.info.clone()
    }

    async fn command(&mut self, cmd: TableCommand) -> Result<(), DriverError> {
        loop {
            let r = match self.link().await {
                Ok(l) => l.command(cmd.clone()).await,
                Err(e) => Err(e),
            };
            match r {
                Err(e) if lost(&e) => {
                    let since = *self.lost_at.get_or_insert_with(Instant::now);
                    if since.elapsed() >= self.timeout {
                        return Err(e);
                    }
                    if let Some(l) = &self.link
                        && !l.is_broken()
                    {
                        return Err(e);
                    }
                }
                r => {
                    if r.is_ok() {
                        self.lost_at = None;
                    }
                    return r;
                }
            }
        }
    }

    async fn read(&mut self, out: &mut Vec<TableSample>) -> Result<(), DriverError> {
        match self.link().await?.read(out).await {
            Err(e) if lost(&e) => {
                let since = *self.lost_at.get_or_insert_with(Instant::now);
                if since.elapsed() < self.timeout {
                    Err(DriverError::new(DriverErrorKind::Timeout, e.message))
                } else {
                    Err(e)
                }
            }
            r => {
                if r.is_ok() {
                    self.lost_at = None;
                }
                r
            }
        }
    }

    fn link_stats(&self) -> Option<LinkStats> {
        Some(
            self.link
                .as_ref()
                .map_or(&self.clock, |l| l.clock())
                .stats
                .clone(),
        )
    }
}
