//! `ratecal certificate RUN_DIR --lab LAB.yaml [--customer NAME] [--order REF]
//! [--customer-address TEXT] [--received DATE] [--condition TEXT] [--format pdf|html|md|json] [--out FILE] [--archive DIR_OR_URL] [--amend --reason TEXT]
//! [--allow-expired] [--allow-untraceable]` and `ratecal certificate verify FILE.pdf
//! [--archive DIR_OR_URL]`: a calibration certificate (ISO/IEC 17025, 7.8)
//! of an archived, sealed run (`ratecal_ops::certificate`). Exit codes: 0 written (a DRAFT
//! too), 1 input error or refused, 2 usage, 4 the folder fails its seal.

use ratecal_certificate::issue::Request;
use ratecal_ops::certificate::{self as ops, certificate};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal certificate`.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    command: Option<Sub>,
    /// Run folder (sealed, approved with `ratecal approve`, added with `ratecal archive add`).
    #[arg(required = true)]
    run_dir: Option<PathBuf>,
    /// The laboratory: name, address, accreditation, certificate_prefix, signers, optional
    /// logo and template.
    #[arg(long, value_name = "LAB.yaml", required = true)]
    lab: Option<PathBuf>,
    /// The customer, as the certificate names them.
    #[arg(long, value_name = "NAME")]
    customer: Option<String>,
    /// The customer's order reference.
    #[arg(long, value_name = "REF")]
    order: Option<String>,
    /// The customer's address.
    #[arg(long, value_name = "TEXT")]
    customer_address: Option<String>,
    /// The date the item was received (YYYY-MM-DD).
    #[arg(long, value_name = "DATE")]
    received: Option<String>,
    /// The item's condition on receipt.
    #[arg(long, value_name = "TEXT")]
    condition: Option<String>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Pdf)]
    format: Format,
    /// Write here instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// The archive holding the run and the number sequence (default: $RATECAL_ARCHIVE,
    /// else ./archive/).
    #[arg(long, value_name = "DIR_OR_URL")]
    archive: Option<String>,
    /// Issue an amended certificate: a new number that names the one it replaces (needs
    /// --reason).
    #[arg(long)]
    amend: bool,
    /// Why the certificate is amended: printed beside the number it replaces.
    #[arg(long, value_name = "TEXT", requires = "amend")]
    reason: Option<String>,
    /// Issue although the table's calibration had expired on the date of calibration
    /// (printed on the certificate).
    #[arg(long)]
    allow_expired: bool,
    /// Issue although the station states no calibration of the table (printed).
    #[arg(long)]
    allow_untraceable: bool,
}

/// `ratecal certificate verify`.
#[derive(clap::Subcommand)]
enum Sub {
    /// Whether a PDF is a certificate the archive issued, unaltered (exit 0), or not (1).
    Verify {
        /// The certificate's PDF file.
        #[arg(value_name = "FILE.pdf")]
        pdf: PathBuf,
        /// The archive that issued it (default: $RATECAL_ARCHIVE, else ./archive/).
        #[arg(long, value_name = "DIR_OR_URL")]
        archive: Option<String>,
    },
}

/// `--format`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Format {
    /// PDF (a typeset document, fonts embedded).
    Pdf,
    /// Self-contained HTML.
    Html,
    /// Markdown.
    Md,
    /// The certificate's data (`docs/certificate.md`).
    Json,
}

/// Runs the subcommand.
pub fn main(a: Args) -> ExitCode {
    if let Some(Sub::Verify { pdf, archive }) = a.command {
        return ExitCode::from(ops::verify(&pdf, archive.as_deref()));
    }
    let format = match a.format {
        Format::Pdf => ops::Format::Pdf,
        Format::Html => ops::Format::Html,
        Format::Md => ops::Format::Md,
        Format::Json => ops::Format::Json,
    };
    let request = Request {
        run_dir: a.run_dir.unwrap_or_default(),
        lab: a.lab.unwrap_or_default(),
        customer: a.customer,
        order: a.order,
        customer_address: a.customer_address,
        received: a.received,
        condition: a.condition,
        archive: a.archive,
        amend: a.amend,
        reason: a.reason,
        allow_expired: a.allow_expired,
        allow_untraceable: a.allow_untraceable,
    };
    ExitCode::from(certificate(&request, format, a.out.as_deref()))
}
