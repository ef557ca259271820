//! `survey gap …`: the sim-to-real gap diagnosis.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand, ValueEnum};
use robot_survey::gap::{self, DiagnoseOptions, EffectLibrary, TrialSet};
use robot_survey::io::write_atomic;
use robot_survey::progress::{Observer, Silent, Stopwatch};
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
    /// Where the simulation misses the trials, which effect explains it, how far the gap
    /// shrinks on held-out conditions.
    Diagnose(DiagnoseArgs),
    /// Which settings of the designs' declared uncertain parameters fit the trials at all:
    /// a Latin hypercube over their whole ranges (history matching), what each parameter
    /// is pinned to, and how far each measured metric can be reached.
    Explore(ExploreArgs),
    /// Tell look-alike explanations apart: fit each candidate (an effect or a declared
    /// parameter) by walks on the summaries alone and on summaries + the logged cycles
    /// (trials whose `trajectory` column names a log), rank them, name one only when it fits
    /// within noise and beats every rival.
    Separate(SeparateArgs),
    /// The next trials to run: the conditions at the robot's own size (drive frequency,
    /// amplitude, payload, slope) where the two leading candidates differ most, computed
    /// with the simulator.
    Suggest(SuggestArgs),
    /// What the logged cycles buy: look-alike pairs of effects, each side the truth at
    /// multiples of its identification threshold, separated on summaries only and on
    /// summaries + waveforms over noise seeds (reports/gap-waveforms.md).
    WaveformBenchmark(WaveformBenchArgs),
    /// Every effect at several magnitudes × noise levels × seeds, plus null cases:
    /// identification confusion matrix, parameter recovery, shrink.
    Benchmark(Box<BenchmarkArgs>),
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
    /// sensor noise) into this folder, named in the trials' `trajectory` column: the input of
    /// `survey gap separate`'s waveform evidence.
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
    #[arg(long, default_value_t = 9)]
    pub grid: usize,
    /// Relative sd assumed where a measurement states none.
    #[arg(long, default_value_t = 0.10)]
    pub default_sd: f64,
    /// Family-wise false-alarm rate of the effect tests.
    #[arg(long, default_value_t = 0.001)]
    pub alpha: f64,
    /// Take the design's nominal parameters as right: do not calibrate its [[uncertain]]
    /// values (only effects are candidates).
    #[arg(long)]
    pub no_calibration: bool,
    #[arg(long, value_enum, default_value_t)]
    pub format: GapFormat,
    /// Figure of the standardised residuals per condition, before and after (SVG or PNG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Trials CSV of the same robot without the change asked about (before a damper, on the
    /// old floor, the same model without an effect), at the same conditions. The diagnosis
    /// is then of the change: each metric is carried onto the model as nominal + (trial −
    /// reference), so a discrepancy the model has everywhere (another engine, an unmodelled
    /// structure) cancels. Trust it where the model's gait is like the robot's: an effect
    /// must change both alike (Drake with physical friction: yes; with SAP's convex
    /// friction: no; reports/gap-benchmark-drake-lagged/)
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
    #[command(flatten)]
    pub selection: SelectionArgs,
}

