//! Synthetic "real" trials: the simulator with effects the nominal model lacks, plus
//! Gaussian measurement noise, over a default set of conditions or given ones.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::cases::resolve_design;
use super::error::GapError;
use super::knob::ModelSetting;
use super::library::{EffectLibrary, EffectSetting};
use super::likelihood::normal;
use super::simulate::{Condition, SimMetrics, resolve};
use super::trials::{Measurement, Metric, Trial, TrialSet};
use crate::progress::Observer;
use crate::sim::{Design, WalkOptions, simulate_walk};

/// Drive frequencies tried around the design's, as factors; the default conditions keep
/// those at which the nominal design walks at 1× (a lab tests conditions where its robot
/// walks).
pub const FREQUENCY_FACTORS: [f64; 5] = [0.97, 1.0, 1.03, 0.94, 1.06];
/// Sizes, as factors of the design's leg length, taken in this order until there are at
/// least [`MIN_CONDITIONS`] conditions.
pub const SIZE_FACTORS: [f64; 6] = [1.0, 0.5, 2.0, 0.7, 1.4, 4.0];
pub const MIN_CONDITIONS: usize = 12;

/// The default conditions for `design_name`: sizes × drive frequencies at which the nominal
/// design walks (m ∝ L², similar contact).
pub fn default_conditions(design_name: &str) -> Result<Vec<Trial>, GapError> {
    let design = resolve_design(design_name)?;
    let f0 = design.controller().frequency_hz().unwrap_or(1.0);
    let walks: Vec<bool> = {
        use rayon::prelude::*;
        FREQUENCY_FACTORS
            .par_iter()
            .map(|k| {
                let o = WalkOptions {
                    frequency_hz: Some(f0 * k),
                    duration_s: super::simulate::CYCLES_PER_TRIAL / (f0 * k),
                    record_trajectory: false,
                    ..WalkOptions::default()
                };
                simulate_walk(&design, &o).map(|r| r.report.walks)
            })
            .collect::<Result<Vec<bool>, _>>()
            .map_err(GapError::sim(design_name))?
    };
    let mut freqs: Vec<f64> = FREQUENCY_FACTORS
        .iter()
        .zip(&walks)
        .filter(|(_, w)| **w)
        .map(|(k, _)| *k)
        .take(4)
        .collect();
    if freqs.is_empty() {
        // The design does not walk near its own frequency: keep the design's own frequency
        // so the trials still say so.
        freqs.push(1.0);
    }
    freqs.sort_by(f64::total_cmp);
    let n_sizes = MIN_CONDITIONS.div_ceil(freqs.len()).min(SIZE_FACTORS.len());
    let mut sizes: Vec<f64> = SIZE_FACTORS[..n_sizes].to_vec();
    sizes.sort_by(f64::total_cmp);
    let l0 = design.geometry.leg_length_m;
    let mut out = Vec::new();
    for s in &sizes {
        for k in &freqs {
            let l = l0 * s;
            let mut t = Trial::condition(design_name, round_sig(l, 6));
            t.frequency_hz = Some(round_sig(f0 * k / s.sqrt(), 6));
            t.label = format!("L{s}x-f{k}x");
            out.push(t);
        }
    }
    Ok(out)
}

/// `x` to `digits` significant digits (what a lab sets; no float noise in a CSV).
pub(crate) fn round_sig(x: f64, digits: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let p = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * p).round() / p
}

/// Measured trials from true metrics: value + FRACTION·|value|·N(0, 1), sd = FRACTION·|value|.
/// A fallen walk measures nothing. Deterministic in `seed`.
pub fn add_noise(
    conditions: &[Trial],
    truth: &[SimMetrics],
    noise: f64,
    seed: u64,
    source: &str,
) -> Vec<Trial> {
    measured(conditions, truth, noise, Some(seed), source)
}

/// The expected trials: every value the truth's, every sd FRACTION·|value| as in
/// [`add_noise`]. What a trial set shows on average: the diagnosis' answer without the draw's
/// luck either way (a draw can also mislead it: an undeclared mass error of +8 % is
/// "unexplained" on its expected trials and soft ground on one 3 % draw). A cause it cannot
/// name from them is either not identifiable (a simpler model fits them within noise) or
/// missed by the search (the truth fits them exactly, the chain stops short): the answer's
/// gap left tells which.
pub fn expected_trials(
    conditions: &[Trial],
    truth: &[SimMetrics],
    noise: f64,
    source: &str,
) -> Vec<Trial> {
    measured(conditions, truth, noise, None, source)
}

