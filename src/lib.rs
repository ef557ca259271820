//! robot-survey: allometric scaling of legged robots.
//!
//! The library is organised by concern; the `survey` binary is a thin layer over it.
//! - [`dataset`]: curated robot records, upstream import, validation, frozen releases.
//! - [`regression`]: log–log power laws (OLS, MA, SMA), intervals, tests, diagnostics.
//! - [`analysis`]: the paper's analyses over a dataset: Table 2, designer predictions,
//!   hypothesis tests, Table 1 (the laws), the live records against a frozen release.
//! - [`sim`]: 3D quasi-passive walker simulation.
//! - [`study`]: studies over the simulator (the scaling study, Table III, minimum walking
//!   torque, feet, torque checks).
//! - [`gap`]: sim-to-real gap diagnosis (trials, candidate effects, fitting, benchmark).
//! - [`crosscheck`]: the simulator against Drake on identical models (goldens from tools/drake/).
//! - [`motors`]: the motor catalogue (scaling laws, actuator datasheets, anchors) and its validation.
//! - [`checkpoint`]: points files of long runs: resume after an interruption, shards, merge.
//! - [`report`]: output formats (md, tex, csv, json) and figures.
//! - [`interop`]: designs as MJCF, URDF and SDF (export) and robot files as designs (import).
//! - [`io`]: writing files atomically.
//! - [`progress`]: what long runs report as they go (an [`progress::Observer`]) and their
//!   timings.

pub mod analysis;
pub mod checkpoint;
pub mod crosscheck;
pub mod dataset;
pub mod gap;
pub mod interop;
pub mod io;
pub mod motors;
pub mod progress;
pub mod regression;
pub mod report;
pub mod sim;
pub mod study;
