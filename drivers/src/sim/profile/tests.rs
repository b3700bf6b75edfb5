use super::*;

const SERVO: Servo = Servo {
    wn: 2.0 * std::f64::consts::PI * 5.0,
    zeta: 0.6,
    feedforward: 0.0,
};

fn scan(p: &AxisProfile, t0: f64, t1: f64, dt: f64) -> Vec<(f64, AxisKinematics)> {
    let mut hint = 0;
    let n = ((t1 - t0) / dt) as usize;
    (0..=n)
        .map(|k| t0 + k as f64 * dt)
        .map(|t| (t, p.eval(t, &mut hint)))
        .collect()
}

#[test]
fn move_reaches_target_within_limits() {
    let mut p = AxisProfile::at_rest(0.0, SERVO, 500.0, 200.0);
    let end = p.move_to(1.0, 90.0);
    // Triangle or trapezoid: 90 deg at 200 deg/s^2 peaks at sqrt(90 * 200) = 134 deg/s.
    assert!(
        (end - (1.0 + 2.0 * (90.0f64 / 200.0).sqrt())).abs() < 1e-9,
        "{end}"
    );
    let mut hint = 0;
    for t in [1.0 + 0.3, 1.0 + 0.6] {
        let (c, _) = p.commanded(t);
        let _ = c;
        let k = p.eval(t, &mut hint);
        assert!(k.rate.abs() <= 135.0);
    }
    // The commanded trajectory respects the limits exactly; the servo response adds a
    // small transient on top.
    for (t, _) in scan(&p, 0.0, end + 2.0, 1e-3) {
        let (_, w) = p.commanded(t);
        assert!(w.abs() <= 500.0 + 1e-9);
    }
    let settled = p.eval(end + 2.0, &mut hint);
    assert!((settled.angle - 90.0).abs() < 1e-9, "{settled:?}");
    assert_eq!(settled.rate, 0.0);
}

#[test]
fn long_move_cruises_at_max_rate() {
    let mut p = AxisProfile::at_rest(0.0, SERVO, 100.0, 200.0);
    let end = p.move_to(0.0, 360.0);
    // 0.5 s up, 0.5 s down covering 25 deg each; 310 deg at 100 deg/s.
    assert!((end - 4.1).abs() < 1e-9, "{end}");
    assert_eq!(p.commanded(2.0), (175.0, 100.0));
}

#[test]
fn motion_is_continuous_and_derivatives_agree() {
    let mut p = AxisProfile::at_rest(10.0, SERVO, 500.0, 200.0);
    p.move_to(0.5, -30.0);
    p.ramp_to_rate(0.9, 50.0); // interrupts the move
    p.oscillate(3.0, 0.0, 20.0, 4.0);
    let pts = scan(&p, 0.0, 14.0, 1e-4);
    for w in pts.windows(3) {
        let (ta, a) = w[0];
        let (tc, c) = w[2];
        let b = w[1].1;
        let h = tc - ta;
        // Central differences over 2e-4 s; the jerk (up to ~1e4 deg/s^3 when a phase
        // starts) bounds their error at kinks.
        assert!(
            ((c.angle - a.angle) / h - b.rate).abs() < 1e-3,
            "rate at {}",
            w[1].0
        );
        assert!(
            ((c.rate - a.rate) / h - b.accel).abs() < 1.0,
            "accel at {}",
            w[1].0
        );
    }
}

#[test]
fn settling_overshoots_then_holds_exactly() {
    let mut p = AxisProfile::at_rest(0.0, SERVO, 500.0, 200.0);
    let end = p.move_to(0.0, 45.0);
    let after: Vec<_> = scan(&p, end, end + 3.0, 1e-3);
    let max_dev = after
        .iter()
        .map(|(_, k)| (k.angle - 45.0).abs())
        .fold(0.0, f64::max);
    // Steady lag while decelerating is a / wn^2 = 200 / 987 = 0.2 deg.
    assert!(max_dev > 0.01 && max_dev < 0.3, "{max_dev}");
    let last = after.last().unwrap().1;
    assert_eq!(last.angle, 45.0);
    assert_eq!(last, p.eval(end + 10.0, &mut 0));
}

#[test]
fn rate_ramp_takes_rate_over_accel() {
    let mut p = AxisProfile::at_rest(0.0, SERVO, 500.0, 200.0);
    p.ramp_to_rate(1.0, 100.0);
    assert_eq!(p.commanded(1.25), (0.5 * 200.0 * 0.25 * 0.25, 50.0));
    let k = p.eval(10.0, &mut 0);
    assert!((k.rate - 100.0).abs() < 1e-9);
    p.ramp_to_rate(10.0, 0.0);
    assert_eq!(p.commanded(11.0).1, 0.0);
}
