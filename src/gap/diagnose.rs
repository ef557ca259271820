//! The diagnosis: where the nominal simulation misses the trials, and the posterior
//! probability of every explanation — nothing off, a declared parameter off, a library effect
//! missing, two of these at once, an undeclared number off, or something outside all of
//! them — with the answer the criterion draws from it ([`super::decide`]).
//!
//! Steps: the trials become observations (metrics, and the Fourier coefficients of logged
//! cycles; through a reference, the change is carried onto the model); the model's own
//! spread is walked ([`super::discrepancy`]); every knob is walked over its range
//! ([`build_surrogate`]); every explanation is integrated and the leading ones confirmed by
//! walks ([`super::posterior`]); the answer and where the gap lies follow.

use serde::Serialize;

use super::cache::SimCache;
use super::criterion::Criterion;
use super::curve::Curve;
use super::decide::{Answer, Lead, Named, decide, leads, named};
use super::discrepancy::{BlockSpread, STARTS, apply, by_block, model_spread};
use super::error::{GapError, check_default_sd};
use super::evidence::Slab;
use super::hypothesis::{Class, hypotheses};
use super::knob::{KnobKind, Knobs, ModelSetting};
use super::library::EffectLibrary;
use super::likelihood::{Observation, chi2_of};
use super::locate::{MetricGap, Residual, metric_gaps, summarize};
use super::posterior::{Inputs, Posterior, Search, weigh};
use super::simulate::{Condition, Walked, resolve};
use super::surrogate::Surrogate;
use super::trials::TrialSet;
use crate::progress::{Observer, Stopwatch};

#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// Candidate effects (empty: the whole library).
    pub effects: Vec<String>,
    /// Walks per knob over its plausible range (before refinement).
    pub grid_points: usize,
    /// Relative sd assumed for a measurement that states none.
    pub default_relative_sd: f64,
    /// The designs' declared `[[uncertain]]` parameters are suspects (off: the nominal
    /// values are taken as right, only effects are).
    pub calibrate: bool,
    /// The designs' undeclared numbers are suspects too (at their class's lower prior).
    pub undeclared: bool,
    /// Trials of the same robot without the change asked about: the diagnosis is then of
    /// the change ([`super::reference`]).
    pub reference: Option<TrialSet>,
    /// Robot logs in memory in place of the trials' log files ([`super::observe::Logs`]).
    pub logs: Option<super::observe::Logs>,
    /// Priors and decision ([`Criterion`]).
    pub criterion: Criterion,
    pub search: Search,
}

impl DiagnoseOptions {
    /// The defaults with the bundled criterion.
    pub fn new() -> Result<DiagnoseOptions, GapError> {
        Ok(DiagnoseOptions {
            effects: Vec::new(),
            grid_points: 9,
            default_relative_sd: 0.10,
            calibrate: true,
            undeclared: true,
            reference: None,
            logs: None,
            criterion: Criterion::bundled()?,
            search: Search::default(),
        })
    }
}

/// One explanation in the report.
#[derive(Clone, Debug, Serialize)]
pub struct Explanation {
    pub explanation: String,
    pub class: Class,
    pub prior: f64,
    pub probability: f64,
    /// ln of the evidence, and its Laplace approximation.
    pub log_evidence: f64,
    pub log_evidence_laplace: f64,
    /// The knobs at their most probable values, with 95 % credible intervals.
    pub knobs: Vec<Named>,
    /// χ² at the most probable point: of real walks where `walked`, else the surrogate's.
    pub chi2: f64,
    pub walked: bool,
    /// Posterior-predictive p-value.
    pub fit_p: f64,
    /// ln of the Bayes factor of this explanation with "something outside these" beside it
    /// over it alone.
    pub log_bayes_factor_outside: f64,
}

