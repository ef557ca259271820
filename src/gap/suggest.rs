//! The next trials to run: the conditions, at the user's own robot size, where the two
//! leading explanations of the trials (fitted to them by [`super::separate`]) differ most —
//! the expected likelihood-ratio statistic between them, in the trials' own noise units,
//! on the summaries and on the logged cycles — computed with the simulator.
//!
//! The pool is a grid over what a lab can change on one robot without rebuilding it: drive
//! frequency, servo amplitude (position-servo designs), payload and ground slope, within
//! [`POOL`]'s ranges; a condition is offered only where the nominal model and both leading
//! explanations walk forward (a trial that falls measures nothing, and risks the robot; one
//! that scuffs in place is on a gait where another engine, or the robot, parts from the
//! model most: Drake-Lagged at such conditions, `tests/golden/drake/gap-lagged-next/`).

use rayon::prelude::*;
use serde::Serialize;

use super::error::GapError;
use super::library::EffectLibrary;
use super::separate::{
    CycleCache, Evidence, SeparateOptions, SimCycle, measured_signatures, separate_with,
    simulate_cycles,
};
use super::simulate::{Condition, resolve};
use super::synth::round_sig;
use super::trials::{Metric, Trial, TrialSet};
use super::waveform;
use crate::progress::Observer;
use crate::sim::design::ControlSpec;

/// The pool's levels: drive frequency (× the design's at the robot's size), servo amplitude
/// (× the design's), payload (fraction of the robot's mass added) and slope [deg, downhill
/// positive]. ±15 % in frequency and ±20 % in amplitude stay near the gait the design was
/// tuned for; 30 % payload and 2° are what a bench test adds without new hardware.
pub struct Pool {
    pub frequency_factors: &'static [f64],
    pub amplitude_factors: &'static [f64],
    pub payload_fractions: &'static [f64],
    pub slopes_deg: &'static [f64],
}

pub const POOL: Pool = Pool {
    frequency_factors: &[0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15],
    amplitude_factors: &[0.8, 1.0, 1.2],
    payload_fractions: &[0.0, 0.15, 0.3],
    slopes_deg: &[-2.0, 0.0, 2.0],
};

/// Step of a leader's value for the smoothness check, as a fraction of its range in its
/// coordinate (effects: ln magnitude, so ≈ ±10 % for a range of two decades).
const SMOOTHNESS_STEP: f64 = 0.02;
/// Largest bend (m₋ + m₊ − 2m₀, in the new trial's sds) a metric may show over the step:
/// beyond it the gait changes character within the candidate's own uncertainty.
const SMOOTHNESS_Z: f64 = 2.0;

/// Largest expected z² one metric (or one signal's cycle) of one trial may contribute: a
/// 5-sd difference already decides; beyond it the two models walk qualitatively different
/// gaits there (a bifurcation), where the simulator's own resolution is least trusted, so a
/// larger number must not rank a knife-edge condition first.
const MAX_Z2: f64 = 25.0;

#[derive(Clone, Debug)]
pub struct SuggestOptions {
    pub budget: usize,
    pub separate: SeparateOptions,
    /// Relative sd assumed for the new trials' summaries (the median of the trials' own when
    /// they state sds).
    pub default_relative_sd: f64,
    /// Also offer conditions where a model stands, scuffs or walks backward (not falls). In
    /// the simulator's own world they separate look-alikes best (hip Coulomb friction vs
    /// damping: 10/10 named with them, 5/10 without); on another engine they made an answer
    /// worse (`tests/golden/drake/gap-lagged-next/README.md`).
    pub any_gait: bool,
}

