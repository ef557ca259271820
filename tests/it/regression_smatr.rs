//! The regression engine against smatr (Warton et al. 2006; traitecoevo/smatr).
//!
//! Where the expected numbers come from
//! ------------------------------------
//! smatr's own suite (tests/testthat/test-numeric.R) checks `ma()`/`sma()` on its
//! bundled `leaflife` data, but that data ships only as a binary `data/leaflife.rda`
//! and no text copy of all 67 rows could be found, so those numbers cannot be
//! reproduced here (see the report; no data were invented).
//!
//! Instead every expected number below was produced outside this crate by running
//! smatr's own R source in R 4.2.2 (Debian `r-base-core`): the non-robust branches
//! of `line.cis` (R/line.cis.R @1b65f3b), `slope.test`, `elev.test`, `slope.com`,
//! `lr.b.com`, `com.ci`, `elev.com` (@37ab116) and `b.com.est` (@a9688bb), copied
//! with only the `data=`/`robust=` plumbing removed, plus base R's `lm`,
//! `hatvalues`, `rstandard`, `rstudent`, `cooks.distance`, `predict.lm`, `anova`
//! and `cor.test`. Printed with `sprintf("%.15g")`.
//!
//! The bootstrap section checks BCa intervals and jackknife influence values against the
//! R `boot` package (1.3-28.1), via `tests/golden/boot.R`.
//!
//! Data sets (both public, both text):
//! - `Animals` (MASS; text copy vincentarelbundock/Rdatasets csv/MASS/Animals.csv
//!   @cc03c29): brain (g) vs body (kg) of 28 species, the allometry example of
//!   Warton's *Eco-Stats* Box 13.2 (`sma(brain ~ body, log = "xy", slope.test = 2/3)`).
//! - `iris` (R `datasets`): log10 petal/sepal lengths by species, three groups of 50,
//!   for the multi-group tests.
//!
//! Tolerances are relative. One-sample quantities are closed forms, so 1e-9. smatr
//! stops its common-slope iteration at |Δb| < 1e-6 (b.com.est) whereas this crate
//! iterates to 1e-12, so common-slope quantities use smatr's own test tolerance, 1e-5.

use robot_survey::regression::{
    Group, Method, TestKind, bca_interval, elev_com, elev_test, fit_line, fit_power_law,
    jackknife_influence, jackknife_line, leave_one_out, ols_diagnostics, predict_ols, slope_com,
    slope_test,
};

const BODY: [f64; 28] = [
    1.35, 465.0, 36.33, 27.66, 1.04, 11700.0, 2547.0, 187.1, 521.0, 10.0, 3.3, 529.0, 207.0, 62.0,
    6654.0, 9400.0, 6.8, 35.0, 0.12, 0.023, 2.5, 55.5, 100.0, 52.16, 0.28, 87000.0, 0.122, 192.0,
];
const BRAIN: [f64; 28] = [
    8.1, 423.0, 119.5, 115.0, 5.5, 50.0, 4603.0, 419.0, 655.0, 115.0, 25.6, 680.0, 406.0, 1320.0,
    5712.0, 70.0, 179.0, 56.0, 1.0, 0.4, 12.1, 175.0, 157.0, 440.0, 1.9, 154.5, 3.0, 180.0,
];

