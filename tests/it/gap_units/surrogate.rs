//! Unit tests of `gap::surrogate`.

use robot_survey::gap::curve::Curve;
use robot_survey::gap::simulate::{SimMetrics, Walked};
use robot_survey::gap::surrogate::{Anchored, Surrogate};
use std::collections::BTreeMap;

fn walk(v: f64) -> Walked {
    Walked {
        metrics: SimMetrics {
            values: [v; 8],
            fell: false,
        },
        cycles: None,
    }
}

fn line(slope: f64, at: f64) -> Curve {
    Curve::new(
        &[8],
        vec![-1.0, 0.0, 1.0],
        [-1.0, 0.0, 1.0]
            .iter()
            .map(|x| vec![walk(at + slope * x)])
            .collect(),
    )
}

/// Two knobs whose curves are straight lines of slopes 2 and −3 around a nominal of 10:
/// the additive surrogate at (x₁, x₂) is 10 + 2·x₁ − 3·x₂ exactly, a correction shifts it,
/// and a fall on either curve makes the prediction a fall.
#[test]
fn the_surrogate_adds_the_knobs_changes() {
    let s = Surrogate {
        channels: vec![8],
        nominal: vec![walk(10.0)],
        curves: vec![line(2.0, 10.0), line(-3.0, 10.0)],
        anchored: None,
    };
    let set = [(0, 0.5), (1, -0.25)];
    let y = s.predict(0, 0, &set, None);
    assert!((y - (10.0 + 1.0 + 0.75)).abs() < 1e-12, "{y}");
    assert_eq!(s.predict(0, 0, &[], None), 10.0);
    let c = s.correction_at(&set, &[walk(12.5)]);
    assert!((s.predict(0, 0, &set, Some(&c)) - 12.5).abs() < 1e-12);
    let mut falls = line(2.0, 10.0);
    falls.insert(
        0.75,
        &[Walked {
            metrics: SimMetrics {
                values: [f64::NAN; 8],
                fell: true,
            },
            cycles: None,
        }],
    );
    let s = Surrogate {
        channels: vec![8],
        nominal: vec![walk(10.0)],
        curves: vec![falls],
        anchored: None,
    };
    assert!(s.predict(0, 0, &[(0, 0.8)], None).is_nan());
}

/// The truth y = 10 + 2a − 3b + 4ab has an interaction the additive surrogate misses
/// (at (0.5, 0.5): 10.5 against 9.5). Anchored at a = 0.5 (b's curve walked there:
/// slope −1 about 11), a pair reads the truth exactly along b, and along a through the
/// anchor's line; a first-order correction from walks at (0.5, 0.5) and a step of 0.1
/// along each knob matches the truth's slopes there.
#[test]
fn anchored_curves_and_first_order_corrections_see_an_interaction() {
    let truth = |a: f64, b: f64| 10.0 + 2.0 * a - 3.0 * b + 4.0 * a * b;
    let mut anchored = BTreeMap::new();
    anchored.insert(1, line(-3.0 + 4.0 * 0.5, truth(0.5, 0.0)));
    let s = Surrogate {
        channels: vec![8],
        nominal: vec![walk(10.0)],
        curves: vec![line(2.0, 10.0), line(-3.0, 10.0)],
        anchored: Some(Anchored {
            knob: 0,
            x: 0.5,
            curves: anchored,
        }),
    };
    for b in [-1.0, 0.0, 0.5, 1.0] {
        assert!((s.predict(0, 0, &[(0, 0.5), (1, b)], None) - truth(0.5, b)).abs() < 1e-12);
    }
    let plain = Surrogate {
        anchored: None,
        ..s
    };
    let at = [(0, 0.5), (1, 0.5)];
    let c = plain.first_order_at(
        &at,
        &[walk(truth(0.5, 0.5))],
        &[vec![walk(truth(0.6, 0.5))], vec![walk(truth(0.5, 0.6))]],
        &[0.1, 0.1],
    );
    let p = |a: f64, b: f64| plain.predict(0, 0, &[(0, a), (1, b)], Some(&c));
    assert!((p(0.5, 0.5) - truth(0.5, 0.5)).abs() < 1e-12);
    let slope_a = (p(0.51, 0.5) - p(0.49, 0.5)) / 0.02;
    let slope_b = (p(0.5, 0.51) - p(0.5, 0.49)) / 0.02;
    assert!(
        (slope_a - 4.0).abs() < 1e-9 && (slope_b + 1.0).abs() < 1e-9,
        "{slope_a} {slope_b}"
    );
}
