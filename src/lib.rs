//! robot-survey: allometric scaling of legged robots.
//!
//! The library is organised by concern; the `survey` binary is a thin layer over it.
//! - [`dataset`]: curated robot records, upstream import, validation, frozen releases.
//! - [`regression`]: log–log power laws (OLS, MA, SMA), intervals, tests, diagnostics.
//! - [`survey`]: the paper's analyses over a dataset (Table 2, predictions).
//! - [`sim`]: 3D quasi-passive walker simulation; [`scaling`]: the scaling study over it.
//! - [`study`]: searches over the simulator (minimum walking torque).
//! - [`gap`]: sim-to-real gap diagnosis (trials, candidate effects, fitting, benchmark).
//! - [`crosscheck`]: the simulator against Drake on identical models (goldens from tools/drake/).
//! - [`predict`], [`inference`], [`laws`]: designer predictions, hypothesis tests, Table 1.
//! - [`motors`]: the motor catalogue (scaling laws, actuator datasheets, anchors) and its validation.
//! - [`diff`]: the live records against a frozen release, for a pull request's reviewer.
//! - [`checkpoint`]: points files of long runs: resume after an interruption, shards, merge.
//! - [`report`]: output formats (md, tex, csv, json) and figures.

pub mod checkpoint;
pub mod crosscheck;
pub mod dataset;
pub mod diff;
pub mod gap;
pub mod inference;
pub mod laws;
pub mod motors;
pub mod predict;
pub mod regression;
pub mod report;
pub use study::scaling;
pub mod sim;
pub mod study;
pub mod survey;
