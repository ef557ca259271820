//! OLS prediction in log space, back-transformation to raw units with optional
//! retransformation-bias corrections, and inverse prediction.
//!
//! Why the corrections: if log10 y = a + b·log10 x + ε, then 10^(a + b·log10 x) is
//! the *median* of y at x, not its mean. The mean is larger by E[10^ε], estimated
//! either non-parametrically (Duan 1983 smearing: mean of 10^residual) or under
//! normal errors (lognormal: exp(σ²·ln(10)²/2)).

use serde::Serialize;

use super::dist;
use super::error::RegressionError;
use super::line::{Interval, LineFit, Method};
use super::power_law::PowerLawFit;

/// Prediction of y at a new x0 from an OLS line (all in the fitted scale).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OlsPrediction {
    /// The new x.
    pub x0: f64,
    /// Point estimate a + b·x0.
    pub fit: f64,
    /// Standard error of the fitted mean, s·√(1/n + (x0 − x̄)²/Sxx).
    pub se_mean: f64,
    /// Confidence interval of the mean response at x0.
    pub mean_ci: Interval,
    /// Standard error for a new observation, s·√(1 + 1/n + (x0 − x̄)²/Sxx).
    pub se_prediction: f64,
    /// Prediction interval for a single new observation at x0.
    pub prediction_interval: Interval,
    /// Residual degrees of freedom of the t quantile.
    pub df: usize,
    /// Confidence level.
    pub level: f64,
    /// Residual variance s² of the fit, needed for the lognormal correction.
    pub residual_variance: f64,
}

fn require_ols(fit: &LineFit, what: &str) -> Result<(), RegressionError> {
    if fit.method == Method::Ols {
        Ok(())
    } else {
        Err(RegressionError::InvalidArgument(format!(
            "{what} is defined for OLS fits only, got {}",
            fit.method.label()
        )))
    }
}

/// Predicts at `x0` with t-based mean and prediction intervals (R's
/// `predict.lm(..., interval = "confidence" | "prediction")`).
pub fn predict_ols(fit: &LineFit, x0: f64, level: f64) -> Result<OlsPrediction, RegressionError> {
    require_ols(fit, "prediction")?;
    dist::check_level(level)?;
    if !x0.is_finite() {
        return Err(RegressionError::InvalidArgument(format!(
            "x0 must be finite, got {x0}"
        )));
    }
    let m = &fit.moments;
    let t = dist::t_critical(level, fit.df as f64)?;
    let s2 = fit.residual_variance;
    let lever = 1.0 / m.n as f64 + (x0 - m.mean_x).powi(2) / m.sxx;
    let y_hat = fit.fitted(x0);
    let se_mean = (s2 * lever).sqrt();
    let se_prediction = (s2 * (1.0 + lever)).sqrt();
    Ok(OlsPrediction {
        x0,
        fit: y_hat,
        se_mean,
        mean_ci: Interval::around(y_hat, t * se_mean),
        se_prediction,
        prediction_interval: Interval::around(y_hat, t * se_prediction),
        df: fit.df,
        level,
        residual_variance: s2,
    })
}

/// Retransformation-bias correction applied when back-transforming 10^(log10 ŷ).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum BiasCorrection {
    /// No correction: the centre is the median of y.
    None,
    /// Duan's smearing estimator, factor = mean(10^residual).
    DuanSmearing {
        /// Multiplicative factor.
        factor: f64,
    },
    /// Normal-errors correction, factor = exp(σ²·ln(10)²/2).
    Lognormal {
        /// Multiplicative factor.
        factor: f64,
    },
}

impl BiasCorrection {
    /// Duan smearing factor from log10-scale residuals of the fit.
    pub fn duan(residuals_log10: &[f64]) -> Result<Self, RegressionError> {
        if residuals_log10.is_empty() || residuals_log10.iter().any(|r| !r.is_finite()) {
            return Err(RegressionError::InvalidArgument(
                "smearing needs a non-empty set of finite residuals".into(),
            ));
        }
        let factor = residuals_log10.iter().map(|r| 10f64.powf(*r)).sum::<f64>()
            / residuals_log10.len() as f64;
        Ok(Self::DuanSmearing { factor })
    }

    /// Lognormal factor from the log10-scale residual variance σ².
    pub fn lognormal(residual_variance_log10: f64) -> Result<Self, RegressionError> {
        if !(residual_variance_log10.is_finite() && residual_variance_log10 >= 0.0) {
            return Err(RegressionError::InvalidArgument(format!(
                "residual variance must be finite and ≥ 0, got {residual_variance_log10}"
            )));
        }
        let ln10 = std::f64::consts::LN_10;
        Ok(Self::Lognormal {
            factor: (residual_variance_log10 * ln10 * ln10 / 2.0).exp(),
        })
    }

