//! What several commands share: exit codes, the dataset and method options, the
//! confidence parser, the simulation output format, printing, and how a library run's
//! progress is shown. Kept in one file below the command files so that none of them
//! reaches into another.

use std::path::PathBuf;

use clap::ValueEnum;
use indicatif::ProgressBar;
use robot_survey::progress::Observer;
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

/// A survey variable by name: `speed` is the speed of `kind`; otherwise leg_length,
/// body_length, mass or a speed of a named kind (speed_top, …).
pub fn parse_var(
    s: &str,
    kind: robot_survey::dataset::SpeedKind,
) -> anyhow::Result<robot_survey::analysis::table2::Var> {
    use robot_survey::analysis::table2::Var;
    if s == "speed" {
        return Ok(Var::speed(kind));
    }
    Var::parse(s).ok_or_else(|| {
        anyhow::anyhow!(
            "unknown variable `{s}` (one of: leg_length, body_length, mass, speed — with --speed-kind top|typical|walking|running|unstated)"
        )
    })
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

/// Tells on stderr which files a command wrote.
pub fn report_written(paths: &[PathBuf]) {
    eprintln!(
        "wrote {}",
        paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
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

/// A progress bar of `len` units drawn with the indicatif `template` (its default style if
/// the template does not parse).
pub fn templated_bar(len: u64, template: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template(template)
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// A library run's progress on stderr: the CLI's [`Observer`], in the three forms its
/// commands use. Only what is shown lives here; the run decides what to report.
pub enum Progress {
    /// A bar (`{pos}/{len}` in its template): each finished unit advances it, each stage
    /// becomes its message.
    Bar(ProgressBar),
    /// A spinner: each finished unit counts and turns it, each stage becomes its message and
    /// turns it (it moves only when there is news, unless it has a steady tick).
    Spinner(ProgressBar),
    /// Each stage a line (a run of minutes to hours, whose log is worth keeping).
    Lines,
}

impl Progress {
    /// Takes a bar or spinner off the terminal once the run is over.
    pub fn clear(&self) {
        if let Progress::Bar(bar) | Progress::Spinner(bar) = self {
            bar.finish_and_clear();
        }
    }
}

impl Observer for Progress {
    fn tick(&self) {
        match self {
            Progress::Bar(bar) => bar.inc(1),
            Progress::Spinner(spinner) => {
                spinner.inc(1);
                spinner.tick();
            }
            Progress::Lines => {}
        }
    }

    fn stage(&self, what: &str) {
        match self {
            Progress::Bar(bar) => bar.set_message(what.to_string()),
            Progress::Spinner(spinner) => {
                spinner.set_message(what.to_string());
                spinner.tick();
            }
            Progress::Lines => eprintln!("{what}"),
        }
    }
}
