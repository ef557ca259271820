//! The diagnosis benchmarked on synthetic trials whose cause is known: every effect at
//! several magnitudes (multiples of its identification threshold) × noise levels × seeds,
//! plus null cases. All cases share the default conditions, so the candidates' grid walks
//! are simulated once and reused through a [`SimCache`].

use std::time::Instant;

use serde::Serialize;

use super::diagnose::{DiagnoseOptions, Identifiability, SimCache, diagnose_conditions};
use super::error::GapError;
use super::library::{EffectDef, EffectLibrary, EffectSetting};
use super::simulate::resolve;
use super::synth::{add_noise, default_conditions, truth_metrics};
use super::trials::{Measurement, Metric, TrialSet};

pub struct BenchmarkOptions {
    pub design: String,
    pub seeds: u64,
    pub noise_levels: Vec<f64>,
    /// Magnitudes as multiples of the identification threshold at 5 % noise.
    pub multiples: Vec<f64>,
    pub effects: Vec<String>,
    /// Null cases (no effect) per noise level.
    pub null_seeds: u64,
}

/// Thresholds of one effect at one noise level.
#[derive(Clone, Debug, Serialize)]
pub struct ThresholdRow {
    pub noise: f64,
    #[serde(flatten)]
    pub identifiability: Identifiability,
}

/// One synthetic case and what the diagnosis made of it.
#[derive(Clone, Debug, Serialize)]
pub struct CaseRow {
    pub noise: f64,
    pub seed: u64,
    /// None: the null case.
    pub true_effect: Option<String>,
    pub multiple: Option<f64>,
    /// True magnitude in SI (the design at 1×).
    pub magnitude: Option<f64>,
    /// Beyond this noise level's identification threshold.
    pub above_threshold: bool,
    pub called: Option<String>,
    pub correct: bool,
    pub fitted: Option<f64>,
    pub ci: Option<[f64; 2]>,
    /// Truth inside the reported interval (when the right effect was called).
    pub covered: Option<bool>,
    /// |ln(fitted/true)|.
    pub log_error: Option<f64>,
    pub gap_before: f64,
    pub gap_after: Option<f64>,
    pub shrink_pct: Option<f64>,
}

