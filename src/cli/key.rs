//! `ratecal key new DIR`: creates DIR and writes a new Ed25519 key pair for signing run
//! seals, `DIR/lab.key` (private, PKCS#8 PEM, readable by its owner only) and `DIR/lab.pub`
//! (public, SPKI PEM, for `ratecal verify RUN --key DIR/lab.pub`). Exit 0, or 1 when DIR
//! cannot be written or already holds a key.

use ed25519_dalek::SigningKey;
use ed25519_dalek::pkcs8::{EncodePrivateKey, EncodePublicKey, spki::der::pem::LineEnding};
use miette::{Report, miette};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `ratecal key`.
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    action: Action,
}

#[derive(clap::Subcommand)]
enum Action {
    /// Create DIR and write a new key pair: DIR/lab.key (keep it secret) and DIR/lab.pub.
    New {
        /// Folder to create for the key pair.
        dir: PathBuf,
    },
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let Action::New { dir } = args.action;
    match new(&dir) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            errln!("{e:?}");
            ExitCode::from(1)
        }
    }
}

fn new(dir: &Path) -> Result<(), Report> {
    let (secret, public) = (dir.join("lab.key"), dir.join("lab.pub"));
    if secret.exists() || public.exists() {
        return Err(miette!(
            code = "key::exists",
            help = "choose another folder: a lab key is never overwritten",
            "{} already holds a key",
            dir.display()
        ));
    }
    let io = |e: &dyn std::fmt::Display| {
        miette!(
            code = "key::io",
            help = "check that the folder can be created and written",
            "cannot write the key pair in {}: {e}",
            dir.display()
        )
    };
    let mut seed = [0u8; 32];
    getrandom::fill(&mut seed).map_err(|e| io(&e))?;
    let key = SigningKey::from_bytes(&seed);
    let pem = key.to_pkcs8_pem(LineEnding::LF).map_err(|e| io(&e))?;
    let pub_pem = key
        .verifying_key()
        .to_public_key_pem(LineEnding::LF)
        .map_err(|e| io(&e))?;
    std::fs::create_dir_all(dir).map_err(|e| io(&e))?;
    let mut opts = std::fs::OpenOptions::new();
    opts.write(true).create_new(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut opts, 0o600);
    opts.open(&secret)
        .and_then(|mut f| f.write_all(pem.as_bytes()))
        .map_err(|e| io(&e))?;
    std::fs::write(&public, pub_pem).map_err(|e| io(&e))?;
    outln!("private key: {} (keep it secret)", secret.display());
    outln!("public key:  {}", public.display());
    Ok(())
}
