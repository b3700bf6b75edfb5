//! The control loop and the walk over the plan's steps.

mod manual;

use super::command::{AxisCmd, CmdState, axis_id, substitute};
use super::live::{ImuRow, Live, TableRow, stability_unmet};
use super::monitor::{Fire, Monitor};
use super::{JournalEntry, JournalEvent, Progress, RunOptions, RunOutcome, RunSink, RunStatus};
use ratecal_drivers::{
    DriverError, DriverErrorKind, ImuDriver, ImuSample, TableCommand, TableDriver, TableSample,
};
use ratecal_plan::{AbortAction, Acquire, Action, Axis, Node, OnTimeout, Plan, Settle};
use ratecal_recording::{AbortRecord, Mount};
use std::io;
use std::sync::atomic::Ordering;
use std::time::Duration;
use tokio::time::{Instant, sleep_until};

/// Wall-clock time between flushes of the recording to the disk, s (at most a second of
/// data is ever only in memory; half of it leaves room for a slow tick).
const FLUSH_EVERY_S: f64 = 0.5;

/// Run-clock time between looks at the wall clock for [`FLUSH_EVERY_S`], s: a real run's
/// clock is the wall's, so a flush is at most this late; a simulated run looks a few times
/// per simulated second, not at every tick (a clock read each is a tenth of a dry run's
/// interpreter).
const FLUSH_LOOK_S: f64 = 0.1;

/// Why the walk stops early.
pub(super) enum Stop {
    Abort(AbortRecord),
}

type Res = Result<(), Stop>;

/// Runs `plan` from `opts.start_step` on the station, recording into `sink`. Aborts (rules,
/// settle timeouts with `abort`, driver or recording errors, `opts.cancel`) bring the table
/// to its safe state and close the recording as `aborted`; the outcome says which. `Err` only
/// when the sink cannot be closed.
pub async fn execute(
    plan: &Plan,
    table: &mut dyn TableDriver,
    imu: &mut dyn ImuDriver,
    sink: &mut dyn RunSink,
    progress: &mut dyn Progress,
    opts: &RunOptions,
) -> io::Result<RunOutcome> {
    let info = imu.info();
    let table_info = table.info();
    let longest = plan
        .steps
        .iter()
        .flat_map(|s| s.body.iter())
        .flat_map(stabilities)
        .fold(1.0_f64, f64::max);
    let now = Instant::now();
    let mut ex = Exec {
        plan,
        table,
        imu,
        sink,
        progress,
        opts,
        start: now,
        next_tick: now,
        t0: None,
        cmd: CmdState::default(),
        armed: false,
        live: Live::new(longest),
        monitor: Monitor::new(&plan.aborts, (info.accel_range_mps2, info.gyro_range_dps)),
        imu_buf: Vec::new(),
        table_buf: Vec::new(),
        last_imu_t: opts.t_offset,
        last_finite_imu_t: opts.t_offset,
        last_table_t: opts.t_offset,
        last_table: None,
        step: None,
        pending_mount: None,
        segments: 0,
        steps_completed: opts.start_step,
        imu_samples: 0,
        table_samples: 0,
        warnings: Vec::new(),
        fires: Vec::new(),
        last_progress: f64::NEG_INFINITY,
        last_flush: std::time::Instant::now(),
        flush_look: f64::NEG_INFINITY,
        stall_s: opts.stall_timeout_s.max(3.0 / info.sample_hz.max(1e-3)),
        imu_hz: info.sample_hz,
        table_hz: table_info.feedback_hz,
        simulated: info.simulated && table_info.simulated,
        timeouts_since: None,
        warned_nonfinite: false,
        manual: manual::Manual::default(),
        operator: plan
            .steps
            .iter()
            .flat_map(|s| s.body.iter())
            .any(asks_operator),
    };
    ex.journal(JournalEvent::Start {
        procedure: plan.name.clone(),
        from_step: opts.start_step,
        resumed: opts.start_step > 0,
    });
    let result = match ex.drain().await {
        Ok(()) => ex.walk().await,
        Err(e) => Err(e),
    };
    // The last segment's checkpoint may still be under way: its failure aborts the run.
    let result = result.and_then(|()| ex.settled());
    let status = match result {
        Ok(()) => {
            if matches!(ex.cmd.outer, AxisCmd::Rate(_) | AxisCmd::Osc { .. })
                || matches!(ex.cmd.inner, AxisCmd::Rate(_) | AxisCmd::Osc { .. })
            {
                ex.safe_stop().await;
            }
            RunStatus::Completed
        }
        Err(Stop::Abort(rec)) => {
            ex.journal(JournalEvent::Abort {
                rule: rec.rule.clone(),
                values: rec.values.clone(),
            });
            ex.progress.message(&format!(
                "aborting: {} at t = {:.3} s ({})",
                rec.rule, rec.t, rec.values
            ));
            ex.safe_stop().await;
            RunStatus::Aborted(rec)
        }
    };
    ex.journal(JournalEvent::End {
        status: status.as_str().into(),
    });
    let shift = ex.t0.map_or(0.0, |t0| ex.opts.t_offset - t0);
    let sync = super::links::sync_record(ex.table.link_stats(), ex.imu.link_stats(), shift);
    if let Some(s) = &sync {
        ex.sink.links(s);
    }
    let t_end = ex.now();
    ex.sink.end(&status)?;
    Ok(RunOutcome {
        status,
        t_start: opts.t_offset,
        t_end,
        segments: ex.segments,
        steps_completed: ex.steps_completed,
        imu_samples: ex.imu_samples,
        table_samples: ex.table_samples,
        warnings: ex.warnings,
        sync,
    })
}