/// A suspect the trials cannot detect anywhere in its range, or the smallest value at which
/// they can.
#[derive(Clone, Debug, Serialize)]
pub struct Detectable {
    pub knob: String,
    pub kind: KnobKind,
    /// The value (SI) nearest the nominal or off setting that changes the predictions by
    /// one total sd; None: nowhere in its range.
    pub from: Option<f64>,
    pub unit: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub trials: String,
    pub n_trials: usize,
    pub n_observations: usize,
    /// Observations that are Fourier coefficients of logged cycles.
    pub n_cycle_observations: usize,
    /// RMS z of the nominal model (measurement and model spread in the sd).
    pub gap_before: f64,
    pub chi2_before: f64,
    pub summary: String,
    #[serde(rename = "where")]
    pub where_: Vec<MetricGap>,
    pub answer: Answer,
    /// The most probable explanations (at most twelve), and the nominal.
    pub explanations: Vec<Explanation>,
    /// Every explanation weighed (and "something outside these") with its probability,
    /// most probable first.
    pub posterior: Vec<Lead>,
    /// Trials whose logged cycles are observations.
    pub logged_trials: usize,
    /// Explanations weighed, and those confirmed by walks.
    pub weighed: usize,
    pub confirmed: usize,
    /// The suspects and where the trials can see them.
    pub detectable: Vec<Detectable>,
    /// The model's own spread against the measurements, per block.
    pub spread: Vec<BlockSpread>,
    /// Effects left out because a design calibrates their quantity.
    pub aliased: Vec<(String, String)>,
    pub criterion: Criterion,
    pub notes: Vec<String>,
    pub residuals: Vec<Residual>,
    pub walks_evaluated: usize,
}

/// Wall-clock breakdown (not part of the deterministic result).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timing {
    pub spread_s: f64,
    pub grid_s: f64,
    pub posterior_s: f64,
    pub walks: usize,
}

/// Diagnoses `set` against the simulator.
pub fn diagnose(
    set: &TrialSet,
    lib: &EffectLibrary,
    opts: &DiagnoseOptions,
    progress: &dyn Observer,
) -> Result<(Diagnosis, Timing), GapError> {
    let conditions = resolve(set)?;
    let cache = SimCache::default();
    diagnose_conditions(set, &conditions, lib, opts, &cache, progress)
}

/// The distinct designs of the conditions, in order of first appearance.
pub fn designs_of(conditions: &[Condition]) -> Vec<&crate::sim::Design> {
    let mut designs: Vec<&crate::sim::Design> = Vec::new();
    for c in conditions {
        if !designs.iter().any(|d| d.name == c.design.name) {
            designs.push(&c.design);
        }
    }
    designs
}

fn check_options(opts: &DiagnoseOptions) -> Result<(), GapError> {
    if !(2..=64).contains(&opts.grid_points) {
        return Err(GapError::Invalid("grid points must be in [2, 64]".into()));
    }
    check_default_sd(opts.default_relative_sd)
}

/// [`diagnose`] on resolved conditions, sharing walks through `cache`.
pub fn diagnose_conditions(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
    opts: &DiagnoseOptions,
    cache: &SimCache,
    progress: &dyn Observer,
) -> Result<(Diagnosis, Timing), GapError> {
    check_options(opts)?;
    let walks0 = cache.walks();
    let mut timing = Timing::default();
    progress.stage("the nominal model at every condition");
    let nominal = cache.get(conditions, lib, &ModelSetting::nominal(), progress)?;
    let observing = super::observe::Observing {
        reference: opts.reference.as_ref(),
        logs: opts.logs.as_ref(),
        default_relative_sd: opts.default_relative_sd,
    };
    let observed = super::observe::observe(set, conditions, lib, &nominal, &observing)?;
    let (set, mut obs, mut notes) = (observed.set, observed.obs, observed.notes);
    let clock = Stopwatch::start();
    progress.stage("the model's own spread over perturbed starts");
    let spread = model_spread(conditions, lib, &ModelSetting::nominal(), STARTS, cache)?;
    apply(&mut obs, &spread);
    timing.spread_s = clock.seconds();
    let knobs = suspects(conditions, lib, opts, &set.origin)?;
    knob_notes(&knobs, opts.calibrate, &mut notes);
    let inputs = Inputs {
        conditions,
        lib,
        cache,
        knobs: &knobs,
        obs: &obs,
        progress,
    };
    let clock = Stopwatch::start();
    progress.stage("walking every knob over its range");
    let surrogate = build_surrogate(&inputs, opts.grid_points)?;
    timing.grid_s = clock.seconds();
    let clock = Stopwatch::start();
    let (post, slabs, weighed) = posterior_of(&inputs, surrogate, opts)?;
    let c = &opts.criterion;
    let answer = decide(&post, &knobs, conditions, &c.decision);
    timing.posterior_s = clock.seconds();
    let chi2_before = chi2_of(&obs, &nominal);
    let residuals = residuals(
        &set,
        conditions,
        &obs,
        &nominal,
        after_walks(&post, &answer),
    )?;
    let where_ = metric_gaps(&residuals, c.decision.fit_level);
    let within = crate::regression::dist::chi2_upper_p(chi2_before, obs.len() as f64)
        .unwrap_or(0.0)
        >= c.decision.fit_level;
    assumed_sd_note(&obs, opts.default_relative_sd, &mut notes);
    timing.walks = cache.walks() - walks0;
    Ok((
        Diagnosis {
            trials: set.origin.clone(),
            n_trials: set.trials.len(),
            n_observations: obs.len(),
            n_cycle_observations: obs.iter().filter(|o| o.as_metric().is_none()).count(),
            gap_before: (chi2_before / obs.len() as f64).sqrt(),
            chi2_before,
            summary: summarize(&where_, within),
            where_,
            explanations: explanations(&post, &knobs, conditions),
            posterior: leads(&post, &knobs, post.outside.as_ref().map(|o| o.2)),
            logged_trials: obs
                .iter()
                .filter(|o| o.as_metric().is_none())
                .map(|o| o.trial)
                .collect::<std::collections::BTreeSet<_>>()
                .len(),
            weighed,
            confirmed: post.weighed.iter().filter(|w| w.walks.is_some()).count(),
            detectable: detectable(&knobs, &slabs),
            spread: by_block(&obs),
            aliased: knobs.aliased.clone(),
            criterion: *c,
            answer,
            notes,
            residuals,
            walks_evaluated: timing.walks,
        },
        timing,
    ))
}

