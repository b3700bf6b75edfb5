//! The analysis read span by span (`fit::Streamed`, what `ratecal analyze` uses) against
//! the same recording held in memory, and segments cut into windows against one window:
//! how the samples are held must not change what is found.

use crate::fit_support;
use fit_support::{SimSpec, standard_windows, write};
use ratecal_analysis::fit;
use ratecal_analysis::results::Results;
use ratecal_plan::Outliers;
use ratecal_recording as recording;

fn sim(spec: &SimSpec) -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), spec, &standard_windows(spec.block_s));
    tmp
}

/// Every estimate of `a` and `b` differs by at most `tol` times its uncertainty.
fn agree(a: &Results, b: &Results, tol: f64) -> f64 {
    let mut worst = 0.0f64;
    for name in a.parameters.keys() {
        match (a.value(name), b.value(name)) {
            (Some((va, ua)), Some((vb, _))) => {
                let z = (va - vb).abs() / ua;
                assert!(z <= tol, "{name}: {va} vs {vb} (u {ua}, {z:.3e} u apart)");
                worst = worst.max(z);
            }
            (None, None) => {}
            (x, y) => panic!("{name}: {x:?} vs {y:?}"),
        }
    }
    worst
}

#[test]
fn read_span_by_span_gives_the_results_of_a_whole_read() {
    let mut spec = SimSpec::tactical(21);
    spec.temp = Some((22.0, 3.0));
    let tmp = sim(&spec);
    let opts = fit::Options {
        with: vec!["lever_arm".into(), "gyro_thermal_drift".into()],
        ..Default::default()
    };
    let rec = recording::read(tmp.path()).unwrap();
    let whole = fit::analyze_with(&rec, None, &opts);
    let streamed = fit::Streamed::open(tmp.path()).unwrap();
    let spans = fit::analyze_source(&streamed, None, &opts).unwrap();
    // The same rows in the same windows in the same order: the same numbers, but for the
    // last bits of the thermal reference (the recording's mean temperature, summed in
    // another order).
    agree(&whole, &spans, 1e-9);
    assert_eq!(whole.segments, spans.segments);
    assert_eq!(whole.recording, spans.recording);
    assert_eq!(whole.warnings, spans.warnings);
    assert!(whole.parameters.contains_key("lever_arm.rxx_mm"));
    assert_eq!(whole.recording.imu_rows, rec.imu.t.len());
}

/// Without an outlier test, windows change nothing but where the samples are cut: the
/// low-pass, read with margins, filters each window as it filters the whole segment (to
/// rounding: each window's sampling rate comes from its own stamps; a sample lost or
/// counted twice at a window's edge would move the gyro bias by about 2e-3 u).
#[test]
fn windows_with_margins_filter_as_one_window_does() {
    let tmp = sim(&SimSpec::tactical(22));
    let rec = recording::read(tmp.path()).unwrap();
    let opts = |rows: usize| fit::Options {
        outliers: None,
        lowpass: Some((4, 5.0)),
        window_rows: rows,
        ..Default::default()
    };
    let one = fit::analyze_with(&rec, None, &opts(fit::Options::default().window_rows));
    // 12,000 rows of gyro block in 2,000-row windows; the 1,000-row rate segments in 250.
    let many = fit::analyze_with(&rec, None, &opts(2_000));
    let worst = agree(&one, &many, 1e-8);
    eprintln!("worst difference {worst:.2e} u");
    let (a, b) = (one.allan.unwrap(), many.allan.unwrap());
    let pairs = a.adev_dps.iter().flatten().zip(b.adev_dps.iter().flatten());
    for (x, y) in a.tau_s.iter().zip(&b.tau_s).chain(pairs) {
        assert!((x - y).abs() <= 1e-9 * x, "{x} vs {y}");
    }
}

/// With the 3-sigma test, each window is judged on its own statistics: a few samples at
/// the edge of the threshold change sides, and the estimates stay well inside their
/// uncertainty of each other.
#[test]
fn outliers_judged_per_window_move_estimates_by_a_fraction_of_u() {
    let tmp = sim(&SimSpec::tactical(23));
    let rec = recording::read(tmp.path()).unwrap();
    let opts = |rows: usize| fit::Options {
        outliers: Some(Outliers::Sigma(3.0)),
        window_rows: rows,
        ..Default::default()
    };
    let one = fit::analyze_with(&rec, None, &opts(fit::Options::default().window_rows));
    let many = fit::analyze_with(&rec, None, &opts(2_000));
    let worst = agree(&one, &many, 0.5);
    eprintln!("worst difference {worst:.2e} u");
    let removed = |r: &Results| r.segments.iter().map(|s| s.outliers_removed).sum::<usize>();
    let (a, b) = (removed(&one), removed(&many));
    assert!(a > 0 && b > 0, "{a} {b}");
    assert!(a.abs_diff(b) * 10 < a.max(b), "{a} vs {b} samples removed");
}

