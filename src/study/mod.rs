//! Studies over the walker simulator: sweeps and searches that call `sim` many times.
//!
//! * [`min_torque`]: the minimum hip torque at which a design walks consistently, by
//!   bracketing and bisection (the problem, "walks at τ?", separate from the solver).

pub mod min_torque;

pub use min_torque::{MinTorqueOptions, MinTorqueResult, min_torque};
