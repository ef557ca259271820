//! Hand-worked cases, closed forms, invariances and error handling of the
//! regression engine. Every expected number is derived in a comment from the
//! textbook formula (or is an exact property), never from running this crate.

use crate::common;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robot_survey::regression::{
    BiasCorrection, BootstrapConfig, CentreKind, Group, Method, RegressionError, back_transform,
    bca_interval, bootstrap_line, fit_line, fit_power_law, inverse_predict_ols, jackknife_line,
    leave_one_out, log10_checked, ols_diagnostics, predict_ols, predict_power_law, quantile,
    slope_com, slope_test,
};

#[track_caller]
fn close(actual: f64, expected: f64, tol: f64) {
    assert!(
        (actual - expected).abs() <= tol * expected.abs().max(1.0),
        "actual {actual:.17e} vs expected {expected:.17e}"
    );
}

/// Student t quantile t_{0.975, 3} (standard tables: 3.182446305...; R `qt(0.975, 3)`).
const T975_3: f64 = 3.182_446_305_284_263;

// The 5-point example used throughout:
//   x = 1..5, y = 2, 4, 5, 4, 5
//   x̄ = 3, ȳ = 4, dx = −2,−1,0,1,2, dy = −2,0,1,0,1
//   Sxx = 10, Syy = 6, Sxy = 6, r = 6/√60, r² = 0.6
const X5: [f64; 5] = [1.0, 2.0, 3.0, 4.0, 5.0];
const Y5: [f64; 5] = [2.0, 4.0, 5.0, 4.0, 5.0];

#[test]
fn ols_five_points_by_hand() {
    let f = fit_line(&X5, &Y5, Method::Ols, 0.95).unwrap();
    // b = Sxy/Sxx = 0.6, a = ȳ − b·x̄ = 4 − 1.8 = 2.2
    close(f.b, 0.6, 1e-14);
    close(f.intercept, 2.2, 1e-14);
    // fitted 2.8, 3.4, 4.0, 4.6, 5.2; residuals −0.8, 0.6, 1.0, −0.6, −0.2
    // RSS = 0.64 + 0.36 + 1 + 0.36 + 0.04 = 2.4 (= Syy − Sxy²/Sxx), s² = 2.4/3 = 0.8
    close(f.residual_variance, 0.8, 1e-14);
    // se(b) = √(s²/Sxx) = √0.08; se(a) = √(s²(1/n + x̄²/Sxx)) = √(0.8·1.1) = √0.88
    close(f.se_b, 0.08_f64.sqrt(), 1e-14);
    close(f.se_intercept, 0.88_f64.sqrt(), 1e-14);
    // 95% t-interval: 0.6 ± 3.1824463·√0.08 = [−0.30013175, 1.50013175]
    close(f.b_ci.lower, 0.6 - T975_3 * 0.08_f64.sqrt(), 1e-12);
    close(f.b_ci.upper, 0.6 + T975_3 * 0.08_f64.sqrt(), 1e-12);
    close(f.intercept_ci.lower, 2.2 - T975_3 * 0.88_f64.sqrt(), 1e-12);
    close(f.intercept_ci.upper, 2.2 + T975_3 * 0.88_f64.sqrt(), 1e-12);
    close(f.r2, 0.6, 1e-14);
    // slope t = 0.6/√0.08 = 2.1213; with 3 df that is p ≈ 0.124 (> 0.05), so the
    // interval must straddle 0.
    assert!(f.b_ci.contains(0.0));
    assert!(f.p_b_equals_0 > 0.05 && f.p_b_equals_0 < 0.2);
}

#[test]
fn sma_and_ma_five_points_closed_forms() {
    let sma = fit_line(&X5, &Y5, Method::Sma, 0.95).unwrap();
    // SMA: sign(r)·sy/sx = √(Syy/Sxx) = √0.6
    close(sma.b, 0.6_f64.sqrt(), 1e-14);
    close(sma.intercept, 4.0 - 3.0 * 0.6_f64.sqrt(), 1e-14);
    // SMA CI (Warton et al. 2006 Table 4): b(√(B+1) ± √B), B = t²(1 − r²)/(n − 2)
    let big_b = T975_3 * T975_3 * 0.4 / 3.0;
    close(
        sma.b_ci.lower,
        0.6_f64.sqrt() * ((big_b + 1.0).sqrt() - big_b.sqrt()),
        1e-12,
    );
    close(
        sma.b_ci.upper,
        0.6_f64.sqrt() * ((big_b + 1.0).sqrt() + big_b.sqrt()),
        1e-12,
    );

    let ma = fit_line(&X5, &Y5, Method::Ma, 0.95).unwrap();
    // MA: b = (Syy − Sxx + √((Syy − Sxx)² + 4Sxy²)) / (2Sxy) = (−4 + √160)/12
    close(ma.b, (-4.0 + 160.0_f64.sqrt()) / 12.0, 1e-14);
    // OLS ≤ MA ≤ SMA here since r > 0 and Syy < Sxx.
    assert!(0.6 < ma.b && ma.b < sma.b);
}

