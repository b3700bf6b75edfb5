//! What `ratecal run` prepares before the interpreter starts: the station, the procedure
//! (text, canonical hash, checked plan), the run folder and its manifest.

use miette::{IntoDiagnostic, Report, WrapErr, miette};
use ratecal_drivers::{DEFAULT_STATION_YAML, MANUAL_STATION_YAML, SWAYING_STATION_YAML, Station};
use ratecal_plan::Plan;
use ratecal_recording::{
    EnvironmentRecord, FORMAT, Manifest, ManifestStation, Mount, ProcedureRef, RunInfo, TableAxes,
    rfc3339, sha256_hex,
};
use std::path::{Path, PathBuf};

use super::imports::Imports;

/// A station and the text it came from.
pub struct LoadedStation {
    /// Parsed station.
    pub station: Station,
    /// Its YAML text (copied into the run folder).
    pub yaml: String,
}

/// Reads a station file (or the embedded default); with `dry_run` both drivers become the
/// simulator, keeping every other key (geometry, IMU model, faults).
pub fn station(path: Option<&Path>, dry_run: bool) -> Result<LoadedStation, Report> {
    station_for(path, dry_run, None)
}

/// The embedded station a procedure runs (and is checked) on without `--station`: the
/// swaying one for a procedure that declares `geometry vertical_outer`, the manual one for
/// a procedure that asks the operator (`place`, `turn`), the default one otherwise.
pub fn builtin_for(procedure_text: &str) -> (&'static str, &'static str) {
    use ratecal_grammar::ast::{Block, ProcItem, Stmt, TopItem};
    fn asks_operator(b: &Block<Stmt>) -> bool {
        b.items.iter().any(|s| match &s.node {
            Stmt::Place { .. } | Stmt::Turn { .. } => true,
            Stmt::For { body, .. } | Stmt::Repeat { body, .. } => asks_operator(body),
            _ => false,
        })
    }
    let Ok(file) = ratecal_grammar::parse(procedure_text) else {
        return (DEFAULT_STATION_YAML, "<default station>");
    };
    let items = file.body.items.iter().flat_map(|it| match &it.node {
        TopItem::Procedure(p) => p.body.items.iter().collect::<Vec<_>>(),
        _ => Vec::new(),
    });
    let (mut vertical, mut manual) = (false, false);
    for pi in items {
        match &pi.node {
            ProcItem::Geometry(g) if g.node == "vertical_outer" => vertical = true,
            ProcItem::Step(s) if asks_operator(&s.body) => manual = true,
            _ => {}
        }
    }
    if vertical {
        (SWAYING_STATION_YAML, "<swaying station>")
    } else if manual {
        (MANUAL_STATION_YAML, "<manual station>")
    } else {
        (DEFAULT_STATION_YAML, "<default station>")
    }
}

/// As [`station`], with `builtin` (YAML, name) in place of the embedded default.
pub fn station_for(
    path: Option<&Path>,
    dry_run: bool,
    builtin: Option<(&str, &str)>,
) -> Result<LoadedStation, Report> {
    let (yaml, name) = match path {
        Some(p) => (
            std::fs::read_to_string(p)
                .into_diagnostic()
                .wrap_err_with(|| format!("cannot read station file {}", p.display()))?,
            p.display().to_string(),
        ),
        None => {
            let (y, n) = builtin.unwrap_or((DEFAULT_STATION_YAML, "<default station>"));
            (y.to_string(), n.to_string())
        }
    };
    let mut station = Station::from_yaml(&yaml, &name).map_err(|e| Report::new(*e))?;
    crate::station::load(&mut station, &yaml, path)?;
    if dry_run && station.table.driver.kind.operator {
        // A manual station's dry run simulates the operator and the IMU in its hand.
        station.table.driver = ratecal_drivers::DriverSpec::new("hand", Default::default())
            .map_err(|e| miette!("internal: {e}"))?;
        station.imu.driver = ratecal_drivers::DriverSpec::sim();
    } else if dry_run {
        station.table.driver = ratecal_drivers::DriverSpec::sim();
        station.imu.driver = ratecal_drivers::DriverSpec::sim();
    }
    Ok(LoadedStation { station, yaml })
}

/// Refuses a released version changed after its release (unless `allow`); with `allow`,
/// what the manifest records.
pub fn released_unchanged(path: &Path, allow: bool) -> Result<Option<String>, Report> {
    let file = crate::procedure::read(&path.display().to_string()).map_err(|d| {
        crate::procedure::report(&d);
        miette!("no procedure to run")
    })?;
    crate::procedure::released_unchanged(&file, allow).map_err(|_| {
        miette!(
            "{}: changed after its release; nothing was run",
            file.display
        )
    })
}

/// A procedure ready to run.
pub struct LoadedProcedure {
    /// The checked plan.
    pub plan: Plan,
    /// The file's text (copied into the run folder).
    pub text: String,
    /// SHA-256 of the canonical text.
    pub sha256: String,
    /// The files it imports (copied into the run folder).
    pub imports: Imports,
}

/// Finds the procedure file: a file, a procedure folder (its newest released version, or
/// with `draft` its newest version) or `folder@version`.
pub fn procedure_file(arg: &Path, draft: bool) -> Result<PathBuf, Report> {
    crate::procedure::resolve_for(&arg.to_string_lossy(), draft).map_err(|d| {
        crate::procedure::report(&d);
        miette!("no procedure to run")
    })
}