/// The selection's rules (`gap diagnose`, and every case of `gap benchmark`). By default
/// five rules judge the chain again once it is built: one exchange round, the look-ahead
/// check, the deferred recalibration test, the step's look-alikes compared at the end and
/// the within-noise subset of the look-ahead's larger model; the flags below switch each
/// off, or add an experimental one.
#[derive(Args, Debug, Clone, Default)]
#[command(next_help_heading = "Selection rules")]
pub struct SelectionArgs {
    /// Forward selection and the backward pass alone, without the five rules that are on by
    /// default (the selection before 2026-11-28, which the reports' older runs used): to
    /// compare a rule with the selection without it. --exchange-rounds still applies.
    #[arg(long)]
    pub plain_selection: bool,
    /// Rounds of the exchange step after the backward pass. The answer's model is compared
    /// with its same-size neighbours (other pairs of knobs, or one knob exchanged); a better
    /// one replaces it only if its knobs form a chain every rule accepts, and one that fits
    /// alike makes the exchanged knobs "not told apart". Default 1 (0 with
    /// --plain-selection); measured in reports/gap-benchmark.md.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(0..=4))]
    pub exchange_rounds: Option<u8>,
    /// Without the look-ahead check. The check weighs each named knob at the answer's size
    /// (the answer against the best model with that knob exchanged for another) and one size
    /// up; a named knob that a model without it fits better than one with it by the
    /// identification distance, held out too, is not named (ambiguous): a look-alike that
    /// won the first step. It only takes names away.
    #[arg(long, conflicts_with = "look_ahead")]
    pub no_look_ahead: bool,
    /// With --plain-selection: the look-ahead check alone (on by default).
    #[arg(long)]
    pub look_ahead: bool,
    /// Without the deferred recalibration test. With it, when no knob passes every rule at a
    /// step, an effect that fails only the test against the recalibration is taken and that
    /// test is made at the end with every other effect of the answer in (if it fails then,
    /// the search is made again without deferring it). Tested alone, the first of two causes
    /// carries the second one's misfit in the over-dispersion that scales its test.
    #[arg(long, conflicts_with = "deferred_recalibration")]
    pub no_deferred_recalibration: bool,
    /// With --plain-selection: the deferred recalibration test alone (on by default).
    #[arg(long)]
    pub deferred_recalibration: bool,
    /// Without the end comparison of look-alikes. With it, the look-alikes a step could not
    /// tell its knob from are compared again in the final model (the knob exchanged for each,
    /// walked): at the step a still-missing second cause widens the identification distance
    /// by its misfit; with every cause of the answer in, the trials may tell them apart.
    #[arg(long, conflicts_with = "rivals_at_end")]
    pub no_rivals_at_end: bool,
    /// With --plain-selection: the end comparison of look-alikes alone (on by default).
    #[arg(long)]
    pub rivals_at_end: bool,
    /// Experimental: the joint step. When no single knob passes and the model is still
    /// beyond noise, every pair of knobs is fitted together and the best pair is taken if
    /// it passes a 2-dof test at α over the number of pairs and each of its knobs is
    /// needed beside the other. Off: with the exchange step and the look-ahead it named both
    /// causes of 3 more benchmark pairs and nothing on 19 Drake and parameter-error cases,
    /// but on another noise draw of one pair it named a look-alike (viscous damping for
    /// Coulomb friction) and a wrong parameter (reports/gap-benchmark.md).
    #[arg(long)]
    pub joint_step: bool,
    /// Experimental: Levenberg–Marquardt on walks for the two fits the call rule weighs, the
    /// recalibration of every uncertain parameter and an effect with it (about a dozen
    /// knobs, which interact where the surrogate cannot see it). Off: on every noisy
    /// benchmark pair it named both causes of 2 more pairs and of 4 fewer, since the
    /// recalibration gains more than an effect does (reports/gap-benchmark.md, fifth
    /// session); 1.9× the walks.
    #[arg(long)]
    pub walked_lm: bool,
    /// Experimental: find every named knob's look-alikes again in the final model, among
    /// all knobs outside it (the knob exchanged for each, screened, the nearest walked):
    /// one within the identification distance makes the knob ambiguous, as at a step.
    /// Supersedes the end comparison of the step's look-alikes: flags are cleared only when
    /// no named knob has one.
    #[arg(long)]
    pub look_alikes_at_end: bool,
    /// Without the within-noise subset. With it, when the look-ahead unnames a knob because
    /// a model one knob larger fits better, each model of the answer's size inside that
    /// larger one is walked, and one that fits within noise and whose knobs form a chain
    /// every rule accepts replaces the answer (then weighed again). For a look-alike that
    /// forward selection took first (actuation latency for hip backlash) and that kept the
    /// true pair out of reach. When no such model fits, the larger model itself may replace
    /// an answer beyond noise, and so may a pair from the nominal in place of an answer of
    /// one knob (the joint step's search): each only if it fits within noise, passes the
    /// chain's or the joint step's rules, and is then weighed against every model of its
    /// size (an unreported slope with hip Coulomb friction or damping, where the leg's COM
    /// offset alone explains more and was taken first).
    #[arg(long, conflicts_with = "within_noise_subset")]
    pub no_within_noise_subset: bool,
    /// With --plain-selection: the within-noise subset (on by default; it acts only after
    /// the look-ahead check, so it needs --look-ahead there).
    #[arg(long)]
    pub within_noise_subset: bool,
    /// Without the stop at the simulator's resolution. With it, forward selection stops
    /// where the model is beyond noise by the measurements' sds but within it once the
    /// simulator's own resolution at the model (the metrics' spread over nudges of 1/256 of
    /// each knob's range) is counted beside them, as the answer's residual check does: where
    /// the gait is knife-edge a further knob fits the chaos, not a cause
    #[arg(long, conflicts_with = "stop_at_resolution")]
    pub no_stop_at_resolution: bool,
    /// With --plain-selection: the stop at the simulator's resolution (on by default).
    #[arg(long)]
    pub stop_at_resolution: bool,
    /// `gap benchmark`: run the undeclared-parameter audit on every case (`gap diagnose`
    /// runs it by default; see --no-audit-undeclared). The benchmark's committed figures
    /// are without it, the audit's own in reports/gap-benchmark-audit.points.csv.
    #[arg(long, conflicts_with = "no_audit_undeclared")]
    pub audit_undeclared: bool,
    /// `gap diagnose`: without the undeclared-parameter audit. The audit weighs the answer
    /// against every number of the design file it does not declare [[uncertain]] (×/÷ 2
    /// around the file's value, or the design's [audit] table; a number whose fit stops at
    /// an end is weighed again up to ×/÷ 8): a named knob that an
    /// undeclared number, in its place, fits as well (within the identification distance)
    /// is not named — the answer says "not told apart from the undeclared …". It runs only
    /// when the chain holds a knob (the answer's names, or a partly explained answer's
    /// leads; 1.2–2.2× the walks) and only takes names away. On truths
    /// held out from every rule it turned both stand-ins named without it (COM height for
    /// the leg's roll inertia, μ for the stiction speed) into groups holding the truth; on
    /// the benchmark it unnamed 2 stand-ins and 5 right names whose look-alike is a real
    /// one of the model (μ beside the stiction speed, the servo gain beside its torque
    /// limit).
    #[arg(long)]
    pub no_audit_undeclared: bool,
    /// The audit's declared partners (0: one undeclared number at a time). An undeclared
    /// number that, in a named knob's place, explains part of the gap but not all of it is
    /// walked again beside each of the N declared knobs the surrogate ranks best: a truth
    /// of two numbers, one of them undeclared (the leg's roll inertia +30 % with μ 3 % low),
    /// can be fitted by neither alone, and the selection names a declared stand-in for the
    /// pair. The pair unnames the knob when, charged 2·φ for its knob more, it fits within
    /// the identification distance and each of its two is significant beside the other
    #[arg(long, value_name = "N", default_value_t = gap::audit::PARTNERS)]
    pub audit_partners: usize,
    /// Experimental: count the model's own trial-to-trial spread as noise. The nominal is
    /// walked at every condition from N starts perturbed by the design's [initial] seed table,
    /// and the sd of each metric over them (and the unperturbed walk) is added to the
    /// measurement's sd. A stable gait forgets its start (no change); an irregular one
    /// (Zippy's) does not, and a fit to a few cycles of it chases their chance. Off (0): on
    /// Zippy's benchmark (N = 4, 68 cases) it cleared 2 wrong names (μ for an undeclared
    /// contact stiffness and stiction speed) but made 3 others and named 7 of 24 single
    /// effects instead of 12 (reports/gap-benchmark-zippy/gap-benchmark.md)
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub model_spread: u64,
}

