//! The benchmark: the diagnosis on cases whose cause is known, inside and outside what it
//! assumes. Every case is a row of a points file (resumable, shardable, mergeable like the
//! sweeps) holding the posterior's leading explanations, so the decision can be scored at
//! any threshold afterwards (`scoring.rs`).
//!
//! Suites (each over one set of conditions, so the knobs' walks are shared through a
//! [`SimCache`]):
//! * `main`: the design's default conditions (3 sizes × 4 drives). Null cases per noise
//!   level; every library effect alone at multiples of its identification threshold; every
//!   pair at twice theirs (and on their noise-free trials); nominal-parameter errors
//!   (declared or not, [`super::cases`]); a declared error with each effect (compound).
//! * `one-robot`: one size, conditions varied by drive, amplitude, payload and slope.
//! * `drake/<folder>`: trials Drake made (`tests/golden/drake/<folder>/trials-*.csv`, named
//!   by the effects Drake added), with measurement noise, diagnosed as they are or through
//!   the folder's no-effect trials (`…-ref`); logs, where the files name them, get sensor
//!   noise of their own.
//!
//! A run can take its cases from another points file ([`BenchmarkOptions::cases_from`]):
//! the same truths, keys and noise draws, for a side-by-side comparison.

use std::path::Path;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::cases::resolve_design;
use super::diagnose::{DiagnoseOptions, Diagnosis, diagnose_conditions};
use super::error::GapError;
use super::hypothesis::NONE_OF_THESE;
use super::knob::ModelSetting;
use super::library::EffectLibrary;
use super::observe::Logs;
use super::plan::{
    BenchmarkOptions, CaseSpec, DRAKE_NONE, EXPECTED_PAIR, Plan, Suite, Truth, pairs, truth_setting,
};
pub use super::plan::{parse_pairs, split};
use super::simulate::{Condition, SimMetrics};
use super::synth::{SensorNoise, add_noise, add_sensor_noise, expected_trials, truth_metrics};
use super::trials::TrialSet;
use super::waveform::LogSample;
use crate::checkpoint::{Shard, SweepPoint, append_to, finish_points, open_log, spec_line};
use crate::progress::{Observer, Silent};
use crate::sim::Design;

pub const BENCHMARK_KIND: &str = "gap-benchmark-posterior";

/// The outcome of one case: a row of the points file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseRow {
    pub key: String,
    pub suite: String,
    pub kind: String,
    pub noise: f64,
    pub seed: u64,
    pub calibrate: bool,
    pub multiple: Option<f64>,
    /// What made the trials, as `name=value` pairs joined by `;`.
    pub truth_effects: String,
    pub truth_params: String,
    /// The parameter-error truth is a declared uncertain parameter of the design.
    pub truth_declared: bool,
    /// The explanation that made the trials as the diagnosis labels explanations (knob
    /// labels, sorted, joined by " + "; "nominal"), or "something outside these".
    pub truth: String,
    /// The answer under the criterion the case ran with.
    pub answer: String,
    /// The most probable explanations, `label=p` joined by `;` (eight at most).
    pub leading: String,
    /// The truth's posterior probability.
    pub truth_probability: f64,
    /// Σ p² over every explanation (the Brier score's part that needs them all).
    pub sum_p2: f64,
    /// Posterior-predictive p-value of the most probable explanation.
    pub fit_p: f64,
    /// 95 % credible intervals of the most probable explanation's knobs: `knob=lo..hi`
    /// (`knob=±lo..hi`: a magnitude) joined by `;`.
    pub intervals: String,
    pub gap_before: f64,
    pub walks: usize,
    /// Trials whose logged cycles entered the likelihood.
    pub logged_trials: usize,
    /// With every explanation confirmed by walks (the cases `exhaustive` names): its most
    /// probable explanation and probability; empty otherwise.
    #[serde(default)]
    pub exhaustive_top: String,
    #[serde(default)]
    pub exhaustive_probability: Option<f64>,
}

