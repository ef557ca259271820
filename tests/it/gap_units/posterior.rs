//! Unit tests of `gap::posterior`: the normalisation of priors, evidences and Bayes factors
//! into probabilities, and the surrogate's error of a confirmed pair, against values derived
//! by hand.

use robot_survey::gap::evidence::Evidence;
use robot_survey::gap::hypothesis::{Class, Hypothesis};
use robot_survey::gap::posterior::{Weighed, normalise, surrogate_sd};

fn weighed(knobs: Vec<usize>, class: Class, prior: f64, log_z: f64, log_bf: f64) -> Weighed {
    let mut evidence = Evidence::empty(knobs.len());
    evidence.log_z = log_z;
    Weighed {
        hypothesis: Hypothesis {
            knobs,
            class,
            prior,
        },
        evidence,
        correction: None,
        walks: None,
        walked_chi2: None,
        surrogate_sd: None,
        obs: None,
        log_bf,
        probability: 0.0,
        share: 0.0,
    }
}

/// Three explanations, priors ½, ¼, ¼, ln Z = −1000, −990, −995. Their shares of the library's
/// mass are ∝ ½e⁻¹⁰, ¼, ¼e⁻⁵ (relative to e⁻⁹⁹⁰): A = 1 / (1 + 2e⁻¹⁰ + e⁻⁵). With no
/// Bayes factor beside them P(outside) = 0 and the probabilities are the shares; with
/// ln BF = 0 for each, E = 1 and P(outside) = q (here 1/16).
#[test]
fn probabilities_are_prior_times_evidence_and_outside_takes_q_e() {
    let make = |bf: f64| {
        vec![
            weighed(vec![], Class::Nominal, 0.5, -1000.0, bf),
            weighed(vec![0], Class::One, 0.25, -990.0, bf),
            weighed(vec![1], Class::One, 0.25, -995.0, bf),
        ]
    };
    let a = 1.0 / (1.0 + 2.0 * (-10.0f64).exp() + (-5.0f64).exp());
    let mut w = make(f64::NEG_INFINITY);
    let outside = normalise(&mut w, 1.0 / 16.0);
    assert_eq!(outside, 0.0);
    assert_eq!(w[0].hypothesis.knobs, vec![0]);
    assert_eq!(w[1].hypothesis.knobs, vec![1]);
    assert!((w[0].probability - a).abs() < 1e-12);
    assert!((w[1].probability - a * (-5.0f64).exp()).abs() < 1e-12);
    assert!((w[2].probability - 2.0 * a * (-10.0f64).exp()).abs() < 1e-12);

    let mut w = make(0.0);
    let outside = normalise(&mut w, 1.0 / 16.0);
    assert!((outside - 1.0 / 16.0).abs() < 1e-12, "{outside}");
    assert!((w[0].probability - a * 15.0 / 16.0).abs() < 1e-12);
    assert!((w[0].share - a).abs() < 1e-12);
}

/// When "something outside these" takes all the mass (every explanation misses by hundreds
/// of sds, ln BF = 800), every probability is 0 in f64, but the explanations still rank by
/// their share of the library's mass, which the search walks in that order.
#[test]
fn explanations_rank_by_their_share_when_outside_takes_everything() {
    let mut w = vec![
        weighed(vec![], Class::Nominal, 0.5, -5000.0, 800.0),
        weighed(vec![0], Class::One, 0.25, -4000.0, 800.0),
        weighed(vec![0, 1], Class::Two, 0.125, -300.0, 800.0),
        weighed(vec![1], Class::One, 0.25, -301.0, 800.0),
    ];
    let outside = normalise(&mut w, 1.0 / 16.0);
    assert_eq!(outside, 1.0);
    assert!(w.iter().all(|x| x.probability == 0.0));
    let order: Vec<Vec<usize>> = w.iter().map(|x| x.hypothesis.knobs.clone()).collect();
    // The last two have shares that underflow to 0: they keep their list order.
    assert_eq!(order, vec![vec![0, 1], vec![1], vec![], vec![0]]);
    // Shares: ¼e⁻³⁰¹ against ⅛e⁻³⁰⁰ = 2e⁻¹ : 1.
    let r = 2.0 * (-1.0f64).exp();
    assert!((w[0].share - 1.0 / (1.0 + r)).abs() < 1e-12);
    assert!((w[1].share - r / (1.0 + r)).abs() < 1e-12);
}

/// The surrogate's error per observation is the root-mean-square of its finite misses over
/// the walks it had not seen: misses (1, −1) → 1; (NaN, 2) → 2; (3, NaN) → 3; none finite
/// → 0; and no walk at all measures nothing.
#[test]
fn surrogate_error_is_the_rms_of_finite_misses() {
    let nan = f64::NAN;
    let misses = vec![vec![1.0, nan, 3.0, nan], vec![-1.0, 2.0, nan, nan]];
    assert_eq!(surrogate_sd(&misses), Some(vec![1.0, 2.0, 3.0, 0.0]));
    assert_eq!(surrogate_sd(&[]), None);
}
