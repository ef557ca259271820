//! Errors of the regression engine.
//!
//! Every failure on user-controlled input is reported through [`RegressionError`]
//! (never a panic), with enough context (variable, index, group) for the caller to
//! point at the offending data row.

use thiserror::Error;

/// Why a fit, test, or resampling could not be carried out.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RegressionError {
    /// `x` and `y` must pair up one-to-one.
    #[error("x and y have different lengths ({x_len} vs {y_len})")]
    LengthMismatch {
        /// Length of the x slice.
        x_len: usize,
        /// Length of the y slice.
        y_len: usize,
    },
    /// A line with intercept has n − 2 residual degrees of freedom, so n ≥ 3 is required.
    #[error("need at least {needed} points, got {got}")]
    TooFewPoints {
        /// Minimum number of points for the requested computation.
        needed: usize,
        /// Number of points supplied.
        got: usize,
    },
    /// NaN or ±∞ in the input.
    #[error("{variable}[{index}] = {value} is not finite")]
    NonFinite {
        /// Which input (`"x"` or `"y"`).
        variable: &'static str,
        /// Zero-based position in the input slice.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A log10 transform needs strictly positive data.
    #[error("{variable}[{index}] = {value} is not positive; log10 needs values > 0")]
    NonPositive {
        /// Which input (`"x"` or `"y"`).
        variable: &'static str,
        /// Zero-based position in the input slice.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// All values of a variable are (numerically) equal, so no line is identifiable.
    #[error("{variable} has zero variance")]
    ZeroVariance {
        /// Which input (`"x"` or `"y"`).
        variable: &'static str,
    },
    /// MA and SMA slopes take their sign from the covariance; with Sxy = 0 they are undefined.
    #[error("x and y are uncorrelated (Sxy = 0): the {method} slope is undefined")]
    ZeroCovariance {
        /// The method whose slope is undefined.
        method: &'static str,
    },
    /// Confidence levels are probabilities strictly between 0 and 1.
    #[error("confidence level must lie strictly between 0 and 1, got {0}")]
    InvalidLevel(f64),
    /// A parameter outside its domain (e.g. a non-finite test value, zero replicates).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// A problem within one group of a multi-group comparison.
    #[error("group {label:?}: {source}")]
    InGroup {
        /// Label of the failing group.
        label: String,
        /// The underlying error.
        source: Box<RegressionError>,
    },
    /// Sums overflowed or an iteration failed to converge.
    #[error("numerical failure: {0}")]
    Numerical(String),
}
