//! Unit tests of `gap::explore`.

use robot_survey::gap::explore::latin_hypercube;
use robot_survey::regression::spearman;

#[test]
fn latin_hypercube_fills_every_stratum_once() {
    let n = 17;
    let pts = latin_hypercube(n, 3, 9);
    assert_eq!(pts.len(), n);
    for d in 0..3 {
        let mut strata: Vec<usize> = pts.iter().map(|p| (p[d] * n as f64) as usize).collect();
        strata.sort();
        assert_eq!(strata, (0..n).collect::<Vec<_>>(), "coordinate {d}");
    }
    assert_eq!(pts, latin_hypercube(n, 3, 9), "deterministic in the seed");
}

#[test]
fn spearman_matches_hand_values() {
    // Monotone: +1 / −1 whatever the spacing.
    assert!((spearman(&[1.0, 2.0, 3.0, 4.0], &[1.0, 10.0, 100.0, 1000.0]) - 1.0).abs() < 1e-12);
    assert!((spearman(&[1.0, 2.0, 3.0, 4.0], &[4.0, 3.0, 1.0, 0.5]) + 1.0).abs() < 1e-12);
    // Ranks x = 1..5, y = (2,1,4,3,5): Σd² = 4, ρ = 1 − 6·4/(5·24) = 0.8.
    let r = spearman(&[1.0, 2.0, 3.0, 4.0, 5.0], &[2.0, 1.0, 4.0, 3.0, 5.0]);
    assert!((r - 0.8).abs() < 1e-12, "{r}");
}
