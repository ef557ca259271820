//! What several commands share: exit codes, the dataset and method options, the
//! confidence parser, the simulation output format, and printing. Kept in one file below
//! the command files so that none of them reaches into another.

use std::path::PathBuf;

use clap::ValueEnum;
use robot_survey::regression::Method;

/// Exit code: the command ran and found problems.
pub const EXIT_PROBLEMS: u8 = 1;
/// Exit code: the command could not run.
pub const EXIT_ERROR: u8 = 2;

/// Options shared by every command that reads the dataset.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct DatasetArgs {
    /// Dataset directory (default: ./dataset when present, else the bundled copy).
    #[arg(long, value_name = "DIR")]
    pub dataset: Option<PathBuf>,
    /// Use a frozen release (e.g. 1.0.0, the table as the paper used it) instead of the live records.
    #[arg(long, value_name = "X.Y.Z")]
    pub release: Option<String>,
}

/// Line-fitting method (log–log space).
#[derive(ValueEnum, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum MethodArg {
    /// Ordinary least squares of log y on log x (the paper's method; use it to predict y).
    #[default]
    Ols,
    /// Major axis: minimises perpendicular distances (symmetric in x and y).
    Ma,
    /// Standardised major axis (reduced major axis): the usual allometric line.
    Sma,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Ols => Method::Ols,
            MethodArg::Ma => Method::Ma,
            MethodArg::Sma => Method::Sma,
        }
    }
}

/// Parses a confidence level, which must lie in (0, 1).
pub fn parse_confidence(s: &str) -> Result<f64, String> {
    let c: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if c > 0.0 && c < 1.0 {
        Ok(c)
    } else {
        Err(format!("confidence must be in (0, 1), got {c}"))
    }
}

// Output of the simulation and study commands.
#[derive(ValueEnum, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SimFormat {
    /// Human-readable summary.
    #[default]
    Text,
    Json,
}

/// Writes `text` to stdout, ignoring a closed pipe (`survey fit | head`).
pub fn print(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes());
    if !text.ends_with('\n') {
        let _ = out.write_all(b"\n");
    }
}
