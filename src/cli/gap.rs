//! `survey gap …`: the sim-to-real gap diagnosis.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand, ValueEnum};
use robot_survey::gap::{self, DiagnoseOptions, EffectLibrary, TrialSet};
use robot_survey::report;
use robot_survey::sim::Design;

use super::print;

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
    /// Where the simulation misses the trials, which effect explains it, how far the gap
    /// shrinks on held-out conditions.
    Diagnose(DiagnoseArgs),
    /// Every effect at several magnitudes × noise levels × seeds, plus null cases:
    /// identification confusion matrix, parameter recovery, shrink.
    Benchmark(BenchmarkArgs),
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
    /// Relative sd of the Gaussian measurement noise (written into the _sd columns).
    #[arg(long, default_value_t = 0.05)]
    pub noise: f64,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output trials CSV.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  survey gap diagnose --trials dataset/trials/published.csv --plot reports/gap-published.svg\n\n\
Exit code 0 whether or not a gap is found; `best` is null when the gap is within noise or no \
candidate reduces it significantly."
)]
pub struct DiagnoseArgs {
    /// Trials CSV (format: dataset/trials/README.md).
    #[arg(long, value_name = "FILE")]
    pub trials: PathBuf,
    /// Candidate effects, comma-separated (default: the whole library).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Magnitudes simulated per candidate across its plausible range.
    #[arg(long, default_value_t = 8)]
    pub grid: usize,
    /// Relative sd assumed where a measurement states none.
    #[arg(long, default_value_t = 0.10)]
    pub default_sd: f64,
    /// Family-wise false-alarm rate of the effect tests.
    #[arg(long, default_value_t = 0.001)]
    pub alpha: f64,
    #[arg(long, value_enum, default_value_t)]
    pub format: GapFormat,
    /// Figure of the standardised residuals per condition, before and after (SVG or PNG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct BenchmarkArgs {
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    /// Noise seeds per (effect, magnitude, noise level).
    #[arg(long, default_value_t = 3)]
    pub seeds: u64,
    /// Null cases (no effect) per noise level: the false-alarm rate.
    #[arg(long, default_value_t = 10)]
    pub null_seeds: u64,
    /// Noise levels (relative sd).
    #[arg(long, value_delimiter = ',', default_values_t = vec![0.01, 0.05, 0.10])]
    pub noise: Vec<f64>,
    /// Magnitudes as multiples of each effect's identification threshold at 5 % noise.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1.0, 2.0, 4.0])]
    pub multiples: Vec<f64>,
    /// Effects to benchmark (default: all).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Folder for gap-benchmark.md, .json and .svg.
    #[arg(long, value_name = "DIR", default_value = "reports")]
    pub out: PathBuf,
}

pub fn run(a: &GapArgs) -> anyhow::Result<ExitCode> {
    match &a.command {
        GapCommand::Effects(e) => effects(e),
        GapCommand::Synth(s) => synth(s),
        GapCommand::Diagnose(d) => diagnose(d),
        GapCommand::Benchmark(b) => benchmark(b),
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

fn bar(len: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} walks, {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(what.to_string());
    bar
}

fn synth(a: &SynthArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let design = Design::resolve(&a.design)?;
    let effects = gap::library::parse_effect_args(&lib, &design, &a.effects)?;
    let conditions = match &a.conditions {
        Some(p) => Some(TrialSet::read(p)?),
        None => None,
    };
    let n = conditions.as_ref().map(|c| c.trials.len()).unwrap_or(12) as u64;
    let pb = bar(n, "simulating the trials");
    let mut command = format!(
        "synthetic: survey gap synth --design {} --noise {} --seed {}",
        a.design, a.noise, a.seed
    );
    for e in &a.effects {
        command.push_str(&format!(" --effect {e}"));
    }
    let opts = gap::synth::SynthOptions {
        design: a.design.clone(),
        effects,
        noise: a.noise,
        seed: a.seed,
    };
    let set = gap::synth::synthesize(&lib, &opts, conditions, &command, &|| pb.inc(1))?;
    pb.finish_and_clear();
    write_atomic(&a.out, set.to_csv().as_bytes())?;
    eprintln!("wrote {} ({} trials)", a.out.display(), set.trials.len());
    Ok(ExitCode::SUCCESS)
}

/// Writes through a temporary file in the same folder, so a failure leaves no half file.
pub fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> anyhow::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let tmp = dir.join(format!(
        ".{}.tmp",
        path.file_name().and_then(|f| f.to_str()).unwrap_or("out")
    ));
    std::fs::write(&tmp, bytes).map_err(|e| anyhow::anyhow!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok(())
}

fn diagnose(a: &DiagnoseArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let set = TrialSet::read(&a.trials)?;
    let opts = DiagnoseOptions {
        effects: a.effects.clone(),
        grid_points: a.grid,
        default_relative_sd: a.default_sd,
        alpha: a.alpha,
        ..DiagnoseOptions::default()
    };
    let pb = indicatif::ProgressBar::new_spinner();
    let count = std::sync::atomic::AtomicU64::new(0);
    let (d, timing) = gap::diagnose(&set, &lib, &opts, &|what| {
        if what.is_empty() {
            let k = count.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            pb.set_position(k);
            pb.tick();
        } else {
            pb.set_message(what.to_string());
        }
    })?;
    pb.finish_and_clear();
    eprintln!(
        "{} walks: nominal {:.1} s, candidate grids {:.1} s, refinement {:.1} s, fitting {:.2} s",
        timing.walks, timing.nominal_s, timing.grid_s, timing.refine_s, timing.fit_s
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

fn benchmark(a: &BenchmarkArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let opts = gap::benchmark::BenchmarkOptions {
        design: a.design.clone(),
        seeds: a.seeds,
        noise_levels: a.noise.clone(),
        multiples: a.multiples.clone(),
        effects: a.effects.clone(),
        null_seeds: a.null_seeds,
    };
    let pb = indicatif::ProgressBar::new_spinner();
    let result = gap::benchmark::run(&lib, &opts, &|what| {
        pb.set_message(what.to_string());
        pb.tick();
    })?;
    pb.finish_and_clear();
    std::fs::create_dir_all(&a.out)?;
    let md = report::gap::benchmark_md(&result);
    write_atomic(&a.out.join("gap-benchmark.md"), md.as_bytes())?;
    write_atomic(
        &a.out.join("gap-benchmark.json"),
        report::json(&result)?.as_bytes(),
    )?;
    report::gap::confusion_plot(&result, &a.out.join("gap-benchmark.svg"))?;
    eprintln!("wrote {}/gap-benchmark.{{md,json,svg}}", a.out.display());
    print(&md);
    Ok(ExitCode::SUCCESS)
}
