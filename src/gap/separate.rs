//! Telling look-alike explanations apart: each candidate knob (an effect's magnitude or a
//! declared uncertain parameter, the rest at the file's values) is fitted to the trials by
//! real walks, once on the summary metrics alone and once on the summaries plus the logged
//! cycles ([`super::waveform`]), and the candidates are ranked by χ² in each mode.
//!
//! The rules that keep a name honest, in each mode:
//! * a candidate is named only if it fits within noise (χ² p ≥ α over all observations):
//!   the best of several wrong candidates is still wrong, and ranking them would name it;
//! * and only if every rival is worse by more than the likelihood-ratio test allows at
//!   α/(K−1), with the Δχ² divided by the over-dispersion left at the best fit;
//! * otherwise the answer is "cannot tell" (with the group that stays within reach), or
//!   "none fits" (with where the rest lies), or "no gap" when the nominal fits already.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;
use serde::Serialize;

use super::diagnose::{AnswerKind, designs_of, measured};
use super::error::GapError;
use super::fit::dispersion;
use super::knob::{KnobKind, Knobs};
use super::library::EffectLibrary;
use super::problem::{FELL_Z2, Observation};
use super::simulate::{Condition, SimMetrics, resolve};
use super::trials::TrialSet;
use super::waveform::{self, CycleSignature, Signal};
use crate::progress::Observer;
use crate::regression::dist::chi2_upper_p;

#[derive(Clone, Debug)]
pub struct SeparateOptions {
    /// Knob labels: effect names, or `design:path` of declared uncertain parameters.
    pub candidates: Vec<String>,
    /// Walks per candidate over its range before the golden-section refinement.
    pub grid_points: usize,
    /// Golden-section steps on walks around the best grid node.
    pub refine_steps: usize,
    /// Model-error floor of a cycle coefficient, as a fraction of the measured signal's RMS.
    pub relative_floor: f64,
    /// Drive cycles left out at the start of every log and simulated walk.
    pub settle_cycles: usize,
    pub alpha: f64,
    /// Relative sd assumed for a measurement that states none.
    pub default_relative_sd: f64,
    /// Set by [`separate_through`]: the evidence is carried through a reference, so with
    /// cycles the summaries decide which candidates are plausible and the cycles rank them
    /// (`Fitted::ranking`).
    pub through_reference: bool,
}

impl Default for SeparateOptions {
    fn default() -> Self {
        SeparateOptions {
            candidates: Vec::new(),
            grid_points: 9,
            refine_steps: 10,
            relative_floor: 0.05,
            settle_cycles: 6,
            alpha: 0.01,
            default_relative_sd: 0.10,
            through_reference: false,
        }
    }
}

/// Which evidence a ranking uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Evidence {
    Summaries,
    SummariesAndWaveforms,
}

impl Evidence {
    pub fn label(self) -> &'static str {
        match self {
            Evidence::Summaries => "summaries only",
            Evidence::SummariesAndWaveforms => "summaries + waveforms",
        }
    }
}

/// One candidate's best fit under one kind of evidence.
#[derive(Clone, Debug, Serialize)]
pub struct CandidateFit {
    pub knob: String,
    pub kind: KnobKind,
    /// Fitted value: SI at the first design's 1× for effects, the field's unit for
    /// parameters.
    pub value: f64,
    pub unit: String,
    /// At an end of the candidate's range.
    pub at_range_end: bool,
    pub chi2_summaries: f64,
    pub chi2_waveforms: f64,
    /// The ranked χ² (summaries, or summaries + waveforms).
    pub chi2: f64,
    /// (χ² − best χ²) / over-dispersion: the likelihood-ratio statistic against the best.
    pub delta: f64,
    /// The rival is worse than the best beyond the test (always false for the best).
    pub separated: bool,
}

/// The answer of one ranking.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Verdict {
    /// No candidate beats the nominal model by the likelihood-ratio test: nothing to
    /// separate.
    NoGap,
    /// One candidate fits within noise and every rival is worse beyond the test.
    Named { knob: String },
    /// Two candidates at once ([`PairFit`]): the pair fits within noise, beats each of its
    /// knobs alone beyond the test, and no other pair does.
    NamedTogether { knobs: Vec<String> },
    /// The candidates within reach of the best: the trials cannot tell them apart.
    CannotTell { group: Vec<String> },
    /// No candidate fits within noise; where the best one's rest lies.
    NoneFits { rest_in: String },
    /// Through a reference: the nominal model walks none of the reference trials' gaits, so
    /// no change can be carried onto it ([`super::reference::like_gait`]).
    NotComparable { why: String },
}

#[derive(Clone, Debug, Serialize)]
pub struct Ranking {
    pub evidence: Evidence,
    /// Best first.
    pub fits: Vec<CandidateFit>,
    pub nominal_chi2: f64,
    /// Observations: summary metrics plus (with waveforms) cycle coefficients.
    pub observations: usize,
    /// χ²/(n − 1) at the best fit, at least 1 (the worst block of evidence).
    pub overdispersion: f64,
    /// χ² p-value of the best fit, the worst block's, Bonferroni-adjusted over the blocks
    /// (within noise when ≥ α).
    pub best_p_value: f64,
    pub verdict: Verdict,
    /// Through a reference, with cycles: the one metric without which the best candidate's
    /// carried summaries fit within noise, where they do not with it (its plausibility rests
    /// on leaving that metric out). What lies there is either another cause outside the
    /// candidates or the engines' versions of the effect answering that metric apart; the
    /// trials do not say which, so the answer says so.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub summaries_left_out: Option<MetricLeftOut>,
    /// The best candidate with each plausible rival fitted together (summaries + waveforms
    /// only): [`FitProblem::check_pairs`].
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pairs: Vec<PairFit>,
}

/// A metric the best candidate's summaries fit within noise only without
/// ([`Ranking::summaries_left_out`]).
#[derive(Clone, Debug, Serialize)]
pub struct MetricLeftOut {
    pub metric: String,
    /// χ² of that metric's values at the best fit, and how many values it has.
    pub chi2: f64,
    pub values: usize,
}

/// Two candidates fitted together on walks (the profile of the second, the first refitted
/// at each of its nodes).
#[derive(Clone, Debug, Serialize)]
pub struct PairFit {
    pub knobs: [String; 2],
    /// Fitted values (SI at the first design's 1× for effects; the field's unit otherwise).
    pub values: [f64; 2],
    pub units: [String; 2],
    pub chi2_summaries: f64,
    pub chi2_waveforms: f64,
    /// (χ² of each knob alone − the pair's) / over-dispersion, in the evidence the pair is
    /// tested on: the likelihood-ratio statistic (1 dof) of the other knob beside it.
    pub delta: [f64; 2],
    /// The values of the second knob beside the first that the profile does not reject at
    /// 95 %, at the grid's resolution (low, high; SI): the grid nodes just outside the kept
    /// ones, or a range end. "This knob, with that much of the other at most".
    pub second_range: [f64; 2],
    /// Named together: every rule below passed, and every other pair that passed them fits
    /// worse beyond the test.
    pub passes: bool,
    /// Why not, when it does not pass.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub why_not: Option<String>,
    /// Through a reference: the one metric without which the pair's carried summaries fit
    /// within noise, where they do not with it (as [`Ranking::summaries_left_out`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub summaries_left_out: Option<MetricLeftOut>,
}

