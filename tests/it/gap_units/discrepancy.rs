//! Unit tests of `gap::discrepancy`.

use robot_survey::gap::discrepancy::channel_spread;
use robot_survey::gap::simulate::{SimMetrics, Walked};

fn walk(v: f64, fell: bool) -> Walked {
    Walked {
        metrics: SimMetrics {
            values: [if fell { f64::NAN } else { v }; 8],
            fell,
        },
        cycles: None,
    }
}

/// The sample sd of 1, 2, 3 is 1; a fall among walks gives the largest |value|; all
/// fallen, 0.
#[test]
fn spread_by_hand() {
    let (a, b, c) = (walk(1.0, false), walk(2.0, false), walk(3.0, false));
    assert_eq!(channel_spread(&[&a, &b, &c], 0), 1.0);
    let f = walk(0.0, true);
    assert_eq!(channel_spread(&[&a, &c, &f], 0), 3.0);
    assert_eq!(channel_spread(&[&f, &f], 0), 0.0);
}
