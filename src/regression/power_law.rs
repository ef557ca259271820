//! Power-law fits y = A·x^b on raw data, fitted as a line in log10–log10 space
//! (smatr's `log = "xy"`).

use serde::Serialize;

use super::error::RegressionError;
use super::line::{Interval, LineFit, Method, fit_line};
use super::moments::check_pairs;

/// A power law `y = A·x^b` with inference carried over from the log–log line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PowerLawFit {
    /// Method used for the log–log line.
    pub method: Method,
    /// Number of points.
    pub n: usize,
    /// Confidence level of the intervals.
    pub level: f64,
    /// Exponent (slope in log–log space).
    pub b: f64,
    /// Confidence interval of the exponent.
    pub b_ci: Interval,
    /// Standard error of the exponent.
    pub se_b: f64,
    /// log10 A (intercept in log–log space).
    pub log_a: f64,
    /// Confidence interval of log10 A.
    pub log_a_ci: Interval,
    /// Standard error of log10 A.
    pub se_log_a: f64,
    /// Prefactor A = 10^log_a. This is the back-transformed median line, not a mean.
    pub a: f64,
    /// 10^log_a_ci: a valid interval for A because 10^v is monotone.
    pub a_ci: Interval,
    /// r² of log10 y on log10 x.
    pub r2: f64,
    /// p-value of the log–log correlation test.
    pub p_b_equals_0: f64,
    /// The underlying log–log fit (x = log10 x_raw, y = log10 y_raw).
    pub log_fit: LineFit,
}

/// log10 of each value, rejecting non-finite and non-positive values by index.
pub fn log10_checked(values: &[f64], variable: &'static str) -> Result<Vec<f64>, RegressionError> {
    values
        .iter()
        .enumerate()
        .map(|(index, &value)| {
            if !value.is_finite() {
                Err(RegressionError::NonFinite {
                    variable,
                    index,
                    value,
                })
            } else if value <= 0.0 {
                Err(RegressionError::NonPositive {
                    variable,
                    index,
                    value,
                })
            } else {
                Ok(value.log10())
            }
        })
        .collect()
}

/// Fits `y_raw = A·x_raw^b` by `method` on log10-transformed data.
///
/// Unlike smatr, which silently drops non-positive rows, this refuses them and
/// names the index, so that a data-entry error cannot quietly shrink the sample.
pub fn fit_power_law(
    x_raw: &[f64],
    y_raw: &[f64],
    method: Method,
    level: f64,
) -> Result<PowerLawFit, RegressionError> {
    check_pairs(x_raw, y_raw, 3)?;
    let lx = log10_checked(x_raw, "x")?;
    let ly = log10_checked(y_raw, "y")?;
    let fit = fit_line(&lx, &ly, method, level)?;
    Ok(PowerLawFit::from_log_fit(fit))
}

impl PowerLawFit {
    /// Re-expresses a line fitted to (log10 x, log10 y) as a power law.
    pub fn from_log_fit(fit: LineFit) -> Self {
        Self {
            method: fit.method,
            n: fit.n,
            level: fit.level,
            b: fit.b,
            b_ci: fit.b_ci,
            se_b: fit.se_b,
            log_a: fit.intercept,
            log_a_ci: fit.intercept_ci,
            se_log_a: fit.se_intercept,
            a: 10f64.powf(fit.intercept),
            a_ci: fit.intercept_ci.map(|v| 10f64.powf(v)),
            r2: fit.r2,
            p_b_equals_0: fit.p_b_equals_0,
            log_fit: fit,
        }
    }

    /// Median of y at a raw x on the fitted power law, A·x^b.
    pub fn predict_median(&self, x_raw: f64) -> f64 {
        self.a * x_raw.powf(self.b)
    }
}
