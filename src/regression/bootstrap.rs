//! Seeded case-resampling bootstrap with percentile intervals.
//!
//! Determinism: one ChaCha8 stream seeded from a `u64` and consumed in a fixed
//! order, so a seed reproduces the same replicates bit for bit on any platform.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::dist;
use super::error::RegressionError;
use super::line::{Interval, Method, fit_line, slope_from_moments};
use super::moments::Moments;

/// Settings of a bootstrap run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BootstrapConfig {
    /// Number of resamples to draw.
    pub replicates: usize,
    /// Seed of the ChaCha8 generator.
    pub seed: u64,
    /// Level of the percentile intervals.
    pub level: f64,
}

impl Default for BootstrapConfig {
    fn default() -> Self {
        Self {
            replicates: 2000,
            seed: 0,
            level: 0.95,
        }
    }
}

/// Bootstrap distribution summary for slope and intercept.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BootstrapResult {
    /// Method.
    pub method: Method,
    /// Sample size.
    pub n: usize,
    /// Configuration used.
    pub config: BootstrapConfig,
    /// Resamples that admitted a line; degenerate ones (e.g. all x equal) are
    /// skipped rather than redrawn so the random stream stays fixed.
    pub successful: usize,
    /// Slope of the full sample.
    pub b: f64,
    /// Intercept of the full sample.
    pub intercept: f64,
    /// Percentile interval of the slope (R `quantile` type 7).
    pub b_ci: Interval,
    /// Percentile interval of the intercept.
    pub intercept_ci: Interval,
    /// Standard deviation of the bootstrap slopes.
    pub se_b: f64,
    /// Standard deviation of the bootstrap intercepts.
    pub se_intercept: f64,
    /// Bootstrap slopes in draw order (not serialized; can be long).
    #[serde(skip)]
    pub b_samples: Vec<f64>,
    /// Bootstrap intercepts in draw order (not serialized).
    #[serde(skip)]
    pub intercept_samples: Vec<f64>,
}

/// Resamples (x, y) pairs with replacement and refits by `method`.
///
/// Resampled slopes use the closed-form estimators (for OLS, Sxy/Sxx, which equals
/// the QR solution) to avoid a factorisation per replicate.
pub fn bootstrap_line(
    x: &[f64],
    y: &[f64],
    method: Method,
    config: BootstrapConfig,
) -> Result<BootstrapResult, RegressionError> {
    dist::check_level(config.level)?;
    if config.replicates < 2 {
        return Err(RegressionError::InvalidArgument(format!(
            "bootstrap needs at least 2 replicates, got {}",
            config.replicates
        )));
    }
    let full = fit_line(x, y, method, config.level)?;
    let n = x.len();
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let mut xs = vec![0.0; n];
    let mut ys = vec![0.0; n];
    let mut b_samples = Vec::with_capacity(config.replicates);
    let mut intercept_samples = Vec::with_capacity(config.replicates);
    for _ in 0..config.replicates {
        for k in 0..n {
            let i = rng.random_range(0..n);
            xs[k] = x[i];
            ys[k] = y[i];
        }
        let Ok(m) = Moments::from_xy(&xs, &ys, 3) else {
            continue;
        };
        let Ok(b) = slope_from_moments(&m, method) else {
            continue;
        };
        b_samples.push(b);
        intercept_samples.push(m.mean_y - b * m.mean_x);
    }
    if b_samples.len() < 2 {
        return Err(RegressionError::Numerical(
            "fewer than 2 bootstrap resamples admitted a line".into(),
        ));
    }
    let lo = (1.0 - config.level) / 2.0;
    let hi = 1.0 - lo;
    Ok(BootstrapResult {
        method,
        n,
        config,
        successful: b_samples.len(),
        b: full.b,
        intercept: full.intercept,
        b_ci: Interval::new(quantile(&b_samples, lo), quantile(&b_samples, hi)),
        intercept_ci: Interval::new(
            quantile(&intercept_samples, lo),
            quantile(&intercept_samples, hi),
        ),
        se_b: std_dev(&b_samples),
        se_intercept: std_dev(&intercept_samples),
        b_samples,
        intercept_samples,
    })
}

/// Sample quantile with linear interpolation (R's default, type 7).
/// Returns NaN for an empty slice.
pub fn quantile(values: &[f64], p: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let h = (sorted.len() - 1) as f64 * p.clamp(0.0, 1.0);
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(sorted.len() - 1);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

fn std_dev(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}