/// Whether a node asks the operator of a manual station for something.
fn asks_operator(n: &Node) -> bool {
    match n {
        Node::Do(a) => matches!(a, Action::Place(_) | Action::Turn(_)),
        Node::Repeat { body, .. } => body.iter().any(asks_operator),
    }
}

/// Stability windows used by a node (to size the live window).
fn stabilities(n: &Node) -> Vec<f64> {
    match n {
        Node::Do(Action::Settle(s)) => s.stable.iter().map(|x| x.window_s).collect(),
        Node::Do(_) => Vec::new(),
        Node::Repeat { body, .. } => body.iter().flat_map(stabilities).collect(),
    }
}

struct Exec<'a> {
    plan: &'a Plan,
    table: &'a mut dyn TableDriver,
    imu: &'a mut dyn ImuDriver,
    sink: &'a mut dyn RunSink,
    progress: &'a mut dyn Progress,
    opts: &'a RunOptions,
    start: Instant,
    next_tick: Instant,
    /// Station time of recording time `opts.t_offset`.
    t0: Option<f64>,
    cmd: CmdState,
    /// Whether attitude/rate-error rules apply (after a settle or at an acquisition; not
    /// while the table travels to a new command).
    armed: bool,
    live: Live,
    monitor: Monitor,
    imu_buf: Vec<ImuSample>,
    table_buf: Vec<TableSample>,
    last_imu_t: f64,
    /// Time of the latest IMU sample the recording can hold (finite outputs).
    last_finite_imu_t: f64,
    last_table_t: f64,
    last_table: Option<TableSample>,
    step: Option<usize>,
    pending_mount: Option<Mount>,
    segments: usize,
    steps_completed: usize,
    imu_samples: u64,
    table_samples: u64,
    warnings: Vec<String>,
    fires: Vec<Fire>,
    last_progress: f64,
    last_flush: std::time::Instant,
    /// Run-clock time of the last look at the wall clock for a flush.
    flush_look: f64,
    stall_s: f64,
    imu_hz: f64,
    table_hz: f64,
    /// Both drivers simulated: data is never late.
    simulated: bool,
    timeouts_since: Option<f64>,
    warned_nonfinite: bool,
    /// The operator's last request (a manual station).
    manual: manual::Manual,
    /// Whether the plan asks an operator (`place`, `turn`): static segments then carry the
    /// attitude asked for, not the table's.
    operator: bool,
}