/// Cycles of one trial for the figure: measured, nominal and best candidate (waveform mode).
#[derive(Clone, Debug, Serialize)]
pub struct TrialCycles {
    pub trial: String,
    pub measured: CycleSignature,
    pub nominal: Option<CycleSignature>,
    pub best: Option<CycleSignature>,
    pub best_knob: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct Separation {
    pub trials: usize,
    pub trials_with_logs: usize,
    pub relative_floor: f64,
    pub alpha: f64,
    pub rankings: Vec<Ranking>,
    pub cycles: Vec<TrialCycles>,
    pub notes: Vec<String>,
    pub walks: usize,
}

/// Walks of candidate settings shared between separations of the same conditions (the
/// benchmark's seeds): (knob label, coordinate bits) → the conditions' walks; the nominal is
/// ("", 0).
#[derive(Default)]
pub struct CycleCache {
    map: Mutex<HashMap<CacheKey, Arc<Vec<SimCycle>>>>,
}

/// (knob label, coordinate bits).
type CacheKey = (String, u64);

impl CycleCache {
    fn get(&self, key: &CacheKey) -> Result<Option<Arc<Vec<SimCycle>>>, GapError> {
        Ok(self.map.lock().map_err(poisoned)?.get(key).cloned())
    }
    fn put(&self, key: CacheKey, v: Arc<Vec<SimCycle>>) -> Result<(), GapError> {
        self.map.lock().map_err(poisoned)?.insert(key, v);
        Ok(())
    }
}

/// The measured cycles of the trials that name a log (`trajectory` column), by trial.
pub fn measured_signatures(
    set: &TrialSet,
    conditions: &[Condition],
    settle_cycles: usize,
) -> Result<Vec<Option<CycleSignature>>, GapError> {
    set.trials
        .iter()
        .zip(conditions)
        .map(|(t, c)| {
            let Some(rel) = &t.trajectory else {
                return Ok(None);
            };
            let at = |message: String| GapError::Trials {
                path: set.origin.clone(),
                line: t.line,
                column: 0,
                message,
            };
            let path = set.base_dir.join(rel);
            let log = waveform::read_log_csv(&path)?;
            let f = c.drive_frequency_hz()?;
            waveform::signature(&log, f, settle_cycles)
                .map(Some)
                .map_err(|e| at(format!("trajectory {}: {e}", path.display())))
        })
        .collect()
}

/// A trial set's resolved conditions and the cycles measured from the logs its rows name.
type Resolved = (Vec<Condition>, Vec<Option<CycleSignature>>);

fn resolve_with_cycles(set: &TrialSet, settle_cycles: usize) -> Result<Resolved, GapError> {
    let conditions = resolve(set)?;
    let sigs = measured_signatures(set, &conditions, settle_cycles)?;
    Ok((conditions, sigs))
}

/// Separates the candidates on the trials of `set`, reading the logs its rows name.
pub fn separate(
    set: &TrialSet,
    lib: &EffectLibrary,
    opts: &SeparateOptions,
    progress: &dyn Observer,
) -> Result<Separation, GapError> {
    check(opts)?;
    let (conditions, sigs) = resolve_with_cycles(set, opts.settle_cycles)?;
    separate_with(
        set,
        &conditions,
        &sigs,
        lib,
        opts,
        &CycleCache::default(),
        progress,
    )
}

/// Trials of the same robot without the change asked about, and their measured cycles: the
/// reference a separation is made through ([`separate_through`]).
pub struct Reference<'a> {
    pub set: &'a TrialSet,
    pub conditions: &'a [Condition],
    pub sigs: &'a [Option<CycleSignature>],
}

/// What changed between a reference and a trial set, carried onto the nominal model
/// ([`carry_through`]): made once, whatever the candidates separated on it.
struct Carrying {
    /// The carried summaries (a trial where the model does not walk the reference's gait
    /// has none).
    set: TrialSet,
    /// The carried cycles.
    sigs: Vec<Option<CycleSignature>>,
    /// Why nothing could be carried: the model walks none of the reference's gaits.
    not_comparable: Option<String>,
    notes: Vec<String>,
    trials_with_logs: usize,
    /// The nominal walks made to carry (not found in the cache).
    walks: usize,
}

/// Carries `set` and its cycles (`sigs`) onto the nominal model through `reference`: the
/// summaries as `gap diagnose --reference` carries them ([`super::reference::carry`]), each
/// logged cycle likewise ([`super::reference::carry_cycles`]), so that a discrepancy the
/// model has at every condition (another engine's contact, an unmodelled structure) cancels
/// in both kinds of evidence. Only where the model walks the reference's gait
/// ([`super::reference::like_gait`]) is a trial carried; a trial's cycles only where the
/// trial, its reference trial and the nominal walk all have them.
#[allow(clippy::too_many_arguments)]
fn carry_through(
    set: &TrialSet,
    conditions: &[Condition],
    sigs: &[Option<CycleSignature>],
    reference: &Reference<'_>,
    lib: &EffectLibrary,
    opts: &SeparateOptions,
    cache: &CycleCache,
    progress: &dyn Observer,
) -> Result<Carrying, GapError> {
    if sigs.len() != set.trials.len() || reference.sigs.len() != reference.set.trials.len() {
        return Err(GapError::Invalid(format!(
            "{}: {} trials but {} cycle signatures; reference {}: {} trials but {}",
            set.origin,
            set.trials.len(),
            sigs.len(),
            reference.set.origin,
            reference.set.trials.len(),
            reference.sigs.len()
        )));
    }
    let walker = Walker {
        conditions,
        lib,
        settle_cycles: opts.settle_cycles,
        cache,
        progress,
        walks: std::sync::atomic::AtomicUsize::new(0),
    };
    let nominal = walker.run((String::new(), 0), &super::knob::ModelSetting::nominal())?;
    let filled = super::diagnose::fill_from_trajectories(set, conditions, lib)?;
    let filled_reference =
        super::diagnose::fill_from_trajectories(reference.set, reference.conditions, lib)?;
    let nominal_metrics: Vec<SimMetrics> = nominal.iter().map(|s| s.metrics).collect();
    let carried = super::reference::carry(
        &filled,
        conditions,
        &filled_reference,
        reference.conditions,
        &nominal_metrics,
        opts.default_relative_sd,
    )?;
    // Each trial's reference trial, once (`carry` has checked that every trial has one).
    let reference_index: Vec<Option<usize>> = conditions
        .iter()
        .map(|c| {
            reference
                .conditions
                .iter()
                .position(|rc| super::reference::same_condition(c, rc))
        })
        .collect();
    // Only where the model walks the reference's gait is the change carried (both kinds of
    // evidence); elsewhere the trial is left out, with why.
    let mut unlike: Vec<String> = Vec::new();
    let like: Vec<bool> = reference_index
        .iter()
        .zip(nominal.iter())
        .zip(&set.trials)
        .map(|((j, nom), t)| {
            let verdict = j.map(|j| {
                super::reference::like_gait(
                    &filled_reference.trials[j],
                    &nom.metrics,
                    opts.default_relative_sd,
                )
            });
            if let Some(Err(why)) = verdict {
                unlike.push(format!("{}: {why}", t.name()));
                return false;
            }
            true
        })
        .collect();
    let mut carried_set = carried.set;
    for (t, &ok) in carried_set.trials.iter_mut().zip(&like) {
        if !ok {
            t.measured = [None; 8];
        }
    }
    let mut notes = carried.notes;
    let trials_with_logs = sigs.iter().filter(|s| s.is_some()).count();
    if !like.iter().any(|&l| l) {
        let why = format!(
            "the nominal model walks none of the reference trials' gaits ({}): a change \
             carried onto it would not be its mark on the model",
            unlike.join("; ")
        );
        notes.push(why.clone());
        return Ok(Carrying {
            set: carried_set,
            sigs: Vec::new(),
            not_comparable: Some(why),
            notes,
            trials_with_logs,
            walks: walker.walks.into_inner(),
        });
    }
    let mut uncarried = 0usize;
    let carried_sigs: Vec<Option<CycleSignature>> = sigs
        .iter()
        .zip(&reference_index)
        .zip(nominal.iter())
        .zip(&like)
        .map(|(((t, j), nom), &ok)| {
            let t = t.as_ref().filter(|_| ok)?;
            let r = j.and_then(|j| reference.sigs[j].as_ref());
            let out = match (r, &nom.cycles) {
                (Some(r), Some(n)) => super::reference::carry_cycles(t, r, n),
                _ => None,
            };
            if out.is_none() {
                uncarried += 1;
            }
            out
        })
        .collect();
    if !unlike.is_empty() {
        notes.push(format!(
            "{} trial(s) left out: the nominal model does not walk the reference's gait there \
             (within {:.0} % on speed, roll and pitch, {:.0} % on step frequency), so a change \
             carried there is not its mark on the model: {}",
            unlike.len(),
            100.0 * super::reference::LIKE_GAIT_TOLERANCE,
            100.0 * super::reference::LIKE_STEP_TOLERANCE,
            unlike.join("; ")
        ));
    }
    if trials_with_logs > 0 {
        notes.push(format!(
            "relative to the reference, each logged cycle is the nominal walk's + (trial − \
             reference), coefficient by coefficient, its sd the three means' and the change × \
             the model's relative miss of the reference's amplitude combined{}",
            if uncarried > 0 {
                format!(
                    "; {uncarried} trial log(s) not carried: the reference trial of the same \
                     condition has no log, or the nominal walk fell"
                )
            } else {
                String::new()
            }
        ));
    }
    Ok(Carrying {
        set: carried_set,
        sigs: carried_sigs,
        not_comparable: None,
        notes,
        trials_with_logs,
        walks: walker.walks.into_inner(),
    })
}

/// [`separate_with`] on carried evidence: through a reference, with cycles, the summaries
/// say which candidates are plausible and the cycles rank them (`Fitted::ranking`).
fn separate_carried(
    carrying: &Carrying,
    conditions: &[Condition],
    lib: &EffectLibrary,
    opts: &SeparateOptions,
    cache: &CycleCache,
    progress: &dyn Observer,
) -> Result<Separation, GapError> {
    check(opts)?;
    if let Some(why) = &carrying.not_comparable {
        return Ok(Separation {
            trials: carrying.set.trials.len(),
            trials_with_logs: carrying.trials_with_logs,
            relative_floor: opts.relative_floor,
            alpha: opts.alpha,
            rankings: vec![Ranking {
                evidence: Evidence::Summaries,
                fits: Vec::new(),
                nominal_chi2: f64::NAN,
                observations: 0,
                overdispersion: 1.0,
                best_p_value: f64::NAN,
                verdict: Verdict::NotComparable { why: why.clone() },
                summaries_left_out: None,
                pairs: Vec::new(),
            }],
            cycles: Vec::new(),
            notes: carrying.notes.clone(),
            walks: 0,
        });
    }
    let through = SeparateOptions {
        through_reference: true,
        ..opts.clone()
    };
    let mut sep = separate_with(
        &carrying.set,
        conditions,
        &carrying.sigs,
        lib,
        &through,
        cache,
        progress,
    )?;
    let mut notes = carrying.notes.clone();
    notes.append(&mut sep.notes);
    sep.notes = notes;
    Ok(sep)
}

