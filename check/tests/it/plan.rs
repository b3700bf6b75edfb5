//! The standard procedure's plan, checked against the seed's numbers and closed forms.

use ratecal_check::{CheckOptions, NoImports, StationLimits, check_text};
use ratecal_physics::Geometry;
use ratecal_plan::{Action, Axis, FitModel, Node, Plan, VerifyPoint};

const STANDARD: &str = include_str!("../../../procedures/imu-2d-standard/1.0.0.rcal");

fn standard() -> Plan {
    check_text("standard", STANDARD, &NoImports, &CheckOptions::default())
        .expect("the standard procedure checks")
        .plan
}

fn actions(nodes: &[Node]) -> Vec<&Action> {
    nodes
        .iter()
        .flat_map(|n| match n {
            Node::Do(a) => vec![a],
            Node::Repeat { body, .. } => actions(body),
        })
        .collect()
}

#[test]
fn accel_attitudes_are_the_seeds_with_attitude_4_corrected() {
    let plan = standard();
    let step = &plan.steps[0];
    assert_eq!(step.name, "accel_static");
    let moves: Vec<(f64, f64)> = actions(&step.body)
        .into_iter()
        .filter_map(|a| match a {
            Action::MoveTo {
                outer_deg,
                inner_deg,
            } => Some((*outer_deg, *inner_deg)),
            _ => None,
        })
        .collect();
    // pitch = outer, roll = inner on the seed geometry
    assert_eq!(
        moves,
        vec![
            (0.0, 0.0),
            (0.0, 180.0),
            (90.0, 0.0),
            (-90.0, 0.0),
            (0.0, 90.0),
            (0.0, 270.0)
        ]
    );
    for a in actions(&step.body) {
        if let Action::Settle(s) = a {
            assert_eq!(s.min_time_s, 30.0);
            assert!((s.stable[0].max_fluctuation - 0.001 * 9.80665).abs() < 1e-15);
            assert!((s.attitude_error_deg.unwrap() - 5.0 / 3600.0).abs() < 1e-15);
        }
        if let Action::Acquire(acq) = a {
            assert_eq!((acq.duration_s, acq.rate_hz), (10.0, 100.0));
        }
    }
}

#[test]
fn segments_fits_and_acceptance() {
    let plan = standard();
    let segs = plan.segment_templates();
    for want in [
        "accel_static/1",
        "accel_static/6",
        "gyro_bias",
        "gyro_scale/outer/-100",
        "gyro_scale/outer/+0",
        "gyro_scale/inner/+100",
        "verify/attitude",
    ] {
        assert!(segs.contains(&want), "missing segment {want}: {segs:?}");
    }
    assert_eq!(
        segs.iter().filter(|s| s.starts_with("gyro_scale/")).count(),
        10
    );
    let models: Vec<&FitModel> = plan.fits.iter().map(|f| &f.model).collect();
    assert_eq!(
        models,
        vec![
            &FitModel::AccelBiasScale,
            &FitModel::GyroBias,
            &FitModel::GyroScale
        ]
    );
    assert_eq!(plan.fits[2].axes, vec![0, 1]);
    assert_eq!(plan.fits[2].using.as_deref(), Some("gyro_bias"));
    assert_eq!(plan.fits[0].lowpass, Some((4, 10.0)));
    let accept = |q: &str| plan.accepts.iter().find(|a| a.quantity == q).expect(q);
    assert!((accept("accel.residual.std").limit.value - 0.002 * 9.80665).abs() < 1e-15);
    assert_eq!(accept("accel.residual.std").limit.unit, "g");
    assert_eq!(accept("gyro.residual.std").limit.value, 0.1);
    assert_eq!(accept("repeatability.cv").limit.value, 0.01);
    assert_eq!(accept("repeatability.cv").over_runs, Some(3));
    assert_eq!(plan.verifications.len(), 5);
    assert_eq!(
        plan.verifications[0].point,
        VerifyPoint::Attitude {
            outer_deg: 45.0,
            inner_deg: 30.0
        }
    );
    assert_eq!(
        plan.verifications[1].point,
        VerifyPoint::Rate {
            axis: Axis::Outer,
            rate_dps: 75.0
        }
    );
    let env = plan
        .environment
        .iter()
        .find(|e| e.name == "temperature")
        .unwrap();
    assert_eq!(
        (
            env.min.as_ref().unwrap().value,
            env.max.as_ref().unwrap().value
        ),
        (18.0, 22.0)
    );
    assert_eq!(plan.aborts.len(), 3);
    assert_eq!(plan.steps[1].aborts.len(), 2);
}