const SEPAL_LENGTH: [f64; 150] = [
    5.1, 4.9, 4.7, 4.6, 5.0, 5.4, 4.6, 5.0, 4.4, 4.9, 5.4, 4.8, 4.8, 4.3, 5.8, 5.7, 5.4, 5.1, 5.7,
    5.1, 5.4, 5.1, 4.6, 5.1, 4.8, 5.0, 5.0, 5.2, 5.2, 4.7, 4.8, 5.4, 5.2, 5.5, 4.9, 5.0, 5.5, 4.9,
    4.4, 5.1, 5.0, 4.5, 4.4, 5.0, 5.1, 4.8, 5.1, 4.6, 5.3, 5.0, 7.0, 6.4, 6.9, 5.5, 6.5, 5.7, 6.3,
    4.9, 6.6, 5.2, 5.0, 5.9, 6.0, 6.1, 5.6, 6.7, 5.6, 5.8, 6.2, 5.6, 5.9, 6.1, 6.3, 6.1, 6.4, 6.6,
    6.8, 6.7, 6.0, 5.7, 5.5, 5.5, 5.8, 6.0, 5.4, 6.0, 6.7, 6.3, 5.6, 5.5, 5.5, 6.1, 5.8, 5.0, 5.6,
    5.7, 5.7, 6.2, 5.1, 5.7, 6.3, 5.8, 7.1, 6.3, 6.5, 7.6, 4.9, 7.3, 6.7, 7.2, 6.5, 6.4, 6.8, 5.7,
    5.8, 6.4, 6.5, 7.7, 7.7, 6.0, 6.9, 5.6, 7.7, 6.3, 6.7, 7.2, 6.2, 6.1, 6.4, 7.2, 7.4, 7.9, 6.4,
    6.3, 6.1, 7.7, 6.3, 6.4, 6.0, 6.9, 6.7, 6.9, 5.8, 6.8, 6.7, 6.7, 6.3, 6.5, 6.2, 5.9,
];
const SEPAL_WIDTH: [f64; 150] = [
    3.5, 3.0, 3.2, 3.1, 3.6, 3.9, 3.4, 3.4, 2.9, 3.1, 3.7, 3.4, 3.0, 3.0, 4.0, 4.4, 3.9, 3.5, 3.8,
    3.8, 3.4, 3.7, 3.6, 3.3, 3.4, 3.0, 3.4, 3.5, 3.4, 3.2, 3.1, 3.4, 4.1, 4.2, 3.1, 3.2, 3.5, 3.6,
    3.0, 3.4, 3.5, 2.3, 3.2, 3.5, 3.8, 3.0, 3.8, 3.2, 3.7, 3.3, 3.2, 3.2, 3.1, 2.3, 2.8, 2.8, 3.3,
    2.4, 2.9, 2.7, 2.0, 3.0, 2.2, 2.9, 2.9, 3.1, 3.0, 2.7, 2.2, 2.5, 3.2, 2.8, 2.5, 2.8, 2.9, 3.0,
    2.8, 3.0, 2.9, 2.6, 2.4, 2.4, 2.7, 2.7, 3.0, 3.4, 3.1, 2.3, 3.0, 2.5, 2.6, 3.0, 2.6, 2.3, 2.7,
    3.0, 2.9, 2.9, 2.5, 2.8, 3.3, 2.7, 3.0, 2.9, 3.0, 3.0, 2.5, 2.9, 2.5, 3.6, 3.2, 2.7, 3.0, 2.5,
    2.8, 3.2, 3.0, 3.8, 2.6, 2.2, 3.2, 2.8, 2.8, 2.7, 3.3, 3.2, 2.8, 3.0, 2.8, 3.0, 2.8, 3.8, 2.8,
    2.8, 2.6, 3.0, 3.4, 3.1, 3.0, 3.1, 3.1, 3.1, 2.7, 3.2, 3.3, 3.0, 2.5, 3.0, 3.4, 3.0,
];
const PETAL_LENGTH: [f64; 150] = [
    1.4, 1.4, 1.3, 1.5, 1.4, 1.7, 1.4, 1.5, 1.4, 1.5, 1.5, 1.6, 1.4, 1.1, 1.2, 1.5, 1.3, 1.4, 1.7,
    1.5, 1.7, 1.5, 1.0, 1.7, 1.9, 1.6, 1.6, 1.5, 1.4, 1.6, 1.6, 1.5, 1.5, 1.4, 1.5, 1.2, 1.3, 1.4,
    1.3, 1.5, 1.3, 1.3, 1.3, 1.6, 1.9, 1.4, 1.6, 1.4, 1.5, 1.4, 4.7, 4.5, 4.9, 4.0, 4.6, 4.5, 4.7,
    3.3, 4.6, 3.9, 3.5, 4.2, 4.0, 4.7, 3.6, 4.4, 4.5, 4.1, 4.5, 3.9, 4.8, 4.0, 4.9, 4.7, 4.3, 4.4,
    4.8, 5.0, 4.5, 3.5, 3.8, 3.7, 3.9, 5.1, 4.5, 4.5, 4.7, 4.4, 4.1, 4.0, 4.4, 4.6, 4.0, 3.3, 4.2,
    4.2, 4.2, 4.3, 3.0, 4.1, 6.0, 5.1, 5.9, 5.6, 5.8, 6.6, 4.5, 6.3, 5.8, 6.1, 5.1, 5.3, 5.5, 5.0,
    5.1, 5.3, 5.5, 6.7, 6.9, 5.0, 5.7, 4.9, 6.7, 4.9, 5.7, 6.0, 4.8, 4.9, 5.6, 5.8, 6.1, 6.4, 5.6,
    5.1, 5.6, 6.1, 5.6, 5.5, 4.8, 5.4, 5.6, 5.1, 5.1, 5.9, 5.7, 5.2, 5.0, 5.2, 5.4, 5.1,
];
const SPECIES: [&str; 3] = ["setosa", "versicolor", "virginica"];

/// Relative closeness, like testthat's `expect_equal(tolerance = tol)`.
#[track_caller]
fn close(actual: f64, expected: f64, tol: f64) {
    let scale = expected.abs().max(f64::MIN_POSITIVE);
    assert!(
        (actual - expected).abs() <= tol * scale,
        "actual {actual:.15e} vs expected {expected:.15e} (rel tol {tol:e}, rel err {:e})",
        (actual - expected).abs() / scale
    );
}

#[track_caller]
fn close_all(actual: &[f64], expected: &[f64], tol: f64) {
    assert_eq!(actual.len(), expected.len());
    for (a, e) in actual.iter().zip(expected) {
        close(*a, *e, tol);
    }
}

fn animals_log() -> (Vec<f64>, Vec<f64>) {
    (
        BODY.iter().map(|v| v.log10()).collect(),
        BRAIN.iter().map(|v| v.log10()).collect(),
    )
}

