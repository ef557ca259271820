//! OLS, major axis (MA) and standardised major axis (SMA) line fits with the
//! confidence intervals of smatr's `line.cis` (Warton et al. 2006, Table 4).

use faer::Mat;
use faer::linalg::solvers::SolveLstsq;
use serde::Serialize;

use super::dist;
use super::error::RegressionError;
use super::moments::Moments;

/// Line-fitting method.
///
/// OLS predicts y from x; MA and SMA describe the bivariate scatter symmetrically
/// (residuals measured perpendicular to the line, or in standardised units), which is
/// what allometry needs when neither variable is a controlled predictor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Method {
    /// Ordinary least squares of y on x.
    #[serde(rename = "OLS")]
    Ols,
    /// Major axis: minimises squared perpendicular distances.
    #[serde(rename = "MA")]
    Ma,
    /// Standardised major axis (reduced major axis): slope sign(r)·s_y/s_x.
    #[serde(rename = "SMA")]
    Sma,
}

impl Method {
    /// The label smatr prints ("OLS", "MA", "SMA").
    pub fn label(self) -> &'static str {
        match self {
            Method::Ols => "OLS",
            Method::Ma => "MA",
            Method::Sma => "SMA",
        }
    }
}

/// A closed interval `[lower, upper]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Interval {
    /// Lower limit.
    pub lower: f64,
    /// Upper limit.
    pub upper: f64,
}

impl Interval {
    /// Builds an interval, ordering the limits.
    pub fn new(a: f64, b: f64) -> Self {
        if a <= b {
            Self { lower: a, upper: b }
        } else {
            Self { lower: b, upper: a }
        }
    }

    /// `centre ± half_width`.
    pub fn around(centre: f64, half_width: f64) -> Self {
        Self::new(centre - half_width, centre + half_width)
    }

    /// Applies a monotone increasing map to both limits (e.g. `10^v`).
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Self::new(f(self.lower), f(self.upper))
    }

    /// Whether `v` lies inside the interval (limits included).
    pub fn contains(&self, v: f64) -> bool {
        self.lower <= v && v <= self.upper
    }
}

/// A fitted line `y = intercept + b·x` with smatr's inference.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LineFit {
    /// Method used.
    pub method: Method,
    /// Number of points.
    pub n: usize,
    /// Residual degrees of freedom, n − 2.
    pub df: usize,
    /// Confidence level of the intervals (e.g. 0.95).
    pub level: f64,
    /// Slope.
    pub b: f64,
    /// Confidence interval of the slope. For MA, see `b_ci_inverted`.
    pub b_ci: Interval,
    /// Standard error of the slope (smatr's `sqrt(var.b)`).
    pub se_b: f64,
    /// MA only: the interval contains the vertical (the Y axis). `b_ci.lower` is
    /// then above `b_ci.upper` and the actual region is
    /// `[b_ci.lower, +∞) ∪ (−∞, b_ci.upper]`, as smatr warns.
    pub b_ci_inverted: bool,
    /// Intercept (elevation).
    pub intercept: f64,
    /// Confidence interval of the intercept, `a ± sqrt(var.a · F(1, n−2))`.
    pub intercept_ci: Interval,
    /// Standard error of the intercept.
    pub se_intercept: f64,
    /// Pearson correlation of x and y.
    pub r: f64,
    /// Coefficient of determination, r².
    pub r2: f64,
    /// Two-sided p-value of `cor.test(x, y)` (for OLS also the slope t-test).
    pub p_b_equals_0: f64,
    /// Variance of the y-residuals y − a − b·x, divided by n − 2.
    pub residual_variance: f64,
    /// Sufficient statistics of the data, kept for prediction and tests.
    pub moments: Moments,
}

impl LineFit {
    /// Value of the line at `x`.
    pub fn fitted(&self, x: f64) -> f64 {
        self.intercept + self.b * x
    }
}

/// Fits a line by `method` and computes smatr's confidence intervals at `level`.
///
/// OLS coefficients come from a QR least-squares solve on the design matrix
/// `[1, x]` (faer); MA and SMA come from the centred (co)variances.
pub fn fit_line(
    x: &[f64],
    y: &[f64],
    method: Method,
    level: f64,
) -> Result<LineFit, RegressionError> {
    dist::check_level(level)?;
    let m = Moments::from_xy(x, y, 3)?;
    let ols = if method == Method::Ols {
        Some(ols_qr(x, y)?)
    } else {
        None
    };
    fit_from_moments(&m, method, level, ols)
}

/// OLS coefficients `(intercept, slope)` and residual sum of squares via faer QR.
pub(crate) fn ols_qr(x: &[f64], y: &[f64]) -> Result<(f64, f64, f64), RegressionError> {
    let n = x.len();
    let design = Mat::from_fn(n, 2, |i, j| if j == 0 { 1.0 } else { x[i] });
    let rhs = Mat::from_fn(n, 1, |i, _| y[i]);
    let coef = design.qr().solve_lstsq(&rhs);
    let (a, b) = (coef[(0, 0)], coef[(1, 0)]);
    let rss: f64 = x
        .iter()
        .zip(y)
        .map(|(&xi, &yi)| (yi - a - b * xi).powi(2))
        .sum();
    if !(a.is_finite() && b.is_finite() && rss.is_finite()) {
        return Err(RegressionError::Numerical(
            "QR least squares produced non-finite coefficients".into(),
        ));
    }
    Ok((a, b, rss))
}

