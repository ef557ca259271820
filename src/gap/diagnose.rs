//! The diagnosis: where the nominal simulation misses the trials, and which of three kinds
//! of explanation the trials support — **nominal parameters off** (the design's declared
//! uncertain values, calibrated), **an effect missing** (the library's, tested with the
//! parameters free as a nuisance), **both** — or that they support none ("unexplained").
//!
//! Method. Every observation (trial × metric) gives z = (simulated − measured)/sd; the gap
//! is the RMS of z. Every knob (uncertain parameter, effect magnitude) is walked on a grid
//! of its plausible range on every condition; the surrogate adds the knobs' changes
//! ([`super::surrogate`]). Forward selection ([`super::select`]) then adds knobs one at a
//! time under the call rules; every model it keeps is confirmed by real walks at its fitted
//! point. The answer names the chain's knobs with profile intervals, checks the final
//! residuals and says where any rest lies.

use serde::Serialize;

use super::cache::SimCache;
use super::curve::Curve;
use super::error::GapError;
use super::fit::{Fit, FitContext, ProfileInterval, dispersion, groupings, lr_p_value};
use super::identify::{Identifiability, identifiability};
use super::knob::{Knob, KnobKind, Knobs, ModelSetting};
use super::library::EffectLibrary;
use super::locate::{MetricGap, Residual, metric_gaps, summarize};
use super::problem::Observation;
use super::select::{SelectOptions, Step, gap_of, select, within_noise};
use super::simulate::{Condition, SimMetrics, resolve};
use super::surrogate::Surrogate;
use super::trials::{Metric, TrialSet};
use crate::progress::{Observer, Stopwatch};
use crate::regression::dist::chi2_upper_p;

#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// Candidate effects (empty: the whole library).
    pub effects: Vec<String>,
    /// Walks per knob over its plausible range.
    pub grid_points: usize,
    /// Relative sd assumed for a measurement that states none.
    pub default_relative_sd: f64,
    /// Family-wise false-alarm rate of each step's tests.
    pub alpha: f64,
    /// Calibrate the designs' `[[uncertain]]` parameters (off: the nominal model is taken
    /// as right, only effects are candidates).
    pub calibrate: bool,
    /// Compute the identifiability thresholds (a few seconds; the benchmark's cases skip it).
    pub identifiability: bool,
    /// Fit the competing explanations side by side and the recalibration table (walks; the
    /// benchmark's cases skip it: the answer does not depend on it).
    pub explanations: bool,
    pub select: SelectOptions,
    /// Audit what the answer names against the designs' undeclared numbers
    /// ([`super::audit`]): a named knob that one of them, in its place, fits as well is not
    /// named. On by default: on truths held out from every rule it turned both confident
    /// stand-ins into "not told apart" groups holding the truth (reports/gap-benchmark.md,
    /// eleventh session); the benchmark runs it only when asked (its figures are without it).
    pub audit_undeclared: bool,
    /// The audit's declared partners: an undeclared number that, in a named knob's place,
    /// explains part of the gap is walked again beside this many declared knobs (the
    /// surrogate's best), for a truth of two numbers, one undeclared ([`super::audit`]);
    /// 0: one number at a time.
    pub audit_partners: usize,
    /// Count the model's own trial-to-trial spread as an error beside each measurement's:
    /// the nominal walked from this many perturbed starts ([`model_spread`]); 0: off.
    pub model_spread_seeds: u64,
    /// Trials of the same robot without the change asked about: the diagnosis is then of
    /// the change, with the model's discrepancy at each condition taken from them
    /// ([`super::reference`]).
    pub reference: Option<TrialSet>,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            effects: Vec::new(),
            grid_points: 9,
            default_relative_sd: 0.10,
            alpha: 0.001,
            calibrate: true,
            identifiability: true,
            explanations: true,
            select: SelectOptions::default(),
            audit_undeclared: true,
            audit_partners: super::audit::PARTNERS,
            model_spread_seeds: 0,
            reference: None,
        }
    }
}

/// The kind of answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AnswerKind {
    /// The nominal model fits within noise; nothing is called.
    WithinNoise,
    /// Uncertain parameters of the design, recalibrated, explain the gap (within noise).
    ParametersOff,
    /// An effect (or effects) of the library explains the gap (within noise).
    EffectMissing,
    /// Both parameters and effects are needed (within noise).
    Both,
    /// Knobs shrink the gap but the rest stays beyond noise: they are reported as leads,
    /// nothing is named.
    PartlyExplained,
    /// A real gap that no knob explains under the call rules.
    Unexplained,
    /// Knobs explain the gap, but these trials cannot tell which (each step had a rival
    /// within the identification distance): nothing is named.
    Ambiguous,
}

/// A knob the answer names, with its fitted value and interval (SI, the design at 1×).
#[derive(Clone, Debug, Serialize)]
pub struct Named {
    pub knob: String,
    pub kind: KnobKind,
    pub value: f64,
    /// 95 % profile interval (scaled by the over-dispersion).
    pub interval: [f64; 2],
    /// The interval reaches an end of the plausible range (open there).
    pub interval_open: bool,
    /// Parameters: the design file's value, and the change in % of it.
    pub nominal: Option<f64>,
    pub change_pct: Option<f64>,
    pub unit: String,
    /// Other knobs the trials cannot tell from this one.
    pub not_separable_from: Vec<String>,
    /// False for a fore–aft mirror-odd parameter of a design that walks either way, fitted
    /// only where the start sets the direction ([`sign_identified`]): `value` and `interval`
    /// are then magnitudes, the sign open.
    pub sign_identified: bool,
}

