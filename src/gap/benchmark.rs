//! Benchmark 2.0: the diagnosis on cases whose cause is known, inside and outside what it
//! assumes.
//!
//! Suites (each over one set of conditions, so the knobs' grid walks are shared through a
//! [`SimCache`]):
//! * `main`: the design's default conditions (3 sizes × 4 drives). Null cases (no cause)
//!   per noise level; every library effect alone at multiples of its identification
//!   threshold; every pair of effects at 2× their thresholds; nominal-parameter errors
//!   (declared uncertain or not, inside or outside their ranges), an unreported slope, a
//!   drive amplitude off; the single effects again with calibration off; every pair again
//!   on its expected (noise-free) trials, the ceiling of what any rule could name from such
//!   trials; a declared parameter error together with each effect (compound cases). The
//!   parameter and compound errors are data ([`super::cases`]: `dataset/benchmarks/<design>.toml`,
//!   or derived from any other design's declarations).
//! * `one-robot`: one size, conditions varied by drive frequency, amplitude, payload and
//!   slope, as a user with one robot would measure.
//! * `drake`: trials made by Drake on the reference design (`tests/golden/drake/gap/`),
//!   with and without an effect added in Drake, plus measurement noise. Where the trials
//!   name robot logs (`tests/golden/drake/gap-lagged-logs/`), the logs get sensor noise too
//!   and the diagnosis is followed by the logged cycles ([`super::separate::follow_up_with`]).
//!
//! Every case is a row of a points file (resumable, shardable, mergeable like the sweeps);
//! the scores are computed from the rows ([`summarize`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::cache::SimCache;
use super::cases::BenchmarkCases;
use super::diagnose::{DiagnoseOptions, diagnose_conditions};
use super::error::GapError;
use super::identify::Identifiability;
use super::knob::ModelSetting;
use super::library::{EffectLibrary, EffectSetting};
use super::select::SelectOptions;
use super::separate::{CycleCache, FollowPurpose, Reference, SeparateOptions, follow_up_with};
use super::simulate::{Condition, SimMetrics, resolve};
use super::synth::{
    SensorNoise, add_noise, add_sensor_noise, default_conditions, expected_trials, truth_metrics,
};
use super::trials::{Measurement, Metric, Trial, TrialSet};
use super::waveform::{CycleSignature, LogSample};
use crate::checkpoint::{Shard, SweepPoint, append_to, finish_points, open_log, spec_line};
use crate::progress::{Observer, Silent};
use crate::regression::dist::{binomial_interval, binomial_upper_bound};
use crate::sim::Design;

pub const BENCHMARK_KIND: &str = "gap-benchmark";

/// The kind of a pair case run on its expected (noise-free) trials.
pub const EXPECTED_PAIR: &str = "pair-expected";

/// Every kind of case a plan holds (`--kinds`).
pub const KINDS: [&str; 7] = [
    "null",
    "effect",
    "pair",
    EXPECTED_PAIR,
    "parameter",
    "compound",
    "drake",
];

#[derive(Clone, Debug, Serialize)]
pub struct BenchmarkOptions {
    pub design: String,
    /// Noise levels of the null and single-effect cases.
    pub noise_levels: Vec<f64>,
    /// Null cases per noise level (main suite).
    pub null_cases: u64,
    /// Seeds per non-null case.
    pub seeds: u64,
    /// Single effects at these multiples of their identification threshold.
    pub multiples: Vec<f64>,
    /// Noise of the pair, parameter-error and Drake cases.
    pub pair_noise: f64,
    pub pair_multiple: f64,
    /// Nominal-parameter errors: each a list of `path=value` (the design at 1×).
    pub parameter_errors: Vec<Vec<(String, f64)>>,
    pub parameter_noise: Vec<f64>,
    /// Folder of the Drake trials (`tests/golden/drake/gap`), if any.
    pub drake_dir: Option<PathBuf>,
    pub drake_seeds: u64,
    /// Null cases of the one-robot suite (0: no one-robot suite).
    pub one_robot_null_cases: u64,
    /// Run the single-effect cases at this noise again with calibration off.
    pub calibration_off_noise: Option<f64>,
    /// Compound cases: each of these nominal-parameter errors together with every effect at
    /// the pair multiple of its threshold, at the pair noise (the answer "both").
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub compound_errors: Vec<Vec<(String, f64)>>,
    pub effects: Vec<String>,
    /// The selection of every case (the diagnosis' default in the standard run). Flattened
    /// into the points file's signature, where only its rules that are on appear
    /// ([`SelectOptions`]'s serialisation): a run with other rules is another benchmark and
    /// cannot resume this one's file, and a run with all of them off
    /// (`SelectOptions::plain`) has the signature of the files written before they were the
    /// default.
    #[serde(flatten)]
    pub select: SelectOptions,
    /// The undeclared-parameter audit on every case ([`super::audit`]); written into the
    /// signature only when on.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub audit_undeclared: bool,
    /// With the audit: the declared partners walked beside an undeclared number
    /// ([`DiagnoseOptions::audit_partners`]); written into the signature only when > 0, so
    /// the audit's points file of one number at a time keeps its signature.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub audit_partners: u64,
    /// The model's spread over this many perturbed starts counted as noise in every case
    /// ([`super::diagnose::model_spread`]); written into the signature only when > 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub model_spread_seeds: u64,
    /// Each Drake case diagnosed relative to a noisy copy (another seed) of the folder's
    /// `trials-none.csv` ([`super::reference`]); written into the signature only when on.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub drake_reference: bool,
    /// The nominal model the Drake cases are diagnosed against, in place of their files'
    /// `design` (e.g. `mugatu-ref-sap`, the reference with SAP's convex friction cone, for
    /// trials Drake-SAP made from `mugatu-ref`); written into the signature only when set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drake_design: Option<String>,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

impl BenchmarkOptions {
    /// The benchmark for a design: its out-of-library cases from
    /// `dataset/benchmarks/<design>.toml`, or derived from the design ([`BenchmarkCases`]).
    pub fn standard(design: &str) -> Result<BenchmarkOptions, GapError> {
        Ok(Self::with_cases(
            design,
            BenchmarkCases::for_design(design)?,
        ))
    }

    /// The benchmark for a design with these out-of-library cases.
    pub fn with_cases(design: &str, cases: BenchmarkCases) -> BenchmarkOptions {
        BenchmarkOptions {
            design: design.to_string(),
            noise_levels: vec![0.01, 0.03, 0.05, 0.10],
            null_cases: 300,
            seeds: 3,
            multiples: vec![1.0, 2.0, 4.0],
            pair_noise: 0.03,
            pair_multiple: 2.0,
            parameter_errors: cases.parameter_errors,
            parameter_noise: vec![0.03, 0.05],
            drake_dir: None,
            drake_seeds: 5,
            one_robot_null_cases: 100,
            calibration_off_noise: Some(0.05),
            compound_errors: cases.compound_errors,
            effects: Vec::new(),
            select: SelectOptions::default(),
            audit_undeclared: false,
            audit_partners: 0,
            model_spread_seeds: 0,
            drake_reference: false,
            drake_design: None,
        }
    }
}

/// What a case's trials are made from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Truth {
    /// The simulator under a setting: parameter values (path, value at 1×) and effects
    /// (name, magnitude in SI at 1×).
    Sim {
        params: Vec<(String, f64)>,
        effects: Vec<(String, f64)>,
    },
    /// A Drake trials file (exact metrics) and the effects added in Drake: none, one, or
    /// several at once (`trials-<effect>-<value>+<effect>-<value>.csv`).
    Drake {
        file: String,
        effects: Vec<(String, f64)>,
    },
}

/// One case to run.
#[derive(Clone, Debug)]
pub struct CaseSpec {
    pub key: String,
    pub suite: String,
    pub kind: String,
    pub noise: f64,
    pub seed: u64,
    pub calibrate: bool,
    pub multiple: Option<f64>,
    pub truth: Truth,
}