#[test]
fn exact_line_gives_exact_slope_for_every_method() {
    // y = 2x + 1 exactly.
    let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
    let y: Vec<f64> = x.iter().map(|v| 2.0 * v + 1.0).collect();
    for method in [Method::Ols, Method::Ma, Method::Sma] {
        let f = fit_line(&x, &y, method, 0.95).unwrap();
        close(f.b, 2.0, 1e-13);
        close(f.intercept, 1.0, 1e-13);
        close(f.r2, 1.0, 1e-14);
        assert_eq!(f.p_b_equals_0, 0.0);
        // No scatter: the intervals collapse onto the estimate.
        close(f.b_ci.lower, 2.0, 1e-6);
        close(f.b_ci.upper, 2.0, 1e-6);
        assert!(f.se_b < 1e-6);
    }
}

#[test]
fn negative_relation_sma_takes_sign_of_r() {
    // y = 10 − 3x + symmetric noise: Sxy < 0, so SMA = −sy/sx.
    let x = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let y = [7.5, 3.5, 1.5, -2.5, -4.5, -8.5];
    let f = fit_line(&x, &y, Method::Sma, 0.95).unwrap();
    let (mx, my) = (3.5, (7.5 + 3.5 + 1.5 - 2.5 - 4.5 - 8.5) / 6.0);
    let sxx: f64 = x.iter().map(|v| (v - mx) * (v - mx)).sum();
    let syy: f64 = y.iter().map(|v| (v - my) * (v - my)).sum();
    close(f.b, -(syy / sxx).sqrt(), 1e-13);
    assert!(f.b_ci.lower < f.b && f.b < f.b_ci.upper && f.b_ci.upper < 0.0);
}

#[test]
fn symmetric_scatter_about_the_diagonal() {
    // x = 1,2,3,4; y = 2,1,4,3: Sxx = Syy = 5, Sxy = 3.
    // SMA = √(5/5) = 1; MA = (0 + √(0 + 36))/6 = 1; OLS = 3/5.
    let x = [1.0, 2.0, 3.0, 4.0];
    let y = [2.0, 1.0, 4.0, 3.0];
    close(fit_line(&x, &y, Method::Sma, 0.95).unwrap().b, 1.0, 1e-14);
    close(fit_line(&x, &y, Method::Ma, 0.95).unwrap().b, 1.0, 1e-14);
    close(fit_line(&x, &y, Method::Ols, 0.95).unwrap().b, 0.6, 1e-14);
    // H0: slope = 1 holds exactly for SMA and MA (test correlation 0, p = 1).
    for method in [Method::Sma, Method::Ma] {
        let t = slope_test(&x, &y, method, 1.0).unwrap();
        close(t.test_correlation, 0.0, 1e-14);
        close(t.p_value, 1.0, 1e-12);
    }
}

#[test]
fn ols_slope_test_is_the_textbook_t_test() {
    // t = (b − b0)/se(b) = (0.6 − 0)/√0.08 = 2.1213203; F = t² = 4.5.
    let t = slope_test(&X5, &Y5, Method::Ols, 0.0).unwrap();
    close(t.t_statistic, 0.6 / 0.08_f64.sqrt(), 1e-12);
    close(t.f_statistic, 4.5, 1e-12);
    // b0 = 0.6 − t_{0.975,3}·se(b) lies exactly on the CI boundary → p = 0.05.
    let t = slope_test(&X5, &Y5, Method::Ols, 0.6 - T975_3 * 0.08_f64.sqrt()).unwrap();
    close(t.p_value, 0.05, 1e-9);
}

