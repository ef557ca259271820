//! Hypothesis tests about slopes and elevations, after smatr's `slope.test`,
//! `elev.test`, `slope.com` and `elev.com` (Warton et al. 2006, §IV–V; Warton &
//! Weber 2002).
//!
//! smatr itself offers no multi-group OLS tests; for OLS the classical ANCOVA
//! F-tests are used instead, which is what Warton et al. recommend for OLS.

use faer::Mat;
use faer::linalg::solvers::DenseSolveCore;
use serde::Serialize;

use super::dist;
use super::error::RegressionError;
use super::line::{Interval, LineFit, Method, fit_line, slope_from_moments};
use super::moments::Moments;

/// Test of H0: slope = `b0` for one sample.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SlopeTest {
    /// Method of the fitted line.
    pub method: Method,
    /// Hypothesised slope.
    pub b0: f64,
    /// Estimated slope.
    pub b: f64,
    /// Number of points.
    pub n: usize,
    /// The correlation whose nullity is equivalent to b = b0: cor(y − b0·x, x) for
    /// OLS, cor(y − b0·x, y + b0·x) for SMA (Pitman), and the MA analogue.
    pub test_correlation: f64,
    /// F = r²/(1 − r²)·(n − 2), on (1, n − 2) degrees of freedom.
    pub f_statistic: f64,
    /// Signed square root of F; for OLS this is the usual t = (b − b0)/se(b).
    pub t_statistic: f64,
    /// Denominator degrees of freedom, n − 2.
    pub df: usize,
    /// Two-sided p-value.
    pub p_value: f64,
}

/// Tests slope = `b0` exactly as smatr's `slope.test` does.
///
/// Because the test statistic is a correlation that vanishes under H0, its null
/// distribution is exact under bivariate normality, unlike a Wald test on b.
pub fn slope_test(
    x: &[f64],
    y: &[f64],
    method: Method,
    b0: f64,
) -> Result<SlopeTest, RegressionError> {
    if !b0.is_finite() {
        return Err(RegressionError::InvalidArgument(format!(
            "test slope must be finite, got {b0}"
        )));
    }
    let m = Moments::from_xy(x, y, 3)?;
    let b = slope_from_moments(&m, method)?;
    let (v11, v12, v22) = match method {
        Method::Ols => (
            m.syy - 2.0 * b0 * m.sxy + b0 * b0 * m.sxx,
            m.sxy - b0 * m.sxx,
            m.sxx,
        ),
        Method::Sma => (
            m.syy - 2.0 * b0 * m.sxy + b0 * b0 * m.sxx,
            m.syy - b0 * b0 * m.sxx,
            m.syy + 2.0 * b0 * m.sxy + b0 * b0 * m.sxx,
        ),
        Method::Ma => (
            m.syy - 2.0 * b0 * m.sxy + b0 * b0 * m.sxx,
            -b0 * b0 * m.sxy + b0 * (m.syy - m.sxx) + m.sxy,
            b0 * b0 * m.syy + 2.0 * b0 * m.sxy + m.sxx,
        ),
    };
    let denom = v11.sqrt() * v22.sqrt();
    // y − b0·x constant means the data lie exactly on the hypothesised line.
    let r_test = if denom > 0.0 {
        (v12 / denom).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let df = m.df();
    let f = if r_test.abs() >= 1.0 {
        f64::INFINITY
    } else {
        r_test * r_test / (1.0 - r_test * r_test) * df as f64
    };
    let p_value = if f.is_infinite() {
        0.0
    } else {
        dist::f_upper_p(f, 1.0, df as f64)?
    };
    Ok(SlopeTest {
        method,
        b0,
        b,
        n: m.n,
        test_correlation: r_test,
        f_statistic: f,
        t_statistic: r_test.signum() * f.sqrt(),
        df,
        p_value,
    })
}

/// Test of H0: intercept = `a0` for one sample (smatr `elev.test`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ElevationTest {
    /// Method of the fitted line.
    pub method: Method,
    /// Hypothesised intercept.
    pub a0: f64,
    /// Estimated intercept.
    pub intercept: f64,
    /// Its confidence interval at `level`.
    pub intercept_ci: Interval,
    /// Its standard error.
    pub se_intercept: f64,
    /// t = (a − a0)/se(a).
    pub t_statistic: f64,
    /// Degrees of freedom, n − 2.
    pub df: usize,
    /// Two-sided p-value.
    pub p_value: f64,
    /// Confidence level of `intercept_ci`.
    pub level: f64,
}

