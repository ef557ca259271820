//! The one likelihood every explanation is weighed by. Each observation (a trial's measured
//! metric, or a Fourier coefficient of its logged cycle) is Gaussian about the simulator's
//! value, with variance the measurement's sd² plus the model's own spread at that condition
//! and channel (`discrepancy.rs`): the spread of the simulator's own answer over
//! perturbed starts, estimated by walks, not tuned. A simulated walk that falls where the
//! robot walked charges [`FELL_Z2`].

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::simulate::Walked;
use super::trials::Metric;
use super::waveform::Signal;

/// z² charged to an observation whose simulated walk fell: a 100-sd miss. A fall predicts
/// that nothing could be measured, so it must never fit better than a walk that misses by
/// tens of sds.
pub const FELL_Z2: f64 = 1.0e4;

/// A group of observations of one kind: a summary metric, or one logged signal's cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Block {
    Metric(Metric),
    Cycle(Signal),
}

impl Block {
    pub fn words(self) -> String {
        match self {
            Block::Metric(m) => m.words().to_string(),
            Block::Cycle(s) => format!("{} cycle", s.column()),
        }
    }
}

/// One observation: a measured channel of a trial with its sd and the model's spread there.
#[derive(Clone, Copy, Debug)]
pub struct Observation {
    pub trial: usize,
    /// The channel of the trial's walks ([`Walked::channel`]).
    pub channel: usize,
    pub block: Block,
    pub value: f64,
    /// The measurement's sd.
    pub sd: f64,
    pub sd_assumed: bool,
    /// The model's own spread at this condition and channel (with, for a refined
    /// explanation, its surrogate's error there).
    pub model_sd: f64,
}

impl Observation {
    /// A summary metric's observation (no model spread yet).
    pub fn metric(trial: usize, m: Metric, value: f64, sd: f64, sd_assumed: bool) -> Self {
        Observation {
            trial,
            channel: m.index(),
            block: Block::Metric(m),
            value,
            sd,
            sd_assumed,
            model_sd: 0.0,
        }
    }

    /// The summary metric observed, if it is one.
    pub fn as_metric(&self) -> Option<Metric> {
        match self.block {
            Block::Metric(m) => Some(m),
            Block::Cycle(_) => None,
        }
    }

    /// The total sd: measurement and model spread in quadrature.
    pub fn total_sd(&self) -> f64 {
        self.sd.hypot(self.model_sd)
    }

    /// The signed residual (simulated − measured) / total sd; a fall's is √[`FELL_Z2`].
    pub fn z(&self, simulated: f64) -> f64 {
        if simulated.is_finite() {
            (simulated - self.value) / self.total_sd()
        } else {
            FELL_Z2.sqrt()
        }
    }

    pub fn z2(&self, simulated: f64) -> f64 {
        self.z(simulated).powi(2).min(FELL_Z2)
    }
}

/// −½ Σ ln(2π σᵢ²): the part of the Gaussian log-likelihood that does not depend on the
/// explanation, so that evidences of different data (with or without logs) are on one
/// scale.
pub fn log_normaliser(obs: &[Observation]) -> f64 {
    obs.iter()
        .map(|o| -0.5 * (2.0 * std::f64::consts::PI * o.total_sd().powi(2)).ln())
        .sum()
}

/// A standard normal draw by Box–Muller from ChaCha8 (rand_distr is not a dependency and
/// one transform does not justify one).
pub fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// χ² of real walks (indexed by trial).
pub fn chi2_of(obs: &[Observation], walks: &[Walked]) -> f64 {
    obs.iter()
        .map(|o| o.z2(walks[o.trial].channel(o.channel)))
        .sum()
}
