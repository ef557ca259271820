//! Unit tests of `gap::explore`.

use robot_survey::gap::explore::latin_hypercube;

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
