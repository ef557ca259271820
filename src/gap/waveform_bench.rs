//! What the logged cycles buy: look-alike pairs of effects, each side taken as the truth at
//! multiples of its identification threshold (from the summaries, against the other
//! effects), separated by `survey gap separate` on summaries only and on summaries +
//! waveforms, over noise seeds. Rates of correct names, of the rival named (confusion), and
//! of "cannot tell" / "none fits" per mode; and, per pair, the smallest tested multiple at
//! which each mode names the truth in ≥ 90 % of the seeds.

use rayon::prelude::*;
use serde::Serialize;

use super::cache::SimCache;
use super::error::GapError;
use super::knob::ModelSetting;
use super::library::EffectLibrary;
use super::separate::{CycleCache, Evidence, SeparateOptions, Verdict, separate_with};
use super::simulate::{Condition, SimMetrics, resolve};
use super::synth::{SensorNoise, add_noise, add_sensor_noise, default_conditions, log_seed};
use super::trials::TrialSet;
use super::waveform::{self, CycleSignature};
use crate::progress::{Observer, Silent};
use crate::sim::TrajectorySample;

#[derive(Clone, Debug)]
pub struct WaveformBenchOptions {
    pub design: String,
    /// Look-alike pairs (each side is the truth in turn).
    pub pairs: Vec<(String, String)>,
    /// Truth magnitudes as multiples of its identification threshold (summaries).
    pub multiples: Vec<f64>,
    pub seeds: u64,
    /// Relative sd of the summaries' noise.
    pub noise: f64,
    pub sensor: SensorNoise,
    pub separate: SeparateOptions,
}

impl WaveformBenchOptions {
    pub fn standard(design: &str) -> WaveformBenchOptions {
        WaveformBenchOptions {
            design: design.to_string(),
            pairs: vec![
                ("hip_coulomb_friction".into(), "hip_viscous_damping".into()),
                ("actuation_latency".into(), "hip_backlash".into()),
                ("soft_ground".into(), "hip_backlash".into()),
            ],
            multiples: vec![0.5, 1.0, 2.0],
            seeds: 8,
            noise: 0.03,
            sensor: SensorNoise::default(),
            separate: SeparateOptions {
                refine_steps: 8,
                ..SeparateOptions::default()
            },
        }
    }
}

/// One (truth, rival, multiple) cell over the seeds.
#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    pub truth: String,
    pub rival: String,
    pub multiple: f64,
    /// The truth's magnitude (SI, the design at 1×).
    pub magnitude: f64,
    pub seeds: u64,
    /// Per mode [summaries, summaries + waveforms].
    pub correct: [u64; 2],
    pub confused: [u64; 2],
    pub cannot_tell: [u64; 2],
    pub none_fits: [u64; 2],
    pub no_gap: [u64; 2],
}

#[derive(Clone, Debug, Serialize)]
pub struct PairSummary {
    pub truth: String,
    pub rival: String,
    /// The truth's identification threshold from the summaries (SI), against the library.
    pub threshold: Option<f64>,
    /// Smallest tested multiple naming the truth in ≥ 90 % of seeds, per mode (None: none).
    pub smallest_multiple_90: [Option<f64>; 2],
    /// The rival named at 1× the threshold, per mode (count, seeds).
    pub confusion_at_1x: [u64; 2],
}

#[derive(Clone, Debug, Serialize)]
pub struct WaveformBench {
    pub design: String,
    pub noise: f64,
    pub sensor_angle_deg: f64,
    pub sensor_torque_fraction: f64,
    pub relative_floor: f64,
    pub seeds: u64,
    pub cells: Vec<Cell>,
    pub pairs: Vec<PairSummary>,
    pub walks: usize,
}