/// (log10 x, log10 y) per iris species, in smatr's sorted group order.
fn iris_groups(y_raw: &[f64; 150], species: &[usize]) -> Vec<(String, Vec<f64>, Vec<f64>)> {
    species
        .iter()
        .map(|&s| {
            let rows = s * 50..(s + 1) * 50;
            (
                SPECIES[s].to_string(),
                SEPAL_LENGTH[rows.clone()]
                    .iter()
                    .map(|v| v.log10())
                    .collect(),
                y_raw[rows].iter().map(|v| v.log10()).collect(),
            )
        })
        .collect()
}

fn as_groups(data: &[(String, Vec<f64>, Vec<f64>)]) -> Vec<Group<'_>> {
    data.iter()
        .map(|(label, x, y)| Group { label, x, y })
        .collect()
}

const TIGHT: f64 = 1e-9;
const SMATR_TOL: f64 = 1e-5;

// ---------------------------------------------------------------- one sample

#[test]
fn animals_sma_matches_line_cis() {
    let (x, y) = animals_log();
    let f = fit_line(&x, &y, Method::Sma, 0.95).unwrap();
    // line.cis(y, x, method = "SMA"): elevation and slope with 95% limits.
    close(f.intercept, 0.879771843485117, TIGHT);
    close(f.intercept_ci.lower, 0.499912326817443, TIGHT);
    close(f.intercept_ci.upper, 1.25963136015279, TIGHT);
    close(f.b, 0.636303822555941, TIGHT);
    close(f.b_ci.lower, 0.495598230440749, TIGHT);
    close(f.b_ci.upper, 0.816957224078925, TIGHT);
    // sqrt(var.b), sqrt(var.a) of line.cis.
    close(f.se_b, 0.0781693970411699, TIGHT);
    close(f.se_intercept, 0.184798869588786, TIGHT);
    // cor.test(x, y): r² and p, which sma() prints as "R-squared" and "P-value".
    close(f.r2, 0.607610111442041, TIGHT);
    close(f.p_b_equals_0, 1.01687177581193e-06, 1e-7);
}

#[test]
fn animals_sma_90_percent_interval() {
    let (x, y) = animals_log();
    let f = fit_line(&x, &y, Method::Sma, 0.90).unwrap();
    // line.cis(y, x, method = "SMA", alpha = 0.10)
    close(f.b_ci.lower, 0.516794923165593, TIGHT);
    close(f.b_ci.upper, 0.783449171905987, TIGHT);
}

#[test]
fn animals_ma_matches_line_cis() {
    let (x, y) = animals_log();
    let f = fit_line(&x, &y, Method::Ma, 0.95).unwrap();
    // line.cis(y, x, method = "MA")
    close(f.intercept, 0.994546577703751, TIGHT);
    close(f.intercept_ci.lower, 0.595678212401285, TIGHT);
    close(f.intercept_ci.upper, 1.39341494300622, TIGHT);
    close(f.b, 0.566227667439864, TIGHT);
    close(f.b_ci.lower, 0.393010228866425, TIGHT);
    close(f.b_ci.upper, 0.76966292338809, TIGHT);
    close(f.se_b, 0.0892382037531783, TIGHT);
    close(f.se_intercept, 0.194046535069725, TIGHT);
    assert!(!f.b_ci_inverted);
}

/// An MA interval that contains the vertical: setosa log10 petal length (x) against
/// 3·log10 sepal width (y), weakly correlated (r = 0.181) with Var(y) ≫ Var(x).
/// line.cis returns lower > upper, meaning the slopes [5.18, +∞) ∪ (−∞, −23.25];
/// swapping the axes turns it into the ordinary interval of the reciprocal.
#[test]
fn iris_ma_interval_through_the_vertical_matches_line_cis() {
    let rows = 0..50;
    let x: Vec<f64> = PETAL_LENGTH[rows.clone()]
        .iter()
        .map(|v| v.log10())
        .collect();
    let y: Vec<f64> = SEPAL_WIDTH[rows].iter().map(|v| 3.0 * v.log10()).collect();
    let f = fit_line(&x, &y, Method::Ma, 0.95).unwrap();
    // line.cis(y, x, method = "MA")
    close(f.intercept, -0.59329977618571, TIGHT);
    close(f.b, 13.5307114274395, TIGHT);
    close(f.b_ci.lower, 5.18497897711229, TIGHT);
    close(f.b_ci.upper, -23.2513115241534, TIGHT);
    close(f.se_b, 10.5923028204975, TIGHT);
    assert!(f.b_ci_inverted);
    // line.cis(x, y, method = "MA")
    let swapped = fit_line(&y, &x, Method::Ma, 0.95).unwrap();
    close(swapped.b, 0.0739059439233961, TIGHT);
    close(swapped.b_ci.lower, -0.0430083266039083, TIGHT);
    close(swapped.b_ci.upper, 0.192864812839982, TIGHT);
    assert!(!swapped.b_ci_inverted);
}

// ---------------------------------------------------------- bootstrap (R boot)
// Expected values from R 4.2.2 with boot 1.3-28.1 (Debian r-base-core): `boot:::bca.ci`
// with given replicates, estimate and influence values, and `empinf(type = "jack",
// stype = "i")` for the jackknife influence of the Animals fits.