/// A condition to run next.
#[derive(Clone, Debug, Serialize)]
pub struct Suggested {
    pub label: String,
    pub leg_length_m: f64,
    pub frequency_hz: f64,
    pub amplitude_deg: Option<f64>,
    pub mass_kg: f64,
    pub slope_deg: f64,
    /// Expected LR statistic between the two leading explanations on this trial's summaries
    /// (noiseless, in the trials' sd units).
    pub separation_summaries: f64,
    /// The same on its cycles (with the model-error floor).
    pub separation_waveforms: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Suggestion {
    /// The design as the trials name it (bundled name or TOML path).
    pub design: String,
    /// The two leading explanations and their fitted values (SI).
    pub leading: Vec<(String, f64)>,
    pub budget: usize,
    /// Pool conditions tried, and those offered: all three models walk forward and the
    /// leaders' gaits are smooth there.
    pub pool: usize,
    pub walkable: usize,
    /// Conditions left out because a model, without falling, does not walk forward there
    /// (steady speed at or below the design's walking threshold: it stands, scuffs or walks
    /// backward).
    pub not_forward: usize,
    /// Whether conditions off the forward gait were offered too ([`SuggestOptions::any_gait`]).
    pub any_gait: bool,
    /// Conditions left out because a leader's metrics bend sharply there (or a step falls).
    pub knife_edge: usize,
    pub relative_sd: f64,
    /// Best first.
    pub suggested: Vec<Suggested>,
    /// The design's default condition at the robot's size (its own drive), for comparison.
    pub default_condition: Option<Suggested>,
    pub walks: usize,
}

/// Suggests `opts.budget` conditions that best separate the two leading candidates among
/// `opts.separate.candidates` on the trials of `set`.
pub fn suggest(
    set: &TrialSet,
    lib: &EffectLibrary,
    opts: &SuggestOptions,
    progress: &dyn Observer,
) -> Result<Suggestion, GapError> {
    if opts.budget == 0 || opts.budget > 50 {
        return Err(GapError::Invalid(format!(
            "--budget {}: must be in 1..=50",
            opts.budget
        )));
    }
    let conditions = resolve(set)?;
    let sigs = measured_signatures(set, &conditions, opts.separate.settle_cycles)?;
    let cache = CycleCache::default();
    let sep = separate_with(
        set,
        &conditions,
        &sigs,
        lib,
        &opts.separate,
        &cache,
        progress,
    )?;
    let ranking = sep
        .rankings
        .iter()
        .find(|r| r.evidence == Evidence::SummariesAndWaveforms)
        .or_else(|| sep.rankings.first())
        .ok_or_else(|| GapError::Invalid("no ranking of the candidates".into()))?;
    let leading: Vec<(String, f64)> = ranking
        .fits
        .iter()
        .take(2)
        .map(|f| (f.knob.clone(), f.value))
        .collect();
    let settings = separate_settings(&conditions, lib, &leading)?;
    // The robot's own size and design: the most common of the trials (first on ties).
    let robot = robot_condition(&conditions)?;
    let base = conditions[robot].clone();
    let design = set.trials[robot].design.clone();
    let relative_sd = trials_relative_sd(set).unwrap_or(opts.default_relative_sd);
    let (pool, default_index) = pool_conditions(&base)?;
    let models = [
        super::knob::ModelSetting::nominal(),
        settings[0].clone(),
        settings[1].clone(),
    ];
    let settle = opts.separate.settle_cycles;
    let walks: Vec<[SimCycle; 3]> = pool
        .par_iter()
        .map(|c| {
            let r = [
                simulate_cycles(c, lib, &models[0], settle)?,
                simulate_cycles(c, lib, &models[1], settle)?,
                simulate_cycles(c, lib, &models[2], settle)?,
            ];
            progress.tick();
            Ok(r)
        })
        .collect::<Result<_, GapError>>()?;
    let fell: Vec<bool> = walks
        .iter()
        .map(|w| w.iter().any(|x| x.metrics.fell))
        .collect();
    let forward: Vec<bool> = pool
        .iter()
        .zip(&walks)
        .zip(&fell)
        .map(|((c, w), &fell)| !fell && (opts.any_gait || walks_forward(c, w)))
        .collect();
    let smooth: Vec<bool> = pool
        .par_iter()
        .zip(&walks)
        .zip(&forward)
        .map(|((c, w), &f)| {
            let ok = f && is_smooth(c, w, lib, &settings, settle, relative_sd)?;
            if ok {
                progress.tick();
            }
            Ok(ok)
        })
        .collect::<Result<_, GapError>>()?;
    let not_forward = fell
        .iter()
        .zip(&forward)
        .filter(|(fell, f)| !**fell && !**f)
        .count();
    let knife_edge = forward
        .iter()
        .zip(&smooth)
        .filter(|(f, ok)| **f && !**ok)
        .count();
    let forward_count = forward.iter().filter(|f| **f).count();
    let floor = opts.separate.relative_floor;
    let score = |c: &Condition, w: &[SimCycle; 3]| score_condition(c, w, relative_sd, floor);
    let mut scored: Vec<Suggested> = pool
        .iter()
        .zip(&walks)
        .zip(&smooth)
        .filter(|(_, ok)| **ok)
        .filter_map(|((c, w), _)| score(c, w))
        .collect();
    let walkable = scored.len();
    let with_logs = sep.trials_with_logs > 0;
    let total = |s: &Suggested| {
        s.separation_summaries
            + if with_logs {
                s.separation_waveforms
            } else {
                0.0
            }
    };
    let default_condition = default_index.and_then(|i| score(&pool[i], &walks[i]));
    // Best first; ties (and equal floats) broken by the pool's order, so the answer is
    // deterministic.
    scored.sort_by(|a, b| total(b).total_cmp(&total(a)));
    scored.truncate(opts.budget);
    for (k, s) in scored.iter_mut().enumerate() {
        s.label = format!("next-{}", k + 1);
    }
    Ok(Suggestion {
        design,
        leading,
        budget: opts.budget,
        pool: pool.len(),
        walkable,
        not_forward,
        any_gait: opts.any_gait,
        knife_edge,
        relative_sd,
        suggested: scored,
        default_condition,
        walks: sep.walks + 3 * pool.len() + 4 * forward_count,
    })
}

/// Whether the nominal and both leaders walk forward at `c`: no fall and a steady speed
/// above the design's walking threshold, the criterion of `WalkReport::walks` (the
/// criteria are dimensionless: the unscaled design's serve at every size).
fn walks_forward(c: &Condition, w: &[SimCycle; 3]) -> bool {
    let threshold_mps = c.design.criteria.walk_speed_threshold_mps(c.leg_length_m);
    w.iter()
        .all(|x| !x.metrics.fell && x.metrics.get(Metric::VelocityMps) > threshold_mps)
}

/// Smoothness: each leader a step below and above its fitted value; a condition where
/// the metrics bend more than SMOOTHNESS_Z sds over that step (or a step falls) is a
/// knife-edge gait: a trial there cannot be fitted reliably, whatever it separates.
/// `w` are the condition's walks under the nominal and the two leaders, `settings` those
/// of [`separate_settings`].
fn is_smooth(
    c: &Condition,
    w: &[SimCycle; 3],
    lib: &EffectLibrary,
    settings: &[super::knob::ModelSetting],
    settle: usize,
    relative_sd: f64,
) -> Result<bool, GapError> {
    if w.iter().any(|x| x.metrics.fell) {
        return Ok(false);
    }
    for (lead, (lo, hi)) in [(1usize, (2usize, 3usize)), (2, (4, 5))] {
        let minus = simulate_cycles(c, lib, &settings[lo], settle)?;
        let plus = simulate_cycles(c, lib, &settings[hi], settle)?;
        if minus.metrics.fell || plus.metrics.fell {
            return Ok(false);
        }
        for m in Metric::SIMULATED {
            let (a, b, x) = (
                minus.metrics.get(m),
                plus.metrics.get(m),
                w[lead].metrics.get(m),
            );
            if a.is_finite() && b.is_finite() && x.is_finite() && x != 0.0 {
                let bend = (a + b - 2.0 * x).abs() / (relative_sd * x.abs());
                if bend > SMOOTHNESS_Z {
                    return Ok(false);
                }
            }
        }
    }
    Ok(true)
}

/// How far apart the two leaders' walks at a condition are (summaries and waveforms,
/// each term capped at MAX_Z2); `None` when a walk fell or the design cannot be scaled.
fn score_condition(
    c: &Condition,
    w: &[SimCycle; 3],
    relative_sd: f64,
    floor: f64,
) -> Option<Suggested> {
    if w.iter().any(|x| x.metrics.fell) {
        return None;
    }
    let (a, b) = (&w[1], &w[2]);
    let mut s = 0.0;
    for m in Metric::SIMULATED {
        let (x, y) = (a.metrics.get(m), b.metrics.get(m));
        if x.is_finite() && y.is_finite() && x != 0.0 {
            s += ((x - y) / (relative_sd * x.abs())).powi(2).min(MAX_Z2);
        }
    }
    let wv = match (&a.cycles, &b.cycles) {
        (Some(x), Some(y)) => waveform::chi2(x, y, floor)
            .per_signal
            .iter()
            .map(|(_, c2, _)| c2.min(MAX_Z2))
            .sum(),
        _ => 0.0,
    };
    let scaled = c.scaled_design().ok()?;
    Some(Suggested {
        label: String::new(),
        leg_length_m: c.leg_length_m,
        frequency_hz: c.frequency_hz.unwrap_or(f64::NAN),
        amplitude_deg: c.amplitude_deg,
        mass_kg: c.mass_kg.unwrap_or(scaled.mass.total_mass_kg),
        slope_deg: c.slope_deg.unwrap_or(0.0),
        separation_summaries: s,
        separation_waveforms: wv,
    })
}

/// The settings of the two leading candidates at their fitted values, and each a step
/// [`SMOOTHNESS_STEP`] (of its range, in its coordinate) below and above: [A, B, A−, A+, B−, B+].
fn separate_settings(
    conditions: &[Condition],
    lib: &EffectLibrary,
    leading: &[(String, f64)],
) -> Result<Vec<super::knob::ModelSetting>, GapError> {
    let designs = super::diagnose::designs_of(conditions);
    let effects: Vec<_> = lib.effects.iter().collect();
    let knobs = super::knob::Knobs::build(&designs, &effects, true).map_err(|e| GapError::Sim {
        origin: "designs".into(),
        source: e,
    })?;
    let mut at = Vec::new();
    let mut steps = Vec::new();
    for (label, si) in leading {
        let k = knobs
            .index_of(label)
            .ok_or_else(|| GapError::Invalid(format!("unknown knob {label}")))?;
        let knob = &knobs.list[k];
        let x = knob.coordinate(si / knob.si_per_value);
        let h = SMOOTHNESS_STEP * (knob.hi - knob.lo);
        let setting = |x: f64| {
            let mut point = knobs.nominal_point();
            point[k] = Some(x);
            knobs.setting(lib, &point)
        };
        at.push(setting(x));
        steps.push(setting(x - h));
        steps.push(setting(x + h));
    }
    at.extend(steps);
    Ok(at)
}

/// The index of the robot's own condition: the most common (design, size) of the trials.
fn robot_condition(conditions: &[Condition]) -> Result<usize, GapError> {
    let mut best: Option<(usize, usize)> = None;
    for (i, c) in conditions.iter().enumerate() {
        let n = conditions
            .iter()
            .filter(|o| o.design.name == c.design.name && o.leg_length_m == c.leg_length_m)
            .count();
        if best.is_none_or(|(_, m)| n > m) {
            best = Some((i, n));
        }
    }
    best.map(|(i, _)| i)
        .ok_or_else(|| GapError::Invalid("no trials".into()))
}

/// The median relative sd the trials state (None: none stated).
fn trials_relative_sd(set: &TrialSet) -> Option<f64> {
    let mut v: Vec<f64> = set
        .trials
        .iter()
        .flat_map(|t| t.measured.iter().flatten())
        .filter_map(|m| m.sd.map(|sd| sd / m.value.abs()))
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// The pool of conditions at the robot's size, and which of them is the default one (the
/// design's own drive, amplitude and mass, level floor).
fn pool_conditions(base: &Condition) -> Result<(Vec<Condition>, Option<usize>), GapError> {
    let scaled = base.scaled_design()?;
    let f0 = scaled.controller().frequency_hz().unwrap_or(1.0);
    let m0 = scaled.mass.total_mass_kg;
    let servo_amplitude = match &base.design.control {
        ControlSpec::ServoSine { amplitude_deg, .. } => Some(*amplitude_deg),
        _ => None,
    };
    let amplitudes: Vec<(Option<f64>, bool)> = match servo_amplitude {
        Some(a) => POOL
            .amplitude_factors
            .iter()
            .map(|k| (Some(a * k), *k == 1.0))
            .collect(),
        None => vec![(None, true)],
    };
    let mut out = Vec::new();
    let mut default = None;
    for &kf in POOL.frequency_factors {
        for &(a, own_amplitude) in &amplitudes {
            for &p in POOL.payload_fractions {
                for &s in POOL.slopes_deg {
                    if kf == 1.0 && own_amplitude && p == 0.0 && s == 0.0 && default.is_none() {
                        default = Some(out.len());
                    }
                    let mut c = base.clone();
                    c.frequency_hz = Some(f0 * kf);
                    c.amplitude_deg = a;
                    c.mass_kg = Some(m0 * (1.0 + p));
                    c.slope_deg = Some(s);
                    c.torque_nm = None;
                    out.push(c);
                }
            }
        }
    }
    Ok((out, default))
}

/// The suggestions as trial rows (a trials CSV the lab fills in).
pub fn as_trials(s: &Suggestion) -> Vec<Trial> {
    s.suggested
        .iter()
        .map(|x| {
            let mut t = Trial::condition(&s.design, x.leg_length_m);
            t.label = x.label.clone();
            t.frequency_hz = Some(round_sig(x.frequency_hz, 6));
            t.amplitude_deg = x.amplitude_deg.map(|a| round_sig(a, 6));
            t.mass_kg = Some(round_sig(x.mass_kg, 6));
            t.slope_deg = Some(x.slope_deg);
            t.source = format!(
                "suggested by survey gap suggest: separates {} from {}",
                s.leading.first().map(|l| l.0.as_str()).unwrap_or("?"),
                s.leading.get(1).map(|l| l.0.as_str()).unwrap_or("?")
            );
            t
        })
        .collect()
}
