//! The next trials to run: the conditions, at the robot's own size, whose measurement is
//! expected to reduce the posterior's entropy most — the expected information gain of a
//! trial about which explanation holds (Lindley 1956), computed with the simulator.
//!
//! The leading explanations of the trials (the diagnosis' posterior, until their
//! probabilities add up to 0.99, six at most) are each walked at their most probable point on
//! every condition of a pool of what a lab can change on one robot without rebuilding it:
//! drive frequency, servo amplitude (position-servo designs), payload and ground slope
//! ([`POOL`]). A new trial's summaries are predicted as Gaussian about each explanation's
//! walk, with the trials' own relative sd; the expected entropy of the posterior after the
//! trials is estimated by Monte Carlo over their predicted outcomes (fixed seeds), and the
//! budget is filled greedily, each next condition the one that lowers the expected entropy
//! of the chosen set most. A condition where an explanation falls is never offered (it
//! measures nothing and risks the robot), nor, unless asked, one where a model does not walk
//! forward (where another engine, or the robot, parts from the model most).
//!
//! The prediction uses each explanation's most probable point, not its whole posterior: a
//! condition where an explanation's gait changes within its own credible interval is scored
//! as if it did not.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

use super::cache::SimCache;
use super::diagnose::{DiagnoseOptions, Diagnosis, diagnose_conditions, suspects};
use super::error::GapError;
use super::knob::{Knobs, ModelSetting};
use super::library::EffectLibrary;
use super::likelihood::normal;
use super::simulate::{Condition, SimMetrics, resolve};
use super::synth::round_sig;
use super::trials::{Metric, Trial, TrialSet};
use crate::progress::Observer;
use crate::sim::design::ControlSpec;

/// The pool's levels: drive frequency (× the design's at the robot's size), servo amplitude
/// (× the design's), payload (fraction of the robot's mass added) and slope [deg].
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

/// Predicted outcomes drawn per evaluation of the expected entropy.
const DRAWS: usize = 256;