/// BCa endpoints, bias correction and acceleration against `boot:::bca.ci(NULL, conf,
/// t0 = 0.3, t = (i/200)^2 + 0.05*sin(i), L = cos(j) + 0.3*sin(2j))`, i = 1..199, j = 1..20.
#[test]
fn bca_interval_matches_boot_bca_ci() {
    let t: Vec<f64> = (1..=199)
        .map(|i| (f64::from(i) / 200.0).powi(2) + 0.05 * f64::from(i).sin())
        .collect();
    let l: Vec<f64> = (1..=20)
        .map(|j| f64::from(j).cos() + 0.3 * (2.0 * f64::from(j)).sin())
        .collect();
    let bca95 = bca_interval(&t, 0.3, &l, 0.95).unwrap();
    close(bca95.z0, 0.11995018056019, TIGHT);
    close(bca95.acceleration, 0.00250135684891742, TIGHT);
    close(bca95.interval.lower, -0.0253472623566444, TIGHT);
    close(bca95.interval.upper, 0.984252401017934, TIGHT);
    let bca90 = bca_interval(&t, 0.3, &l, 0.90).unwrap();
    close(bca90.interval.lower, 0.00236740757289081, TIGHT);
    close(bca90.interval.upper, 0.946895949976844, TIGHT);
}

/// Jackknife influence values l_i = (n − 1)(t − t₋ᵢ) of the SMA and MA slopes and of the
/// OLS intercept on log Animals, and the acceleration Σl³/(6(Σl²)^1.5), against
/// `empinf(data, statistic, type = "jack", stype = "i")`.
#[test]
fn animals_jackknife_influence_matches_boot_empinf() {
    let (x, y) = animals_log();
    // (method, slope?, [l_1, l_6, l_26], a)
    let cases = [
        (
            Method::Sma,
            true,
            [0.0336283444828711, -0.760523302155861, -1.49833760568467],
            -0.0635630835425719,
        ),
        (
            Method::Ma,
            true,
            [0.115695374624212, -1.28855777080932, -2.08803367131842],
            -0.0573695104847509,
        ),
        (
            Method::Ols,
            false,
            [-0.53695420555145, 0.841585235016732, 1.77238661695218],
            -0.0294883798986755,
        ),
    ];
    for (method, slope, expected, a) in cases {
        let full = fit_line(&x, &y, method, 0.95).unwrap();
        let (slopes, intercepts) = jackknife_line(&x, &y, method).unwrap();
        let l = if slope {
            jackknife_influence(&slopes, full.b)
        } else {
            jackknife_influence(&intercepts, full.intercept)
        };
        for (k, e) in [0, 5, 25].into_iter().zip(expected) {
            close(l[k], e, TIGHT);
        }
        // The crate's own acceleration from these influence values (the replicates only
        // set z₀, here Φ⁻¹(½) = 0), not a formula restated in the test.
        let bca = bca_interval(&[-1.0, 1.0], 0.0, &l, 0.95).unwrap();
        close(bca.acceleration, a, TIGHT);
    }
}

#[test]
fn animals_ols_matches_line_cis_and_lm() {
    let (x, y) = animals_log();
    let f = fit_line(&x, &y, Method::Ols, 0.95).unwrap();
    // line.cis(method = "OLS") and coef/confint/summary of lm(y ~ x) agree:
    close(f.intercept, 1.10957816182941, TIGHT);
    close(f.intercept_ci.lower, 0.740768691634046, TIGHT);
    close(f.intercept_ci.upper, 1.47838763202477, TIGHT);
    close(f.b, 0.495994691625848, TIGHT);
    close(f.b_ci.lower, 0.335315194806761, TIGHT);
    close(f.b_ci.upper, 0.656674188444936, TIGHT);
    close(f.se_b, 0.0781693970411699, TIGHT);
    close(f.se_intercept, 0.17942310300302, TIGHT);
    // summary(lm)$sigma
    close(f.residual_variance.sqrt(), 0.665150297854954, TIGHT);
}

#[test]
fn animals_power_law_is_the_log10_line() {
    // sma(brain ~ body, log = "xy") fits on log10 of both: same numbers as above.
    let p = fit_power_law(&BODY, &BRAIN, Method::Sma, 0.95).unwrap();
    close(p.b, 0.636303822555941, TIGHT);
    close(p.log_a, 0.879771843485117, TIGHT);
    close(p.a, 10f64.powf(0.879771843485117), TIGHT);
    close(p.a_ci.lower, 10f64.powf(0.499912326817443), TIGHT);
    close(p.a_ci.upper, 10f64.powf(1.25963136015279), TIGHT);
}

