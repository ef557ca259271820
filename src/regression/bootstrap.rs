//! Seeded case-resampling bootstrap with percentile and BCa intervals.
//!
//! BCa (bias-corrected and accelerated; Efron 1987, DiCiccio & Efron 1996) follows R's
//! `boot` package exactly (`boot.ci(type = "bca")`: bias correction from the share of
//! replicates below the estimate, acceleration from jackknife influence values, endpoints
//! interpolated on the normal-quantile scale), so its numbers can be checked against R.
//!
//! Determinism: one ChaCha8 stream seeded from a `u64` and consumed in a fixed
//! order, so a seed reproduces the same replicates bit for bit on any platform.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use super::dist::{self, normal_cdf, normal_quantile};
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
    /// BCa interval of the slope (None when undefined, e.g. every replicate on one side
    /// of the estimate; the percentile interval still holds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b_bca: Option<BcaInterval>,
    /// BCa interval of the intercept.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intercept_bca: Option<BcaInterval>,
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
    // Percentile and BCa endpoints are both order statistics: sort each set once. Every
    // replicate is finite (slope_from_moments refused the degenerate resamples).
    let b_sorted = sorted(&b_samples);
    let intercept_sorted = sorted(&intercept_samples);
    // BCa needs the jackknife (n ≥ 4 so each leave-one-out sample still has a line).
    let (b_bca, intercept_bca) = match jackknife_line(x, y, method) {
        Ok((jb, ja)) => (
            bca_of_sorted(
                &b_sorted,
                full.b,
                &jackknife_influence(&jb, full.b),
                config.level,
            )
            .ok(),
            bca_of_sorted(
                &intercept_sorted,
                full.intercept,
                &jackknife_influence(&ja, full.intercept),
                config.level,
            )
            .ok(),
        ),
        Err(_) => (None, None),
    };
    Ok(BootstrapResult {
        method,
        n,
        config,
        successful: b_samples.len(),
        b: full.b,
        intercept: full.intercept,
        b_ci: Interval::new(
            quantile_of_sorted(&b_sorted, lo),
            quantile_of_sorted(&b_sorted, hi),
        ),
        intercept_ci: Interval::new(
            quantile_of_sorted(&intercept_sorted, lo),
            quantile_of_sorted(&intercept_sorted, hi),
        ),
        b_bca,
        intercept_bca,
        se_b: std_dev(&b_samples),
        se_intercept: std_dev(&intercept_samples),
        b_samples,
        intercept_samples,
    })
}

/// A BCa interval with its two adjustments.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BcaInterval {
    /// The interval at the requested level.
    pub interval: Interval,
    /// Bias correction z₀ = Φ⁻¹(share of replicates below the estimate).
    pub z0: f64,
    /// Acceleration a = Σl³ / (6 (Σl²)^{3/2}) from the influence values l.
    pub acceleration: f64,
    /// An endpoint fell on the smallest or largest replicate (R warns "extreme order
    /// statistics used as endpoints"): draw more replicates.
    pub extreme_endpoints: bool,
}

/// Leave-one-out estimates of the slope and intercept of `method`, by downdating the
/// moments (O(n) in all, not O(n²)): removing point i changes Sxx by −n/(n−1)·(xᵢ − x̄)²,
/// and likewise Syy and Sxy.
pub fn jackknife_line(
    x: &[f64],
    y: &[f64],
    method: Method,
) -> Result<(Vec<f64>, Vec<f64>), RegressionError> {
    let m = Moments::from_xy(x, y, 4)?;
    let n = m.n as f64;
    let shrink = n / (n - 1.0);
    let mut slopes = Vec::with_capacity(m.n);
    let mut intercepts = Vec::with_capacity(m.n);
    for (&xi, &yi) in x.iter().zip(y) {
        let (dx, dy) = (xi - m.mean_x, yi - m.mean_y);
        let without = Moments {
            n: m.n - 1,
            mean_x: m.mean_x - dx / (n - 1.0),
            mean_y: m.mean_y - dy / (n - 1.0),
            sxx: (m.sxx - shrink * dx * dx).max(0.0),
            syy: (m.syy - shrink * dy * dy).max(0.0),
            sxy: m.sxy - shrink * dx * dy,
        };
        if without.sxx == 0.0 {
            return Err(RegressionError::Numerical(
                "a leave-one-out sample has constant x".into(),
            ));
        }
        let b = slope_from_moments(&without, method)?;
        slopes.push(b);
        intercepts.push(without.mean_y - b * without.mean_x);
    }
    Ok((slopes, intercepts))
}