/// The suspects of the trials' designs: their declared parameters (when calibrating), the
/// candidate effects, and their undeclared numbers (when asked); `origin` names the trials
/// in errors.
pub fn suspects(
    conditions: &[Condition],
    lib: &EffectLibrary,
    opts: &DiagnoseOptions,
    origin: &str,
) -> Result<Knobs, GapError> {
    let designs = designs_of(conditions);
    let candidates = lib.subset(&opts.effects)?;
    let sim_error = GapError::sim(origin);
    let knobs = Knobs::build(&designs, &candidates, opts.calibrate).map_err(&sim_error)?;
    if opts.undeclared {
        knobs.with_undeclared(&designs, lib).map_err(&sim_error)
    } else {
        Ok(knobs)
    }
}

/// The posterior over every testable explanation, the slabs it ends with, and how many
/// explanations were weighed.
fn posterior_of(
    inputs: &Inputs<'_>,
    surrogate: Surrogate,
    opts: &DiagnoseOptions,
) -> Result<(Posterior, Vec<Slab>, usize), GapError> {
    let slabs = slabs_of(inputs.knobs, &surrogate, inputs.obs);
    let testable: Vec<bool> = slabs.iter().map(|s| !s.is_empty()).collect();
    let hyps = hypotheses(inputs.knobs, &testable, &opts.criterion.prior);
    let weighed = hyps.len();
    let (post, slabs) = weigh(inputs, surrogate, slabs, hyps, &opts.criterion, opts.search)?;
    Ok((post, slabs, weighed))
}

fn assumed_sd_note(obs: &[Observation], default: f64, notes: &mut Vec<String>) {
    if obs.iter().any(|o| o.sd_assumed) {
        notes.push(format!(
            "{} of {} measurements state no sd: {} % of the value assumed",
            obs.iter().filter(|o| o.sd_assumed).count(),
            obs.len(),
            default * 100.0
        ));
    }
}

/// The walks the residuals' "after" column shows: the named explanation's, else the most
/// probable one's.
fn after_walks<'a>(post: &'a Posterior, answer: &Answer) -> Option<&'a [Walked]> {
    let w = post.best()?;
    if w.hypothesis.class == Class::Nominal && answer.explanation.is_none() {
        return None;
    }
    w.walks.as_deref()
}

/// Every knob's slab (in parallel).
fn slabs_of(knobs: &Knobs, surrogate: &Surrogate, obs: &[Observation]) -> Vec<Slab> {
    use rayon::prelude::*;
    (0..knobs.len())
        .into_par_iter()
        .map(|k| Slab::new(k, &knobs.list[k], surrogate, obs))
        .collect()
}

/// Notes on the knobs: no uncertain parameter to calibrate, effects aliased to a declared
/// parameter.
fn knob_notes(knobs: &Knobs, calibrate: bool, notes: &mut Vec<String>) {
    if calibrate && !knobs.list.iter().any(|k| k.kind == KnobKind::Parameter) {
        notes.push(
            "no design of these trials declares [[uncertain]] parameters: only effects (and \
             undeclared numbers) are suspects"
                .into(),
        );
    }
    for (e, p) in &knobs.aliased {
        notes.push(format!(
            "{e} is not an effect here: the design declares {p} uncertain, the same physics"
        ));
    }
}

