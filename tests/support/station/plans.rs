//! Plans built by hand (the checker builds them from procedure text).

use ratecal_plan::*;

pub fn plan(aborts: Vec<AbortRule>, steps: Vec<Step>) -> Plan {
    Plan {
        name: "test".into(),
        version: "1.0.0".into(),
        title: "t".into(),
        references: vec![],
        imu_class: None,
        meta: Default::default(),
        requirements: vec![],
        environment: vec![],
        aborts,
        steps,
        fits: vec![],
        accepts: vec![],
        verifications: vec![],
        estimated_duration_s: 0.0,
    }
}

pub fn step(name: &str, body: Vec<Node>) -> Step {
    Step {
        name: name.into(),
        title: None,
        aborts: vec![],
        body,
        estimated_duration_s: 0.0,
    }
}

pub fn mv(outer: f64, inner: f64) -> Node {
    Node::Do(Action::MoveTo {
        outer_deg: outer,
        inner_deg: inner,
    })
}

pub fn settle(
    min: f64,
    att: Option<f64>,
    rate: Option<f64>,
    timeout: f64,
    on_timeout: OnTimeout,
) -> Node {
    Node::Do(Action::Settle(Settle {
        min_time_s: min,
        stable: vec![],
        attitude_error_deg: att,
        rate_error_dps: rate,
        timeout_s: Some(timeout),
        on_timeout,
    }))
}

pub fn acquire(id: &str, dur: f64) -> Node {
    Node::Do(Action::Acquire(Acquire {
        segment: id.into(),
        channels: vec!["accel".into()],
        duration_s: dur,
        rate_hz: 100.0,
    }))
}

pub fn rule(text: &str, condition: AbortCondition, persistence_s: f64) -> AbortRule {
    AbortRule {
        text: text.into(),
        condition,
        persistence_s,
        action: AbortAction::Abort,
        unit: String::new(),
    }
}

const ARCSEC: f64 = 1.0 / 3600.0;

/// The standard procedure (seed text) as the checker would resolve it, with the gyro-bias
/// block `bias_s` long (3600 s in the standard).
pub fn standard(bias_s: f64) -> Plan {
    let aborts = vec![
        rule(
            "abort when table.attitude_error > 5 arcsec for 1 s",
            AbortCondition::Above {
                signal: Signal::AttitudeError,
                limit: 5.0 * ARCSEC,
            },
            1.0,
        ),
        rule(
            "abort when imu.output abnormal for 0.5 s",
            AbortCondition::ImuAbnormal,
            0.5,
        ),
        rule(
            "abort when ambient.temperature outside 18 degC .. 22 degC for 10 s",
            AbortCondition::Outside {
                signal: Signal::AmbientTemperature,
                lo: 18.0,
                hi: 22.0,
            },
            10.0,
        ),
    ];
    let mut statics = Vec::new();
    for (n, (pitch, roll)) in [
        (0.0, 0.0),
        (0.0, 180.0),
        (90.0, 0.0),
        (-90.0, 0.0),
        (0.0, 90.0),
        (0.0, 270.0),
    ]
    .into_iter()
    .enumerate()
    {
        statics.push(mv(pitch, roll));
        statics.push(Node::Do(Action::Settle(Settle {
            min_time_s: 30.0,
            stable: vec![Stability {
                signal: Signal::Accel,
                max_fluctuation: 0.001 * 9.80665,
                window_s: 5.0,
            }],
            attitude_error_deg: Some(5.0 * ARCSEC),
            rate_error_dps: None,
            timeout_s: Some(120.0),
            on_timeout: OnTimeout::Abort,
        })));
        statics.push(acquire(&format!("accel_static/{}", n + 1), 10.0));
    }
    let mut bias = step(
        "gyro_bias",
        vec![
            mv(0.0, 0.0),
            settle(30.0, Some(5.0 * ARCSEC), None, 120.0, OnTimeout::Abort),
            acquire("gyro_bias", bias_s),
        ],
    );
    bias.aborts.push(rule(
        "abort when ambient.temperature drifts > 0.2 degC",
        AbortCondition::Drifts {
            signal: Signal::AmbientTemperature,
            limit: 0.2,
        },
        0.0,
    ));
    let mut scale = Vec::new();
    for (axis, name) in [(Axis::Outer, "outer"), (Axis::Inner, "inner")] {
        for rate in [-100.0, -50.0, 0.0, 50.0, 100.0] {
            scale.push(Node::Do(Action::Spin {
                axis,
                rate_dps: rate,
            }));
            scale.push(settle(20.0, None, Some(0.5), 60.0, OnTimeout::Abort));
            scale.push(acquire(&format!("gyro_scale/{name}/{rate:+}"), 10.0));
        }
        scale.push(Node::Do(Action::Stop { axis: Some(axis) }));
    }
    let mut p = plan(
        aborts,
        vec![
            step("accel_static", statics),
            bias,
            step("gyro_scale", scale),
        ],
    );
    p.name = "imu-2d-standard".into();
    p.estimated_duration_s = 6.0 * 50.0 + bias_s + 60.0 + 10.0 * 40.0;
    p
}
