//! The station file's `effects:` block: catalogue effects of the physics registry under
//! their canonical ids, each with its parameters under the registry's names and units. The
//! registry decides which ids and parameters exist: adding an effect there makes it
//! writable here, with nothing to change in this crate.

use super::quantity::shown;
use serde::de::{self, DeserializeSeed, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};
use std::collections::BTreeMap;
use std::fmt;

/// Catalogue effects present in the simulated IMU: id -> parameter -> value (in the
/// parameter's unit). `earth_rate` is not here: the Earth's rotation is site physics.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
#[serde(transparent)]
pub struct EffectsSpec(pub BTreeMap<String, BTreeMap<String, f64>>);

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

/// The ids a station may set: every catalogue effect but the Earth's rate.
fn settable() -> impl Iterator<Item = &'static dyn ratecal_physics::effects::Effect> {
    ratecal_physics::effects::catalogue().filter(|e| e.id() != "earth_rate")
}

/// The largest time offset a station may set, ms: an offset of 1e300 ms evaluates the
/// motion at 1e297 s, where `s^2` overflows (NaN outputs).
const MAX_TAU_MS: f64 = 60_000.0;

impl<'de> Deserialize<'de> for EffectsSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(EffectsVisitor)
    }
}

struct EffectsVisitor;

impl<'de> Visitor<'de> for EffectsVisitor {
    type Value = EffectsSpec;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a map of catalogue effect ids to their parameters")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<EffectsSpec, A::Error> {
        let mut out = BTreeMap::new();
        while let Some(id) = map.next_key::<String>()? {
            let Some(effect) = settable().find(|e| e.id() == id) else {
                let ids: Vec<String> = settable().map(|e| format!("`{}`", e.id())).collect();
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
            if effect.id() == "time_offset" && v.abs() > MAX_TAU_MS {
                return Err(de::Error::custom(format!(
                    "must be within a minute either way (-60000 to 60000 ms), found {}",
                    shown(v)
                )));
            }
            out.insert(name, v);
        }
        Ok(out)
    }
}
