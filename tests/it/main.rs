//! The integration tests of this crate in one binary (one link instead of one per file).

#[path = "../archive_common/mod.rs"]
mod archive_common;
#[path = "../support/pg.rs"]
mod pg;
#[path = "../support/mod.rs"]
mod support;

mod altered_cli;
mod archive_cleanup;
mod archive_cli;
mod archive_pg;
mod audit_cli;
mod bounded_cli;
mod certificate_assessor;
mod certificate_cli;
mod certificate_pdf;
mod check_station;
mod cli_analyze;
mod cli_check;
mod cli_explain;
mod cli_explain_discover;
mod cli_explain_figures;
mod cli_explain_station;
mod cli_explain_twin;
mod cli_explain_twin_discovered;
mod cli_explain_twin_timing;
mod cli_report;
mod cli_size_effect;
mod crash_cli;
mod explain_across;
mod explain_across_archive;
mod explain_real;
mod harden_cli;
mod import_cli;
mod import_feedback;
mod import_mat;
mod import_real;
mod manual_real;
mod manual_resume;
mod manual_station;
mod progress_log;
mod readme_walkthrough;
mod release_cli;
mod run_cli;
mod run_folder_lock;
mod sanity_cli;
mod seal_cli;
mod verdict_cli;
mod witness_analyze;
mod write_failure_cli;
