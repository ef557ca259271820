//! Unit tests of `gap::likelihood`.

use robot_survey::gap::likelihood::{FELL_Z2, Observation, log_normaliser};
use robot_survey::gap::trials::Metric;

/// z uses the measurement's and the model's sds in quadrature (3-4-5), a fall charges
/// FELL_Z2, and the normaliser is −½ ln(2πσ²) per observation.
#[test]
fn residuals_and_normaliser_by_hand() {
    let mut o = Observation::metric(0, Metric::VelocityMps, 1.0, 3.0, false);
    o.model_sd = 4.0;
    assert_eq!(o.total_sd(), 5.0);
    assert_eq!(o.z(11.0), 2.0);
    assert_eq!(o.z2(f64::NAN), FELL_Z2);
    let want = -0.5 * (2.0 * std::f64::consts::PI * 25.0).ln();
    assert!((log_normaliser(&[o]) - want).abs() < 1e-12);
}
