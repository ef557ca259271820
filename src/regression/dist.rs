//! Thin wrappers over statrs distributions with the tail conventions smatr uses.
//!
//! Upper-tail p-values use survival functions rather than `1 - cdf` so that very
//! small p-values keep their precision (R's `1 - pf(...)` rounds them to 0).

use statrs::distribution::{ChiSquared, ContinuousCDF, FisherSnedecor, Normal, StudentsT};

use super::error::RegressionError;

fn numerical(what: &str) -> RegressionError {
    RegressionError::Numerical(format!("could not build {what} distribution"))
}

/// Checks a confidence level and returns it unchanged.
pub(crate) fn check_level(level: f64) -> Result<f64, RegressionError> {
    if level.is_finite() && level > 0.0 && level < 1.0 {
        Ok(level)
    } else {
        Err(RegressionError::InvalidLevel(level))
    }
}

/// Quantile of Student's t with `df` degrees of freedom.
pub(crate) fn t_quantile(p: f64, df: f64) -> Result<f64, RegressionError> {
    let t = StudentsT::new(0.0, 1.0, df).map_err(|_| numerical("Student t"))?;
    Ok(t.inverse_cdf(p))
}

/// Two-sided critical value t_{(1+level)/2, df}; its square is smatr's `qf(1 - alpha, 1, df)`.
pub(crate) fn t_critical(level: f64, df: f64) -> Result<f64, RegressionError> {
    t_quantile(0.5 + level / 2.0, df)
}

/// Two-sided p-value of a t statistic.
pub(crate) fn t_two_sided_p(t: f64, df: f64) -> Result<f64, RegressionError> {
    let dist = StudentsT::new(0.0, 1.0, df).map_err(|_| numerical("Student t"))?;
    Ok((2.0 * dist.sf(t.abs())).min(1.0))
}

/// Upper-tail probability of an F(d1, d2) statistic.
pub(crate) fn f_upper_p(f: f64, d1: f64, d2: f64) -> Result<f64, RegressionError> {
    let dist = FisherSnedecor::new(d1, d2).map_err(|_| numerical("F"))?;
    Ok(if f <= 0.0 { 1.0 } else { dist.sf(f) })
}

/// Upper-tail probability of a chi-squared statistic.
pub(crate) fn chi2_upper_p(x: f64, df: f64) -> Result<f64, RegressionError> {
    let dist = ChiSquared::new(df).map_err(|_| numerical("chi-squared"))?;
    Ok(if x <= 0.0 { 1.0 } else { dist.sf(x) })
}

/// `qchisq(level, 1)`, computed as the squared normal quantile because that is
/// exact and avoids an iterative gamma inversion.
pub(crate) fn chi2_1_critical(level: f64) -> Result<f64, RegressionError> {
    let z = normal_quantile(0.5 + level / 2.0)?;
    Ok(z * z)
}

fn standard_normal() -> Result<Normal, RegressionError> {
    Normal::new(0.0, 1.0).map_err(|_| numerical("normal"))
}

/// Standard normal quantile Φ⁻¹(p) (±∞ at p = 0, 1).
pub(crate) fn normal_quantile(p: f64) -> Result<f64, RegressionError> {
    Ok(standard_normal()?.inverse_cdf(p))
}

/// Standard normal distribution function Φ(z).
pub(crate) fn normal_cdf(z: f64) -> Result<f64, RegressionError> {
    Ok(standard_normal()?.cdf(z))
}