#[test]
fn animals_slope_tests_match_slope_test() {
    let (x, y) = animals_log();
    // slope.test(y, x, test.value, method): (F, r, p). 2/3 is Eco-Stats Box 13.2's H0.
    let cases = [
        (
            Method::Sma,
            2.0 / 3.0,
            0.144079788220668,
            -0.0742360491440801,
            0.707341110878508,
        ),
        (
            Method::Sma,
            1.0,
            14.4901155088504,
            -0.598220671362709,
            0.00077264000149091,
        ),
        (
            Method::Ma,
            2.0 / 3.0,
            1.1520604164386,
            -0.205985301651911,
            0.292979585908766,
        ),
        (
            Method::Ma,
            1.0,
            14.4901155088504,
            -0.598220671362709,
            0.00077264000149091,
        ),
        (
            Method::Ols,
            2.0 / 3.0,
            4.76706314179995,
            -0.393624779882734,
            0.0382272259218058,
        ),
        (
            Method::Ols,
            1.0,
            41.5715959112162,
            -0.784361485675151,
            7.83857518671383e-07,
        ),
    ];
    for (method, b0, f_stat, r, p) in cases {
        let t = slope_test(&x, &y, method, b0).unwrap();
        close(t.f_statistic, f_stat, TIGHT);
        close(t.test_correlation, r, TIGHT);
        // R's `1 - pf(F)` loses relative precision for small p; the sf here does not.
        close(t.p_value, p, 1e-7);
        assert_eq!(t.df, 26);
    }
}

#[test]
fn animals_elevation_tests_match_elev_test() {
    let (x, y) = animals_log();
    // elev.test(y, x, test.value, method): (t, p).
    let cases = [
        (Method::Sma, 0.0, 4.76069926965887, 6.32092367674545e-05),
        (Method::Sma, 1.0, -0.650589242144254, 0.52101997704142),
        (Method::Ma, 0.0, 5.12529933784384, 2.41508223315978e-05),
        (Method::Ma, 1.0, -0.0281036829350727, 0.977794065524113),
        (Method::Ols, 0.0, 6.1841431970482, 1.53379528707205e-06),
        (Method::Ols, 1.0, 0.610724928927138, 0.546683992236611),
    ];
    for (method, a0, t_stat, p) in cases {
        let e = elev_test(&x, &y, method, a0, 0.95).unwrap();
        close(e.t_statistic, t_stat, TIGHT);
        close(e.p_value, p, 1e-8);
    }
}

// ------------------------------------------------------------ OLS vs base R

#[test]
fn animals_ols_diagnostics_match_r_influence_measures() {
    let (x, y) = animals_log();
    let d = ols_diagnostics(&x, &y).unwrap();
    // hatvalues(fit), rstandard(fit), rstudent(fit), cooks.distance(fit) for fit = lm(y ~ x).
    let hat = [
        0.0671021725699472,
        0.0503551744777161,
        0.0357974363290375,
        0.0362448869897174,
        0.0719974854600572,
        0.117290578825277,
        0.0788943061872491,
        0.0412696066888258,
        0.0517933646114509,
        0.0413335679980794,
        0.0530188437032523,
        0.0519912122123814,
        0.0420652297993497,
        0.0360441116984724,
        0.101666063651622,
        0.111033953022969,
        0.0446720866670592,
        0.0358357753041899,
        0.12613428826491,
        0.183951083661991,
        0.0569476737966994,
        0.0358707478950077,
        0.0375255994825576,
        0.0358015334164038,
        0.101996868908206,
        0.186270672820138,
        0.125627637856632,
        0.0414680377008006,
    ];
    let rstandard = [
        -0.413634573341525,
        0.298863856694099,
        0.296884953166083,
        0.361369235038897,
        -0.589401352610804,
        -2.28572102338659,
        1.35358248352306,
        0.592216958582743,
        0.554466897326889,
        0.698838992936971,
        0.0640863412730296,
        0.574575050829876,
        0.537992956774433,
        1.71805222192712,
        1.19121570115769,
        -1.96947490082751,
        1.12340901474027,
        -0.194817201387422,
        -1.04996758349014,
        -1.15656979123499,
        -0.347046541538182,
        0.410802400022787,
        0.144559005886808,
        1.04432331746102,
        -0.883076721916293,
        -2.28433017677487,
        -0.288272466907399,
        0.0202530563916842,
    ];
    let rstudent = [
        -0.406943228783196,
        0.293564808136833,
        0.291614357727791,
        0.355244939154334,
        -0.581855825359809,
        -2.50736581289748,
        1.37668962933998,
        0.58467330123025,
        0.546942766640937,
        0.691796053675663,
        0.0628467917835375,
        0.567028631580722,
        0.530506605903122,
        1.78931559938277,
        1.20132522003088,
        -2.09370949110653,
        1.12934344639154,
        -0.191173567628501,
        -1.05212522012924,
        -1.1644602096411,
        -0.341098093466509,
        0.404138604610582,
        0.141808767995474,
        1.04622102522868,
        -0.879213583094483,
        -2.50545685496567,
        -0.283127237134487,
        0.019859912380902,
    ];
    let cooks = [
        0.00615327277480655,
        0.00236809813786332,
        0.00163617601482268,
        0.00245557052611736,
        0.013475982442518,
        0.34710575766941,
        0.0784649405230809,
        0.00754858444871717,
        0.00839638579225109,
        0.0105283336153885,
        0.000114971414719918,
        0.00905276221151156,
        0.0063549262241441,
        0.0551848532100041,
        0.0802950966044851,
        0.242237587841232,
        0.0295073076772894,
        0.000705326817707243,
        0.0795628347279891,
        0.150764763877185,
        0.00363651718308971,
        0.0031393600018284,
        0.000407379116610983,
        0.0202476742943292,
        0.0442869597090584,
        0.597244656859347,
        0.00596987318684682,
        8.87274568819043e-06,
    ];
    // 1e-8: the last point's residual is tiny, so its ratios carry a little cancellation.
    close_all(&d.leverage, &hat, 1e-9);
    close_all(&d.studentized_internal, &rstandard, 1e-8);
    close_all(&d.studentized_external, &rstudent, 1e-8);
    close_all(&d.cooks_distance, &cooks, 1e-8);
}

