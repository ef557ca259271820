//! Influence diagnostics: OLS residuals, hat values, studentized residuals and
//! Cook's distance (as R's `hatvalues`, `rstandard`, `rstudent`,
//! `cooks.distance`), and leave-one-out slopes for any method.

use faer::Mat;
use serde::Serialize;

use super::error::RegressionError;
use super::line::{Method, fit_line, ols_qr};
use super::moments::Moments;

/// Per-point OLS diagnostics, in input order.
///
/// Entries are NaN where they are undefined: a point with leverage 1 (its
/// residual is forced to 0), or all studentized values of a perfect fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OlsDiagnostics {
    /// OLS intercept.
    pub intercept: f64,
    /// OLS slope.
    pub b: f64,
    /// Fitted values a + b·x.
    pub fitted: Vec<f64>,
    /// Raw residuals y − fitted.
    pub residuals: Vec<f64>,
    /// Diagonal of the hat matrix, from the thin Q factor of the design matrix.
    pub leverage: Vec<f64>,
    /// Internally studentized residuals e / (s·√(1 − h)).
    pub studentized_internal: Vec<f64>,
    /// Externally studentized residuals, using s with the point deleted.
    pub studentized_external: Vec<f64>,
    /// Cook's distance r²·h / (2·(1 − h)).
    pub cooks_distance: Vec<f64>,
}

/// Computes OLS influence diagnostics for the regression of `y` on `x`.
pub fn ols_diagnostics(x: &[f64], y: &[f64]) -> Result<OlsDiagnostics, RegressionError> {
    let m = Moments::from_xy(x, y, 3)?;
    let (a, b, rss) = ols_qr(x, y)?;
    let n = m.n;
    let p = 2.0;
    let design = Mat::from_fn(n, 2, |i, j| if j == 0 { 1.0 } else { x[i] });
    // H = Q Qᵀ for the thin Q of X, so h_i is the squared norm of row i of Q.
    let q = design.qr().compute_thin_Q();
    let leverage: Vec<f64> = (0..n)
        .map(|i| (q[(i, 0)].powi(2) + q[(i, 1)].powi(2)).min(1.0))
        .collect();
    let fitted: Vec<f64> = x.iter().map(|&xi| a + b * xi).collect();
    let residuals: Vec<f64> = y.iter().zip(&fitted).map(|(yi, fi)| yi - fi).collect();
    let df = n as f64 - p;
    let s = (rss / df).sqrt();
    let studentized_internal: Vec<f64> = residuals
        .iter()
        .zip(&leverage)
        .map(|(e, h)| undefined_if_nan(e / (s * (1.0 - h).sqrt())))
        .collect();
    let studentized_external = studentized_internal
        .iter()
        .map(|r| undefined_if_nan(r * ((df - 1.0) / (df - r * r)).sqrt()))
        .collect();
    let cooks_distance = studentized_internal
        .iter()
        .zip(&leverage)
        .map(|(r, h)| undefined_if_nan(r * r * h / (p * (1.0 - h))))
        .collect();
    Ok(OlsDiagnostics {
        intercept: a,
        b,
        fitted,
        residuals,
        leverage,
        studentized_internal,
        studentized_external,
        cooks_distance,
    })
}

/// The leave-one-out outlier rule: the points whose externally studentized residual in
/// the OLS fit of `y` on `x` exceeds `threshold` in magnitude, as (index, residual) in
/// input order. Fewer than 5 points, or data that admit no fit, give none: too few to call
/// one point unusual.
pub fn studentized_outliers(x: &[f64], y: &[f64], threshold: f64) -> Vec<(usize, f64)> {
    if x.len() < 5 {
        return Vec::new();
    }
    let Ok(d) = ols_diagnostics(x, y) else {
        return Vec::new();
    };
    d.studentized_external
        .iter()
        .enumerate()
        .filter(|(_, t)| t.is_finite() && t.abs() > threshold)
        .map(|(i, t)| (i, *t))
        .collect()
}

/// Maps ±∞ (from a zero denominator) to NaN so that every undefined entry is NaN.
fn undefined_if_nan(v: f64) -> f64 {
    if v.is_finite() { v } else { f64::NAN }
}

/// The fit with one point removed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeaveOneOut {
    /// Index of the dropped point.
    pub index: usize,
    /// Slope without the point (None if the reduced data admit no line).
    pub b_without: Option<f64>,
    /// b_without − b_full: how much this point pulls the slope.
    pub delta_b: Option<f64>,
    /// Intercept without the point.
    pub intercept_without: Option<f64>,
    /// r² without the point (the same for every method: the squared correlation).
    pub r2_without: Option<f64>,
}

/// Refits without each point in turn (any method); needs n ≥ 4 so that every
/// reduced sample still has n − 1 ≥ 3 points.
pub fn leave_one_out(
    x: &[f64],
    y: &[f64],
    method: Method,
) -> Result<Vec<LeaveOneOut>, RegressionError> {
    Moments::from_xy(x, y, 4)?;
    let full = fit_line(x, y, method, 0.95)?;
    let mut xs = Vec::with_capacity(x.len() - 1);
    let mut ys = Vec::with_capacity(x.len() - 1);
    Ok((0..x.len())
        .map(|index| {
            xs.clear();
            ys.clear();
            for j in (0..x.len()).filter(|&j| j != index) {
                xs.push(x[j]);
                ys.push(y[j]);
            }
            let reduced = fit_line(&xs, &ys, method, 0.95).ok();
            LeaveOneOut {
                index,
                b_without: reduced.as_ref().map(|f| f.b),
                delta_b: reduced.as_ref().map(|f| f.b - full.b),
                intercept_without: reduced.as_ref().map(|f| f.intercept),
                r2_without: reduced.as_ref().map(|f| f.r2),
            }
        })
        .collect())
}
