//! Dates as the manifest writes them (RFC 3339, UTC) to days since 1970, and back.

/// Days since 1970-01-01T00:00Z of `YYYY-MM-DD[THH:MM[:SS[.fff]]][Z|±HH:MM]`.
pub fn days_from_iso(s: &str) -> Option<f64> {
    let s = s.trim();
    let (date, time) = match s.split_once(['T', ' ']) {
        Some((d, t)) => (d, Some(t)),
        None => (s, None),
    };
    let mut it = date.split('-');
    let y: i64 = it.next()?.parse().ok()?;
    let m: i64 = it.next()?.parse().ok()?;
    let d: i64 = it.next()?.parse().ok()?;
    if it.next().is_some() || !(1..=12).contains(&m) || !(1..=31).contains(&d) {
        return None;
    }
    let mut days = days_from_civil(y, m, d) as f64;
    if let Some(t) = time {
        let (clock, offset_min) = split_offset(t)?;
        let mut parts = clock.split(':');
        let h: f64 = parts.next()?.parse().ok()?;
        let mi: f64 = parts.next().unwrap_or("0").parse().ok()?;
        let sec: f64 = parts.next().unwrap_or("0").parse().ok()?;
        if !(0.0..24.0).contains(&h) || !(0.0..60.0).contains(&mi) || !(0.0..61.0).contains(&sec) {
            return None;
        }
        days += (h * 3600.0 + mi * 60.0 + sec - offset_min * 60.0) / 86400.0;
    }
    Some(days)
}

/// `YYYY-MM-DD` of a day count.
pub fn iso_date(days: f64) -> String {
    let (y, m, d) = ratecal_recording::civil_from_days(days.floor() as i64);
    format!("{y:04}-{m:02}-{d:02}")
}

/// Now, RFC 3339 UTC.
pub fn now_rfc3339() -> String {
    ratecal_recording::rfc3339(std::time::SystemTime::now())
}

fn split_offset(t: &str) -> Option<(&str, f64)> {
    if let Some(c) = t.strip_suffix(['Z', 'z']) {
        return Some((c, 0.0));
    }
    if let Some(i) = t.rfind(['+', '-']) {
        let (c, off) = t.split_at(i);
        let sign = if off.starts_with('-') { -1.0 } else { 1.0 };
        let (h, m) = off[1..].split_once(':').unwrap_or((&off[1..], "0"));
        let h: f64 = h.parse().ok()?;
        let m: f64 = m.parse().ok()?;
        return Some((c, sign * (h * 60.0 + m)));
    }
    Some((t, 0.0))
}

// Howard Hinnant's algorithm: the inverse of `recording::civil_from_days`.
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146097 + doe - 719468
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_offsets() {
        assert_eq!(days_from_iso("1970-01-01"), Some(0.0));
        assert_eq!(
            iso_date(days_from_iso("2026-11-24T02:21:05Z").unwrap()),
            "2026-11-24"
        );
        let a = days_from_iso("2026-03-01T12:00:00Z").unwrap();
        let b = days_from_iso("2026-03-01T14:00:00+02:00").unwrap();
        assert!((a - b).abs() < 1e-9);
        assert_eq!(days_from_iso("2026-13-01"), None);
        assert_eq!(days_from_iso("yesterday"), None);
    }
}