/// [`separate_with`] on what changed between `reference` and `set` ([`carry_through`]).
#[allow(clippy::too_many_arguments)]
pub fn separate_through(
    set: &TrialSet,
    conditions: &[Condition],
    sigs: &[Option<CycleSignature>],
    reference: &Reference<'_>,
    lib: &EffectLibrary,
    opts: &SeparateOptions,
    cache: &CycleCache,
    progress: &dyn Observer,
) -> Result<Separation, GapError> {
    check(opts)?;
    let carrying = carry_through(set, conditions, sigs, reference, lib, opts, cache, progress)?;
    let mut sep = separate_carried(&carrying, conditions, lib, opts, cache, progress)?;
    sep.walks += carrying.walks;
    Ok(sep)
}

/// [`separate`] through `reference` ([`separate_through`]), reading the logs both sets'
/// rows name.
pub fn separate_relative(
    set: &TrialSet,
    reference: &TrialSet,
    lib: &EffectLibrary,
    opts: &SeparateOptions,
    progress: &dyn Observer,
) -> Result<Separation, GapError> {
    check(opts)?;
    let (conditions, sigs) = resolve_with_cycles(set, opts.settle_cycles)?;
    let (reference_conditions, reference_sigs) =
        resolve_with_cycles(reference, opts.settle_cycles)?;
    separate_through(
        set,
        &conditions,
        &sigs,
        &Reference {
            set: reference,
            conditions: &reference_conditions,
            sigs: &reference_sigs,
        },
        lib,
        opts,
        &CycleCache::default(),
        progress,
    )
}

/// A simulated condition: its metrics and its cycles (None when it fell or is too short).
#[derive(Clone, Debug)]
pub struct SimCycle {
    pub metrics: SimMetrics,
    pub cycles: Option<CycleSignature>,
}

/// Simulates a condition under a setting, with the trajectory kept for the cycles.
pub fn simulate_cycles(
    c: &Condition,
    lib: &EffectLibrary,
    setting: &super::knob::ModelSetting,
    settle_cycles: usize,
) -> Result<SimCycle, GapError> {
    let (metrics, trajectory) = c.walk(lib, setting, true)?;
    let f = c
        .design_with(lib, setting)?
        .controller()
        .frequency_hz()
        .unwrap_or(1.0);
    let fell = metrics.fell;
    let cycles = if fell {
        None
    } else {
        waveform::signature(&waveform::log_of(&trajectory), f, settle_cycles).ok()
    };
    Ok(SimCycle { metrics, cycles })
}

/// χ² of simulated conditions: (summaries, waveforms).
fn chi2_pair(
    obs: &[Observation],
    sigs: &[Option<CycleSignature>],
    sims: &[SimCycle],
    floor: f64,
) -> (f64, f64) {
    let s: f64 = obs
        .iter()
        .map(|o| o.z2(sims[o.trial].metrics.get(o.metric)))
        .sum();
    let w: f64 = sigs
        .iter()
        .zip(sims)
        .filter_map(|(m, s)| m.as_ref().map(|m| (m, s)))
        .map(|(m, s)| match &s.cycles {
            Some(c) => waveform::chi2(m, c, floor).chi2,
            None => FELL_Z2 * coefficient_count(m) as f64,
        })
        .sum();
    (s, w)
}

fn coefficient_count(m: &CycleSignature) -> usize {
    m.signals
        .iter()
        .map(|s| s.coefficients.iter().filter(|c| c.is_finite()).count())
        .sum()
}

/// [`separate`] on resolved conditions and measured cycles (the benchmark's entry: its logs
/// are in memory).
pub fn separate_with(
    set: &TrialSet,
    conditions: &[Condition],
    sigs: &[Option<CycleSignature>],
    lib: &EffectLibrary,
    opts: &SeparateOptions,
    cache: &CycleCache,
    progress: &dyn Observer,
) -> Result<Separation, GapError> {
    check(opts)?;
    let (_, obs, mut notes) = measured(set, conditions, lib, opts.default_relative_sd)?;
    let designs = designs_of(conditions);
    let effects: Vec<_> = lib.effects.iter().collect();
    let knobs = Knobs::build(&designs, &effects, true).map_err(|e| GapError::Sim {
        origin: "designs".into(),
        source: e,
    })?;
    let idx = candidate_knobs(&knobs, opts)?;
    let with_logs = sigs.iter().filter(|s| s.is_some()).count();
    if with_logs == 0 {
        notes.push(
            "no trial names a log (`trajectory` column): only the summaries can separate the \
             candidates"
                .into(),
        );
    }
    let walker = Walker {
        conditions,
        lib,
        settle_cycles: opts.settle_cycles,
        cache,
        progress,
        walks: std::sync::atomic::AtomicUsize::new(0),
    };
    let nominal = walker.run((String::new(), 0), &super::knob::ModelSetting::nominal())?;
    let (nom_s, nom_w) = chi2_pair(&obs, sigs, &nominal, opts.relative_floor);
    let n_wave: usize = sigs.iter().flatten().map(coefficient_count).sum();

    let problem = FitProblem {
        walker: &walker,
        knobs: &knobs,
        obs: &obs,
        sigs,
        opts,
    };
    let mut fits: Vec<[Best; 2]> = Vec::new();
    for &k in &idx {
        fits.push(problem.fit_candidate(k)?);
    }
    let fitted = Fitted {
        obs: &obs,
        sigs,
        knobs: &knobs,
        idx: &idx,
        fits: &fits,
        nominal: (nom_s, nom_w),
        n_wave,
        opts,
    };
    let mut rankings = Vec::new();
    for (mi, mode) in [Evidence::Summaries, Evidence::SummariesAndWaveforms]
        .into_iter()
        .enumerate()
    {
        if mode == Evidence::SummariesAndWaveforms && with_logs == 0 {
            continue;
        }
        rankings.push(fitted.ranking(mi, mode));
    }
    // A mixture of two candidates: only the cycles can tell one (a single knob fits the
    // summaries of two hip losses within noise), so pairs are weighed with them.
    if let Some(r) = rankings
        .iter_mut()
        .find(|r| r.evidence == Evidence::SummariesAndWaveforms)
    {
        problem.check_pairs(r)?;
    }
    let cycles = fitted.cycles(set, &rankings, &nominal);
    Ok(Separation {
        trials: set.trials.len(),
        trials_with_logs: with_logs,
        relative_floor: opts.relative_floor,
        alpha: opts.alpha,
        rankings,
        cycles,
        notes,
        walks: walker.walks.into_inner(),
    })
}