#[test]
fn leverage_studentized_and_cooks_by_hand() {
    let d = ols_diagnostics(&X5, &Y5).unwrap();
    // h_i = 1/n + dx²/Sxx = 0.2 + dx²/10 → 0.6, 0.3, 0.2, 0.3, 0.6
    for (h, e) in d.leverage.iter().zip([0.6, 0.3, 0.2, 0.3, 0.6]) {
        close(*h, e, 1e-13);
    }
    for (r, e) in d.residuals.iter().zip([-0.8, 0.6, 1.0, -0.6, -0.2]) {
        close(*r, e, 1e-13);
    }
    // r_i = e_i / (s√(1 − h_i)), s² = 0.8:
    //   r_1 = −0.8/√(0.8·0.4) = −√2,  r_3 = 1/√(0.8·0.8) = 1.25
    close(d.studentized_internal[0], -(2.0_f64.sqrt()), 1e-12);
    close(d.studentized_internal[2], 1.25, 1e-12);
    // External: r_i·√((n − p − 1)/(n − p − r_i²)); for i = 1: −√2·√(2/(3 − 2)) = −2
    close(d.studentized_external[0], -2.0, 1e-12);
    // Cook: r_i²·h_i/(p(1 − h_i)):
    //   D_1 = 2·0.6/(2·0.4) = 1.5, D_2 = (0.36/0.56)·0.3/1.4 = 27/196,
    //   D_3 = 1.5625·0.2/1.6 = 25/128, D_5 = (0.04/0.32)·0.6/0.8 = 3/32
    close(d.cooks_distance[0], 1.5, 1e-12);
    close(d.cooks_distance[1], 27.0 / 196.0, 1e-12);
    close(d.cooks_distance[2], 25.0 / 128.0, 1e-12);
    close(d.cooks_distance[4], 3.0 / 32.0, 1e-12);
    // Leverages of a line with intercept sum to p = 2.
    close(d.leverage.iter().sum::<f64>(), 2.0, 1e-12);
}

#[test]
fn prediction_intervals_by_hand() {
    let f = fit_line(&X5, &Y5, Method::Ols, 0.95).unwrap();
    // At x0 = x̄ = 3: ŷ = 4, se_mean = √(s²/n) = √0.16 = 0.4,
    // se_pred = √(s²(1 + 1/n)) = √0.96; PI = 4 ± 3.1824463·√0.96 = [0.88185, 7.11815]
    let p = predict_ols(&f, 3.0, 0.95).unwrap();
    close(p.fit, 4.0, 1e-13);
    close(p.se_mean, 0.4, 1e-13);
    close(p.se_prediction, 0.96_f64.sqrt(), 1e-13);
    close(
        p.prediction_interval.lower,
        4.0 - T975_3 * 0.96_f64.sqrt(),
        1e-12,
    );
    close(
        p.prediction_interval.upper,
        4.0 + T975_3 * 0.96_f64.sqrt(),
        1e-12,
    );
    close(p.mean_ci.lower, 4.0 - T975_3 * 0.4, 1e-12);
    // At x0 = 6 (extrapolation): lever = 1/5 + 9/10 = 1.1, ŷ = 5.8,
    // se_pred = √(0.8·2.1) = √1.68.
    let p = predict_ols(&f, 6.0, 0.95).unwrap();
    close(p.fit, 5.8, 1e-13);
    close(p.se_mean, 0.88_f64.sqrt(), 1e-13);
    close(p.se_prediction, 1.68_f64.sqrt(), 1e-13);
    close(
        p.prediction_interval.upper,
        5.8 + T975_3 * 1.68_f64.sqrt(),
        1e-12,
    );
}

#[test]
fn duan_smearing_and_lognormal_factors_by_hand() {
    // Residuals ±log10 2: smearing factor = (10^log10 2 + 10^−log10 2)/2 = (2 + 0.5)/2 = 1.25.
    let l2 = 2.0_f64.log10();
    let duan = BiasCorrection::duan(&[l2, -l2]).unwrap();
    close(duan.factor(), 1.25, 1e-14);
    // Residuals 0, 1, −1 (decades): (1 + 10 + 0.1)/3 = 3.7.
    close(
        BiasCorrection::duan(&[0.0, 1.0, -1.0]).unwrap().factor(),
        3.7,
        1e-14,
    );
    // Lognormal exp(σ²·ln²10/2): σ² = 0 → 1; σ² = 2/ln²10 → e.
    close(BiasCorrection::lognormal(0.0).unwrap().factor(), 1.0, 0.0);
    let ln10 = std::f64::consts::LN_10;
    close(
        BiasCorrection::lognormal(2.0 / (ln10 * ln10))
            .unwrap()
            .factor(),
        std::f64::consts::E,
        1e-14,
    );
    assert!(BiasCorrection::duan(&[]).is_err());
    assert!(BiasCorrection::duan(&[f64::NAN]).is_err());
    assert!(BiasCorrection::lognormal(-1.0).is_err());
}

