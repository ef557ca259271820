//! Unit tests of `gap::curve`.

use robot_survey::gap::curve::pchip;

/// A monotone cubic reproduces data that are linear exactly, and never overshoots
/// monotone data (Fritsch & Carlson 1980): a step sampled at 0, 1, 2, 3 stays within
/// [0, 1] and is flat on the flat parts.
#[test]
fn pchip_is_exact_on_lines_and_does_not_overshoot() {
    let x = [0.0, 1.0, 2.5, 4.0];
    let y: Vec<f64> = x.iter().map(|v| 3.0 - 2.0 * v).collect();
    for t in [0.0, 0.3, 1.7, 2.5, 3.9] {
        assert!((pchip(&x, &y, t) - (3.0 - 2.0 * t)).abs() < 1e-12);
    }
    let xs = [0.0, 1.0, 2.0, 3.0];
    let ys = [0.0, 0.0, 1.0, 1.0];
    for k in 0..=300 {
        let t = k as f64 / 100.0;
        let v = pchip(&xs, &ys, t);
        assert!((-1e-12..=1.0 + 1e-12).contains(&v), "{t} -> {v}");
        if t <= 1.0 || t >= 2.0 {
            assert!(v.abs() < 1e-12 || (v - 1.0).abs() < 1e-12, "{t} -> {v}");
        }
    }
    // Ends: clamped to the end values.
    assert_eq!(pchip(&xs, &ys, -5.0), 0.0);
    assert_eq!(pchip(&xs, &ys, 9.0), 1.0);
}

/// Values between nodes, derived by hand from Fritsch–Carlson (1980) with the
/// weighted harmonic mean of Brodlie at interior nodes and the one-sided secant at the
/// ends. Data (0, 0), (1, 1), (2, 4): secants 1 and 3; slopes m₀ = 1, m₁ = 2·1·3/(1+3)
/// = 1.5 (equal spacing: w₁ = w₂ = 3), m₂ = 3. Hermite basis at s = ½: h₀₀ = h₀₁ = ½,
/// h₁₀ = ⅛, h₁₁ = −⅛. So p(0.5) = ⅛·1 + ½·1 − ⅛·1.5 = 0.4375 and
/// p(1.5) = ½·1 + ⅛·1.5 + ½·4 − ⅛·3 = 2.3125. At a local maximum (0, 1, 0) the node
/// slope is 0: p(0.5) = ⅛·1 + ½·1 = 0.625, and the curve never exceeds 1.
#[test]
fn pchip_matches_hand_derived_values_between_nodes() {
    let x = [0.0, 1.0, 2.0];
    let y = [0.0, 1.0, 4.0];
    assert!((pchip(&x, &y, 0.5) - 0.4375).abs() < 1e-12);
    assert!((pchip(&x, &y, 1.5) - 2.3125).abs() < 1e-12);
    for (xi, yi) in x.iter().zip(&y) {
        assert_eq!(pchip(&x, &y, *xi), *yi);
    }
    let peak = [0.0, 1.0, 0.0];
    assert!((pchip(&x, &peak, 0.5) - 0.625).abs() < 1e-12);
    assert!((pchip(&x, &peak, 1.5) - 0.625).abs() < 1e-12);
    for k in 0..=200 {
        assert!(pchip(&x, &peak, k as f64 / 100.0) <= 1.0 + 1e-12);
    }
    // Monotone on monotone data with uneven spacing and a steep step.
    let xs = [0.0, 0.1, 0.5, 2.0, 2.2];
    let ys = [-3.0, -2.9, 5.0, 5.1, 40.0];
    let mut last = f64::NEG_INFINITY;
    for k in 0..=2200 {
        let v = pchip(&xs, &ys, k as f64 / 1000.0);
        assert!(v >= last - 1e-12, "not monotone at {k}: {v} < {last}");
        last = v;
    }
}

#[test]
fn pchip_is_nan_next_to_a_fallen_walk() {
    let x = [0.0, 1.0, 2.0];
    let y = [1.0, f64::NAN, 3.0];
    assert!(pchip(&x, &y, 0.5).is_nan());
    assert!(pchip(&x, &y, 1.5).is_nan());
    assert_eq!(pchip(&[0.0], &[7.0], 3.0), 7.0);
}