/// Trials from true metrics with noise drawn from `seed`, or none (`None`: expected values).
fn measured(
    conditions: &[Trial],
    truth: &[SimMetrics],
    noise: f64,
    seed: Option<u64>,
    source: &str,
) -> Vec<Trial> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.unwrap_or(0));
    let mut out = Vec::with_capacity(conditions.len());
    for (t, m) in conditions.iter().zip(truth) {
        let mut t = t.clone();
        t.measured = [None; 8];
        for metric in Metric::simulated() {
            let v = m.get(metric);
            // Draw even for a missing value, so one trial's fall does not shift the noise of
            // the others.
            let e = normal(&mut rng);
            let e = if seed.is_some() { e } else { 0.0 };
            if !v.is_finite() {
                continue;
            }
            let sd = noise * v.abs();
            t.measured[metric.index()] = Some(Measurement {
                value: v + sd * e,
                sd: (sd > 0.0).then_some(sd),
            });
        }
        t.source = if m.fell {
            format!("{source}; the walk fell: nothing measured")
        } else {
            source.to_string()
        };
        out.push(t);
    }
    out
}

/// Sensor noise added to a simulated log to make a synthetic measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorNoise {
    /// sd of each angle sample [deg] (an IMU's attitude estimate, an encoder's quantisation).
    pub angle_deg: f64,
    /// sd of each torque sample, as a fraction of the log's largest |torque| (a current sense).
    pub torque_fraction: f64,
}

impl Default for SensorNoise {
    fn default() -> Self {
        SensorNoise {
            angle_deg: 0.3,
            torque_fraction: 0.03,
        }
    }
}

/// The sensor-noise seed of trial `i`'s log under a measurement seed: distinct per trial, so
/// two trials of one synthetic set never share a noise sequence.
pub fn log_seed(seed: u64, i: usize) -> u64 {
    seed ^ 0x9E37_79B9_7F4A_7C15u64.wrapping_mul(i as u64 + 1)
}

/// The log plus white Gaussian sensor noise, deterministic in `seed`.
pub fn add_sensor_noise(
    log: &[super::waveform::LogSample],
    noise: SensorNoise,
    seed: u64,
) -> Vec<super::waveform::LogSample> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let peak = log
        .iter()
        .filter_map(|s| s.hip_torque_nm)
        .fold(0.0f64, |a, b| a.max(b.abs()));
    let torque_sd = noise.torque_fraction * peak;
    log.iter()
        .map(|s| {
            let mut n = || normal(&mut rng);
            super::waveform::LogSample {
                hip_angle_deg: s.hip_angle_deg + noise.angle_deg * n(),
                roll_deg: s.roll_deg + noise.angle_deg * n(),
                pitch_deg: s.pitch_deg + noise.angle_deg * n(),
                yaw_deg: s.yaw_deg + noise.angle_deg * n(),
                hip_torque_nm: s.hip_torque_nm.map(|v| v + torque_sd * n()),
                ..*s
            }
        })
        .collect()
}

/// What `survey gap synth` produces.
pub struct SynthOptions {
    pub design: String,
    pub effects: Vec<EffectSetting>,
    /// Values of the design that differ from its file (path, value at 1×): "real" trials of
    /// a robot whose nominal parameters are wrong.
    pub params: Vec<(String, f64)>,
    pub noise: f64,
    pub seed: u64,
    /// Write the expected values (no noise drawn; the sd columns as with the noise): what
    /// such trials show on average, to ask what the diagnosis can name at best.
    pub expected: bool,
}

impl SynthOptions {
    /// The options of `survey gap synth` from its arguments — effects as `NAME=VALUE` or
    /// `NAME.PARAM=VALUE`, wrong parameters as `PATH=VALUE` (checked on `design` now, so an
    /// error names the argument) — and the command line every row records as its source.
    /// `design_arg` is the design as the user named it (a bundled name or a path).
    pub fn from_args(
        lib: &EffectLibrary,
        design: &Design,
        design_arg: &str,
        effects: &[String],
        set: &[String],
        noise: f64,
        seed: u64,
    ) -> Result<(SynthOptions, String), GapError> {
        let settings = super::library::parse_effect_args(lib, design, effects)?;
        let mut command = format!(
            "synthetic: survey gap synth --design {design_arg} --noise {noise} --seed {seed}"
        );
        for e in effects {
            command.push_str(&format!(" --effect {e}"));
        }
        let mut params = Vec::new();
        for arg in set {
            let bad = |why: String| GapError::Invalid(format!("--set {arg}: {why}"));
            let (path, value) = arg
                .split_once('=')
                .ok_or_else(|| bad("expected PATH=VALUE".into()))?;
            let value: f64 = value
                .trim()
                .parse()
                .map_err(|_| bad(format!("{value:?} is not a number")))?;
            design
                .with_value(path.trim(), value)
                .map_err(|e| bad(e.to_string()))?;
            params.push((path.trim().to_string(), value));
            command.push_str(&format!(" --set {arg}"));
        }
        Ok((
            SynthOptions {
                design: design_arg.to_string(),
                effects: settings,
                params,
                noise,
                seed,
                expected: false,
            },
            command,
        ))
    }
}

