//! `ratecal import SOURCE... --map MAP.yaml --out RUN_DIR [--station S.yaml]`: a lab's own
//! DAQ files to a recording folder (docs/import.md), with a copy of the station file the
//! recording was measured on when one is given (sealed with it: what `certificate` needs). Prints what it found (segments, up axes, the
//! synthesized table) for the engineer to confirm. Exit codes: 0 written, 1 refused (a
//! located diagnostic; nothing written), 2 usage error (clap).

use ratecal_import::map::Segments;
use ratecal_import::{ImportMap, Summary};
use ratecal_recording::SegmentKind;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal import`.
#[derive(clap::Args)]
pub struct Args {
    /// Source files (read side by side when several: the columns of the second follow
    /// those of the first).
    #[arg(required = true, value_name = "SOURCE")]
    sources: Vec<PathBuf>,
    /// The import map (YAML): columns, units, axes, segments, site.
    #[arg(long, value_name = "MAP.yaml")]
    map: PathBuf,
    /// The recording folder to write (must not exist, or be empty).
    #[arg(long, value_name = "RUN_DIR")]
    out: PathBuf,
    /// The station the recording was measured on: copied into the folder as
    /// `station.yaml` and sealed with it (its Type B figures and the table's calibration,
    /// which `analyze` and `certificate` read).
    #[arg(long, value_name = "S.yaml")]
    station: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let name = args.map.display().to_string();
    let text = match std::fs::read(&args.map) {
        Ok(b) => String::from_utf8_lossy(&b).into_owned(),
        Err(e) => {
            let e = ratecal_import::ImportError::in_file(
                ratecal_import::ErrorKind::Io,
                &name,
                &format!("cannot read the import map: {e}"),
                "--map names the YAML import map (docs/import.md)",
            );
            errln!("{:?}", miette::Report::new(*e));
            return ExitCode::from(1);
        }
    };
    let map = match ratecal_import::load_map(&text, &name) {
        Ok(m) => m,
        Err(e) => {
            errln!("{:?}", miette::Report::new(*e));
            return ExitCode::from(1);
        }
    };
    // The station file is read and checked before anything is written.
    let station = match &args.station {
        Some(path) => match station_copy(path) {
            Ok(text) => Some(text),
            Err(e) => {
                errln!("{e:?}");
                errln!("nothing was written to {}", args.out.display());
                return ExitCode::from(1);
            }
        },
        None => None,
    };
    match ratecal_import::import(&args.sources, &map, &args.out) {
        Ok(mut s) => {
            if let Some(text) = &station {
                let path = s.out.join(ratecal_folder::names::STATION);
                if let Err(e) = ratecal_recording::commit::write_nofollow(&path, text.as_bytes()) {
                    let _ = std::fs::remove_dir_all(&s.out);
                    let e = miette::miette!(
                        code = "import::io",
                        help = "check the space and permissions where --out points",
                        "cannot write {}: {e}",
                        path.display()
                    );
                    errln!("{e:?}");
                    errln!("nothing was written to {}", args.out.display());
                    return ExitCode::from(1);
                }
                s.files.push(ratecal_recording::WrittenFile {
                    name: ratecal_folder::names::STATION.into(),
                    sha256: ratecal_recording::sha256_hex(text.as_bytes()),
                    len: text.len() as u64,
                });
            }
            // Sealed as written, like a run folder: `verify` shows it unaltered and
            // `archive add` accepts it.
            if let Err(e) = ratecal_folder::sealing::write_known(&s.out, None, &s.files) {
                errln!("error: cannot seal {}: {e}", s.out.display());
                return ExitCode::from(1);
            }
            print_summary(&map, &s);
            ExitCode::SUCCESS
        }
        Err(e) => {
            errln!("{:?}", miette::Report::new(*e));
            errln!("nothing was written to {}", args.out.display());
            ExitCode::from(1)
        }
    }
}

/// The station file's text, when it is one (`ratecal check --station` reads it the same
/// way); else its diagnostic.
fn station_copy(path: &std::path::Path) -> miette::Result<String> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| {
        miette::miette!(
            code = "import::station",
            help = "--station names the station file the recording was measured on \
                    (docs/examples/station.yaml shows one)",
            "cannot read {name}: {e}"
        )
    })?;
    ratecal_drivers::Station::from_yaml(&text, &name).map_err(|e| miette::Report::new(*e))?;
    Ok(text)
}

fn print_summary(map: &ImportMap, s: &Summary) {
    outln!(
        "imported {} samples (t = {} to {} s) into {}",
        s.samples,
        s.t.0,
        s.t.1,
        s.out.display()
    );
    let how = match map.segments {
        Segments::None => "none declared",
        Segments::List(_) => "declared in the map",
        Segments::Detect(_) => "detected from the signal: please confirm",
    };
    outln!("segments ({how}):");
    outln!(
        "  {:<16} {:<7} {:>11} {:>11} {:>17}  {:<14} {:>10}",
        "id",
        "kind",
        "t_start s",
        "t_end s",
        "samples",
        "up / axis",
        "|f| m/s^2"
    );
    for f in &s.segments {
        let st = &f.stretch;
        let what = match (f.kind, f.up, f.rate) {
            (SegmentKind::Static, Some(u), _) => u.name(),
            (_, _, Some((a, r))) => format!("{} {r} deg/s", a.name()),
            (SegmentKind::Turn, _, _) => match f.turn.and_then(|t| t.axis.zip(t.angle_deg)) {
                Some(((k, s), a)) => format!(
                    "{}{} {a} deg",
                    if s < 0.0 { "-" } else { "" },
                    ["x", "y", "z"][k]
                ),
                None => "free".into(),
            },
            _ => String::new(),
        };
        outln!(
            "  {:<16} {:<7} {:>11.4} {:>11.4} {:>17}  {:<14} {:>10.4}",
            f.id,
            format!("{:?}", f.kind).to_lowercase(),
            st.t.0,
            st.t.1,
            format!("{}..{}", st.samples.0, st.samples.1 + 1),
            what,
            st.mag_f.median()
        );
    }
    if !s.oblique.is_empty() {
        outln!(
            "note: {} static segment(s) of unknown attitude (hand-held poses) are marked \
             `attitude: unknown` in the manifest: the fits use only gravity's magnitude there",
            s.oblique.len()
        );
    }
    if !s.nominal_by_default.is_empty() {
        outln!(
            "note: {} face(s) without `attitude` in the map are `attitude: nominal` within the \
             import's check of `up` (tolerance_deg: {}): declare `attitude: nominal` with your \
             fixture's tolerance for tighter misalignments",
            s.nominal_by_default.len(),
            ratecal_import::UP_TOLERANCE_DEG
        );
    }
    match &map.table {
        Some(f) => outln!(
            "table: {} feedback samples from {} (manifest provenance.table: feedback)",
            s.table_samples,
            f.file
        ),
        None => outln!(
            "table: synthesized from the segments' attitudes ({} samples at 50 Hz; manifest \
             provenance.table: synthesized)",
            s.table_samples
        ),
    }
}
