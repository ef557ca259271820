//! One knob's walks: every channel (metrics, and a logged condition's cycle coefficients)
//! of every condition at several values of one parameter or effect magnitude (the others at
//! their nominal values), interpolated between the walks by a monotone cubic. The surrogate
//! is built from these curves.

use super::simulate::Walked;

/// Fritsch–Carlson monotone cubic through (x, y), NaN-aware: NaN where a bracketing node is
/// NaN (a walk that fell). Outside [x₀, xₙ] the end value. Hand-written: the interpolation
/// crates do not keep monotonicity or handle the NaN of a fallen walk, and this is twenty
/// lines.
pub fn pchip(x: &[f64], y: &[f64], t: f64) -> f64 {
    hermite(x, y, &pchip_slopes(x, y), t)
}

/// The node slopes of the monotone cubic: the weighted harmonic mean of the neighbouring
/// secants (Brodlie) where they agree in sign, 0 where they do not, the one-sided secant at
/// an end or beside a NaN.
pub fn pchip_slopes(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let d = |i: usize| -> f64 { (y[i + 1] - y[i]) / (x[i + 1] - x[i]) };
    (0..n)
        .map(|i| {
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
        })
        .collect()
}

/// The cubic Hermite interpolant through (x, y) with node slopes `m` at `t`.
fn hermite(x: &[f64], y: &[f64], m: &[f64], t: f64) -> f64 {
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
    let s = ((t - x[k]) / h).clamp(0.0, 1.0);
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * y0
        + (s3 - 2.0 * s2 + s) * h * m[k]
        + (-2.0 * s3 + 3.0 * s2) * y1
        + (s3 - s2) * h * m[k + 1]
}

/// A knob's walks: every channel of every condition at each node (the knob's coordinate),
/// sorted.
#[derive(Clone, Debug)]
pub struct Curve {
    pub x: Vec<f64>,
    /// [condition][channel] → (values at the nodes, the cubic's slopes there), kept beside
    /// `x` so that evaluating the interpolant (millions of times in the evidence integrals)
    /// allocates and recomputes nothing.
    series: Vec<Vec<(Vec<f64>, Vec<f64>)>>,
}

impl Curve {
    /// An empty curve over conditions with these channel counts.
    pub fn empty(channels: &[usize]) -> Curve {
        Curve {
            x: Vec::new(),
            series: channels
                .iter()
                .map(|n| vec![(Vec::new(), Vec::new()); *n])
                .collect(),
        }
    }

    /// `walks` is [node][condition], in the order of `x` (any order; sorted here).
    pub fn new(channels: &[usize], x: Vec<f64>, walks: Vec<Vec<Walked>>) -> Curve {
        let mut curve = Curve::empty(channels);
        for (xi, w) in x.into_iter().zip(walks) {
            curve.add(xi, &w);
        }
        curve.update_slopes();
        curve
    }

    /// Adds a node (ignored if one already sits within 1e-12: `has_node`).
    pub fn insert(&mut self, x: f64, walks: &[Walked]) {
        if self.add(x, walks) {
            self.update_slopes();
        }
    }

    pub fn has_node(&self, x: f64) -> bool {
        self.x.iter().any(|v| (v - x).abs() < 1e-12)
    }

    fn add(&mut self, x: f64, walks: &[Walked]) -> bool {
        if self.has_node(x) {
            return false;
        }
        let k = self.x.partition_point(|v| *v < x);
        self.x.insert(k, x);
        for (per_channel, w) in self.series.iter_mut().zip(walks) {
            for (ch, s) in per_channel.iter_mut().enumerate() {
                s.0.insert(k, w.channel(ch));
            }
        }
        true
    }

    fn update_slopes(&mut self) {
        for s in self.series.iter_mut().flatten() {
            s.1 = pchip_slopes(&self.x, &s.0);
        }
    }

    pub fn value(&self, cond: usize, channel: usize, x: f64) -> f64 {
        let (y, m) = &self.series[cond][channel];
        hermite(&self.x, y, m, x)
    }

    pub fn conditions(&self) -> usize {
        self.series.len()
    }

    /// Channels of condition `cond`.
    pub fn channels(&self, cond: usize) -> usize {
        self.series[cond].len()
    }
}
