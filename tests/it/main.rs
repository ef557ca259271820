//! One integration-test crate: each module was once its own test binary; linking the
//! crate and its dependencies once instead of fourteen times is most of a fresh `cargo test`.

mod cli;
mod common;
mod diff;
mod drake_crosscheck;
mod gap;
mod gap_cases;
mod gap_logs;
mod gap_open;
mod gap_posterior;
mod gap_spread;
mod gap_units;
mod interop;
mod live_dataset;
mod load_fuzz;
mod min_torque;
mod motors;
mod readme;
mod regression_hand;
mod regression_smatr;
mod sim_cli;
mod sim_effects;
mod sim_physics;
mod sim_scaling;
mod sim_walk;
mod speed;
mod survey_html;
mod survey_inference;
mod table2;
mod table3;
mod torque_check;
mod upstream_import;
mod validate_corpus;