    /// Multiplier applied to the median (1 for `None`).
    pub fn factor(&self) -> f64 {
        match *self {
            Self::None => 1.0,
            Self::DuanSmearing { factor } | Self::Lognormal { factor } => factor,
        }
    }
}

/// What the back-transformed centre estimates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CentreKind {
    /// Plain back-transform: the median of y at x0.
    Median,
    /// Bias-corrected: an estimate of the mean of y at x0.
    Mean,
}

/// A log10-space prediction mapped back to raw units.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BackTransformedPrediction {
    /// 10^fit × correction factor.
    pub centre: f64,
    /// Whether `centre` is a median or a bias-corrected mean.
    pub centre_is: CentreKind,
    /// The correction applied.
    pub correction: BiasCorrection,
    /// 10^fit: the median of y at x0.
    pub median: f64,
    /// 10^mean_ci: confidence interval of the median (quantiles survive monotone maps).
    pub median_ci: Interval,
    /// 10^prediction_interval: prediction interval of a new y at x0.
    pub prediction_interval: Interval,
}

/// Back-transforms a prediction made on log10 y.
pub fn back_transform(
    pred: &OlsPrediction,
    correction: BiasCorrection,
) -> BackTransformedPrediction {
    let pow10 = |v: f64| 10f64.powf(v);
    let median = pow10(pred.fit);
    BackTransformedPrediction {
        centre: median * correction.factor(),
        centre_is: match correction {
            BiasCorrection::None => CentreKind::Median,
            _ => CentreKind::Mean,
        },
        correction,
        median,
        median_ci: pred.mean_ci.map(pow10),
        prediction_interval: pred.prediction_interval.map(pow10),
    }
}

/// Predicts raw y at raw `x_raw` from an OLS power-law fit: log-space prediction
/// at log10(x_raw), then back-transformation with `correction`.
pub fn predict_power_law(
    fit: &PowerLawFit,
    x_raw: f64,
    level: f64,
    correction: BiasCorrection,
) -> Result<(OlsPrediction, BackTransformedPrediction), RegressionError> {
    if !(x_raw.is_finite() && x_raw > 0.0) {
        return Err(RegressionError::InvalidArgument(format!(
            "x must be finite and positive for a power law, got {x_raw}"
        )));
    }
    let pred = predict_ols(&fit.log_fit, x_raw.log10(), level)?;
    let back = back_transform(&pred, correction);
    Ok((pred, back))
}

/// Inverse prediction (calibration) from an OLS line: the x at which the mean
/// response equals `y0`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InversePrediction {
    /// Target mean response.
    pub y0: f64,
    /// Point estimate (y0 − a)/b.
    pub x0: f64,
    /// Fieller interval {x : |a + b·x − y0| ≤ t·se_mean(x)}; None when the slope is
    /// not significantly non-zero at `level`, as the set is then unbounded.
    pub x0_ci: Option<Interval>,
    /// Confidence level.
    pub level: f64,
}

/// Inverts the OLS line at `y0`, with a Fieller-type interval. This treats `y0`
/// as a target *mean* response, not a single new observation, and inverts the
/// y-on-x regression; it is not the x-on-y regression.
pub fn inverse_predict_ols(
    fit: &LineFit,
    y0: f64,
    level: f64,
) -> Result<InversePrediction, RegressionError> {
    require_ols(fit, "inverse prediction")?;
    dist::check_level(level)?;
    if !y0.is_finite() {
        return Err(RegressionError::InvalidArgument(format!(
            "y0 must be finite, got {y0}"
        )));
    }
    if fit.b == 0.0 {
        return Err(RegressionError::InvalidArgument(
            "a horizontal line cannot be inverted".into(),
        ));
    }
    let m = &fit.moments;
    let t = dist::t_critical(level, fit.df as f64)?;
    let k = t * t * fit.residual_variance;
    // With u = x − x̄ and d = y0 − ȳ the band condition is A·u² + B·u + C ≤ 0.
    let d = y0 - m.mean_y;
    let a_coef = fit.b * fit.b - k / m.sxx;
    let b_coef = -2.0 * fit.b * d;
    let c_coef = d * d - k / m.n as f64;
    let x0_ci = if a_coef > 0.0 {
        let disc = (b_coef * b_coef - 4.0 * a_coef * c_coef).max(0.0).sqrt();
        Some(Interval::new(
            m.mean_x + (-b_coef - disc) / (2.0 * a_coef),
            m.mean_x + (-b_coef + disc) / (2.0 * a_coef),
        ))
    } else {
        None
    };
    Ok(InversePrediction {
        y0,
        x0: (y0 - fit.intercept) / fit.b,
        x0_ci,
        level,
    })
}
