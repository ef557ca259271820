//! Which settings of a design's declared uncertain parameters are compatible with the trials
//! at all: a space-filling exploration of their whole box ("history matching").
//!
//! The diagnosis calibrates by fitting from the nominal point on an additive surrogate, a
//! local answer. When the question is global — can *any* plausible setting reproduce the
//! hardware? which parameters does that pin down? — the honest tool is to walk a
//! space-filling sample of the box and keep the settings whose χ² against the trials is
//! within noise (χ² p-value ≥ [`PLAUSIBLE_P`]): every parameter's range among them says how
//! far the trials identify it, and the reach of each measured metric over the sample says
//! whether the box can get there at all. The sample is a Latin hypercube in the parameters'
//! own coordinates (log where the design declares `log = true`), deterministic in its seed.

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::cache::SimCache;
use super::diagnose::designs_of;
use super::error::{GapError, check_default_sd};
use super::knob::{KnobKind, Knobs};
use super::library::EffectLibrary;
use super::likelihood::{Observation, chi2_of};
use super::observe::{fill_from_trajectories, metric_observations};
use super::simulate::{Condition, Walked};
use super::trials::{Metric, TrialSet};
use crate::progress::Observer;
use crate::regression::dist::chi2_upper_p;
use crate::regression::spearman;

/// A setting is plausible when its χ² against the trials has at least this p-value.
pub const PLAUSIBLE_P: f64 = 0.05;

#[derive(Clone, Debug)]
pub struct ExploreOptions {
    /// Settings walked (each on every condition).
    pub samples: usize,
    pub seed: u64,
    /// Relative sd assumed where a measurement states none.
    pub default_relative_sd: f64,
}

impl Default for ExploreOptions {
    fn default() -> Self {
        ExploreOptions {
            samples: 256,
            seed: 1,
            default_relative_sd: 0.1,
        }
    }
}

/// One parameter over the sample.
#[derive(Clone, Debug, Serialize)]
pub struct ParameterReach {
    /// `design:path`.
    pub parameter: String,
    pub nominal: f64,
    pub range: [f64; 2],
    /// Its value in the best setting.
    pub best: f64,
    /// Lowest and highest value among the plausible settings (None: no plausible setting).
    pub plausible: Option<[f64; 2]>,
    /// Share of the range (in its own coordinate) the plausible values span: near 1, the
    /// trials do not pin it down; small, they do (within the sample's resolution).
    pub plausible_width: Option<f64>,
    /// Spearman rank correlation between the value and the χ² over the walking settings:
    /// which way the trials push it.
    pub rank_correlation_with_chi2: f64,
    pub why: String,
}

