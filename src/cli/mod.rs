//! Command-line parsing and dispatch. Exit codes follow ripgrep: 0 success, 1 problems
//! found (validation errors, a check that failed), 2 could not run (bad input, I/O).

mod common;
mod dataset_cmd;
mod diff_cmd;
mod fit_cmd;
mod gap;
mod gap_benchmark;
mod sim;
mod study;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use common::EXIT_ERROR;

#[derive(Parser, Debug)]
#[command(
    name = "survey",
    version,
    about = "Allometric scaling of legged robots: curated dataset, power-law fits, walker simulation",
    long_about = "Allometric scaling of legged robots.\n\n\
        The curated dataset of legged robots (default: ./dataset when present, else the copy \
        bundled into this binary) is validated with `survey validate`, fitted with `survey fit` \
        (the paper's Table 2), queried with `survey predict` and `survey test`, and the \
        quasi-passive walkers of the paper are simulated with `survey sim walk` and `survey sim scale`.\n\n\
        Exit codes: 0 success, 1 problems found, 2 could not run."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Check every record of the dataset and the frozen releases; report every problem.
    Validate(dataset_cmd::ValidateArgs),
    /// Fit the survey's power laws per class (the paper's Table 2).
    Fit(fit_cmd::FitArgs),
    /// Compare the live records with a frozen release: records, validation, Table 2.
    Diff(diff_cmd::DiffArgs),
    /// Predict mass and body length for a target leg length (or leg length for a mass budget).
    Predict(fit_cmd::PredictArgs),
    /// Hypothesis tests on the power laws (slope value, common slope, elevation).
    Test(fit_cmd::TestArgs),
    /// The scaling-law comparison: isometric vs biology vs robotics (the paper's Table 1).
    Laws(fit_cmd::LawsArgs),
    /// Work on the dataset itself: import the upstream table, format records, cut releases.
    Dataset(dataset_cmd::DatasetCmdArgs),
    /// Simulate the quasi-passive walkers (Mugatu, Zippy).
    Sim(sim::SimArgs),
    /// The sim-to-real gap: where the simulation misses measured trials, which unmodelled
    /// effect explains it, how far the gap shrinks (and synthetic trials to prove it).
    Gap(gap::GapArgs),
    /// Walker hip torque against motor-torque scaling laws: Table III's minimum torque
    /// across leg length beside what each law delivers, under two explicit bridges between
    /// motor size and robot size (isometric actuator; fixed actuator mass fraction).
    TorqueCheck(study::TorqueCheckArgs),
}

/// Entry point: parse, run, map errors to exit codes.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // --help and --version are not errors.
            let code = if e.use_stderr() { EXIT_ERROR } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("survey: error: {}", error_chain(&e));
            ExitCode::from(EXIT_ERROR)
        }
    }
}

/// The error and its causes, "outer: cause: …", leaving out a cause whose text the message
/// already ends with (most of the crate's errors print their source at the end of their own
/// message, "{path}: {source}", and `{:#}` would repeat it). Only a repeat at the end is
/// dropped: a short cause that happens to appear mid-message is still printed, so no cause is
/// ever lost.
pub fn error_chain(e: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if !text.is_empty() && message.ends_with(&text) {
            continue;
        }
        if !message.is_empty() {
            message.push_str(": ");
        }
        message.push_str(&text);
    }
    message
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Validate(a) => dataset_cmd::validate(&a),
        Command::Fit(a) => fit_cmd::fit(&a),
        Command::Diff(a) => diff_cmd::diff(&a),
        Command::Predict(a) => fit_cmd::predict(&a),
        Command::Test(a) => fit_cmd::test(&a),
        Command::Laws(a) => fit_cmd::laws(&a),
        Command::Dataset(a) => dataset_cmd::run(&a),
        Command::Sim(a) => sim::run(&a),
        Command::Gap(a) => gap::run(&a),
        Command::TorqueCheck(a) => study::torque_check(&a),
    }
}

#[cfg(test)]
mod tests {
    use super::error_chain;

    #[derive(Debug)]
    struct Wrapped {
        text: String,
        source: std::io::Error,
    }
    impl std::fmt::Display for Wrapped {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str(&self.text)
        }
    }
    impl std::error::Error for Wrapped {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.source)
        }
    }

    fn chain_of(text: &str, cause: &str) -> String {
        let e = Wrapped {
            text: text.to_string(),
            source: std::io::Error::other(cause.to_string()),
        };
        error_chain(&anyhow::Error::new(e))
    }

    #[test]
    fn a_cause_printed_at_the_end_of_its_message_is_not_repeated() {
        assert_eq!(
            chain_of("/x.csv: no such file", "no such file"),
            "/x.csv: no such file"
        );
    }

    #[test]
    fn a_cause_found_only_mid_message_is_kept() {
        // "bad" appears inside the message but is not its source's rendering at the end
        assert_eq!(
            chain_of("bad row 3 in x.csv", "bad"),
            "bad row 3 in x.csv: bad"
        );
        assert_eq!(chain_of("reading x.csv", "denied"), "reading x.csv: denied");
    }
}