/// Whether trials at `conditions` identify the sign of `knob`. Not for a parameter that
/// changes sign under the fore–aft mirror ([`crate::sim::MIRROR_ODD_PATHS`]) of a design that
/// walks either way, when every condition where the parameter acts leaves the direction to
/// the start ([`Condition::direction_free`]; a condition's own slope replaces the design's):
/// the design with −v walks the mirror image of the gait the walker's other start (the
/// drive half a period later) walks with v, its speed and attitude amplitudes the same, and
/// which start the robot took is not a prediction of such a model. Measured on
/// mugatu-ref-sap: on a 1.5° slope the two starts walk 0.034 and 0.075 m/s (both uphill),
/// and the second is the exact mirror of the first start on −1.5°
/// (`the_sign_of_a_mirror_odd_parameter_is_not_identified_where_the_start_sets_the_direction`).
pub fn sign_identified(knob: &Knob, conditions: &[Condition]) -> bool {
    if knob.kind != KnobKind::Parameter
        || knob.log
        || !crate::sim::MIRROR_ODD_PATHS.contains(&knob.name.as_str())
    {
        return true;
    }
    let mut acting = conditions
        .iter()
        .filter(|c| c.design.name == knob.design)
        .filter(|c| !(knob.name == "ground.slope_deg" && c.slope_deg.is_some()))
        .peekable();
    acting.peek().is_none() || !acting.all(|c| c.direction_free())
}

/// A fitted value and its interval as the answer states them: signed, or as magnitudes when
/// [`sign_identified`] says the sign is open.
fn as_stated(signed: bool, value: f64, [lo, hi]: [f64; 2]) -> (f64, [f64; 2]) {
    if signed {
        (value, [lo, hi])
    } else {
        (value.abs(), magnitude_interval(lo, hi))
    }
}

