//! The station file's `effects:` blocks: catalogue effects of the physics registry under
//! their canonical ids, each with its parameters under the registry's names and units. The
//! registry decides which ids and parameters exist: adding an effect there makes it
//! writable here, with nothing to change in this crate. The IMU's effects go in
//! `imu.effects`, the station-side ones (the table's encoder eccentricity) in
//! `table.effects`.

use super::quantity::shown;
use serde::de::{self, DeserializeSeed, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};
use std::collections::BTreeMap;
use std::fmt;

/// Catalogue effects present in the simulated IMU (`imu.effects`) or table
/// (`table.effects`): id -> parameter -> value (in the parameter's unit). `earth_rate` is
/// not here: the Earth's rotation is site physics.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
#[serde(transparent)]
pub struct EffectsSpec(pub BTreeMap<String, BTreeMap<String, f64>>);

/// The table's block (`table.effects`): the station-side effects of the registry.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
#[serde(transparent)]
pub struct TableEffectsSpec(pub EffectsSpec);

impl EffectsSpec {
    /// One parameter's value (0 when absent).
    pub fn value(&self, id: &str, param: &str) -> f64 {
        self.0
            .get(id)
            .and_then(|p| p.get(param))
            .copied()
            .unwrap_or(0.0)
    }

    /// The values of an effect in the registry's parameter order (0 when absent).
    pub fn values(&self, effect: &dyn ratecal_physics::effects::Effect) -> Vec<f64> {
        effect
            .params()
            .iter()
            .map(|p| self.value(effect.id(), p.name))
            .collect()
    }
}

/// The ids a block may set: every catalogue effect of its side but the Earth's rate.
fn settable(
    station_side: bool,
) -> impl Iterator<Item = &'static dyn ratecal_physics::effects::Effect> {
    ratecal_physics::effects::catalogue()
        .filter(move |e| e.id() != "earth_rate" && e.station_side() == station_side)
}

/// Values a simulation can evaluate, per effect and parameter: `(id, largest magnitude,
/// the message's range)`. An offset of 1e300 ms evaluates the motion at 1e297 s, where
/// `s^2` overflows (NaN outputs); a clock rate of -1e6 ppm stops the clock; an encoder
/// error of a radian is no longer an error the table's servo can invert.
const SIM_LIMITS: [(&str, f64, &str); 3] = [
    (
        "time_offset",
        60_000.0,
        "within a minute either way (-60000 to 60000 ms)",
    ),
    (
        "clock_rate",
        100_000.0,
        "within 10 % either way (-100000 to 100000 ppm)",
    ),
    (
        "table_encoder_eccentricity",
        3600.0,
        "within a degree either way (-3600 to 3600 arcsec)",
    ),
];

impl<'de> Deserialize<'de> for EffectsSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(EffectsVisitor {
            station_side: false,
        })
    }
}

impl<'de> Deserialize<'de> for TableEffectsSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(EffectsVisitor { station_side: true })
            .map(TableEffectsSpec)
    }
}

/// One block: the IMU's or the table's (`station_side`).
struct EffectsVisitor {
    station_side: bool,
}

impl<'de> Visitor<'de> for EffectsVisitor {
    type Value = EffectsSpec;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a map of catalogue effect ids to their parameters")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<EffectsSpec, A::Error> {
        let mut out = BTreeMap::new();
        while let Some(id) = map.next_key::<String>()? {
            let Some(effect) = settable(self.station_side).find(|e| e.id() == id) else {
                if settable(!self.station_side).any(|e| e.id() == id) {
                    let (here, there) = if self.station_side {
                        ("the IMU's", "`imu.effects`")
                    } else {
                        ("the table's, a station-side error", "`table.effects`")
                    };
                    return Err(de::Error::custom(format!(
                        "`{id}` is {here}: write it under {there}"
                    )));
                }
                let ids: Vec<String> = settable(self.station_side)
                    .map(|e| format!("`{}`", e.id()))
                    .collect();
                return Err(de::Error::custom(format!(
                    "unknown field `{id}`, expected one of {}",
                    ids.join(", ")
                )));
            };
            let params = map.next_value_seed(ParamsSeed(effect))?;
            out.insert(id, params);
        }
        Ok(EffectsSpec(out))
    }
}

/// One effect's parameters, checked against the registry.
struct ParamsSeed(&'static dyn ratecal_physics::effects::Effect);

impl<'de> DeserializeSeed<'de> for ParamsSeed {
    type Value = BTreeMap<String, f64>;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for ParamsSeed {
    type Value = BTreeMap<String, f64>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "the parameters of `{}`", self.0.id())
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let effect = self.0;
        let mut out = BTreeMap::new();
        while let Some(name) = map.next_key::<String>()? {
            if !effect.params().iter().any(|p| p.name == name) {
                let names: Vec<String> = effect
                    .params()
                    .iter()
                    .map(|p| format!("`{}`", p.name))
                    .collect();
                return Err(de::Error::custom(format!(
                    "unknown field `{name}`, expected one of {}",
                    names.join(", ")
                )));
            }
            let v: f64 = map.next_value()?;
            if !v.is_finite() {
                return Err(de::Error::custom(format!(
                    "must be a finite number, found {}",
                    shown(v)
                )));
            }
            if let Some((_, _, range)) = SIM_LIMITS
                .iter()
                .find(|(id, max, _)| *id == effect.id() && v.abs() > *max)
            {
                return Err(de::Error::custom(format!(
                    "must be {range}, found {}",
                    shown(v)
                )));
            }
            out.insert(name, v);
        }
        Ok(out)
    }
}