/// One measured metric over the sample.
#[derive(Clone, Debug, Serialize)]
pub struct MetricReach {
    pub trial: String,
    pub metric: Metric,
    pub measured: f64,
    pub sd: f64,
    pub nominal: f64,
    /// Lowest and highest simulated value over the walking sampled settings: what the box
    /// reaches at least (a sample, not the box's true extremes).
    pub reach: [f64; 2],
    /// Value in the best setting.
    pub best: f64,
    /// The measured value lies within the sampled reach widened by 2 sd.
    pub reachable: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct Exploration {
    pub origin: String,
    pub samples: usize,
    pub seed: u64,
    pub observations: usize,
    /// Settings with a walk that fell on some condition.
    pub fell: usize,
    pub plausible: usize,
    pub nominal_chi2: f64,
    /// The file's values fit within noise (p ≥ [`PLAUSIBLE_P`]).
    pub nominal_plausible: bool,
    /// Every sampled setting fits worse than the file's values: the sample is too sparse
    /// for these trials (the region that fits, if any, is narrower than its spacing), and
    /// "no plausible sample" says nothing about the box.
    pub too_sparse: bool,
    pub best_chi2: f64,
    pub best_p: f64,
    pub parameters: Vec<ParameterReach>,
    pub metrics: Vec<MetricReach>,
    pub walks: usize,
    pub notes: Vec<String>,
}

/// A Latin hypercube of `n` points in [0, 1]^dim: each coordinate's n strata each hold one
/// point, jittered within the stratum, strata shuffled per coordinate.
pub fn latin_hypercube(n: usize, dim: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut columns: Vec<Vec<f64>> = Vec::with_capacity(dim);
    for _ in 0..dim {
        let mut strata: Vec<usize> = (0..n).collect();
        strata.shuffle(&mut rng);
        columns.push(
            strata
                .into_iter()
                .map(|s| (s as f64 + rng.random::<f64>()) / n as f64)
                .collect(),
        );
    }
    (0..n)
        .map(|i| columns.iter().map(|c| c[i]).collect())
        .collect()
}

/// Walks a Latin hypercube over every declared uncertain parameter of the trials' designs
/// and reports which settings fit the trials within noise.
pub fn explore(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
    opts: &ExploreOptions,
    cache: &SimCache,
    progress: &dyn Observer,
) -> Result<Exploration, GapError> {
    if opts.samples < 2 {
        return Err(GapError::Invalid("explore needs at least 2 samples".into()));
    }
    check_default_sd(opts.default_relative_sd)?;
    let set = &fill_from_trajectories(set, conditions, lib)?;
    let mut notes = Vec::new();
    let obs = metric_observations(set, opts.default_relative_sd, &mut notes);
    if obs.is_empty() {
        let why = "no trial has a measured metric the simulator computes";
        return Err(GapError::file(&set.origin, why));
    }
    let designs = designs_of(conditions);
    let knobs = Knobs::build(&designs, &[], true).map_err(GapError::sim(&set.origin))?;
    let params: Vec<usize> = (0..knobs.len())
        .filter(|i| knobs.list[*i].kind == KnobKind::Parameter)
        .collect();
    if params.is_empty() {
        return Err(GapError::Invalid(format!(
            "{}: no design of these trials declares [[uncertain]] parameters: nothing to explore",
            set.origin
        )));
    }
    let units = latin_hypercube(opts.samples, params.len(), opts.seed);
    let points: Vec<Vec<Option<f64>>> = units
        .iter()
        .map(|u| knobs.point_at(&knobs.nominal_point(), &params, u))
        .collect();
    let mut settings = vec![knobs.setting(lib, &knobs.nominal_point())];
    settings.extend(points.iter().map(|p| knobs.setting(lib, p)));
    let walks_before = cache.walks();
    let sims = cache.get_many(conditions, lib, &settings, progress)?;
    let nominal_chi2 = chi2_of(&obs, &sims[0]);
    let n_obs = obs.len();
    let p_of = |chi2: f64| chi2_upper_p(chi2, n_obs as f64).unwrap_or(0.0);
    let fell = |s: &[Walked]| s.iter().any(|m| m.metrics.fell);

    let sample_sims = &sims[1..];
    let chi2: Vec<f64> = sample_sims.iter().map(|s| chi2_of(&obs, s)).collect();
    let plausible: Vec<bool> = sample_sims
        .iter()
        .zip(&chi2)
        .map(|(s, c)| !fell(s) && p_of(*c) >= PLAUSIBLE_P)
        .collect();
    let best = (0..chi2.len())
        .min_by(|a, b| chi2[*a].total_cmp(&chi2[*b]))
        .ok_or_else(|| GapError::Invalid("no sample".into()))?;
    let walking: Vec<usize> = (0..chi2.len())
        .filter(|i| !fell(&sample_sims[*i]))
        .collect();
    let samples = Samples {
        units: &units,
        points: &points,
        chi2: &chi2,
        plausible: &plausible,
        walking: &walking,
        best,
    };
    samples.notes(nominal_chi2, &mut notes);
    let parameters = samples.parameters(&knobs, &params);
    let metrics = samples.metrics(&obs, set, sample_sims, &sims[0]);
    Ok(Exploration {
        origin: set.origin.clone(),
        samples: opts.samples,
        seed: opts.seed,
        observations: n_obs,
        fell: opts.samples - walking.len(),
        plausible: plausible.iter().filter(|p| **p).count(),
        nominal_chi2,
        nominal_plausible: !fell(&sims[0]) && p_of(nominal_chi2) >= PLAUSIBLE_P,
        too_sparse: chi2[best] > nominal_chi2,
        best_chi2: chi2[best],
        best_p: p_of(chi2[best]),
        parameters,
        metrics,
        walks: cache.walks() - walks_before,
        notes,
    })
}

/// The samples of an exploration, each a setting of the explored parameters.
struct Samples<'a> {
    /// Unit-cube coordinates [sample][parameter].
    units: &'a [Vec<f64>],
    /// Knob points [sample][knob].
    points: &'a [Vec<Option<f64>>],
    chi2: &'a [f64],
    plausible: &'a [bool],
    /// The samples that walked on every condition.
    walking: &'a [usize],
    best: usize,
}

