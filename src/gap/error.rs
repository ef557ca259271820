//! Errors of the gap diagnosis: each names the file, line and column (or field) at fault.

use std::path::{Path, PathBuf};

use crate::sim::SimError;

#[derive(Debug, thiserror::Error)]
pub enum GapError {
    #[error("{path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}", at_line(path, *line, *column, message))]
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

impl GapError {
    /// An error about the file (or trials) `path` as a whole.
    pub fn file(path: impl ToString, message: impl Into<String>) -> GapError {
        GapError::File {
            path: path.to_string(),
            message: message.into(),
        }
    }

    /// An error at `line` and `column` (0: not known) of the file `path`.
    pub fn at(path: impl ToString, line: u64, column: usize, message: String) -> GapError {
        GapError::Trials {
            path: path.to_string(),
            line,
            column,
            message,
        }
    }

    /// The error of reading `path`, for `map_err`.
    pub fn read(path: &Path) -> impl Fn(std::io::Error) -> GapError + '_ {
        move |source| GapError::Read {
            path: path.to_path_buf(),
            source,
        }
    }

    /// The error of a simulator call about `origin`, for `map_err`.
    pub fn sim(origin: impl ToString) -> impl Fn(SimError) -> GapError {
        let origin = origin.to_string();
        move |source| GapError::Sim {
            origin: origin.clone(),
            source,
        }
    }
}

/// Checks the relative sd assumed where a measurement states none.
pub fn check_default_sd(sd: f64) -> Result<(), GapError> {
    let message = "the default relative sd must be finite and > 0";
    (sd > 0.0 && sd.is_finite())
        .then_some(())
        .ok_or_else(|| GapError::Invalid(message.into()))
}

/// The text of the file at `path`.
pub fn read_text(path: &Path) -> Result<String, GapError> {
    std::fs::read_to_string(path).map_err(GapError::read(path))
}

/// `file:line:column: message`, the column left out when it is not known (0).
fn at_line(path: &str, line: u64, column: usize, message: &str) -> String {
    match column {
        0 => format!("{path}:{line}: {message}"),
        c => format!("{path}:{line}:{c}: {message}"),
    }
}