/// Move time of one axis with the acceleration-limited model (v = 300 deg/s, a = 100 deg/s^2).
fn t_move(d: f64) -> f64 {
    let (v, a) = (300.0_f64, 100.0_f64);
    let d = d.abs();
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

#[test]
fn estimated_duration_is_the_sum_of_the_seeds_times_and_the_motions() {
    let plan = standard();
    // settle minima + acquisitions, from the seed's numbers
    let fixed = 6.0 * (30.0 + 10.0)
        + (30.0 + 3600.0)
        + 10.0 * (20.0 + 10.0)
        + (30.0 + 10.0)
        + 4.0 * (20.0 + 10.0);
    // moves between attitudes (the slower axis counts)
    let moves = t_move(180.0) + t_move(180.0) + t_move(180.0) + t_move(90.0) + t_move(180.0) // accel_static
        + t_move(270.0) // back to level for the bias
        + t_move(45.0).max(t_move(30.0)) + t_move(45.0).max(t_move(30.0)); // verification
    // rate ramps at 100 deg/s^2: -100, -50, 0, 50, 100, stop; then -75, 75, stop; both axes
    let ramps = 2.0 * (100.0 + 50.0 + 50.0 + 50.0 + 50.0 + 100.0) / 100.0
        + 2.0 * (75.0 + 150.0 + 75.0) / 100.0;
    let want = fixed + moves + ramps;
    assert!(
        (plan.estimated_duration_s - want).abs() < 1e-9,
        "{} vs {want}",
        plan.estimated_duration_s
    );
    // about 73 minutes: dominated by the 60 min gyro bias block
    assert!((70.0 * 60.0..80.0 * 60.0).contains(&plan.estimated_duration_s));
}

#[test]
fn the_seeds_attitude_4_is_refused_on_its_own_span() {
    let flawed = STANDARD.replace("(4, -90 deg, 0 deg)", "(4, 90 deg, 180 deg)");
    let diags =
        check_text("seed", &flawed, &NoImports, &CheckOptions::default()).expect_err("refused");
    assert_eq!(diags.len(), 1, "{diags:?}");
    let d = &diags[0];
    assert_eq!(d.code, "check::unobservable");
    assert!(d.message.contains("accelerometer X"));
    let span = d.labels[0].0;
    assert_eq!(&flawed[span.start..span.end], "(4, 90 deg, 180 deg)");
    assert!(
        d.help
            .as_deref()
            .unwrap_or("")
            .contains("pitch -90 deg, roll 0 deg")
    );
}

fn station(max_rate: f64, gyro_range: f64, max_accel: f64) -> CheckOptions {
    CheckOptions {
        station: Some(StationLimits {
            max_rate_dps: max_rate,
            max_accel_dps2: max_accel,
            gyro_range_dps: gyro_range,
            accel_range_mps2: 16.0 * 9.80665,
            geometry: Geometry::seed(),
            manual: false,
            travel_deg: [None, None],
            imu_grade: String::new(),
        }),
    }
}

#[test]
fn station_limits() {
    check_text(
        "standard",
        STANDARD,
        &NoImports,
        &station(500.0, 400.0, 1000.0),
    )
    .expect("within limits");
    let diags = check_text(
        "standard",
        STANDARD,
        &NoImports,
        &station(80.0, 400.0, 1000.0),
    )
    .expect_err("too fast");
    let over: Vec<_> = diags
        .iter()
        .filter(|d| d.code == "check::station_limit")
        .collect();
    // -100 and 100 deg/s exceed 80 deg/s (75 deg/s does not): one diagnostic per value
    // as written in the rate list, which both axes share
    assert_eq!(over.len(), 2, "{diags:?}");
    for d in &over {
        let span = d.labels[0].0;
        assert!(["-100", "100"].contains(&&STANDARD[span.start..span.end]));
    }
    assert!(over.iter().all(|d| d.line_col().is_some()));
    let diags = check_text(
        "standard",
        STANDARD,
        &NoImports,
        &station(500.0, 90.0, 1000.0),
    )
    .expect_err("gyro range");
    assert!(
        diags
            .iter()
            .any(|d| d.code == "check::station_limit" && d.message.contains("gyro range"))
    );
    // the swaying procedure peaks at 90 deg * (2 pi / 6 s)^2 = 98.7 deg/s^2
    let sway = include_str!("../../../procedures/size-effect/1.0.0.rcal");
    let mut opts = station(500.0, 400.0, 90.0);
    if let Some(s) = opts.station.as_mut() {
        s.geometry = Geometry::vertical_outer();
    }
    let diags = check_text("sway", sway, &NoImports, &opts).expect_err("too much acceleration");
    assert!(
        diags.iter().all(|d| d.code == "check::station_limit"),
        "{diags:?}"
    );
    // reported once on the oscillate statement (the 12 s period is within the limit)
    assert_eq!(diags.len(), 1, "{diags:?}");
    assert!(
        diags[0].labels[0].1.contains("peak 98.7 deg/s^2"),
        "{:?}",
        diags[0].labels
    );
}

#[test]
fn size_effect_procedure_remounts_each_axis_up() {
    let text = include_str!("../../../procedures/size-effect/1.0.0.rcal");
    let plan = check_text("sway", text, &NoImports, &CheckOptions::default())
        .expect("checks")
        .plan;
    let rots: Vec<[[f64; 3]; 3]> = actions(&plan.steps[0].body)
        .into_iter()
        .filter_map(|a| match a {
            Action::Remount { rotation, .. } => Some(*rotation),
            _ => None,
        })
        .collect();
    assert_eq!(rots.len(), 3);
    // Column k of C_PB is body axis k in platform axes: the axis named up has P z = 1.
    for (rot, up) in rots.iter().zip([2, 0, 1]) {
        assert_eq!(rot[2][up], 1.0);
    }
    let osc: Vec<f64> = actions(&plan.steps[0].body)
        .into_iter()
        .filter_map(|a| match a {
            Action::Oscillate { period_s, .. } => Some(*period_s),
            _ => None,
        })
        .collect();
    assert_eq!(osc, vec![6.0, 12.0, 6.0, 12.0, 6.0, 12.0]);
    assert_eq!(plan.fits[0].model, FitModel::SizeEffect);
}

#[test]
fn huge_repeat_counts_cost_nothing() {
    let text = "procedure r version 1.0.0 {\n step s {\n move to pitch 0 deg, roll 0 deg\n repeat 1000000000000 as i {\n repeat 1000000000000 as j {\n for k in [1, 2, 3] {\n acquire gyro for 1 s at 100 Hz as \"s/{i}/{j}/{k}\"\n }\n }\n }\n fit gyro bias from s/*\n }\n}\n";
    let start = std::time::Instant::now();
    let plan = check_text("r", text, &NoImports, &CheckOptions::default())
        .expect("checks")
        .plan;
    assert!(start.elapsed().as_secs() < 2);
    assert!((plan.estimated_duration_s - 3.0e24).abs() / 3.0e24 < 1e-9);
    assert_eq!(
        plan.segment_templates(),
        vec!["s/{i}/{j}/1", "s/{i}/{j}/2", "s/{i}/{j}/3"]
    );
}

#[test]
fn acceptance_checks_on_calibrated_parameters_carry_their_dimension() {
    let text = STANDARD.replacen(
        "  step accel_static",
        "  accept accel.bias.x <= 80 mg\n  accept gyro.scale.x <= 300 ppm\n  \
         accept gyro.bias.z <= 0.1 deg/s\n\n  step accel_static",
        1,
    );
    let plan = check_text("p", &text, &NoImports, &CheckOptions::default())
        .expect("parameter checks are accepted")
        .plan;
    let accept = |q: &str| plan.accepts.iter().find(|a| a.quantity == q).expect(q);
    assert!((accept("accel.bias.x").limit.value - 0.080 * 9.80665).abs() < 1e-12);
    assert!((accept("gyro.scale.x").limit.value - 300e-6).abs() < 1e-18);
    // A misalignment limit on a full model, in mrad, resolved to degrees.
    let full = STANDARD
        .replacen("fit accel bias_scale", "fit accel full", 1)
        .replacen(
            "  step accel_static",
            "  accept accel.misalignment.xy <= 1 mrad\n\n  step accel_static",
            1,
        );
    let plan_full = check_text("p", &full, &NoImports, &CheckOptions::default())
        .expect("a misalignment check on a full model")
        .plan;
    let mis = plan_full
        .accepts
        .iter()
        .find(|a| a.quantity == "accel.misalignment.xy")
        .unwrap();
    assert!((mis.limit.value - 1e-3f64.to_degrees()).abs() < 1e-12);
    assert_eq!(accept("gyro.bias.z").limit.value, 0.1);
    // A parameter in the wrong unit, and one that does not exist: located errors.
    for (bad, code) in [
        ("accept gyro.scale.x <= 80 mg", "check::unit_mismatch"),
        ("accept accel.bias.w <= 80 mg", "check::unknown_name"),
        (
            "accept accel.misalignment.xx <= 1 mrad",
            "check::unknown_name",
        ),
        // The standard fits `accel bias_scale`: no misalignment in its model.
        (
            "accept accel.misalignment.xy <= 1 mrad",
            "check::not_fitted",
        ),
    ] {
        let text = STANDARD.replacen(
            "  step accel_static",
            &format!("  {bad}\n\n  step accel_static"),
            1,
        );
        let errs = match check_text("p", &text, &NoImports, &CheckOptions::default()) {
            Ok(_) => panic!("`{bad}` was accepted"),
            Err(e) => format!("{e:?}"),
        };
        assert!(errs.contains(code), "`{bad}`: {errs}");
    }
}