#[test]
fn animals_ols_prediction_matches_predict_lm() {
    let (x, y) = animals_log();
    let f = fit_line(&x, &y, Method::Ols, 0.95).unwrap();
    // predict(fit, data.frame(x = c(0, 2, 5)), interval = "confidence" / "prediction", se.fit = TRUE)
    let expected = [
        // x0, fit, conf lo, conf hi, pred lo, pred hi, se.fit
        (
            0.0,
            1.10957816182941,
            0.740768691634046,
            1.47838763202477,
            -0.306527326901821,
            2.52568365056063,
            0.17942310300302,
        ),
        (
            2.0,
            2.1015675450811,
            1.83671307303436,
            2.36642201712784,
            0.708914601497496,
            3.49422048866471,
            0.128849758640093,
        ),
        (
            5.0,
            3.58955161995865,
            2.99071307667695,
            4.18839016324035,
            2.09692241924312,
            5.08218082067417,
            0.291330560401545,
        ),
    ];
    for (x0, fit, clo, chi, plo, phi, se) in expected {
        let p = predict_ols(&f, x0, 0.95).unwrap();
        close(p.fit, fit, TIGHT);
        close(p.mean_ci.lower, clo, TIGHT);
        close(p.mean_ci.upper, chi, TIGHT);
        close(p.prediction_interval.lower, plo, TIGHT);
        close(p.prediction_interval.upper, phi, TIGHT);
        close(p.se_mean, se, TIGHT);
    }
}

#[test]
fn animals_leave_one_out_matches_refits() {
    let (x, y) = animals_log();
    // sapply(1:28, function(i) coef(lm(y[-i] ~ x[-i]))[2])
    let ols = [
        0.490063832722067,
        0.493093921754661,
        0.496210204659565,
        0.496657501142876,
        0.486884529547355,
        0.550311355446149,
        0.473085583808951,
        0.492470788732709,
        0.490350633558912,
        0.500177043375129,
        0.496671883638267,
        0.490109460193949,
        0.492570449008442,
        0.493510489232867,
        0.47076444348139,
        0.540807155417166,
        0.504498219445253,
        0.495823745962088,
        0.469593558869712,
        0.457462073086103,
        0.491924018441634,
        0.495585612994859,
        0.4955044793692,
        0.495218148610885,
        0.477240602042083,
        0.572802477690015,
        0.488768594235799,
        0.495872032573968,
    ];
    // sapply(1:28, function(i) line.cis(y[-i], x[-i], method = "SMA")$b)
    let sma = [
        0.635058328315835,
        0.635538040584452,
        0.636059323006211,
        0.636262188168452,
        0.632403536460742,
        0.664471352265417,
        0.615149691720714,
        0.632585481804631,
        0.632533948870718,
        0.637948619459297,
        0.63908712470069,
        0.632261771896479,
        0.633064331025911,
        0.620029323213269,
        0.618746629941201,
        0.662642735959529,
        0.638040725732032,
        0.636003995548551,
        0.623213624153677,
        0.622369901721813,
        0.635362599717691,
        0.635193941532065,
        0.636056258173691,
        0.630446252938767,
        0.627088602733212,
        0.691797807951669,
        0.643073592520239,
        0.636955278620492,
    ];
    for (method, expected, full) in [
        (Method::Ols, &ols, 0.495994691625848),
        (Method::Sma, &sma, 0.636303822555941),
    ] {
        let loo = leave_one_out(&x, &y, method).unwrap();
        assert_eq!(loo.len(), 28);
        for (row, &e) in loo.iter().zip(expected.iter()) {
            close(row.b_without.unwrap(), e, TIGHT);
            close(row.delta_b.unwrap(), e - full, 1e-7);
        }
    }
}

// ------------------------------------------------------------- multi-group

#[test]
fn iris_sma_common_slope_matches_slope_com() {
    let data = iris_groups(&PETAL_LENGTH, &[0, 1, 2]);
    let groups = as_groups(&data);
    let t = slope_com(&groups, Method::Sma, 0.95).unwrap();
    // slope.com(Y, X, Species, method = "SMA"): LR, p, b, varb, df.
    assert_eq!(t.test, TestKind::LikelihoodRatio);
    close(t.statistic, 12.8369043243069, SMATR_TOL);
    close(t.p_value, 0.00163117908252342, SMATR_TOL);
    close(t.b, 1.20074966449002, SMATR_TOL);
    close(t.var_b, 0.00433664329643926, SMATR_TOL);
    assert_eq!(t.df, 2);
    // com.ci limits, re-run with uniroot(tol = 1e-12) (smatr's default 1e-4 gives
    // 1.07142648041967, 1.35118033012415, within its own tolerance of these).
    let ci = t.b_ci.expect("likelihood-ratio CI");
    close(ci.lower, 1.07144192609201, SMATR_TOL);
    close(ci.upper, 1.35117992644363, SMATR_TOL);
    // Separate per-group SMA slopes and limits (line.cis on each species).
    let expected = [
        (1.71409473823452, 1.30349203021063, 2.25403815562149),
        (1.32610051247399, 1.10103026372153, 1.5971791395087),
        (1.00674512939945, 0.867291003050264, 1.16862247158672),
    ];
    for (g, (b, lo, hi)) in t.groups.iter().zip(expected) {
        close(g.b, b, TIGHT);
        close(g.b_ci.lower, lo, TIGHT);
        close(g.b_ci.upper, hi, TIGHT);
    }
}