impl Exec<'_> {
    /// Recording-clock time now.
    fn now(&self) -> f64 {
        self.opts.t_offset + (Instant::now() - self.start).as_secs_f64()
    }

    fn step_name(&self) -> Option<String> {
        self.step.map(|i| self.plan.steps[i].name.clone())
    }

    fn journal(&mut self, event: JournalEvent) {
        let e = JournalEntry {
            t: self.now(),
            step: self.step_name(),
            event,
        };
        // A journal that cannot be written surfaces at the next stream write or checkpoint.
        let _ = self.sink.journal(&e);
    }

    fn abort(&self, rule: String, values: String) -> Stop {
        Stop::Abort(AbortRecord {
            rule,
            t: self.now(),
            step: self.step_name(),
            values,
        })
    }

    /// Waits until every segment recorded so far is persisted (the sink's checkpoints run
    /// beside the interpreter); one that could not be aborts the run.
    fn settled(&mut self) -> Res {
        self.sink
            .settle()
            .map_err(|e| self.abort("recording error".into(), e.to_string()))
    }

    async fn walk(&mut self) -> Res {
        let plan = self.plan;
        for (i, step) in plan.steps.iter().enumerate().skip(self.opts.start_step) {
            self.step = Some(i);
            self.progress.step(i, &step.name);
            self.journal(JournalEvent::StepStart { index: i });
            self.monitor.enter_step(&step.aborts);
            if i > 0 && i == self.opts.start_step {
                self.resume_pose(&step.body).await?;
            }
            let mut vars = Vec::new();
            self.nodes(&step.body, &mut vars).await?;
            self.monitor.leave_step();
            // A resume trusts `step_end`: its segments are on the disk before it is written.
            self.settled()?;
            self.journal(JournalEvent::StepEnd {
                index: i,
                segments: self.total_segments(),
            });
            self.steps_completed = i + 1;
        }
        self.step = None;
        Ok(())
    }

    fn total_segments(&self) -> usize {
        self.opts.resume_segments + self.segments
    }

    async fn nodes(&mut self, nodes: &[Node], vars: &mut Vec<(String, u64)>) -> Res {
        for n in nodes {
            match n {
                Node::Do(a) => self.action(a, vars).await?,
                Node::Repeat { count, var, body } => {
                    for k in 1..=*count {
                        vars.push((var.clone().unwrap_or_default(), k));
                        let r = Box::pin(self.nodes(body, vars)).await;
                        vars.pop();
                        r?;
                    }
                }
            }
        }
        Ok(())
    }

    async fn action(&mut self, a: &Action, vars: &[(String, u64)]) -> Res {
        match a {
            Action::MoveTo {
                outer_deg,
                inner_deg,
            } => {
                self.command(TableCommand::MoveTo {
                    outer_deg: *outer_deg,
                    inner_deg: *inner_deg,
                })
                .await?;
                self.cmd.outer = AxisCmd::Hold(Some(*outer_deg));
                self.cmd.inner = AxisCmd::Hold(Some(*inner_deg));
            }
            Action::Spin { axis, rate_dps } => {
                self.command(TableCommand::Rate {
                    axis: axis_id(*axis),
                    rate_dps: *rate_dps,
                })
                .await?;
                self.cmd.set(*axis, AxisCmd::Rate(*rate_dps));
            }
            Action::Stop { axis } => {
                let axes = axis.map_or(vec![Axis::Outer, Axis::Inner], |a| vec![a]);
                for a in axes {
                    self.command(TableCommand::Stop { axis: axis_id(a) })
                        .await?;
                    self.cmd.set(a, AxisCmd::Hold(None));
                }
            }
            Action::Oscillate {
                axis,
                amplitude_deg,
                period_s,
                center_deg,
                duration_s,
            } => {
                let center = center_deg.unwrap_or_else(|| self.current_angle(*axis));
                let c = TableCommand::Oscillate {
                    axis: axis_id(*axis),
                    center_deg: center,
                    amplitude_deg: *amplitude_deg,
                    period_s: *period_s,
                };
                self.command(c).await?;
                self.cmd.set(
                    *axis,
                    AxisCmd::Osc {
                        center,
                        amplitude: *amplitude_deg,
                        period: *period_s,
                    },
                );
                self.wait(*duration_s).await?;
            }
            Action::Hold { duration_s } => {
                self.journal(JournalEvent::Hold {
                    duration_s: *duration_s,
                });
                self.wait(*duration_s).await?;
            }
            Action::Settle(s) => self.settle(s).await?,
            Action::Acquire(acq) => self.acquire(acq, vars).await?,
            Action::Place(p) => self.place(p).await?,
            Action::Turn(t) => self.turn(t, vars).await?,
            Action::Remount { rotation, message } => {
                if !self.progress.confirm(message) {
                    return Err(self.abort("operator declined the remount".into(), message.clone()));
                }
                if let Err(e) = self.imu.remount(*rotation).await {
                    return Err(self.driver_abort("imu", &e));
                }
                self.journal(JournalEvent::Remount {
                    rotation: *rotation,
                    message: message.clone(),
                });
                self.pending_mount = Some(Mount {
                    rotation: *rotation,
                });
            }
        }
        Ok(())
    }

    /// The commanded angle of an axis, or its latest feedback angle.
    fn current_angle(&self, a: Axis) -> f64 {
        match self.cmd.axis(a) {
            AxisCmd::Hold(Some(t)) => t,
            AxisCmd::Osc { center, .. } => center,
            _ => self.last_table.map_or(0.0, |s| match a {
                Axis::Outer => s.outer_deg,
                Axis::Inner => s.inner_deg,
            }),
        }
    }

    async fn command(&mut self, c: TableCommand) -> Res {
        self.journal(JournalEvent::Command {
            command: format!("{c:?}"),
        });
        self.armed = false;
        match self.table.command(c).await {
            Ok(()) => Ok(()),
            Err(e) => Err(self.driver_abort("table", &e)),
        }
    }

    fn driver_abort(&self, which: &str, e: &DriverError) -> Stop {
        self.abort(
            format!("{which} driver error ({:?})", e.kind()),
            e.message.clone(),
        )
    }

    /// Waits `duration_s` of run time, recording and monitoring.
    async fn wait(&mut self, duration_s: f64) -> Res {
        let end = Instant::now() + Duration::from_secs_f64(duration_s.max(0.0));
        while Instant::now() < end {
            self.tick(Some(end)).await?;
        }
        Ok(())
    }

    async fn settle(&mut self, s: &Settle) -> Res {
        if !self.awaiting_operator() {
            return self.settle_plain(s).await;
        }
        loop {
            let since = self.now();
            if self.manual.need_motion {
                self.await_motion(s, since).await?;
            }
            self.settle_plain(s).await?;
            let now = self.now();
            if self.at_rest(s, now).await? {
                return Ok(());
            }
        }
    }

    async fn settle_plain(&mut self, s: &Settle) -> Res {
        let since = self.now();
        loop {
            let now = self.now();
            let waited = now - since;
            if waited + 1e-9 >= s.min_time_s {
                match self.settle_unmet(s, since, now) {
                    None => {
                        self.journal(JournalEvent::Settled { after_s: waited });
                        self.armed = true;
                        return Ok(());
                    }
                    Some(unmet) => {
                        if s.timeout_s.is_some_and(|to| waited + 1e-9 >= to) {
                            return self.settle_timeout(s, waited, unmet);
                        }
                    }
                }
            } else if s.timeout_s.is_some_and(|to| waited + 1e-9 >= to) {
                return self.settle_timeout(
                    s,
                    waited,
                    "minimum time longer than the timeout".into(),
                );
            }
            self.tick(None).await?;
        }
    }

    fn settle_timeout(&mut self, s: &Settle, waited: f64, unmet: String) -> Res {
        let action = match s.on_timeout {
            OnTimeout::Abort => "abort",
            OnTimeout::Warn => "warn",
            OnTimeout::Continue => "continue",
        };
        self.journal(JournalEvent::SettleTimeout {
            after_s: waited,
            action: action.into(),
            unmet: unmet.clone(),
        });
        let rule = format!(
            "settle timeout after {waited:.1} s in step {}",
            self.step_name().unwrap_or_default()
        );
        match s.on_timeout {
            OnTimeout::Abort => return Err(self.abort(rule, unmet)),
            OnTimeout::Warn => {
                self.progress.message(&format!("warning: {rule}: {unmet}"));
                self.warnings.push(format!("{rule}: {unmet}"));
            }
            OnTimeout::Continue => {}
        }
        self.armed = true;
        Ok(())
    }

    /// The settle conditions that do not hold now (`None`: settled).
    fn settle_unmet(&self, s: &Settle, since: f64, now: f64) -> Option<String> {
        let mut unmet = Vec::new();
        match self.live.last_table() {
            Some(r) if r.reached => {}
            Some(_) => unmet.push("table not yet on its command".to_string()),
            None => unmet.push("no table feedback".to_string()),
        }
        for st in &s.stable {
            if let Some(u) = stability_unmet(&self.live, st, since, now) {
                unmet.push(u);
            }
        }
        let window = (now - 1.0).max(since);
        for (limit, ch, what) in [
            (s.attitude_error_deg, 0, "attitude error (deg)"),
            (s.rate_error_dps, 1, "rate error (deg/s)"),
        ] {
            let Some(limit) = limit else { continue };
            match self.live.table_max(ch, window, now) {
                Some(m) if m <= limit => {}
                Some(m) => unmet.push(format!("{what} {m:.6} > {limit}")),
                None => unmet.push(format!("{what}: no table feedback")),
            }
        }
        if unmet.is_empty() {
            None
        } else {
            Some(unmet.join("; "))
        }
    }

    async fn acquire(&mut self, a: &Acquire, vars: &[(String, u64)]) -> Res {
        let id = substitute(&a.segment, vars);
        self.journal(JournalEvent::AcquireStart {
            segment: id.clone(),
        });
        if self.imu_hz + 1e-9 < a.rate_hz {
            let w = format!(
                "segment {id}: the IMU samples at {} Hz, the procedure asks {} Hz",
                self.imu_hz, a.rate_hz
            );
            self.journal(JournalEvent::Warning {
                rule: "sample rate".into(),
                values: w.clone(),
            });
            self.warnings.push(w);
        }
        self.armed = true;
        let t_start = self.now();
        self.wait(a.duration_s).await?;
        let t_end = self.now();
        if !self.simulated {
            self.await_data(t_end, &id).await?;
        }
        let mut seg = self
            .cmd
            .segment(id.clone(), t_start, t_end, self.last_table.as_ref());
        seg.mount = self.pending_mount.take();
        self.manual_segment(&mut seg);
        if let Err(e) = self.sink.segment(seg) {
            return Err(self.abort("recording error".into(), e.to_string()));
        }
        self.segments += 1;
        self.journal(JournalEvent::AcquireEnd {
            segment: id,
            t_start,
            t_end,
        });
        Ok(())
    }

    /// Waits until both streams have delivered the data of a segment ending at `t_end`
    /// (hardware delivers it late by its link delay; the recording must cover every segment
    /// it lists, to half a sample). Gives up, aborting, after the stall time.
    async fn await_data(&mut self, t_end: f64, id: &str) -> Res {
        let need_imu = t_end - 0.4 / self.imu_hz.max(1e-3);
        let need_table = t_end - 0.4 / self.table_hz.max(1e-3);
        let give_up = self.now() + self.stall_s;
        while self.last_finite_imu_t < need_imu || self.last_table_t < need_table {
            if self.now() >= give_up {
                return Err(self.abort(
                    format!("the data of segment {id} did not arrive"),
                    format!(
                        "IMU up to t = {:.3} s, table up to t = {:.3} s, segment ends at {t_end:.3} s",
                        self.last_finite_imu_t, self.last_table_t
                    ),
                ));
            }
            self.tick(None).await?;
        }
        Ok(())
    }

    /// One control-loop period: sleep to the next tick (or `until`), drain, monitor.
    async fn tick(&mut self, until: Option<Instant>) -> Res {
        self.sleep(until).await;
        self.drain().await?;
        self.check()
    }

    async fn sleep(&mut self, until: Option<Instant>) {
        let deadline = until.map_or(self.next_tick, |u| u.min(self.next_tick));
        sleep_until(deadline).await;
        let now = Instant::now();
        while self.next_tick <= now {
            self.next_tick += self.opts.tick;
        }
    }

    /// Reads both drivers, shifts times onto the recording clock, records, and feeds the
    /// live window and the abort monitor.
    async fn drain(&mut self) -> Res {
        self.imu_buf.clear();
        self.table_buf.clear();
        let imu_r = self.imu.read(&mut self.imu_buf).await;
        let table_r = self.table.read(&mut self.table_buf).await;
        for (which, r) in [("imu", imu_r), ("table", table_r)] {
            match r {
                Ok(()) => {}
                // A late answer is tolerated; a stream that stays silent trips the stall check.
                Err(e) if e.kind() == DriverErrorKind::Timeout => {
                    self.timeouts_since.get_or_insert(self.now());
                }
                Err(e) => return Err(self.driver_abort(which, &e)),
            }
        }
        if self.imu_buf.is_empty() && self.table_buf.is_empty() {
            return Ok(());
        }
        self.timeouts_since = None;
        let t0 = match self.t0 {
            Some(t0) => t0,
            None => {
                let elapsed = self.now() - self.opts.t_offset;
                let firsts = self
                    .imu_buf
                    .first()
                    .map(|s| s.t)
                    .into_iter()
                    .chain(self.table_buf.first().map(|s| s.t));
                let newest = self
                    .imu_buf
                    .last()
                    .map(|s| s.t)
                    .into_iter()
                    .chain(self.table_buf.last().map(|s| s.t))
                    .fold(f64::NEG_INFINITY, f64::max);
                let t0 = firsts.fold(newest - elapsed, f64::min);
                self.t0 = Some(t0);
                t0
            }
        };
        let shift = self.opts.t_offset - t0;
        let mut last = self.last_imu_t;
        let first_imu = self.imu_samples == 0;
        self.imu_buf.retain_mut(|s| {
            s.t += shift;
            // The host arrival time is on the clock of `t`: it moves with it.
            s.t_host = s.t_host.map(|h| h + shift);
            let keep = (first_imu && s.t >= last) || s.t > last;
            if keep {
                last = s.t;
            }
            keep
        });
        let mut last = self.last_table_t;
        let first_table = self.table_samples == 0;
        self.table_buf.retain_mut(|s| {
            s.t += shift;
            // The host arrival time is on the clock of `t`: it moves with it.
            s.t_host = s.t_host.map(|h| h + shift);
            let keep = (first_table && s.t >= last) || s.t > last;
            if keep {
                last = s.t;
            }
            keep
        });
        if let Err(e) = self
            .sink
            .imu(&self.imu_buf)
            .and_then(|()| self.sink.table(&self.table_buf))
        {
            return Err(self.abort("recording error".into(), e.to_string()));
        }
        let nonfinite = self
            .imu_buf
            .iter()
            .filter(|s| !s.accel.iter().chain(&s.gyro).all(|v| v.is_finite()))
            .count();
        if nonfinite > 0 && !self.warned_nonfinite {
            self.warned_nonfinite = true;
            let values =
                "the IMU delivers non-finite outputs; those samples are not recorded".to_string();
            self.journal(JournalEvent::Warning {
                rule: "imu output".into(),
                values,
            });
        }
        for s in &self.imu_buf {
            let row = ImuRow {
                t: s.t,
                v: [
                    s.accel[0],
                    s.accel[1],
                    s.accel[2],
                    s.gyro[0],
                    s.gyro[1],
                    s.gyro[2],
                    s.temp_c.unwrap_or(f64::NAN),
                ],
            };
            self.live.push_imu(row);
            self.monitor.on_imu(&row, &mut self.fires);
        }
        for s in &self.table_buf {
            let (att, rate) = self.cmd.errors(s);
            let row = TableRow {
                t: s.t,
                v: [att, rate, s.ambient_c.unwrap_or(f64::NAN), f64::NAN],
                reached: self.cmd.reached(s),
            };
            let row = self.live.push_table(row);
            self.monitor.on_table(&row, self.armed, &mut self.fires);
        }
        if let Some(s) = self.imu_buf.last() {
            self.last_imu_t = s.t;
        }
        if let Some(s) = self.imu_buf.iter().rev().find(|s| {
            s.accel.iter().chain(&s.gyro).all(|v| v.is_finite())
                && s.temp_c.is_none_or(f64::is_finite)
        }) {
            self.last_finite_imu_t = s.t;
        }
        if let Some(s) = self.table_buf.last() {
            self.last_table_t = s.t;
            self.last_table = Some(*s);
        }
        self.imu_samples += self.imu_buf.len() as u64;
        self.table_samples += self.table_buf.len() as u64;
        Ok(())
    }

    /// Rules that fired, stalls, cancellation, progress.
    fn check(&mut self) -> Res {
        let now = self.now();
        self.live.trim(now);
        for f in std::mem::take(&mut self.fires) {
            match f.action {
                AbortAction::Abort => {
                    let step = self.step_name();
                    return Err(Stop::Abort(AbortRecord {
                        rule: f.rule,
                        t: f.t,
                        step,
                        values: f.values,
                    }));
                }
                AbortAction::Warn => {
                    self.journal(JournalEvent::Warning {
                        rule: f.rule.clone(),
                        values: f.values.clone(),
                    });
                    self.progress
                        .message(&format!("warning: {} ({})", f.rule, f.values));
                    self.warnings.push(format!("{}: {}", f.rule, f.values));
                }
            }
        }
        if self
            .opts
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
        {
            return Err(self.abort("interrupted by the operator (Ctrl-C)".into(), String::new()));
        }
        for (which, last) in [("imu", self.last_imu_t), ("table", self.last_table_t)] {
            if now - last > self.stall_s {
                let what = if which == "imu" {
                    "IMU dropout"
                } else {
                    "table feedback lost"
                };
                return Err(self.abort(
                    what.into(),
                    format!(
                        "no {which} sample since t = {last:.3} s ({:.3} s)",
                        now - last
                    ),
                ));
            }
        }
        if now - self.last_progress >= 0.5 {
            self.last_progress = now;
            self.progress.time(now);
        }
        // Wall-clock time: a simulated run on the paused clock flushes as rarely as a real
        // one, not every half second of simulated time.
        if now - self.flush_look < FLUSH_LOOK_S {
            return Ok(());
        }
        self.flush_look = now;
        if self.last_flush.elapsed().as_secs_f64() >= FLUSH_EVERY_S {
            self.last_flush = std::time::Instant::now();
            if let Err(e) = self.sink.flush() {
                return Err(self.abort("recording error".into(), e.to_string()));
            }
        }
        Ok(())
    }

    /// Drives the table to its safe state and keeps recording until it is at rest (both
    /// rates below 0.05 deg/s for 0.5 s) or the safe-stop time runs out.
    async fn safe_stop(&mut self) {
        self.journal(JournalEvent::Command {
            command: format!("{:?}", TableCommand::SafeStop),
        });
        if let Err(e) = self.table.command(TableCommand::SafeStop).await {
            self.journal(JournalEvent::Warning {
                rule: "safe stop refused".into(),
                values: e.message.clone(),
            });
            self.warnings
                .push(format!("safe stop refused: {}", e.message));
        }
        self.cmd = CmdState::default();
        let started = self.now();
        let give_up = started + self.opts.safe_stop_timeout_s;
        let mut rest_since: Option<f64> = None;
        let mut errors = 0;
        let at_rest = loop {
            self.sleep(None).await;
            if self.drain().await.is_err() {
                errors += 1;
                if errors > 10 {
                    break false;
                }
            }
            self.fires.clear();
            let now = self.now();
            let still = self
                .last_table
                .is_some_and(|s| s.outer_rate_dps.abs() < 0.05 && s.inner_rate_dps.abs() < 0.05);
            if still && now - self.last_table_t < self.stall_s {
                let since = *rest_since.get_or_insert(now);
                if now - since >= 0.5 {
                    break true;
                }
            } else {
                rest_since = None;
            }
            // A table whose feedback stays lost cannot be seen to stop: the command was
            // sent (or could not be); waiting out the whole safe-stop time helps nobody.
            if now >= give_up
                || (now - started > 2.0 * self.stall_s && now - self.last_table_t > self.stall_s)
            {
                break false;
            }
        };
        self.journal(JournalEvent::SafeState { at_rest });
        if !at_rest {
            // Counted like every warning (the summary's count is the journal's), and the
            // console prints it last.
            self.journal(JournalEvent::Warning {
                rule: "not at rest".into(),
                values: super::NOT_AT_REST.into(),
            });
            self.warnings
                .push(format!("not at rest: {}", super::NOT_AT_REST));
        }
    }
}
