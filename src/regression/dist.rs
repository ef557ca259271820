//! Thin wrappers over statrs distributions with the tail conventions smatr uses: the one
//! home of the project's distribution helpers (the gap diagnosis uses them too).
//!
//! Upper-tail p-values use survival functions rather than `1 - cdf` so that very
//! small p-values keep their precision (R's `1 - pf(...)` rounds them to 0).

use statrs::distribution::{Beta, ChiSquared, ContinuousCDF, FisherSnedecor, Normal, StudentsT};

use super::error::RegressionError;

fn numerical(what: &str) -> RegressionError {
    RegressionError::Numerical(format!("could not build {what} distribution"))
}

/// Checks a confidence level and returns it unchanged.
pub fn check_level(level: f64) -> Result<f64, RegressionError> {
    if level.is_finite() && level > 0.0 && level < 1.0 {
        Ok(level)
    } else {
        Err(RegressionError::InvalidLevel(level))
    }
}

/// Quantile of Student's t with `df` degrees of freedom.
pub fn t_quantile(p: f64, df: f64) -> Result<f64, RegressionError> {
    let t = StudentsT::new(0.0, 1.0, df).map_err(|_| numerical("Student t"))?;
    Ok(t.inverse_cdf(p))
}

/// Two-sided critical value t_{(1+level)/2, df}; its square is smatr's `qf(1 - alpha, 1, df)`.
pub fn t_critical(level: f64, df: f64) -> Result<f64, RegressionError> {
    t_quantile(0.5 + level / 2.0, df)
}

/// Two-sided p-value of a t statistic.
pub fn t_two_sided_p(t: f64, df: f64) -> Result<f64, RegressionError> {
    let dist = StudentsT::new(0.0, 1.0, df).map_err(|_| numerical("Student t"))?;
    Ok((2.0 * dist.sf(t.abs())).min(1.0))
}

/// Upper-tail probability of an F(d1, d2) statistic.
pub fn f_upper_p(f: f64, d1: f64, d2: f64) -> Result<f64, RegressionError> {
    let dist = FisherSnedecor::new(d1, d2).map_err(|_| numerical("F"))?;
    Ok(if f <= 0.0 { 1.0 } else { dist.sf(f) })
}

/// Upper-tail probability of a chi-squared statistic.
pub fn chi2_upper_p(x: f64, df: f64) -> Result<f64, RegressionError> {
    let dist = ChiSquared::new(df).map_err(|_| numerical("chi-squared"))?;
    Ok(if x <= 0.0 { 1.0 } else { dist.sf(x) })
}

/// `qchisq(level, 1)`, computed as the squared normal quantile because that is
/// exact and avoids an iterative gamma inversion.
pub fn chi2_1_critical(level: f64) -> Result<f64, RegressionError> {
    let z = normal_quantile(0.5 + level / 2.0)?;
    Ok(z * z)
}

fn standard_normal() -> Result<Normal, RegressionError> {
    Normal::new(0.0, 1.0).map_err(|_| numerical("normal"))
}

/// Standard normal quantile Φ⁻¹(p) (±∞ at p = 0, 1).
pub fn normal_quantile(p: f64) -> Result<f64, RegressionError> {
    Ok(standard_normal()?.inverse_cdf(p))
}

/// Standard normal distribution function Φ(z).
pub fn normal_cdf(z: f64) -> Result<f64, RegressionError> {
    Ok(standard_normal()?.cdf(z))
}

/// Clopper–Pearson (exact) one-sided upper confidence bound at `level` for a binomial
/// proportion with `k` successes in `n` trials: the p with P(X ≤ k | n, p) = 1 − level,
/// i.e. the (level) quantile of Beta(k + 1, n − k); 1 when k = n.
pub fn binomial_upper_bound(k: u64, n: u64, level: f64) -> Result<f64, RegressionError> {
    check_level(level)?;
    if n == 0 {
        return Err(RegressionError::Numerical(
            "a proportion of 0 trials".into(),
        ));
    }
    if k >= n {
        return Ok(1.0);
    }
    let b = Beta::new(k as f64 + 1.0, (n - k) as f64).map_err(|_| numerical("beta"))?;
    Ok(b.inverse_cdf(level))
}

/// Clopper–Pearson two-sided interval at `level` for `k` successes in `n` trials.
pub fn binomial_interval(k: u64, n: u64, level: f64) -> Result<[f64; 2], RegressionError> {
    check_level(level)?;
    if n == 0 {
        return Err(RegressionError::Numerical(
            "a proportion of 0 trials".into(),
        ));
    }
    let a = (1.0 - level) / 2.0;
    let lo = if k == 0 {
        0.0
    } else {
        Beta::new(k as f64, (n - k + 1) as f64)
            .map_err(|_| numerical("beta"))?
            .inverse_cdf(a)
    };
    let hi = if k >= n {
        1.0
    } else {
        Beta::new(k as f64 + 1.0, (n - k) as f64)
            .map_err(|_| numerical("beta"))?
            .inverse_cdf(1.0 - a)
    };
    Ok([lo, hi])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference values: R's `qbeta(0.95, 1, 300)` = 0.0099361 (close to the "rule of three"
    /// 3/n for k = 0) and `binom.test(3, 300)$conf.int` = [0.0020670, 0.0289445] (also
    /// scipy.stats.beta.ppf(0.025, 3, 298) and beta.ppf(0.975, 4, 297)).
    #[test]
    fn clopper_pearson_matches_r() {
        let u = binomial_upper_bound(0, 300, 0.95).expect("bound");
        assert!((u - 0.0099361).abs() < 1e-6, "{u}");
        let [lo, hi] = binomial_interval(3, 300, 0.95).expect("interval");
        assert!((lo - 0.0020670).abs() < 1e-6, "{lo}");
        assert!((hi - 0.0289445).abs() < 1e-6, "{hi}");
        assert_eq!(binomial_upper_bound(5, 5, 0.95).expect("k = n"), 1.0);
    }
}