/// The knob indices of the candidates, in the order given, each once.
fn candidate_knobs(knobs: &Knobs, opts: &SeparateOptions) -> Result<Vec<usize>, GapError> {
    let mut idx = Vec::new();
    for c in &opts.candidates {
        let i = knobs.index_of(c).ok_or_else(|| {
            GapError::Invalid(format!(
                "candidate {c:?} is neither an effect of the library nor a declared uncertain \
                 parameter of the trials' designs; the knobs are: {}",
                knobs
                    .list
                    .iter()
                    .map(|k| k.label())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        if !idx.contains(&i) {
            idx.push(i);
        }
    }
    Ok(idx)
}

/// Walks every condition under a setting, through the cache, counting the walks.
struct Walker<'a> {
    conditions: &'a [Condition],
    lib: &'a EffectLibrary,
    settle_cycles: usize,
    cache: &'a CycleCache,
    progress: &'a dyn Observer,
    walks: std::sync::atomic::AtomicUsize,
}

impl Walker<'_> {
    fn run(
        &self,
        key: CacheKey,
        setting: &super::knob::ModelSetting,
    ) -> Result<Arc<Vec<SimCycle>>, GapError> {
        if let Some(v) = self.cache.get(&key)? {
            return Ok(v);
        }
        let r: Vec<SimCycle> = self
            .conditions
            .par_iter()
            .map(|c| simulate_cycles(c, self.lib, setting, self.settle_cycles))
            .collect::<Result<Vec<_>, _>>()?;
        self.walks
            .fetch_add(self.conditions.len(), std::sync::atomic::Ordering::Relaxed);
        self.progress.tick();
        let r = Arc::new(r);
        self.cache.put(key, r.clone())?;
        Ok(r)
    }
}

/// A candidate's best fit in one evidence mode.
struct Best {
    x: f64,
    sims: Arc<Vec<SimCycle>>,
    s: f64,
    w: f64,
}

/// What every fit on walks of a separation shares (the problem; each fit says which knobs
/// it frees and by which cost): the walker, the knobs, the observations and measured cycles
/// the fits are judged on, and the options.
struct FitProblem<'a> {
    walker: &'a Walker<'a>,
    knobs: &'a Knobs,
    obs: &'a [Observation],
    sigs: &'a [Option<CycleSignature>],
    opts: &'a SeparateOptions,
}

impl FitProblem<'_> {
    /// Each candidate: grid, then golden section per evidence kind, all on walks. Returns the
    /// best fit on summaries and on summaries and waveforms.
    fn fit_candidate(&self, k: usize) -> Result<[Best; 2], GapError> {
        let by_summary = self.fit_one(k, &|s, _| s)?;
        let by_both = self.fit_one(k, &|s, w| s + w)?;
        Ok([by_summary, by_both])
    }

    /// One knob alone (the rest at the file's values) fitted by `cost(summaries χ², cycles χ²)`:
    /// its grid, then a golden section between the best node's neighbours, on walks (the grid's
    /// walks are shared through the cache by every cost).
    fn fit_one(&self, k: usize, cost: &dyn Fn(f64, f64) -> f64) -> Result<Best, GapError> {
        let (walker, knobs, obs, sigs, opts) =
            (self.walker, self.knobs, self.obs, self.sigs, self.opts);
        let knob = &knobs.list[k];
        let label = knob.label();
        let eval = |x: f64| -> Result<Best, GapError> {
            let mut point = knobs.nominal_point();
            point[k] = Some(x);
            let sims = walker.run(
                (label.clone(), x.to_bits()),
                &knobs.setting(walker.lib, &point),
            )?;
            let (s, w) = chi2_pair(obs, sigs, &sims, opts.relative_floor);
            Ok(Best { x, sims, s, w })
        };
        grid_then_golden(
            &knob.nodes(opts.grid_points),
            opts.refine_steps.saturating_sub(1),
            |x| eval(x).map(|q| (cost(q.s, q.w), q)),
        )
    }
}

/// A 1-D fit on walks: the grid `nodes`, then a golden section of `reductions` steps between
/// the best node's neighbours (reductions + 2 evaluations), kept only where it beats the node.
fn grid_then_golden<T>(
    nodes: &[f64],
    reductions: usize,
    mut eval: impl FnMut(f64) -> Result<(f64, T), GapError>,
) -> Result<T, GapError> {
    let mut best: Option<(usize, f64, T)> = None;
    for (j, &x) in nodes.iter().enumerate() {
        let (c, t) = eval(x)?;
        if best.as_ref().is_none_or(|(_, bc, _)| c < *bc) {
            best = Some((j, c, t));
        }
    }
    let (j, c, t) = best.ok_or_else(|| GapError::Invalid("a knob with no grid".into()))?;
    let (a, b) = (
        nodes[j.saturating_sub(1)],
        nodes[(j + 1).min(nodes.len() - 1)],
    );
    let (_, refined_c, refined) = super::solver::golden_section(a, b, reductions, eval)?;
    Ok(if refined_c < c { refined } else { t })
}

/// The candidates' fits, ready to be ranked.
struct Fitted<'a> {
    obs: &'a [Observation],
    sigs: &'a [Option<CycleSignature>],
    knobs: &'a Knobs,
    idx: &'a [usize],
    /// Per candidate (as `idx`): the best fit by summaries, and by summaries and waveforms.
    fits: &'a [[Best; 2]],
    /// The nominal's χ² on summaries and on waveforms.
    nominal: (f64, f64),
    n_wave: usize,
    opts: &'a SeparateOptions,
}

impl Fitted<'_> {
    /// The position in `idx` (and `fits`) of the knob with this label (0 if none).
    fn position(&self, label: &str) -> usize {
        self.idx
            .iter()
            .position(|&k| self.knobs.list[k].label() == label)
            .unwrap_or(0)
    }

    /// The ranking in one evidence mode (`mi` 0: summaries; 1: summaries and waveforms).
    fn ranking(&self, mi: usize, mode: Evidence) -> Ranking {
        let (obs, opts) = (self.obs, self.opts);
        let (nom_s, nom_w) = self.nominal;
        let n = obs.len() + if mi == 1 { self.n_wave } else { 0 };
        let cost = |s: f64, w: f64| if mi == 1 { s + w } else { s };
        let dof = |n: usize| (n.max(2) - 1) as f64;
        let nb = if mi == 1 { 2.0 } else { 1.0 };
        // Through a reference, with cycles: which look-alike carried summaries favour is
        // the engines' business (the carried numbers hold an error no sd counts; measured on
        // Drake-Lagged's hip Coulomb friction 0.05 N·m, noise-free: the summaries favour
        // viscous damping by Δχ² 18.6), while a hip loss changes the robot's cycle as it
        // changes the model's (r ≥ 0.994). So the summaries say which candidates are
        // plausible (within noise there), the cycles rank those, and a plausible rival is
        // told apart only by the cycles.
        let cycles_decide = mi == 1 && opts.through_reference && self.n_wave > 0;
        // The summaries' p-value (Bonferroni over the blocks); through a reference the larger
        // of it and the p-value without the one metric that misses most: a candidate only one
        // metric rejects is plausible, since that metric's misfit may be the engines' versions
        // of the effect answering it apart (`reference::within_noise_but_one_metric`,
        // measured on Drake's hip Coulomb friction 0.08 N·m: the yaw swing).
        let summaries = |b: &Best| summaries_fit(obs, &b.sims, b.s, 1, nb, opts);
        // Each candidate with its summaries' p-value, computed once.
        let mut ranked: Vec<(CandidateFit, SummariesFit)> = self
            .idx
            .iter()
            .zip(self.fits)
            .map(|(&k, f)| {
                let knob = &self.knobs.list[k];
                let b = &f[mi];
                let span = knob.hi - knob.lo;
                let fit = CandidateFit {
                    knob: knob.label(),
                    kind: knob.kind,
                    value: knob.si(b.x),
                    unit: knob.unit.clone(),
                    at_range_end: (b.x - knob.lo).abs() < 1e-3 * span
                        || (knob.hi - b.x).abs() < 1e-3 * span,
                    chi2_summaries: b.s,
                    chi2_waveforms: b.w,
                    chi2: cost(b.s, b.w),
                    delta: 0.0,
                    separated: false,
                };
                (fit, summaries(b))
            })
            .collect();
        let is_plausible = |p: f64| p >= opts.alpha;
        if cycles_decide {
            ranked.sort_by(|(a, sa), (b, sb)| {
                is_plausible(sb.p)
                    .cmp(&is_plausible(sa.p))
                    .then(if is_plausible(sa.p) {
                        a.chi2_waveforms.total_cmp(&b.chi2_waveforms)
                    } else {
                        a.chi2.total_cmp(&b.chi2)
                    })
            });
        } else {
            ranked.sort_by(|(a, _), (b, _)| a.chi2.total_cmp(&b.chi2));
        }
        let (mut list, mut summary_fits): (Vec<CandidateFit>, Vec<SummariesFit>) =
            ranked.into_iter().unzip();
        let plausible = |i: usize| is_plausible(summary_fits[i].p);
        let best = list[0].chi2;
        // Each block of evidence (summaries; cycles) is tested on its own: pooled, a few
        // hundred well-fitting cycle coefficients would dilute a summary gap into "no gap"
        // (and the other way round). Bonferroni over the blocks; the over-dispersion is the
        // worst block's.
        let blocks: Vec<(usize, f64, f64)> = if mi == 1 {
            vec![
                (obs.len(), list[0].chi2_summaries, nom_s),
                (self.n_wave, list[0].chi2_waveforms, nom_w),
            ]
        } else {
            vec![(obs.len(), list[0].chi2_summaries, nom_s)]
        };
        let phi = blocks
            .iter()
            .map(|(n, c, _)| c / dof(*n))
            .fold(1.0f64, f64::max);
        let per_test = opts.alpha / (list.len() - 1) as f64;
        let (best_plausible, best_w) = (plausible(0), list[0].chi2_waveforms);
        for (i, f) in list.iter_mut().enumerate().skip(1) {
            if cycles_decide && best_plausible {
                if plausible(i) {
                    f.delta = (f.chi2_waveforms - best_w) / phi;
                    f.separated = chi2_upper_p(f.delta, 1.0).unwrap_or(1.0) < per_test;
                } else {
                    // Implausible on the summaries, and worse on the whole by the test: a
                    // rival the summaries reject by a hair while its cycles fit better is
                    // not told apart (measured: Drake's hip Coulomb friction 0.05 N·m, one
                    // draw of five, χ² 106 against damping's 92 on the 63 carried
                    // summaries, 43 against 78 on the cycles).
                    f.delta = (f.chi2 - best) / phi;
                    f.separated = chi2_upper_p(f.delta.max(0.0), 1.0).unwrap_or(1.0) < per_test;
                }
                continue;
            }
            f.delta = (f.chi2 - best) / phi;
            // Through a reference, on the summaries alone, a rival that fits within noise
            // (or would but for one metric) is not told apart, as in `gap diagnose
            // --reference` (`reference::rivals_within_noise`).
            f.separated = chi2_upper_p(f.delta, 1.0).unwrap_or(1.0) < per_test
                && !(mi == 0 && opts.through_reference && best_plausible && plausible(i));
        }
        let nominal_chi2 = cost(nom_s, nom_w);
        let block_p = |c: f64, n: usize| (nb * chi2_upper_p(c, dof(n)).unwrap_or(0.0)).min(1.0);
        // When the cycles decide, the best fits the summaries when it is plausible there.
        let best_p = blocks
            .iter()
            .enumerate()
            .map(|(i, (n, c, _))| {
                if i == 0 && cycles_decide {
                    summary_fits[0].p
                } else {
                    block_p(*c, *n)
                }
            })
            .fold(1.0f64, f64::min);
        // A gap a candidate explains: the best candidate beats the nominal by the
        // likelihood-ratio test (one knob: 1 dof) — an omnibus χ² over all observations
        // misses a gap a single knob explains. But a nominal that fails the goodness-of-fit
        // test has a gap whether or not a candidate beats it: then the answer is about the
        // candidates' fit ("none fits"), never "no gap".
        let lr_gap = chi2_upper_p(
            ((nominal_chi2 - list.iter().map(|f| f.chi2).fold(f64::INFINITY, f64::min)) / phi)
                .max(0.0),
            1.0,
        )
        .unwrap_or(0.0)
            < opts.alpha;
        let nominal_fits = blocks
            .iter()
            .map(|(n, _, c)| block_p(*c, *n))
            .fold(1.0f64, f64::min)
            >= opts.alpha;
        let best_sims = &self.fits[self.position(&list[0].knob)][mi].sims;
        // The best fits only through leaving one metric out (through a reference, with
        // cycles): said beside the answer, whatever it is.
        let summaries_left_out = if cycles_decide && best_plausible {
            summary_fits[0].left_out.take()
        } else {
            None
        };
        // Never "no gap" where the best candidate, no better than the nominal, "fits" only by
        // leaving out one metric: the whole change may lie there (an actuation latency the
        // candidates cannot draw moves only the peak torque, through a reference), so none
        // fits, and the rest lies there.
        let verdict = if !lr_gap && nominal_fits {
            Verdict::NoGap
        } else if best_p < opts.alpha || (!lr_gap && summaries_left_out.is_some()) {
            Verdict::NoneFits {
                rest_in: rest_in(obs, self.sigs, best_sims, opts.relative_floor, mi == 1),
            }
        } else if !lr_gap {
            Verdict::NoGap
        } else if list.iter().skip(1).all(|f| f.separated) {
            Verdict::Named {
                knob: list[0].knob.clone(),
            }
        } else {
            Verdict::CannotTell {
                group: list
                    .iter()
                    .filter(|f| !f.separated)
                    .map(|f| f.knob.clone())
                    .collect(),
            }
        };
        Ranking {
            evidence: mode,
            fits: list,
            nominal_chi2,
            observations: n,
            overdispersion: phi,
            best_p_value: best_p,
            verdict,
            summaries_left_out,
            pairs: Vec::new(),
        }
    }

    /// Cycles for the figure: every trial with a log, nominal and the waveform ranking's
    /// best.
    fn cycles(
        &self,
        set: &TrialSet,
        rankings: &[Ranking],
        nominal: &[SimCycle],
    ) -> Vec<TrialCycles> {
        let mut cycles = Vec::new();
        if let Some(r) = rankings
            .iter()
            .find(|r| r.evidence == Evidence::SummariesAndWaveforms)
        {
            let bi = self.position(&r.fits[0].knob);
            for (i, m) in self.sigs.iter().enumerate() {
                let Some(m) = m else { continue };
                cycles.push(TrialCycles {
                    trial: set.trials[i].name(),
                    measured: m.clone(),
                    nominal: nominal[i].cycles.clone(),
                    best: self.fits[bi][1].sims[i].cycles.clone(),
                    best_knob: r.fits[0].knob.clone(),
                });
            }
        }
        cycles
    }
}

