//! A checked user effect as a registry [`Effect`], so the layout, the joint fit and the
//! selection treat it exactly like the built-in ones.

use super::check::{Checked, Reg};
use ratecal_physics::effects::{Effect, Param, Partials, Sensor, Signals};
use std::sync::atomic::{AtomicUsize, Ordering};

/// An effect defined in a file (docs/user-effects.md).
pub struct UserEffect {
    id: &'static str,
    explanation: &'static str,
    follows: &'static str,
    params: &'static [Param],
    sensors: &'static [Sensor],
    regs: Vec<Reg>,
    file: String,
    /// Regressor values that were not finite (taken as zero), for a warning.
    nonfinite: AtomicUsize,
}

impl std::fmt::Debug for UserEffect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "UserEffect({} from {})", self.id, self.file)
    }
}

fn leak(s: String) -> &'static str {
    Box::leak(s.into_boxed_str())
}

fn sensor_of(channel: usize) -> (Sensor, usize) {
    if channel < 3 {
        (Sensor::Accel, channel)
    } else {
        (Sensor::Gyro, channel - 3)
    }
}

impl UserEffect {
    /// Makes a checked effect live for the rest of the process.
    ///
    /// The registry's [`Effect`] trait hands out `&'static` ids, parameters and units, and
    /// the joint fit's layout holds `&'static dyn Effect`; a user effect is parsed once per
    /// process (a handful of small files read by one `ratecal explain`), so leaking it is
    /// bounded and keeps every consumer of the registry unchanged.
    pub(crate) fn leak(c: Checked, file: &str) -> &'static UserEffect {
        let mut channels: Vec<Vec<usize>> = vec![Vec::new(); c.params.len()];
        for r in &c.regs {
            if !channels[r.param].contains(&r.channel) {
                channels[r.param].push(r.channel);
            }
        }
        let params: Vec<Param> = c
            .params
            .into_iter()
            .zip(&channels)
            .map(|((name, unit, needs), ch)| Param {
                name: leak(name),
                unit: leak(unit),
                // One channel: the parameter acts there only; several: on every axis of
                // the effect's sensors, with zero partials where it has no term.
                channel: match ch.as_slice() {
                    [one] => Some(sensor_of(*one)),
                    _ => None,
                },
                needs: leak(needs),
                // A user effect declares no plausible range.
                max_abs: f64::INFINITY,
            })
            .collect();
        let accel = c.regs.iter().any(|r| r.channel < 3);
        let gyro = c.regs.iter().any(|r| r.channel >= 3);
        let sensors: &'static [Sensor] = match (accel, gyro) {
            (true, true) => &[Sensor::Accel, Sensor::Gyro],
            (true, false) => Sensor::Accel.only(),
            _ => Sensor::Gyro.only(),
        };
        Box::leak(Box::new(UserEffect {
            id: leak(c.id.node),
            explanation: leak(c.explanation),
            follows: leak(c.follows),
            params: Box::leak(params.into_boxed_slice()),
            sensors,
            regs: c.regs,
            file: file.to_string(),
            nonfinite: AtomicUsize::new(0),
        }))
    }

    /// The file it was defined in, as named on the command line.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// How many regressor values so far were not finite (a square root of a negative
    /// number, a division by zero) and were taken as zero.
    pub fn nonfinite(&self) -> usize {
        self.nonfinite.load(Ordering::Relaxed)
    }
}

impl Effect for UserEffect {
    fn id(&self) -> &'static str {
        self.id
    }

    fn explanation(&self) -> &'static str {
        self.explanation
    }

    fn follows(&self) -> &'static str {
        self.follows
    }

    fn params(&self) -> &'static [Param] {
        self.params
    }

    // A user's expression may read `dtemp_c`: taken to, so the reference is always known.
    fn uses_temperature(&self) -> bool {
        true
    }

    fn sensors(&self) -> &'static [Sensor] {
        self.sensors
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        out.fill(Partials::default());
        for r in &self.regs {
            let mut v = r.ex.eval(s);
            if !v.is_finite() {
                self.nonfinite.fetch_add(1, Ordering::Relaxed);
                v = 0.0;
            }
            let (sensor, i) = sensor_of(r.channel);
            if let Some(p) = out.get_mut(r.param) {
                match sensor {
                    Sensor::Accel => p.accel[i] += v,
                    Sensor::Gyro => p.gyro[i] += v,
                }
            }
        }
    }

    // Any number of parameters (the trait's default holds sixteen).
    fn forward(&self, values: &[f64], s: &Signals) -> Partials {
        let mut parts = vec![Partials::default(); self.params.len()];
        self.regressors(s, &mut parts);
        let mut out = Partials::default();
        for (v, p) in values.iter().zip(&parts) {
            out.accel += p.accel * *v;
            out.gyro += p.gyro * *v;
        }
        out
    }
}
