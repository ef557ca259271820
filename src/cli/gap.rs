//! `survey gap …`: the sim-to-real gap diagnosis.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand, ValueEnum};
use robot_survey::gap::{self, DiagnoseOptions, EffectLibrary, TrialSet};
use robot_survey::io::write_atomic;
use robot_survey::report;
use robot_survey::sim::Design;

use super::common::{Progress, print, templated_bar};

#[derive(Args, Debug)]
pub struct GapArgs {
    #[command(subcommand)]
    pub command: GapCommand,
}

#[derive(Subcommand, Debug)]
pub enum GapCommand {
    /// List the candidate unmodelled effects (dataset/effects/): what each models, its
    /// parameters with unit, default and plausible range (SI, for a design at 1×).
    Effects(EffectsArgs),
    /// Simulate "real" trials with effects the nominal model lacks, plus measurement noise.
    Synth(SynthArgs),
    /// Where the simulation misses the trials, and how probable each explanation is: nothing
    /// off, a declared parameter off, a library effect missing, two at once, an undeclared
    /// number off, or something outside all of these.
    Diagnose(DiagnoseArgs),
    /// Which settings of the designs' declared uncertain parameters fit the trials at all:
    /// a Latin hypercube over their whole ranges (history matching), what each parameter
    /// is pinned to, and how far each measured metric can be reached.
    Explore(ExploreArgs),
    /// The next trials to run: the conditions at the robot's own size (drive frequency,
    /// amplitude, payload, slope) whose measurement is expected to reduce the posterior's
    /// entropy most, computed with the simulator.
    Suggest(SuggestArgs),
    /// The diagnosis on cases of known cause (nulls, single effects, pairs, parameter errors,
    /// Drake-made trials): scores, the calibration of its probabilities, and the decision's
    /// threshold chosen on half of the cases and verified on the other half.
    Benchmark(Box<super::gap_benchmark::BenchmarkArgs>),
}

#[derive(Clone, Copy, Debug, Default, ValueEnum)]
pub enum GapFormat {
    #[default]
    Text,
    Json,
}

#[derive(Args, Debug)]
pub struct EffectsArgs {
    /// Design whose 1× size sets the SI values of the ranges.
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    #[arg(long, value_enum, default_value_t)]
    pub format: GapFormat,
}

#[derive(Args, Debug)]
#[command(after_help = "Examples:\n  \
survey gap synth --effect hip_coulomb_friction=0.05 --noise 0.05 --seed 1 --out trials.csv\n  \
survey gap synth --design zippy --effect soft_ground=2e6 --effect actuation_latency.latency_s=0.004 \
--noise 0.02 --seed 7 --out z.csv\n  \
survey gap synth --noise 0.05 --seed 3 --out null.csv        # the null case: no effect\n\n\
Values are in SI at the design's 1× size (see `survey gap effects --design D`); each trial scales \
them with its size by the effect's rule. Default conditions: the design at 3–4 sizes × the drive \
frequencies (0.94–1.06 × its own) at which the nominal design walks, at least 12.")]
pub struct SynthArgs {
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    /// A trials CSV whose conditions to simulate (its measurements are ignored).
    #[arg(long, value_name = "FILE")]
    pub conditions: Option<PathBuf>,
    /// NAME=VALUE sets an effect's magnitude (its first parameter), NAME.PARAM=VALUE one
    /// parameter; repeat for several. None: the null case.
    #[arg(long = "effect", value_name = "NAME=VALUE")]
    pub effects: Vec<String>,
    /// PATH=VALUE: the robot differs from its design file here (a dotted path of the design
    /// TOML at 1×, e.g. mass.leg_com_height_over_l=0.52): trials of a robot whose nominal
    /// parameters are wrong. Repeat for several.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,
    /// Relative sd of the Gaussian measurement noise (written into the _sd columns).
    #[arg(long, default_value_t = 0.05)]
    pub noise: f64,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Write the expected values: no noise drawn, the _sd columns as --noise gives them. What
    /// such trials show on average: `gap diagnose`'s answer without the draw's luck either way
    /// (a draw can mislead it where these do not). A cause it cannot name is either not
    /// identifiable from these conditions at this noise (a simpler model fits within noise:
    /// gap left ≤ 1) or missed by its search (gap left beyond noise although the truth fits
    /// exactly). (Logs, with --logs, keep their sensor noise.)
    #[arg(long)]
    pub expected: bool,
    /// Output trials CSV.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Also write each trial's log (time, hip angle, roll/pitch/yaw, hip torque, with white
    /// sensor noise) into this folder, named in the trials' `trajectory` column: the cycles `survey gap diagnose`
    /// adds to its likelihood.
    #[arg(long, value_name = "DIR")]
    pub logs: Option<PathBuf>,
    /// Sensor noise of the logs' angles: sd of each sample [deg].
    #[arg(long, default_value_t = 0.3, requires = "logs")]
    pub sensor_noise_deg: f64,
    /// Sensor noise of the logs' hip torque: sd of each sample as a fraction of the log's
    /// largest |torque|.
    #[arg(long, default_value_t = 0.03, requires = "logs")]
    pub sensor_noise_torque: f64,
}

