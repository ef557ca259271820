//! The surrogate of the simulator over the knobs: the nominal walks plus, for every free
//! knob, the change its own curve makes (an additive model across knobs), plus a per-model
//! correction measured by real walks at the model's fitted point (output space mapping:
//! the surrogate is shifted to agree with the simulator there, then re-optimised).
//!
//! The additive model is exact for one knob and for knobs that act on different things; it
//! misses interactions, which the correction absorbs near the fitted point. Every reported
//! χ² of a fitted model comes from real walks at its point, never from the surrogate.

use super::curve::Curve;
use super::simulate::SimMetrics;
use super::trials::Metric;

/// Real minus surrogate, per condition and metric, at a model's fitted point (0: none).
#[derive(Clone, Debug, PartialEq)]
pub struct Correction {
    pub per_condition: Vec<[f64; 8]>,
}

impl Correction {
    pub fn none(n_conditions: usize) -> Correction {
        Correction {
            per_condition: vec![[0.0; 8]; n_conditions],
        }
    }

    pub fn get(&self, cond: usize, metric: Metric) -> f64 {
        self.per_condition[cond][metric.index()]
    }
}

pub struct Surrogate {
    /// The nominal model's walks, per condition.
    pub nominal: Vec<SimMetrics>,
    /// Per knob (in [`super::knob::Knobs`] order): its walks over its range.
    pub curves: Vec<Curve>,
}

impl Surrogate {
    /// The predicted metric of condition `cond` with the knobs of `point` (coordinates; None:
    /// nominal or off), shifted by `correction`. NaN: predicted to fall.
    pub fn predict(
        &self,
        cond: usize,
        metric: Metric,
        point: &[Option<f64>],
        correction: &Correction,
    ) -> f64 {
        let y0 = self.nominal[cond].get(metric);
        let mut y = y0;
        if y0.is_finite() {
            for (curve, x) in self.curves.iter().zip(point) {
                if let Some(x) = x {
                    let v = curve.value(cond, metric, *x);
                    if !v.is_finite() {
                        return f64::NAN;
                    }
                    y += v - y0;
                }
            }
        } else {
            // The nominal falls here: no base to add changes to. A knob whose own walk
            // stands is the best estimate (the correction refines it).
            for (curve, x) in self.curves.iter().zip(point) {
                if let Some(x) = x {
                    let v = curve.value(cond, metric, *x);
                    if v.is_finite() {
                        y = v;
                        break;
                    }
                }
            }
            if !y.is_finite() {
                return f64::NAN;
            }
        }
        let c = correction.get(cond, metric);
        if c.is_finite() { y + c } else { y }
    }

    /// The correction that makes the surrogate agree with `real` walks at `point`. Where the
    /// real walk fell or the surrogate predicts a fall, no shift (the fall is charged by the
    /// real χ²; a shift cannot express it).
    pub fn correction_at(&self, point: &[Option<f64>], real: &[SimMetrics]) -> Correction {
        let zero = Correction::none(real.len());
        let mut out = zero.clone();
        for (c, r) in real.iter().enumerate() {
            for m in Metric::ALL {
                let s = self.predict(c, m, point, &zero);
                let v = r.get(m);
                out.per_condition[c][m.index()] = if s.is_finite() && v.is_finite() {
                    v - s
                } else {
                    0.0
                };
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metrics(v: f64) -> SimMetrics {
        SimMetrics {
            values: [v; 8],
            fell: false,
        }
    }

    /// Two knobs whose curves are straight lines of slopes 2 and −3 around a nominal of 10:
    /// the additive surrogate at (x₁, x₂) is 10 + 2·x₁ − 3·x₂ exactly, a correction shifts it,
    /// and a fall on either curve makes the prediction a fall.
    #[test]
    fn the_surrogate_adds_the_knobs_changes() {
        let nominal = vec![metrics(10.0)];
        let line = |slope: f64| {
            Curve::new(
                vec![-1.0, 0.0, 1.0],
                [-1.0, 0.0, 1.0]
                    .iter()
                    .map(|x| vec![metrics(10.0 + slope * x)])
                    .collect(),
            )
        };
        let s = Surrogate {
            nominal,
            curves: vec![line(2.0), line(-3.0)],
        };
        let zero = Correction::none(1);
        let m = Metric::VelocityMps;
        let y = s.predict(0, m, &[Some(0.5), Some(-0.25)], &zero);
        assert!((y - (10.0 + 1.0 + 0.75)).abs() < 1e-12, "{y}");
        assert_eq!(s.predict(0, m, &[None, None], &zero), 10.0);
        let real = vec![metrics(12.5)];
        let c = s.correction_at(&[Some(0.5), Some(-0.25)], &real);
        assert!((s.predict(0, m, &[Some(0.5), Some(-0.25)], &c) - 12.5).abs() < 1e-12);
        let mut falls = line(2.0);
        falls.insert(
            0.75,
            &[SimMetrics {
                values: [f64::NAN; 8],
                fell: true,
            }],
        );
        let s = Surrogate {
            nominal: vec![metrics(10.0)],
            curves: vec![falls],
        };
        assert!(s.predict(0, m, &[Some(0.8)], &zero).is_nan());
    }
}
