//! Input validation and centred second moments, the sufficient statistics of
//! every bivariate line fit here (Warton et al. 2006, Table 3).

use serde::Serialize;

use super::error::RegressionError;

/// Means and centred sums of squares/products of a bivariate sample.
///
/// Computed in two passes (mean first, then centred sums) so that data with a
/// large offset, such as log-masses around 3, do not lose precision.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Moments {
    /// Number of points.
    pub n: usize,
    /// Mean of x.
    pub mean_x: f64,
    /// Mean of y.
    pub mean_y: f64,
    /// Σ (x − x̄)².
    pub sxx: f64,
    /// Σ (y − ȳ)².
    pub syy: f64,
    /// Σ (x − x̄)(y − ȳ).
    pub sxy: f64,
}

impl Moments {
    /// Validates `x`, `y` (equal length, finite, at least `min_n` points, both
    /// non-constant) and computes their moments.
    pub fn from_xy(x: &[f64], y: &[f64], min_n: usize) -> Result<Self, RegressionError> {
        check_pairs(x, y, min_n)?;
        let n = x.len();
        let nf = n as f64;
        let mean_x = x.iter().sum::<f64>() / nf;
        let mean_y = y.iter().sum::<f64>() / nf;
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        for (&xi, &yi) in x.iter().zip(y) {
            let dx = xi - mean_x;
            let dy = yi - mean_y;
            sxx += dx * dx;
            syy += dy * dy;
            sxy += dx * dy;
        }
        let m = Self {
            n,
            mean_x,
            mean_y,
            sxx,
            syy,
            sxy,
        };
        if ![mean_x, mean_y, sxx, syy, sxy]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(RegressionError::Numerical(
                "sums of squares overflowed; rescale the data".into(),
            ));
        }
        if is_constant(sxx, x) {
            return Err(RegressionError::ZeroVariance { variable: "x" });
        }
        if is_constant(syy, y) {
            return Err(RegressionError::ZeroVariance { variable: "y" });
        }
        Ok(m)
    }

    /// Residual degrees of freedom of a line with intercept.
    pub fn df(&self) -> usize {
        self.n - 2
    }

    /// Pearson correlation coefficient.
    pub fn r(&self) -> f64 {
        (self.sxy / (self.sxx.sqrt() * self.syy.sqrt())).clamp(-1.0, 1.0)
    }
}

/// A spread at the level of rounding noise counts as zero variance: a line
/// through such data is not identifiable and the QR factor would be singular.
fn is_constant(centred_ss: f64, v: &[f64]) -> bool {
    let scale = v.iter().fold(0.0_f64, |m, &a| m.max(a.abs()));
    centred_ss <= v.len() as f64 * (4.0 * f64::EPSILON * scale).powi(2)
}

/// Checks lengths, sample size and finiteness, naming the first bad index.
pub(crate) fn check_pairs(x: &[f64], y: &[f64], min_n: usize) -> Result<(), RegressionError> {
    if x.len() != y.len() {
        return Err(RegressionError::LengthMismatch {
            x_len: x.len(),
            y_len: y.len(),
        });
    }
    if x.len() < min_n {
        return Err(RegressionError::TooFewPoints {
            needed: min_n,
            got: x.len(),
        });
    }
    for (variable, values) in [("x", x), ("y", y)] {
        if let Some((index, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(RegressionError::NonFinite {
                variable,
                index,
                value,
            });
        }
    }
    Ok(())
}