/// Tests intercept = `a0` with smatr's `elev.test` t statistic.
pub fn elev_test(
    x: &[f64],
    y: &[f64],
    method: Method,
    a0: f64,
    level: f64,
) -> Result<ElevationTest, RegressionError> {
    if !a0.is_finite() {
        return Err(RegressionError::InvalidArgument(format!(
            "test elevation must be finite, got {a0}"
        )));
    }
    let fit = fit_line(x, y, method, level)?;
    let t = (fit.intercept - a0) / fit.se_intercept;
    let p_value = if t.is_finite() {
        dist::t_two_sided_p(t, fit.df as f64)?
    } else if t.is_nan() {
        1.0
    } else {
        0.0
    };
    Ok(ElevationTest {
        method,
        a0,
        intercept: fit.intercept,
        intercept_ci: fit.intercept_ci,
        se_intercept: fit.se_intercept,
        t_statistic: t,
        df: fit.df,
        p_value,
        level,
    })
}

/// One sample of a multi-group comparison.
#[derive(Debug, Clone, Copy)]
pub struct Group<'a> {
    /// Name reported back in results and errors.
    pub label: &'a str,
    /// Explanatory variable (already transformed, e.g. log10).
    pub x: &'a [f64],
    /// Response variable (already transformed).
    pub y: &'a [f64],
}

/// Which test statistic a multi-group comparison reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TestKind {
    /// Bartlett-corrected likelihood ratio, chi-squared on `df` (smatr `slope.com`).
    LikelihoodRatio,
    /// Wald statistic, chi-squared on `df` (smatr `elev.com`).
    Wald,
    /// ANCOVA F statistic on (`df`, `df_den`) (OLS only).
    F,
}

/// Per-group line reported alongside a comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupLine {
    /// Group label.
    pub label: String,
    /// Group size.
    pub n: usize,
    /// Separate slope of this group.
    pub b: f64,
    /// Its confidence interval.
    pub b_ci: Interval,
}

/// Result of testing for a common slope among groups.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CommonSlopeTest {
    /// Method.
    pub method: Method,
    /// Confidence level of `b_ci`.
    pub level: f64,
    /// Common-slope estimate.
    pub b: f64,
    /// Confidence interval of the common slope (None if no sign change bracketed
    /// the likelihood-ratio limit).
    pub b_ci: Option<Interval>,
    /// Asymptotic variance of the common slope (smatr's `varb`).
    pub var_b: f64,
    /// Statistic type.
    pub test: TestKind,
    /// Test statistic of H0: all slopes equal.
    pub statistic: f64,
    /// (Numerator) degrees of freedom, g − 1.
    pub df: usize,
    /// Denominator degrees of freedom (F test only).
    pub df_den: Option<usize>,
    /// p-value.
    pub p_value: f64,
    /// Iterations of the common-slope fixed point (0 for OLS, closed form).
    pub iterations: usize,
    /// Separate per-group lines.
    pub groups: Vec<GroupLine>,
}

struct GroupStats {
    label: String,
    m: Moments,
    // smatr's z row: var(y), var(x), cov(x, y), with n − 1 divisors.
    z: [f64; 3],
}