#[derive(Args, Debug)]
#[command(after_help = "Examples:\n  \
survey gap diagnose --trials dataset/trials/published.csv --plot residuals.svg\n  \
survey gap diagnose --trials t.csv --reference before.csv      # what changed between them\n  \
survey gap diagnose --trials t.csv --format json > d.json\n\n\
The answer is the posterior probability of every explanation (dataset/gap/criterion.toml holds \
the priors and the decision; docs/gap-criterion.md the method). Trials whose `trajectory` column \
names a log add its cycles to the same likelihood. Text and JSON give the same answer. Exit code \
0 whatever the answer.")]
pub struct DiagnoseArgs {
    /// Trials CSV (format: dataset/trials/README.md).
    #[arg(long, value_name = "FILE")]
    pub trials: PathBuf,
    /// Candidate effects, comma-separated (default: the whole library).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Walks per suspect across its range before the curve is refined where it bends.
    #[arg(long, default_value_t = 9)]
    pub grid: usize,
    /// Relative sd assumed where a measurement states none.
    #[arg(long, default_value_t = 0.10)]
    pub default_sd: f64,
    /// Take the designs' declared [[uncertain]] values as right: only effects (and
    /// undeclared numbers) are suspects.
    #[arg(long)]
    pub no_calibration: bool,
    /// Leave the designs' undeclared numbers out of the suspects (fewer walks).
    #[arg(long)]
    pub no_undeclared: bool,
    /// Trials of the same robot without the change asked about (before a damper, on the old
    /// floor, the same model without an effect), at the same conditions. The diagnosis is
    /// then of the change: each metric (and logged cycle) is carried onto the model as
    /// nominal + (trial − reference), so a discrepancy the model has everywhere cancels.
    /// Trust it where the model walks the robot's gait.
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
    /// A criterion file in place of the bundled dataset/gap/criterion.toml (priors, decision).
    #[arg(long, value_name = "FILE")]
    pub criterion: Option<PathBuf>,
    /// Confirm every explanation by walks, not only the leading ones (slow: measures what the
    /// search misses).
    #[arg(long)]
    pub exhaustive: bool,
    #[arg(long, value_enum, default_value_t)]
    pub format: GapFormat,
    /// Figure of the standardised residuals per condition, before and after (SVG or PNG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

impl DiagnoseArgs {
    /// The diagnosis' options these arguments ask for.
    pub fn options(&self) -> anyhow::Result<DiagnoseOptions> {
        let mut opts = DiagnoseOptions::new()?;
        opts.reference = self.reference.as_deref().map(TrialSet::read).transpose()?;
        opts.effects = self.effects.clone();
        opts.grid_points = self.grid;
        opts.default_relative_sd = self.default_sd;
        opts.calibrate = !self.no_calibration;
        opts.undeclared = !self.no_undeclared;
        if let Some(c) = &self.criterion {
            opts.criterion = gap::criterion::Criterion::read(c)?;
        }
        opts.search.exhaustive = self.exhaustive;
        Ok(opts)
    }
}

#[derive(Args, Debug)]
#[command(after_help = "Examples:\n  \
survey gap explore --trials dataset/trials/zippy-calibration.csv --samples 512\n  \
survey gap explore --trials dataset/trials/zippy-top-speed.csv --format json\n\n\
A setting is plausible when its χ² against the trials has p ≥ 0.05 (χ² with one degree of freedom \
per measurement). Every sample walks every condition of the trials file; the sample is \
deterministic in --seed.")]
pub struct ExploreArgs {
    /// Trials CSV (format: dataset/trials/README.md); its designs must declare [[uncertain]].
    #[arg(long, value_name = "FILE")]
    pub trials: PathBuf,
    /// Parameter settings walked (Latin hypercube).
    #[arg(long, default_value_t = 256)]
    pub samples: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Relative sd assumed where a measurement states none.
    #[arg(long, default_value_t = 0.10)]
    pub default_sd: f64,
    #[arg(long, value_enum, default_value_t)]
    pub format: GapFormat,
}

#[derive(Args, Debug)]
#[command(after_help = "Example:\n  \
survey gap suggest --trials t.csv --budget 3 --out next.csv\n\n\
The trials are diagnosed first; the leading explanations (until their probabilities add up to 0.99, \
six at most) are walked at their most probable values on every condition of the pool (drive \
frequency 0.85-1.15x the design's, servo amplitude 0.8-1.2x, payload 0-30 %, slope -2..2 deg, at \
the robot's own size). A condition is offered only where no explanation falls and, unless \
--any-gait, all walk forward. The score is the expected entropy of the posterior after the \
trials (Monte Carlo over their predicted summaries at the trials' median relative sd); the \
budget is filled greedily.")]
pub struct SuggestArgs {
    /// Trials CSV (format: dataset/trials/README.md).
    #[arg(long, value_name = "FILE")]
    pub trials: PathBuf,
    /// Conditions to suggest.
    #[arg(long, default_value_t = 3)]
    pub budget: usize,
    /// Relative sd of the new trials' summaries when the trials state none.
    #[arg(long, default_value_t = 0.05)]
    pub default_sd: f64,
    /// Also offer conditions where a model stands, scuffs or walks backward (not falls).
    #[arg(long)]
    pub any_gait: bool,
    /// Candidate effects, comma-separated (default: the whole library).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Write the suggested conditions as a trials CSV to fill in.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t)]
    pub format: GapFormat,
}

pub fn run(a: &GapArgs) -> anyhow::Result<ExitCode> {
    match &a.command {
        GapCommand::Effects(e) => effects(e),
        GapCommand::Synth(s) => synth(s),
        GapCommand::Diagnose(d) => diagnose(d),
        GapCommand::Explore(e) => explore(e),
        GapCommand::Suggest(s) => suggest(s),
        GapCommand::Benchmark(b) => super::gap_benchmark::benchmark(b),
    }
}

fn effects(a: &EffectsArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let d = Design::resolve(&a.design)?;
    let list: Vec<_> = lib.effects.iter().map(|e| e.summary(&d)).collect();
    print(&match a.format {
        GapFormat::Json => report::json(&list)?,
        GapFormat::Text => report::gap::effects_text(&list, &d.name),
    });
    Ok(ExitCode::SUCCESS)
}

/// A bar of `len` walks with the message `what`.
fn bar(len: u64, what: &str) -> Progress {
    let bar = templated_bar(len, "{msg} [{bar:30}] {pos}/{len} walks, {elapsed}");
    bar.set_message(what.to_string());
    Progress::Bar(bar)
}

/// A spinner with the message `what`.
fn spinner(what: &str) -> Progress {
    let spinner = indicatif::ProgressBar::new_spinner();
    spinner.set_message(what.to_string());
    Progress::Spinner(spinner)
}

fn synth(a: &SynthArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let design = Design::resolve(&a.design)?;
    let (mut opts, mut command) = gap::synth::SynthOptions::from_args(
        &lib, &design, &a.design, &a.effects, &a.set, a.noise, a.seed,
    )?;
    if a.expected {
        opts.expected = true;
        command.push_str(" --expected");
    }
    let conditions = match &a.conditions {
        Some(p) => {
            // The conditions (and their designs) are the file's: the source must say so.
            command.push_str(&format!(" --conditions {}", p.display()));
            Some(TrialSet::read(p)?)
        }
        None => None,
    };
    let n = conditions.as_ref().map(|c| c.trials.len()).unwrap_or(12) as u64;
    let pb = bar(n, "simulating the trials");
    let Some(dir) = &a.logs else {
        let set = gap::synth::synthesize(&lib, &opts, conditions, &command, &pb)?;
        pb.clear();
        write_atomic(&a.out, set.to_csv()?.as_bytes())?;
        eprintln!("wrote {} ({} trials)", a.out.display(), set.trials.len());
        return Ok(ExitCode::SUCCESS);
    };
    if !(a.sensor_noise_deg >= 0.0 && a.sensor_noise_deg.is_finite()) {
        anyhow::bail!("--sensor-noise-deg {}: must be ≥ 0", a.sensor_noise_deg);
    }
    if !(a.sensor_noise_torque >= 0.0 && a.sensor_noise_torque < 1.0) {
        anyhow::bail!(
            "--sensor-noise-torque {}: must be a fraction in [0, 1)",
            a.sensor_noise_torque
        );
    }
    command.push_str(&format!(
        " --logs {} --sensor-noise-deg {} --sensor-noise-torque {}",
        dir.display(),
        a.sensor_noise_deg,
        a.sensor_noise_torque
    ));
    let sensor = gap::synth::SensorNoise {
        angle_deg: a.sensor_noise_deg,
        torque_fraction: a.sensor_noise_torque,
    };
    let (mut set, logs) =
        gap::synth::synthesize_logs(&lib, &opts, conditions, &command, sensor, &pb)?;
    pb.clear();
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    // The trials file names each log relative to its own folder.
    let out_dir = a
        .out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let rel_dir = relative_to(dir, out_dir);
    for (i, (t, log)) in set.trials.iter_mut().zip(&logs).enumerate() {
        let name = if t.label.is_empty() {
            format!("trial-{}.csv", i + 1)
        } else {
            format!("{}.csv", t.label)
        };
        write_atomic(
            &dir.join(&name),
            gap::waveform::log_csv_text(log).as_bytes(),
        )?;
        t.trajectory = Some(rel_dir.join(&name).to_string_lossy().replace('\\', "/"));
    }
    write_atomic(&a.out, set.to_csv()?.as_bytes())?;
    eprintln!(
        "wrote {} ({} trials) and {} logs in {}",
        a.out.display(),
        set.trials.len(),
        logs.len(),
        dir.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// `path` relative to `base` when both are relative or both absolute and `path` lies under
/// `base`'s canonical form; otherwise `path` made absolute (a trials file must find its logs).
fn relative_to(path: &std::path::Path, base: &std::path::Path) -> PathBuf {
    match (path.canonicalize(), base.canonicalize()) {
        (Ok(p), Ok(b)) => {
            // Walk up from base until p starts with it, counting `..`.
            let mut up = PathBuf::new();
            let mut anc = b.as_path();
            loop {
                if let Ok(rest) = p.strip_prefix(anc) {
                    return up.join(rest);
                }
                match anc.parent() {
                    Some(parent) => {
                        up.push("..");
                        anc = parent;
                    }
                    None => return p,
                }
            }
        }
        _ => path.to_path_buf(),
    }
}

fn diagnose(a: &DiagnoseArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let set = TrialSet::read(&a.trials)?;
    let opts = a.options()?;
    let pb = spinner("diagnosing");
    let (d, timing) = gap::diagnose(&set, &lib, &opts, &pb)?;
    pb.clear();
    eprintln!(
        "{} walks: the model's spread {:.1} s, the suspects' curves {:.1} s, the posterior {:.1} s",
        timing.walks, timing.spread_s, timing.grid_s, timing.posterior_s
    );
    if let Some(p) = &a.plot {
        report::gap::residual_plot(&d, p)?;
        eprintln!("wrote {}", p.display());
    }
    print(&match a.format {
        GapFormat::Json => report::json(&d)?,
        GapFormat::Text => report::gap::diagnosis_md(&d),
    });
    Ok(ExitCode::SUCCESS)
}

fn suggest(a: &SuggestArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let set = TrialSet::read(&a.trials)?;
    anyhow::ensure!(
        a.default_sd > 0.0 && a.default_sd < 1.0,
        "--default-sd {}: must be a fraction in (0, 1)",
        a.default_sd
    );
    let mut diagnose = DiagnoseOptions::new()?;
    diagnose.effects = a.effects.clone();
    let opts = gap::suggest::SuggestOptions {
        budget: a.budget,
        default_relative_sd: a.default_sd,
        any_gait: a.any_gait,
        diagnose,
    };
    let pb = spinner("diagnosing, then walking the pool");
    let s = gap::suggest::suggest(&set, &lib, &opts, &pb)?;
    pb.clear();
    if let Some(p) = &a.out {
        if s.suggested.is_empty() {
            eprintln!(
                "nothing written to {}: no condition of the pool qualifies",
                p.display()
            );
        } else {
            let next = TrialSet {
                origin: p.display().to_string(),
                base_dir: PathBuf::from("."),
                trials: gap::suggest::as_trials(&s),
            };
            write_atomic(p, next.to_csv()?.as_bytes())?;
            eprintln!(
                "wrote {} ({} conditions to run)",
                p.display(),
                next.trials.len()
            );
        }
    }
    print(&match a.format {
        GapFormat::Json => report::json(&s)?,
        GapFormat::Text => report::gap::suggestion_md(&s),
    });
    Ok(ExitCode::SUCCESS)
}

fn explore(a: &ExploreArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let set = TrialSet::read(&a.trials)?;
    let conditions = gap::simulate::resolve(&set)?;
    let opts = gap::explore::ExploreOptions {
        samples: a.samples,
        seed: a.seed,
        default_relative_sd: a.default_sd,
    };
    let pb = bar((a.samples * conditions.len()) as u64, "exploring");
    let e = gap::explore::explore(
        &set,
        &conditions,
        &lib,
        &opts,
        &gap::cache::SimCache::default(),
        &pb,
    )?;
    pb.clear();
    print(&match a.format {
        GapFormat::Json => report::json(&e)?,
        GapFormat::Text => report::gap::exploration_md(&e),
    });
    Ok(ExitCode::SUCCESS)
}
