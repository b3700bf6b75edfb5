//! A hand-built plan shaped like the standard procedure 1.0.0, for the audit tests.

#![allow(dead_code)]

use ratecal_plan::*;
use std::collections::BTreeMap;

pub const G: f64 = 9.80665;

/// A quantity written as `written unit`, with its internal value.
pub fn q(written: f64, unit: &str, dim: Dim, value: f64) -> Quantity {
    Quantity {
        written,
        unit: unit.into(),
        dim,
        value,
    }
}

pub fn settle_static() -> Settle {
    Settle {
        min_time_s: 30.0,
        stable: vec![Stability {
            signal: Signal::Accel,
            max_fluctuation: 0.001 * G,
            window_s: 5.0,
        }],
        attitude_error_deg: Some(5.0 / 3600.0),
        rate_error_dps: None,
        timeout_s: Some(120.0),
        on_timeout: OnTimeout::Abort,
    }
}

pub fn acquire(segment: &str, duration_s: f64) -> Action {
    Action::Acquire(Acquire {
        segment: segment.into(),
        channels: vec!["accel".into(), "gyro".into(), "table".into()],
        duration_s,
        rate_hz: 100.0,
    })
}

pub fn accel_static() -> Step {
    let attitudes = [
        (0.0, 0.0),
        (0.0, 180.0),
        (90.0, 0.0),
        (-90.0, 0.0),
        (0.0, 90.0),
        (0.0, 270.0),
    ];
    let mut body = Vec::new();
    for (n, (p, r)) in attitudes.iter().enumerate() {
        body.push(Node::Do(Action::MoveTo {
            outer_deg: *p,
            inner_deg: *r,
        }));
        body.push(Node::Do(Action::Settle(settle_static())));
        body.push(Node::Do(acquire(&format!("accel_static/{}", n + 1), 10.0)));
    }
    Step {
        name: "accel_static".into(),
        title: Some("Static accelerometer positions".into()),
        aborts: vec![],
        body,
        estimated_duration_s: 6.0 * 45.0,
    }
}

pub fn gyro_bias() -> Step {
    let settle = Settle {
        min_time_s: 30.0,
        stable: vec![],
        attitude_error_deg: None,
        rate_error_dps: None,
        timeout_s: None,
        on_timeout: OnTimeout::Abort,
    };
    Step {
        name: "gyro_bias".into(),
        title: Some("Static gyro bias".into()),
        aborts: vec![AbortRule {
            text: "ambient.temperature drifts > 0.2 degC".into(),
            condition: AbortCondition::Drifts {
                signal: Signal::AmbientTemperature,
                limit: 0.2,
            },
            persistence_s: 0.0,
            action: AbortAction::Abort,
            unit: String::new(),
        }],
        body: vec![
            Node::Do(Action::MoveTo {
                outer_deg: 0.0,
                inner_deg: 0.0,
            }),
            Node::Do(Action::Settle(settle)),
            Node::Do(acquire("gyro_bias", 3600.0)),
        ],
        estimated_duration_s: 3630.0,
    }
}

pub fn gyro_scale(rates: &[f64]) -> Step {
    let mut body = Vec::new();
    for axis in [Axis::Outer, Axis::Inner] {
        let a = if axis == Axis::Outer {
            "outer"
        } else {
            "inner"
        };
        for r in rates {
            body.push(Node::Do(Action::Spin { axis, rate_dps: *r }));
            body.push(Node::Do(Action::Settle(Settle {
                min_time_s: 20.0,
                stable: vec![],
                attitude_error_deg: None,
                rate_error_dps: Some(0.5),
                timeout_s: Some(60.0),
                on_timeout: OnTimeout::Abort,
            })));
            body.push(Node::Do(acquire(&format!("gyro_scale/{a}/{r:+}"), 10.0)));
        }
        body.push(Node::Do(Action::Stop { axis: Some(axis) }));
    }
    Step {
        name: "gyro_scale".into(),
        title: Some("Gyro scale factors".into()),
        aborts: vec![],
        body,
        estimated_duration_s: 10.0 * 30.0,
    }
}

