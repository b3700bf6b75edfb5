//! A station file's `driver:` value: a kind of driver, by name, and its settings
//! (`driver: sim`, `driver: { tcp: { address: "host:port", timeout: "2 s" } }`). Here is
//! the one list of kinds: a name it does not list is refused with the closest one, and
//! each kind says which settings it takes and needs. How each kind is built is the
//! registry's (`registry::builders`).

use super::quantity::Time;
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::ser::{SerializeMap, Serializer};
use serde::{Deserialize, Serialize};
use std::fmt;

/// A kind of driver the registry knows.
#[derive(Clone, Copy)]
pub struct DriverKind {
    /// Name as written in a station file (`driver: sim`, `driver: { tcp: ... }`).
    pub name: &'static str,
    /// Whether it is a simulation (runs on the paused clock) rather than a device.
    pub simulated: bool,
    /// Whether its samples carry their host arrival time (`t_host`, a column of the
    /// recording's streams).
    pub host_arrival: bool,
    /// Whether the operator is the table (a manual station: `place` and `turn` instead of
    /// `move` and `spin`).
    pub operator: bool,
    /// The settings it takes, each with whether it is required (none: written `driver:
    /// NAME`).
    pub keys: &'static [(&'static str, bool)],
    /// One line for people.
    pub about: &'static str,
}

impl fmt::Debug for DriverKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "DriverKind({})", self.name)
    }
}

/// Every driver kind.
pub const DRIVERS: &[DriverKind] = &[
    DriverKind {
        name: "sim",
        simulated: true,
        host_arrival: false,
        operator: false,
        keys: &[],
        about: "simulated station (physics.md), seeded, virtual time",
    },
    DriverKind {
        name: "tcp",
        simulated: false,
        host_arrival: true,
        operator: false,
        keys: &[("address", true), ("timeout", false)],
        about: "table over the line protocol, IMU over binary frames (docs/protocols.md), TCP",
    },
    DriverKind {
        name: "serial",
        simulated: false,
        host_arrival: true,
        operator: false,
        keys: &[("port", true), ("baud", false), ("timeout", false)],
        about: "the same protocols over a serial port (tokio-serial)",
    },
    DriverKind {
        name: "replay",
        simulated: false,
        host_arrival: false,
        operator: false,
        keys: &[("recording", true)],
        about: "replays the streams of a recording folder in time",
    },
    DriverKind {
        name: "manual",
        simulated: false,
        host_arrival: false,
        operator: true,
        keys: &[],
        about: "no rate table: the operator places and turns the unit, prompted on the terminal",
    },
    DriverKind {
        name: "hand",
        simulated: true,
        host_arrival: false,
        operator: true,
        keys: &[],
        about: "a simulated operator for a manual station (--dry-run): tilted poses, uneven turns, a tremor",
    },
];

/// The registered kind of a name.
pub fn kind(name: &str) -> Option<&'static DriverKind> {
    DRIVERS.iter().find(|k| k.name == name)
}

/// The settings of a hardware or replay driver; the kind says which it takes
/// (`DriverKind::keys`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    /// `host:port` of a TCP link.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub address: Option<String>,
    /// Device path of a serial link (`/dev/ttyUSB0`, a pseudo-terminal).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub port: Option<String>,
    /// Baud rate of a serial link (921600 if not given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub baud: Option<u32>,
    /// Reply timeout and reconnect window of a link (2 s if not given).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "seconds"
    )]
    pub timeout: Option<Time>,
    /// A recording folder to replay.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recording: Option<String>,
}

/// A time written back with its unit, as the station file takes it.
fn seconds<S: Serializer>(t: &Option<Time>, s: S) -> Result<S::Ok, S::Error> {
    match t {
        Some(t) => s.serialize_str(&format!("{} s", t.0)),
        None => s.serialize_none(),
    }
}

impl Settings {
    /// The settings given, by key name.
    fn given(&self) -> impl Iterator<Item = &'static str> + '_ {
        [
            ("address", self.address.is_some()),
            ("port", self.port.is_some()),
            ("baud", self.baud.is_some()),
            ("timeout", self.timeout.is_some()),
            ("recording", self.recording.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, on)| on.then_some(k))
    }

