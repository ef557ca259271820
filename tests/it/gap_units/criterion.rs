//! Unit tests of `gap::criterion`.

use robot_survey::gap::criterion::{BUNDLED, Criterion};

#[test]
fn the_bundled_criterion_reads_and_bad_ones_are_refused() {
    let c = Criterion::bundled().expect("bundled");
    assert_eq!(c.prior.nominal, 0.5);
    let bad = BUNDLED.replace("nominal = 0.5", "nominal = 0.6");
    let e = Criterion::parse(&bad, "x.toml").unwrap_err().to_string();
    assert!(e.contains("x.toml") && e.contains("sum to 1.1"), "{e}");
    let bad = BUNDLED.replace("threshold = ", "threshold = 0.4 #");
    let e = Criterion::parse(&bad, "x.toml").unwrap_err().to_string();
    assert!(e.contains("decision.threshold"), "{e}");
}