/// Jackknife influence values lᵢ = (n − 1)(θ̂ − θ̂₋ᵢ) (Davison & Hinkley 1997, eq. 2.35;
/// R `boot::empinf(type = "jack")`).
pub fn jackknife_influence(leave_one_out: &[f64], estimate: f64) -> Vec<f64> {
    let n1 = leave_one_out.len() as f64 - 1.0;
    leave_one_out.iter().map(|t| n1 * (estimate - t)).collect()
}

/// The BCa interval at `level` from bootstrap `replicates` of an `estimate` and its
/// `influence` values, as R's `boot:::bca.ci` (boot 1.3-28).
pub fn bca_interval(
    replicates: &[f64],
    estimate: f64,
    influence: &[f64],
    level: f64,
) -> Result<BcaInterval, RegressionError> {
    let finite: Vec<f64> = replicates
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    bca_of_sorted(&sorted(&finite), estimate, influence, level)
}

/// [`bca_interval`] of finite replicates already in ascending order.
fn bca_of_sorted(
    t: &[f64],
    estimate: f64,
    influence: &[f64],
    level: f64,
) -> Result<BcaInterval, RegressionError> {
    dist::check_level(level)?;
    if t.len() < 2 {
        return Err(RegressionError::InvalidArgument(
            "BCa needs at least 2 finite replicates".into(),
        ));
    }
    let below = t.iter().filter(|&&v| v < estimate).count();
    let z0 = normal_quantile(below as f64 / t.len() as f64)?;
    if !z0.is_finite() {
        return Err(RegressionError::Numerical(
            "BCa bias correction is infinite: every replicate lies on one side of the estimate"
                .into(),
        ));
    }
    let (s2, s3) = influence
        .iter()
        .fold((0.0, 0.0), |(s2, s3), l| (s2 + l * l, s3 + l * l * l));
    let acceleration = s3 / (6.0 * s2.powf(1.5));
    if !acceleration.is_finite() {
        return Err(RegressionError::Numerical(
            "BCa acceleration is undefined (all influence values are zero)".into(),
        ));
    }
    let mut ends = [0.0; 2];
    let mut extreme_endpoints = false;
    for (end, alpha) in ends
        .iter_mut()
        .zip([(1.0 - level) / 2.0, (1.0 + level) / 2.0])
    {
        let z = z0 + normal_quantile(alpha)?;
        let adjusted = normal_cdf(z0 + z / (1.0 - acceleration * z))?;
        let (value, extreme) = normal_interpolated_quantile(t, adjusted)?;
        *end = value;
        extreme_endpoints |= extreme;
    }
    Ok(BcaInterval {
        interval: Interval::new(ends[0], ends[1]),
        z0,
        acceleration,
        extreme_endpoints,
    })
}

/// The `alpha` quantile of sorted replicates by interpolation on the normal-quantile scale
/// between order statistics k and k + 1 of R, k = ⌊(R + 1)α⌋ (Davison & Hinkley 1997,
/// eq. 5.8; R `boot:::norm.inter`). Returns the value and whether an extreme order
/// statistic was used. Hand-written: no Rust crate implements this convention.
fn normal_interpolated_quantile(
    sorted: &[f64],
    alpha: f64,
) -> Result<(f64, bool), RegressionError> {
    let r = sorted.len();
    let rk = (r as f64 + 1.0) * alpha;
    let extreme = !(rk > 1.0 && rk < r as f64);
    let k = rk.trunc() as usize;
    let value = if k == 0 {
        sorted[0]
    } else if k >= r {
        sorted[r - 1]
    } else if k as f64 == rk {
        sorted[k - 1]
    } else {
        let rp1 = r as f64 + 1.0;
        let za = normal_quantile(alpha)?;
        let zk = normal_quantile(k as f64 / rp1)?;
        let zk1 = normal_quantile((k as f64 + 1.0) / rp1)?;
        let (tk, tk1) = (sorted[k - 1], sorted[k]);
        tk + (za - zk) / (zk1 - zk) * (tk1 - tk)
    };
    Ok((value, extreme))
}

/// Sample quantile with linear interpolation (R's default, type 7).
/// Returns NaN for an empty slice.
pub fn quantile(values: &[f64], p: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    quantile_of_sorted(&sorted(values), p)
}

/// [`quantile`] of a non-empty slice already in ascending order.
fn quantile_of_sorted(sorted: &[f64], p: f64) -> f64 {
    let h = (sorted.len() - 1) as f64 * p.clamp(0.0, 1.0);
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(sorted.len() - 1);
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// A copy in ascending order (`total_cmp`: NaN last, never a panic).
fn sorted(values: &[f64]) -> Vec<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v
}

fn std_dev(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}
