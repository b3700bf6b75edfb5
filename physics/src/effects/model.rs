//! A measurement model as a list of registry terms with values: what the simulator
//! applies to the ideal outputs.

use super::{Effect, Sensor, Signals};
use crate::Vec3;

/// One effect with its parameter values (in the catalogue's units).
#[derive(Debug, Clone)]
pub struct Term {
    /// The effect.
    pub effect: &'static dyn Effect,
    /// One value per parameter.
    pub values: Vec<f64>,
}

/// The IMU's deterministic behaviour: the ideal outputs plus every term's contribution.
#[derive(Debug, Clone, Default)]
pub struct ImuModel {
    /// The terms, in any order (they add).
    pub terms: Vec<Term>,
    /// Reference temperature of the thermal terms, degC.
    pub t_ref_c: f64,
}

impl ImuModel {
    /// Adds a term when any of its values is not zero.
    pub fn push(&mut self, id: &str, values: Vec<f64>) {
        if values.iter().any(|v| *v != 0.0) {
            let effect = super::effect(id).expect("a registry id");
            assert_eq!(
                values.len(),
                effect.params().len(),
                "{id}: one value a parameter"
            );
            self.terms.push(Term { effect, values });
        }
    }

    /// Noise-free accelerometer (m/s^2) and gyro (deg/s) outputs for these signals. The
    /// ideal outputs are the specific force at the reference point and the body rate
    /// relative to the lab; the Earth's rate, like everything else, is a term.
    pub fn outputs(&self, s: &Signals) -> (Vec3, Vec3) {
        // What the accelerometers sense (the lever arm included): the other accelerometer
        // terms (scale, cross-coupling) apply to it, exactly as `a = K_a s + b_a`.
        let mut sensed = *s;
        for t in self.terms.iter().filter(|t| t.effect.sensed()) {
            sensed.f_b += t.effect.forward(&t.values, s).accel;
        }
        let mut a = sensed.f_b;
        let mut g = s.w_b_dps();
        for t in &self.terms {
            // A term adds nothing to a sensor it does not touch: it is not evaluated for it.
            let on = t.effect.sensors();
            if !t.effect.sensed() && on.contains(&Sensor::Accel) {
                a += t.effect.forward(&t.values, &sensed).accel;
            }
            if on.contains(&Sensor::Gyro) {
                g += t.effect.forward(&t.values, s).gyro;
            }
        }
        (a, g)
    }

    /// How long after the motion the samples are stamped, s (the constant part: the time
    /// offset).
    pub fn delay_s(&self) -> f64 {
        self.terms.iter().map(|t| t.effect.delay_s(&t.values)).sum()
    }

    /// How long after the motion the sample stamped `t_s` (IMU clock) is stamped, s: the
    /// time offset plus the clock rate's growing lag. The motion it saw is that of table
    /// time `t_s - delay_at_s(t_s)` (`t_s / (1 + eps) - tau`).
    pub fn delay_at_s(&self, t_s: f64) -> f64 {
        self.terms
            .iter()
            .map(|t| t.effect.delay_at_s(&t.values, t_s))
            .sum()
    }
}