impl SelectionArgs {
    /// The selection's options these flags ask for.
    pub fn options(&self) -> gap::select::SelectOptions {
        let base = if self.plain_selection {
            gap::select::SelectOptions::plain()
        } else {
            gap::select::SelectOptions::default()
        };
        gap::select::SelectOptions {
            exchange_rounds: self
                .exchange_rounds
                .map_or(base.exchange_rounds, usize::from),
            look_ahead: (base.look_ahead || self.look_ahead) && !self.no_look_ahead,
            deferred_recalibration: (base.deferred_recalibration || self.deferred_recalibration)
                && !self.no_deferred_recalibration,
            rivals_at_end: (base.rivals_at_end || self.rivals_at_end) && !self.no_rivals_at_end,
            joint_step: self.joint_step,
            walked_lm: self.walked_lm,
            look_alikes_at_end: self.look_alikes_at_end,
            within_noise_subset: (base.within_noise_subset || self.within_noise_subset)
                && !self.no_within_noise_subset,
            stop_at_resolution: (base.stop_at_resolution || self.stop_at_resolution)
                && !self.no_stop_at_resolution,
            ..base
        }
    }

    /// The flags as given, for a report's command line.
    fn flags(&self) -> String {
        let mut f = String::new();
        let mut flag = |on: bool, name: &str| {
            if on {
                f.push_str(" --");
                f.push_str(name);
            }
        };
        flag(self.plain_selection, "plain-selection");
        flag(self.no_look_ahead, "no-look-ahead");
        flag(self.look_ahead, "look-ahead");
        flag(self.no_deferred_recalibration, "no-deferred-recalibration");
        flag(self.deferred_recalibration, "deferred-recalibration");
        flag(self.no_rivals_at_end, "no-rivals-at-end");
        flag(self.rivals_at_end, "rivals-at-end");
        flag(self.joint_step, "joint-step");
        flag(self.walked_lm, "walked-lm");
        flag(self.look_alikes_at_end, "look-alikes-at-end");
        flag(self.no_within_noise_subset, "no-within-noise-subset");
        flag(self.within_noise_subset, "within-noise-subset");
        flag(self.no_stop_at_resolution, "no-stop-at-resolution");
        flag(self.stop_at_resolution, "stop-at-resolution");
        flag(self.audit_undeclared, "audit-undeclared");
        flag(self.no_audit_undeclared, "no-audit-undeclared");
        if self.audit_partners != gap::audit::PARTNERS {
            f.push_str(&format!(" --audit-partners {}", self.audit_partners));
        }
        if self.model_spread > 0 {
            f.push_str(&format!(" --model-spread {}", self.model_spread));
        }
        if let Some(n) = self.exchange_rounds {
            f.push_str(&format!(" --exchange-rounds {n}"));
        }
        f
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
#[command(after_help = "Examples:\n  \
survey gap synth --effect hip_coulomb_friction=0.02 --noise 0.03 --seed 1 --out t.csv --logs logs/\n  \
survey gap separate --trials t.csv --candidates hip_coulomb_friction,hip_viscous_damping --plot cycles.svg\n\n\
A log needs the columns t_s, hip_angle_deg, roll_deg, pitch_deg, yaw_deg (hip_torque_nm and \
drive_phase_cycles optional; dataset/trials/README.md). Each candidate is fitted alone, the other \
knobs at the design file's values. Exit code 0 whatever the verdict.")]
pub struct SeparateArgs {
    /// Trials CSV (format: dataset/trials/README.md); rows may name a log in `trajectory`.
    #[arg(long, value_name = "FILE")]
    pub trials: PathBuf,
    /// Two or more knobs: effect names (`survey gap effects`) or `design:path` of declared
    /// uncertain parameters (e.g. mugatu:control.kp_nm_per_rad).
    #[arg(long, value_delimiter = ',', required = true, num_args = 1..)]
    pub candidates: Vec<String>,
    /// Model-error floor of a cycle coefficient, as a fraction of the measured signal's RMS.
    #[arg(long, default_value_t = 0.05)]
    pub waveform_floor: f64,
    /// Drive cycles left out at the start of every log and walk.
    #[arg(long, default_value_t = 6)]
    pub settle_cycles: usize,
    /// Walks per candidate over its range before the refinement.
    #[arg(long, default_value_t = 9)]
    pub grid: usize,
    /// False-alarm rate of the tests between candidates (and of the "fits within noise" test).
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Relative sd assumed where a measurement states none.
    #[arg(long, default_value_t = 0.10)]
    pub default_sd: f64,
    #[arg(long, value_enum, default_value_t)]
    pub format: GapFormat,
    /// Figure of the measured cycles against the nominal and the best candidate (SVG or PNG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Trials of the same robot at the same conditions without the change asked about
    /// (before the damper, on the old floor, another engine without the effect): the
    /// separation is then about what changed. Each summary and each logged cycle becomes the
    /// nominal model's + (trial − reference), so a discrepancy the model has everywhere
    /// cancels (as `gap diagnose --reference`). Every trial needs a reference trial of the
    /// same condition; a log is compared only where its reference trial has one too. A trial
    /// is used only where the nominal model walks the reference's gait (step frequency within
    /// 5 %, speed, roll and pitch within 25 %, each plus 2 sd); where it walks none, the
    /// answer is "not comparable". On the summaries, a rival that fits within noise, or would
    /// with one metric left out, is not told apart (the model's version of an effect may
    /// answer one metric unlike the robot's). With logs, the carried summaries say which
    /// candidates are plausible (by the same test) and the cycles tell those apart.
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
}

#[derive(Args, Debug)]
#[command(after_help = "Example:\n  \
survey gap suggest --trials t.csv --candidates hip_coulomb_friction,hip_viscous_damping --budget 3 --out next.csv\n\n\
The candidates are fitted to the trials (as `survey gap separate`); the two leading ones are \
walked on every condition of the pool (drive frequency 0.85-1.15x the design's, servo amplitude \
0.8-1.2x, payload 0-30 %, slope -2..2 deg, at the robot's own size); a condition is offered only \
where the nominal and both candidates walk forward (no fall, steady speed above the design's \
walking threshold: where a model scuffs in place, another engine or the robot parts from it most) \
and their gaits are smooth. The score is the expected likelihood-ratio statistic \
between the two on that trial: summaries at the trials' median relative sd, plus the cycles when \
the trials have logs.")]
pub struct SuggestArgs {
    /// Trials CSV (format: dataset/trials/README.md).
    #[arg(long, value_name = "FILE")]
    pub trials: PathBuf,
    /// Two or more candidate knobs (as for `survey gap separate`).
    #[arg(long, value_delimiter = ',', required = true, num_args = 1..)]
    pub candidates: Vec<String>,
    /// How many trials to suggest.
    #[arg(long, default_value_t = 3)]
    pub budget: usize,
    /// Model-error floor of a cycle coefficient (fraction of the signal's RMS).
    #[arg(long, default_value_t = 0.05)]
    pub waveform_floor: f64,
    /// Relative sd assumed for the new trials when the trials state none.
    #[arg(long, default_value_t = 0.05)]
    pub default_sd: f64,
    /// Also offer conditions where a model stands, scuffs or walks backward (only falls
    /// excluded). They separate look-alikes best in the simulator's own world, but there the
    /// robot (or another engine) parts from the model most: off by default.
    #[arg(long)]
    pub any_gait: bool,
    /// Write the suggested conditions as a trials CSV to fill in.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t)]
    pub format: GapFormat,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  survey gap waveform-benchmark --seeds 8 --out reports/\n\n\
Each pair is A:B (both sides are taken as the truth in turn). Thresholds: the summaries' \
identification threshold of the truth against the other effects of the library, at --noise."
)]
pub struct WaveformBenchArgs {
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    /// Look-alike pairs A:B, comma-separated (default: Coulomb:damping, latency:backlash,
    /// soft ground:backlash).
    #[arg(long, value_delimiter = ',', value_name = "A:B")]
    pub pairs: Vec<String>,
    /// Truth magnitudes as multiples of its identification threshold.
    #[arg(long, value_delimiter = ',', default_value = "0.5,1,2")]
    pub multiples: Vec<f64>,
    #[arg(long, default_value_t = 8)]
    pub seeds: u64,
    /// Relative sd of the summaries' noise.
    #[arg(long, default_value_t = 0.03)]
    pub noise: f64,
    /// Model-error floor of a cycle coefficient (fraction of the signal's RMS).
    #[arg(long, default_value_t = 0.05)]
    pub waveform_floor: f64,
    /// Folder for gap-waveforms.md and .json.
    #[arg(long, value_name = "DIR", default_value = "reports")]
    pub out: PathBuf,
}

#[derive(Args, Debug)]
#[command(after_help = "Examples:\n  \
survey gap benchmark --drake tests/golden/drake/gap --points bench.csv --out reports/\n  \
survey gap benchmark --drake tests/golden/drake/gap --points b-2.csv --shard 2/4   # one slice\n  \
survey gap benchmark --drake tests/golden/drake/gap --merge b-1.csv b-2.csv b-3.csv b-4.csv --points bench.csv --out reports/\n  \
survey gap benchmark --quick --out /tmp/bench          # a small run (minutes)\n\n\
Suites: main (the design's default conditions: nulls, single effects, pairs, nominal-parameter \
errors), one-robot (one size, conditions varied by drive, amplitude, payload, slope), drake \
(trials made by Drake with effects added in Drake). Every finished case is appended to the \
points file at once: a re-run resumes, shards merge into what one run writes.")]
pub struct BenchmarkArgs {
    #[arg(long, default_value = "mugatu")]
    pub design: String,
    /// The out-of-library cases (nominal-parameter and compound errors) from this TOML
    /// (format: dataset/benchmarks/README.md). Default: dataset/benchmarks/<design>.toml when
    /// it exists, else cases derived from the design (each declared [[uncertain]] value
    /// half-way to its farther range end; each undeclared number ×1.3 or + 0.015 L)
    #[arg(long, value_name = "FILE")]
    pub cases: Option<PathBuf>,
    /// A small run: 20 nulls per noise level, 1 seed, noise 5 % only, no one-robot suite.
    #[arg(long)]
    pub quick: bool,
    /// Null cases per noise level (main suite).
    #[arg(long)]
    pub null_cases: Option<u64>,
    /// Noise seeds per non-null case.
    #[arg(long)]
    pub seeds: Option<u64>,
    /// Null cases of the one-robot suite (one size; conditions varied by drive, amplitude,
    /// payload and slope). Its single-effect and parameter-error cases run when this is > 0;
    /// 0 leaves the suite out (--quick's default; otherwise 100).
    #[arg(long, value_name = "N")]
    pub one_robot_nulls: Option<u64>,
    /// The selection's rules of every case (as `gap diagnose`). A run with other rules than
    /// the default is another benchmark: use its own points file.
    #[command(flatten)]
    pub selection: SelectionArgs,
    /// Noise levels (relative sd) of the null and single-effect cases.
    #[arg(long, value_delimiter = ',')]
    pub noise: Option<Vec<f64>>,
    /// Folder of Drake trials files (`trials-*.csv`, e.g. tests/golden/drake/gap), each named
    /// by what Drake added: trials-none.csv, trials-<effect>-<value>.csv, or several effects
    /// joined by `+` (trials-hip_viscous_damping-0.01+hip_coulomb_friction-0.03.csv).
    #[arg(long, value_name = "DIR")]
    pub drake: Option<PathBuf>,
    /// Diagnose each Drake case relative to a noisy copy of the folder's `trials-none.csv`
    /// (another seed): `gap diagnose --reference`, the diagnosis of what the added effect
    /// changed, with the engine difference taken from the no-effect trials.
    #[arg(long, requires = "drake")]
    pub drake_reference: bool,
    /// Noisy copies of each Drake trials file (default 5; 1 with --quick).
    #[arg(long, value_name = "N", requires = "drake")]
    pub drake_seeds: Option<u64>,
    /// Diagnose the Drake cases against this design instead of their files' (a bundled name
    /// or a path relative to the Drake folder): e.g. `mugatu-ref-sap`, the reference with
    /// Drake SAP's convex friction cone, for trials Drake-SAP made from `mugatu-ref`.
    #[arg(long, value_name = "DESIGN", requires = "drake")]
    pub drake_design: Option<String>,
    /// Effects to benchmark (default: all).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Points file: every finished case is appended; an existing file is resumed.
    #[arg(long, value_name = "FILE")]
    pub points: Option<PathBuf>,
    /// Run one slice i/n of the cases (needs --points).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<robot_survey::checkpoint::Shard>,
    /// Points files of shards to merge into --points (no cases are run).
    #[arg(long, num_args = 1.., value_name = "FILE")]
    pub merge: Vec<PathBuf>,
    /// Run only the cases of these kinds (null, effect, pair, pair-expected, parameter,
    /// compound, drake), e.g. to spend a short session on the pairs: the points file stays
    /// the same benchmark's, and the report scores every row it holds. With --shard, slices
    /// are taken after the filter. pair-expected: each pair on its noise-free trials (the
    /// ceiling of any rule); compound: a declared parameter error plus each effect.
    #[arg(long, value_delimiter = ',', value_name = "KIND")]
    pub kinds: Vec<String>,
    /// Run only the cases whose key (the points file's first column) contains one of these
    /// texts, e.g. `--keys pair/hip_backlash` or one whole key to look at one case again.
    /// Applied after --kinds; an empty selection is an error.
    #[arg(long, value_delimiter = ',', value_name = "TEXT")]
    pub keys: Vec<String>,
    /// Folder for gap-benchmark.md, .json and .svg [default: reports]. A narrowed run
    /// (--kinds, --keys, --drake-design, --drake-reference) needs it given: its report is not
    /// the committed reports/gap-benchmark.md and must not overwrite it unasked.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

impl BenchmarkArgs {
    /// The report folder: --out, or reports/ for a run of the whole benchmark; an error
    /// for a narrowed run without --out.
    fn out_dir(&self) -> anyhow::Result<PathBuf> {
        if let Some(out) = &self.out {
            return Ok(out.clone());
        }
        let mut narrowing = Vec::new();
        if !self.kinds.is_empty() {
            narrowing.push("--kinds");
        }
        if !self.keys.is_empty() {
            narrowing.push("--keys");
        }
        if self.drake_design.is_some() {
            narrowing.push("--drake-design");
        }
        if self.drake_reference {
            narrowing.push("--drake-reference");
        }
        if narrowing.is_empty() {
            return Ok(PathBuf::from("reports"));
        }
        anyhow::bail!(
            "{} narrow the benchmark: its report would overwrite reports/gap-benchmark.{{md,json,svg}}; \
             give --out DIR (--out reports to mean it)",
            narrowing.join(", ")
        )
    }
}

pub fn run(a: &GapArgs) -> anyhow::Result<ExitCode> {
    match &a.command {
        GapCommand::Effects(e) => effects(e),
        GapCommand::Synth(s) => synth(s),
        GapCommand::Diagnose(d) => diagnose(d),
        GapCommand::Explore(e) => explore(e),
        GapCommand::Separate(s) => separate(s),
        GapCommand::Suggest(s) => suggest(s),
        GapCommand::WaveformBenchmark(w) => waveform_benchmark(w),
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

fn separate(a: &SeparateArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let set = TrialSet::read(&a.trials)?;
    let opts = gap::separate::SeparateOptions {
        candidates: a.candidates.clone(),
        grid_points: a.grid,
        relative_floor: a.waveform_floor,
        settle_cycles: a.settle_cycles,
        alpha: a.alpha,
        default_relative_sd: a.default_sd,
        ..Default::default()
    };
    let reference = a.reference.as_deref().map(TrialSet::read).transpose()?;
    let pb = spinner("walking the candidates");
    let s = match &reference {
        Some(r) => gap::separate::separate_relative(&set, r, &lib, &opts, &pb)?,
        None => gap::separate::separate(&set, &lib, &opts, &pb)?,
    };
    pb.clear();
    eprintln!("{} walks", s.walks);
    if let Some(p) = &a.plot {
        report::separation::cycles_plot(&s, p)?;
        eprintln!("wrote {}", p.display());
    }
    print(&match a.format {
        GapFormat::Json => report::json(&s)?,
        GapFormat::Text => report::separation::separation_md(&s),
    });
    Ok(ExitCode::SUCCESS)
}

fn suggest(a: &SuggestArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let set = TrialSet::read(&a.trials)?;
    if !(a.default_sd > 0.0 && a.default_sd < 1.0) {
        anyhow::bail!(
            "--default-sd {}: must be a fraction in (0, 1)",
            a.default_sd
        );
    }
    let opts = gap::suggest::SuggestOptions {
        budget: a.budget,
        separate: gap::separate::SeparateOptions {
            candidates: a.candidates.clone(),
            relative_floor: a.waveform_floor,
            ..Default::default()
        },
        default_relative_sd: a.default_sd,
        any_gait: a.any_gait,
    };
    let pb = spinner("fitting the candidates, then walking the pool");
    let s = gap::suggest::suggest(&set, &lib, &opts, &pb)?;
    pb.clear();
    if let Some(p) = &a.out
        && s.suggested.is_empty()
    {
        eprintln!(
            "nothing written to {}: no condition of the pool qualifies (see below)",
            p.display()
        );
    } else if let Some(p) = &a.out {
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
    print(&match a.format {
        GapFormat::Json => report::json(&s)?,
        GapFormat::Text => report::separation::suggestion_md(&s),
    });
    Ok(ExitCode::SUCCESS)
}

fn waveform_benchmark(a: &WaveformBenchArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let mut opts = gap::waveform_bench::WaveformBenchOptions::standard(&a.design);
    if !a.pairs.is_empty() {
        opts.pairs = a
            .pairs
            .iter()
            .map(|p| {
                p.split_once(':')
                    .map(|(x, y)| (x.trim().to_string(), y.trim().to_string()))
                    .ok_or_else(|| anyhow::anyhow!("--pairs {p}: expected A:B"))
            })
            .collect::<anyhow::Result<_>>()?;
    }
    if let Some(bad) = a.multiples.iter().find(|m| !(**m > 0.0 && m.is_finite())) {
        anyhow::bail!("--multiples {bad}: each must be a positive number");
    }
    if !(a.noise > 0.0 && a.noise < 1.0) {
        anyhow::bail!("--noise {}: must be a fraction in (0, 1)", a.noise);
    }
    opts.multiples = a.multiples.clone();
    opts.seeds = a.seeds.max(1);
    opts.noise = a.noise;
    opts.separate.relative_floor = a.waveform_floor;
    let mut command = format!(
        "survey gap waveform-benchmark --design {} --seeds {} --noise {} --waveform-floor {} --multiples {}",
        a.design,
        opts.seeds,
        a.noise,
        a.waveform_floor,
        a.multiples
            .iter()
            .map(|m| m.to_string())
            .collect::<Vec<_>>()
            .join(",")
    );
    if !a.pairs.is_empty() {
        command.push_str(&format!(" --pairs {}", a.pairs.join(",")));
    }
    let clock = Stopwatch::start();
    let b = gap::waveform_bench::run(&lib, &opts, &Progress::Lines)?;
    let elapsed = clock.seconds();
    std::fs::create_dir_all(&a.out).map_err(|e| anyhow::anyhow!("{}: {e}", a.out.display()))?;
    let md = a.out.join("gap-waveforms.md");
    write_atomic(
        &md,
        report::separation::waveform_bench_md(&b, &command).as_bytes(),
    )?;
    write_atomic(
        &a.out.join("gap-waveforms.json"),
        report::json(&b)?.as_bytes(),
    )?;
    eprintln!("wrote {} ({} walks, {elapsed:.0} s)", md.display(), b.walks);
    Ok(ExitCode::SUCCESS)
}

fn diagnose(a: &DiagnoseArgs) -> anyhow::Result<ExitCode> {
    let lib = EffectLibrary::bundled()?;
    let set = TrialSet::read(&a.trials)?;
    let reference = a.reference.as_deref().map(TrialSet::read).transpose()?;
    let opts = DiagnoseOptions {
        reference,
        effects: a.effects.clone(),
        grid_points: a.grid,
        default_relative_sd: a.default_sd,
        alpha: a.alpha,
        calibrate: !a.no_calibration,
        select: a.selection.options(),
        audit_undeclared: !a.selection.no_audit_undeclared,
        audit_partners: a.selection.audit_partners,
        model_spread_seeds: a.selection.model_spread,
        ..DiagnoseOptions::default()
    };
    let pb = Progress::Spinner(indicatif::ProgressBar::new_spinner());
    let (d, timing) = gap::diagnose(&set, &lib, &opts, &pb)?;
    pb.clear();
    eprintln!(
        "{} walks: knob grids {:.1} s, forward selection {:.1} s, explanations and intervals {:.1} s",
        timing.walks, timing.grid_s, timing.select_s, timing.report_s
    );
    if let Some(p) = &a.plot {
        report::gap::residual_plot(&d, p)?;
        eprintln!("wrote {}", p.display());
    }
    // Look-alike groups the summaries left, and a single named knob, separated with the
    // trials' logs (when they have any); with a reference, the cycles are carried through it
    // as the summaries are. Text only: the JSON stays the diagnosis (`survey gap separate
    // --format json` gives a group's separation as JSON).
    let follow = match a.format {
        GapFormat::Text => Some(gap::separate::follow_up(
            &d,
            &set,
            opts.reference.as_ref(),
            &lib,
            &gap::separate::SeparateOptions::default(),
            &Silent,
        )?),
        GapFormat::Json => None,
    };
    print(&match a.format {
        GapFormat::Json => report::json(&d)?,
        GapFormat::Text => {
            let mut text = report::gap::diagnosis_md(&d);
            if let Some(f) = &follow {
                text.push_str(&report::separation::follow_up_md(f));
            }
            text
        }
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

/// Where two specification lines part: a few characters of each from the first difference.
fn first_difference(files: &str, these: &str) -> String {
    let at = files
        .char_indices()
        .zip(these.chars())
        .find(|((_, a), b)| a != b)
        .map_or(files.len().min(these.len()), |((i, _), _)| i);
    let start = files[..at]
        .char_indices()
        .rev()
        .nth(40)
        .map_or(0, |(i, _)| i);
    let excerpt = |s: &str| {
        s.get(start..)
            .unwrap_or("")
            .chars()
            .take(120)
            .collect::<String>()
    };
    format!(
        "the files say …{}…, these options …{}…",
        excerpt(files),
        excerpt(these)
    )
}

fn benchmark(a: &BenchmarkArgs) -> anyhow::Result<ExitCode> {
    use robot_survey::checkpoint::Shard;
    let out = a.out_dir()?;
    let lib = EffectLibrary::bundled()?;
    let mut opts = match &a.cases {
        Some(file) => gap::benchmark::BenchmarkOptions::with_cases(
            &a.design,
            gap::cases::BenchmarkCases::read(file, &a.design)?,
        ),
        None => gap::benchmark::BenchmarkOptions::standard(&a.design)?,
    };
    if a.quick {
        opts.null_cases = 20;
        opts.seeds = 1;
        opts.noise_levels = vec![0.05];
        opts.one_robot_null_cases = 0;
        opts.drake_seeds = 1;
        opts.calibration_off_noise = None;
    }
    if let Some(n) = a.null_cases {
        opts.null_cases = n;
    }
    if let Some(n) = a.drake_seeds {
        if n == 0 {
            anyhow::bail!("--drake-seeds 0: give at least one noisy copy per Drake file");
        }
        opts.drake_seeds = n;
    }
    if let Some(s) = a.seeds {
        opts.seeds = s;
    }
    if let Some(n) = a.one_robot_nulls {
        opts.one_robot_null_cases = n;
    }
    opts.select = a.selection.options();
    opts.audit_undeclared = a.selection.audit_undeclared;
    opts.audit_partners = if a.selection.audit_undeclared {
        a.selection.audit_partners as u64
    } else {
        0
    };
    opts.model_spread_seeds = a.selection.model_spread;
    if let Some(n) = &a.noise {
        if let Some(bad) = n.iter().find(|x| !(**x > 0.0 && **x < 1.0)) {
            anyhow::bail!("--noise {bad}: each level must be a fraction in (0, 1)");
        }
        opts.noise_levels = n.clone();
    }
    opts.drake_dir = a.drake.clone();
    opts.drake_reference = a.drake_reference;
    opts.drake_design = a.drake_design.clone();
    opts.effects = a.effects.clone();
    let shard = a.shard.unwrap_or(Shard::WHOLE);
    if shard != Shard::WHOLE && a.points.is_none() {
        anyhow::bail!("--shard needs --points FILE (each slice writes its own points file)");
    }
    // A points file of another benchmark is refused now, not after minutes of planning.
    if a.merge.is_empty()
        && let Some(p) = &a.points
    {
        robot_survey::checkpoint::check_resumable(p, &gap::benchmark::spec(&opts))?;
    }
    let pb = indicatif::ProgressBar::new_spinner();
    pb.enable_steady_tick(std::time::Duration::from_millis(250));
    let pb = Progress::Spinner(pb);
    pb.stage("planning: thresholds and cases");
    let mut plan = gap::benchmark::plan(&lib, &opts, &pb)?;
    use gap::benchmark::KINDS;
    if let Some(bad) = a.kinds.iter().find(|k| !KINDS.contains(&k.as_str())) {
        anyhow::bail!(
            "--kinds {bad}: not a case kind (one of {})",
            KINDS.join(", ")
        );
    }
    if !a.kinds.is_empty() {
        plan.cases.retain(|c| a.kinds.contains(&c.kind));
    }
    if !a.keys.is_empty() {
        plan.cases
            .retain(|c| a.keys.iter().any(|k| c.key.contains(k.as_str())));
        if plan.cases.is_empty() {
            anyhow::bail!(
                "--keys {}: no case of this benchmark has such a key (see the points file's first column)",
                a.keys.join(",")
            );
        }
    }
    let rows = if a.merge.is_empty() {
        gap::benchmark::run(&lib, &opts, &plan, a.points.as_deref(), shard, &pb)?
    } else {
        let Some(target) = &a.points else {
            anyhow::bail!("--merge needs --points FILE (the merged file)");
        };
        let (header, rows) = robot_survey::checkpoint::merge::<gap::benchmark::CaseRow>(&a.merge)?;
        let expected = gap::benchmark::spec(&opts);
        if header != expected {
            anyhow::bail!(
                "the merged files were written with other benchmark options than these; merge with the options of the run ({})",
                first_difference(&header, &expected)
            );
        }
        robot_survey::checkpoint::finish_points(target, &header, &rows)?;
        let mut rows = rows;
        rows.sort_by(|x, y| x.key.cmp(&y.key));
        rows
    };
    pb.clear();
    if shard != Shard::WHOLE {
        eprintln!(
            "shard {shard}: {} cases in {}; merge the shards with --merge to score them",
            rows.len(),
            a.points
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_default()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let summary = gap::benchmark::summarize(&rows, &lib, &opts, plan.thresholds.clone());
    let mut command = format!("survey gap benchmark --design {}", a.design);
    if a.quick {
        command.push_str(" --quick");
    }
    if let Some(n) = &a.noise {
        let n: Vec<String> = n.iter().map(|x| x.to_string()).collect();
        command.push_str(&format!(" --noise {}", n.join(",")));
    }
    if let Some(n) = a.null_cases {
        command.push_str(&format!(" --null-cases {n}"));
    }
    if let Some(s) = a.seeds {
        command.push_str(&format!(" --seeds {s}"));
    }
    if let Some(n) = a.one_robot_nulls {
        command.push_str(&format!(" --one-robot-nulls {n}"));
    }
    command.push_str(&a.selection.flags());
    if !a.effects.is_empty() {
        command.push_str(&format!(" --effects {}", a.effects.join(",")));
    }
    if let Some(d) = &a.drake {
        command.push_str(&format!(" --drake {}", d.display()));
    }
    if let Some(n) = a.drake_seeds {
        command.push_str(&format!(" --drake-seeds {n}"));
    }
    if let Some(d) = &a.drake_design {
        command.push_str(&format!(" --drake-design {d}"));
    }
    if a.drake_reference {
        command.push_str(" --drake-reference");
    }
    std::fs::create_dir_all(&out)?;
    let md = report::gap::benchmark_md(&summary, &rows, &command);
    write_atomic(&out.join("gap-benchmark.md"), md.as_bytes())?;
    write_atomic(
        &out.join("gap-benchmark.json"),
        report::json(&serde_json::json!({ "summary": summary, "cases": rows }))?.as_bytes(),
    )?;
    report::gap::confusion_plot(&summary, &out.join("gap-benchmark.svg"))?;
    eprintln!("wrote {}/gap-benchmark.{{md,json,svg}}", out.display());
    print(&md);
    Ok(ExitCode::SUCCESS)
}