#[test]
fn iris_ma_common_slope_matches_slope_com() {
    let data = iris_groups(&PETAL_LENGTH, &[0, 1, 2]);
    let groups = as_groups(&data);
    let t = slope_com(&groups, Method::Ma, 0.95).unwrap();
    // slope.com(Y, X, Species, method = "MA")
    close(t.statistic, 17.6644638603282, SMATR_TOL);
    close(t.p_value, 0.000145952120741866, SMATR_TOL);
    close(t.b, 1.19996404335795, SMATR_TOL);
    close(t.var_b, 0.00758549949890184, SMATR_TOL);
    let ci = t.b_ci.expect("likelihood-ratio CI");
    close(ci.lower, 1.02480400663061, SMATR_TOL);
    close(ci.upper, 1.4258551147777, SMATR_TOL);
    // line.cis(method = "MA") per species; setosa's MA interval is very wide.
    let expected = [
        (4.07514915390934, 1.99073407022286, 63.4375451933953),
        (1.44178348636628, 1.13551538450244, 1.87124325632053),
        (1.00787706098269, 0.844919438146409, 1.20255853801639),
    ];
    for (g, (b, lo, hi)) in t.groups.iter().zip(expected) {
        close(g.b, b, TIGHT);
        close(g.b_ci.lower, lo, 1e-8);
        close(g.b_ci.upper, hi, 1e-8);
    }
}

#[test]
fn iris_two_groups_sma_common_slope() {
    // slope.com on setosa + versicolor only: a non-significant-ish LR on 1 df.
    let data = iris_groups(&PETAL_LENGTH, &[0, 1]);
    let t = slope_com(&as_groups(&data), Method::Sma, 0.95).unwrap();
    close(t.statistic, 2.34048956287923, SMATR_TOL);
    close(t.p_value, 0.126049934341463, SMATR_TOL);
    close(t.b, 1.43678081388581, SMATR_TOL);
    let ci = t.b_ci.unwrap();
    close(ci.lower, 1.23155328086671, SMATR_TOL);
    close(ci.upper, 1.68191335758242, SMATR_TOL);
    assert_eq!(t.df, 1);
}

#[test]
fn iris_sma_elevation_comparison_matches_elev_com() {
    // Sepal width vs sepal length, versicolor vs virginica: slopes plausibly common
    // (LR 1.10, p 0.29) and a moderate elevation shift (Wald 4.61, p 0.032).
    let data = iris_groups(&SEPAL_WIDTH, &[1, 2]);
    let groups = as_groups(&data);
    let s = slope_com(&groups, Method::Sma, 0.95).unwrap();
    // slope.com(..., method = "SMA", tol = 1e-12 in com.ci): LR, p, b, ci, varb
    close(s.statistic, 1.10359044527476, SMATR_TOL);
    close(s.p_value, 0.293479499761479, SMATR_TOL);
    close(s.b, 1.22803460319573, SMATR_TOL);
    close(s.var_b, 0.0118564613541086, SMATR_TOL);
    let ci = s.b_ci.unwrap();
    close(ci.lower, 1.02883863781248, SMATR_TOL);
    close(ci.upper, 1.46531271268433, SMATR_TOL);

    let e = elev_com(&groups, Method::Sma, 0.95).unwrap();
    // elev.com(Y, X, Species, method = "SMA"): stat, p, a, a.ci, and per-group as.
    assert_eq!(e.test, TestKind::Wald);
    close(e.statistic, 4.6071480968717, SMATR_TOL);
    close(e.p_value, 0.0318389414008994, SMATR_TOL);
    close(e.elevation, -0.437914043238616, SMATR_TOL);
    close(e.elevation_ci.lower, -0.590183283435393, SMATR_TOL);
    close(e.elevation_ci.upper, -0.285644803041839, SMATR_TOL);
    let groups_expected = [
        (-0.508266638051609, -0.677805163320277, -0.338728112782941),
        (-0.532153530301131, -0.711578116158572, -0.35272894444369),
    ];
    for (g, (a, lo, hi)) in e.groups.iter().zip(groups_expected) {
        close(g.elevation, a, SMATR_TOL);
        close(g.elevation_ci.lower, lo, SMATR_TOL);
        close(g.elevation_ci.upper, hi, SMATR_TOL);
    }
}