/// The outcome of one case: a row of the points file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseRow {
    pub key: String,
    pub suite: String,
    /// null, effect, pair, parameter, drake.
    pub kind: String,
    pub noise: f64,
    pub seed: u64,
    pub calibrate: bool,
    pub multiple: Option<f64>,
    /// What made the trials, as `name=value` pairs joined by `;` (empty: nothing).
    pub truth_effects: String,
    pub truth_params: String,
    /// The parameter-error truth is a declared uncertain parameter of the design.
    pub truth_declared: bool,
    pub answer: String,
    /// Named knobs (`;`-joined): effects, and parameters as `design:path`.
    pub named_effects: String,
    pub named_params: String,
    /// Named knobs with their 95 % intervals: `knob=lo..hi` (`knob=±lo..hi`: a magnitude, its
    /// sign not identified) joined by `;`.
    pub intervals: String,
    /// Groups of knobs the trials could not tell apart (`a|b` joined by `;`): not named.
    pub ambiguous: String,
    /// Leads of a partly explained answer (`;`-joined): not named.
    pub leads: String,
    pub gap_before: f64,
    pub gap_after: Option<f64>,
    pub walks: usize,
    /// Trials whose logged cycles were compared after the diagnosis (Drake trials with
    /// robot logs); 0: none (the next two fields are then empty).
    #[serde(default)]
    pub logged_trials: usize,
    /// What the cycles said, per separation: `ambiguous:a|b→verdict` or
    /// `confirm:a|b|c→verdict`, `;`-joined.
    #[serde(default)]
    pub cycles: String,
    /// The names that stand with the cycles (`;`-joined; effects, and parameters as
    /// `design:path`).
    #[serde(default)]
    pub cycles_named: String,
}

impl SweepPoint for CaseRow {
    fn key(&self) -> String {
        self.key.clone()
    }
}

fn split(s: &str) -> Vec<String> {
    s.split(';')
        .filter(|x| !x.is_empty())
        .map(str::to_string)
        .collect()
}

fn pairs(v: &[(String, f64)]) -> String {
    v.iter()
        .map(|(k, x)| format!("{k}={x}"))
        .collect::<Vec<_>>()
        .join(";")
}

fn parse_pairs(s: &str) -> Vec<(String, f64)> {
    split(s)
        .into_iter()
        .filter_map(|p| {
            let (k, v) = p.split_once('=')?;
            Some((k.to_string(), v.parse().ok()?))
        })
        .collect()
}