/// The most probable explanations (at most twelve) and the nominal, as rows.
fn explanations(post: &Posterior, knobs: &Knobs, conditions: &[Condition]) -> Vec<Explanation> {
    post.weighed
        .iter()
        .enumerate()
        .filter(|(i, w)| *i < 12 || w.hypothesis.class == Class::Nominal)
        .map(|(_, w)| Explanation {
            explanation: w.hypothesis.label(knobs),
            class: w.hypothesis.class,
            prior: w.hypothesis.prior,
            probability: w.probability,
            log_evidence: w.evidence.log_z,
            log_evidence_laplace: w.evidence.log_z_laplace,
            knobs: named(w, knobs, conditions),
            chi2: w.walked_chi2.unwrap_or(w.evidence.chi2_mode),
            walked: w.walked_chi2.is_some(),
            fit_p: w.evidence.fit_p,
            log_bayes_factor_outside: w.log_bf,
        })
        .collect()
}

/// Every suspect's detection edge (SI), in knob order.
fn detectable(knobs: &Knobs, slabs: &[Slab]) -> Vec<Detectable> {
    knobs
        .list
        .iter()
        .zip(slabs)
        .map(|(k, s)| {
            let from = k.to_unit(k.resting());
            Detectable {
                knob: k.label(),
                kind: k.kind,
                from: s.detectable_from(from).map(|u| k.si(k.from_unit(u))),
                unit: k.unit.clone(),
            }
        })
        .collect()
}

/// Rounds of adaptive refinement of the knobs' curves.
const CURVE_ROUNDS: usize = 4;
/// A curve segment is split while, at its midpoint, the monotone cubic and the straight line
/// between its ends differ by more than this many total sds for some observation (the curve
/// bends there more than the data resolve), or one end falls and the other walks.
const CURVE_MAX_BEND_Z: f64 = 1.0;
/// Only where the curve is within this many sds of the measured value (at either end of
/// the segment) does its shape matter.
const CURVE_REACH_Z: f64 = 10.0;
/// Most nodes a curve gets before the search refines it.
const CURVE_MAX_NODES: usize = 25;

/// The surrogate: the nominal walks and every knob's curve — `grid_points` walks over the
/// knob's range, then midpoints added where a segment bends more than the data resolve
/// ([`CURVE_MAX_BEND_Z`]) or crosses a fall, all walks of a round in one parallel batch.
pub fn build_surrogate(inputs: &Inputs<'_>, grid_points: usize) -> Result<Surrogate, GapError> {
    let (conditions, lib, cache) = (inputs.conditions, inputs.lib, inputs.cache);
    let (knobs, obs, progress) = (inputs.knobs, inputs.obs, inputs.progress);
    let nominal = cache.get(conditions, lib, &ModelSetting::nominal(), progress)?;
    let channels: Vec<usize> = conditions.iter().map(Walked::channels_of).collect();
    let setting_at = |k: usize, x: f64| knobs.setting_at(lib, &[(k, x)]);
    let nodes: Vec<Vec<f64>> = knobs.list.iter().map(|k| k.nodes(grid_points)).collect();
    let settings: Vec<ModelSetting> = nodes
        .iter()
        .enumerate()
        .flat_map(|(k, xs)| xs.iter().map(move |x| (k, *x)))
        .map(|(k, x)| setting_at(k, x))
        .collect();
    let walks = cache.get_many(conditions, lib, &settings, progress)?;
    let mut it = walks.into_iter();
    let mut curves: Vec<Curve> = nodes
        .into_iter()
        .enumerate()
        .map(|(k, xs)| {
            let w: Vec<Vec<Walked>> = (0..xs.len()).filter_map(|_| it.next()).collect();
            let mut curve = Curve::new(&channels, xs, w);
            // A nominal inside the range is a walk already made: the nominal one.
            if let Some(x) = knobs.list[k].nominal {
                curve.insert(x, &nominal);
            }
            curve
        })
        .collect();
    for _ in 0..CURVE_ROUNDS {
        let wanted = refinements(knobs, &curves, obs);
        if wanted.is_empty() {
            break;
        }
        progress.stage("refining the knobs' curves where the gait changes fast");
        let settings: Vec<_> = wanted.iter().map(|(k, x)| setting_at(*k, *x)).collect();
        let walks = cache.get_many(conditions, lib, &settings, progress)?;
        for ((k, x), w) in wanted.into_iter().zip(walks) {
            curves[k].insert(x, &w);
        }
    }
    Ok(Surrogate {
        channels,
        nominal,
        curves,
        anchored: None,
    })
}