#[test]
fn iris_ma_elevation_comparison_matches_elev_com() {
    let data = iris_groups(&SEPAL_WIDTH, &[1, 2]);
    let groups = as_groups(&data);
    let s = slope_com(&groups, Method::Ma, 0.95).unwrap();
    // slope.com(..., method = "MA")
    close(s.statistic, 0.701162699229267, SMATR_TOL);
    close(s.p_value, 0.40239328605768, SMATR_TOL);
    close(s.b, 1.53253366862243, SMATR_TOL);
    close(s.var_b, 0.0752261026922284, SMATR_TOL);
    let ci = s.b_ci.unwrap();
    close(ci.lower, 1.07794683225009, SMATR_TOL);
    close(ci.upper, 2.30039617492337, SMATR_TOL);

    let e = elev_com(&groups, Method::Ma, 0.95).unwrap();
    // elev.com(..., method = "MA")
    close(e.statistic, 4.98974212299981, SMATR_TOL);
    close(e.p_value, 0.0254980084114269, SMATR_TOL);
    close(e.elevation, -0.404744791050789, SMATR_TOL);
    close(e.elevation_ci.lower, -0.694832731355584, SMATR_TOL);
    close(e.elevation_ci.upper, -0.114656850745994, SMATR_TOL);
    let groups_expected = [
        (-0.74330331716969, -1.169242455571, -0.317364178768381),
        (-0.780855518367849, -1.23159670279108, -0.330114333944618),
    ];
    for (g, (a, lo, hi)) in e.groups.iter().zip(groups_expected) {
        close(g.elevation, a, SMATR_TOL);
        close(g.elevation_ci.lower, lo, SMATR_TOL);
        close(g.elevation_ci.upper, hi, SMATR_TOL);
    }
}

#[test]
fn iris_three_group_elevations_match_elev_com() {
    // elev.com(log10 Petal.Length, log10 Sepal.Length, Species): a huge shift.
    let data = iris_groups(&PETAL_LENGTH, &[0, 1, 2]);
    let groups = as_groups(&data);
    let sma = elev_com(&groups, Method::Sma, 0.95).unwrap();
    close(sma.statistic, 1517.7165510442, SMATR_TOL);
    // R prints 1 - pchisq(1517.7, 2) as 0; the survival function gives a tiny positive p.
    assert!(sma.p_value < 1e-300);
    close(sma.b_common, 1.20074966449002, SMATR_TOL);
    close(sma.elevation, -1.55198777728979, SMATR_TOL);
    close(sma.elevation_ci.lower, -1.62624017091815, SMATR_TOL);
    close(sma.elevation_ci.upper, -1.47773538366142, SMATR_TOL);
    let as_sma = [
        (-0.676758205495156, -0.770550102761045, -0.582966308229268),
        (-0.300177849030989, -0.402822452827696, -0.197533245234281),
        (-0.238327371736707, -0.346731955110094, -0.12992278836332),
    ];
    for (g, (a, lo, hi)) in sma.groups.iter().zip(as_sma) {
        close(g.elevation, a, SMATR_TOL);
        close(g.elevation_ci.lower, lo, SMATR_TOL);
        close(g.elevation_ci.upper, hi, SMATR_TOL);
    }

    let ma = elev_com(&groups, Method::Ma, 0.95).unwrap();
    close(ma.statistic, 1201.73568144074, SMATR_TOL);
    close(ma.elevation, -1.91708394403543, SMATR_TOL);
    close(ma.elevation_ci.lower, -2.00150871866022, SMATR_TOL);
    close(ma.elevation_ci.upper, -1.83265916941064, SMATR_TOL);
}

#[test]
fn iris_ols_ancova_matches_anova() {
    let data = iris_groups(&PETAL_LENGTH, &[0, 1, 2]);
    let groups = as_groups(&data);
    // anova(lm(Y ~ X + G), lm(Y ~ X * G)): F, p, Df, Res.Df
    let s = slope_com(&groups, Method::Ols, 0.95).unwrap();
    assert_eq!(s.test, TestKind::F);
    close(s.statistic, 2.64788806426321, TIGHT);
    close(s.p_value, 0.0742468323008804, 1e-8);
    assert_eq!((s.df, s.df_den), (2, Some(144)));
    // summary(lm(Y ~ X + G))$coefficients["X", ]: pooled within-group slope and its SE.
    close(s.b, 0.83433168267241, TIGHT);
    close(s.var_b.sqrt(), 0.0831510593216859, TIGHT);
    // anova(lm(Y ~ X), lm(Y ~ X + G))
    let e = elev_com(&groups, Method::Ols, 0.95).unwrap();
    close(e.statistic, 943.596962112885, TIGHT);
    close(e.p_value, 3.16742132366734e-84, 1e-6);
    assert_eq!((e.df, e.df_den), (2, Some(146)));

    // versicolor vs virginica, sepal width: both non-significant.
    let data = iris_groups(&SEPAL_WIDTH, &[1, 2]);
    let groups = as_groups(&data);
    let s = slope_com(&groups, Method::Ols, 0.95).unwrap();
    close(s.statistic, 0.814734312113773, TIGHT);
    close(s.p_value, 0.368983467335313, 1e-8);
    let e = elev_com(&groups, Method::Ols, 0.95).unwrap();
    close(e.statistic, 0.186448439771332, TIGHT);
    close(e.p_value, 0.666847410282863, 1e-8);
}