/// A deterministic 64-bit seed from a case key (FNV-1a).
fn seed_of(key: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in key.as_bytes() {
        h ^= *b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The conditions of the one-robot suite: the design at its own size, drive frequency
/// 0.97–1.03 × its own, amplitude ±4° (servo designs), payload +10 % and +20 %, slope ±1°.
pub fn one_robot_conditions(design_name: &str) -> Result<Vec<Trial>, GapError> {
    let d = Design::resolve(design_name).map_err(|e| GapError::Sim {
        origin: design_name.to_string(),
        source: e,
    })?;
    let f0 = d.controller().frequency_hz().unwrap_or(1.0);
    let l = d.geometry.leg_length_m;
    let m0 = d.mass.total_mass_kg;
    let servo = matches!(d.control, crate::sim::design::ControlSpec::ServoSine { .. });
    let a0 = match d.control {
        crate::sim::design::ControlSpec::ServoSine { amplitude_deg, .. } => Some(amplitude_deg),
        _ => None,
    };
    let mut out = Vec::new();
    let mut add = |label: &str, f: f64, a: Option<f64>, m: Option<f64>, s: Option<f64>| {
        let mut t = Trial::condition(design_name, l);
        t.label = label.to_string();
        t.frequency_hz = Some((f0 * f * 1e6).round() / 1e6);
        t.amplitude_deg = a;
        t.mass_kg = m.map(|k| (m0 * k * 1e6).round() / 1e6);
        t.slope_deg = s;
        out.push(t);
    };
    for k in [0.97, 1.0, 1.03] {
        add(&format!("f{k}x"), k, None, None, None);
    }
    if servo && let Some(a) = a0 {
        add("A-4", 1.0, Some(a - 4.0), None, None);
        add("A+4", 1.0, Some(a + 4.0), None, None);
    } else {
        add("f0.985x", 0.985, None, None, None);
        add("f1.015x", 1.015, None, None, None);
    }
    add("m+10%", 1.0, None, Some(1.1), None);
    add("m+20%", 1.0, None, Some(1.2), None);
    add("m+20%-f0.97x", 0.97, None, Some(1.2), None);
    add("m+20%-f1.03x", 1.03, None, Some(1.2), None);
    add("slope+1", 1.0, None, None, Some(1.0));
    add("slope-1", 1.0, None, None, Some(-1.0));
    add("slope+1-m+10%", 1.0, None, Some(1.1), Some(1.0));
    Ok(out)
}

/// The per-effect identification thresholds (SI) of a set of conditions at a noise level:
/// the diagnosis of a noiseless "measurement" of the nominal with that noise's sds. With
/// `calibrate`, against the other effects, every uncertain parameter and their
/// recalibration; without, against the other effects only.
#[allow(clippy::too_many_arguments)]
pub fn thresholds(
    set: &TrialSet,
    conditions: &[Condition],
    nominal: &[SimMetrics],
    lib: &EffectLibrary,
    noise: f64,
    effects: &[String],
    calibrate: bool,
    cache: &SimCache,
) -> Result<Vec<Identifiability>, GapError> {
    let mut s = set.clone();
    for (t, m) in s.trials.iter_mut().zip(nominal) {
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
    let opts = DiagnoseOptions {
        effects: effects.to_vec(),
        calibrate,
        explanations: false,
        identifiability: true,
        // The thresholds depend neither on the selection (its plain rules are the quickest)
        // nor on the audit of its answer.
        select: SelectOptions::plain(),
        audit_undeclared: false,
        ..DiagnoseOptions::default()
    };
    Ok(
        diagnose_conditions(&s, conditions, lib, &opts, cache, &Silent)?
            .0
            .identifiability,
    )
}

/// The magnitude (SI) `multiple` times as strong as `threshold`, away from the effect's
/// off value, kept inside the plausible range by a margin of 15 % (in log): a truth at a
/// range end is never called (the fit cannot tell it from one beyond), by design.
pub(crate) fn magnitude_at(
    lib: &EffectLibrary,
    design: &Design,
    effect: &str,
    threshold: f64,
    multiple: f64,
) -> f64 {
    let Ok(def) = lib.get(effect) else {
        return threshold;
    };
    let p = def.magnitude();
    let scale = p.scale.value(design);
    let off = p.off_nondimensional(design, &def.name) * scale;
    let [lo, hi] = [p.range[0] * scale * 1.15, p.range[1] * scale / 1.15];
    let v = if off == 0.0 {
        threshold * multiple
    } else if off.is_infinite() {
        threshold / multiple
    } else {
        (off.ln() + multiple * (threshold.ln() - off.ln())).exp()
    };
    v.clamp(lo, hi)
}

/// A suite's conditions and the walks of its truths.
struct Suite {
    name: String,
    base: TrialSet,
    conditions: Vec<Condition>,
    cache: SimCache,
    /// Walks with their cycles, shared by the follow-ups of cases with logs.
    cycles: CycleCache,
}

impl Suite {
    fn new(name: &str, base: TrialSet) -> Result<Suite, GapError> {
        let conditions = resolve(&base)?;
        Ok(Suite {
            name: name.into(),
            base,
            conditions,
            cache: SimCache::default(),
            cycles: CycleCache::default(),
        })
    }
}

/// Everything the cases of a run need: suites, thresholds, Drake truths.
pub struct Plan {
    pub cases: Vec<CaseSpec>,
    pub thresholds: BTreeMap<String, Vec<(String, Option<f64>)>>,
    /// The selection's options of every case (the rules the run asks for).
    select: SelectOptions,
    audit_undeclared: bool,
    audit_partners: u64,
    model_spread_seeds: u64,
    drake_reference: bool,
    suites: Vec<Suite>,
    drake: BTreeMap<String, DrakeFile>,
}

/// One Drake trials file: its trials, their metrics as the truth, and the robot logs its
/// rows name (read once; each case adds its own sensor noise).
struct DrakeFile {
    set: TrialSet,
    truth: Vec<SimMetrics>,
    logs: Vec<Option<Vec<LogSample>>>,
}

fn truth_setting(
    lib: &EffectLibrary,
    design: &Design,
    params: &[(String, f64)],
    effects: &[(String, f64)],
) -> Result<ModelSetting, GapError> {
    let mut s = ModelSetting::default();
    for (p, v) in params {
        s.params.push((design.name.clone(), p.clone(), *v));
    }
    for (e, v) in effects {
        let def = lib.get(e)?;
        let mut set: EffectSetting = def.setting(def.magnitude().default);
        set.nondimensional[0] = v / def.magnitude().scale.value(design);
        s.effects.push(set);
    }
    Ok(s)
}

/// Builds the list of cases (deterministic; the same for every shard).
pub fn plan(
    lib: &EffectLibrary,
    opts: &BenchmarkOptions,
    progress: &dyn Observer,
) -> Result<Plan, GapError> {
    let design = Design::resolve(&opts.design).map_err(|e| GapError::Sim {
        origin: opts.design.clone(),
        source: e,
    })?;
    let effect_names: Vec<String> = lib
        .subset(&opts.effects)?
        .iter()
        .map(|e| e.name.clone())
        .collect();

    // The Drake files are read (and their names, conditions and logs checked) before the
    // minutes the thresholds take: a bad file fails at once.
    let mut drake_specs = Vec::new();
    let drake = match &opts.drake_dir {
        Some(dir) => drake_cases(opts, dir, &mut drake_specs)?,
        None => BTreeMap::new(),
    };

    progress.stage("default conditions");
    let main = Suite::new(
        "main",
        TrialSet {
            origin: format!("benchmark conditions of {}", opts.design),
            base_dir: PathBuf::from("."),
            trials: default_conditions(&opts.design)?,
        },
    )?;
    let thr = Thresholds::of_main(lib, opts, &main, &effect_names, progress)?;
    let mut planner = Planner {
        lib,
        opts,
        design: &design,
        effect_names: &effect_names,
        thr: &thr,
        cases: Vec::new(),
    };
    planner.main_cases();
    let mut suites = vec![main];
    if opts.one_robot_null_cases > 0 {
        suites.push(planner.one_robot_cases()?);
    }
    let mut cases = planner.cases;
    cases.append(&mut drake_specs);
    if let Some(first) = drake.values().next() {
        let mut base = first.set.clone();
        for t in base.trials.iter_mut() {
            t.measured = [None; 8];
            // Each case's logs are its file's, in memory (`DrakeFile::logs`).
            t.trajectory = None;
        }
        suites.push(Suite::new("drake", base)?);
    }
    // Two multiples of a threshold clamped to the same end of an effect's range make the
    // same truth: one case (the key is the truth), not two rows that collide.
    let mut seen = std::collections::HashSet::new();
    cases.retain(|c| seen.insert(c.key.clone()));
    Ok(Plan {
        cases,
        thresholds: thr.table,
        select: opts.select.clone(),
        audit_undeclared: opts.audit_undeclared,
        audit_partners: if opts.audit_undeclared {
            opts.audit_partners
        } else {
            0
        },
        model_spread_seeds: opts.model_spread_seeds,
        drake_reference: opts.drake_reference,
        suites,
        drake,
    })
}

/// The main suite's identification thresholds per noise level (keyed by `{noise}`).
struct Thresholds {
    /// Every effect, `None` when not identifiable within its range (for the report).
    table: BTreeMap<String, Vec<(String, Option<f64>)>>,
    /// With calibration.
    on: BTreeMap<String, BTreeMap<String, f64>>,
    /// Calibration off (only at `calibration_off_noise`).
    off: BTreeMap<String, BTreeMap<String, f64>>,
}

impl Thresholds {
    /// The thresholds at every noise level of the null/single cases and at the pair noise.
    fn of_main(
        lib: &EffectLibrary,
        opts: &BenchmarkOptions,
        main: &Suite,
        effect_names: &[String],
        progress: &dyn Observer,
    ) -> Result<Thresholds, GapError> {
        let nominal = main
            .cache
            .get(&main.conditions, lib, &ModelSetting::nominal(), &Silent)?;
        let mut noise_for_thr: Vec<f64> = opts.noise_levels.clone();
        noise_for_thr.push(opts.pair_noise);
        noise_for_thr.sort_by(f64::total_cmp);
        noise_for_thr.dedup();
        let mut out = Thresholds {
            table: BTreeMap::new(),
            on: BTreeMap::new(),
            off: BTreeMap::new(),
        };
        let at = |noise: f64, effects: &[String], calibrate: bool| {
            thresholds(
                &main.base,
                &main.conditions,
                &nominal,
                lib,
                noise,
                effects,
                calibrate,
                &main.cache,
            )
        };
        let named = |ids: &[Identifiability]| -> BTreeMap<String, f64> {
            ids.iter()
                .filter_map(|i| i.identification_threshold.map(|t| (i.effect.clone(), t)))
                .collect()
        };
        for &noise in &noise_for_thr {
            progress.stage(&format!("thresholds at {} % noise", noise * 100.0));
            if opts.calibration_off_noise == Some(noise) {
                let off = at(noise, &opts.effects, false)?;
                out.off.insert(format!("{noise}"), named(&off));
            }
            let mut ids = at(noise, &opts.effects, true)?;
            // Effects the design calibrates as a parameter have no effect knob: their
            // threshold against the other effects (calibration off).
            let missing: Vec<String> = effect_names
                .iter()
                .filter(|e| !ids.iter().any(|i| &i.effect == *e))
                .cloned()
                .collect();
            if !missing.is_empty() {
                let off = at(noise, &missing, false)?;
                ids.extend(off);
                ids.sort_by(|a, b| a.effect.cmp(&b.effect));
            }
            let key = format!("{noise}");
            // An effect not identifiable within its range has no threshold: no case of it
            // is made (the report lists it), since "k times the threshold" does not exist.
            out.table.insert(
                key.clone(),
                ids.iter()
                    .map(|i| (i.effect.clone(), i.identification_threshold))
                    .collect(),
            );
            out.on.insert(key, named(&ids));
        }
        Ok(out)
    }

    /// An effect's threshold at a noise level, with calibration on or off.
    fn get(&self, noise: f64, e: &str, calibrate: bool) -> Option<f64> {
        let map = if calibrate { &self.on } else { &self.off };
        map.get(&format!("{noise}")).and_then(|m| m.get(e)).copied()
    }
}

/// What the simulated cases of one kind in one suite share; each case adds a seed and its
/// truth.
#[derive(Clone, Copy)]
struct Batch<'k> {
    suite: &'k str,
    kind: &'k str,
    noise: f64,
    calibrate: bool,
    multiple: Option<f64>,
}

impl Batch<'_> {
    /// The case of `seed` whose trials the simulator makes from this truth; its key is the
    /// truth.
    fn case(&self, seed: u64, params: &[(String, f64)], effects: &[(String, f64)]) -> CaseSpec {
        let key = format!(
            "{}/{}/{}/{}/n{}/s{seed}{}",
            self.suite,
            self.kind,
            pairs(effects),
            pairs(params),
            self.noise,
            if self.calibrate { "" } else { "/nocal" }
        );
        CaseSpec {
            key,
            suite: self.suite.into(),
            kind: self.kind.into(),
            noise: self.noise,
            seed,
            calibrate: self.calibrate,
            multiple: self.multiple,
            truth: Truth::Sim {
                params: params.to_vec(),
                effects: effects.to_vec(),
            },
        }
    }
}

/// Makes the simulated cases, in the plan's order.
struct Planner<'a> {
    lib: &'a EffectLibrary,
    opts: &'a BenchmarkOptions,
    design: &'a Design,
    effect_names: &'a [String],
    thr: &'a Thresholds,
    cases: Vec<CaseSpec>,
}