/// Counts of calls per true effect (rows) at one noise level, over the cases above
/// threshold and the null cases.
#[derive(Clone, Debug, Serialize)]
pub struct Confusion {
    pub noise: f64,
    /// Row and column labels: the effects, then "none".
    pub labels: Vec<String>,
    pub counts: Vec<Vec<usize>>,
    pub identification_rate_above_threshold: f64,
    pub cases_above_threshold: usize,
    pub false_alarms: usize,
    pub null_cases: usize,
    /// Share of correctly called cases whose interval holds the truth.
    pub coverage: f64,
    pub median_log_error: f64,
    pub median_shrink_pct: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct BenchmarkResult {
    pub design: String,
    pub conditions: usize,
    pub seeds: u64,
    pub null_seeds: u64,
    pub multiples: Vec<f64>,
    pub thresholds: Vec<ThresholdRow>,
    pub confusion: Vec<Confusion>,
    pub cases: Vec<CaseRow>,
    pub walks: usize,
    pub seconds: f64,
    pub seconds_per_diagnosis: f64,
}

/// The magnitude `multiple` times as strong as `threshold` (nondimensional), moving away
/// from the effect's off value, clamped to the plausible range.
fn magnitude_at(def: &EffectDef, off: f64, threshold: f64, multiple: f64) -> f64 {
    let [lo, hi] = def.magnitude().range;
    let v = if off == 0.0 {
        threshold * multiple
    } else if off.is_infinite() {
        threshold / multiple
    } else {
        // An off value inside the range (μ): scale the log-distance from it.
        (off.ln() + multiple * (threshold.ln() - off.ln())).exp()
    };
    v.clamp(lo, hi)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

pub fn run(
    lib: &EffectLibrary,
    opts: &BenchmarkOptions,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<BenchmarkResult, GapError> {
    let start = Instant::now();
    if opts.seeds == 0 || opts.noise_levels.is_empty() || opts.multiples.is_empty() {
        return Err(GapError::Invalid(
            "the benchmark needs ≥ 1 seed, noise level and multiple".into(),
        ));
    }
    if let Some(bad) = opts.noise_levels.iter().find(|x| !(**x > 0.0 && **x < 1.0)) {
        return Err(GapError::Invalid(format!(
            "noise level {bad}: must be in (0, 1)"
        )));
    }
    let effects = lib.subset(&opts.effects)?;
    progress("default conditions");
    let trials = default_conditions(&opts.design)?;
    let base = TrialSet {
        origin: format!("benchmark conditions of {}", opts.design),
        base_dir: std::path::PathBuf::from("."),
        trials,
    };
    let conditions = resolve(&base)?;
    let first = &conditions[0];
    let cache = SimCache::default();
    let dopts = DiagnoseOptions::default();
    let nominal = cache.get(&conditions, lib, None, &|| {})?;

    // Thresholds per noise level: a noiseless "measurement" of the nominal model with the
    // noise level's sds (the diagnosis of it reports each effect's identifiability).
    let mut thresholds = Vec::new();
    for &noise in &opts.noise_levels {
        progress(&format!("thresholds at {} % noise", noise * 100.0));
        let mut set = base.clone();
        for (t, m) in set.trials.iter_mut().zip(&nominal) {
            for metric in Metric::SIMULATED {
                let v = m.get(metric);
                if v.is_finite() && v != 0.0 {
                    t.measured[metric.index()] = Some(Measurement {
                        value: v,
                        sd: Some(noise * v.abs()),
                    });
                }
            }
            t.source = "nominal".into();
        }
        let (d, _) = diagnose_conditions(&set, &conditions, lib, &dopts, &cache, &|_| {})?;
        for i in d.identifiability {
            thresholds.push(ThresholdRow {
                noise,
                identifiability: i,
            });
        }
    }
    let threshold_of = |effect: &str, noise: f64| -> Option<f64> {
        thresholds
            .iter()
            .find(|t| t.identifiability.effect == effect && (t.noise - noise).abs() < 1e-12)
            .and_then(|t| {
                t.identifiability
                    .identification_threshold
                    .or(t.identifiability.detection_threshold)
            })
    };
    // Reference noise for the magnitudes: 5 % if benchmarked, else the middle level.
    let ref_noise = opts
        .noise_levels
        .iter()
        .copied()
        .find(|n| (n - 0.05).abs() < 1e-12)
        .unwrap_or(opts.noise_levels[opts.noise_levels.len() / 2]);

    // Truth walks for every (effect, multiple).
    let mut truths: Vec<(Option<&EffectDef>, Option<f64>, Option<EffectSetting>)> =
        vec![(None, None, None)];
    for def in &effects {
        let p = def.magnitude();
        let scale = p.scale.value(&first.design);
        let off = p.off_nondimensional(&first.design, &def.name);
        let thr = threshold_of(&def.name, ref_noise).map(|t| t / scale);
        for &k in &opts.multiples {
            let mag = match thr {
                Some(t) => magnitude_at(def, off, t, k),
                // Not identifiable within the range: its strongest plausible magnitude.
                None => {
                    if off == 0.0 {
                        p.range[1]
                    } else {
                        p.range[0]
                    }
                }
            };
            truths.push((Some(def), Some(k), Some(def.setting(mag))));
        }
    }
    progress("truth walks");
    let truth_metrics: Vec<_> = truths
        .iter()
        .map(|(_, _, s)| match s {
            Some(s) => truth_metrics(&conditions, lib, std::slice::from_ref(s), &|| {}),
            None => Ok(nominal.clone()),
        })
        .collect::<Result<_, _>>()?;

    let mut cases = Vec::new();
    let mut diag_seconds = 0.0;
    let mut n_diag = 0usize;
    for &noise in &opts.noise_levels {
        for ((def, k, setting), truth) in truths.iter().zip(&truth_metrics) {
            let seeds = if def.is_none() {
                opts.null_seeds
            } else {
                opts.seeds
            };
            for seed in 0..seeds {
                progress(&format!(
                    "{} × {} at {} % noise, seed {seed}",
                    def.map(|d| d.name.as_str()).unwrap_or("null"),
                    k.unwrap_or(0.0),
                    noise * 100.0
                ));
                let case_seed = seed
                    .wrapping_mul(1_000_003)
                    .wrapping_add((noise * 1e6) as u64)
                    .wrapping_add(cases.len() as u64 * 7919);
                let trials = add_noise(&base.trials, truth, noise, case_seed, "benchmark");
                let set = TrialSet {
                    origin: "benchmark".into(),
                    base_dir: base.base_dir.clone(),
                    trials,
                };
                let t0 = Instant::now();
                let (d, _) = diagnose_conditions(&set, &conditions, lib, &dopts, &cache, &|_| {})?;
                diag_seconds += t0.elapsed().as_secs_f64();
                n_diag += 1;
                let called = d.best.as_ref().map(|b| b.effect.clone());
                let true_name = def.map(|d| d.name.clone());
                let correct = called == true_name;
                let (magnitude, above) = match (def, setting) {
                    (Some(def), Some(s)) => {
                        let p = def.magnitude();
                        let scale = p.scale.value(&first.design);
                        let off = p.off_nondimensional(&first.design, &def.name);
                        let m = s.nondimensional[0];
                        let above = threshold_of(&def.name, noise)
                            .map(|t| {
                                let t = t / scale;
                                if off == 0.0 {
                                    m >= t * (1.0 - 1e-9)
                                } else if off.is_infinite() {
                                    m <= t * (1.0 + 1e-9)
                                } else {
                                    (m.ln() - off.ln()).abs()
                                        >= (t.ln() - off.ln()).abs() * (1.0 - 1e-9)
                                }
                            })
                            .unwrap_or(false);
                        (Some(m * scale), above)
                    }
                    _ => (None, false),
                };
                let (fitted, ci) = match (&d.best, def) {
                    (Some(b), Some(def)) if correct => (
                        b.params.get(&def.magnitude().name).copied(),
                        b.params_ci.get(&def.magnitude().name).copied(),
                    ),
                    _ => (None, None),
                };
                let covered = match (ci, magnitude) {
                    (Some([lo, hi]), Some(m)) => {
                        Some(m >= lo * (1.0 - 1e-9) && m <= hi * (1.0 + 1e-9))
                    }
                    _ => None,
                };
                let log_error = match (fitted, magnitude) {
                    (Some(f), Some(m)) => Some((f / m).ln().abs()),
                    _ => None,
                };
                cases.push(CaseRow {
                    noise,
                    seed,
                    true_effect: true_name,
                    multiple: *k,
                    magnitude,
                    above_threshold: above,
                    called,
                    correct,
                    fitted,
                    ci,
                    covered,
                    log_error,
                    gap_before: d.gap_before,
                    gap_after: d.best.as_ref().map(|b| b.gap_after),
                    shrink_pct: d.best.as_ref().map(|b| b.shrink_pct),
                });
            }
        }
    }

    let mut labels: Vec<String> = effects.iter().map(|e| e.name.clone()).collect();
    labels.push("none".into());
    let idx = |name: &Option<String>| -> usize {
        match name {
            Some(n) => labels
                .iter()
                .position(|l| l == n)
                .unwrap_or(labels.len() - 1),
            None => labels.len() - 1,
        }
    };
    let mut confusion = Vec::new();
    for &noise in &opts.noise_levels {
        let mut counts = vec![vec![0usize; labels.len()]; labels.len()];
        let here: Vec<&CaseRow> = cases
            .iter()
            .filter(|c| (c.noise - noise).abs() < 1e-12)
            .collect();
        for c in &here {
            if c.above_threshold || c.true_effect.is_none() {
                counts[idx(&c.true_effect)][idx(&c.called)] += 1;
            }
        }
        let above: Vec<&&CaseRow> = here.iter().filter(|c| c.above_threshold).collect();
        let nulls: Vec<&&CaseRow> = here.iter().filter(|c| c.true_effect.is_none()).collect();
        let covered: Vec<bool> = here.iter().filter_map(|c| c.covered).collect();
        confusion.push(Confusion {
            noise,
            labels: labels.clone(),
            counts,
            identification_rate_above_threshold: if above.is_empty() {
                f64::NAN
            } else {
                above.iter().filter(|c| c.correct).count() as f64 / above.len() as f64
            },
            cases_above_threshold: above.len(),
            false_alarms: nulls.iter().filter(|c| c.called.is_some()).count(),
            null_cases: nulls.len(),
            coverage: if covered.is_empty() {
                f64::NAN
            } else {
                covered.iter().filter(|c| **c).count() as f64 / covered.len() as f64
            },
            median_log_error: median(here.iter().filter_map(|c| c.log_error).collect()),
            median_shrink_pct: median(
                here.iter()
                    .filter(|c| c.correct && c.true_effect.is_some())
                    .filter_map(|c| c.shrink_pct)
                    .collect(),
            ),
        });
    }
    Ok(BenchmarkResult {
        design: opts.design.clone(),
        conditions: conditions.len(),
        seeds: opts.seeds,
        null_seeds: opts.null_seeds,
        multiples: opts.multiples.clone(),
        thresholds,
        confusion,
        cases,
        walks: cache.walks.load(std::sync::atomic::Ordering::Relaxed),
        seconds: start.elapsed().as_secs_f64(),
        seconds_per_diagnosis: diag_seconds / n_diag.max(1) as f64,
    })
}
