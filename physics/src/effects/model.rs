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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::REGISTRY;
    use crate::{Geometry, Site, TableState};

    /// What `outputs` computed before a term was evaluated only for the sensors it touches:
    /// every term for both sensors.
    fn every_term_for_both(m: &ImuModel, s: &Signals) -> (Vec3, Vec3) {
        let mut sensed = *s;
        for t in m.terms.iter().filter(|t| t.effect.sensed()) {
            sensed.f_b += t.effect.forward(&t.values, s).accel;
        }
        let (mut a, mut g) = (sensed.f_b, s.w_b_dps());
        for t in &m.terms {
            if !t.effect.sensed() {
                a += t.effect.forward(&t.values, &sensed).accel;
            }
            g += t.effect.forward(&t.values, s).gyro;
        }
        (a, g)
    }

    /// Every registry effect at once, at rest and turning, warm and cold: the outputs are
    /// those of every term evaluated for both sensors, to the bit (a term adds exact zeros
    /// to the sensor it does not touch).
    #[test]
    fn a_term_left_out_of_a_sensor_it_does_not_touch_changes_no_bit() {
        let terms = (REGISTRY.iter())
            .map(|e| Term {
                effect: *e,
                values: (0..e.params().len())
                    .map(|k| 1e-3 * (k as f64 + 1.0) * if k % 2 == 0 { 1.0 } else { -0.7 })
                    .collect(),
            })
            .collect();
        let model = ImuModel {
            terms,
            t_ref_c: 20.0,
        };
        let site = Site {
            latitude_deg: 48.0,
            gravity_mps2: 9.8085,
        };
        let geo = Geometry::seed();
        for (o, i, rate, dtemp) in [
            (0.0, 0.0, 0.0, 0.0),
            (90.0, 30.0, 0.0, 2.5),
            (-45.0, 180.0, 1.3, -1.0),
            (10.0, -60.0, -0.4, 0.3),
        ] {
            let mut st = TableState::at_rest_deg(o, i);
            st.outer.rate = rate;
            st.inner.rate = -0.5 * rate;
            st.inner.accel = 0.2 * rate;
            let s = Signals::new(&st.snapshot(&geo, &site), &site, dtemp).at(123.4);
            let (a, g) = model.outputs(&s);
            let (wa, wg) = every_term_for_both(&model, &s);
            for k in 0..3 {
                assert_eq!(
                    a[k].to_bits(),
                    wa[k].to_bits(),
                    "accel {k} at {o} {i} {rate}"
                );
                assert_eq!(
                    g[k].to_bits(),
                    wg[k].to_bits(),
                    "gyro {k} at {o} {i} {rate}"
                );
            }
        }
    }
}