impl Samples<'_> {
    /// Notes on a sample too sparse for the trials (every setting fits worse than the file's
    /// values, χ² `nominal_chi2`) and on settings that fell.
    fn notes(&self, nominal_chi2: f64, notes: &mut Vec<String>) {
        let (samples, best) = (self.units.len(), self.chi2[self.best]);
        if best > nominal_chi2 {
            notes.push(format!(
                "every sampled setting fits worse than the file's values (best χ² {best:.1} > \
                 nominal {nominal_chi2:.1}): {samples} samples over {} parameters are too sparse \
                 for these trials; run `survey gap diagnose` (a local fit) or more samples \
                 before reading anything into \"no plausible setting\"",
                self.units.first().map_or(0, Vec::len)
            ));
        }
        if self.walking.len() < samples {
            notes.push(format!(
                "{} of {samples} settings fell on some condition (χ² charged as a fall)",
                samples - self.walking.len()
            ));
        }
    }

    /// Each parameter's reach: its plausible range, best value and the rank correlation of
    /// its coordinate with χ² over the walking samples.
    fn parameters(&self, knobs: &Knobs, params: &[usize]) -> Vec<ParameterReach> {
        params
            .iter()
            .enumerate()
            .map(|(j, i)| {
                let k = &knobs.list[*i];
                let coord = |p: &Vec<Option<f64>>| p[*i].unwrap_or(f64::NAN);
                let plaus: Vec<f64> = self
                    .points
                    .iter()
                    .zip(self.plausible)
                    .filter(|(_, ok)| **ok)
                    .map(|(p, _)| coord(p))
                    .collect();
                let (plausible_range, width) = if plaus.is_empty() {
                    (None, None)
                } else {
                    let lo = plaus.iter().copied().fold(f64::INFINITY, f64::min);
                    let hi = plaus.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    (
                        Some([k.value(lo), k.value(hi)]),
                        Some((hi - lo) / (k.hi - k.lo)),
                    )
                };
                let xs: Vec<f64> = self.walking.iter().map(|w| self.units[*w][j]).collect();
                let ys: Vec<f64> = self.walking.iter().map(|w| self.chi2[*w]).collect();
                ParameterReach {
                    parameter: k.label(),
                    nominal: k.nominal.map(|x| k.value(x)).unwrap_or(f64::NAN),
                    range: [k.value(k.lo), k.value(k.hi)],
                    best: k.value(coord(&self.points[self.best])),
                    plausible: plausible_range,
                    plausible_width: width,
                    rank_correlation_with_chi2: if xs.len() > 2 {
                        spearman(&xs, &ys)
                    } else {
                        f64::NAN
                    },
                    why: k.why.clone(),
                }
            })
            .collect()
    }

    /// Each observation's reach over the walking samples, and whether the measured value
    /// lies within it (±2 sd).
    fn metrics(
        &self,
        obs: &[Observation],
        set: &TrialSet,
        sample_sims: &[Vec<Walked>],
        nominal: &[Walked],
    ) -> Vec<MetricReach> {
        obs.iter()
            .map(|o: &Observation| {
                let vals: Vec<f64> = self
                    .walking
                    .iter()
                    .map(|w| sample_sims[*w][o.trial].channel(o.channel))
                    .filter(|v| v.is_finite())
                    .collect();
                let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                MetricReach {
                    trial: set.trials[o.trial].label.clone(),
                    metric: o.as_metric().unwrap_or(super::trials::Metric::VelocityMps),
                    measured: o.value,
                    sd: o.sd,
                    nominal: nominal[o.trial].channel(o.channel),
                    reach: [lo, hi],
                    best: sample_sims[self.best][o.trial].channel(o.channel),
                    reachable: lo - 2.0 * o.sd <= o.value && o.value <= hi + 2.0 * o.sd,
                }
            })
            .collect()
    }
}
