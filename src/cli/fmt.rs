//! `ratecal fmt`: rewrite procedures in canonical layout; `--check` only reports the files
//! that are not canonical (exit 1).

use ratecal_ops::procedure;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `ratecal fmt`.
#[derive(clap::Args)]
pub struct Args {
    /// Procedure files or folders (every procedure file below a folder).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Do not write: list the files that are not in canonical layout and exit 1.
    #[arg(long)]
    check: bool,
}

fn collect(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() || p.extension().is_some_and(|x| x == procedure::EXTENSION) {
                collect(&p, out);
            }
        }
    } else {
        out.push(path.to_path_buf());
    }
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let mut files = Vec::new();
    for i in &args.inputs {
        collect(i, &mut files);
    }
    let mut bad = false;
    for f in files {
        let file = match procedure::read(&f.to_string_lossy()) {
            Ok(x) => x,
            Err(d) => {
                procedure::report(&d);
                bad = true;
                continue;
            }
        };
        let canon = match ratecal_grammar::canonical(&file.text) {
            Ok(c) => c,
            Err(d) => {
                procedure::report(
                    &d.with_source(&ratecal_grammar::source(&file.display, &file.text)),
                );
                bad = true;
                continue;
            }
        };
        if canon.text == file.text {
            continue;
        }
        if args.check {
            outln!("not canonical: {}", file.display);
            bad = true;
        } else if let Err(e) = std::fs::write(&file.path, &canon.text) {
            errln!("ratecal fmt: cannot write {}: {e}", file.display);
            bad = true;
        } else {
            errln!("formatted {}", file.display);
        }
    }
    if bad {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