fn poisoned<T>(_: T) -> GapError {
    GapError::Invalid("internal: a walk cache lock was poisoned by a panic".into())
}

fn check(opts: &SeparateOptions) -> Result<(), GapError> {
    let mut distinct = opts.candidates.clone();
    distinct.sort();
    distinct.dedup();
    if distinct.len() < 2 {
        return Err(GapError::Invalid(
            "give at least two distinct candidates to separate".into(),
        ));
    }
    if !(opts.alpha > 0.0 && opts.alpha < 1.0) {
        return Err(GapError::Invalid("alpha must be in (0, 1)".into()));
    }
    if !(2..=64).contains(&opts.grid_points) {
        return Err(GapError::Invalid("grid points must be in [2, 64]".into()));
    }
    if !(opts.relative_floor > 0.0 && opts.relative_floor < 1.0) {
        return Err(GapError::Invalid(format!(
            "waveform floor {}: must be a fraction in (0, 1)",
            opts.relative_floor
        )));
    }
    Ok(())
}

/// The metric or signal carrying the most χ² at a fit.
fn rest_in(
    obs: &[Observation],
    sigs: &[Option<CycleSignature>],
    sims: &[SimCycle],
    floor: f64,
    waveforms: bool,
) -> String {
    let mut by: Vec<(String, f64)> = Vec::new();
    let mut add = |k: String, v: f64| match by.iter_mut().find(|(n, _)| *n == k) {
        Some(e) => e.1 += v,
        None => by.push((k, v)),
    };
    for o in obs {
        add(
            o.metric.column().to_string(),
            o.z2(sims[o.trial].metrics.get(o.metric)),
        );
    }
    if waveforms {
        for (m, s) in sigs.iter().zip(sims) {
            let (Some(m), Some(c)) = (m, &s.cycles) else {
                continue;
            };
            for (sig, c2, _) in waveform::chi2(m, c, floor).per_signal {
                add(format!("the {} cycle", Signal::column(sig)), c2);
            }
        }
    }
    by.sort_by(|a, b| b.1.total_cmp(&a.1));
    by.first()
        .map(|(k, v)| format!("{k} (χ² {v:.0})"))
        .unwrap_or_default()
}

/// Why a group of knobs was separated with the cycles after a diagnosis.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FollowPurpose {
    /// A look-alike group the summaries could not resolve (`answer.ambiguous`), with the
    /// best single knobs outside it: the cycles may name one of them.
    Ambiguous,
    /// The answer's one named knob against its closest single-knob rivals (by held-out
    /// gap): the name stands only if the cycles name it too.
    Confirm { knob: String },
    /// The summaries left the gap beyond noise with nothing named (partly explained or
    /// unexplained): the answer's leads and the best single knobs, in case the cycles tell.
    Explore,
}

/// One separation made after a diagnosis.
#[derive(Clone, Debug, Serialize)]
pub struct FollowGroup {
    pub purpose: FollowPurpose,
    pub separation: Separation,
    /// The verdict of the richest evidence (summaries + waveforms when any log was compared).
    pub verdict: Verdict,
}

/// What the logged cycles add to a diagnosis: the separations and the names that stand.
#[derive(Clone, Debug, Default, Serialize)]
pub struct FollowUp {
    pub groups: Vec<FollowGroup>,
    /// The knobs named with the cycles: the answer's names that the cycles confirmed (or
    /// that were not checked: an answer of two knobs or more), plus the knob the cycles name
    /// in a look-alike group.
    pub named: Vec<String>,
    /// Names the cycles took away, with why.
    pub withdrawn: Vec<String>,
    /// Groups not separated, with why (one holds a number the design does not declare).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_separated: Vec<String>,
    /// Named knobs whose carried summaries fit only with one metric left out
    /// ([`Ranking::summaries_left_out`]): the knob, with that metric.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub left_out: Vec<(String, MetricLeftOut)>,
}

/// Single-knob rivals a named knob is confirmed against.
const CONFIRM_RIVALS: usize = 2;
/// Candidates separated when the summaries name nothing and leave the gap beyond noise: the
/// answer's leads, then the best single knobs by held-out gap.
const EXPLORE_CANDIDATES: usize = 3;

/// The verdict of a separation's richest evidence.
fn final_verdict(s: &Separation) -> Verdict {
    s.rankings
        .last()
        .map(|r| r.verdict.clone())
        .unwrap_or(Verdict::NoGap)
}