/// Runs the benchmark; `progress` hears a stage (a line) per finished cell.
pub fn run(
    lib: &EffectLibrary,
    opts: &WaveformBenchOptions,
    progress: &dyn Observer,
) -> Result<WaveformBench, GapError> {
    let base = TrialSet {
        origin: format!("default conditions of {}", opts.design),
        base_dir: std::path::PathBuf::from("."),
        trials: default_conditions(&opts.design)?,
    };
    let conditions = resolve(&base)?;
    let design = conditions
        .first()
        .map(|c| c.design.clone())
        .ok_or_else(|| GapError::Invalid("the design has no default conditions".into()))?;
    let nominal: Vec<SimMetrics> = conditions
        .par_iter()
        .map(|c| c.simulate(lib, &ModelSetting::nominal()))
        .collect::<Result<_, _>>()?;
    let mut effects: Vec<String> = Vec::new();
    for (a, b) in &opts.pairs {
        for e in [a, b] {
            lib.get(e)?;
            if !effects.contains(e) {
                effects.push(e.clone());
            }
        }
    }
    progress.stage("identification thresholds from the summaries");
    let ids = super::benchmark::thresholds(
        &base,
        &conditions,
        &nominal,
        lib,
        opts.noise,
        &lib.names(),
        false,
        &SimCache::default(),
    )?;
    let threshold_of = |e: &str| {
        ids.iter()
            .find(|i| i.effect == e)
            .and_then(|i| i.identification_threshold)
    };
    let cache = CycleCache::default();
    let mut cells = Vec::new();
    let mut pairs = Vec::new();
    let mut walks = 0;
    for (a, b) in &opts.pairs {
        for (truth, rival) in [(a, b), (b, a)] {
            let threshold = threshold_of(truth);
            let mut summary = PairSummary {
                truth: truth.clone(),
                rival: rival.clone(),
                threshold,
                smallest_multiple_90: [None, None],
                confusion_at_1x: [0, 0],
            };
            let Some(th) = threshold else {
                progress.stage(&format!(
                    "{truth}: no identification threshold within its range"
                ));
                pairs.push(summary);
                continue;
            };
            let sep = SeparateOptions {
                candidates: vec![truth.clone(), rival.clone()],
                ..opts.separate.clone()
            };
            for &k in &opts.multiples {
                let magnitude = super::benchmark::magnitude_at(lib, &design, truth, th, k);
                let def = lib.get(truth)?;
                let scale = def.magnitude().scale.value(&design);
                let setting = ModelSetting::effect(def.setting(magnitude / scale));
                let truth_walks: Vec<(SimMetrics, Vec<TrajectorySample>)> = conditions
                    .par_iter()
                    .map(|c| c.walk(lib, &setting, true))
                    .collect::<Result<_, _>>()?;
                let mut cell = Cell {
                    truth: truth.clone(),
                    rival: rival.clone(),
                    multiple: k,
                    magnitude,
                    seeds: opts.seeds,
                    correct: [0; 2],
                    confused: [0; 2],
                    cannot_tell: [0; 2],
                    none_fits: [0; 2],
                    no_gap: [0; 2],
                };
                for seed in 0..opts.seeds {
                    let (set, sigs) =
                        measurement(&base, &conditions, &truth_walks, opts, seed, truth, k)?;
                    let s = separate_with(&set, &conditions, &sigs, lib, &sep, &cache, &Silent)?;
                    walks += s.walks;
                    for r in &s.rankings {
                        let m = usize::from(r.evidence == Evidence::SummariesAndWaveforms);
                        match &r.verdict {
                            Verdict::Named { knob } if knob == truth => cell.correct[m] += 1,
                            // A pair on a single truth names a knob outside it.
                            Verdict::Named { .. } | Verdict::NamedTogether { .. } => {
                                cell.confused[m] += 1
                            }
                            Verdict::CannotTell { .. } => cell.cannot_tell[m] += 1,
                            Verdict::NoneFits { .. } | Verdict::NotComparable { .. } => {
                                cell.none_fits[m] += 1
                            }
                            Verdict::NoGap => cell.no_gap[m] += 1,
                        }
                    }
                }
                progress.stage(&format!(
                    "{truth} ×{k} vs {rival}: correct {}/{} (summaries), {}/{} (+ waveforms)",
                    cell.correct[0], cell.seeds, cell.correct[1], cell.seeds
                ));
                if k == 1.0 {
                    summary.confusion_at_1x = cell.confused;
                }
                for m in 0..2 {
                    if summary.smallest_multiple_90[m].is_none()
                        && cell.correct[m] as f64 >= 0.9 * cell.seeds as f64
                    {
                        summary.smallest_multiple_90[m] = Some(k);
                    }
                }
                cells.push(cell);
            }
            pairs.push(summary);
        }
    }
    Ok(WaveformBench {
        design: opts.design.clone(),
        noise: opts.noise,
        sensor_angle_deg: opts.sensor.angle_deg,
        sensor_torque_fraction: opts.sensor.torque_fraction,
        relative_floor: opts.separate.relative_floor,
        seeds: opts.seeds,
        cells,
        pairs,
        walks,
    })
}

/// One seed's measurement: noisy summaries (as `survey gap synth`) and noisy logs' cycles.
fn measurement(
    base: &TrialSet,
    conditions: &[Condition],
    truth: &[(SimMetrics, Vec<TrajectorySample>)],
    opts: &WaveformBenchOptions,
    seed: u64,
    effect: &str,
    multiple: f64,
) -> Result<(TrialSet, Vec<Option<CycleSignature>>), GapError> {
    // A seed per (effect, multiple, seed), so cells do not share noise draws.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in format!("{effect}/{multiple}/{seed}").bytes() {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    let metrics: Vec<SimMetrics> = truth.iter().map(|t| t.0).collect();
    let trials = add_noise(&base.trials, &metrics, opts.noise, h, "waveform benchmark");
    let sigs = truth
        .iter()
        .zip(conditions)
        .enumerate()
        .map(|(i, ((m, tr), c))| {
            if m.fell {
                return Ok(None);
            }
            let log = add_sensor_noise(&waveform::log_of(tr), opts.sensor, log_seed(h, i));
            Ok(
                waveform::signature(&log, c.drive_frequency_hz()?, opts.separate.settle_cycles)
                    .ok(),
            )
        })
        .collect::<Result<Vec<_>, GapError>>()?;
    Ok((
        TrialSet {
            origin: base.origin.clone(),
            base_dir: base.base_dir.clone(),
            trials,
        },
        sigs,
    ))
}