/// Simulates `conditions` (None: the design's defaults) with the withheld effects and
/// noise; `command` is recorded as every row's source.
pub fn synthesize(
    lib: &EffectLibrary,
    opts: &SynthOptions,
    conditions: Option<TrialSet>,
    command: &str,
    progress: &dyn Observer,
) -> Result<TrialSet, GapError> {
    let (set, resolved, setting) = opts.robot(conditions)?;
    let truth = truth_metrics(&resolved, lib, &setting, progress)?;
    let trials = opts.trials(&set.trials, &truth, command);
    Ok(TrialSet { trials, ..set })
}

impl SynthOptions {
    /// The synthetic robot's conditions (None: the design's defaults), resolved, and its
    /// setting: the parameter values (on every design of the trials) and effects.
    fn robot(
        &self,
        conditions: Option<TrialSet>,
    ) -> Result<(TrialSet, Vec<Condition>, ModelSetting), GapError> {
        check_noise(self.noise)?;
        let set = match conditions {
            Some(s) => s,
            None => TrialSet {
                origin: format!("default conditions of {}", self.design),
                base_dir: std::path::PathBuf::from("."),
                trials: default_conditions(&self.design)?,
            },
        };
        let resolved = resolve(&set)?;
        let designs: std::collections::BTreeSet<&str> =
            resolved.iter().map(|c| c.design.name.as_str()).collect();
        let params = designs.iter().flat_map(|d| {
            self.params
                .iter()
                .map(move |(p, v)| (d.to_string(), p.clone(), *v))
        });
        let setting = ModelSetting {
            params: params.collect(),
            effects: self.effects.clone(),
        };
        Ok((set, resolved, setting))
    }

    /// The measured trials from the true metrics: noise drawn from the seed, or the expected
    /// values.
    fn trials(&self, conditions: &[Trial], truth: &[SimMetrics], source: &str) -> Vec<Trial> {
        if self.expected {
            expected_trials(conditions, truth, self.noise, source)
        } else {
            add_noise(conditions, truth, self.noise, self.seed, source)
        }
    }
}

fn check_noise(noise: f64) -> Result<(), GapError> {
    if !(noise >= 0.0 && noise.is_finite() && noise < 1.0) {
        return Err(GapError::Invalid(format!(
            "--noise {noise}: must be a fraction in [0, 1)"
        )));
    }
    Ok(())
}

/// The true metrics of the conditions under `setting` (parameter values and effects).
pub fn truth_metrics(
    conditions: &[Condition],
    lib: &EffectLibrary,
    setting: &ModelSetting,
    progress: &dyn Observer,
) -> Result<Vec<SimMetrics>, GapError> {
    use rayon::prelude::*;
    conditions
        .par_iter()
        .map(|c| {
            let r = c.simulate(lib, setting).map(|w| w.metrics);
            progress.tick();
            r
        })
        .collect()
}

/// [`synthesize`] plus a log of every trial (the signals a robot records, with white sensor
/// noise): the summaries are exactly [`synthesize`]'s for the same options, the logs add the
/// cycles. A fallen walk's log is kept (it shows the fall). Deterministic in the seed.
pub fn synthesize_logs(
    lib: &EffectLibrary,
    opts: &SynthOptions,
    conditions: Option<TrialSet>,
    command: &str,
    sensor: SensorNoise,
    progress: &dyn Observer,
) -> Result<(TrialSet, Vec<Vec<super::waveform::LogSample>>), GapError> {
    use rayon::prelude::*;
    let (set, resolved, setting) = opts.robot(conditions)?;
    let walked: Vec<(SimMetrics, Vec<crate::sim::TrajectorySample>)> = resolved
        .par_iter()
        .map(|c| {
            let r = c.walk(lib, &setting, true);
            progress.tick();
            r
        })
        .collect::<Result<_, _>>()?;
    let truth: Vec<SimMetrics> = walked.iter().map(|w| w.0).collect();
    let trials = opts.trials(&set.trials, &truth, command);
    let logs = walked
        .iter()
        .enumerate()
        .map(|(i, (_, tr))| {
            add_sensor_noise(&super::waveform::log_of(tr), sensor, log_seed(opts.seed, i))
        })
        .collect();
    Ok((TrialSet { trials, ..set }, logs))
}