#[test]
fn back_transform_scales_the_median() {
    // Power law y = 10·x² exactly on x = 1..5 except two points shifted by ×2 and ×½.
    let x = [1.0, 2.0, 3.0, 4.0, 5.0];
    let y = [10.0, 80.0, 90.0, 160.0, 250.0];
    let fit = fit_power_law(&x, &y, Method::Ols, 0.95).unwrap();
    let (pred, back) = predict_power_law(&fit, 3.0, 0.95, BiasCorrection::None).unwrap();
    // Median back-transform = 10^ŷ; intervals map through 10^v (monotone).
    close(back.median, 10f64.powf(pred.fit), 1e-13);
    close(back.centre, back.median, 0.0);
    assert_eq!(back.centre_is, CentreKind::Median);
    close(
        back.prediction_interval.lower,
        10f64.powf(pred.prediction_interval.lower),
        1e-13,
    );
    let corr = BiasCorrection::lognormal(pred.residual_variance).unwrap();
    let mean = back_transform(&pred, corr);
    assert_eq!(mean.centre_is, CentreKind::Mean);
    close(mean.centre, mean.median * corr.factor(), 1e-14);
    assert!(mean.centre > mean.median);
}

#[test]
fn inverse_prediction_inverts_the_line() {
    // Slope not significant (5-point example, t = 2.12 < 3.18): Fieller set unbounded.
    let f = fit_line(&X5, &Y5, Method::Ols, 0.95).unwrap();
    let inv = inverse_predict_ols(&f, 4.0, 0.95).unwrap();
    close(inv.x0, 3.0, 1e-13);
    assert!(inv.x0_ci.is_none());

    // Strong line: y ≈ 2x + 1. The Fieller limits are where the mean-response band
    // crosses y0: |a + b·x − y0| = t·se_mean(x).
    let x = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let y = [3.1, 4.9, 7.2, 8.8, 11.0, 13.1];
    let f = fit_line(&x, &y, Method::Ols, 0.95).unwrap();
    let inv = inverse_predict_ols(&f, 8.0, 0.95).unwrap();
    close(inv.x0, (8.0 - f.intercept) / f.b, 1e-13);
    let ci = inv.x0_ci.unwrap();
    assert!(ci.lower < inv.x0 && inv.x0 < ci.upper);
    for xb in [ci.lower, ci.upper] {
        let p = predict_ols(&f, xb, 0.95).unwrap();
        let t = (p.mean_ci.upper - p.fit) / p.se_mean;
        close((p.fit - 8.0).abs(), t * p.se_mean, 1e-9);
    }
}

#[test]
fn leave_one_out_matches_refit_without_point() {
    let loo = leave_one_out(&X5, &Y5, Method::Ols).unwrap();
    // Without point 3 (x=3, y=5): x = 1,2,4,5, y = 2,4,4,5: x̄ = 3, ȳ = 3.75,
    // Sxx = 10, Sxy = (−2)(−1.75) + (−1)(0.25) + (1)(0.25) + 2(1.25) = 6 → b = 0.6, Δb = 0.
    close(loo[2].b_without.unwrap(), 0.6, 1e-13);
    close(loo[2].delta_b.unwrap(), 0.0, 1e-12);
    // Without point 1 (x=1, y=2): x = 2..5, y = 4,5,4,5: x̄ = 3.5, ȳ = 4.5,
    // dx = −1.5,−0.5,0.5,1.5, dy = −0.5,0.5,−0.5,0.5: Sxx = 5,
    // Sxy = 0.75 − 0.25 − 0.25 + 0.75 = 1 → b = 0.2.
    close(loo[0].b_without.unwrap(), 0.2, 1e-13);
    close(loo[0].delta_b.unwrap(), 0.2 - 0.6, 1e-12);
}

// ------------------------------------------------------------------ bootstrap

