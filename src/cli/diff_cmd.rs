//! `survey diff`: the live records against a frozen release, for a pull request's reviewer.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use robot_survey::dataset::Dataset;
use robot_survey::report::{self, Format};

use super::common::{EXIT_PROBLEMS, MethodArg, parse_confidence, print};

#[derive(Args, Debug)]
#[command(
    after_help = "Examples:\n  survey diff                      # live records against the latest release\n  survey diff --against 1.0.0 --format json\n\n\
Exit code 1 when the live records bring new validation errors, 0 otherwise."
)]
pub struct DiffArgs {
    /// Dataset directory whose live records are compared (default: ./dataset when present,
    /// else the bundled copy).
    #[arg(long, value_name = "DIR")]
    pub dataset: Option<PathBuf>,
    /// Frozen release to compare against (default: the latest release).
    #[arg(long, value_name = "X.Y.Z")]
    pub against: Option<String>,
    /// Output: md (for a review comment) or json.
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
    /// Line-fitting method of the Table 2 entries.
    #[arg(long, value_enum, default_value_t)]
    pub method: MethodArg,
    /// Confidence level of the intervals of b (an exponent outside the release's interval is flagged).
    #[arg(long, default_value_t = 0.95, value_parser = parse_confidence)]
    pub confidence: f64,
}

pub fn diff(a: &DiffArgs) -> anyhow::Result<ExitCode> {
    let ds = Dataset::locate(a.dataset.as_deref())?;
    let d = robot_survey::analysis::release_diff::diff(
        &ds,
        a.against.as_deref(),
        a.method.into(),
        a.confidence,
    )?;
    print(&match a.format {
        Format::Json => report::json(&d)?,
        Format::Md => report::diff_md(&d),
        f => anyhow::bail!("--format {f:?} is not available for diff (use md or json)"),
    });
    Ok(if d.new_errors() > 0 {
        ExitCode::from(EXIT_PROBLEMS)
    } else {
        ExitCode::SUCCESS
    })
}