    /// Baud rate (921600 by default).
    pub fn baud(&self) -> u32 {
        self.baud.unwrap_or(921_600)
    }

    /// Link timeout, s (2 s by default).
    pub fn timeout_s(&self) -> f64 {
        self.timeout.map_or(2.0, |t| t.0)
    }
}

/// A `driver:` value: a registered kind and its settings.
#[derive(Clone)]
pub struct DriverSpec {
    /// The kind, from the registry.
    pub kind: &'static DriverKind,
    /// Its settings (checked against `kind.keys` when parsed).
    pub settings: Settings,
}

impl DriverSpec {
    /// The simulated driver.
    pub fn sim() -> DriverSpec {
        DriverSpec {
            kind: kind("sim").expect("the registry lists `sim`"),
            settings: Settings::default(),
        }
    }

    /// A spec of a registered kind, its settings checked; the message says what is wrong.
    pub fn new(name: &str, settings: Settings) -> Result<DriverSpec, String> {
        let kind = kind(name).ok_or_else(|| unknown(name))?;
        for k in settings.given() {
            if !kind.keys.iter().any(|(key, _)| *key == k) {
                return Err(format!(
                    "unknown field `{k}` of the `{name}` driver, expected one of {}",
                    quoted(kind.keys.iter().map(|(k, _)| *k))
                ));
            }
        }
        if let Some((k, _)) = kind
            .keys
            .iter()
            .find(|(k, needed)| *needed && !settings.given().any(|g| g == *k))
        {
            return Err(format!("the `{name}` driver needs `{k}`"));
        }
        Ok(DriverSpec { kind, settings })
    }

    /// The timeout of a hardware link, s (`None` for a kind without links).
    pub fn link_timeout_s(&self) -> Option<f64> {
        self.kind
            .keys
            .iter()
            .any(|(k, _)| *k == "timeout")
            .then(|| self.settings.timeout_s())
    }
}

fn quoted<'a>(names: impl Iterator<Item = &'a str>) -> String {
    names
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The message of a name the registry does not list; the station loader's help picks the
/// closest name from the list it ends with.
fn unknown(name: &str) -> String {
    format!(
        "unknown driver `{name}`, expected one of {}",
        quoted(DRIVERS.iter().map(|k| k.name))
    )
}

impl PartialEq for DriverSpec {
    fn eq(&self, other: &Self) -> bool {
        self.kind.name == other.kind.name && self.settings == other.settings
    }
}

impl fmt::Debug for DriverSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "DriverSpec({}, {:?})", self.kind.name, self.settings)
    }
}

impl Serialize for DriverSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if self.kind.keys.is_empty() {
            return s.serialize_str(self.kind.name);
        }
        let mut m = s.serialize_map(Some(1))?;
        m.serialize_entry(self.kind.name, &self.settings)?;
        m.end()
    }
}

impl<'de> Deserialize<'de> for DriverSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(SpecVisitor)
    }
}

struct SpecVisitor;

impl<'de> Visitor<'de> for SpecVisitor {
    type Value = DriverSpec;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "a driver: a name ({}) or `{{ NAME: {{ settings }} }}`",
            quoted(DRIVERS.iter().map(|k| k.name))
        )
    }

    fn visit_str<E: de::Error>(self, name: &str) -> Result<DriverSpec, E> {
        DriverSpec::new(name, Settings::default()).map_err(E::custom)
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<DriverSpec, A::Error> {
        let Some(name) = map.next_key::<String>()? else {
            return Err(de::Error::custom("a driver needs its name"));
        };
        // The name first: an unknown one is refused before its settings are read.
        kind(&name).ok_or_else(|| de::Error::custom(unknown(&name)))?;
        let settings: Settings = map.next_value()?;
        if let Some(other) = map.next_key::<String>()? {
            return Err(de::Error::custom(format!(
                "one driver per device: `{name}` and `{other}` are both given"
            )));
        }
        DriverSpec::new(&name, settings).map_err(de::Error::custom)
    }
}