/// The midpoints to walk next: (knob, coordinate) of every segment of a curve that bends more
/// than the data resolve near the measurements, crosses a fall, or may hold a better fit than
/// any of the curve's nodes ([`may_hold_better`]).
fn refinements(knobs: &Knobs, curves: &[Curve], obs: &[Observation]) -> Vec<(usize, f64)> {
    let mut wanted: Vec<(usize, f64)> = Vec::new();
    for (k, curve) in curves.iter().enumerate() {
        let knob = &knobs.list[k];
        let min_gap = (knob.hi - knob.lo) / 256.0;
        let best = curve
            .x
            .iter()
            .map(|&x| {
                obs.iter()
                    .map(|o| o.z2(curve.value(o.trial, o.channel, x)))
                    .sum::<f64>()
            })
            .fold(f64::INFINITY, f64::min);
        let mut added = 0;
        for j in 0..curve.x.len().saturating_sub(1) {
            if curve.x.len() + added >= CURVE_MAX_NODES {
                break;
            }
            let (a, b) = (curve.x[j], curve.x[j + 1]);
            if b - a < 2.0 * min_gap {
                continue;
            }
            if bends(curve, obs, a, b) || may_hold_better(curve, obs, a, b, best) {
                wanted.push((k, 0.5 * (a + b)));
                added += 1;
            }
        }
    }
    wanted
}

/// A segment bends more than the data resolve near a measurement, or one end falls and the
/// other walks.
fn bends(curve: &Curve, obs: &[Observation], a: f64, b: f64) -> bool {
    let m = 0.5 * (a + b);
    obs.iter().any(|o| {
        let sd = o.total_sd();
        let (ya, yb) = (
            curve.value(o.trial, o.channel, a),
            curve.value(o.trial, o.channel, b),
        );
        match (ya.is_finite(), yb.is_finite()) {
            (true, true) => {
                let near =
                    ((ya - o.value) / sd).abs().min(((yb - o.value) / sd).abs()) < CURVE_REACH_Z;
                let bend = curve.value(o.trial, o.channel, m) - 0.5 * (ya + yb);
                near && (bend / sd).abs() > CURVE_MAX_BEND_Z
            }
            (false, false) => false,
            _ => true,
        }
    })
}

/// A segment may hold a better fit than the curve's best node (χ² `best`): if every
/// prediction moved monotonically between its ends, the least χ² inside would be at least
/// Σ (distance of each measurement from the interval its two ends span / sd)²; refine where
/// that bound is below the best node's by more than the χ²'s own sd, √(2n) (a knife-edge
/// gait's narrow minimum between two nodes, which the cubic cannot see).
fn may_hold_better(curve: &Curve, obs: &[Observation], a: f64, b: f64, best: f64) -> bool {
    let bound: f64 = obs
        .iter()
        .map(|o| {
            let (ya, yb) = (
                curve.value(o.trial, o.channel, a),
                curve.value(o.trial, o.channel, b),
            );
            if !(ya.is_finite() && yb.is_finite()) {
                return 0.0;
            }
            let (lo, hi) = (ya.min(yb), ya.max(yb));
            let d = if o.value < lo {
                lo - o.value
            } else if o.value > hi {
                o.value - hi
            } else {
                0.0
            };
            (d / o.total_sd()).powi(2)
        })
        .sum();
    bound < best - (2.0 * obs.len() as f64).sqrt()
}

/// The residuals of every metric observation: nominal, and after (the walks of the named or
/// most probable explanation).
fn residuals(
    set: &TrialSet,
    conditions: &[Condition],
    obs: &[Observation],
    nominal: &[Walked],
    after: Option<&[Walked]>,
) -> Result<Vec<Residual>, GapError> {
    let mut out = Vec::new();
    for o in obs {
        let Some(metric) = o.as_metric() else {
            continue;
        };
        let c = &conditions[o.trial];
        let t = &set.trials[o.trial];
        let sd = o.total_sd();
        let sim = nominal[o.trial].channel(o.channel);
        let later = after.map(|a| a[o.trial].channel(o.channel));
        out.push(Residual {
            trial: o.trial,
            label: t.name(),
            design: t.design.clone(),
            leg_length_m: c.leg_length_m,
            frequency_hz: c.drive_frequency_hz()?,
            metric,
            measured: o.value,
            sd,
            sd_assumed: o.sd_assumed,
            simulated: sim.is_finite().then_some(sim),
            z: sim.is_finite().then(|| (sim - o.value) / sd),
            relative: (sim.is_finite() && o.value != 0.0).then(|| (sim - o.value) / o.value.abs()),
            simulated_after: later.filter(|v| v.is_finite()),
            z_after: later.filter(|v| v.is_finite()).map(|v| (v - o.value) / sd),
        });
    }
    Ok(out)
}
