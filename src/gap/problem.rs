//! The problem a fit solves, separate from the solver (argmin's split): how well does a
//! model with these knob values explain the trials? The cost is χ² = Σ z² over the
//! observations, z = (simulated − measured)/sd, plus the prior charge of parameters with a
//! Gaussian prior. A fallen simulated walk charges [`FELL_Z2`] per observation.

use argmin::core::{CostFunction, Error};

use super::knob::{Knobs, Point};
use super::simulate::SimMetrics;
use super::surrogate::{Correction, Surrogate};
use super::trials::Metric;

/// z² charged to an observation whose simulated walk fell: a 100-sd miss. A fall predicts
/// that nothing could be measured, so it must never fit better than a walk that misses by
/// tens of sds (a smaller charge made "a latency that makes the walker fall" the best
/// explanation of trials the nominal missed widely: the failure the open-world benchmark
/// found).
pub const FELL_Z2: f64 = 1.0e4;

/// One observation: a measured metric of a trial (= condition) with its sd.
#[derive(Clone, Copy, Debug)]
pub struct Observation {
    pub trial: usize,
    pub metric: Metric,
    pub value: f64,
    pub sd: f64,
    pub sd_assumed: bool,
}

impl Observation {
    /// The signed residual (simulated − measured) / sd; a fallen walk's is √[`FELL_Z2`].
    pub fn z(&self, simulated: f64) -> f64 {
        if simulated.is_finite() {
            (simulated - self.value) / self.sd
        } else {
            FELL_Z2.sqrt()
        }
    }

    pub fn z2(&self, simulated: f64) -> f64 {
        let z = self.z(simulated);
        z * z
    }
}

/// Data χ² of real walks (per condition).
pub fn chi2_of(obs: &[Observation], sims: &[SimMetrics]) -> (f64, Vec<f64>) {
    let mut per = vec![0.0; sims.len()];
    for o in obs {
        per[o.trial] += o.z2(sims[o.trial].get(o.metric));
    }
    (per.iter().sum(), per)
}

/// The χ² of a model on the surrogate as a function of its free knobs, in unit-interval
/// coordinates (what the solvers see). Leaving the unit box costs a steep quadratic wall
/// (the value is taken at the nearest point of the box), so unbounded solvers stay inside.
#[derive(Clone)]
pub struct Objective<'a> {
    pub surrogate: &'a Surrogate,
    pub knobs: &'a Knobs,
    pub obs: &'a [Observation],
    /// Free knobs (indices into `knobs`).
    pub active: &'a [usize],
    /// Values of the other knobs (None: nominal/off); the active entries are overwritten.
    pub base: &'a Point,
    pub correction: &'a Correction,
    /// Leave this condition out (a held-out refit).
    pub skip: Option<usize>,
    /// Count only this condition's observations (a group refit), if given.
    pub only: Option<&'a [bool]>,
    /// Add the prior charge (off for group refits, which test data only).
    pub with_prior: bool,
}

impl Objective<'_> {
    /// The full point of unit coordinates `s` of the active knobs.
    pub fn point(&self, s: &[f64]) -> Point {
        self.knobs.point_at(self.base, self.active, s)
    }

    /// Data χ² (per the skip/only selection) at a full point.
    pub fn data_chi2(&self, point: &[Option<f64>]) -> f64 {
        let mut chi2 = 0.0;
        for o in self.obs {
            if self.skip == Some(o.trial) || self.only.is_some_and(|m| !m[o.trial]) {
                continue;
            }
            let v = self
                .surrogate
                .predict(o.trial, o.metric, point, self.correction);
            chi2 += o.z2(v);
        }
        chi2
    }

    /// Data χ² of one condition at a full point.
    pub fn condition_chi2(&self, point: &[Option<f64>], cond: usize) -> f64 {
        self.obs
            .iter()
            .filter(|o| o.trial == cond)
            .map(|o| {
                o.z2(self
                    .surrogate
                    .predict(o.trial, o.metric, point, self.correction))
            })
            .sum()
    }

    /// The cost at unit coordinates `s` (any real numbers: outside [0, 1] the wall).
    pub fn value(&self, s: &[f64]) -> f64 {
        let p = self.point(s);
        let prior = if self.with_prior {
            self.knobs.prior_chi2(&p)
        } else {
            0.0
        };
        self.data_chi2(&p) + prior + wall(s)
    }
}

/// The steep quadratic wall outside the unit box (a solver's point is valued at the nearest
/// point of the box, plus this).
fn wall(s: &[f64]) -> f64 {
    s.iter()
        .map(|v| {
            let d = v - v.clamp(0.0, 1.0);
            1e4 * d * d
        })
        .sum()
}

/// The same problem on real walks: the χ² (data + prior) of the point at unit coordinates
/// `s` of the `active` knobs, the others at `base`, by `chi2_of_point` (walks through the
/// cache). For a model whose knobs interact where the surrogate's one-knob curves cannot
/// see it. A walk that fails stops the solver; its error is kept for the caller.
pub struct WalkedObjective<'a, F> {
    pub knobs: &'a Knobs,
    pub active: &'a [usize],
    pub base: &'a Point,
    pub chi2_of_point: F,
    pub error: std::sync::Mutex<Option<super::error::GapError>>,
}

impl<F> WalkedObjective<'_, F> {
    /// The point at unit coordinates `s` (clamped into the box).
    pub fn point(&self, s: &[f64]) -> Point {
        let clamped: Vec<f64> = s.iter().map(|v| v.clamp(0.0, 1.0)).collect();
        self.knobs.point_at(self.base, self.active, &clamped)
    }

    /// The error of the walk that stopped the solver, if one did.
    pub fn take_error(&self) -> Option<super::error::GapError> {
        self.error.lock().unwrap_or_else(|e| e.into_inner()).take()
    }
}

/// By reference: the solver owns its problem, the caller keeps the walk's error.
impl<F> CostFunction for &WalkedObjective<'_, F>
where
    F: Fn(&Point) -> Result<f64, super::error::GapError>,
{
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, s: &Self::Param) -> Result<f64, Error> {
        match (self.chi2_of_point)(&self.point(s)) {
            Ok(chi2) => Ok(chi2 + wall(s)),
            Err(e) => {
                *self.error.lock().unwrap_or_else(|e| e.into_inner()) = Some(e);
                Err(Error::msg("a walk failed"))
            }
        }
    }
}

impl CostFunction for Objective<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, s: &Self::Param) -> Result<f64, Error> {
        Ok(self.value(s))
    }
}