impl Planner<'_> {
    /// `seeds` cases of `batch` (seeds 0, 1, …) with this truth.
    fn push(
        &mut self,
        batch: Batch,
        seeds: u64,
        params: &[(String, f64)],
        effects: &[(String, f64)],
    ) {
        self.cases
            .extend((0..seeds).map(|seed| batch.case(seed, params, effects)));
    }

    /// The main suite: nulls, single effects (and again with calibration off), pairs,
    /// compounds, nominal-parameter errors.
    fn main_cases(&mut self) {
        let opts = self.opts;
        let main = |kind, noise, multiple| Batch {
            suite: "main",
            kind,
            noise,
            calibrate: true,
            multiple,
        };
        for &noise in &opts.noise_levels {
            self.push(main("null", noise, None), opts.null_cases, &[], &[]);
        }
        for &noise in &opts.noise_levels {
            self.singles(noise, true);
        }
        if let Some(noise) = opts.calibration_off_noise {
            self.singles(noise, false);
        }
        self.pairs();
        self.compounds();
        for params in &opts.parameter_errors {
            for &noise in &opts.parameter_noise {
                self.push(main("parameter", noise, None), opts.seeds, params, &[]);
            }
        }
    }

    /// Every effect alone at each multiple of its threshold.
    fn singles(&mut self, noise: f64, calibrate: bool) {
        for e in self.effect_names {
            let Some(t) = self.thr.get(noise, e, calibrate) else {
                continue;
            };
            for &k in &self.opts.multiples {
                let mag = magnitude_at(self.lib, self.design, e, t, k);
                let batch = Batch {
                    suite: "main",
                    kind: "effect",
                    noise,
                    calibrate,
                    multiple: Some(k),
                };
                self.push(batch, self.opts.seeds, &[], &[(e.clone(), mag)]);
            }
        }
    }

    /// Every pair of effects, each at the pair multiple of its threshold; and once more on
    /// its expected trials.
    fn pairs(&mut self) {
        let opts = self.opts;
        let batch = |kind| Batch {
            suite: "main",
            kind,
            noise: opts.pair_noise,
            calibrate: true,
            multiple: Some(opts.pair_multiple),
        };
        for (i, a) in self.effect_names.iter().enumerate() {
            for b in &self.effect_names[i + 1..] {
                let (Some(ta), Some(tb)) = (
                    self.thr.get(opts.pair_noise, a, true),
                    self.thr.get(opts.pair_noise, b, true),
                ) else {
                    continue;
                };
                let mag =
                    |e: &str, t| magnitude_at(self.lib, self.design, e, t, opts.pair_multiple);
                let effects = [(a.clone(), mag(a, ta)), (b.clone(), mag(b, tb))];
                self.push(batch("pair"), opts.seeds, &[], &effects);
                // Without the draw one case says it all.
                self.push(batch(EXPECTED_PAIR), 1, &[], &effects);
            }
        }
    }

    /// Each compound parameter error with every effect at the pair multiple of its
    /// threshold.
    fn compounds(&mut self) {
        let opts = self.opts;
        let batch = Batch {
            suite: "main",
            kind: "compound",
            noise: opts.pair_noise,
            calibrate: true,
            multiple: Some(opts.pair_multiple),
        };
        for params in &opts.compound_errors {
            for e in self.effect_names {
                let Some(t) = self.thr.get(opts.pair_noise, e, true) else {
                    continue;
                };
                let mag = magnitude_at(self.lib, self.design, e, t, opts.pair_multiple);
                self.push(batch, opts.seeds, params, &[(e.clone(), mag)]);
            }
        }
    }

    /// The one-robot suite at 5 % noise: nulls, single effects at 2× their (main-suite)
    /// threshold, nominal-parameter errors.
    fn one_robot_cases(&mut self) -> Result<Suite, GapError> {
        let opts = self.opts;
        let one = Suite::new(
            "one-robot",
            TrialSet {
                origin: format!("one-robot conditions of {}", opts.design),
                base_dir: PathBuf::from("."),
                trials: one_robot_conditions(&opts.design)?,
            },
        )?;
        let noise = 0.05;
        let batch = |kind, multiple| Batch {
            suite: "one-robot",
            kind,
            noise,
            calibrate: true,
            multiple,
        };
        self.push(batch("null", None), opts.one_robot_null_cases, &[], &[]);
        for e in self.effect_names {
            let Some(t) = self.thr.get(noise, e, true) else {
                continue;
            };
            let mag = magnitude_at(self.lib, self.design, e, t, 2.0);
            self.push(
                batch("effect", Some(2.0)),
                opts.seeds,
                &[],
                &[(e.clone(), mag)],
            );
        }
        for params in &opts.parameter_errors {
            self.push(batch("parameter", None), opts.seeds, params, &[]);
        }
        Ok(one)
    }
}

/// Drake's no-effect trials (the file's stem), the reference of `--drake-reference`.
const DRAKE_NONE: &str = "trials-none";

/// The Drake cases: every `trials-*.csv` of `dir` (named by the effects Drake added,
/// [`drake_effects`]), `drake_seeds` noisy copies each. Returns the truths by file.
fn drake_cases(
    opts: &BenchmarkOptions,
    dir: &Path,
    cases: &mut Vec<CaseSpec>,
) -> Result<BTreeMap<String, DrakeFile>, GapError> {
    let mut drake: BTreeMap<String, DrakeFile> = BTreeMap::new();
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|source| GapError::Read {
            path: dir.to_path_buf(),
            source,
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|f| f.to_str())
                .is_some_and(|f| f.starts_with("trials-") && f.ends_with(".csv"))
        })
        .collect();
    files.sort();
    if opts.drake_reference
        && !files
            .iter()
            .any(|f| f.file_stem() == Some(DRAKE_NONE.as_ref()))
    {
        return Err(GapError::File {
            path: dir.display().to_string(),
            message: format!("--drake-reference needs the no-effect trials {DRAKE_NONE}.csv here"),
        });
    }
    for f in files {
        let mut set = TrialSet::read(&f)?;
        if let Some(d) = &opts.drake_design {
            for t in set.trials.iter_mut() {
                t.design = d.clone();
            }
        }
        let name = f
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("")
            .to_string();
        let effects = drake_effects(&name).ok_or_else(|| GapError::File {
            path: f.display().to_string(),
            message: format!(
                "a Drake trials file is named {DRAKE_NONE}.csv or \
                 trials-<effect>-<value>[+<effect>-<value>…].csv (the effects Drake added)"
            ),
        })?;
        // One suite serves every Drake file: its conditions must be the first file's.
        if let Some(first) = drake.values().next()
            && !same_conditions(&first.set, &set)?
        {
            return Err(GapError::File {
                path: f.display().to_string(),
                message: format!(
                    "its conditions differ from those of the other Drake trials files in {}",
                    dir.display()
                ),
            });
        }
        let truth: Vec<SimMetrics> = set.trials.iter().map(SimMetrics::measured_by).collect();
        let logs = set
            .trials
            .iter()
            .map(|t| {
                t.trajectory
                    .as_ref()
                    .map(|rel| super::waveform::read_log_csv(&set.base_dir.join(rel)))
                    .transpose()
            })
            .collect::<Result<Vec<_>, _>>()?;
        for seed in 0..opts.drake_seeds {
            let key = format!("drake/{name}/n{}/s{seed}", opts.pair_noise);
            cases.push(CaseSpec {
                key,
                suite: "drake".into(),
                kind: "drake".into(),
                noise: opts.pair_noise,
                seed,
                calibrate: true,
                multiple: None,
                truth: Truth::Drake {
                    file: name.clone(),
                    effects: effects.clone(),
                },
            });
        }
        drake.insert(name, DrakeFile { set, truth, logs });
    }
    Ok(drake)
}

/// The effects Drake added to a trials file, from its stem: `trials-none` none,
/// `trials-<effect>-<value>` one, `+` between several; `None` for any other name. Effect
/// names are snake_case, so the first `-` ends the name (a value may hold one: `1e-3`).
fn drake_effects(stem: &str) -> Option<Vec<(String, f64)>> {
    let rest = stem.strip_prefix("trials-")?;
    if stem == DRAKE_NONE {
        return Some(Vec::new());
    }
    rest.split('+')
        .map(|part| {
            let (effect, value) = part.split_once('-')?;
            let value = value.parse::<f64>().ok().filter(|v| v.is_finite())?;
            (!effect.is_empty()).then(|| (effect.to_string(), value))
        })
        .collect()
}

/// The specification line of a benchmark's points file.
pub fn spec(opts: &BenchmarkOptions) -> String {
    spec_line(
        BENCHMARK_KIND,
        &serde_json::to_string(&(env!("CARGO_PKG_VERSION"), opts)).unwrap_or_default(),
    )
}

