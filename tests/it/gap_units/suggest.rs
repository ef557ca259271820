//! Unit tests of `gap::suggest`.

use robot_survey::gap::simulate::SimMetrics;
use robot_survey::gap::suggest::{entropy, expected_entropy};

fn m(v: f64) -> SimMetrics {
    SimMetrics {
        values: [v; 8],
        fell: false,
    }
}

/// Two equally probable explanations (entropy ln 2): a condition where they predict the
/// same leaves the entropy at ln 2; one where they differ by 20 sd in every metric
/// leaves ~0.
#[test]
fn a_trial_that_tells_two_explanations_apart_removes_their_entropy() {
    let w = [0.5, 0.5];
    let walks = vec![vec![m(1.0), m(1.0)], vec![m(1.0), m(2.0)]];
    let same = expected_entropy(&w, &walks, &[0], 0.05);
    let apart = expected_entropy(&w, &walks, &[1], 0.05);
    assert!((same - 2f64.ln()).abs() < 1e-12, "{same}");
    assert!(apart < 1e-6, "{apart}");
    assert!((entropy(&w) - 2f64.ln()).abs() < 1e-15);
}
