//! `ratecal explain RUN --twin STATION.yaml [--write-twin OUT.yaml]`: the station file
//! read as the twin (a file, or a run folder's `station.yaml`), refused when its site or
//! table contradicts the recording's manifest, and the corrected file written in the
//! input's own text with its diff (docs/explain.md, "The twin").

use miette::{Diagnostic, NamedSource, SourceSpan};
use ratecal_analysis::explain::Rms;
use ratecal_analysis::twin::{Change, Twin};
use ratecal_drivers::station::{self, SetValue, Station};
use ratecal_folder::RunFolder;
use ratecal_folder::names::STATION;
use ratecal_recording::Manifest;
use std::path::{Path, PathBuf};

/// A station file read as a twin: its path as shown, its text and what it says.
pub struct TwinFile {
    /// The file (a run folder's `station.yaml` for a folder).
    pub path: PathBuf,
    /// Its text.
    pub text: String,
    /// The parsed station.
    pub station: Station,
    /// The user effects it references (`imu.user_effects`).
    pub user: Vec<&'static ratecal_analysis::explain::UserEffect>,
}

/// A twin whose site or table geometry contradicts the recording's manifest.
#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("{message}")]
#[diagnostic(
    code(explain::twin_contradicts_manifest),
    help(
        "a twin is compared with recordings of its own station: give the station file the recording was made on (its run folder's station.yaml), or correct the value"
    )
)]
pub struct Contradiction {
    message: String,
    #[source_code]
    src: NamedSource<String>,
    #[label("the recording's manifest says {manifest}")]
    span: Option<SourceSpan>,
    manifest: String,
}

/// Reads the twin: a station file, or a run folder's `station.yaml`. Prints the located
/// error on failure.
pub(crate) fn read(arg: &Path) -> Result<TwinFile, ()> {
    let (path, text) = if arg.is_dir() {
        (arg.join(STATION), RunFolder::new(arg).read(STATION))
    } else {
        (arg.to_path_buf(), std::fs::read_to_string(arg))
    };
    let text = text.map_err(|e| {
        errln!("error: cannot read the twin {}: {e}", path.display());
    })?;
    let mut station = Station::from_yaml(&text, &path.display().to_string()).map_err(|e| {
        errln!("{:?}", miette::Report::new(*e));
    })?;
    let user = crate::station::load(&mut station, &text, Some(&path)).map_err(|e| {
        errln!("{e:?}");
    })?;
    Ok(TwinFile {
        path,
        text,
        station,
        user,
    })
}

/// The twin's site, table axes and mount against the manifest's: the first contradiction,
/// located at the station file's value.
pub fn refuse(f: &TwinFile, m: &Manifest) -> Result<(), Box<Contradiction>> {
    let st = &f.station;
    let ms = &m.station;
    let close3 = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-6);
    let mount = ms
        .mount
        .map_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], |m| {
            m.rotation
        });
    let checks: [(&str, &str, bool, String); 5] = [
        (
            "site",
            "latitude_deg",
            (st.site.latitude_deg - ms.site.latitude_deg).abs() <= 1e-3,
            format!("{} deg", ms.site.latitude_deg),
        ),
        (
            "site",
            "gravity_mps2",
            (st.site.gravity_mps2 - ms.site.gravity_mps2).abs() <= 1e-4,
            format!("{} m/s^2", ms.site.gravity_mps2),
        ),
        (
            "table",
            "outer_axis",
            close3(st.table.outer_axis.0, ms.table.outer_axis),
            format!("{:?}", ms.table.outer_axis),
        ),
        (
            "table",
            "inner_axis",
            close3(st.table.inner_axis.0, ms.table.inner_axis),
            format!("{:?}", ms.table.inner_axis),
        ),
        (
            "mount",
            "rotation",
            (0..3).all(|i| close3(st.mount.rotation.0[i], mount[i])),
            format!("{mount:?}"),
        ),
    ];
    for (section, key, ok, manifest) in checks {
        if ok {
            continue;
        }
        let name = f.path.display().to_string();
        return Err(Box::new(Contradiction {
            message: format!(
                "{name}: the twin's {section}.{key} contradicts the recording's manifest: not compared"
            ),
            span: station::locate(&f.text, section, key).map(|(a, n)| SourceSpan::new(a.into(), n)),
            src: NamedSource::new(name, f.text.clone()),
            manifest,
        }));
    }
    Ok(())
}

