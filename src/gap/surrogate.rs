//! The surrogate of the simulator over the knobs: the nominal walks plus, for every knob set,
//! the change its own curve makes (an additive model across knobs). Two refinements by real
//! walks make it agree with the simulator where an explanation's posterior lies:
//!
//! * [`Anchored`]: every other knob's curve walked again with one knob held at a value (the
//!   leading single explanation's), so that a pair holding that knob sees the interaction
//!   along the other (a cut-HDMR expansion about the anchor instead of the nominal);
//! * [`Correction`]: real minus surrogate at a point, with its first-order change along each
//!   knob (output space mapping with matched slopes).
//!
//! The additive model is exact for one knob at its curve's nodes.

use std::collections::BTreeMap;

use super::curve::Curve;
use super::simulate::Walked;

/// Real minus surrogate at `at` per condition and channel, plus its slope per free knob:
/// c(x) = c₀ + Σₖ gₖ·(xₖ − atₖ).
#[derive(Clone, Debug, PartialEq)]
pub struct Correction {
    pub at: Vec<(usize, f64)>,
    pub constant: Vec<Vec<f64>>,
    /// Per knob of `at` (same order): the slope per condition and channel (empty: none).
    pub slopes: Vec<Vec<Vec<f64>>>,
}

impl Correction {
    /// The correction at `set` (coordinates) per condition and channel.
    pub fn get(&self, cond: usize, channel: usize, set: &[(usize, f64)]) -> f64 {
        let mut c = self.constant[cond][channel];
        for ((k, x0), slope) in self.at.iter().zip(&self.slopes) {
            if let (Some(row), Some((_, x))) = (slope.get(cond), set.iter().find(|s| s.0 == *k)) {
                c += row[channel] * (x - x0);
            }
        }
        c
    }
}

/// Curves of knobs walked with `knob` held at `x` (the anchor), for pairs holding `knob`.
#[derive(Clone, Debug)]
pub struct Anchored {
    pub knob: usize,
    pub x: f64,
    /// Per other knob: its curve with the anchor set.
    pub curves: BTreeMap<usize, Curve>,
}

pub struct Surrogate {
    /// Channels per condition ([`Walked::channels_of`]).
    pub channels: Vec<usize>,
    /// The nominal model's walks, per condition.
    pub nominal: Vec<Walked>,
    /// Per knob (in [`super::knob::Knobs`] order): its walks over its range.
    pub curves: Vec<Curve>,
    pub anchored: Option<Anchored>,
}

impl Surrogate {
    /// The predicted channel `ch` of condition `cond` with the knobs `set` at their
    /// coordinates (the others nominal or off), plus `correction`. NaN: predicted to fall.
    pub fn predict(
        &self,
        cond: usize,
        ch: usize,
        set: &[(usize, f64)],
        correction: Option<&Correction>,
    ) -> f64 {
        let y = match self.anchored_pair(set) {
            Some((a, xa, other, xo)) => {
                let base = other.value(cond, ch, xo);
                let along = self.curves[a].value(cond, ch, xa)
                    - self.curves[a].value(cond, ch, self.anchored.as_ref().map_or(xa, |n| n.x));
                base + along
            }
            None => self.additive(cond, ch, set),
        };
        if !y.is_finite() {
            return f64::NAN;
        }
        let c = correction.map_or(0.0, |c| c.get(cond, ch, set));
        if c.is_finite() { y + c } else { y }
    }

    /// The anchored curve a pair reads: (anchor knob, its coordinate, the other's anchored
    /// curve, its coordinate), when `set` is a pair holding the anchor knob.
    fn anchored_pair(&self, set: &[(usize, f64)]) -> Option<(usize, f64, &Curve, f64)> {
        let an = self.anchored.as_ref()?;
        if set.len() != 2 {
            return None;
        }
        let (mine, other) = if set[0].0 == an.knob {
            (set[0], set[1])
        } else if set[1].0 == an.knob {
            (set[1], set[0])
        } else {
            return None;
        };
        let curve = an.curves.get(&other.0)?;
        Some((mine.0, mine.1, curve, other.1))
    }

    fn additive(&self, cond: usize, ch: usize, set: &[(usize, f64)]) -> f64 {
        let y0 = self.nominal[cond].channel(ch);
        if y0.is_finite() {
            let mut y = y0;
            for &(k, x) in set {
                let v = self.curves[k].value(cond, ch, x);
                if !v.is_finite() {
                    return f64::NAN;
                }
                y += v - y0;
            }
            y
        } else {
            // The nominal falls here: no base to add changes to. A knob whose own walk
            // stands is the best estimate.
            set.iter()
                .map(|&(k, x)| self.curves[k].value(cond, ch, x))
                .find(|v| v.is_finite())
                .unwrap_or(f64::NAN)
        }
    }

    /// The constant correction that makes the surrogate agree with `real` walks at `set`.
    /// Where the real walk fell or the surrogate predicts a fall, no shift (the fall is
    /// charged by the likelihood; a shift cannot express it).
    pub fn correction_at(&self, set: &[(usize, f64)], real: &[Walked]) -> Correction {
        Correction {
            at: set.to_vec(),
            constant: self.mismatch(set, real),
            slopes: Vec::new(),
        }
    }

    /// Real minus surrogate at `set`, per condition and channel (0 where either falls).
    fn mismatch(&self, set: &[(usize, f64)], real: &[Walked]) -> Vec<Vec<f64>> {
        real.iter()
            .enumerate()
            .map(|(c, r)| {
                (0..self.channels[c])
                    .map(|ch| {
                        let s = self.predict(c, ch, set, None);
                        let v = r.channel(ch);
                        if s.is_finite() && v.is_finite() {
                            v - s
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// The first-order correction at `set` from the walks there and the walks with each knob
    /// of `set` moved by its step (`stepped[i]`: knob i at `set[i].1 + steps[i]`).
    pub fn first_order_at(
        &self,
        set: &[(usize, f64)],
        real: &[Walked],
        stepped: &[Vec<Walked>],
        steps: &[f64],
    ) -> Correction {
        let constant = self.mismatch(set, real);
        let slopes = stepped
            .iter()
            .zip(steps)
            .enumerate()
            .map(|(i, (walks, h))| {
                let mut moved = set.to_vec();
                moved[i].1 += h;
                let m = self.mismatch(&moved, walks);
                m.iter()
                    .zip(&constant)
                    .map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y) / h).collect())
                    .collect()
            })
            .collect();
        Correction {
            at: set.to_vec(),
            constant,
            slopes,
        }
    }
}