/// The logged cycles after a diagnosis (`answer`, `single` of `d`), on resolved conditions
/// and measured cycles (`sigs`, as [`measured_signatures`]; the benchmark's are in memory):
///
/// * each look-alike group the summaries left (`answer.ambiguous`) is separated, with its
///   [`CONFIRM_RIVALS`] best single-knob rivals outside it; a knob the cycles name there is
///   named;
/// * an answer that names nothing and leaves the gap beyond noise (partly explained or
///   unexplained) has its leads and the best single knobs (up to [`EXPLORE_CANDIDATES`])
///   separated; a knob the cycles name there — fitting within noise in the summaries and in
///   the cycles, every rival worse beyond the test — is named;
/// * an answer that names exactly one knob has it separated from its [`CONFIRM_RIVALS`]
///   closest single-knob rivals (by held-out gap); the name stands only if the cycles name
///   the same knob — a rival named instead, "cannot tell", "none fits" or "no gap" withdraw
///   it. This rule only takes names away: a summary-only name that the cycles contradict is
///   the confident wrong answer a look-alike gives (measured on Drake-Lagged's hip Coulomb
///   friction 0.05 N·m, named hip viscous damping on the summaries:
///   `tests/golden/drake/gap-lagged-logs/README.md`). An answer of two knobs or more is not
///   checked (a single knob alone would not fit a compound cause).
///
/// Nothing is done (an empty follow-up, the answer's names standing) when no trial has a
/// log. With `reference`, each separation is made through it ([`separate_through`]).
#[allow(clippy::too_many_arguments)]
pub fn follow_up_with(
    d: &super::diagnose::Diagnosis,
    set: &TrialSet,
    conditions: &[Condition],
    sigs: &[Option<CycleSignature>],
    reference: Option<&Reference<'_>>,
    lib: &EffectLibrary,
    opts: &SeparateOptions,
    cache: &CycleCache,
    progress: &dyn Observer,
) -> Result<FollowUp, GapError> {
    let answer_names: Vec<String> = d
        .answer
        .effects
        .iter()
        .chain(&d.answer.parameters)
        .map(|n| n.knob.clone())
        .collect();
    let mut out = FollowUp {
        named: answer_names.clone(),
        ..FollowUp::default()
    };
    if sigs.iter().all(Option::is_none) {
        return Ok(out);
    }
    let single: Vec<String> = d.single.iter().map(|f| f.knob.clone()).collect();
    let (jobs, not_separated) = follow_up_jobs(&d.answer, &single);
    out.not_separated = not_separated;
    // The carrying does not depend on the candidates: made once for every group.
    let carrying = match (reference, jobs.is_empty()) {
        (Some(r), false) => Some(carry_through(
            set, conditions, sigs, r, lib, opts, cache, progress,
        )?),
        _ => None,
    };
    let mut carrying_walks = carrying.as_ref().map_or(0, |c| c.walks);
    for (purpose, group) in jobs {
        let o = SeparateOptions {
            candidates: group,
            ..opts.clone()
        };
        let mut separation = match &carrying {
            Some(c) => separate_carried(c, conditions, lib, &o, cache, progress)?,
            None => separate_with(set, conditions, sigs, lib, &o, cache, progress)?,
        };
        // The nominal walks made to carry count once, with the first separation.
        separation.walks += std::mem::take(&mut carrying_walks);
        let verdict = final_verdict(&separation);
        match (&purpose, &verdict) {
            (FollowPurpose::Ambiguous | FollowPurpose::Explore, Verdict::Named { knob })
                if !out.named.contains(knob) =>
            {
                out.named.push(knob.clone());
            }
            // A pair adds both knobs; one that confirms the answer must hold its knob (a pair
            // without it withdraws it below and, as a rival named instead, adds nothing).
            (p, Verdict::NamedTogether { knobs }) if !matches!(p, FollowPurpose::Confirm { knob } if !knobs.contains(knob)) => {
                for k in knobs {
                    if !out.named.contains(k) {
                        out.named.push(k.clone());
                    }
                }
            }
            (FollowPurpose::Confirm { knob }, v) if v != &Verdict::Named { knob: knob.clone() } => {
                out.named.retain(|k| k != knob);
                out.withdrawn.push(format!(
                    "{knob}: the logged cycles do not confirm it against its closest rivals ({})",
                    verdict_words(v)
                ));
            }
            _ => {}
        }
        if let Verdict::Named { knob } = &verdict
            && out.named.contains(knob)
            && let Some(l) = separation
                .rankings
                .last()
                .and_then(|r| r.summaries_left_out.clone())
            && !out.left_out.iter().any(|(k, _)| k == knob)
        {
            out.left_out.push((knob.clone(), l));
        }
        // A named pair whose carried summaries fit only without one metric: under the pair's
        // label ("a + b"), which the paired knobs' own caveats give way to below.
        if let Verdict::NamedTogether { knobs } = &verdict
            && knobs.iter().all(|k| out.named.contains(k))
            && let Some(l) = separation
                .rankings
                .last()
                .and_then(|r| r.pairs.iter().find(|p| p.passes))
                .and_then(|p| p.summaries_left_out.clone())
        {
            let label = knobs.join(" + ");
            if !out.left_out.iter().any(|(k, _)| *k == label) {
                out.left_out.push((label, l));
            }
        }
        out.groups.push(FollowGroup {
            purpose,
            separation,
            verdict,
        });
    }
    // A knob later named with a partner: the pair, not the metric left out, holds what the
    // knob alone left (Coulomb friction alone leaves the peak torque; with the backlash
    // beside it, nothing).
    let paired: Vec<String> = out
        .groups
        .iter()
        .filter_map(|g| match &g.verdict {
            Verdict::NamedTogether { knobs } => Some(knobs.clone()),
            _ => None,
        })
        .flatten()
        .collect();
    out.left_out.retain(|(k, _)| !paired.contains(k));
    Ok(out)
}

/// The groups [`follow_up_with`] separates after a diagnosis whose answer is `answer` and
/// whose single knobs, best first, are `single`, as (why, candidates); and the groups it does
/// not separate, with why.
pub fn follow_up_jobs(
    answer: &super::diagnose::Answer,
    single: &[String],
) -> (Vec<(FollowPurpose, Vec<String>)>, Vec<String>) {
    let answer_names: Vec<String> = answer
        .effects
        .iter()
        .chain(&answer.parameters)
        .map(|n| n.knob.clone())
        .collect();
    let mut not_separated = Vec::new();
    // A group is the summaries' look-alikes; the truth may be a knob the diagnosis did not
    // put in it (measured on Drake-Lagged: hip Coulomb friction 0.015 N·m left the group
    // {viscous damping, μ}, and the cycles named viscous damping from it). So each group is
    // separated together with its best single-knob rivals outside it.
    let with_rivals = |group: &[String]| {
        let mut g = group.to_vec();
        g.extend(
            single
                .iter()
                .filter(|k| !group.contains(k))
                .take(CONFIRM_RIVALS)
                .cloned(),
        );
        g
    };
    let mut jobs: Vec<(FollowPurpose, Vec<String>)> = answer
        .ambiguous
        .iter()
        .filter(|g| g.len() >= 2)
        .map(|g| (FollowPurpose::Ambiguous, with_rivals(g)))
        .collect();
    let beyond_noise = matches!(
        answer.kind,
        AnswerKind::PartlyExplained | AnswerKind::Unexplained
    );
    if answer_names.is_empty() && beyond_noise {
        let mut group: Vec<String> = answer.leads.iter().map(|n| n.knob.clone()).collect();
        for k in single {
            if group.len() >= EXPLORE_CANDIDATES {
                break;
            }
            if !group.contains(k) {
                group.push(k.clone());
            }
        }
        if group.len() >= 2 {
            jobs.push((FollowPurpose::Explore, group));
        }
    }
    if let [knob] = answer_names.as_slice() {
        let mut group = vec![knob.clone()];
        group.extend(
            single
                .iter()
                .filter(|k| *k != knob)
                .take(CONFIRM_RIVALS)
                .cloned(),
        );
        if group.len() >= 2 {
            jobs.push((FollowPurpose::Confirm { knob: knob.clone() }, group));
        }
    }
    // A group holding a number the design does not declare (the audit's look-alike, "…
    // (undeclared)") is not separated: the cycles cannot fit that number, and separating the
    // rest could name the stand-in the audit took the name from. Its knobs stay unnamed.
    jobs.retain(|(_, group)| {
        let Some(u) = group.iter().find(|k| k.contains(super::audit::UNDECLARED)) else {
            return true;
        };
        not_separated.push(format!(
            "{{{}}}: it holds {u}, a number the design does not declare, which the cycles \
             cannot fit (declare it with a range to separate it)",
            group.join(", ")
        ));
        false
    });
    (jobs, not_separated)
}

/// A verdict in a few words.
pub fn verdict_words(v: &Verdict) -> String {
    match v {
        Verdict::NoGap => "no gap".into(),
        Verdict::Named { knob } => format!("they name {knob}"),
        Verdict::NamedTogether { knobs } => format!("they name {} together", knobs.join(" and ")),
        Verdict::CannotTell { group } => format!("cannot tell {}", group.join(" from ")),
        Verdict::NoneFits { rest_in } => format!("none fits; the rest lies in {rest_in}"),
        Verdict::NotComparable { .. } => {
            "not comparable: the model walks none of the reference's gaits".into()
        }
    }
}