/// The twin's terms and noise as the analysis takes them.
pub fn twin_of(st: &Station) -> Twin {
    let imu = &st.imu;
    // The IMU model holds the nominal terms, the catalogue effects set and the user
    // effects' terms.
    let mut terms: Vec<(String, Vec<f64>)> = st
        .imu_model()
        .terms
        .iter()
        .filter(|t| t.effect.id() != "earth_rate")
        .map(|t| (t.effect.id().to_string(), t.values.clone()))
        .collect();
    for id in st.imu.effects.0.keys() {
        if !terms.iter().any(|t| t.0 == *id)
            && let Some(e) = ratecal_physics::effect(id)
        {
            terms.push((id.clone(), st.imu.effects.values(e)));
        }
    }
    for id in st.table.effects.0.0.keys() {
        if let Some(e) = ratecal_physics::effect(id) {
            terms.push((id.clone(), st.table.effects.0.values(e)));
        }
    }
    let fs = imu.sample_rate.0.sqrt();
    Twin {
        terms,
        t_ref_c: st.temperature.reference.0,
        noise: Rms {
            accel_mps2: imu.accel_noise_density.0 * fs,
            gyro_dps: imu.gyro_noise_density.0 * fs,
        },
        gyro_bias_markov_sigma_dps: imu.gyro_bias_markov_sigma.0,
        gyro_bias_random_walk: imu.gyro_bias_random_walk.0,
    }
}

/// The corrected station file's text and the unified diff from the twin to it, `out` its
/// path as given, opening with the comment `header` (empty: none). A user effect is
/// written by reference to its `.effect` file (`imu.user_effects`), the path relative to
/// `out`'s folder.
pub fn corrected(
    f: &TwinFile,
    changes: &[Change],
    out: &Path,
    header: &str,
) -> Result<(String, String), String> {
    let sets: Vec<SetValue> = changes
        .iter()
        .map(|c| SetValue {
            effect: c.effect.clone(),
            param: c.parameter.clone(),
            value: c.to,
            u: c.u,
            file: match (&c.defined_in, f.station.imu.user_effects.get(&c.effect)) {
                (_, Some(r)) => Some(r.file.clone()),
                (Some(d), None) => Some(relative_to(Path::new(d), out)),
                (None, None) => None,
            },
        })
        .collect();
    let text = header.to_string() + &station::edit(&f.text, &sets)?;
    Station::from_yaml(&text, &out.display().to_string())
        .map_err(|e| format!("the corrected file does not parse: {}", e.message))?;
    let diff = similar::TextDiff::from_lines(&f.text, &text)
        .unified_diff()
        .context_radius(2)
        .header(&f.path.display().to_string(), &out.display().to_string())
        .to_string();
    Ok((text, diff))
}

/// `file` (as given on the command line) as a station file at `out` references it: relative
/// to `out`'s folder when it lies below it, absolute otherwise.
fn relative_to(file: &Path, out: &Path) -> String {
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty());
    let Some(dir) = dir else {
        return file.display().to_string();
    };
    match (file.canonicalize(), dir.canonicalize()) {
        (Ok(f), Ok(d)) => f
            .strip_prefix(&d)
            .map(|r| r.display().to_string())
            .unwrap_or_else(|_| f.display().to_string()),
        _ => file.display().to_string(),
    }
}

/// Writes the draft `.effect` file of every discovered finding the changes add beside
/// `out` (the corrected twin), and points those changes at it (`defined_in`), so that the
/// corrected file references it under `imu.user_effects`.
pub fn write_drafts(
    x: &ratecal_analysis::explain::Explanation,
    changes: &mut [Change],
    out: &Path,
    run: &Path,
) -> std::io::Result<()> {
    use ratecal_analysis::explain::draft;
    let dir = out.parent().unwrap_or(Path::new(""));
    for f in x.findings.iter().filter(|f| f.discovered) {
        if !changes.iter().any(|c| c.effect == f.effect) {
            continue;
        }
        let Some(text) = draft::effect_file(f, &run.display().to_string()) else {
            continue;
        };
        let path = dir.join(draft::file_name(f));
        ratecal_recording::commit::write_nofollow(&path, text.as_bytes())?;
        for c in changes.iter_mut().filter(|c| c.effect == f.effect) {
            c.defined_in = Some(path.display().to_string());
        }
    }
    Ok(())
}
