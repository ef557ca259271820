//! Error type of the walker simulation.

use std::path::PathBuf;

/// Everything that can go wrong when loading a design or running a walk.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A design file could not be read from disk.
    #[error("cannot read {path}: {source}")]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The TOML did not parse or a field has the wrong type / is unknown / is missing.
    #[error("invalid design TOML in {origin}: {message}")]
    Parse { origin: String, message: String },
    /// A trajectory CSV (from another simulator or a measurement) is malformed.
    #[error("invalid trajectory {origin}: {message}")]
    Trajectory { origin: String, message: String },
    /// A field parsed but its value is physically meaningless.
    #[error("invalid value in {origin}: field `{field}` = {value}: {reason}")]
    InvalidValue {
        origin: String,
        field: String,
        value: String,
        reason: String,
    },
    /// A design name that is neither built in nor an existing file.
    #[error(
        "unknown design `{0}`: expected one of mugatu, zippy, zippy-spherical, mugatu-lab, mugatu-ref, mugatu-ref-sap, zippy-ref, zippy-spherical-ref or a path to a .toml file"
    )]
    UnknownDesign(String),
    /// Bad option passed to a walk (e.g. negative duration).
    #[error("invalid walk option `{option}`: {reason}")]
    InvalidOption { option: String, reason: String },
    /// The state became non-finite (a blow-up); reported instead of panicking.
    #[error("simulation diverged at t = {time_s:.4} s (non-finite state)")]
    Diverged { time_s: f64 },
    /// Writing the trajectory CSV or the plot failed.
    #[error("cannot write {path}: {message}")]
    Output { path: PathBuf, message: String },
}