/// [`follow_up_with`] reading the logs the trials (and the reference's) name.
pub fn follow_up(
    d: &super::diagnose::Diagnosis,
    set: &TrialSet,
    reference: Option<&TrialSet>,
    lib: &EffectLibrary,
    opts: &SeparateOptions,
    progress: &dyn Observer,
) -> Result<FollowUp, GapError> {
    // Without a log there is nothing to resolve or read: the answer's names stand.
    let logged = set.trials.iter().any(|t| t.trajectory.is_some());
    let (conditions, sigs) = if logged {
        resolve_with_cycles(set, opts.settle_cycles)?
    } else {
        (Vec::new(), Vec::new())
    };
    let resolved_reference = match reference {
        Some(r) if logged => Some((r, resolve_with_cycles(r, opts.settle_cycles)?)),
        _ => None,
    };
    let reference = resolved_reference
        .as_ref()
        .map(|(r, (conditions, sigs))| Reference {
            set: r,
            conditions,
            sigs,
        });
    follow_up_with(
        d,
        set,
        &conditions,
        &sigs,
        reference.as_ref(),
        lib,
        opts,
        &CycleCache::default(),
        progress,
    )
}

/// The summaries' p-value of a fit with `k` free knobs (Bonferroni over `blocks` blocks of
/// evidence); through a reference the larger of it and the p-value without the one metric
/// that misses most: a candidate only one metric rejects is plausible, since that metric's
/// misfit may be the engines' versions of the effect answering it apart
/// (`reference::within_noise_but_one_metric`, measured on Drake's hip Coulomb friction
/// 0.08 N·m: the yaw swing).
/// With the metric left out, when that is what made the summaries plausible.
fn summaries_fit(
    obs: &[Observation],
    sims: &[SimCycle],
    chi2: f64,
    k: usize,
    blocks: f64,
    opts: &SeparateOptions,
) -> SummariesFit {
    let dof = (obs.len().max(k + 1) - k) as f64;
    let p = (blocks * chi2_upper_p(chi2, dof).unwrap_or(0.0)).min(1.0);
    let but_one = opts
        .through_reference
        .then(|| {
            super::reference::within_noise_but_one(
                obs,
                |o| sims[o.trial].metrics.get(o.metric),
                k,
                opts.alpha / blocks,
            )
        })
        .flatten();
    match but_one {
        Some(w) => SummariesFit {
            p: p.max((blocks * w.p_left).min(1.0)),
            left_out: Some(MetricLeftOut {
                metric: w.metric.column().to_string(),
                chi2: w.chi2_metric,
                values: obs.len() - w.n_left,
            }),
        },
        None => SummariesFit { p, left_out: None },
    }
}

/// [`summaries_fit`]'s answer.
struct SummariesFit {
    p: f64,
    /// Through a reference: the metric without which summaries that fail the χ² test fit
    /// within noise (`reference::within_noise_but_one`, at α over the blocks).
    left_out: Option<MetricLeftOut>,
}

/// χ²₁'s 95 % point: a profile's bound.
const CHI2_1_95: f64 = 3.841_458_820_694_124;

impl FitProblem<'_> {
    /// The best candidate of the summaries + waveforms ranking fitted together with each rival
    /// ([`Self::pair_profile`]); a pair is named ([`Verdict::NamedTogether`]) when it passes
    /// every rule and every other pair that does is worse beyond the test:
    /// * each knob is needed beside the other: the pair beats each knob alone by the
    ///   likelihood-ratio test (1 dof, Δχ² over the ranking's over-dispersion) at α over the
    ///   pairs tried;
    /// * neither value sits at an end of its range;
    /// * it fits within noise in both blocks of evidence (Bonferroni over them; the summaries
    ///   by the ranking's rule, which through a reference forgives one metric);
    /// * any other pair that passes these fits worse by the test (1 dof at α over the pairs,
    ///   Δχ² over the best pair's own over-dispersion): else none is named.
    ///
    /// The evidence is the ranking's: summaries + cycles χ², or through a reference the cycles'
    /// χ² alone (the summaries only judge plausibility there: which look-alike carried
    /// summaries favour is the engines' business). Measured on Drake-Lagged through its
    /// no-effect trials, noise-free: viscous damping 0.02 N·m·s/rad with Coulomb friction 0.05
    /// N·m fit the cycles at χ² 11.4 as a pair against 29.1 for damping alone (on 372
    /// coefficients), while Coulomb friction 0.065 N·m alone gains 0.4 from a damping beside
    /// it and damping 0.025 alone nothing from Coulomb friction; on the summaries + cycles the
    /// same Coulomb friction would have gained 12.5 from a spurious damping (the summaries'
    /// engine difference), hence the cycles alone.
    ///
    /// Where no pair passes, each pair still says how much of the second knob the profile does
    /// not reject beside the first (`PairFit::second_upper`): a single name is then "this, with
    /// up to so much of that".
    fn check_pairs(&self, r: &mut Ranking) -> Result<(), GapError> {
        let (knobs, obs, sigs, opts) = (self.knobs, self.obs, self.sigs, self.opts);
        let judged = matches!(
            r.verdict,
            Verdict::Named { .. } | Verdict::CannotTell { .. } | Verdict::NoneFits { .. }
        );
        if !judged || r.fits.len() < 2 {
            return Ok(());
        }
        let n_wave: usize = sigs.iter().flatten().map(coefficient_count).sum();
        let cycles_decide = opts.through_reference && n_wave > 0;
        let cost: &dyn Fn(f64, f64) -> f64 = if cycles_decide {
            &|_, w| w
        } else {
            &|s, w| s + w
        };
        let blocks = if n_wave > 0 { 2.0 } else { 1.0 };
        let Some(a) = knobs.index_of(&r.fits[0].knob) else {
            return Ok(());
        };
        let rivals: Vec<usize> = r.fits[1..]
            .iter()
            .filter_map(|f| knobs.index_of(&f.knob))
            .collect();
        let per_test = opts.alpha / rivals.len().max(1) as f64;
        let needed = |d: f64| chi2_upper_p(d.max(0.0), 1.0).unwrap_or(1.0) < per_test;
        let phi = r.overdispersion.max(1.0);
        let alone_a = self.fit_one(a, cost)?;
        let (ka, wave_dof) = (&knobs.list[a], (n_wave.max(3) - 2) as f64);
        let at_end = |k: &super::knob::Knob, x: f64| {
            let span = k.hi - k.lo;
            (x - k.lo).abs() < 1e-3 * span || (k.hi - x).abs() < 1e-3 * span
        };
        let mut pairs = Vec::with_capacity(rivals.len());
        for b in rivals {
            let kb = &knobs.list[b];
            let alone_b = self.fit_one(b, cost)?;
            let (profile, best) = self.pair_profile(a, b, cost)?;
            let c = cost(best.s, best.w);
            let delta = [
                (cost(alone_a.s, alone_a.w) - c) / phi,
                (cost(alone_b.s, alone_b.w) - c) / phi,
            ];
            let summaries = summaries_fit(obs, &best.sims, best.s, 2, blocks, opts);
            let p_summaries = summaries.p;
            let p_cycles = if n_wave > 0 {
                (blocks * chi2_upper_p(best.w, wave_dof).unwrap_or(0.0)).min(1.0)
            } else {
                1.0
            };
            let why_not = if !needed(delta[0]) {
                Some(format!(
                    "{} is not needed beside {} (Δ {:.1})",
                    kb.label(),
                    ka.label(),
                    delta[0]
                ))
            } else if !needed(delta[1]) {
                Some(format!(
                    "{} is not needed beside {} (Δ {:.1})",
                    ka.label(),
                    kb.label(),
                    delta[1]
                ))
            } else if at_end(ka, best.xa) || at_end(kb, best.xb) {
                Some("a value at an end of its range".to_string())
            } else if p_summaries < opts.alpha || p_cycles < opts.alpha {
                Some(format!(
                    "it does not fit within noise (p {:.2e} on the summaries, {:.2e} on the cycles)",
                    p_summaries, p_cycles
                ))
            } else {
                None
            };
            // The profile's 95 % range of the second knob, at the grid's resolution: from the
            // node below the first one the profile does not reject to the node above the last.
            let floor = profile.iter().map(|q| cost(q.s, q.w)).fold(c, f64::min);
            let kept = |q: &PairPoint| cost(q.s, q.w) <= floor + CHI2_1_95 * phi;
            let first = profile.iter().position(kept).unwrap_or(0);
            let last = profile.iter().rposition(kept).unwrap_or(profile.len() - 1);
            let ends = [
                profile[first.saturating_sub(1)].xb,
                profile[(last + 1).min(profile.len() - 1)].xb,
            ];
            let (lo, hi) = (kb.si(ends[0]), kb.si(ends[1]));
            let second_range = [lo.min(hi), lo.max(hi)];
            pairs.push(PairFit {
                knobs: [ka.label(), kb.label()],
                values: [ka.si(best.xa), kb.si(best.xb)],
                units: [ka.unit.clone(), kb.unit.clone()],
                chi2_summaries: best.s,
                chi2_waveforms: best.w,
                delta,
                second_range,
                passes: why_not.is_none(),
                why_not,
                summaries_left_out: summaries.left_out.filter(|_| cycles_decide),
            });
        }
        // Several pairs pass (the best candidate with each of two look-alikes): the best is
        // named only if every other passing pair is worse beyond the test, by the
        // over-dispersion of the best pair's own fit (the ranking's is the single knob's,
        // which the missing second cause inflates: measured with the COM fore-aft offset
        // 0.01 L and hip Coulomb friction 0.02 N·m, the pair with Coulomb friction fits
        // the cycles at χ² 18 and the one with viscous damping at 120, yet the ranking's
        // over-dispersion of 20 left them "not told apart"). Otherwise none is named.
        let passing: Vec<usize> = (0..pairs.len()).filter(|&i| pairs[i].passes).collect();
        if passing.len() > 1 {
            let pair_cost = |p: &PairFit| cost(p.chi2_summaries, p.chi2_waveforms);
            let best = passing
                .iter()
                .copied()
                .min_by(|&i, &j| pair_cost(&pairs[i]).total_cmp(&pair_cost(&pairs[j])))
                .unwrap_or(passing[0]);
            let bp = &pairs[best];
            // Each block the pair is tested on (through a reference, the cycles alone).
            let own_phi = match (n_wave > 0, cycles_decide) {
                (true, true) => dispersion(bp.chi2_waveforms, n_wave, 2),
                (true, false) => dispersion(bp.chi2_waveforms, n_wave, 2).max(dispersion(
                    bp.chi2_summaries,
                    obs.len(),
                    2,
                )),
                (false, _) => dispersion(bp.chi2_summaries, obs.len(), 2),
            };
            let best_label = format!("{} + {}", bp.knobs[0], bp.knobs[1]);
            let best_cost = pair_cost(bp);
            let deltas: Vec<(usize, f64)> = passing
                .iter()
                .filter(|&&i| i != best)
                .map(|&i| (i, (pair_cost(&pairs[i]) - best_cost) / own_phi))
                .collect();
            let told_apart = deltas
                .iter()
                .all(|(_, d)| chi2_upper_p(d.max(0.0), 1.0).unwrap_or(1.0) < per_test);
            for (i, d) in deltas {
                pairs[i].passes = false;
                pairs[i].why_not = Some(if told_apart {
                    format!("{best_label} fits better beyond the test (Δ {d:.1})")
                } else {
                    format!("{best_label} passes too and is not told apart from it (Δ {d:.1})")
                });
            }
            if !told_apart {
                pairs[best].passes = false;
                pairs[best].why_not =
                    Some("another pair passes too and is not told apart from it".to_string());
            }
        }
        if let Some(p) = pairs.iter().find(|p| p.passes) {
            r.verdict = Verdict::NamedTogether {
                knobs: p.knobs.to_vec(),
            };
        }
        r.pairs = pairs;
        Ok(())
    }
}