/// `Source::windows` hands every row once, in order, however small the windows; the
/// report's temperature series read span by span keeps the rows a whole read keeps.
#[test]
fn windows_hand_every_row_once_and_the_temperature_plot_is_the_same() {
    use fit::Source;
    let mut spec = SimSpec::tactical(24);
    spec.temp = Some((22.0, 3.0));
    let tmp = sim(&spec);
    let rec = recording::read(tmp.path()).unwrap();
    let streamed = fit::Streamed::open(tmp.path()).unwrap();
    for rows in [1_000, 7_777, 1 << 20] {
        let mut seen: Vec<(f64, f64)> = Vec::new();
        streamed
            .windows(rows, |v| {
                seen.extend(v.t.iter().zip(v.gyro[2]).map(|(t, g)| (*t, *g)));
            })
            .unwrap();
        let want: Vec<(f64, f64)> = rec
            .imu
            .t
            .iter()
            .copied()
            .zip(rec.imu.gyro[2].iter().copied())
            .collect();
        assert_eq!(seen, want, "windows of {rows} rows");
    }
    let whole = ratecal_render::TemperatureSeries::from_recording(&rec);
    let spans = ratecal_render::TemperatureSeries::from_source(&streamed).unwrap();
    assert_eq!(whole, spans);
    assert!(
        whole.imu.len() > 1_000 && whole.imu.len() <= 2_000,
        "{}",
        whole.imu.len()
    );
}

/// A long segment's windows passed side by side (the default) and one after another: the
/// same rows in the same windows, judged by the same outlier test and low-passed with the
/// same margins, so the same numbers but for the order of a few sums (the factors of the
/// windows stacked, a block cut by a window's edge joined again). The Allan curve is taken
/// from the same samples in the same order: equal to the last bit.
#[test]
fn windows_side_by_side_give_the_numbers_of_one_pass() {
    let mut spec = SimSpec::tactical(24);
    spec.temp = Some((22.0, 3.0));
    let tmp = sim(&spec);
    let streamed = fit::Streamed::open(tmp.path()).unwrap();
    let opts = |parallel_windows: bool| fit::Options {
        outliers: Some(Outliers::Sigma(3.0)),
        lowpass: Some((4, 5.0)),
        with: vec!["gyro_thermal_drift".into()],
        // 12,000 rows of gyro block in 1,500-row windows, whose edges fall inside seconds.
        window_rows: 1_500,
        parallel_windows,
        ..Default::default()
    };
    let one = fit::analyze_source(&streamed, None, &opts(false)).unwrap();
    let side = fit::analyze_source(&streamed, None, &opts(true)).unwrap();
    let worst = agree(&one, &side, 1e-9);
    eprintln!("worst difference {worst:.2e} u");
    // The uncertainties too: the noise analysis reads the one-second blocks.
    for name in one.parameters.keys() {
        if let (Some((_, ua)), Some((_, ub))) = (one.value(name), side.value(name)) {
            assert!((ua - ub).abs() <= 1e-9 * ua, "{name}: u {ua} vs {ub}");
        }
    }
    assert_eq!(one.segments, side.segments);
    assert_eq!(one.warnings, side.warnings);
    assert_eq!(one.sync, side.sync);
    let (a, b) = (one.allan.unwrap(), side.allan.unwrap());
    assert_eq!(a.tau_s, b.tau_s);
    assert_eq!(a.adev_dps, b.adev_dps);
    // Every number of the residuals, relative to the channel's spread.
    assert_eq!(one.residuals.len(), side.residuals.len());
    for (x, y) in one.residuals.iter().zip(&side.residuals) {
        assert_eq!((&x.segment, &x.channel, x.n), (&y.segment, &y.channel, y.n));
        assert!((x.mean - y.mean).abs() <= 1e-9 * x.std, "{x:?} vs {y:?}");
        assert!((x.std - y.std).abs() <= 1e-9 * x.std, "{x:?} vs {y:?}");
    }
}

/// The Allan series written to a scratch file as its windows pass (side by side, so out of
/// order) and read back gives the results of the series held in memory, to the byte; so
/// does a scratch file that cannot be opened (the series stays in memory).
#[test]
fn an_allan_series_spilled_to_a_scratch_file_gives_the_results_held_in_memory() {
    let tmp = sim(&SimSpec::tactical(24));
    let streamed = fit::Streamed::open(tmp.path()).unwrap();
    let opts = |scratch: Option<fit::Scratch>| fit::Options {
        // 12,000 rows of gyro block in 1,500-row windows.
        window_rows: 1_500,
        scratch,
        ..Default::default()
    };
    let json = |o: &fit::Options| {
        let r = fit::analyze_source(&streamed, None, o).unwrap();
        assert!(r.allan.as_ref().is_some_and(|a| a.tau_s.len() > 5));
        serde_json::to_string(&r).unwrap()
    };
    let held = json(&opts(None));
    let spilled = json(&opts(Some(fit::Scratch::new(tempfile::tempfile))));
    assert_eq!(held, spilled);
    let refused = fit::Scratch::new(|| Err(std::io::Error::other("no scratch space")));
    assert_eq!(held, json(&opts(Some(refused))));
}