/// The point estimate of the slope from moments alone (used by tests and resampling).
pub(crate) fn slope_from_moments(m: &Moments, method: Method) -> Result<f64, RegressionError> {
    match method {
        Method::Ols => Ok(m.sxy / m.sxx),
        Method::Sma => {
            if m.sxy == 0.0 {
                return Err(RegressionError::ZeroCovariance { method: "SMA" });
            }
            Ok(m.sxy.signum() * (m.syy / m.sxx).sqrt())
        }
        Method::Ma => {
            if m.sxy == 0.0 {
                return Err(RegressionError::ZeroCovariance { method: "MA" });
            }
            // b = (fac + s) / 2Sxy with s = √(fac² + 4Sxy²). When Syy < Sxx (a shallow line)
            // fac + s cancels catastrophically; the conjugate form 2Sxy / (s − fac) is the
            // same number without the cancellation (found by the swap property test:
            // b ≈ 1e-4 lost five digits).
            let fac = m.syy - m.sxx;
            let s = (fac * fac + 4.0 * m.sxy * m.sxy).sqrt();
            if fac >= 0.0 {
                Ok((fac + s) / (2.0 * m.sxy))
            } else {
                Ok(2.0 * m.sxy / (s - fac))
            }
        }
    }
}

/// Residual variance of y − b·x about its mean, smatr's `var.res`.
pub(crate) fn residual_variance(m: &Moments, b: f64) -> f64 {
    ((m.syy - 2.0 * b * m.sxy + b * b * m.sxx) / m.df() as f64).max(0.0)
}

/// smatr's `var.b` for each method (line.cis / elev.test).
pub(crate) fn slope_variance(m: &Moments, method: Method, b: f64) -> f64 {
    let df = m.df() as f64;
    let var_res = residual_variance(m, b);
    match method {
        Method::Ols => var_res / m.sxx,
        Method::Sma => ((m.syy - m.sxy * m.sxy / m.sxx) / df / m.sxx).max(0.0),
        Method::Ma => {
            let var_fit = (b * b * m.syy + 2.0 * b * m.sxy + m.sxx) / df;
            if var_res == 0.0 {
                // Perfect fit: the Fisher-information variance tends to 0.
                0.0
            } else {
                (1.0 + b * b).powi(2) / df / (var_res / var_fit + var_fit / var_res - 2.0)
            }
        }
    }
}

pub(crate) fn fit_from_moments(
    m: &Moments,
    method: Method,
    level: f64,
    ols: Option<(f64, f64, f64)>,
) -> Result<LineFit, RegressionError> {
    let n = m.n;
    let df = m.df() as f64;
    let t_crit = dist::t_critical(level, df)?;
    let f_crit = t_crit * t_crit;
    let r = m.r();

    let (b, var_res) = match (method, ols) {
        (Method::Ols, Some((_, b, rss))) => (b, rss / df),
        _ => {
            let b = slope_from_moments(m, method)?;
            (b, residual_variance(m, b))
        }
    };
    let var_b = slope_variance(m, method, b);
    let mut b_ci_inverted = false;
    let b_ci = match method {
        Method::Ols => Interval::around(b, var_b.sqrt() * t_crit),
        Method::Sma => {
            // Warton et al. (2006) eq. for the SMA slope: b(√(B+1) ± √B), B = F(1−r²)/(n−2).
            let big_b = f_crit * (1.0 - r * r) / df;
            Interval::new(
                b * ((big_b + 1.0).sqrt() - big_b.sqrt()),
                b * ((big_b + 1.0).sqrt() + big_b.sqrt()),
            )
        }
        Method::Ma => {
            let fac = m.syy - m.sxx;
            let q = f_crit * (m.syy * m.sxx - m.sxy * m.sxy).max(0.0) / df;
            let disc = fac * fac + 4.0 * m.sxy * m.sxy - 4.0 * q;
            if disc < 0.0 {
                Interval {
                    lower: f64::NEG_INFINITY,
                    upper: f64::INFINITY,
                }
            } else {
                // fac + √disc, in the conjugate form when fac < 0 (see slope_from_moments).
                let num = if fac >= 0.0 {
                    fac + disc.sqrt()
                } else {
                    4.0 * (m.sxy * m.sxy - q) / (disc.sqrt() - fac)
                };
                let lower = num / 2.0 / (m.sxy + q.sqrt());
                let upper = num / 2.0 / (m.sxy - q.sqrt());
                if q > m.sxy * m.sxy && fac > 0.0 {
                    b_ci_inverted = true;
                    Interval { lower, upper }
                } else {
                    Interval::new(lower, upper)
                }
            }
        }
    };

    let intercept = match (method, ols) {
        (Method::Ols, Some((a, _, _))) => a,
        _ => m.mean_y - b * m.mean_x,
    };
    let var_a = var_res / n as f64 + var_b * m.mean_x * m.mean_x;
    let intercept_ci = Interval::around(intercept, (var_a * f_crit).sqrt());

    // cor.test: t = r √(df / (1 − r²)).
    let p_b_equals_0 = if r.abs() >= 1.0 {
        0.0
    } else {
        dist::t_two_sided_p(r * (df / (1.0 - r * r)).sqrt(), df)?
    };

    Ok(LineFit {
        method,
        n,
        df: m.df(),
        level,
        b,
        b_ci,
        se_b: var_b.sqrt(),
        b_ci_inverted,
        intercept,
        intercept_ci,
        se_intercept: var_a.sqrt(),
        r,
        r2: r * r,
        p_b_equals_0,
        residual_variance: var_res,
        moments: *m,
    })
}