/// One point of a pair's profile: knob `b` held at `xb`, knob `a` refitted on walks.
#[derive(Clone)]
struct PairPoint {
    xa: f64,
    xb: f64,
    sims: Arc<Vec<SimCycle>>,
    s: f64,
    w: f64,
}

impl FitProblem<'_> {
    /// The profile of knob `b` beside knob `a` (both free, the rest at the file's values): at
    /// each of `b`'s grid nodes, `a` fitted by its grid and a golden section on walks, by
    /// `cost(summaries χ², cycles χ²)`; then `b` refined by a golden section between the best
    /// node's neighbours, `a` refitted inside the bracket its neighbours' fits span. Returns the
    /// nodes' fits (in `b`'s order) and the refined best.
    fn pair_profile(
        &self,
        a: usize,
        b: usize,
        cost: &dyn Fn(f64, f64) -> f64,
    ) -> Result<(Vec<PairPoint>, PairPoint), GapError> {
        let (walker, knobs, obs, sigs, opts) =
            (self.walker, self.knobs, self.obs, self.sigs, self.opts);
        let (ka, kb) = (&knobs.list[a], &knobs.list[b]);
        let label = format!("{}|{}", ka.label(), kb.label());
        let eval = |xa: f64, xb: f64| -> Result<PairPoint, GapError> {
            let mut point = knobs.nominal_point();
            point[a] = Some(xa);
            point[b] = Some(xb);
            let sims = walker.run(
                (format!("{label}={:x}", xb.to_bits()), xa.to_bits()),
                &knobs.setting(walker.lib, &point),
            )?;
            let (s, w) = chi2_pair(obs, sigs, &sims, opts.relative_floor);
            Ok(PairPoint { xa, xb, sims, s, w })
        };
        let steps = opts.refine_steps.saturating_sub(1);
        let by_cost = |q: PairPoint| (cost(q.s, q.w), q);
        // `a` fitted with `b` at `xb`: over `a`'s whole range, or by a golden section in [lo, hi].
        let fit_a = |xb: f64| {
            grid_then_golden(&ka.nodes(opts.grid_points), steps, |x| {
                eval(x, xb).map(by_cost)
            })
        };
        let fit_a_in = |xb: f64, lo: f64, hi: f64| {
            super::solver::golden_section(lo, hi, steps, |x| eval(x, xb).map(by_cost)).map(|r| r.2)
        };
        let nodes_b = kb.nodes(opts.grid_points);
        let mut profile = Vec::with_capacity(nodes_b.len());
        for &xb in &nodes_b {
            profile.push(fit_a(xb)?);
        }
        let j = (0..profile.len())
            .min_by(|x, y| {
                cost(profile[*x].s, profile[*x].w).total_cmp(&cost(profile[*y].s, profile[*y].w))
            })
            .unwrap_or(0);
        let (jl, jh) = (j.saturating_sub(1), (j + 1).min(profile.len() - 1));
        let step_a = (ka.hi - ka.lo) / (opts.grid_points.max(2) - 1) as f64;
        let a_lo = (profile[jl].xa.min(profile[jh].xa) - step_a).max(ka.lo);
        let a_hi = (profile[jl].xa.max(profile[jh].xa) + step_a).min(ka.hi);
        let (_, c, refined) =
            super::solver::golden_section(nodes_b[jl], nodes_b[jh], steps, |xb| {
                fit_a_in(xb, a_lo, a_hi).map(by_cost)
            })?;
        let best = if c < cost(profile[j].s, profile[j].w) {
            refined
        } else {
            profile[j].clone()
        };
        Ok((profile, best))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gap::diagnose::{Answer, AnswerKind};

    fn ambiguous_answer(groups: Vec<Vec<&str>>) -> Answer {
        Answer {
            kind: AnswerKind::Ambiguous,
            parameters: Vec::new(),
            effects: Vec::new(),
            leads: Vec::new(),
            ambiguous: groups
                .into_iter()
                .map(|g| g.into_iter().map(String::from).collect())
                .collect(),
            rest: None,
            statement: String::new(),
        }
    }

    /// The audit's look-alike group (a declared knob with an undeclared number, which
    /// `separate` cannot fit) is left out with why; a group of fittable knobs is separated
    /// with its two best single rivals outside it. Before, the undeclared label was passed
    /// on as a candidate and the whole diagnosis ended in an error (seen through a reference
    /// with logs: a foot-centre offset of 0.015 L read as μ or the COM offset).
    #[test]
    fn a_look_alike_group_holding_an_undeclared_number_is_not_separated() {
        let single: Vec<String> = ["mugatu:contact.friction_mu", "hip_backlash", "soft_ground"]
            .map(String::from)
            .to_vec();
        let undeclared = format!(
            "mugatu:geometry.foot_center_forward_over_l{}",
            crate::gap::audit::UNDECLARED
        );
        let answer = ambiguous_answer(vec![
            vec!["mugatu:mass.leg_com_forward_over_l", &undeclared],
            vec!["hip_coulomb_friction", "hip_viscous_damping"],
        ]);
        let (jobs, skipped) = follow_up_jobs(&answer, &single);
        assert_eq!(
            jobs,
            vec![(
                FollowPurpose::Ambiguous,
                vec![
                    "hip_coulomb_friction".to_string(),
                    "hip_viscous_damping".into(),
                    "mugatu:contact.friction_mu".into(),
                    "hip_backlash".into(),
                ]
            )]
        );
        assert_eq!(skipped.len(), 1, "{skipped:?}");
        assert!(skipped[0].contains(&undeclared), "{skipped:?}");
        assert!(skipped[0].contains("mugatu:mass.leg_com_forward_over_l"));
        // Against what `separate` accepts: the knobs of Mugatu's file and the library. Every
        // candidate handed on is one of them; the undeclared number is not (the cause of the
        // error this rule removes).
        let design = crate::sim::Design::resolve("mugatu").expect("bundled design");
        let lib = EffectLibrary::bundled().expect("bundled library");
        let effects: Vec<_> = lib.effects.iter().collect();
        let knobs = Knobs::build(&[&design], &effects, true).expect("knobs");
        for (_, group) in &jobs {
            for c in group {
                assert!(knobs.index_of(c).is_some(), "{c} is not a knob");
            }
        }
        assert!(knobs.index_of(&undeclared).is_none());
    }
}
