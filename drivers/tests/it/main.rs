//! The integration tests of this crate in one binary (one link instead of one per file).

mod line_table;
mod replay;
mod sim_behaviour;
mod sim_closed_forms;
mod sim_registry_terms;
mod sim_speed;
mod station_drivers;
mod station_edit;
mod station_file;
mod station_garbage;