/// A signed interval's magnitudes: |x| over [lo, hi].
fn magnitude_interval(lo: f64, hi: f64) -> [f64; 2] {
    let top = lo.abs().max(hi.abs());
    if lo <= 0.0 && hi >= 0.0 {
        [0.0, top]
    } else {
        [lo.abs().min(hi.abs()), top]
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Answer {
    pub kind: AnswerKind,
    pub parameters: Vec<Named>,
    pub effects: Vec<Named>,
    /// The chain's knobs when the chain leaves the rest beyond noise: leads, not findings
    /// (`parameters` and `effects` are then empty). Not named.
    pub leads: Vec<Named>,
    /// Steps that explain part of the gap but could be any of several knobs: each group
    /// lists the step's knob and its rivals. Not named.
    pub ambiguous: Vec<Vec<String>>,
    /// Where the rest lies when the final model is still beyond noise.
    pub rest: Option<String>,
    pub statement: String,
}

/// One competing explanation, fitted and confirmed with walks.
#[derive(Clone, Debug, Serialize)]
pub struct Explanation {
    /// "nominal", "parameters off (recalibrated)", "effect (parameters nominal)",
    /// "effect + recalibrated parameters", "chain (the answer)".
    pub model: String,
    pub knobs: Vec<(String, f64)>,
    pub free: usize,
    pub chi2: f64,
    /// Held-out gap (RMS z, leave one condition out).
    pub gap_held_out: f64,
    pub shrink_pct: f64,
    /// Likelihood-ratio test against the nominal (df = free knobs, over-dispersion scaled).
    pub p_vs_nominal: Option<f64>,
    pub within_noise: bool,
}

/// One uncertain parameter in the best recalibration: how far it moves and how well these
/// trials pin it down.
#[derive(Clone, Debug, Serialize)]
pub struct Calibrated {
    pub parameter: String,
    pub nominal: f64,
    pub value: f64,
    pub interval: [f64; 2],
    pub range: [f64; 2],
    /// Move from the file's value in prior sds (None: uniform prior).
    pub move_in_sd: Option<f64>,
    /// Interval width / range width: near 1, the trials do not constrain it.
    pub width_of_range: f64,
    pub why: String,
    /// As [`Named::sign_identified`]: when false, `value`, `interval` and `move_in_sd` are
    /// magnitudes.
    pub sign_identified: bool,
}

/// A single knob's fit from the nominal (the "which knob alone" table).
#[derive(Clone, Debug, Serialize)]
pub struct SingleFit {
    pub knob: String,
    pub kind: KnobKind,
    pub value: f64,
    pub unit: String,
    pub gap_held_out: f64,
    pub shrink_pct: f64,
    pub lr: f64,
    pub p_value: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub trials: String,
    pub n_trials: usize,
    pub n_observations: usize,
    pub gap_before: f64,
    pub chi2_before: f64,
    pub p_value_before: f64,
    /// The nominal model's misfit is consistent with measurement noise.
    pub within_noise: bool,
    pub summary: String,
    #[serde(rename = "where")]
    pub where_: Vec<MetricGap>,
    pub answer: Answer,
    /// The forward selection's chain.
    pub chain: Vec<Step>,
    pub explanations: Vec<Explanation>,
    /// The best recalibration of every uncertain parameter (empty without calibration).
    pub calibration: Vec<Calibrated>,
    /// Every knob alone, from the nominal, on the surrogate.
    pub single: Vec<SingleFit>,
    pub identifiability: Vec<Identifiability>,
    /// Effects left out because the design calibrates their quantity.
    pub aliased: Vec<(String, String)>,
    pub notes: Vec<String>,
    pub residuals: Vec<Residual>,
    pub walks_evaluated: usize,
}

/// Wall-clock breakdown (not part of the deterministic result).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timing {
    pub grid_s: f64,
    pub select_s: f64,
    pub report_s: f64,
    pub walks: usize,
}

/// Trials whose `trajectory` file is given get the metrics they lack measured from it, by
/// the code that measures the simulator's walks (`sim::report_from_trajectory`); at a
/// condition whose direction the start sets ([`Condition::direction_free`]) the measured
/// velocity becomes a speed |v|, as the simulated one is.
pub(super) fn fill_from_trajectories(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
) -> Result<TrialSet, GapError> {
    let mut out = fill_metrics_from_trajectories(set, conditions, lib)?;
    for (t, c) in out.trials.iter_mut().zip(conditions) {
        if c.direction_free()
            && let Some(v) = &mut t.measured[Metric::VelocityMps.index()]
        {
            v.value = v.value.abs();
        }
    }
    Ok(out)
}

fn fill_metrics_from_trajectories(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
) -> Result<TrialSet, GapError> {
    let mut out = set.clone();
    for (t, c) in out.trials.iter_mut().zip(conditions) {
        let Some(rel) = &t.trajectory else { continue };
        let path = set.base_dir.join(rel);
        let at = |message: String| GapError::Trials {
            path: set.origin.clone(),
            line: t.line,
            column: 0,
            message,
        };
        // A robot's log (time, hip angle, attitude) has no hip position or contact forces:
        // its summaries come from the row; its cycles serve `survey gap separate`.
        if !super::waveform::is_full_trajectory(&path)? {
            continue;
        }
        let samples = crate::sim::read_trajectory_csv(&path)
            .map_err(|e| at(format!("trajectory {}: {e}", path.display())))?;
        let d = c.design_with(lib, &super::knob::ModelSetting::nominal())?;
        let report =
            crate::sim::report_from_trajectory(&d, &crate::sim::WalkOptions::default(), &samples)
                .map_err(|e| at(format!("trajectory {}: {e}", path.display())))?;
        for m in Metric::SIMULATED {
            let v = m.of_report(&report);
            if t.measured(m).is_none() && v.is_finite() {
                t.measured[m.index()] = Some(super::trials::Measurement { value: v, sd: None });
            }
        }
    }
    Ok(out)
}

/// Observations of the trials: every measured metric a walk simulates.
pub fn observations(set: &TrialSet, default_relative_sd: f64) -> (Vec<Observation>, Vec<String>) {
    let mut obs = Vec::new();
    let mut notes = Vec::new();
    let mut min_torque = 0;
    for (i, t) in set.trials.iter().enumerate() {
        for m in Metric::ALL {
            let Some(meas) = t.measured(m) else { continue };
            if m == Metric::MinTorqueNm {
                min_torque += 1;
                continue;
            }
            let (sd, assumed) = meas.sd_or(default_relative_sd);
            obs.push(Observation {
                trial: i,
                metric: m,
                value: meas.value,
                sd,
                sd_assumed: assumed,
            });
        }
    }
    if min_torque > 0 {
        notes.push(format!(
            "{min_torque} min_torque_nm measurement(s) not used: the minimum walking torque needs \
             a bisection of walks per candidate magnitude (compare them with `survey sim min-torque`)"
        ));
    }
    (obs, notes)
}

/// The trials with the metrics their trajectories give filled in, their observations and
/// notes; an error when the default sd is not a positive number or nothing measured is
/// something the simulator computes.
pub fn measured(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
    default_relative_sd: f64,
) -> Result<(TrialSet, Vec<Observation>, Vec<String>), GapError> {
    if !(default_relative_sd > 0.0 && default_relative_sd.is_finite()) {
        return Err(GapError::Invalid(
            "the default relative sd must be finite and > 0".into(),
        ));
    }
    let filled = fill_from_trajectories(set, conditions, lib)?;
    let (obs, notes) = observations(&filled, default_relative_sd);
    if obs.is_empty() {
        return Err(GapError::File {
            path: filled.origin.clone(),
            message: "no trial has a measured metric the simulator computes (velocity_mps, \
                      step_frequency_hz, roll/pitch/yaw_pp_deg, peak_torque_nm, cot)"
                .into(),
        });
    }
    Ok((filled, obs, notes))
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

fn check_options(opts: &DiagnoseOptions) -> Result<(), GapError> {
    if !(opts.alpha > 0.0 && opts.alpha < 1.0) {
        return Err(GapError::Invalid("alpha must be in (0, 1)".into()));
    }
    if !(2..=64).contains(&opts.grid_points) {
        return Err(GapError::Invalid("grid points must be in [2, 64]".into()));
    }
    Ok(())
}

/// Rounds of adaptive refinement of the knobs' curves.
const CURVE_ROUNDS: usize = 3;
/// A curve segment is split while, at its midpoint, the monotone cubic and the straight line
/// between its ends differ by more than this many sds for some observation (the curve bends
/// there more than the data's resolution), or one end falls and the other walks.
const CURVE_MAX_BEND_Z: f64 = 1.0;
/// Only where the curve is within this many sds of the measured value (at either end of
/// the segment) does its shape matter for the fits.
const CURVE_REACH_Z: f64 = 10.0;
/// Most nodes a curve gets.
const CURVE_MAX_NODES: usize = 21;

/// The surrogate: the nominal walks and every knob's curve — `grid_points` walks over the
/// knob's range, then midpoints added where a segment bends more than the data resolve
/// ([`CURVE_MAX_BEND_Z`]) or crosses a fall, all walks of a round in one parallel batch.
pub fn build_surrogate(
    conditions: &[Condition],
    lib: &EffectLibrary,
    knobs: &Knobs,
    obs: &[Observation],
    grid_points: usize,
    cache: &SimCache,
    progress: &dyn Observer,
) -> Result<Surrogate, GapError> {
    let nominal = cache.get(
        conditions,
        lib,
        &super::knob::ModelSetting::nominal(),
        progress,
    )?;
    let all: Vec<usize> = (0..knobs.len()).collect();
    let curves = build_curves(
        conditions,
        lib,
        knobs,
        &all,
        &nominal,
        obs,
        grid_points,
        cache,
        progress,
    )?;
    Ok(Surrogate { nominal, curves })
}

/// The curves of the knobs `which` (of `knobs`), in that order: `grid_points` walks over each
/// knob's range, then midpoints where a segment bends more than the data resolve; `nominal`:
/// the nominal model's walks (a nominal node inside the range is that walk).
#[allow(clippy::too_many_arguments)]
pub fn build_curves(
    conditions: &[Condition],
    lib: &EffectLibrary,
    knobs: &Knobs,
    which: &[usize],
    nominal: &[super::simulate::SimMetrics],
    obs: &[Observation],
    grid_points: usize,
    cache: &SimCache,
    progress: &dyn Observer,
) -> Result<Vec<Curve>, GapError> {
    let setting_at = |k: usize, x: f64| {
        let mut point = knobs.nominal_point();
        point[k] = Some(x);
        knobs.setting(lib, &point)
    };
    let mut settings = Vec::new();
    let mut nodes_of = Vec::new();
    for &k in which {
        let nodes = knobs.list[k].nodes(grid_points);
        settings.extend(nodes.iter().map(|x| setting_at(k, *x)));
        nodes_of.push(nodes);
    }
    let sims = cache.get_many(conditions, lib, &settings, progress)?;
    let mut it = sims.into_iter();
    let mut curves = Vec::new();
    for (&k, nodes) in which.iter().zip(nodes_of) {
        let s: Vec<_> = (0..nodes.len()).filter_map(|_| it.next()).collect();
        let mut curve = Curve::new(nodes, s);
        // A nominal inside the range (a parameter's file value, the design's own μ) is a
        // walk already made: the nominal one.
        if let Some(x) = knobs.list[k].nominal {
            curve.insert(x, nominal);
        }
        curves.push(curve);
    }
    for _ in 0..CURVE_ROUNDS {
        // (position in `which`, coordinate)
        let mut wanted: Vec<(usize, f64)> = Vec::new();
        for (j_knob, (&k, curve)) in which.iter().zip(&curves).enumerate() {
            let knob = &knobs.list[k];
            let min_gap = (knob.hi - knob.lo) / 64.0;
            for j in 0..curve.x.len().saturating_sub(1) {
                if curve.x.len() + wanted.iter().filter(|w| w.0 == j_knob).count()
                    >= CURVE_MAX_NODES
                {
                    break;
                }
                let (a, b) = (curve.x[j], curve.x[j + 1]);
                if b - a < 2.0 * min_gap {
                    continue;
                }
                let m = 0.5 * (a + b);
                let steep = obs.iter().any(|o| {
                    let (ya, yb) = (
                        curve.value(o.trial, o.metric, a),
                        curve.value(o.trial, o.metric, b),
                    );
                    match (ya.is_finite(), yb.is_finite()) {
                        (true, true) => {
                            let near = ((ya - o.value) / o.sd)
                                .abs()
                                .min(((yb - o.value) / o.sd).abs())
                                < CURVE_REACH_Z;
                            let bend = curve.value(o.trial, o.metric, m) - 0.5 * (ya + yb);
                            near && (bend / o.sd).abs() > CURVE_MAX_BEND_Z
                        }
                        (false, false) => false,
                        _ => true,
                    }
                });
                if steep {
                    wanted.push((j_knob, 0.5 * (a + b)));
                }
            }
        }
        if wanted.is_empty() {
            break;
        }
        progress.stage("refining the knobs' curves where the gait changes fast");
        let settings: Vec<_> = wanted
            .iter()
            .map(|(j, x)| setting_at(which[*j], *x))
            .collect();
        let sims = cache.get_many(conditions, lib, &settings, progress)?;
        for ((j, x), s) in wanted.into_iter().zip(sims) {
            curves[j].insert(x, &s);
        }
    }
    Ok(curves)
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
    let candidates = lib.subset(&opts.effects)?;
    let carried = match &opts.reference {
        Some(reference) => {
            let reference_conditions = resolve(reference)?;
            let set = fill_from_trajectories(set, conditions, lib)?;
            let reference = fill_from_trajectories(reference, &reference_conditions, lib)?;
            progress.stage("the nominal model at every condition, for the reference");
            let nominal = cache.get(conditions, lib, &ModelSetting::nominal(), progress)?;
            Some(super::reference::carry(
                &set,
                conditions,
                &reference,
                &reference_conditions,
                &nominal,
                opts.default_relative_sd,
            )?)
        }
        None => None,
    };
    let set = carried.as_ref().map_or(set, |c| &c.set);
    let (filled, mut obs, mut notes) = measured(set, conditions, lib, opts.default_relative_sd)?;
    if let Some(c) = &carried {
        notes.extend(c.notes.iter().cloned());
    }
    let set = &filled;
    if opts.model_spread_seeds > 0 {
        progress.stage("the model's spread over perturbed starts");
        let spread = model_spread(conditions, lib, opts.model_spread_seeds)?;
        notes.push(spread_note(&obs, &spread, set, opts.model_spread_seeds));
        for o in &mut obs {
            o.sd = o.sd.hypot(spread[o.trial][o.metric.index()]);
        }
    }
    let designs = designs_of(conditions);
    let knobs = Knobs::build(&designs, &candidates, opts.calibrate).map_err(|e| GapError::Sim {
        origin: set.origin.clone(),
        source: e,
    })?;
    knob_notes(&knobs, opts.calibrate, &mut notes);
    let walks0 = cache.walks();
    let mut timing = Timing::default();
    let n = obs.len();

    let grid = Stopwatch::start();
    progress.stage("walking every knob over its range");
    let surrogate = build_surrogate(
        conditions,
        lib,
        &knobs,
        &obs,
        opts.grid_points,
        cache,
        progress,
    )?;
    timing.grid_s = grid.seconds();
    let surrogate = std::sync::RwLock::new(surrogate);
    let ctx = FitContext {
        conditions,
        lib,
        cache,
        knobs: &knobs,
        surrogate: &surrogate,
        obs: &obs,
        progress,
    };
    let nominal = ctx.nominal()?;
    let chi2_before = nominal.chi2_data;
    let gap_before = (chi2_before / n as f64).sqrt();
    let p_value_before = chi2_upper_p(chi2_before, n as f64).unwrap_or(1.0);
    let nominal_within_noise = p_value_before >= opts.alpha;

    let selecting = Stopwatch::start();
    let sel_opts = SelectOptions {
        alpha: opts.alpha,
        always_recalibrate: opts.explanations,
        ..opts.select.clone()
    };
    let groups = groupings(conditions);
    let labels: Vec<String> = set.trials.iter().map(|t| t.name()).collect();
    let selection = select(&ctx, &sel_opts, &nominal, &groups, &labels)?;
    timing.select_s = selecting.seconds();

    let reporting = Stopwatch::start();
    progress.stage("intervals and competing explanations");
    let single = single_fits(&ctx, &nominal, &selection.singles);
    let final_fit = if selection.final_fit.active.is_empty() {
        selection.final_fit.clone()
    } else {
        progress.stage("polishing the answer with walks");
        ctx.polish(&selection.final_fit)?
    };
    let (explanations, calibration) = if opts.explanations {
        (
            explanations(
                &ctx,
                &nominal,
                &selection,
                &final_fit,
                &single,
                opts.alpha,
                opts.select.walked_lm,
            )?,
            match &selection.recalibration {
                Some(r) => calibrated(&ctx, r),
                None => Vec::new(),
            },
        )
    } else {
        (Vec::new(), Vec::new())
    };
    let mut steps = selection.steps.clone();
    if opts.audit_undeclared {
        super::audit::audit_undeclared(
            &ctx,
            &designs,
            &final_fit,
            &mut steps,
            super::audit::AuditSettings {
                alpha: opts.alpha,
                grid_points: opts.grid_points,
                partners: opts.audit_partners,
            },
            &mut notes,
        )?;
    }
    if opts.reference.is_some() {
        super::reference::rivals_within_noise(
            &ctx,
            &selection.singles,
            &mut steps,
            opts.alpha,
            &mut notes,
        )?;
    }
    let final_fit = &final_fit;
    let answer = answer(
        &ctx,
        &steps,
        final_fit,
        nominal_within_noise,
        opts.alpha,
        set,
    )?;
    notes.extend(selection.notes.iter().cloned());
    notes.dedup();
    let residuals = residuals(set, conditions, &obs, &nominal, final_fit)?;
    let where_ = metric_gaps(&residuals, opts.alpha);
    let summary = summarize(&where_, nominal_within_noise);
    let identifiability = if opts.identifiability {
        effect_thresholds(&ctx, opts.alpha)?
    } else {
        Vec::new()
    };
    if obs.iter().any(|o| o.sd_assumed) {
        notes.push(format!(
            "{} of {} measurements state no sd: {} % of the value assumed",
            obs.iter().filter(|o| o.sd_assumed).count(),
            obs.len(),
            opts.default_relative_sd * 100.0
        ));
    }
    timing.report_s = reporting.seconds();
    let walks = cache.walks() - walks0;
    timing.walks = walks;
    Ok((
        Diagnosis {
            trials: set.origin.clone(),
            n_trials: set.trials.len(),
            n_observations: n,
            gap_before,
            chi2_before,
            p_value_before,
            within_noise: nominal_within_noise,
            summary,
            where_,
            answer,
            chain: steps,
            explanations,
            calibration,
            single,
            identifiability,
            aliased: knobs.aliased.clone(),
            notes,
            residuals,
            walks_evaluated: walks,
        },
        timing,
    ))
}

/// Notes on the knobs: no uncertain parameter to calibrate, effects aliased to a declared
/// parameter.
fn knob_notes(knobs: &Knobs, calibrate: bool, notes: &mut Vec<String>) {
    if calibrate && !knobs.list.iter().any(|k| k.kind == KnobKind::Parameter) {
        notes.push(
            "no design of these trials declares [[uncertain]] parameters: the nominal model is \
             taken as right (only effects are candidates)"
                .into(),
        );
    }
    for (e, p) in &knobs.aliased {
        notes.push(format!(
            "{e} is not tested as an effect: the design declares {p} uncertain, and calibrating \
             it is the same physics"
        ));
    }
}

/// Every effect's identification threshold, at `alpha` shared over the effects
/// (Bonferroni).
fn effect_thresholds(ctx: &FitContext<'_>, alpha: f64) -> Result<Vec<Identifiability>, GapError> {
    let k = ctx
        .knobs
        .list
        .iter()
        .filter(|k| k.kind == KnobKind::Effect)
        .count()
        .max(1) as f64;
    ctx.progress.stage("identifiability thresholds");
    identifiability(ctx, alpha / k, &|name: &str| match ctx.lib.get(name) {
        Ok(def) => (def.magnitude().name.clone(), def.magnitude().unit.clone()),
        Err(_) => (String::new(), String::new()),
    })
}

/// Every knob alone, fitted from the nominal on the surrogate, held-out gap and LR test.
fn single_fits(ctx: &FitContext<'_>, nominal: &Fit, singles: &[(usize, Fit)]) -> Vec<SingleFit> {
    let n = ctx.n();
    let gap0 = gap_of(nominal, n);
    let mut out: Vec<SingleFit> = singles
        .iter()
        .map(|(k, f)| {
            let knob = &ctx.knobs.list[*k];
            let lr = nominal.chi2 - f.chi2;
            let phi = dispersion(f.chi2_data, n, 1);
            let gap = gap_of(f, n);
            SingleFit {
                knob: knob.label(),
                kind: knob.kind,
                value: f.point[*k].map(|x| knob.si(x)).unwrap_or(f64::NAN),
                unit: knob.unit.clone(),
                gap_held_out: gap,
                shrink_pct: 100.0 * (1.0 - gap / gap0),
                lr,
                p_value: lr_p_value(lr, 1, phi, n.saturating_sub(1)),
            }
        })
        .collect();
    out.sort_by(|a, b| a.gap_held_out.total_cmp(&b.gap_held_out));
    out
}

fn explanation(
    ctx: &FitContext<'_>,
    model: &str,
    fit: &Fit,
    nominal: &Fit,
    alpha: f64,
) -> Explanation {
    let n = ctx.n();
    let gap0 = gap_of(nominal, n);
    let gap = gap_of(fit, n);
    let k = fit.k();
    let lr = nominal.chi2 - fit.chi2;
    let phi = dispersion(fit.chi2_data, n, k);
    Explanation {
        model: model.into(),
        knobs: fit
            .active
            .iter()
            .filter_map(|i| {
                fit.point[*i].map(|x| (ctx.knobs.list[*i].label(), ctx.knobs.list[*i].si(x)))
            })
            .collect(),
        free: k,
        chi2: fit.chi2,
        gap_held_out: gap,
        shrink_pct: 100.0 * (1.0 - gap / gap0),
        p_vs_nominal: (k > 0).then(|| lr_p_value(lr, k, phi, n.saturating_sub(k))),
        within_noise: within_noise(fit, n, alpha),
    }
}

/// The competing explanations side by side, each confirmed with walks: the nominal, the
/// recalibrated parameters, the best effect alone, the best effect with the recalibration,
/// the chain's model.
fn explanations(
    ctx: &FitContext<'_>,
    nominal: &Fit,
    selection: &super::select::Selection,
    final_fit: &Fit,
    single: &[SingleFit],
    alpha: f64,
    walked_lm: bool,
) -> Result<Vec<Explanation>, GapError> {
    let mut out = vec![explanation(ctx, "nominal", nominal, nominal, alpha)];
    if let Some(r) = &selection.recalibration {
        out.push(explanation(
            ctx,
            "parameters off (every uncertain parameter recalibrated)",
            r,
            nominal,
            alpha,
        ));
    }
    let best_effect = single
        .iter()
        .find(|s| s.kind == KnobKind::Effect)
        .and_then(|s| ctx.knobs.index_of(&s.knob));
    if let Some(e) = best_effect {
        let starts = ctx.starts_adding(nominal, e);
        let f = ctx.with_held_out(ctx.fit_walked(&[e], &starts, None, Some(nominal))?);
        let alone = f.point.clone();
        out.push(explanation(
            ctx,
            &format!(
                "effect alone ({}; parameters nominal)",
                ctx.knobs.list[e].label()
            ),
            &f,
            nominal,
            alpha,
        ));
        if let Some(r) = &selection.recalibration {
            let mut active = r.active.clone();
            active.push(e);
            let starts = ctx.starts_adding(r, e);
            let mut f = ctx.fit_walked(&active, &starts, None, Some(r))?;
            // It nests the effect alone: walked from there too, it never fits worse.
            f = ctx.better_of(f, &alone)?;
            // Fitted as the chain's test fits it, so the table and the call agree.
            if walked_lm {
                f = ctx.levenberg_marquardt(f)?;
            }
            let f = ctx.with_held_out(f);
            out.push(explanation(
                ctx,
                &format!(
                    "effect with the parameters recalibrated ({} + every uncertain parameter)",
                    ctx.knobs.list[e].label()
                ),
                &f,
                nominal,
                alpha,
            ));
        }
    }
    if !selection.steps.is_empty() {
        out.push(explanation(
            ctx,
            "the chain (the answer)",
            final_fit,
            nominal,
            alpha,
        ));
    }
    Ok(out)
}

/// The recalibration's parameters: value, profile interval, move in prior sds, and how much
/// of its range the interval still spans.
fn calibrated(ctx: &FitContext<'_>, r: &Fit) -> Vec<Calibrated> {
    let n = ctx.n();
    let phi = dispersion(r.chi2_data, n, r.k());
    let phi = if phi.is_finite() { phi } else { 1.0 };
    r.active
        .iter()
        .map(|&k| {
            let knob = &ctx.knobs.list[k];
            let x = r.point[k].unwrap_or(knob.lo);
            let iv = ctx.profile(r, k, phi).unwrap_or(ProfileInterval {
                lo: knob.lo,
                hi: knob.hi,
                open_below: true,
                open_above: true,
            });
            let nominal = knob.nominal.map(|x| knob.value(x)).unwrap_or(f64::NAN);
            let signed = sign_identified(knob, ctx.conditions);
            let (value, interval) = as_stated(
                signed,
                knob.value(x),
                [knob.value(iv.lo), knob.value(iv.hi)],
            );
            let moved = knob.prior.map(|(m, sd)| (knob.value(x) - m) / sd);
            Calibrated {
                parameter: knob.label(),
                nominal,
                value,
                interval,
                range: [knob.value(knob.lo), knob.value(knob.hi)],
                move_in_sd: if signed { moved } else { moved.map(f64::abs) },
                width_of_range: (iv.hi - iv.lo) / (knob.hi - knob.lo),
                why: knob.why.clone(),
                sign_identified: signed,
            }
        })
        .collect()
}

/// The model's own trial-to-trial spread: the sd of each condition's metrics over the
/// nominal's walk and `seeds` walks from starts perturbed as the design's `[initial]`
/// seed table says. A stable limit cycle forgets its start (sd ≈ 0); an irregular gait does
/// not, and a trial of a few cycles then samples its variability, which a fit cannot remove —
/// a Zippy trial's answer flipped under a relative change of 2e-16 in an undeclared
/// number (reports/gap-benchmark-zippy/gap-benchmark.md). Spread per metric:
/// [`super::simulate::metric_spread`].
pub fn model_spread(
    conditions: &[Condition],
    lib: &EffectLibrary,
    seeds: u64,
) -> Result<Vec<[f64; 8]>, GapError> {
    use rayon::prelude::*;
    let nominal = ModelSetting::nominal();
    let jobs: Vec<(usize, Option<u64>)> = (0..conditions.len())
        .flat_map(|i| std::iter::once((i, None)).chain((1..=seeds).map(move |s| (i, Some(s)))))
        .collect();
    let runs: Vec<SimMetrics> = jobs
        .par_iter()
        .map(|&(i, seed)| conditions[i].simulate_from(lib, &nominal, seed))
        .collect::<Result<_, _>>()?;
    Ok(runs
        .chunks(1 + seeds as usize)
        .map(super::simulate::metric_spread)
        .collect())
}

/// What the model's spread did to the noise: the largest ratio of spread to measurement sd.
fn spread_note(obs: &[Observation], spread: &[[f64; 8]], set: &TrialSet, seeds: u64) -> String {
    let worst = obs
        .iter()
        .map(|o| (spread[o.trial][o.metric.index()] / o.sd, o))
        .filter(|(r, _)| r.is_finite())
        .max_by(|a, b| a.0.total_cmp(&b.0));
    let inflated = obs
        .iter()
        .filter(|o| spread[o.trial][o.metric.index()] > 0.5 * o.sd)
        .count();
    match worst {
        Some((r, o)) => format!(
            "model spread ({seeds} perturbed starts per condition) counted beside the noise: \
             {inflated} of {} measurements' sds grow by more than 12 %; the largest spread is \
             {r:.2}× the measurement's sd ({} at {})",
            obs.len(),
            o.metric.words(),
            set.trials[o.trial].name()
        ),
        None => format!("model spread ({seeds} perturbed starts per condition): none"),
    }
}

/// The answer: the chain's knobs with their intervals, the final model's residual check,
/// and the kind.
fn answer(
    ctx: &FitContext<'_>,
    steps: &[Step],
    final_fit: &Fit,
    nominal_within_noise: bool,
    alpha: f64,
    set: &TrialSet,
) -> Result<Answer, GapError> {
    let n = ctx.n();
    // Intervals and the residual check count the simulator's resolution at the answer as
    // an error of its own, beside the measurement's: where the gait is knife-edge the data
    // cannot pin a knob closer than a nudge that changes the gait.
    let (inflated, _) = ctx.at_resolution(final_fit)?;
    let rctx = FitContext {
        obs: &inflated,
        ..*ctx
    };
    let final_fit = &{
        let sims = final_fit.sims.clone().unwrap_or_default();
        let (data, per) = super::problem::chi2_of(&inflated, &sims);
        Fit {
            chi2: data + ctx.knobs.prior_chi2(&final_fit.point),
            chi2_data: data,
            per_condition: per,
            ..final_fit.clone()
        }
    };
    let ctx = &rctx;
    let phi = dispersion(final_fit.chi2_data, n, final_fit.k());
    let phi = if phi.is_finite() { phi } else { 1.0 };
    let mut parameters = Vec::new();
    let mut effects = Vec::new();
    let mut ambiguous: Vec<Vec<String>> = Vec::new();
    for step in steps {
        let Some(k) = ctx.knobs.index_of(&step.knob) else {
            continue;
        };
        let knob = &ctx.knobs.list[k];
        let x = final_fit.point[k].unwrap_or(knob.lo);
        let iv = ctx.profile_walked(final_fit, k, phi)?;
        let (lo, hi, open) = match iv {
            Some(i) => (i.lo, i.hi, i.open_below || i.open_above),
            None => (x, x, false),
        };
        let nominal = match knob.kind {
            KnobKind::Parameter => knob.nominal.map(|x| knob.si(x)),
            KnobKind::Effect => None,
        };
        let signed = sign_identified(knob, ctx.conditions);
        let (value, interval) = as_stated(signed, knob.si(x), [knob.si(lo), knob.si(hi)]);
        let named = Named {
            knob: knob.label(),
            kind: knob.kind,
            value,
            interval,
            interval_open: open,
            nominal,
            change_pct: nominal
                .filter(|v| *v != 0.0 && signed)
                .map(|v| 100.0 * (knob.si(x) / v - 1.0)),
            unit: knob.unit.clone(),
            not_separable_from: step.not_separable_from.clone(),
            sign_identified: signed,
        };
        if !step.not_separable_from.is_empty() {
            let mut group = vec![knob.label()];
            group.extend(step.not_separable_from.iter().cloned());
            ambiguous.push(group);
            continue;
        }
        match knob.kind {
            KnobKind::Parameter => parameters.push(named),
            KnobKind::Effect => effects.push(named),
        }
    }
    let fits = within_noise(final_fit, n, alpha);
    // Names only for a model that fits: knobs of a chain that leaves the rest beyond noise
    // are leads (shown, with their shrink), not findings — a look-alike that explains part
    // of a gap it did not cause is exactly what an open world produces.
    let mut leads = Vec::new();
    if !fits {
        leads.append(&mut parameters);
        leads.append(&mut effects);
    }
    let kind = match (leads.is_empty(), parameters.is_empty(), effects.is_empty()) {
        _ if steps.is_empty() && nominal_within_noise => AnswerKind::WithinNoise,
        (false, _, _) => AnswerKind::PartlyExplained,
        // Look-alikes that together leave the rest beyond noise: not "ambiguous" (that
        // answer says the gap is explained), only partly explained.
        (true, true, true) if !ambiguous.is_empty() && !fits => AnswerKind::PartlyExplained,
        (true, true, true) if !ambiguous.is_empty() => AnswerKind::Ambiguous,
        (true, true, true) if nominal_within_noise => AnswerKind::WithinNoise,
        (true, true, true) => AnswerKind::Unexplained,
        (true, false, true) => AnswerKind::ParametersOff,
        (true, true, false) => AnswerKind::EffectMissing,
        (true, false, false) => AnswerKind::Both,
    };
    let rest = (!fits && kind != AnswerKind::WithinNoise)
        .then(|| rest_of(ctx, final_fit, alpha, set))
        .flatten();
    let statement = statement(
        kind,
        &parameters,
        &effects,
        &leads,
        &ambiguous,
        steps,
        rest.as_deref(),
    );
    Ok(Answer {
        kind,
        parameters,
        effects,
        leads,
        ambiguous,
        rest,
        statement,
    })
}

/// Where a model's remaining misfit lies: the metrics beyond noise and their worst trials.
fn rest_of(ctx: &FitContext<'_>, fit: &Fit, alpha: f64, set: &TrialSet) -> Option<String> {
    let sims = fit.sims.as_ref()?;
    let mut parts = Vec::new();
    for m in Metric::SIMULATED {
        let z: Vec<(usize, f64)> = ctx
            .obs
            .iter()
            .filter(|o| o.metric == m)
            .map(|o| (o.trial, o.z2(sims[o.trial].get(m))))
            .collect();
        if z.is_empty() {
            continue;
        }
        let chi2: f64 = z.iter().map(|(_, v)| v).sum();
        let p = chi2_upper_p(chi2, z.len() as f64).unwrap_or(1.0);
        if p >= alpha {
            continue;
        }
        let mut worst = z.clone();
        worst.sort_by(|a, b| b.1.total_cmp(&a.1));
        let labels: Vec<String> = worst
            .iter()
            .take(3)
            .filter(|(_, v)| *v > 4.0)
            .map(|(t, v)| format!("{} (|z| {:.1})", set.trials[*t].name(), v.sqrt()))
            .collect();
        parts.push(format!(
            "{} (RMS z {:.1}{}{})",
            m.words(),
            (chi2 / z.len() as f64).sqrt(),
            if labels.is_empty() { "" } else { "; worst at " },
            labels.join(", ")
        ));
    }
    (!parts.is_empty()).then(|| parts.join("; "))
}

fn named_text(n: &Named) -> String {
    let v = super::locate::sig3(n.value);
    let iv = format!(
        "[{}, {}]{}",
        super::locate::sig3(n.interval[0]),
        super::locate::sig3(n.interval[1]),
        if n.interval_open {
            ", open at a range end"
        } else {
            ""
        }
    );
    let change = n
        .change_pct
        .map(|c| {
            format!(
                " ({c:+.0} % of the file's {})",
                super::locate::sig3(n.nominal.unwrap_or(0.0))
            )
        })
        .unwrap_or_default();
    let alt = if n.not_separable_from.is_empty() {
        String::new()
    } else {
        format!(
            "; these trials cannot tell it from {}",
            n.not_separable_from.join(", ")
        )
    };
    if !n.sign_identified {
        return format!(
            "{} = ±{v} {} {iv}{alt} (magnitude: its sign is not identified, since the design \
             walks either way and the value's negative walks the mirror gait of the other start)",
            n.knob, n.unit
        )
        .replace("  ", " ");
    }
    format!("{} = {v} {}{change} {iv}{alt}", n.knob, n.unit).replace("  ", " ")
}

fn statement(
    kind: AnswerKind,
    parameters: &[Named],
    effects: &[Named],
    leads: &[Named],
    ambiguous: &[Vec<String>],
    steps: &[Step],
    rest: Option<&str>,
) -> String {
    let chain: Vec<String> = steps
        .iter()
        .enumerate()
        .map(|(i, s)| {
            // A joint step's second knob: the pair explains together what neither did
            // alone, so its share is only meaningful beside the first's.
            let together = s
                .joint_with
                .as_ref()
                .filter(|_| i > 0 && steps[i - 1].joint_with.as_deref() == Some(s.knob.as_str()))
                .map(|w| format!(" (fitted together with {w})"))
                .unwrap_or_default();
            format!(
                "{}{}: −{:.0} %{together}",
                if i > 0 { "+ " } else { "" },
                s.knob,
                s.shrink_pct
            )
        })
        .collect();
    let list = |v: &[Named]| v.iter().map(named_text).collect::<Vec<_>>().join("; ");
    let undecided = if ambiguous.is_empty() {
        String::new()
    } else {
        format!(
            "; not told apart by these trials: {}",
            ambiguous
                .iter()
                .map(|g| format!("one of {{{}}}", g.join(", ")))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let s = match kind {
        AnswerKind::WithinNoise => {
            "no significant gap: the nominal model fits within the stated noise".into()
        }
        AnswerKind::Unexplained => "unexplained: the gap is real, and neither a recalibration of \
             the design's uncertain parameters nor an effect of the library explains it under \
             the call rules (a model error outside the declared parameters, or an effect outside \
             the library)"
            .into(),
        AnswerKind::ParametersOff => format!(
            "parameters off: {} (chain {}; the rest within noise)",
            list(parameters),
            chain.join(", ")
        ),
        AnswerKind::EffectMissing => format!(
            "effect missing: {} (chain {}; the rest within noise)",
            list(effects),
            chain.join(", ")
        ),
        AnswerKind::Both => format!(
            "both parameters off and an effect missing: {}; {} (chain {}; the rest within noise)",
            list(parameters),
            list(effects),
            chain.join(", ")
        ),
        AnswerKind::PartlyExplained => format!(
            "partly explained, nothing named: the best chain ({}) leaves the rest beyond noise \
             in {}; leads, not findings: {}",
            chain.join(", "),
            rest.unwrap_or("several metrics"),
            if leads.is_empty() {
                "only the groups below".to_string()
            } else {
                list(leads)
            }
        ),
        AnswerKind::Ambiguous => format!(
            "ambiguous: the gap is explained (chain {}){}, but no knob is named",
            chain.join(", "),
            if rest.is_some() { " only in part" } else { "" }
        ),
    };
    format!("{s}{undecided}")
}

/// Residuals of the nominal model and of the final model.
fn residuals(
    set: &TrialSet,
    conditions: &[Condition],
    obs: &[Observation],
    nominal: &Fit,
    final_fit: &Fit,
) -> Result<Vec<Residual>, GapError> {
    let mut out = Vec::new();
    let nom = nominal.sims.as_deref().unwrap_or(&[]);
    let after = (!final_fit.active.is_empty())
        .then_some(final_fit.sims.as_deref())
        .flatten();
    for o in obs {
        let c = &conditions[o.trial];
        let t = &set.trials[o.trial];
        let sim = nom
            .get(o.trial)
            .map(|s| s.get(o.metric))
            .unwrap_or(f64::NAN);
        let (sa, za) = match after.and_then(|a| a.get(o.trial)) {
            Some(s) => {
                let v = s.get(o.metric);
                (
                    v.is_finite().then_some(v),
                    v.is_finite().then(|| (v - o.value) / o.sd),
                )
            }
            None => (None, None),
        };
        out.push(Residual {
            trial: o.trial,
            label: t.name(),
            design: t.design.clone(),
            leg_length_m: c.leg_length_m,
            frequency_hz: c.drive_frequency_hz()?,
            metric: o.metric,
            measured: o.value,
            sd: o.sd,
            sd_assumed: o.sd_assumed,
            simulated: sim.is_finite().then_some(sim),
            z: sim.is_finite().then(|| (sim - o.value) / o.sd),
            relative: (sim.is_finite() && o.value != 0.0).then(|| (sim - o.value) / o.value.abs()),
            simulated_after: sa,
            z_after: za,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |x| over a signed interval, derived by hand: an interval across 0 reaches 0; one on
    /// either side keeps its ends' magnitudes, in order.
    #[test]
    fn a_signed_interval_becomes_the_magnitudes_it_holds() {
        assert_eq!(magnitude_interval(-1.6, -1.4), [1.4, 1.6]);
        assert_eq!(magnitude_interval(1.4, 1.6), [1.4, 1.6]);
        assert_eq!(magnitude_interval(-0.2, 1.1), [0.0, 1.1]);
        assert_eq!(magnitude_interval(-2.0, 0.5), [0.0, 2.0]);
        assert_eq!(magnitude_interval(0.0, 0.3), [0.0, 0.3]);
    }

    /// A magnitude is stated as one, with its sign left open.
    #[test]
    fn a_magnitude_is_stated_with_its_sign_open() {
        let n = Named {
            knob: "d:ground.slope_deg".into(),
            kind: KnobKind::Parameter,
            value: 1.5,
            interval: [1.4, 1.6],
            interval_open: false,
            nominal: Some(0.0),
            change_pct: None,
            unit: "deg".into(),
            not_separable_from: Vec::new(),
            sign_identified: false,
        };
        let t = named_text(&n);
        assert!(
            t.starts_with("d:ground.slope_deg = ±1.5 deg [1.4, 1.6]"),
            "{t}"
        );
        assert!(t.contains("sign is not identified"), "{t}");
        let signed = named_text(&Named {
            sign_identified: true,
            ..n
        });
        assert!(!signed.contains('±'), "{signed}");
    }
}
