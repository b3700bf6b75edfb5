//! The host arrival times (`t_host`) a run over hardware links writes per sample, checked
//! for what they must be physically (non-decreasing; never before the stamp by more than
//! the clock map's anchor error; within a second of it on loopback) and against the
//! manifest's synchronisation figures (`run.sync`), which the driver keeps per batch from
//! the same arrivals.

use ratecal_recording::{LinkRecord, parse_manifest};

/// Rows that arrived within this of the previous one came in the same read, s.
const SAME_READ_S: f64 = 0.5e-3;

/// `(t, t_host)` of every row of one stream.
fn times(name: &str, csv: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or(format!("{name} is empty"))?
        .split(',')
        .collect();
    let col = |c: &str| {
        header
            .iter()
            .position(|h| *h == c)
            .ok_or(format!("{name} has no `{c}` column: {header:?}"))
    };
    let (it, ih) = (col("t")?, col("t_host")?);
    lines
        .filter(|l| !l.is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let num = |i: usize| {
                f.get(i)
                    .and_then(|v| v.parse::<f64>().ok())
                    .ok_or(format!("{name}: unreadable row `{l}`"))
            };
            Ok((num(it)?, num(ih)?))
        })
        .collect()
}

/// What is wrong with one stream's host times, given its link's manifest record.
fn check_stream(scenario: &str, name: &str, csv: &str, link: &LinkRecord) -> Vec<String> {
    let rows = match times(name, csv) {
        Ok(r) => r,
        Err(e) => return vec![e],
    };
    let mut wrong = Vec::new();
    if rows.len() < 100 {
        wrong.push(format!("{name}: only {} rows", rows.len()));
        return wrong;
    }
    if let Some(w) = rows.windows(2).find(|w| w[1].1 < w[0].1) {
        wrong.push(format!("{name}: t_host goes back: {w:?}"));
    }
    // Arrival delay per sample. The map anchors the device clock on the first batch, so a
    // delay may be negative by as much as that batch was late: the least delay, which the
    // manifest reports.
    let delays: Vec<f64> = rows.iter().map(|(t, h)| h - t).collect();
    let tolerance = (-link.latency_min_ms * 1e-3).max(0.0) + 1e-3;
    let least = delays.iter().copied().fold(f64::INFINITY, f64::min);
    let most = delays.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if least < -tolerance || most > 1.0 {
        wrong.push(format!(
            "{name}: arrival delays from {:.2} to {:.2} ms (allowed -{:.2} ms to 1 s)",
            least * 1e3,
            most * 1e3,
            tolerance * 1e3
        ));
    }
    // The driver's figures are per read, from its newest sample: the last row of each run
    // of rows that arrived together.
    let newest: Vec<f64> = (0..rows.len())
        .filter(|&i| {
            rows.get(i + 1)
                .is_none_or(|n| n.1 - rows[i].1 > SAME_READ_S)
        })
        .map(|i| delays[i] * 1e3)
        .collect();
    let mean = newest.iter().sum::<f64>() / newest.len() as f64;
    let mut sorted = newest.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let figures = format!(
        "{name}: {} reads, delay min {:.2} / median {median:.2} / mean {mean:.2} ms; manifest min {:.2} / mean {:.2} / max {:.2} ms",
        newest.len(),
        least * 1e3,
        link.latency_min_ms,
        link.latency_mean_ms,
        link.latency_max_ms
    );
    eprintln!("{scenario}: {figures}");
    if (least * 1e3 - link.latency_min_ms).abs() > 1.0
        || (mean - link.latency_mean_ms).abs() > 2.0
        || !(link.latency_min_ms - 1.0..=link.latency_max_ms + 1.0).contains(&median)
    {
        wrong.push(format!(
            "per-sample delays disagree with the manifest: {figures}"
        ));
    }
    wrong
}

/// What is wrong with the host times of a run's `imu.csv` and `table.csv`, given its
/// `manifest.yaml` (the figures are printed, headed by `scenario`).
pub fn check(scenario: &str, manifest: &str, imu_csv: &str, table_csv: &str) -> Vec<String> {
    let sync = parse_manifest("manifest.yaml", manifest)
        .ok()
        .and_then(|m| m.run?.sync);
    let Some((imu, table)) = sync.and_then(|s| Some((s.imu?, s.table?))) else {
        return vec!["the manifest has no run.sync for both links".into()];
    };
    let mut wrong = check_stream(scenario, "imu.csv", imu_csv, &imu);
    wrong.extend(check_stream(scenario, "table.csv", table_csv, &table));
    wrong.extend(device_stamps(imu_csv, &imu));
    wrong
}

/// The device's own stamps, `t - device_offset_s`: the emulated IMU stamps its frames on
/// a clock that starts at zero with the session and ticks at its sample rate, so they are
/// whole periods from zero (to 10 us: the CSV cells' resolution), the first within seconds of the start.
fn device_stamps(imu_csv: &str, link: &LinkRecord) -> Vec<String> {
    let Some(offset) = link.device_offset_s else {
        return vec!["imu link: no device_offset_s in run.sync".into()];
    };
    let Ok(rows) = times("imu.csv", imu_csv) else {
        return Vec::new(); // reported by check_stream
    };
    let device: Vec<f64> = rows.iter().map(|(t, _)| t - offset).collect();
    let period = {
        let mut d: Vec<f64> = device.windows(2).map(|w| w[1] - w[0]).collect();
        d.sort_by(f64::total_cmp);
        d[d.len() / 2]
    };
    let mut wrong = Vec::new();
    if !(-1e-5..5.0).contains(&device[0]) {
        wrong.push(format!("imu: first device stamp {} s", device[0]));
    }
    if let Some(t) = device
        .iter()
        .find(|t| ((*t / period) - (*t / period).round()).abs() * period > 1e-5)
    {
        wrong.push(format!(
            "imu: device stamp {t} s is not a whole number of {period} s periods"
        ));
    }
    wrong
}
