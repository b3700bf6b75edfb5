//! Chart axes: the range of the data (linear or log), round tick values and their labels.

/// A drawn axis: its range (in decades when logarithmic).
pub(super) struct Axis {
    /// Lower end (log10 of it on a log axis).
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Logarithmic.
    pub log: bool,
}

impl Axis {
    /// Where `v` falls, 0 at `lo` to 1 at `hi`.
    pub fn t(&self, v: f64) -> f64 {
        if self.log {
            (v.log10() - self.lo) / (self.hi - self.lo)
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }

    /// Round tick values inside the range.
    pub fn ticks(&self) -> Vec<f64> {
        if self.log {
            (self.lo.ceil() as i32..=self.hi.floor() as i32)
                .map(|e| 10f64.powi(e))
                .collect()
        } else {
            let step = nice_step((self.hi - self.lo) / 5.0);
            let first = (self.lo / step).ceil() as i64;
            let last = (self.hi / step).floor() as i64;
            (first..=last).map(|k| k as f64 * step).collect()
        }
    }
}

/// The round step (1, 2 or 5 times a power of ten) nearest to `raw` on a log scale.
fn nice_step(raw: f64) -> f64 {
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    let nice = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .min_by(|a: &f64, b: &f64| (a / f).ln().abs().total_cmp(&(b / f).ln().abs()))
        .unwrap_or(1.0);
    nice * mag
}

pub(super) fn axis(values: impl Iterator<Item = f64>, log: bool) -> Option<Axis> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        let v = if log { v.log10() } else { v };
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return None;
    }
    if log {
        // A decade computed as -1.9999999 must not add an empty decade below.
        let (lo, hi) = ((lo + 1e-9).floor(), (hi - 1e-9).ceil());
        return Some(Axis {
            lo,
            hi: hi.max(lo + 1.0),
            log,
        });
    }
    if hi - lo < 1e-12 * lo.abs().max(1e-300) || hi == lo {
        let pad = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        return Some(Axis {
            lo: lo - pad,
            hi: hi + pad,
            log,
        });
    }
    let pad = (hi - lo) * 0.06;
    Some(Axis {
        lo: lo - pad,
        hi: hi + pad,
        log,
    })
}

pub(super) fn tick_label(v: f64, log: bool) -> String {
    if log {
        let e = v.log10().round() as i32;
        return match e {
            0 => "1".into(),
            1 => "10".into(),
            _ => format!("1e{e}"),
        };
    }
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.1e}");
    }
    // Enough decimals to tell ticks apart, no trailing noise.
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axis_ticks_are_decades() {
        let a = axis([0.02, 300.0].into_iter(), true).unwrap();
        assert_eq!(a.ticks(), vec![0.01, 0.1, 1.0, 10.0, 100.0, 1000.0]);
    }

    #[test]
    fn linear_ticks_are_round_numbers() {
        let a = Axis {
            lo: -0.013,
            hi: 0.052,
            log: false,
        };
        let t = a.ticks();
        assert_eq!(t.len(), 7);
        assert!((t[0] + 0.01).abs() < 1e-12 && (t[6] - 0.05).abs() < 1e-12);
    }
}
