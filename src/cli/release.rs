//! `ratecal release FOLDER@VERSION --signer NAME --key KEY`: writes that version's line in
//! its folder's `versions.lock` (version, hash, public key, signature, signer), signed with
//! the lab's key. Exit 0 released, 1 refused (does not check, already released, not above
//! the newest release, unreadable key), 2 usage.

use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal release`.
#[derive(clap::Args)]
pub struct Args {
    /// The version to release: folder@version.
    spec: String,
    /// Who releases it (recorded and signed in the line).
    #[arg(long)]
    signer: String,
    /// The lab's private key (`ratecal key new DIR` writes DIR/lab.key).
    #[arg(long)]
    key: PathBuf,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    match ratecal_ops::release::release(&args.spec, &args.signer, &args.key) {
        Ok(line) => {
            outln!("released {}: {}", args.spec, line.trim_end());
            ExitCode::SUCCESS
        }
        Err(e) => {
            errln!("{e:?}");
            ExitCode::from(1)
        }
    }
}