fn normal_sample(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    // Box–Muller from a seeded ChaCha stream: y = 1 + 0.75x + ε, x ~ N(0,1), ε ~ N(0, 0.5²).
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut normal = move || {
        let u1: f64 = rng.random::<f64>().max(1e-300);
        let u2: f64 = rng.random();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let x: Vec<f64> = (0..n).map(|_| normal()).collect();
    let y: Vec<f64> = x.iter().map(|v| 1.0 + 0.75 * v + 0.5 * normal()).collect();
    (x, y)
}

#[test]
fn bootstrap_is_deterministic_per_seed() {
    let (x, y) = normal_sample(40, 7);
    let cfg = BootstrapConfig {
        replicates: 300,
        seed: 42,
        level: 0.95,
    };
    let a = bootstrap_line(&x, &y, Method::Sma, cfg).unwrap();
    let b = bootstrap_line(&x, &y, Method::Sma, cfg).unwrap();
    // Bit-identical, not merely close.
    assert_eq!(a.b_samples, b.b_samples);
    assert_eq!(a.intercept_samples, b.intercept_samples);
    assert_eq!(a.b_ci, b.b_ci);
    let c = bootstrap_line(&x, &y, Method::Sma, BootstrapConfig { seed: 43, ..cfg }).unwrap();
    assert_ne!(a.b_samples, c.b_samples);
    assert_eq!(a.successful, 300);
    assert!(a.b_ci.contains(a.b));
}

#[test]
fn bootstrap_percentile_ci_agrees_with_analytic_ci_for_large_n() {
    // With normal errors and n = 400 the case bootstrap should reproduce the t-interval
    // (OLS) and Warton's interval (SMA) to within sampling error of the quantiles.
    let (x, y) = normal_sample(400, 11);
    for method in [Method::Ols, Method::Sma, Method::Ma] {
        let fit = fit_line(&x, &y, method, 0.95).unwrap();
        let boot = bootstrap_line(
            &x,
            &y,
            method,
            BootstrapConfig {
                replicates: 2000,
                seed: 1,
                level: 0.95,
            },
        )
        .unwrap();
        let width = fit.b_ci.upper - fit.b_ci.lower;
        assert!(
            (boot.b_ci.lower - fit.b_ci.lower).abs() < 0.2 * width,
            "{method:?}"
        );
        assert!(
            (boot.b_ci.upper - fit.b_ci.upper).abs() < 0.2 * width,
            "{method:?}"
        );
        assert!((boot.se_b / fit.se_b - 1.0).abs() < 0.2, "{method:?}");
        assert!(boot.b_ci.contains(fit.b));
        // For a near-normal, unbiased estimator BCa's corrections are small (|z₀|, |a| ≪ 1)
        // and its interval lands near the analytic one too.
        let bca = boot.b_bca.expect("BCa defined");
        assert!(
            bca.z0.abs() < 0.2 && bca.acceleration.abs() < 0.05,
            "{method:?} {bca:?}"
        );
        assert!(
            (bca.interval.lower - fit.b_ci.lower).abs() < 0.2 * width
                && (bca.interval.upper - fit.b_ci.upper).abs() < 0.2 * width,
            "{method:?} {bca:?}"
        );
        assert!(!bca.extreme_endpoints);
    }
}

/// With replicates symmetric about the estimate (z₀ = Φ⁻¹(½) = 0) and antisymmetric
/// influence values (a = Σl³ = 0), BCa is the plain normal-scale-interpolated percentile
/// interval, symmetric about the estimate: lower + upper = 2·20.5.
#[test]
fn bca_without_bias_or_skew_is_symmetric() {
    let t: Vec<f64> = (1..=40).map(f64::from).collect();
    let l = [1.0, -1.0, 2.0, -2.0];
    let bca = bca_interval(&t, 20.5, &l, 0.95).unwrap();
    assert_eq!(bca.z0, 0.0);
    assert_eq!(bca.acceleration, 0.0);
    close(bca.interval.lower + bca.interval.upper, 41.0, 1e-12);
    // (R + 1)·0.025 = 1.025: between the 1st and 2nd order statistics.
    assert!(bca.interval.lower > 1.0 && bca.interval.lower < 2.0);
    // Every replicate above the estimate: the bias correction is infinite, an error.
    assert!(bca_interval(&t, 0.5, &l, 0.95).is_err());
    // All influence values zero: acceleration 0/0, an error.
    assert!(bca_interval(&t, 20.5, &[0.0; 4], 0.95).is_err());
}

/// Jackknife by downdating the moments equals refitting each leave-one-out sample.
#[test]
fn jackknife_downdate_equals_refits() {
    let (x, y) = normal_sample(25, 3);
    for method in [Method::Ols, Method::Sma, Method::Ma] {
        let (slopes, intercepts) = jackknife_line(&x, &y, method).unwrap();
        let without = |v: &[f64], i: usize| -> Vec<f64> { [&v[..i], &v[i + 1..]].concat() };
        for i in 0..x.len() {
            let f = fit_line(&without(&x, i), &without(&y, i), method, 0.95).unwrap();
            close(slopes[i], f.b, 1e-12);
            close(intercepts[i], f.intercept, 1e-12);
        }
    }
}

#[test]
fn quantile_type7_by_hand() {
    // R: quantile(c(1, 2, 3, 4), 0.25) = 1 + 0.75·(2 − 1) = 1.75 (type 7, h = 3·0.25).
    close(quantile(&[4.0, 1.0, 3.0, 2.0], 0.25), 1.75, 1e-15);
    close(quantile(&[4.0, 1.0, 3.0, 2.0], 1.0), 4.0, 0.0);
    assert!(quantile(&[], 0.5).is_nan());
}

// ------------------------------------------------------------------ errors

#[test]
fn errors_not_panics() {
    use RegressionError as E;
    let ok = [1.0, 2.0, 3.0, 4.0];
    assert!(matches!(
        fit_line(&[1.0, 2.0], &[1.0, 2.0], Method::Sma, 0.95),
        Err(E::TooFewPoints { needed: 3, got: 2 })
    ));
    assert!(matches!(
        fit_line(&[], &[], Method::Ols, 0.95),
        Err(E::TooFewPoints { .. })
    ));
    assert!(matches!(
        fit_line(&ok, &[1.0, 2.0, 3.0], Method::Ols, 0.95),
        Err(E::LengthMismatch { x_len: 4, y_len: 3 })
    ));
    assert!(matches!(
        fit_line(&[2.0; 4], &ok, Method::Ols, 0.95),
        Err(E::ZeroVariance { variable: "x" })
    ));
    assert!(matches!(
        fit_line(&ok, &[5.0; 4], Method::Sma, 0.95),
        Err(E::ZeroVariance { variable: "y" })
    ));
    assert!(matches!(
        fit_line(&ok, &[1.0, f64::NAN, 3.0, 4.0], Method::Ma, 0.95),
        Err(E::NonFinite {
            variable: "y",
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        fit_line(&ok, &ok, Method::Ols, 1.0),
        Err(E::InvalidLevel(_))
    ));
    // Uncorrelated: x = −1, 0, 1, 0; y = 0, 1, 0, −1 → Sxy = 0; SMA/MA undefined.
    let (xu, yu) = ([-1.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, -1.0]);
    assert!(matches!(
        fit_line(&xu, &yu, Method::Sma, 0.95),
        Err(E::ZeroCovariance { .. })
    ));
    assert!(matches!(
        fit_line(&xu, &yu, Method::Ma, 0.95),
        Err(E::ZeroCovariance { .. })
    ));
    assert!(fit_line(&xu, &yu, Method::Ols, 0.95).is_ok());
    // log10 of non-positive values names the index.
    assert!(matches!(
        log10_checked(&[1.0, 0.0, 3.0], "x"),
        Err(E::NonPositive {
            variable: "x",
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        fit_power_law(&ok, &[1.0, 2.0, -3.0, 4.0], Method::Sma, 0.95),
        Err(E::NonPositive {
            variable: "y",
            index: 2,
            ..
        })
    ));
    assert!(matches!(
        fit_power_law(&[1.0, f64::INFINITY, 3.0], &ok[..3], Method::Sma, 0.95),
        Err(E::NonFinite { .. })
    ));
    // Overflowing sums of squares.
    assert!(matches!(
        fit_line(&[1e200, -1e200, 3e200], &ok[..3], Method::Ols, 0.95),
        Err(E::Numerical(_))
    ));
    assert!(matches!(
        slope_test(&ok, &[1.0, 3.0, 2.0, 4.0], Method::Sma, f64::NAN),
        Err(E::InvalidArgument(_))
    ));
    assert!(matches!(
        leave_one_out(&ok[..3], &ok[..3], Method::Ols),
        Err(E::TooFewPoints { needed: 4, .. })
    ));
    assert!(matches!(
        bootstrap_line(
            &ok,
            &[1.0, 3.0, 2.0, 4.0],
            Method::Ols,
            BootstrapConfig {
                replicates: 0,
                ..Default::default()
            }
        ),
        Err(E::InvalidArgument(_))
    ));
    let sma = fit_line(&ok, &[1.0, 3.0, 2.0, 4.0], Method::Sma, 0.95).unwrap();
    assert!(matches!(
        predict_ols(&sma, 1.0, 0.95),
        Err(E::InvalidArgument(_))
    ));
    let ols = fit_line(&ok, &[1.0, 3.0, 2.0, 4.0], Method::Ols, 0.95).unwrap();
    assert!(predict_ols(&ols, f64::NAN, 0.95).is_err());
    assert!(inverse_predict_ols(&ols, f64::INFINITY, 0.95).is_err());
    // Multi-group: one group, or a group too small, is an error naming the group.
    let g_ok = Group {
        label: "a",
        x: &ok,
        y: &[1.0, 3.0, 2.0, 4.0],
    };
    assert!(matches!(
        slope_com(&[g_ok], Method::Sma, 0.95),
        Err(E::InvalidArgument(_))
    ));
    let g_small = Group {
        label: "tiny",
        x: &[1.0, 2.0],
        y: &[1.0, 2.0],
    };
    match slope_com(&[g_ok, g_small], Method::Sma, 0.95) {
        Err(E::InGroup { label, .. }) => assert_eq!(label, "tiny"),
        other => panic!("expected InGroup, got {other:?}"),
    }
}

// ------------------------------------------------------------------ properties

fn moments(x: &[f64], y: &[f64]) -> (f64, f64, f64) {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxx = x.iter().map(|v| (v - mx).powi(2)).sum();
    let syy = y.iter().map(|v| (v - my).powi(2)).sum();
    let sxy = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    (sxx, syy, sxy)
}

fn xy_strategy() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    (3usize..40).prop_flat_map(|n| {
        (
            prop::collection::vec(-100.0f64..100.0, n),
            prop::collection::vec(-100.0f64..100.0, n),
        )
    })
}

/// Regression: the MA slope of a shallow line lost digits to cancellation in
/// (Syy − Sxx) + √((Syy − Sxx)² + 4Sxy²) (CI, fresh machine, swap property test).
/// On the exact line y = 1e-6·x every fitting method must return 1e-6: the old
/// formula gave a relative error near ε/b² ≈ 1e-4.
#[test]
fn ma_slope_of_a_shallow_line_keeps_its_digits() {
    let x = [-100.0, -50.0, 0.0, 25.0, 50.0, 100.0];
    let y: Vec<f64> = x.iter().map(|v| 1e-6 * v).collect();
    for method in [Method::Ols, Method::Sma, Method::Ma] {
        let f = fit_line(&x, &y, method, 0.95).unwrap();
        close(f.b, 1e-6, 1e-6 * 1e-10);
        let swapped = fit_line(&y, &x, method, 0.95);
        if method != Method::Ols {
            close(swapped.unwrap().b, 1e6, 1e6 * 1e-10);
        }
    }
    // With scatter the MA interval of the shallow line still brackets its estimate,
    // and swapping x and y gives the reciprocal interval (Warton et al. 2006, MA is symmetric).
    let y: Vec<f64> = x
        .iter()
        .zip([1.0, -1.0, 0.5, -0.5, 1.0, -1.0])
        .map(|(v, e)| 1e-4 * v + 1e-4 * e)
        .collect();
    let xy = fit_line(&x, &y, Method::Ma, 0.95).unwrap();
    let yx = fit_line(&y, &x, Method::Ma, 0.95).unwrap();
    close(xy.b * yx.b, 1.0, 1e-12);
    assert!(xy.b_ci.lower < xy.b && xy.b < xy.b_ci.upper);
    close(xy.b_ci.lower * yx.b_ci.upper, 1.0, 1e-9);
    close(xy.b_ci.upper * yx.b_ci.lower, 1.0, 1e-9);
}

proptest! {
    #![proptest_config(common::reproducible_proptest(200))]

    /// OLS slope from faer's QR solve equals the closed form Sxy/Sxx.
    #[test]
    fn ols_qr_equals_closed_form((x, y) in xy_strategy()) {
        let (sxx, syy, sxy) = moments(&x, &y);
        prop_assume!(sxx > 1e-6 && syy > 1e-6);
        let f = fit_line(&x, &y, Method::Ols, 0.95).unwrap();
        let b = sxy / sxx;
        prop_assert!((f.b - b).abs() <= 1e-9 * (1.0 + b.abs()), "{} vs {}", f.b, b);
    }

    /// SMA and MA treat x and y symmetrically: swapping gives the reciprocal slope.
    #[test]
    fn sma_and_ma_swap_to_reciprocal((x, y) in xy_strategy()) {
        let (sxx, syy, sxy) = moments(&x, &y);
        prop_assume!(sxx > 1e-6 && syy > 1e-6 && sxy.abs() > 1e-6 * (sxx * syy).sqrt());
        for method in [Method::Sma, Method::Ma] {
            let xy = fit_line(&x, &y, method, 0.95).unwrap();
            let yx = fit_line(&y, &x, method, 0.95).unwrap();
            prop_assert!((xy.b * yx.b - 1.0).abs() < 1e-9, "{method:?}: {} · {}", xy.b, yx.b);
            // Both lines pass through the centroid, so they are the same line.
            prop_assert!((yx.intercept + xy.intercept / xy.b).abs()
                < 1e-7 * (1.0 + yx.intercept.abs()));
        }
        // SMA slope is sign(r)·sy/sx.
        let sma = fit_line(&x, &y, Method::Sma, 0.95).unwrap();
        prop_assert!((sma.b - sxy.signum() * (syy / sxx).sqrt()).abs() < 1e-9 * (1.0 + sma.b.abs()));
    }

    /// Testing the estimated slope itself gives p = 1 for SMA and MA (test correlation 0),
    /// and every CI contains its estimate.
    #[test]
    fn slope_test_at_estimate_is_null((x, y) in xy_strategy()) {
        let (sxx, syy, sxy) = moments(&x, &y);
        prop_assume!(sxx > 1e-6 && syy > 1e-6 && sxy.abs() > 1e-3 * (sxx * syy).sqrt());
        for method in [Method::Ols, Method::Sma, Method::Ma] {
            let f = fit_line(&x, &y, method, 0.95).unwrap();
            let t = slope_test(&x, &y, method, f.b).unwrap();
            prop_assert!(t.p_value > 1.0 - 1e-6, "{method:?} p = {}", t.p_value);
            if !f.b_ci_inverted {
                prop_assert!(f.b_ci.lower <= f.b && f.b <= f.b_ci.upper);
            }
            prop_assert!(f.intercept_ci.contains(f.intercept));
        }
    }

    /// Arbitrary, often degenerate input (NaN, ±∞, zeros, repeats, tiny n) never panics.
    #[test]
    fn no_panic_on_garbage(
        x in prop::collection::vec(prop_oneof![
            Just(0.0), Just(f64::NAN), Just(f64::INFINITY), Just(-1.0), Just(1.0), -1e3f64..1e3
        ], 0..8),
        y in prop::collection::vec(prop_oneof![
            Just(0.0), Just(f64::NAN), Just(1.0), Just(1e-300), -1e3f64..1e3
        ], 0..8),
        level in prop_oneof![Just(0.95), Just(0.0), Just(1.0), Just(f64::NAN), 0.0f64..1.0],
    ) {
        for method in [Method::Ols, Method::Ma, Method::Sma] {
            let _ = fit_line(&x, &y, method, level);
            let _ = fit_power_law(&x, &y, method, level);
            let _ = slope_test(&x, &y, method, 1.0);
            let _ = leave_one_out(&x, &y, method);
            let _ = bootstrap_line(&x, &y, method, BootstrapConfig { replicates: 5, seed: 0, level });
            let g = [Group { label: "a", x: &x, y: &y }, Group { label: "b", x: &y, y: &x }];
            let _ = slope_com(&g, method, level);
            let _ = robot_survey::regression::elev_com(&g, method, level);
        }
        let _ = ols_diagnostics(&x, &y);
        if let Ok(f) = fit_line(&x, &y, Method::Ols, 0.95) {
            let _ = predict_ols(&f, 2.0, level);
            let _ = inverse_predict_ols(&f, 2.0, level);
        }
    }
}

#[test]
fn spearman_matches_hand_values() {
    use robot_survey::regression::spearman;
    // Monotone: +1 / −1 whatever the spacing.
    assert!((spearman(&[1.0, 2.0, 3.0, 4.0], &[1.0, 10.0, 100.0, 1000.0]) - 1.0).abs() < 1e-12);
    assert!((spearman(&[1.0, 2.0, 3.0, 4.0], &[4.0, 3.0, 1.0, 0.5]) + 1.0).abs() < 1e-12);
    // Ranks x = 1..5, y = (2,1,4,3,5): Σd² = 4, ρ = 1 − 6·4/(5·24) = 0.8.
    let r = spearman(&[1.0, 2.0, 3.0, 4.0, 5.0], &[2.0, 1.0, 4.0, 3.0, 5.0]);
    assert!((r - 0.8).abs() < 1e-12, "{r}");
}