pub fn accept(step: Option<&str>, quantity: &str, op: Cmp, limit: Quantity) -> Accept {
    Accept {
        step: step.map(Into::into),
        quantity: quantity.into(),
        op,
        limit,
        over_runs: None,
        rule: DecisionRule::Simple,
        within: false,
    }
}

/// The standard procedure 1.0.0, by hand.
pub fn standard() -> Plan {
    let steps = vec![
        accel_static(),
        gyro_bias(),
        gyro_scale(&[-100.0, -50.0, 0.0, 50.0, 100.0]),
    ];
    let estimated_duration_s = steps.iter().map(|s| s.estimated_duration_s).sum();
    Plan {
        name: "imu-2d-standard".into(),
        version: "1.0.0".into(),
        title: "IMU two-dimensional calibration on a dual-axis rate table".into(),
        references: vec!["Standard procedure for IMU two-dimensional calibration".into()],
        imu_class: Some("tactical".into()),
        meta: BTreeMap::new(),
        requirements: vec![
            Requirement {
                name: "table.position_accuracy".into(),
                op: Cmp::Le,
                limit: q(10.0, "arcsec", Dim::Angle, 10.0 / 3600.0),
            },
            Requirement {
                name: "imu.warm_up".into(),
                op: Cmp::Ge,
                limit: q(30.0, "min", Dim::Time, 1800.0),
            },
        ],
        environment: vec![EnvCondition {
            name: "temperature".into(),
            min: Some(q(18.0, "degC", Dim::Temperature, 18.0)),
            max: Some(q(22.0, "degC", Dim::Temperature, 22.0)),
        }],
        aborts: vec![
            AbortRule {
                text: "table.attitude_error > 5 arcsec for 1 s".into(),
                condition: AbortCondition::Above {
                    signal: Signal::AttitudeError,
                    limit: 5.0 / 3600.0,
                },
                persistence_s: 1.0,
                action: AbortAction::Abort,
                unit: String::new(),
            },
            AbortRule {
                text: "imu.accel out of range or imu.stuck for 0.5 s".into(),
                condition: AbortCondition::ImuAbnormal,
                persistence_s: 0.5,
                action: AbortAction::Abort,
                unit: String::new(),
            },
        ],
        steps,
        fits: vec![
            FitSpec {
                step: "accel_static".into(),
                model: FitModel::AccelBiasScale,
                axes: vec![0, 1, 2],
                segments: vec!["accel_static/*".into()],
                outliers: Some(Outliers::Sigma(3.0)),
                lowpass: None,
                using: None,
                effects: Vec::new(),
            },
            FitSpec {
                step: "gyro_bias".into(),
                model: FitModel::GyroBias,
                axes: vec![0, 1, 2],
                segments: vec!["gyro_bias".into()],
                outliers: Some(Outliers::Sigma(3.0)),
                lowpass: None,
                using: None,
                effects: Vec::new(),
            },
            FitSpec {
                step: "gyro_scale".into(),
                model: FitModel::GyroScale,
                axes: vec![0, 1],
                segments: vec!["gyro_scale/*".into()],
                outliers: None,
                lowpass: None,
                using: Some("gyro_bias".into()),
                effects: Vec::new(),
            },
        ],
        accepts: vec![
            accept(
                Some("accel_static"),
                "accel.residual.std",
                Cmp::Le,
                q(0.002, "g", Dim::Accel, 0.002 * G),
            ),
            accept(
                Some("gyro_scale"),
                "gyro.residual.std",
                Cmp::Le,
                q(0.1, "deg/s", Dim::Rate, 0.1),
            ),
            Accept {
                over_runs: Some(3),
                ..accept(
                    None,
                    "repeatability.cv",
                    Cmp::Le,
                    q(1.0, "%", Dim::Ratio, 0.01),
                )
            },
        ],
        verifications: vec![Verification {
            point: VerifyPoint::Attitude {
                outer_deg: 45.0,
                inner_deg: 30.0,
            },
            limits: vec![accept(
                None,
                "accel.error",
                Cmp::Le,
                q(0.01, "g", Dim::Accel, 0.01 * G),
            )],
            segments: vec![],
        }],
        estimated_duration_s,
    }
}
