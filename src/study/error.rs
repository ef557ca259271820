//! Errors of the studies over the simulator.

use std::path::PathBuf;

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
    #[error("cannot read or write {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A points file (checkpoint or shard) that cannot be used.
    #[error("{path}: {message}")]
    Points { path: PathBuf, message: String },
    /// A data file (motor laws, actuators) that does not parse or holds a bad value.
    #[error("{origin}: {message}")]
    Data { origin: String, message: String },
}

impl StudyError {
    pub(crate) fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        StudyError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
    pub(crate) fn points(path: &std::path::Path, message: impl Into<String>) -> Self {
        StudyError::Points {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}
