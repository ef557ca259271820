//! Errors of the studies over the simulator.

use crate::regression::RegressionError;
use crate::sim::SimError;

#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error(transparent)]
    Regression(#[from] RegressionError),
    /// A study option that cannot be run.
    #[error("invalid study option `{option}`: {reason}")]
    InvalidOption { option: String, reason: String },
    #[error(transparent)]
    Checkpoint(#[from] crate::checkpoint::CheckpointError),
    /// The actuator catalogue (`./dataset/motors` or the bundled one) does not load.
    #[error(transparent)]
    Motors(#[from] crate::motors::MotorError),
    /// `survey predict --torque-margin`: the stall torque's margin over the requirement.
    #[error("--torque-margin must be > 0, got {0}")]
    TorqueMargin(f64),
    /// A data file (motor laws, actuators) that does not parse or holds a bad value.
    #[error("{origin}: {message}")]
    Data { origin: String, message: String },
}
