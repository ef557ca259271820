//! Unit tests of `gap::evidence`.

use robot_survey::gap::curve::Curve;
use robot_survey::gap::evidence::{Evidence, Slab, Target, evidence};
use robot_survey::gap::knob::{Knob, KnobKind, Knobs};
use robot_survey::gap::likelihood::{Observation, log_normaliser};
use robot_survey::gap::simulate::{SimMetrics, Walked};
use robot_survey::gap::surrogate::Surrogate;
use robot_survey::gap::trials::Metric;

fn walk(v: f64) -> Walked {
    Walked {
        metrics: SimMetrics {
            values: [v; 8],
            fell: false,
        },
        cycles: None,
    }
}

fn knob(name: &str) -> Knob {
    Knob {
        kind: KnobKind::Effect,
        design: String::new(),
        name: name.into(),
        log: false,
        lo: 0.0,
        hi: 1.0,
        nominal: None,
        off_value: None,
        prior: None,
        si_per_value: 1.0,
        unit: String::new(),
        why: String::new(),
    }
}

/// A knob whose curve is the line y = slope·x on one condition, nominal 0.
fn linear(slopes: &[f64]) -> (Knobs, Surrogate) {
    let knobs = Knobs {
        list: slopes.iter().map(|_| knob("k")).collect(),
        aliased: Vec::new(),
    };
    let xs: Vec<f64> = (0..=64).map(|i| i as f64 / 64.0).collect();
    let curves = slopes
        .iter()
        .map(|s| {
            Curve::new(
                &[8],
                xs.clone(),
                xs.iter().map(|x| vec![walk(s * x)]).collect(),
            )
        })
        .collect();
    (
        knobs,
        Surrogate {
            channels: vec![8],
            nominal: vec![walk(0.0)],
            curves,
            anchored: None,
        },
    )
}

/// The evidence of one linear knob y = 10x (nominal 0) from y measured at `y` with sd 1.
fn one_linear_knob(y: f64) -> Evidence {
    let (knobs, sur) = linear(&[10.0]);
    let obs = [Observation::metric(0, Metric::VelocityMps, y, 1.0, false)];
    let slabs = [Slab::new(0, &knobs.list[0], &sur, &obs)];
    let t = Target {
        surrogate: &sur,
        knobs: &knobs,
        obs: &obs,
        free: &[0],
        slabs: &slabs,
        correction: None,
        log_norm: log_normaliser(&obs),
    };
    evidence(&t, 0)
}

/// One linear knob, one observation y ~ N(10x, 1), measured 5, uniform prior on [0, 1]
/// less the slab's hole |10x| < 1 (resolved to the cell: x ≥ 51/512): by hand,
/// Z = ∫ φ(10x − 5) dx / (1 − 51/512) = [Φ(5) − Φ(−4.98)] / 10 / (1 − 51/512). The
/// quadrature matches to 1e-6; the mode is 0.5, the 95 % interval 0.5 ± 0.196 and
/// Laplace's value 0.1 / (1 − 51/512) (a Gaussian, far from the ends).
#[test]
fn one_knob_evidence_is_the_gaussian_integral() {
    let e = one_linear_knob(5.0);
    let phi = |z: f64| robot_survey::regression::dist::normal_cdf(z).unwrap();
    let mass = 1.0 - 51.0 / 512.0;
    let want = ((phi(5.0) - phi(10.0 * 51.0 / 512.0 - 5.0)) / 10.0 / mass).ln();
    assert!((e.log_z - want).abs() < 1e-6, "{} vs {want}", e.log_z);
    assert!((e.mode[0] - 0.5).abs() < 1e-6);
    assert!((e.log_z_laplace - (0.1 / mass).ln()).abs() < 1e-6);
    // 95 % interval 0.5 ± 0.196.
    assert!(
        (e.intervals[0][0] - 0.304).abs() < 0.003,
        "{:?}",
        e.intervals
    );
    assert!(
        (e.intervals[0][1] - 0.696).abs() < 0.003,
        "{:?}",
        e.intervals
    );
}