#[derive(Clone, Debug)]
pub struct SuggestOptions {
    pub budget: usize,
    /// Relative sd assumed for the new trials' summaries (the median of the trials' own when
    /// they state sds).
    pub default_relative_sd: f64,
    /// Also offer conditions where a model stands, scuffs or walks backward (not falls).
    pub any_gait: bool,
    pub diagnose: DiagnoseOptions,
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
    /// Expected entropy of the posterior (nats) after the trials chosen up to this one.
    pub expected_entropy: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Suggestion {
    /// The design as the trials name it (bundled name or TOML path).
    pub design: String,
    /// The leading explanations and their probabilities.
    pub leading: Vec<(String, f64)>,
    /// The posterior's entropy now (nats, over the leading explanations renormalised).
    pub entropy_now: f64,
    pub budget: usize,
    /// Pool conditions tried, offered, and left out (a fall; not walking forward).
    pub pool: usize,
    pub offered: usize,
    pub fell: usize,
    pub not_forward: usize,
    pub any_gait: bool,
    pub relative_sd: f64,
    /// Best first.
    pub suggested: Vec<Suggested>,
    /// The expected entropy after one trial at the design's own condition, for comparison.
    pub default_entropy: Option<f64>,
    pub walks: usize,
}

/// Suggests `opts.budget` conditions that most reduce the expected entropy of the trials'
/// posterior.
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
    let cache = SimCache::default();
    let (d, _) = diagnose_conditions(set, &conditions, lib, &opts.diagnose, &cache, progress)?;
    let leading = leaders(&d);
    // The knobs the diagnosis weighed.
    let knobs = suspects(&conditions, lib, &opts.diagnose, "the trials' designs")?;
    let settings: Vec<ModelSetting> = leading
        .iter()
        .map(|(label, _)| setting_of(&d, label, &knobs, lib))
        .collect::<Result<_, _>>()?;
    let robot = robot_condition(&conditions)?;
    let (pool, default_index) = pool_conditions(&conditions[robot])?;
    progress.stage(&format!(
        "walking {} explanations on {} pool conditions",
        settings.len(),
        pool.len()
    ));
    let walks: Vec<Vec<SimMetrics>> = pool
        .par_iter()
        .map(|c| {
            let w = settings
                .iter()
                .map(|s| c.simulate(lib, s).map(|w| w.metrics))
                .collect::<Result<Vec<_>, _>>();
            progress.tick();
            w
        })
        .collect::<Result<_, _>>()?;
    let relative_sd = trials_relative_sd(set).unwrap_or(opts.default_relative_sd);
    let weights: Vec<f64> = renormalised(&leading);
    let fell: Vec<bool> = walks.iter().map(|w| w.iter().any(|m| m.fell)).collect();
    let forward: Vec<bool> = pool
        .iter()
        .zip(&walks)
        .map(|(c, w)| opts.any_gait || walks_forward(c, w))
        .collect();
    let offered: Vec<usize> = (0..pool.len())
        .filter(|&i| !fell[i] && forward[i])
        .collect();
    let score = |chosen: &[usize]| expected_entropy(&weights, &walks, chosen, relative_sd);
    let mut chosen: Vec<usize> = Vec::new();
    let mut suggested = Vec::new();
    while chosen.len() < opts.budget {
        let best = offered
            .par_iter()
            .filter(|i| !chosen.contains(i))
            .map(|&i| {
                let mut with = chosen.clone();
                with.push(i);
                (i, score(&with))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        let Some((i, h)) = best else { break };
        chosen.push(i);
        suggested.push(described(&pool[i], h, suggested.len() + 1)?);
    }
    Ok(Suggestion {
        design: set.trials[robot].design.clone(),
        entropy_now: entropy(&weights),
        leading,
        budget: opts.budget,
        pool: pool.len(),
        offered: offered.len(),
        fell: fell.iter().filter(|f| **f).count(),
        not_forward: (0..pool.len()).filter(|&i| !fell[i] && !forward[i]).count(),
        any_gait: opts.any_gait,
        relative_sd,
        suggested,
        default_entropy: default_index.filter(|i| !fell[*i]).map(|i| score(&[i])),
        walks: d.walks_evaluated + pool.len() * settings.len(),
    })
}

/// The leading explanations (not "something outside these", which predicts nothing) until
/// their probabilities add up to 0.99, six at most.
fn leaders(d: &Diagnosis) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    let mut acc = 0.0;
    for l in d
        .posterior
        .iter()
        .filter(|l| l.explanation != super::hypothesis::NONE_OF_THESE)
    {
        out.push((l.explanation.clone(), l.probability));
        acc += l.probability;
        if acc >= 0.99 || out.len() == 6 {
            break;
        }
    }
    out
}

fn renormalised(leading: &[(String, f64)]) -> Vec<f64> {
    let total: f64 = leading.iter().map(|l| l.1).sum();
    leading
        .iter()
        .map(|l| l.1 / total.max(f64::MIN_POSITIVE))
        .collect()
}

/// The entropy (nats) of the weights `w`.
pub fn entropy(w: &[f64]) -> f64 {
    w.iter().filter(|p| **p > 0.0).map(|p| -p * p.ln()).sum()
}

/// The simulator's setting of an explanation at its most probable values (from the
/// diagnosis' table of explanations).
fn setting_of(
    d: &Diagnosis,
    label: &str,
    knobs: &Knobs,
    lib: &EffectLibrary,
) -> Result<ModelSetting, GapError> {
    let mut point = knobs.nominal_point();
    if label == "nominal" {
        return Ok(ModelSetting::nominal());
    }
    let e = d
        .explanations
        .iter()
        .find(|e| e.explanation == label)
        .ok_or_else(|| GapError::Invalid(format!("explanation {label} has no values")))?;
    for n in &e.knobs {
        let k = knobs
            .index_of(&n.knob)
            .ok_or_else(|| GapError::Invalid(format!("unknown knob {}", n.knob)))?;
        let knob = &knobs.list[k];
        point[k] = Some(knob.coordinate(n.value / knob.si_per_value));
    }
    Ok(knobs.setting(lib, &point))
}

/// The expected entropy (nats) of the explanations' posterior after trials at the
/// `chosen` pool conditions, by Monte Carlo: an explanation drawn by its weight, its
/// predicted summaries with Gaussian noise of sd `relative_sd`·|value|, the posterior of
/// every explanation on that outcome.
pub fn expected_entropy(
    weights: &[f64],
    walks: &[Vec<SimMetrics>],
    chosen: &[usize],
    relative_sd: f64,
) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let mut total = 0.0;
    for draw in 0..DRAWS {
        // The truth for this draw: explanations in proportion to their weights (stratified).
        let u = (draw as f64 + 0.5) / DRAWS as f64;
        let mut acc = 0.0;
        let truth = weights
            .iter()
            .position(|w| {
                acc += w;
                u < acc
            })
            .unwrap_or(weights.len() - 1);
        let mut logs: Vec<f64> = weights
            .iter()
            .map(|w| w.max(f64::MIN_POSITIVE).ln())
            .collect();
        for &c in chosen {
            for m in Metric::simulated() {
                let mu = walks[c][truth].get(m);
                if !mu.is_finite() || mu == 0.0 {
                    continue;
                }
                let sd = relative_sd * mu.abs();
                let y = mu + sd * normal(&mut rng);
                for (h, l) in logs.iter_mut().enumerate() {
                    let p = walks[c][h].get(m);
                    let z = if p.is_finite() { (y - p) / sd } else { 100.0 };
                    *l -= 0.5 * z * z;
                }
            }
        }
        let max = logs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let z: f64 = logs.iter().map(|l| (l - max).exp()).sum();
        let post: Vec<f64> = logs.iter().map(|l| (l - max).exp() / z).collect();
        total += entropy(&post);
    }
    total / DRAWS as f64
}

/// Whether every explanation walks forward at `c`: a steady speed above the design's
/// walking threshold (a fall is counted apart).
fn walks_forward(c: &Condition, w: &[SimMetrics]) -> bool {
    let threshold_mps = c.design.criteria.walk_speed_threshold_mps(c.leg_length_m);
    w.iter()
        .all(|x| x.fell || x.get(Metric::VelocityMps) > threshold_mps)
}

fn described(c: &Condition, h: f64, k: usize) -> Result<Suggested, GapError> {
    let scaled = c.scaled_design()?;
    Ok(Suggested {
        label: format!("next-{k}"),
        leg_length_m: c.leg_length_m,
        frequency_hz: c.frequency_hz.unwrap_or(f64::NAN),
        amplitude_deg: c.amplitude_deg,
        mass_kg: c.mass_kg.unwrap_or(scaled.mass.total_mass_kg),
        slope_deg: c.slope_deg.unwrap_or(0.0),
        expected_entropy: h,
    })
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
    let amplitudes: Vec<(Option<f64>, bool)> = match &base.design.control {
        ControlSpec::ServoSine { amplitude_deg, .. } => POOL
            .amplitude_factors
            .iter()
            .map(|k| (Some(amplitude_deg * k), *k == 1.0))
            .collect(),
        _ => vec![(None, true)],
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
                    c.cycles = false;
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
                "suggested by survey gap suggest: expected entropy of the posterior {:.3} nats after it",
                x.expected_entropy
            );
            t
        })
        .collect()
}
