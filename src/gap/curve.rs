//! One knob's walks: the metrics of every condition at several values of one parameter or
//! effect magnitude (the others at their nominal values), interpolated between the walks by
//! a monotone cubic. The surrogate of a model is built from these curves.

use super::simulate::SimMetrics;
use super::trials::Metric;

/// Fritsch–Carlson monotone cubic through (x, y), NaN-aware: NaN where a bracketing node is
/// NaN (a walk that fell). Outside [x₀, xₙ] the end value. Hand-written: the interpolation
/// crates do not keep monotonicity or handle the NaN of a fallen walk, and this is twenty
/// lines.
pub fn pchip(x: &[f64], y: &[f64], t: f64) -> f64 {
    let n = x.len();
    if n == 0 {
        return f64::NAN;
    }
    if n == 1 {
        return y[0];
    }
    let k = x.partition_point(|v| *v <= t).clamp(1, n - 1) - 1;
    let (y0, y1) = (y[k], y[k + 1]);
    if !(y0.is_finite() && y1.is_finite()) {
        return f64::NAN;
    }
    let h = x[k + 1] - x[k];
    let d = |i: usize| -> f64 { (y[i + 1] - y[i]) / (x[i + 1] - x[i]) };
    let slope = |i: usize| -> f64 {
        let left = if i > 0 { d(i - 1) } else { f64::NAN };
        let right = if i + 1 < n { d(i) } else { f64::NAN };
        match (left.is_finite(), right.is_finite()) {
            (true, true) => {
                if left * right <= 0.0 {
                    0.0
                } else {
                    let (h0, h1) = (x[i] - x[i - 1], x[i + 1] - x[i]);
                    let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
                    (w1 + w2) / (w1 / left + w2 / right)
                }
            }
            (true, false) => left,
            (false, true) => right,
            _ => 0.0,
        }
    };
    let (m0, m1) = (slope(k), slope(k + 1));
    let s = ((t - x[k]) / h).clamp(0.0, 1.0);
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * y0
        + (s3 - 2.0 * s2 + s) * h * m0
        + (-2.0 * s3 + 3.0 * s2) * y1
        + (s3 - s2) * h * m1
}

/// A knob's walks: the metrics at each node (the knob's coordinate), sorted.
#[derive(Clone, Debug)]
pub struct Curve {
    pub x: Vec<f64>,
    /// [condition][metric index][node], kept beside `x` so that evaluating the interpolant
    /// (millions of times in fits and profiles) allocates nothing.
    series: Vec<Vec<Vec<f64>>>,
}

impl Curve {
    /// `sims` is [node][condition], in the order of `x` (any order; sorted here).
    pub fn new(x: Vec<f64>, sims: Vec<Vec<SimMetrics>>) -> Curve {
        let n_cond = sims.first().map(Vec::len).unwrap_or(0);
        let mut curve = Curve {
            x: Vec::new(),
            series: vec![vec![Vec::new(); Metric::ALL.len()]; n_cond],
        };
        for (xi, s) in x.into_iter().zip(sims) {
            curve.insert(xi, &s);
        }
        curve
    }

    /// Adds a node (ignored if one already sits within 1e-12).
    pub fn insert(&mut self, x: f64, sims: &[SimMetrics]) {
        if self.x.iter().any(|v| (v - x).abs() < 1e-12) {
            return;
        }
        let k = self.x.partition_point(|v| *v < x);
        self.x.insert(k, x);
        for (per_metric, s) in self.series.iter_mut().zip(sims) {
            for m in Metric::ALL {
                per_metric[m.index()].insert(k, s.get(m));
            }
        }
    }

    pub fn value(&self, cond: usize, metric: Metric, x: f64) -> f64 {
        pchip(&self.x, &self.series[cond][metric.index()], x)
    }

    pub fn conditions(&self) -> usize {
        self.series.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
