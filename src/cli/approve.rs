//! `ratecal approve RUN_DIR --signer NAME --role ROLE --key LAB.key`: records in the run
//! folder's seal who approved its results for a certificate (name, role, time, the key's
//! fingerprint), signed with the approver's Ed25519 key over the seal as it is
//! (`ratecal_folder::seal::Approval`). The folder must pass its seal first. Exit 0
//! approved, 1 input error (unreadable key, not a run folder), 4 the seal fails.

use miette::miette;
use ratecal_folder::{names::SEAL_FILE, seal::Seal};
use ratecal_recording::rfc3339;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal approve`.
#[derive(clap::Args)]
pub struct Args {
    /// Run folder (sealed by its run).
    run_dir: PathBuf,
    /// The approver's name, as the certificate's signature block shows it.
    #[arg(long)]
    signer: String,
    /// The approver's role (e.g. "Head of laboratory").
    #[arg(long)]
    role: String,
    /// The approver's private key (`ratecal key new DIR` wrote DIR/lab.key).
    #[arg(long, value_name = "KEY")]
    key: PathBuf,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let dir = &args.run_dir;
    let key = match ratecal_folder::keys::signing_key(&args.key) {
        Ok(k) => k,
        Err(e) => {
            errln!("{e:?}");
            return ExitCode::from(1);
        }
    };
    for (what, value) in [("--signer", &args.signer), ("--role", &args.role)] {
        if value.trim().is_empty() || value.contains('\n') {
            let e = miette!(
                code = "approve::empty",
                help = "give the name and role as the certificate should print them",
                "{what} must be one non-empty line"
            );
            errln!("{e:?}");
            return ExitCode::from(2);
        }
    }
    let _lock = match ratecal_folder::lock::acquire(dir, "approve") {
        Ok(l) => l,
        Err(e) => {
            errln!("{e:?}");
            return ExitCode::from(1);
        }
    };
    if let Err(e) = ratecal_folder::verify::require_intact(dir, "approval") {
        errln!("{e:?}");
        return ExitCode::from(4);
    }
    let text = match std::fs::read_to_string(dir.join(SEAL_FILE)) {
        Ok(t) => t,
        Err(e) => {
            errln!("{:?}", not_sealed(dir, &e.to_string()));
            return ExitCode::from(1);
        }
    };
    let mut seal: Seal = match serde_json::from_str(&text) {
        Ok(s) => s,
        Err(e) => {
            errln!("{:?}", not_sealed(dir, &e.to_string()));
            return ExitCode::from(4);
        }
    };
    let now = rfc3339(std::time::SystemTime::now());
    seal.approve(args.signer.trim(), args.role.trim(), &now, &key);
    if let Err(e) = ratecal_folder::sealing::save(dir, &seal) {
        errln!("cannot write the seal of {}: {e}", dir.display());
        return ExitCode::from(1);
    }
    let a = seal.approval.as_ref().expect("just approved");
    outln!(
        "approved: {} ({}) at {}, key {}",
        a.signer,
        a.role,
        a.time,
        a.key_fingerprint
    );
    ExitCode::SUCCESS
}

fn not_sealed(dir: &std::path::Path, why: &str) -> miette::Report {
    miette!(
        code = "approve::no_seal",
        help = "a run seals its folder when it ends; approve the folder `ratecal run` wrote",
        "cannot read the seal of {}: {why}",
        dir.display()
    )
}
