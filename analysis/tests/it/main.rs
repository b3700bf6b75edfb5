//! The integration tests of this crate in one binary (one link instead of one per file).

#[path = "../../../tests/support/station/mod.rs"]
mod common;
#[path = "../fit_support/mod.rs"]
mod fit_support;
#[path = "../../../tests/support/shared.rs"]
mod shared;
#[path = "../size_effect_support/mod.rs"]
mod size_effect_support;

mod accept_derived;
mod effects_sim;
mod explain_adopt;
mod explain_combos;
mod explain_sim;
mod explain_user;
mod ferraris_real;
mod fit_example;
mod fit_plan;
mod fit_sim;
mod fit_stream;
mod open_world;
mod recording_garbage;
mod size_effect;
mod size_effect_closed_form;
mod user_effects;
mod witness_change_points;
mod witness_discover;
mod witness_manual;
mod witness_open_world;
mod witness_station;
mod witness_table_unknown;
mod witness_tau_coverage;
