//! Errors of the gap diagnosis: each names the file, line and column (or field) at fault.

use std::path::PathBuf;

use crate::sim::SimError;

#[derive(Debug, thiserror::Error)]
pub enum GapError {
    #[error("{path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}:{line}:{column}: {message}")]
    Trials {
        path: String,
        line: u64,
        column: usize,
        message: String,
    },
    #[error("{path}: {message}")]
    File { path: String, message: String },
    #[error("effect library: {0}")]
    Library(String),
    #[error("--effect {spec}: {reason}")]
    EffectArg { spec: String, reason: String },
    #[error("{origin}: {source}")]
    Sim { origin: String, source: SimError },
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Checkpoint(#[from] crate::checkpoint::CheckpointError),
}
