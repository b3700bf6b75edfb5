//! The station file: what the site, the table and the IMU are, and how to drive them.
//! Parsing refuses unknown keys and wrong units with a diagnostic located in the file.

mod describe;
mod driver;
mod edit;
mod effects;
mod faults;
mod file;
mod quantity;

pub use describe::{Environment, ImuIdentity, StationInfo};
pub use driver::{DRIVERS, DriverKind, DriverSpec, Settings, kind};

pub use edit::{SetValue, edit, locate, number};
pub use effects::{EffectsSpec, TableEffectsSpec};
pub use faults::{AxisName, DropoutMode, FaultSpec, LinkName, TableFaultMode};
pub use file::{
    AmbientSpec, DaqSpec, EnvironmentSpec, ImuSpec, ImuTemperatureSpec, MountSpec, ReferencesSpec,
    SettlingSpec, SiteSpec, Station, TableCalibration, TableSpec, TemperatureCoefficients,
    TemperatureSpec, UserEffectRef, UserTerms,
};
pub use quantity::{
    Accel, AccelDensity, Angle, Freq, Pressure, Rate, RateDensity, RateWalk, Ratio, Rotation, Temp,
    TempDelta, TempRate, Time, UnitVec, Value,
};

use miette::{Diagnostic, NamedSource, SourceSpan};
use ratecal_physics::effects::{EncoderError, ImuModel};
use ratecal_physics::{Geometry, Mat3, Site, Vec3};

/// The embedded default station's YAML (a simulated tactical-grade IMU on a simulated table).
pub const DEFAULT_STATION_YAML: &str = include_str!("../../stations/default.yaml");

/// The embedded swaying station's YAML (a simulated navigation-grade IMU with lever arms on
/// a table whose outer axis is vertical): the default of procedures with `geometry
/// vertical_outer`.
pub const SWAYING_STATION_YAML: &str = include_str!("../../stations/swaying.yaml");

/// The embedded manual station's YAML (a cube fixture and a consumer IMU, the operator in
/// place of a table): the default of procedures that ask the operator (`place`, `turn`).
pub const MANUAL_STATION_YAML: &str = include_str!("../../stations/manual.yaml");

/// A station file that cannot be used, located in the file.
#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("{message}")]
#[diagnostic(code(station::invalid))]
pub struct StationError {
    /// What is wrong.
    pub message: String,
    /// The file.
    #[source_code]
    pub src: NamedSource<String>,
    /// Where.
    #[label("{label}")]
    pub span: Option<SourceSpan>,
    /// The label's text.
    pub label: String,
    /// 1-based line, if known.
    pub line: Option<usize>,
    /// 1-based column, if known.
    pub column: Option<usize>,
    /// What to do.
    #[help]
    pub help: String,
}

const HELP: &str = "docs/station.md lists every key of a station file with its unit and default";

impl Station {
    /// Parses a station file; `file_name` names it in diagnostics.
    pub fn from_yaml(text: &str, file_name: &str) -> Result<Station, Box<StationError>> {
        serde_saphyr::from_str::<Station>(text).map_err(|e| Box::new(located(&e, text, file_name)))
    }

    /// The embedded default station: seed geometry, a lab at 55.70 deg N, a tactical-grade
    /// IMU at 100 Hz and a table reporting at 50 Hz, both simulated.
    pub fn default_sim() -> Station {
        Station::from_yaml(DEFAULT_STATION_YAML, "<default station>")
            .expect("the embedded default station parses")
    }

    /// The site as the physics crate needs it.
    pub fn site(&self) -> Site {
        Site {
            latitude_deg: self.site.latitude_deg,
            gravity_mps2: self.site.gravity_mps2,
        }
    }

    /// Axis geometry and mount rotation.
    pub fn geometry(&self) -> Geometry {
        let v = |a: [f64; 3]| Vec3::new(a[0], a[1], a[2]);
        let r = self.mount.rotation.0;
        Geometry {
            outer_axis: v(self.table.outer_axis.0),
            inner_axis: v(self.table.inner_axis.0),
            c_pb: Mat3::from_fn(|i, j| r[i][j]),
        }
    }

    /// The IMU's deterministic errors as registry terms: the nominal ones (biases, scale
    /// factors), the Earth's rate at the site, and every catalogue effect the file sets.
    pub fn imu_model(&self) -> ImuModel {
        let imu = &self.imu;
        let mut m = ImuModel {
            terms: Vec::new(),
            t_ref_c: self.temperature.reference.0,
        };
        let v3 = |x: [f64; 3]| x.to_vec();
        m.push("accel_bias", v3(imu.accel_bias.map(|a| a.0)));
        m.push("accel_scale", v3(imu.accel_scale.map(|r| r.0 * 1e6)));
        m.push("gyro_bias", v3(imu.gyro_bias.map(|r| r.0)));
        m.push("gyro_scale", v3(imu.gyro_scale.map(|r| r.0 * 1e6)));
        let site = self.site();
        m.push(
            "earth_rate",
            ratecal_physics::effects::EarthRate::values(site.latitude_deg).to_vec(),
        );
        for e in ratecal_physics::effects::catalogue() {
            if self.imu.effects.0.contains_key(e.id()) {
                m.push(e.id(), self.imu.effects.values(e));
            }
        }
        m.terms.extend(self.user_terms.0.iter().cloned());
        m
    }