/// One linear knob, y ~ N(10x, 1) measured 10.5: the likelihood peaks beyond the range, so the
/// posterior rises all the way to x = 1. By hand its 95 % highest-density interval is [x₀, 1]
/// with Φ(10x₀ − 10.5) = 0.05 Φ(−0.5) (the slab's hole at x < 51/512 holds ~1e-19 of it):
/// x₀ = 0.8341 — it holds the mode, where the equal-tailed interval [0.8078, 0.9978] would not.
#[test]
fn interval_at_a_range_end_holds_the_mode() {
    let e = one_linear_knob(10.5);
    let [lo, hi] = e.intervals[0];
    assert!((lo - 0.8341).abs() < 0.003, "{:?}", e.intervals);
    assert!(hi > 0.998 && (lo..=hi).contains(&e.mode[0]), "{e:?}");
}

/// Two linear knobs, two observations y₁ ~ N(10a, 1) = 4 and y₂ ~ N(10a + 10b, 1) = 9: the
/// posterior is Gaussian at (0.4, 0.5) with precision [[200, 100], [100, 100]]. The
/// importance sampler's ln Z matches a 1000 × 1000 midpoint grid of the same target to
/// 0.02, Laplace's to 0.01 (the box and the slabs' holes cut 0.3 % of the Gaussian); each
/// knob's interval spans the joint 95 % region.
#[test]
fn two_knob_importance_sampling_matches_a_dense_grid() {
    let (knobs, mut sur) = linear(&[10.0, 10.0]);
    // The second knob acts on the second channel only; the first on both.
    let xs: Vec<f64> = (0..=64).map(|i| i as f64 / 64.0).collect();
    let two = |a: f64, b: f64| {
        let mut w = walk(0.0);
        w.metrics.values[0] = a;
        w.metrics.values[1] = b;
        w
    };
    sur.curves[0] = Curve::new(
        &[8],
        xs.clone(),
        xs.iter().map(|x| vec![two(10.0 * x, 10.0 * x)]).collect(),
    );
    sur.curves[1] = Curve::new(
        &[8],
        xs.clone(),
        xs.iter().map(|x| vec![two(0.0, 10.0 * x)]).collect(),
    );
    let obs = [
        Observation::metric(0, Metric::VelocityMps, 4.0, 1.0, false),
        Observation::metric(0, Metric::StepFrequencyHz, 9.0, 1.0, false),
    ];
    let slabs: Vec<Slab> = (0..2)
        .map(|k| Slab::new(k, &knobs.list[k], &sur, &obs))
        .collect();
    let t = Target {
        surrogate: &sur,
        knobs: &knobs,
        obs: &obs,
        free: &[0, 1],
        slabs: &slabs,
        correction: None,
        log_norm: log_normaliser(&obs),
    };
    let e = evidence(&t, 7);
    let n = 1000;
    let mut acc = 0.0;
    for i in 0..n {
        for j in 0..n {
            let u = [(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64];
            acc += t.eval(&u).0.exp();
        }
    }
    let grid = (acc / (n * n) as f64).ln();
    assert!((e.log_z - grid).abs() < 0.02, "IS {} grid {grid}", e.log_z);
    assert!(
        (e.log_z_laplace - grid).abs() < 0.01,
        "Laplace {} grid {grid}",
        e.log_z_laplace
    );
    assert!(
        (e.mode[0] - 0.4).abs() < 1e-3 && (e.mode[1] - 0.5).abs() < 1e-3,
        "{:?}",
        e.mode
    );
    // The 95 % highest-density region is the ellipse Δᵀ P Δ ≤ χ²₂(0.95) = 5.991; on each axis
    // it reaches ±√(5.991·Σᵢᵢ) (Σ = P⁻¹: 0.01, 0.02): a ± 0.2448, b ± 0.3462, wider than the
    // marginals' ±1.96 sd (0.196, 0.277). Samples fill it from inside, so within 0.02.
    for (i, (m, r)) in [(0.4, 0.2448), (0.5, 0.3462)].into_iter().enumerate() {
        let [lo, hi] = e.intervals[i];
        assert!(
            (lo - (m - r)).abs() < 0.02 && (hi - (m + r)).abs() < 0.02,
            "{e:?}"
        );
        let [mlo, mhi] = e.marginal[i];
        assert!((mhi - mlo) < hi - lo, "{e:?}");
    }
    // Same seed, same bits.
    assert_eq!(evidence(&t, 7), e);
}

/// A knob that changes nothing detectably has an empty slab.
#[test]
fn an_undetectable_knob_has_no_prior_support() {
    let (knobs, sur) = linear(&[0.5]);
    let obs = [Observation::metric(0, Metric::VelocityMps, 0.0, 1.0, false)];
    assert!(Slab::new(0, &knobs.list[0], &sur, &obs).is_empty());
}