/// Refuses a version its folder has not released, unless `allowed` (`--draft`): then what
/// the manifest, results, reports and console say of it (also said now on the console).
pub fn draft(path: &Path, allowed: bool) -> Result<Option<String>, Report> {
    let file = crate::procedure::read(&path.display().to_string()).map_err(|d| {
        crate::procedure::report(&d);
        miette!("no procedure to run")
    })?;
    if crate::release::release_of(&file) != crate::release::Release::Draft {
        return Ok(None);
    }
    let version = path
        .file_name()
        .and_then(|n| ratecal_plan::versions::version_of_file_name(&n.to_string_lossy()))
        .map(|v| v.to_string())
        .unwrap_or_default();
    // `FOLDER@VERSION` as one shell word.
    let at = path
        .parent()
        .map(|p| format!("{}@{version}", p.display()))
        .unwrap_or_default();
    let at = ratecal_folder::shell::quoted(Path::new(&at));
    if !allowed {
        return Err(miette!(
            code = "run::unreleased",
            help = format!(
                "release it (`ratecal release {at} --signer NAME --key lab.key`), or run it as a draft with --draft"
            ),
            "{}: version {version} is not released; nothing was run",
            file.display
        ));
    }
    let note = format!(
        "DRAFT PROCEDURE: {} version {version} is not released (run with --draft)",
        file.display
    );
    errln!("{note}");
    Ok(Some(note))
}

/// Reads, hashes and checks a procedure against the station's limits; its imports come
/// from the lab's files, or with `run_dir` from that run folder's copies.
pub fn procedure(
    path: &Path,
    station: &Station,
    run_dir: Option<&Path>,
) -> Result<LoadedProcedure, Report> {
    let text = std::fs::read_to_string(path)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot read procedure {}", path.display()))?;
    let name = path.display().to_string();
    let imports = match run_dir {
        Some(dir) => Imports::from_run(dir, &name),
        None => Imports::from_files(&name),
    };
    let (plan, sha256) = super::check::plan(path, &text, station, &imports)?;
    Ok(LoadedProcedure {
        plan,
        text,
        sha256,
        imports,
    })
}

/// `runs/<procedure>-<UTC timestamp>` (with `-2`, `-3`... if taken).
pub fn default_out(name: &str) -> PathBuf {
    let stamp: String = rfc3339(std::time::SystemTime::now())
        .chars()
        .filter(|c| c.is_ascii_digit())
        .collect();
    let base = PathBuf::from("runs").join(format!("{name}-{}-{}", &stamp[..8], &stamp[8..]));
    let mut p = base.clone();
    let mut k = 2;
    while p.exists() {
        p = PathBuf::from(format!("{}-{k}", base.display()));
        k += 1;
    }
    p
}

/// What the manifest says about this run before it starts.
pub struct RunFacts<'a> {
    pub dir: &'a Path,
    pub dry_run: bool,
    pub seed: u64,
    pub operator: Option<String>,
    /// Set when a released version changed after release runs (`--allow-changed`).
    pub changed_after_release: Option<String>,
    /// Set when an unreleased version runs (`--draft`): what the outputs say of it.
    pub draft: Option<String>,
}

/// The manifest of a new run.
pub fn manifest(st: &LoadedStation, proc_: &LoadedProcedure, facts: &RunFacts) -> Manifest {
    let info = st.station.describe();
    let g = &info.geometry;
    let c = g.c_pb;
    let rotation = [
        [c[(0, 0)], c[(0, 1)], c[(0, 2)]],
        [c[(1, 0)], c[(1, 1)], c[(1, 2)]],
        [c[(2, 0)], c[(2, 1)], c[(2, 2)]],
    ];
    Manifest {
        format: FORMAT.into(),
        station: ManifestStation {
            site: info.site,
            table: TableAxes {
                outer_axis: [g.outer_axis[0], g.outer_axis[1], g.outer_axis[2]],
                inner_axis: [g.inner_axis[0], g.inner_axis[1], g.inner_axis[2]],
                model: Some(info.table_model.clone()),
            },
            mount: Some(Mount { rotation }),
        },
        imu: [
            ("model", info.imu.model),
            ("serial", info.imu.serial),
            ("grade", info.imu.grade),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect(),
        procedure: Some(ProcedureRef {
            name: proc_.plan.name.clone(),
            version: proc_.plan.version.clone(),
            sha256: proc_.sha256.clone(),
        }),
        segments: Vec::new(),
        environment: info.environment.map(|e| EnvironmentRecord {
            temperature_c: e.temperature_c,
            humidity_pct: e.humidity_pct,
            pressure_kpa: e.pressure_kpa,
            vibration_g: e.vibration_g,
        }),
        run: Some(RunInfo {
            id: facts
                .dir
                .file_name()
                .map_or_else(|| "run".into(), |n| n.to_string_lossy().into_owned()),
            ratecal_version: env!("CARGO_PKG_VERSION").into(),
            dry_run: facts.dry_run,
            started: rfc3339(std::time::SystemTime::now()),
            ended: None,
            status: "running".into(),
            abort: None,
            operator: facts.operator.clone(),
            seed: facts.dry_run.then_some(facts.seed),
            station_sha256: Some(sha256_hex(st.yaml.as_bytes())),
            // The import copies are hashed now; the data files when the run ends.
            files_sha256: proc_.imports.hashes(),
            failure: None,
            resumes: Vec::new(),
            changed_after_release: facts.changed_after_release.clone(),
            draft_procedure: facts.draft.clone(),
            sync: None,
            write_failure: None,
        }),
    }
}