/// Two trials files hold the same conditions (each row's design, size and every condition
/// column, in order: [`super::reference::same_condition`]), whatever they measured.
fn same_conditions(a: &TrialSet, b: &TrialSet) -> Result<bool, GapError> {
    let (ca, cb) = (resolve(a)?, resolve(b)?);
    Ok(ca.len() == cb.len()
        && ca
            .iter()
            .zip(&cb)
            .all(|(x, y)| super::reference::same_condition(x, y)))
}

/// Runs one case.
fn run_case(
    case: &CaseSpec,
    plan: &Plan,
    lib: &EffectLibrary,
    design: &Design,
) -> Result<CaseRow, GapError> {
    let suite = plan
        .suites
        .iter()
        .find(|s| s.name == case.suite)
        .ok_or_else(|| GapError::Invalid(format!("no suite {}", case.suite)))?;
    let truth = match &case.truth {
        Truth::Sim { params, effects } => {
            let setting = truth_setting(lib, design, params, effects)?;
            if setting == ModelSetting::nominal() {
                suite.cache.get(&suite.conditions, lib, &setting, &Silent)?
            } else {
                truth_metrics(&suite.conditions, lib, &setting, &Silent)?
            }
        }
        Truth::Drake { file, .. } => plan
            .drake
            .get(file)
            .map(|f| f.truth.clone())
            .ok_or_else(|| GapError::Invalid(format!("no Drake trials {file}")))?,
    };
    let trials = if case.kind == EXPECTED_PAIR {
        expected_trials(&suite.base.trials, &truth, case.noise, "benchmark")
    } else {
        add_noise(
            &suite.base.trials,
            &truth,
            case.noise,
            seed_of(&case.key),
            "benchmark",
        )
    };
    let set = TrialSet {
        origin: case.key.clone(),
        base_dir: suite.base.base_dir.clone(),
        trials,
    };
    // The reference: Drake's no-effect trials with noise of their own (another seed).
    let reference = match &case.truth {
        Truth::Drake { .. } if plan.drake_reference => {
            let truth = &plan
                .drake
                .get(DRAKE_NONE)
                .ok_or_else(|| GapError::Invalid(format!("no Drake trials {DRAKE_NONE}")))?
                .truth;
            let key = format!("{}/reference", case.key);
            Some(TrialSet {
                origin: key.clone(),
                base_dir: suite.base.base_dir.clone(),
                trials: add_noise(
                    &suite.base.trials,
                    truth,
                    case.noise,
                    seed_of(&key),
                    "benchmark",
                ),
            })
        }
        _ => None,
    };
    let opts = DiagnoseOptions {
        reference: reference.clone(),
        effects: Vec::new(),
        calibrate: case.calibrate,
        explanations: false,
        identifiability: false,
        select: plan.select.clone(),
        audit_undeclared: plan.audit_undeclared,
        audit_partners: plan.audit_partners as usize,
        model_spread_seeds: plan.model_spread_seeds,
        ..DiagnoseOptions::default()
    };
    let walks0 = suite.cache.walks();
    let (d, _) = diagnose_conditions(&set, &suite.conditions, lib, &opts, &suite.cache, &Silent)?;
    let cycles = match &case.truth {
        Truth::Drake { file, .. } => {
            drake_cycles(case, plan, suite, file, &set, reference.as_ref(), &d, lib)?
        }
        Truth::Sim { .. } => None,
    };
    let knobs = |v: &[super::diagnose::Named]| {
        v.iter()
            .map(|n| n.knob.clone())
            .collect::<Vec<_>>()
            .join(";")
    };
    Ok(CaseRow {
        answer: format!("{:?}", d.answer.kind),
        named_effects: knobs(&d.answer.effects),
        named_params: knobs(&d.answer.parameters),
        intervals: d
            .answer
            .effects
            .iter()
            .chain(&d.answer.parameters)
            .map(|n| {
                // A magnitude (sign not identified) is marked `±`: it holds a truth of either sign.
                let sign = if n.sign_identified { "" } else { "±" };
                format!("{}={sign}{}..{}", n.knob, n.interval[0], n.interval[1])
            })
            .collect::<Vec<_>>()
            .join(";"),
        leads: knobs(&d.answer.leads),
        ambiguous: d
            .answer
            .ambiguous
            .iter()
            .map(|g| g.join("|"))
            .collect::<Vec<_>>()
            .join(";"),
        gap_before: d.gap_before,
        gap_after: d.chain.last().map(|s| s.gap_after),
        walks: suite.cache.walks() - walks0 + cycles.as_ref().map_or(0, |c| c.walks),
        logged_trials: cycles.as_ref().map_or(0, |c| c.logged_trials),
        cycles: cycles.as_ref().map_or(String::new(), |c| c.said.clone()),
        cycles_named: cycles.map_or(String::new(), |c| c.named),
        ..CaseRow::unanswered(case, design)
    })
}

/// What the logged cycles said about one Drake case.
struct DrakeCycles {
    logged_trials: usize,
    said: String,
    named: String,
    walks: usize,
}

/// The cycles of one trial set's logs, each with sensor noise of its own (seeded by the
/// case's key, the set's role and the trial): `None` where a trial has no log or its log
/// gives no steady cycles.
fn noisy_signatures(
    logs: &[Option<Vec<LogSample>>],
    conditions: &[Condition],
    key: &str,
    settle_cycles: usize,
) -> Result<Vec<Option<CycleSignature>>, GapError> {
    logs.iter()
        .zip(conditions)
        .enumerate()
        .map(|(i, (log, c))| {
            let Some(log) = log else { return Ok(None) };
            let noisy = add_sensor_noise(
                log,
                SensorNoise::default(),
                seed_of(&format!("{key}/log/{i}")),
            );
            let f = c.drive_frequency_hz()?;
            Ok(super::waveform::signature(&noisy, f, settle_cycles).ok())
        })
        .collect()
}

/// A Drake case whose file names robot logs: after the diagnosis, its look-alike groups and
/// its single named knob separated with the logged cycles (sensor noise added as `survey
/// gap synth --logs` adds it), through the no-effect trials' logs when the run is
/// `--drake-reference`. `None` when the file has no logs.
#[allow(clippy::too_many_arguments)]
fn drake_cycles(
    case: &CaseSpec,
    plan: &Plan,
    suite: &Suite,
    file: &str,
    set: &TrialSet,
    reference: Option<&TrialSet>,
    d: &super::diagnose::Diagnosis,
    lib: &EffectLibrary,
) -> Result<Option<DrakeCycles>, GapError> {
    let logs = &plan
        .drake
        .get(file)
        .ok_or_else(|| GapError::Invalid(format!("no Drake trials {file}")))?
        .logs;
    if logs.iter().all(Option::is_none) {
        return Ok(None);
    }
    let opts = SeparateOptions::default();
    let sigs = noisy_signatures(logs, &suite.conditions, &case.key, opts.settle_cycles)?;
    let reference_sigs = match reference {
        Some(_) => {
            let none = plan
                .drake
                .get(DRAKE_NONE)
                .ok_or_else(|| GapError::Invalid(format!("no Drake trials {DRAKE_NONE}")))?;
            Some(noisy_signatures(
                &none.logs,
                &suite.conditions,
                &format!("{}/reference", case.key),
                opts.settle_cycles,
            )?)
        }
        None => None,
    };
    let through = match (reference, &reference_sigs) {
        (Some(r), Some(rs)) => Some(Reference {
            set: r,
            conditions: &suite.conditions,
            sigs: rs,
        }),
        _ => None,
    };
    let f = follow_up_with(
        d,
        set,
        &suite.conditions,
        &sigs,
        through.as_ref(),
        lib,
        &opts,
        &suite.cycles,
        &Silent,
    )?;
    let said = f
        .groups
        .iter()
        .map(|g| {
            let purpose = match &g.purpose {
                FollowPurpose::Ambiguous => "ambiguous",
                FollowPurpose::Confirm { .. } => "confirm",
                FollowPurpose::Explore => "explore",
            };
            let candidates: Vec<String> = g
                .separation
                .rankings
                .first()
                .map(|r| r.fits.iter().map(|c| c.knob.clone()).collect())
                .unwrap_or_default();
            format!(
                "{purpose}:{}→{}",
                candidates.join("|"),
                super::separate::verdict_words(&g.verdict)
            )
        })
        .collect::<Vec<_>>()
        .join(";");
    Ok(Some(DrakeCycles {
        logged_trials: sigs.iter().filter(|s| s.is_some()).count(),
        said,
        named: f.named.join(";"),
        walks: f.groups.iter().map(|g| g.separation.walks).sum(),
    }))
}