impl SweepPoint for CaseRow {
    fn key(&self) -> String {
        self.key.clone()
    }
}

/// A deterministic 64-bit seed from a case key (FNV-1a).
pub(crate) fn seed_of(key: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in key.as_bytes() {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The specification line of a benchmark's points file.
pub fn spec(opts: &BenchmarkOptions) -> String {
    spec_line(
        BENCHMARK_KIND,
        &serde_json::to_string(&(env!("CARGO_PKG_VERSION"), opts)).unwrap_or_default(),
    )
}

/// The trials (and in-memory logs) of a case.
fn trials_of(
    case: &CaseSpec,
    plan: &Plan,
    suite: &Suite,
    lib: &EffectLibrary,
    design: &Design,
) -> Result<(TrialSet, Option<Logs>, Option<TrialSet>), GapError> {
    let set = |key: &str, trials| TrialSet {
        origin: key.to_string(),
        base_dir: suite.base.base_dir.clone(),
        trials,
    };
    let conditions = &suite.base.trials;
    let noisy = |truth: &[SimMetrics], key: &str| {
        set(
            key,
            add_noise(conditions, truth, case.noise, seed_of(key), "benchmark"),
        )
    };
    match &case.truth {
        Truth::Sim { params, effects } => {
            let setting = truth_setting(lib, design, params, effects)?;
            let truth: Vec<SimMetrics> = if setting == ModelSetting::nominal() {
                suite
                    .cache
                    .get(&suite.conditions, lib, &setting, &Silent)?
                    .iter()
                    .map(|w| w.metrics)
                    .collect()
            } else {
                truth_metrics(&suite.conditions, lib, &setting, &Silent)?
            };
            let trials = if case.kind == EXPECTED_PAIR {
                let expected = expected_trials(conditions, &truth, case.noise, "benchmark");
                set(&case.key, expected)
            } else {
                noisy(&truth, &case.key)
            };
            Ok((trials, None, None))
        }
        Truth::Drake {
            folder,
            file,
            reference,
            ..
        } => {
            let get = |f: &str| {
                plan.drake
                    .get(&(folder.clone(), f.to_string()))
                    .ok_or_else(|| GapError::Invalid(format!("no Drake trials {folder}/{f}")))
            };
            let f = get(file)?;
            let trials = noisy(&f.truth, &case.key);
            let sensor = |logs: &[Option<Vec<LogSample>>], key: &str| {
                logs.iter()
                    .enumerate()
                    .map(|(i, l)| {
                        l.as_ref().map(|l| {
                            add_sensor_noise(
                                l,
                                SensorNoise::default(),
                                seed_of(&format!("{key}/log/{i}")),
                            )
                        })
                    })
                    .collect::<Vec<_>>()
            };
            let rkey = format!("{}/reference", case.key);
            let (reference, reference_logs) = if *reference {
                let none = get(DRAKE_NONE)?;
                (Some(noisy(&none.truth, &rkey)), sensor(&none.logs, &rkey))
            } else {
                (None, Vec::new())
            };
            let logs = f.logs.iter().any(Option::is_some).then(|| Logs {
                trials: sensor(&f.logs, &case.key),
                reference: reference_logs,
            });
            Ok((trials, logs, reference))
        }
    }
}

/// Runs one case.
fn run_case(
    case: &CaseSpec,
    plan: &Plan,
    lib: &EffectLibrary,
    design: &Design,
    opts: &BenchmarkOptions,
) -> Result<CaseRow, GapError> {
    let suite = plan
        .suites
        .iter()
        .find(|s| s.name == case.suite)
        .ok_or_else(|| GapError::Invalid(format!("no suite {}", case.suite)))?;
    let (set, logs, reference) = trials_of(case, plan, suite, lib, design)?;
    let mut dopts = DiagnoseOptions::new()?;
    dopts.reference = reference;
    dopts.logs = logs;
    dopts.calibrate = case.calibrate;
    dopts.undeclared = opts.undeclared;
    dopts.criterion.prior = opts.prior;
    dopts.search.confirm = opts.search_confirm;
    let walks0 = suite.cache.walks();
    let (d, _) = diagnose_conditions(&set, &suite.conditions, lib, &dopts, &suite.cache, &Silent)?;
    let mut row = CaseRow::unanswered(case, design, &suite.conditions);
    fill_row(&mut row, &d);
    if opts
        .exhaustive
        .iter()
        .any(|k| case.key.contains(k.as_str()))
    {
        dopts.search.exhaustive = true;
        let (e, _) =
            diagnose_conditions(&set, &suite.conditions, lib, &dopts, &suite.cache, &Silent)?;
        if let Some(top) = e.posterior.first() {
            row.exhaustive_top = normalise_label(&top.explanation);
            row.exhaustive_probability = Some(top.probability);
        }
    }
    row.walks = suite.cache.walks() - walks0;
    Ok(row)
}

/// An explanation's label with its knobs sorted, so that labels compare as sets.
pub fn normalise_label(label: &str) -> String {
    let mut parts: Vec<&str> = label.split(" + ").collect();
    parts.sort();
    parts.join(" + ")
}

/// The row's answer fields from a diagnosis.
fn fill_row(row: &mut CaseRow, d: &Diagnosis) {
    let truth = row.truth.clone();
    row.answer = format!("{:?}", d.answer.kind);
    row.leading = d
        .posterior
        .iter()
        .take(8)
        .map(|l| format!("{}={}", normalise_label(&l.explanation), l.probability))
        .collect::<Vec<_>>()
        .join(";");
    row.truth_probability = d
        .posterior
        .iter()
        .find(|l| normalise_label(&l.explanation) == truth)
        .map_or(0.0, |l| l.probability);
    row.sum_p2 = d.posterior.iter().map(|l| l.probability.powi(2)).sum();
    row.fit_p = d.answer.fit_p;
    row.intervals = d
        .explanations
        .first()
        .map(|e| {
            e.knobs
                .iter()
                .map(|n| {
                    let sign = if n.sign_identified { "" } else { "±" };
                    format!("{}={sign}{}..{}", n.knob, n.interval[0], n.interval[1])
                })
                .collect::<Vec<_>>()
                .join(";")
        })
        .unwrap_or_default();
    row.gap_before = d.gap_before;
    row.logged_trials = d.logged_trials;
}

impl CaseRow {
    /// The row of a case before its answer: what made its trials, nothing answered.
    fn unanswered(case: &CaseSpec, design: &Design, conditions: &[Condition]) -> CaseRow {
        let (truth_effects, truth_params, truth_declared) = match &case.truth {
            Truth::Sim { params, effects } => (
                pairs(effects),
                pairs(params),
                !params.is_empty()
                    && params
                        .iter()
                        .all(|(p, _)| design.uncertain.iter().any(|u| &u.path == p)),
            ),
            Truth::Drake { effects, .. } => (pairs(effects), String::new(), false),
        };
        let target = conditions.first().map_or(design, |c| &c.design);
        CaseRow {
            key: case.key.clone(),
            suite: case.suite.clone(),
            kind: case.kind.clone(),
            noise: case.noise,
            seed: case.seed,
            calibrate: case.calibrate,
            multiple: case.multiple,
            truth: truth_label(&case.truth, target, case.calibrate),
            truth_effects,
            truth_params,
            truth_declared,
            answer: String::new(),
            leading: String::new(),
            truth_probability: f64::NAN,
            sum_p2: f64::NAN,
            fit_p: f64::NAN,
            intervals: String::new(),
            gap_before: f64::NAN,
            walks: 0,
            logged_trials: 0,
            exhaustive_top: String::new(),
            exhaustive_probability: None,
        }
    }
}

/// The explanation a truth is, as the diagnosis of trials of `design` labels it (sorted);
/// "something outside these" where it is none of the explanations weighed: more than two
/// suspects, a number neither declared nor audited, an undeclared number with another, a
/// Drake case not through a reference (the engine differs from ours), or a declared
/// parameter when the parameters are not suspects.
pub fn truth_label(truth: &Truth, design: &Design, calibrate: bool) -> String {
    // A number counts as its suspect only inside the range its prior covers.
    let inside = |list: Vec<crate::sim::design::UncertainParam>, p: &str, v: f64| {
        list.iter()
            .any(|u| u.path == p && v >= u.lo.min(u.hi) && v <= u.hi.max(u.lo))
    };
    let declared_list = design.uncertain_params().unwrap_or_default();
    let audited_list = design.undeclared_params().unwrap_or_default();
    let declared = |p: &str| design.uncertain.iter().any(|u| u.path == p);
    let (params, effects) = match truth {
        Truth::Sim { params, effects } => (params.clone(), effects.clone()),
        Truth::Drake {
            reference, effects, ..
        } => {
            if !reference {
                return NONE_OF_THESE.into();
            }
            (Vec::new(), effects.clone())
        }
    };
    let mut knobs: Vec<String> = Vec::new();
    let mut undeclared = 0;
    for (p, v) in &params {
        if declared(p) && calibrate && inside(declared_list.clone(), p, *v) {
            knobs.push(format!("{}:{p}", design.name));
        } else if inside(audited_list.clone(), p, *v) {
            undeclared += 1;
            knobs.push(format!("{}:{p}", design.name));
        } else {
            return NONE_OF_THESE.into();
        }
    }
    let lib = EffectLibrary::bundled().ok();
    for (e, _) in &effects {
        let alias = lib
            .as_ref()
            .and_then(|l| l.get(e).ok())
            .and_then(|d| d.replaces.clone())
            .filter(|f| declared(f) && calibrate);
        knobs.push(match alias {
            Some(f) => format!("{}:{f}", design.name),
            None => e.clone(),
        });
    }
    if knobs.is_empty() {
        return "nominal".into();
    }
    if knobs.len() > 2 || (undeclared > 0 && knobs.len() > 1) {
        return NONE_OF_THESE.into();
    }
    knobs.sort();
    knobs.join(" + ")
}

/// Runs the plan's cases of `shard` (all when whole), appending each finished case to the
/// points file; returns every row of the file (done before and now).
pub fn run(
    lib: &EffectLibrary,
    opts: &BenchmarkOptions,
    plan: &Plan,
    points: Option<&Path>,
    shard: Shard,
    progress: &dyn Observer,
) -> Result<Vec<CaseRow>, GapError> {
    let design = resolve_design(&opts.design)?;
    let header = spec(opts);
    let (log, done) = open_log::<CaseRow>(points, &header)?;
    let todo: Vec<&CaseSpec> = plan
        .cases
        .iter()
        .enumerate()
        .filter(|(k, c)| shard.takes(*k) && !done.contains_key(&c.key))
        .map(|(_, c)| c)
        .collect();
    let total = todo.len();
    let count = std::sync::atomic::AtomicUsize::new(0);
    let new: Vec<CaseRow> = todo
        .par_iter()
        .map(|c| {
            // A case whose trials cannot be diagnosed (the truth made every walk fall, so
            // nothing was measured) is a row saying so, not the end of the benchmark.
            let row = match run_case(c, plan, lib, &design, opts) {
                Ok(r) => r,
                Err(GapError::File { message, .. }) => CaseRow {
                    answer: format!("NotDiagnosed: {message}"),
                    ..CaseRow::unanswered(c, &design, &[])
                },
                Err(e) => return Err(e),
            };
            append_to(log.as_ref(), &row)?;
            let k = count.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress.stage(&format!("{k}/{total} cases ({})", c.key));
            Ok(row)
        })
        .collect::<Result<_, GapError>>()?;
    let mut rows: Vec<CaseRow> = done.into_values().chain(new).collect();
    rows.sort_by(|a, b| a.key.cmp(&b.key));
    if let Some(p) = points
        && shard == Shard::WHOLE
    {
        finish_points(p, &header, &rows)?;
    }
    Ok(rows)
}