fn group_stats(groups: &[Group<'_>]) -> Result<Vec<GroupStats>, RegressionError> {
    if groups.len() < 2 {
        return Err(RegressionError::InvalidArgument(format!(
            "a comparison needs at least 2 groups, got {}",
            groups.len()
        )));
    }
    groups
        .iter()
        .map(|g| {
            let m = Moments::from_xy(g.x, g.y, 3).map_err(|e| RegressionError::InGroup {
                label: g.label.to_string(),
                source: Box::new(e),
            })?;
            let d = (m.n - 1) as f64;
            Ok(GroupStats {
                label: g.label.to_string(),
                m,
                z: [m.syy / d, m.sxx / d, m.sxy / d],
            })
        })
        .collect()
}

fn group_lines(
    groups: &[Group<'_>],
    method: Method,
    level: f64,
) -> Result<Vec<GroupLine>, RegressionError> {
    groups
        .iter()
        .map(|g| {
            let fit = fit_line(g.x, g.y, method, level).map_err(|e| RegressionError::InGroup {
                label: g.label.to_string(),
                source: Box::new(e),
            })?;
            Ok(GroupLine {
                label: g.label.to_string(),
                n: fit.n,
                b: fit.b,
                b_ci: fit.b_ci,
            })
        })
        .collect()
}

/// Eigenvalue-like quantities (l1, l2) of one group at slope `b` (smatr `lr.b.com`).
fn l1_l2(method: Method, b: f64, z: &[f64; 3]) -> (f64, f64) {
    match method {
        Method::Sma => {
            let b = if b == 0.0 { 1e-6 } else { b };
            (
                (b * b * z[1] + 2.0 * b * z[2] + z[0]) / 2.0 / b.abs(),
                (b * b * z[1] - 2.0 * b * z[2] + z[0]) / 2.0 / b.abs(),
            )
        }
        // MA with error-variance ratio λ = 1.
        Method::Ma | Method::Ols => (
            (z[1] + 2.0 * b * z[2] + b * b * z[0]) / (1.0 + b * b),
            (b * b * z[1] - 2.0 * b * z[2] + z[0]) / (1.0 + b * b),
        ),
    }
}

/// Bartlett-corrected log-likelihood ratio Σ (n_i − 2.5)·log(l1b·l2b / (l1·l2)).
fn lr_statistic(method: Method, b: f64, stats: &[GroupStats], reference: &[(f64, f64)]) -> f64 {
    stats
        .iter()
        .zip(reference)
        .map(|(s, &(l1, l2))| {
            let (l1b, l2b) = l1_l2(method, b, &s.z);
            (s.m.df() as f64 - 0.5) * (l1b * l2b / l1 / l2).ln()
        })
        .sum()
}

/// Σ_i w_i·z_i over groups: smatr's `t(z) %*% wts`.
fn weighted_z(stats: &[GroupStats], weights: impl Iterator<Item = f64>) -> [f64; 3] {
    let mut zc = [0.0; 3];
    for (s, wi) in stats.iter().zip(weights) {
        for (acc, zk) in zc.iter_mut().zip(s.z) {
            *acc += zk * wi;
        }
    }
    zc
}

/// The maximum-likelihood common slope with the per-group (l1, l2) at it.
struct CommonSlope {
    b: f64,
    ls: Vec<(f64, f64)>,
    iterations: usize,
}

/// Common slope by smatr's `b.com.est` fixed point, iterated to a tighter tolerance
/// than smatr's 1e-6 so that the estimate is the actual maximum-likelihood value.
fn common_slope_ml(method: Method, stats: &[GroupStats]) -> Result<CommonSlope, RegressionError> {
    const MAX_ITER: usize = 1000;
    let mut zcom = weighted_z(stats, stats.iter().map(|s| (s.m.n - 1) as f64));
    let mut b_prev = 0.0;
    for iterations in 1..=MAX_ITER {
        if zcom[2] == 0.0 || !zcom.iter().all(|v| v.is_finite()) {
            return Err(RegressionError::ZeroCovariance {
                method: method.label(),
            });
        }
        let b = match method {
            Method::Sma => zcom[2].signum() * (zcom[0] / zcom[1]).sqrt(),
            _ => {
                let fac = zcom[0] - zcom[1];
                (fac + (fac * fac + 4.0 * zcom[2] * zcom[2]).sqrt()) / 2.0 / zcom[2]
            }
        };
        let ls: Vec<(f64, f64)> = stats.iter().map(|s| l1_l2(method, b, &s.z)).collect();
        let wts = ls.iter().zip(stats).map(|(&(l1, l2), s)| match method {
            Method::Sma => s.m.n as f64 * (1.0 / l2 + 1.0 / l1),
            _ => s.m.n as f64 * (1.0 / l2 - 1.0 / l1),
        });
        zcom = weighted_z(stats, wts);
        if (b - b_prev).abs() <= 1e-12 * b.abs().max(1.0) {
            return Ok(CommonSlope { b, ls, iterations });
        }
        b_prev = b;
    }
    Err(RegressionError::Numerical(
        "common-slope iteration did not converge".into(),
    ))
}

/// smatr's asymptotic variance of the common slope (`varb` in `slope.com`).
fn common_slope_variance(method: Method, b: f64, stats: &[GroupStats], ls: &[(f64, f64)]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (s, &(l1, l2)) in stats.iter().zip(ls) {
        let (var_bs, l12) = match method {
            Method::Sma => (
                4.0 * b * b / (l2 / l1 + l1 / l2 + 2.0),
                (l1 + l2).powi(2) / (l1 * l2),
            ),
            _ => (
                (1.0 + b * b).powi(2) / (l2 / l1 + l1 / l2 - 2.0),
                (l1 - l2).powi(2) / (l1 * l2),
            ),
        };
        let df = s.m.df() as f64;
        num += l12 * l12 * var_bs * df;
        den += l12 * df;
    }
    num / (den * den)
}

/// Root of `f` in `[lo, hi]` by bisection; `f(lo)` and `f(hi)` must differ in sign.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> Option<f64> {
    let mut f_lo = f(lo);
    let f_hi = f(hi);
    if !(f_lo.is_finite() && f_hi.is_finite()) || f_lo * f_hi > 0.0 {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let f_mid = f(mid);
        if f_mid == 0.0 || (hi - lo).abs() <= 1e-14 * mid.abs().max(1e-300) {
            return Some(mid);
        }
        if f_mid * f_lo < 0.0 {
            hi = mid;
        } else {
            lo = mid;
            f_lo = f_mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Likelihood-ratio confidence limits of the common slope (smatr `com.ci`, with
/// the same bracketing steps but bisected to full precision instead of
/// `uniroot(tol = 1e-4)`).
fn common_slope_ci(
    method: Method,
    b: f64,
    var_b: f64,
    crit: f64,
    stats: &[GroupStats],
    ls: &[(f64, f64)],
) -> Option<Interval> {
    let f = |bb: f64| lr_statistic(method, bb, stats, ls) - crit;
    let f_b = f(b);
    let limit = |sign: f64| -> Option<f64> {
        let steps = [
            2.0 * (crit * var_b).sqrt(),
            4.0 * (crit * var_b).sqrt(),
            8.0 * (crit * (var_b + 0.1)).sqrt(),
        ];
        let end = steps
            .iter()
            .map(|s| b + sign * s)
            .find(|&e| f(e) * f_b <= 0.0)?;
        let (lo, hi) = if sign < 0.0 { (end, b) } else { (b, end) };
        bisect(f, lo, hi)
    };
    Some(Interval::new(limit(-1.0)?, limit(1.0)?))
}

/// Tests whether all groups share one slope.
///
/// MA/SMA: smatr's `slope.com` — maximum-likelihood common slope, Bartlett-corrected
/// likelihood-ratio statistic on g − 1 df, likelihood-ratio CI. OLS: ANCOVA
/// F-test of the group × x interaction, pooled within-group slope with a t CI.
pub fn slope_com(
    groups: &[Group<'_>],
    method: Method,
    level: f64,
) -> Result<CommonSlopeTest, RegressionError> {
    dist::check_level(level)?;
    let stats = group_stats(groups)?;
    let lines = group_lines(groups, method, level)?;
    let g = stats.len();
    if method == Method::Ols {
        let sxx: f64 = stats.iter().map(|s| s.m.sxx).sum();
        let sxy: f64 = stats.iter().map(|s| s.m.sxy).sum();
        let syy: f64 = stats.iter().map(|s| s.m.syy).sum();
        let n_total: usize = stats.iter().map(|s| s.m.n).sum();
        let sse_separate: f64 = stats
            .iter()
            .map(|s| s.m.syy - s.m.sxy * s.m.sxy / s.m.sxx)
            .sum();
        let sse_common = syy - sxy * sxy / sxx;
        let df_sep = n_total - 2 * g;
        let df_com = n_total - g - 1;
        let b = sxy / sxx;
        let var_b = sse_common / df_com as f64 / sxx;
        let f = ((sse_common - sse_separate) / (g - 1) as f64 / (sse_separate / df_sep as f64))
            .max(0.0);
        let t = dist::t_critical(level, df_com as f64)?;
        return Ok(CommonSlopeTest {
            method,
            level,
            b,
            b_ci: Some(Interval::around(b, t * var_b.sqrt())),
            var_b,
            test: TestKind::F,
            statistic: f,
            df: g - 1,
            df_den: Some(df_sep),
            p_value: dist::f_upper_p(f, (g - 1) as f64, df_sep as f64)?,
            iterations: 0,
            groups: lines,
        });
    }
    let CommonSlope { b, ls, iterations } = common_slope_ml(method, &stats)?;
    // Under the alternative each group has its own slope: l1·l2 = det of its covariance.
    let separate: Vec<(f64, f64)> = stats
        .iter()
        .map(|s| (s.z[0] * s.z[1] - s.z[2] * s.z[2], 1.0))
        .collect();
    let lr = lr_statistic(method, b, &stats, &separate).max(0.0);
    let var_b = common_slope_variance(method, b, &stats, &ls);
    let crit = dist::chi2_1_critical(level)?;
    Ok(CommonSlopeTest {
        method,
        level,
        b,
        b_ci: common_slope_ci(method, b, var_b, crit, &stats, &ls),
        var_b,
        test: TestKind::LikelihoodRatio,
        statistic: lr,
        df: g - 1,
        df_den: None,
        p_value: dist::chi2_upper_p(lr, (g - 1) as f64)?,
        iterations,
        groups: lines,
    })
}

/// Elevation of one group given the common slope.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupElevation {
    /// Group label.
    pub label: String,
    /// Group size.
    pub n: usize,
    /// ȳ − b_common·x̄ of the group.
    pub elevation: f64,
    /// t-based confidence interval of the elevation.
    pub elevation_ci: Interval,
}

/// Result of testing for equal elevations among groups sharing a common slope.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ElevationComparison {
    /// Method.
    pub method: Method,
    /// Confidence level of the intervals.
    pub level: f64,
    /// Common slope used for the elevations.
    pub b_common: f64,
    /// Statistic type (Wald for MA/SMA, F for OLS).
    pub test: TestKind,
    /// Test statistic of H0: all elevations equal.
    pub statistic: f64,
    /// (Numerator) degrees of freedom, g − 1.
    pub df: usize,
    /// Denominator degrees of freedom (F test only).
    pub df_den: Option<usize>,
    /// p-value.
    pub p_value: f64,
    /// Common elevation: the precision-weighted mean of group elevations (MA/SMA,
    /// smatr), or the intercept of the pooled null-model line (OLS).
    pub elevation: f64,
    /// Confidence interval of the common elevation.
    pub elevation_ci: Interval,
    /// Per-group elevations.
    pub groups: Vec<GroupElevation>,
}

/// Tests for a shift in elevation among groups, assuming a common slope.
///
/// MA/SMA: smatr's `elev.com` Wald test, which accounts for the uncertainty of
/// the common slope through `var_b`. OLS: ANCOVA F-test of y ~ x + group
/// against y ~ x.
pub fn elev_com(
    groups: &[Group<'_>],
    method: Method,
    level: f64,
) -> Result<ElevationComparison, RegressionError> {
    dist::check_level(level)?;
    let stats = group_stats(groups)?;
    let g = stats.len();
    if method == Method::Ols {
        return elev_com_ols(groups, &stats, level);
    }
    let CommonSlope { b, ls, .. } = common_slope_ml(method, &stats)?;
    let var_b = common_slope_variance(method, b, &stats, &ls);

    let elevations: Vec<f64> = stats.iter().map(|s| s.m.mean_y - b * s.m.mean_x).collect();
    // Residual variance of y − b·x within each group, divisor n − 2.
    let var_res: Vec<f64> = stats
        .iter()
        .map(|s| (s.m.syy - 2.0 * b * s.m.sxy + b * b * s.m.sxx) / s.m.df() as f64)
        .collect();
    let cov_elev = Mat::from_fn(g, g, |i, j| {
        let diag = if i == j {
            var_res[i] / stats[i].m.n as f64
        } else {
            0.0
        };
        diag + var_b * stats[i].m.mean_x * stats[j].m.mean_x
    });

    // Contrasts a_1 − a_k, k = 2..g.
    let df = g - 1;
    let contrast = Mat::from_fn(df, g, |i, j| match j {
        0 => 1.0,
        _ if j == i + 1 => -1.0,
        _ => 0.0,
    });
    let la = Mat::from_fn(df, 1, |i, _| elevations[0] - elevations[i + 1]);
    let cov_contrast = &contrast * &cov_elev * contrast.transpose();
    let inv_contrast = cov_contrast.partial_piv_lu().inverse();
    let stat = (la.transpose() * &inv_contrast * &la)[(0, 0)];

    let inv_elev = cov_elev.partial_piv_lu().inverse();
    let (mut total, mut weighted) = (0.0, 0.0);
    for i in 0..g {
        for j in 0..g {
            total += inv_elev[(i, j)];
            weighted += inv_elev[(i, j)] * elevations[j];
        }
    }
    if !(stat.is_finite() && total.is_finite() && total > 0.0) {
        return Err(RegressionError::Numerical(
            "elevation covariance matrix is singular".into(),
        ));
    }
    let elevation = weighted / total;
    let crit = dist::chi2_1_critical(level)?;
    let group_rows = stats
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let t = dist::t_critical(level, s.m.df() as f64)?;
            Ok(GroupElevation {
                label: s.label.clone(),
                n: s.m.n,
                elevation: elevations[i],
                elevation_ci: Interval::around(elevations[i], t * cov_elev[(i, i)].sqrt()),
            })
        })
        .collect::<Result<Vec<_>, RegressionError>>()?;
    Ok(ElevationComparison {
        method,
        level,
        b_common: b,
        test: TestKind::Wald,
        statistic: stat,
        df,
        df_den: None,
        p_value: dist::chi2_upper_p(stat, df as f64)?,
        elevation,
        elevation_ci: Interval::around(elevation, (crit / total).sqrt()),
        groups: group_rows,
    })
}

fn elev_com_ols(
    groups: &[Group<'_>],
    stats: &[GroupStats],
    level: f64,
) -> Result<ElevationComparison, RegressionError> {
    let g = stats.len();
    let sxx: f64 = stats.iter().map(|s| s.m.sxx).sum();
    let sxy: f64 = stats.iter().map(|s| s.m.sxy).sum();
    let syy: f64 = stats.iter().map(|s| s.m.syy).sum();
    let n_total: usize = stats.iter().map(|s| s.m.n).sum();
    let b = sxy / sxx;
    let sse_common = syy - sxy * sxy / sxx;
    let df_den = n_total - g - 1;
    let s2 = sse_common / df_den as f64;

    let all_x: Vec<f64> = groups.iter().flat_map(|g| g.x.iter().copied()).collect();
    let all_y: Vec<f64> = groups.iter().flat_map(|g| g.y.iter().copied()).collect();
    let pooled: LineFit = fit_line(&all_x, &all_y, Method::Ols, level)?;
    let sse_pooled = pooled.residual_variance * pooled.df as f64;
    let f = ((sse_pooled - sse_common) / (g - 1) as f64 / s2).max(0.0);

    let t = dist::t_critical(level, df_den as f64)?;
    let group_rows = stats
        .iter()
        .map(|s| {
            let elevation = s.m.mean_y - b * s.m.mean_x;
            let se = (s2 * (1.0 / s.m.n as f64 + s.m.mean_x * s.m.mean_x / sxx)).sqrt();
            GroupElevation {
                label: s.label.clone(),
                n: s.m.n,
                elevation,
                elevation_ci: Interval::around(elevation, t * se),
            }
        })
        .collect();
    Ok(ElevationComparison {
        method: Method::Ols,
        level,
        b_common: b,
        test: TestKind::F,
        statistic: f,
        df: g - 1,
        df_den: Some(df_den),
        p_value: dist::f_upper_p(f, (g - 1) as f64, df_den as f64)?,
        elevation: pooled.intercept,
        elevation_ci: pooled.intercept_ci,
        groups: group_rows,
    })
}