impl CaseRow {
    /// The row of a case before its answer: what made its trials, nothing named.
    fn unanswered(case: &CaseSpec, design: &Design) -> CaseRow {
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
        CaseRow {
            key: case.key.clone(),
            suite: case.suite.clone(),
            kind: case.kind.clone(),
            noise: case.noise,
            seed: case.seed,
            calibrate: case.calibrate,
            multiple: case.multiple,
            truth_effects,
            truth_params,
            truth_declared,
            answer: String::new(),
            named_effects: String::new(),
            named_params: String::new(),
            intervals: String::new(),
            ambiguous: String::new(),
            leads: String::new(),
            gap_before: f64::NAN,
            gap_after: None,
            walks: 0,
            logged_trials: 0,
            cycles: String::new(),
            cycles_named: String::new(),
        }
    }
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
    let design = Design::resolve(&opts.design).map_err(|e| GapError::Sim {
        origin: opts.design.clone(),
        source: e,
    })?;
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
            let row = match run_case(c, plan, lib, &design) {
                Ok(r) => r,
                Err(GapError::File { message, .. }) => CaseRow {
                    answer: format!("NotDiagnosed: {message}"),
                    ..CaseRow::unanswered(c, &design)
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

/// One line of a score table.
#[derive(Clone, Debug, Serialize)]
pub struct Score {
    pub what: String,
    pub k: usize,
    pub n: usize,
    pub rate: f64,
    /// 95 % Clopper–Pearson interval of the rate.
    pub interval: [f64; 2],
    /// One-sided 95 % upper bound.
    pub upper_95: f64,
    pub target: String,
}

fn score(what: &str, k: usize, n: usize, target: &str) -> Score {
    let (interval, upper) = if n > 0 {
        (
            binomial_interval(k as u64, n as u64, 0.95).unwrap_or([f64::NAN; 2]),
            binomial_upper_bound(k as u64, n as u64, 0.95).unwrap_or(f64::NAN),
        )
    } else {
        ([f64::NAN; 2], f64::NAN)
    };
    Score {
        what: what.into(),
        k,
        n,
        rate: if n > 0 { k as f64 / n as f64 } else { f64::NAN },
        interval,
        upper_95: upper,
        target: target.into(),
    }
}

/// A confusion matrix: rows the truths, columns what was named first.
#[derive(Clone, Debug, Serialize)]
pub struct Confusion {
    pub title: String,
    pub rows: Vec<String>,
    pub columns: Vec<String>,
    pub counts: Vec<Vec<usize>>,
}

#[derive(Clone, Debug, Serialize)]
pub struct BenchmarkSummary {
    pub design: String,
    pub cases: usize,
    pub scores: Vec<Score>,
    pub confusions: Vec<Confusion>,
    /// Thresholds (SI) per noise level and effect.
    pub thresholds: BTreeMap<String, Vec<(String, Option<f64>)>>,
}

/// Does the case name the truth's effect `e` (or the parameter it is an alias of)?
fn names_effect(row: &CaseRow, e: &str, aliases: &BTreeMap<String, String>) -> bool {
    split(&row.named_effects).iter().any(|n| n == e)
        || aliases.get(e).is_some_and(|p| {
            split(&row.named_params)
                .iter()
                .any(|n| n.ends_with(&format!(":{p}")))
        })
}

/// Is `v` inside a named interval of `knob` (a knob label or `:path` suffix)?
fn covered(row: &CaseRow, knob: &dyn Fn(&str) -> bool, v: f64) -> Option<bool> {
    split(&row.intervals).iter().find_map(|iv| {
        let (k, r) = iv.split_once('=')?;
        if !knob(k) {
            return None;
        }
        interval_holds(r, v)
    })
}

/// Does the interval `lo..hi` (or the magnitudes `±lo..hi`) of a points file hold `v`?
fn interval_holds(interval: &str, v: f64) -> Option<bool> {
    let (r, v) = match interval.strip_prefix('±') {
        Some(magnitude) => (magnitude, v.abs()),
        None => (interval, v),
    };
    let (lo, hi) = r.split_once("..")?;
    let (lo, hi): (f64, f64) = (lo.parse().ok()?, hi.parse().ok()?);
    Some(v >= lo.min(hi) * (1.0 - 1e-9) - 1e-12 && v <= hi.max(lo) * (1.0 + 1e-9) + 1e-12)
}

/// A confusion matrix of `cases`: rows by `truth`, columns by what was `named`, both in
/// sorted order.
fn confusion(
    title: String,
    cases: &[&CaseRow],
    truth: impl Fn(&CaseRow) -> String,
    named: impl Fn(&CaseRow) -> String,
) -> Confusion {
    let mut rows: Vec<String> = Vec::new();
    let mut columns: Vec<String> = Vec::new();
    for r in cases {
        let (t, c) = (truth(r), named(r));
        if !rows.contains(&t) {
            rows.push(t);
        }
        if !columns.contains(&c) {
            columns.push(c);
        }
    }
    rows.sort();
    columns.sort();
    let mut counts = vec![vec![0; columns.len()]; rows.len()];
    for r in cases {
        let (t, c) = (truth(r), named(r));
        if let (Some(i), Some(j)) = (
            rows.iter().position(|x| *x == t),
            columns.iter().position(|x| *x == c),
        ) {
            counts[i][j] += 1;
        }
    }
    Confusion {
        title,
        rows,
        columns,
        counts,
    }
}

/// The scores of the rows (any subset: one shard's, or merged).
pub fn summarize(
    rows: &[CaseRow],
    lib: &EffectLibrary,
    opts: &BenchmarkOptions,
    thresholds: BTreeMap<String, Vec<(String, Option<f64>)>>,
) -> BenchmarkSummary {
    let aliases = effect_aliases(lib, &opts.design);
    let mut noise_levels: Vec<f64> = rows.iter().map(|r| r.noise).collect();
    noise_levels.sort_by(f64::total_cmp);
    noise_levels.dedup();
    let mut scores = Vec::new();
    null_scores(rows, &noise_levels, &mut scores);
    single_effect_scores(rows, &noise_levels, &aliases, &mut scores);
    pair_scores(rows, &aliases, &mut scores);
    compound_scores(rows, &aliases, &mut scores);
    parameter_scores(rows, &mut scores);
    drake_scores(rows, &aliases, &mut scores);
    scores.push(coverage_score(rows, &aliases));
    BenchmarkSummary {
        design: opts.design.clone(),
        cases: rows.len(),
        scores,
        confusions: confusions(rows, &noise_levels),
        thresholds,
    }
}

/// Effects that stand for a declared uncertain parameter of the design (effect → path):
/// naming either is naming the truth.
fn effect_aliases(lib: &EffectLibrary, design: &str) -> BTreeMap<String, String> {
    let design = Design::resolve(design).ok();
    lib.effects
        .iter()
        .filter_map(|e| {
            let f = e.replaces.clone()?;
            design
                .as_ref()
                .is_some_and(|d| d.uncertain.iter().any(|u| u.path == f))
                .then(|| (e.name.clone(), f))
        })
        .collect()
}

fn any_named(r: &CaseRow) -> bool {
    !r.named_effects.is_empty() || !r.named_params.is_empty()
}

fn effect_named(r: &CaseRow) -> bool {
    !r.named_effects.is_empty()
}

/// An effect named that is not among the truth's effects.
fn names_other_effect(r: &CaseRow) -> bool {
    let t = parse_pairs(&r.truth_effects);
    split(&r.named_effects)
        .iter()
        .any(|n| !t.iter().any(|(e, _)| e == n))
}

/// Every effect of the truth named (or its parameter alias).
fn names_every_truth_effect(r: &CaseRow, aliases: &BTreeMap<String, String>) -> bool {
    parse_pairs(&r.truth_effects)
        .iter()
        .all(|(e, _)| names_effect(r, e, aliases))
}

/// Nulls: false alarms per suite and noise level.
fn null_scores(rows: &[CaseRow], noise_levels: &[f64], scores: &mut Vec<Score>) {
    for suite in ["main", "one-robot"] {
        for &noise in noise_levels {
            let nulls: Vec<&CaseRow> = rows
                .iter()
                .filter(|r| r.suite == suite && r.kind == "null" && r.noise == noise)
                .collect();
            if nulls.is_empty() {
                continue;
            }
            scores.push(score(
                &format!(
                    "{suite}: false alarms (anything named) at {:.0} % noise",
                    noise * 100.0
                ),
                nulls.iter().filter(|r| any_named(r)).count(),
                nulls.len(),
                "≤ 1 %",
            ));
        }
    }
}

/// Single effects, per suite, calibration and noise level, multiple ≥ 1.
fn single_effect_scores(
    rows: &[CaseRow],
    noise_levels: &[f64],
    aliases: &BTreeMap<String, String>,
    scores: &mut Vec<Score>,
) {
    for suite in ["main", "one-robot"] {
        for calibrate in [true, false] {
            for &noise in noise_levels {
                let cases: Vec<&CaseRow> = rows
                    .iter()
                    .filter(|r| {
                        r.suite == suite
                            && r.kind == "effect"
                            && r.noise == noise
                            && r.calibrate == calibrate
                    })
                    .collect();
                if cases.is_empty() {
                    continue;
                }
                let right = cases
                    .iter()
                    .filter(|r| names_every_truth_effect(r, aliases))
                    .count();
                let wrong = cases.iter().filter(|r| names_other_effect(r)).count();
                let tag = if calibrate { "" } else { " (calibration off)" };
                scores.push(score(
                    &format!("{suite}: single effect named{tag} at {:.0} % noise (×1, ×2, ×4 thresholds)", noise * 100.0),
                    right,
                    cases.len(),
                    "high",
                ));
                scores.push(score(
                    &format!(
                        "{suite}: another effect named{tag} at {:.0} % noise",
                        noise * 100.0
                    ),
                    wrong,
                    cases.len(),
                    "low",
                ));
            }
        }
    }
}

/// Pairs: both named, and a spurious third knob (effect, or a parameter that is not an
/// alias of a truth effect).
/// The same scores on the pairs' expected (noise-free) trials: the ceiling of any call rule
/// on such trials.
fn pair_scores(rows: &[CaseRow], aliases: &BTreeMap<String, String>, scores: &mut Vec<Score>) {
    for (kind, names, targets) in [
        (
            "pair",
            [
                "pairs of effects at 2× thresholds: both named",
                "pairs: a spurious third knob named",
            ],
            ["≥ 80 %", "≤ 5 %"],
        ),
        (
            EXPECTED_PAIR,
            [
                "pairs of effects at 2× thresholds, on their expected (noise-free) trials: both named",
                "pairs on their expected trials: a spurious third knob named",
            ],
            ["ceiling of the above", "low"],
        ),
    ] {
        let pairs_rows: Vec<&CaseRow> = rows.iter().filter(|r| r.kind == kind).collect();
        if pairs_rows.is_empty() {
            continue;
        }
        let both = pairs_rows
            .iter()
            .filter(|r| names_every_truth_effect(r, aliases))
            .count();
        let third = pairs_rows
            .iter()
            .filter(|r| names_spurious_knob(r, aliases))
            .count();
        scores.push(score(names[0], both, pairs_rows.len(), targets[0]));
        scores.push(score(names[1], third, pairs_rows.len(), targets[1]));
    }
}

/// A knob named that made none of the trials: an effect not in the truth, or a parameter
/// that is neither the truth's nor the alias of a truth effect.
fn names_spurious_knob(r: &CaseRow, aliases: &BTreeMap<String, String>) -> bool {
    let t = parse_pairs(&r.truth_effects);
    let truth_params = truth_params(r);
    names_other_effect(r)
        || split(&r.named_params).iter().any(|n| {
            !truth_params.iter().any(|p| n.ends_with(&format!(":{p}")))
                && !t.iter().any(|(e, _)| {
                    aliases
                        .get(e)
                        .is_some_and(|p| n.ends_with(&format!(":{p}")))
                })
        })
}

/// Compound cases (a parameter error plus an effect). With a declared parameter: the effect
/// named, the parameter named, both, and a knob named that is in neither. With an undeclared
/// one (which no answer can name): the effect named, and a knob named that made none of the
/// trials — a look-alike standing for the undeclared error.
fn compound_scores(rows: &[CaseRow], aliases: &BTreeMap<String, String>, scores: &mut Vec<Score>) {
    for declared in [true, false] {
        let c: Vec<&CaseRow> = rows
            .iter()
            .filter(|r| r.kind == "compound" && r.truth_declared == declared)
            .collect();
        if c.is_empty() {
            continue;
        }
        let count = |pred: &dyn Fn(&CaseRow) -> bool| c.iter().filter(|r| pred(r)).count();
        let effect = |r: &CaseRow| names_every_truth_effect(r, aliases);
        let mut list = vec![("the effect named", count(&effect), "high")];
        // An undeclared error cannot be named: its parameter and "both" scores would be 0
        // by construction.
        if declared {
            let param = |r: &CaseRow| names_every_truth_param(r);
            list.push(("the parameter named", count(&param), "high"));
            let both = |r: &CaseRow| effect(r) && param(r);
            list.push(("both named (the answer \"both\")", count(&both), "high"));
        }
        let spurious = |r: &CaseRow| names_spurious_knob(r, aliases);
        list.push(("a knob in neither named", count(&spurious), "≤ 5 %"));
        let kind = if declared { "declared" } else { "undeclared" };
        for (what, k, target) in list {
            scores.push(score(
                &format!("compound ({kind} parameter error + effect at 2× threshold): {what}"),
                k,
                c.len(),
                target,
            ));
        }
    }
}

/// Every parameter of the truth named.
fn names_every_truth_param(r: &CaseRow) -> bool {
    let named = split(&r.named_params);
    truth_params(r)
        .iter()
        .all(|t| named.iter().any(|n| n.ends_with(&format!(":{t}"))))
}

/// The truth's parameter paths.
fn truth_params(r: &CaseRow) -> Vec<String> {
    parse_pairs(&r.truth_params)
        .into_iter()
        .map(|(k, _)| k)
        .collect()
}

/// Parameter errors per suite: an effect wrongly called, a wrong parameter named, the
/// right declared parameter named, undeclared ones reported unexplained.
fn parameter_scores(rows: &[CaseRow], scores: &mut Vec<Score>) {
    for suite in ["main", "one-robot"] {
        let p: Vec<&CaseRow> = rows
            .iter()
            .filter(|r| r.suite == suite && r.kind == "parameter")
            .collect();
        if p.is_empty() {
            continue;
        }
        scores.push(score(
            &format!("{suite}: parameter errors: a library effect wrongly called"),
            p.iter().filter(|r| effect_named(r)).count(),
            p.len(),
            "≤ 5 %",
        ));
        let wrong_param = |r: &&&CaseRow| {
            let truth = truth_params(r);
            split(&r.named_params)
                .iter()
                .any(|n| !truth.iter().any(|t| n.ends_with(&format!(":{t}"))))
        };
        scores.push(score(
            &format!("{suite}: parameter errors: a wrong parameter named"),
            p.iter().filter(wrong_param).count(),
            p.len(),
            "≤ 10 %",
        ));
        let declared: Vec<&&CaseRow> = p.iter().filter(|r| r.truth_declared).collect();
        scores.push(score(
            &format!("{suite}: parameter errors in a declared parameter: the right one named"),
            declared
                .iter()
                .filter(|r| names_every_truth_param(r))
                .count(),
            declared.len(),
            "high",
        ));
        let undeclared: Vec<&&CaseRow> = p.iter().filter(|r| !r.truth_declared).collect();
        scores.push(score(
            &format!("{suite}: parameter errors outside the declared parameters: reported unexplained (nothing named)"),
            undeclared.iter().filter(|r| !any_named(r)).count(),
            undeclared.len(),
            "high",
        ));
    }
}

/// Drake trials: an effect blamed without one added; with one added, it named and
/// another named — on the answers, and again on the names that stand after the logged
/// cycles where the trials have logs.
fn drake_scores(rows: &[CaseRow], aliases: &BTreeMap<String, String>, scores: &mut Vec<Score>) {
    let drake: Vec<&CaseRow> = rows.iter().filter(|r| r.kind == "drake").collect();
    if drake.is_empty() {
        return;
    }
    drake_rates(
        &drake,
        [
            "Drake, no effect added: an effect blamed",
            "Drake, effect added: that effect named (on top of the engine difference)",
            "Drake, effect added: another effect named",
        ],
        &effect_named,
        &names_other_effect,
        aliases,
        scores,
    );
    // With the logged cycles: the same questions of the names that stand after them.
    let logged: Vec<CaseRow> = drake
        .iter()
        .filter(|r| r.logged_trials > 0)
        .map(|r| with_cycles(r))
        .collect();
    if logged.is_empty() {
        return;
    }
    drake_rates(
        &logged.iter().collect::<Vec<_>>(),
        [
            "Drake with logged cycles, no effect added: anything named (the answer with the cycles)",
            "Drake with logged cycles, effect added: that effect named (the answer with the cycles)",
            "Drake with logged cycles, effect added: another knob named (the answer with the cycles)",
        ],
        &any_named,
        &|r| names_other_knob(r, aliases),
        aliases,
        scores,
    );
}

/// The three Drake rates of `rows` under `labels`: a null case blamed (`blamed`), the added
/// effect named, another named (`other`).
fn drake_rates(
    rows: &[&CaseRow],
    labels: [&str; 3],
    blamed: &dyn Fn(&CaseRow) -> bool,
    other: &dyn Fn(&CaseRow) -> bool,
    aliases: &BTreeMap<String, String>,
    scores: &mut Vec<Score>,
) {
    let (nulls, with): (Vec<&CaseRow>, Vec<&CaseRow>) =
        rows.iter().partition(|r| r.truth_effects.is_empty());
    scores.push(score(
        labels[0],
        nulls.iter().filter(|r| blamed(r)).count(),
        nulls.len(),
        "0 %",
    ));
    scores.push(score(
        labels[1],
        with.iter()
            .filter(|r| names_every_truth_effect(r, aliases))
            .count(),
        with.len(),
        "high",
    ));
    scores.push(score(
        labels[2],
        with.iter().filter(|r| other(r)).count(),
        with.len(),
        "low",
    ));
}

/// A case's row with the names that stand after the logged cycles in place of the
/// answer's: effects, and parameters (`design:path`).
fn with_cycles(r: &CaseRow) -> CaseRow {
    let names = split(&r.cycles_named);
    let (params, effects): (Vec<String>, Vec<String>) =
        names.into_iter().partition(|n| n.contains(':'));
    CaseRow {
        named_effects: effects.join(";"),
        named_params: params.join(";"),
        ..r.clone()
    }
}

/// A knob named that is neither a truth's effect nor the parameter a truth's effect is an
/// alias of.
fn names_other_knob(r: &CaseRow, aliases: &BTreeMap<String, String>) -> bool {
    let truth = parse_pairs(&r.truth_effects);
    let truth_params: Vec<String> = truth
        .iter()
        .filter_map(|(e, _)| aliases.get(e).map(|p| format!(":{p}")))
        .collect();
    names_other_effect(r)
        || split(&r.named_params)
            .iter()
            .any(|n| !truth_params.iter().any(|p| n.ends_with(p.as_str())))
}

/// Interval coverage over every case whose true knob was named with an interval.
fn coverage_score(rows: &[CaseRow], aliases: &BTreeMap<String, String>) -> Score {
    let mut cov = (0usize, 0usize);
    for r in rows {
        // Drake's magnitudes are another engine's; an expected case's interval is centred on
        // the truth by construction.
        if r.kind == "drake" || r.kind == EXPECTED_PAIR {
            continue;
        }
        for (e, v) in parse_pairs(&r.truth_effects) {
            let alias = aliases.get(&e).cloned();
            let is = |k: &str| {
                k == e
                    || alias
                        .as_ref()
                        .is_some_and(|p| k.ends_with(&format!(":{p}")))
            };
            if let Some(c) = covered(r, &is, v) {
                cov.1 += 1;
                cov.0 += c as usize;
            }
        }
        let params = parse_pairs(&r.truth_params);
        if params.len() == 1 {
            let (p, v) = &params[0];
            let is = |k: &str| k.ends_with(&format!(":{p}"));
            if let Some(c) = covered(r, &is, *v) {
                cov.1 += 1;
                cov.0 += c as usize;
            }
        }
    }
    score(
        "95 % intervals holding the truth (every case that named its true knob)",
        cov.0,
        cov.1,
        "90–97 %",
    )
}

/// Confusions: single effects (main) by calibration and noise; parameter errors.
fn confusions(rows: &[CaseRow], noise_levels: &[f64]) -> Vec<Confusion> {
    let mut confusions = Vec::new();
    for calibrate in [true, false] {
        for &noise in noise_levels {
            let cases: Vec<&CaseRow> = rows
                .iter()
                .filter(|r| {
                    r.suite == "main"
                        && (r.kind == "effect" || r.kind == "null")
                        && r.noise == noise
                        && r.calibrate == calibrate
                })
                .collect();
            if cases.iter().all(|r| r.kind == "null") {
                continue;
            }
            let first = |r: &CaseRow| -> String {
                split(&r.named_effects)
                    .first()
                    .cloned()
                    .or_else(|| {
                        split(&r.named_params)
                            .first()
                            .map(|p| format!("param {}", p.split(':').nth(1).unwrap_or(p)))
                    })
                    .unwrap_or_else(|| "none".into())
            };
            let truth = |r: &CaseRow| -> String {
                parse_pairs(&r.truth_effects)
                    .first()
                    .map(|(e, _)| e.clone())
                    .unwrap_or_else(|| "null".into())
            };
            confusions.push(confusion(
                format!(
                    "single effects and nulls at {:.0} % noise{}",
                    noise * 100.0,
                    if calibrate { "" } else { ", calibration off" }
                ),
                &cases,
                truth,
                first,
            ));
        }
    }
    let cases: Vec<&CaseRow> = rows
        .iter()
        .filter(|r| r.suite == "main" && r.kind == "parameter")
        .collect();
    if !cases.is_empty() {
        let label = |r: &CaseRow| -> String {
            let mut v: Vec<String> = split(&r.named_params)
                .iter()
                .map(|p| p.split(':').nth(1).unwrap_or(p).to_string())
                .collect();
            v.extend(split(&r.named_effects));
            if v.is_empty() {
                "none".into()
            } else {
                v.join(" + ")
            }
        };
        confusions.push(confusion(
            "nominal-parameter errors (main suite): what was named".into(),
            &cases,
            |r| r.truth_params.clone(),
            label,
        ));
    }
    confusions
}

#[cfg(test)]
mod tests {
    use super::{drake_effects, interval_holds};

    /// A Drake file's stem names what Drake added; any other name is refused, not taken for
    /// a file with no effect.
    #[test]
    fn a_drake_file_name_gives_the_effects_drake_added() {
        assert_eq!(drake_effects("trials-none"), Some(vec![]));
        assert_eq!(
            drake_effects("trials-soft_ground-6e6"),
            Some(vec![("soft_ground".into(), 6e6)])
        );
        assert_eq!(
            drake_effects("trials-hip_viscous_damping-0.01+hip_coulomb_friction-0.03"),
            Some(vec![
                ("hip_viscous_damping".into(), 0.01),
                ("hip_coulomb_friction".into(), 0.03)
            ])
        );
        assert_eq!(
            drake_effects("trials-hip_backlash-1e-3"),
            Some(vec![("hip_backlash".into(), 1e-3)])
        );
        for bad in [
            "trials-nothing",
            "trials-x-",
            "trials--1",
            "trials-a-1+",
            "trials-a-nan",
            "none",
        ] {
            assert_eq!(drake_effects(bad), None, "{bad}");
        }
    }

    /// A magnitude's interval holds a truth of either sign; a signed one only its own.
    #[test]
    fn a_magnitude_interval_holds_a_truth_of_either_sign() {
        assert_eq!(interval_holds("1.4..1.6", 1.5), Some(true));
        assert_eq!(interval_holds("1.4..1.6", -1.5), Some(false));
        assert_eq!(interval_holds("±1.4..1.6", -1.5), Some(true));
        assert_eq!(interval_holds("±1.4..1.6", 1.7), Some(false));
        assert_eq!(interval_holds("-1.6..-1.4", -1.5), Some(true));
        assert_eq!(interval_holds("x..1", 0.5), None);
    }
}