    /// The table's encoder errors (`table.effects`): what its feedback reports, and its
    /// servo follows, against the true motion.
    pub fn encoder_error(&self) -> EncoderError {
        let e = ratecal_physics::effect("table_encoder_eccentricity").expect("a registry id");
        EncoderError::from_values(&self.table.effects.0.values(e))
    }

    /// The IMU's time offset `tau`, s.
    pub fn time_offset_s(&self) -> f64 {
        self.imu.effects.value("time_offset", "tau_ms") * 1e-3
    }

    /// The same station with every random term switched off (white noise, bias wander,
    /// encoder noise, rate ripple, temperature noise): for closed-form tests.
    pub fn noiseless(mut self) -> Station {
        let imu = &mut self.imu;
        imu.accel_noise_density = AccelDensity(0.0);
        imu.gyro_noise_density = RateDensity(0.0);
        imu.gyro_bias_markov_sigma = Rate(0.0);
        imu.gyro_bias_random_walk = RateWalk(0.0);
        self.table.position_noise = Angle(0.0);
        self.table.rate_ripple = Rate(0.0);
        self.temperature.ambient.noise = TempDelta(0.0);
        self.temperature.imu.noise = TempDelta(0.0);
        self
    }
}

/// Turns a serde-saphyr error into a located diagnostic naming the real file.
fn located(err: &serde_saphyr::Error, text: &str, file_name: &str) -> StationError {
    let loc = err.location();
    let (line, column) = match &loc {
        Some(l) if l.line() > 0 => (Some(l.line() as usize), Some(l.column() as usize)),
        _ => (None, None),
    };
    // Line and column are the parser's own count; its span's byte offset does not always
    // agree with them (after a bare CR, at some scanner errors), so it is used only when
    // it points where they do.
    let offset = line.zip(column).map(|(l, c)| {
        let at = yaml_offset(text, l as u64, c as u64);
        let len = loc
            .as_ref()
            .filter(|l| l.span().byte_offset().map(|o| o as usize) == Some(at))
            .and_then(|l| l.span().byte_len())
            .unwrap_or(1) as usize;
        (at, len)
    });
    let message = message_of(err);
    let help = help_for(&message);
    let label = if message.contains("unknown field") {
        "unknown key"
    } else if message.contains("unknown driver") {
        "unknown driver"
    } else {
        "here"
    }
    .to_string();
    StationError {
        message: format!("{file_name}: {message}"),
        src: NamedSource::new(file_name, text.to_string()),
        span: offset.map(|(o, n)| SourceSpan::new(o.min(text.len()).into(), n.max(1))),
        label,
        line,
        column,
        help,
    }
}

/// The error's own text without serde-saphyr's location suffix and snippet.
fn message_of(err: &serde_saphyr::Error) -> String {
    let text = err.without_snippet().to_string();
    let first = text.lines().next().unwrap_or("").trim().to_string();
    match first.find(" at line ") {
        Some(i) => first[..i].to_string(),
        None => first,
    }
}

fn help_for(message: &str) -> String {
    if message.contains("earth_rate") {
        return "the Earth's rotation is site physics, always on: set site.latitude_deg instead"
            .into();
    }
    if message.contains("unknown field") || message.contains("unknown driver") {
        let found = message.split('`').nth(1).unwrap_or("");
        let keys: Vec<&str> = message
            .split_once("expected ")
            .map(|(_, k)| {
                k.trim_start_matches("one of ")
                    .split(", ")
                    .map(|k| k.trim_matches('`'))
                    .collect()
            })
            .unwrap_or_default();
        // One edit away counts as close too: Jaro-Winkler misses a swap in a short name
        // (`tpc` for `tcp`).
        let close = |k: &str| match strsim::osa_distance(found, k) {
            0 | 1 => 1.0,
            _ => strsim::jaro_winkler(found, k),
        };
        let best = keys
            .iter()
            .map(|k| (close(k), *k))
            .filter(|(score, _)| *score > 0.8)
            .max_by(|a, b| a.0.total_cmp(&b.0));
        return match best {
            Some((_, k)) => format!("did you mean `{k}`? {HELP}"),
            None => format!("this section takes: {}; {HELP}", keys.join(", ")),
        };
    }
    if message.contains("unit") {
        return format!("write the value with a unit of the right kind; {HELP}");
    }
    HELP.into()
}

// One YAML locator for manifests and station files: the recording crate's.
pub use ratecal_recording::yaml_offset;
