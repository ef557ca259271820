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
    /// A data file (motor laws, actuators) that does not parse or holds a bad value.
    #[error("{origin}: {message}")]
    Data { origin: String, message: String },
}
