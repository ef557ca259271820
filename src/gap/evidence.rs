//! The evidence of one explanation: its marginal likelihood Z = ∫ L(θ) π(θ) dθ over the knobs
//! it frees, on the surrogate (shifted by the walks' correction where the search confirmed
//! it). Method and the measurements behind it: `docs/gap-criterion.md`.
//!
//! * No free knob (the nominal): Z = L at the design's values.
//! * One knob: adaptive midpoint quadrature over its unit interval — the prior's cells,
//!   subdivided about the mode finer than the posterior's width. Exact up to the surrogate.
//! * Two knobs: defensive importance sampling (Hesterberg 1995): a mixture of Student-t
//!   components at the posterior's modes (found on a grid, polished by Nelder–Mead, scaled by
//!   the Hessian) and the uniform prior box; a fixed seed per explanation, so the same trials
//!   give the same numbers bit for bit.
//! * "Something outside these" beside an explanation: its predictions plus a Gaussian
//!   discrepancy of relative size κ, log-uniform from where it becomes detectable to the
//!   criterion's `max_relative`; the Bayes factor over the explanation alone is a 1-D
//!   quadrature over ln κ at the explanation's most probable point ([`Discrepancy`]).
//!
//! Every result carries its Laplace approximation beside the integral, which is how the
//! choice of method was measured (knife-edge gaits make the local approximation fragile).
//!
//! A suspect's prior ([`Slab`]) leaves out the values the trials cannot tell from the
//! nominal: where the suspect alone changes the predictions by less than one standard
//! deviation in all (Σ z² < 1). This is a non-local prior (Johnson & Rossell 2010): with it the
//! evidence for "nothing is off" grows as fast with the data as the evidence against it.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::knob::{Knob, Knobs};
use super::likelihood::{FELL_Z2, Observation, normal};
use super::simulate::Walked;
use super::surrogate::{Correction, Surrogate};

/// Cells of a suspect's unit interval on which its prior's support is decided.
pub const SLAB_CELLS: usize = 512;
/// Importance samples of a two-knob explanation.
pub const SAMPLES: usize = 2048;
/// Grid of the two-knob explanations' mode search (per axis).
const MODE_GRID: usize = 25;
/// Student-t degrees of freedom of the importance proposal.
const T_DOF: f64 = 4.0;
/// The share of the proposal drawn from the uniform prior box (defensive component).
const DEFENSIVE: f64 = 0.3;

/// A suspect's prior over its unit interval: the knob's own prior restricted to the values
/// whose predictions differ from the nominal's by at least one total sd (Σ z² ≥ 1).
#[derive(Clone, Debug)]
pub struct Slab {
    support: Vec<bool>,
    log_mass: f64,
}

impl Slab {
    /// The slab of knob `k` on the surrogate's curves and these observations.
    pub fn new(k: usize, knob: &Knob, surrogate: &Surrogate, obs: &[Observation]) -> Slab {
        let mut mass = 0.0;
        let support: Vec<bool> = (0..SLAB_CELLS)
            .map(|i| {
                let u = (i as f64 + 0.5) / SLAB_CELLS as f64;
                let inside = change_z2(k, knob.from_unit(u), surrogate, obs) >= 1.0;
                if inside {
                    mass += knob.log_prior_unit(u).exp() / SLAB_CELLS as f64;
                }
                inside
            })
            .collect();
        Slab {
            support,
            log_mass: mass.ln(),
        }
    }

    /// No value of the suspect changes the predictions detectably.
    pub fn is_empty(&self) -> bool {
        !self.log_mass.is_finite()
    }

    /// Log density at unit coordinate `u` (−∞ outside the support).
    pub fn log_density(&self, knob: &Knob, u: f64) -> f64 {
        let cell = ((u * SLAB_CELLS as f64) as usize).min(SLAB_CELLS - 1);
        if (0.0..=1.0).contains(&u) && self.support[cell] {
            knob.log_prior_unit(u) - self.log_mass
        } else {
            f64::NEG_INFINITY
        }
    }

    /// The unit coordinate closest to `from` (the knob's nominal or weakest setting) where
    /// the suspect becomes detectable.
    pub fn detectable_from(&self, from: f64) -> Option<f64> {
        (0..SLAB_CELLS)
            .filter(|i| self.support[*i])
            .map(|i| (i as f64 + 0.5) / SLAB_CELLS as f64)
            .min_by(|a, b| (a - from).abs().total_cmp(&(b - from).abs()))
    }
}

/// Σ z² of the change knob `k` alone at coordinate `x` makes to the nominal predictions.
fn change_z2(k: usize, x: f64, surrogate: &Surrogate, obs: &[Observation]) -> f64 {
    obs.iter()
        .map(|o| {
            let y0 = surrogate.nominal[o.trial].channel(o.channel);
            let y = surrogate.predict(o.trial, o.channel, &[(k, x)], None);
            match (y0.is_finite(), y.is_finite()) {
                (true, true) => ((y - y0) / o.total_sd()).powi(2).min(FELL_Z2),
                (false, false) => 0.0,
                _ => FELL_Z2,
            }
        })
        .sum()
}

/// One explanation's unnormalised log posterior density over the unit box of its free
/// knobs.
pub struct Target<'a> {
    pub surrogate: &'a Surrogate,
    pub knobs: &'a Knobs,
    pub obs: &'a [Observation],
    pub free: &'a [usize],
    /// Every knob's slab (indexed like `knobs`).
    pub slabs: &'a [Slab],
    pub correction: Option<&'a Correction>,
    /// [`super::likelihood::log_normaliser`] of `obs`.
    pub log_norm: f64,
}

impl Target<'_> {
    /// χ² of the surrogate's predictions at `u`.
    pub fn chi2(&self, u: &[f64]) -> f64 {
        let set = self.knobs.set_of(self.free, u);
        self.obs
            .iter()
            .map(|o| {
                o.z2(self
                    .surrogate
                    .predict(o.trial, o.channel, &set, self.correction))
            })
            .sum()
    }

    fn log_prior(&self, u: &[f64]) -> f64 {
        self.free
            .iter()
            .zip(u)
            .map(|(&k, &s)| self.slabs[k].log_density(&self.knobs.list[k], s))
            .sum()
    }

    /// (log posterior density up to Z, χ²) at `u`; −∞ outside the prior's support.
    pub fn eval(&self, u: &[f64]) -> (f64, f64) {
        let lp = self.log_prior(u);
        if !lp.is_finite() {
            return (f64::NEG_INFINITY, f64::NAN);
        }
        let chi2 = self.chi2(u);
        (lp + self.log_norm - 0.5 * chi2, chi2)
    }
}

/// What the integral of one explanation gives.
#[derive(Clone, Debug, PartialEq)]
pub struct Evidence {
    /// ln Z.
    pub log_z: f64,
    /// ln Z by Laplace's approximation at the mode (NaN where the mode has no finite
    /// curvature).
    pub log_z_laplace: f64,
    /// The most probable point (unit coordinates of the free knobs).
    pub mode: Vec<f64>,
    pub chi2_mode: f64,
    /// 95 % credible interval of each free knob (unit coordinates): its range over the
    /// highest-density region holding 95 % of the posterior, which holds the mode.
    pub intervals: Vec<[f64; 2]>,
    /// 95 % highest-density interval of each knob's marginal: the search's scale.
    pub marginal: Vec<[f64; 2]>,
    /// Posterior-predictive p-value of χ²: E over the posterior of P(χ²ₙ ≥ χ²(θ)).
    pub fit_p: f64,
    /// Effective number of points behind the integral.
    pub ess: f64,
}

/// The evidence of `target`'s explanation; `seed` fixes its importance samples.
pub fn evidence(target: &Target<'_>, seed: u64) -> Evidence {
    match target.free.len() {
        0 => nominal(target),
        1 => one_knob(target),
        _ => two_knobs(target, seed),
    }
}

impl Evidence {
    /// The evidence of nothing integrated yet, or of a posterior with no support, over `d`
    /// knobs.
    pub fn empty(d: usize) -> Evidence {
        Evidence {
            log_z: f64::NEG_INFINITY,
            log_z_laplace: f64::NAN,
            mode: vec![f64::NAN; d],
            chi2_mode: f64::NAN,
            intervals: vec![[f64::NAN; 2]; d],
            marginal: vec![[f64::NAN; 2]; d],
            fit_p: 0.0,
            ess: 0.0,
        }
    }
}

fn chi2_sf(chi2: f64, n: usize) -> f64 {
    crate::regression::dist::chi2_upper_p(chi2, n.max(1) as f64).unwrap_or(0.0)
}

fn nominal(target: &Target<'_>) -> Evidence {
    let (log_z, chi2) = target.eval(&[]);
    Evidence {
        log_z,
        log_z_laplace: log_z,
        mode: Vec::new(),
        chi2_mode: chi2,
        intervals: Vec::new(),
        marginal: Vec::new(),
        fit_p: chi2_sf(chi2, target.obs.len()),
        ess: 1.0,
    }
}

/// Weighted points of a posterior: (unit point, weight ∝ posterior mass, χ², width of the
/// quadrature cell it stands for — 0 for an importance sample).
struct Weighted {
    points: Vec<(Vec<f64>, f64, f64, f64)>,
}

impl Weighted {
    fn total(&self) -> f64 {
        self.points.iter().map(|p| p.1).sum()
    }

    /// The shortest interval of coordinate `axis` holding 95 % of the mass, from its first
    /// cell's lower edge to its last cell's upper edge (the most massive of equally short
    /// ones): the highest posterior density interval of a one-peaked marginal, holding its mode.
    fn shortest(&self, axis: usize) -> [f64; 2] {
        let on_axis = |p: &(Vec<f64>, f64, f64, f64)| (p.0[axis], p.1, p.3 / 2.0);
        let mut v: Vec<(f64, f64, f64)> = self.points.iter().map(on_axis).collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut cum = vec![0.0];
        for p in &v {
            cum.push(cum[cum.len() - 1] + p.1);
        }
        let need = 0.95 * cum[v.len()];
        let mut best = ([f64::NAN; 2], f64::INFINITY, 0.0);
        for i in 0..v.len() {
            let j = cum.partition_point(|c| c - cum[i] < need);
            if i < j && j <= v.len() {
                let iv = [v[i].0 - v[i].2, v[j - 1].0 + v[j - 1].2];
                let (len, mass) = (iv[1] - iv[0], cum[j] - cum[i]);
                if len < best.1 - 1e-9 || (len <= best.1 + 1e-9 && mass > best.2) {
                    best = (iv, len.min(best.1), mass);
                }
            }
        }
        best.0
    }

    fn intervals(&self, d: usize) -> Vec<[f64; 2]> {
        (0..d).map(|a| self.shortest(a)).collect()
    }

    fn fit_p(&self, n: usize) -> f64 {
        let total = self.total();
        self.points
            .iter()
            .map(|p| p.1 * chi2_sf(p.2, n))
            .sum::<f64>()
            / total
    }

    fn ess(&self) -> f64 {
        let s: f64 = self.total();
        let s2: f64 = self.points.iter().map(|p| p.1 * p.1).sum();
        s * s / s2
    }
}

/// One free knob: the midpoint rule on the slab's cells, each cell within eight posterior
/// widths of the mode subdivided finer than an eighth of that width.
fn one_knob(target: &Target<'_>) -> Evidence {
    let n = SLAB_CELLS;
    let h = 1.0 / n as f64;
    let coarse: Vec<(f64, f64, f64)> = (0..n)
        .map(|i| {
            let u = (i as f64 + 0.5) * h;
            let (l, c) = target.eval(&[u]);
            (u, l, c)
        })
        .collect();
    let Some(best) = coarse
        .iter()
        .filter(|p| p.1.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .copied()
    else {
        return Evidence::empty(1);
    };
    let (polished, lpol) = polish(target, &[best.0], h);
    let sigma = curvature_sd(target, polished[0]).unwrap_or(h);
    let reach = 8.0 * sigma;
    let sub = ((8.0 * h / sigma).ceil() as usize).clamp(1, 4096);
    // (u, ln density, χ², cell width) at every point of the rule.
    let mut raw: Vec<(f64, f64, f64, f64)> = Vec::new();
    for (i, &(u, l, c)) in coarse.iter().enumerate() {
        let (a, b) = (i as f64 * h, (i + 1) as f64 * h);
        if sub > 1 && b > polished[0] - reach && a < polished[0] + reach {
            let w = h / sub as f64;
            for j in 0..sub {
                let v = a + (j as f64 + 0.5) * w;
                let (lv, cv) = target.eval(&[v]);
                raw.push((v, lv, cv, w));
            }
        } else {
            raw.push((u, l, c, h));
        }
    }
    raw.retain(|p| p.1.is_finite());
    // The mode is the best point evaluated (on a knife-edge likelihood a point of the rule
    // can beat the polished one); weights relative to it never overflow.
    let (mode, lmax) = raw
        .iter()
        .map(|p| (p.0, p.1))
        .chain(std::iter::once((polished[0], lpol)))
        .filter(|p| p.1.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((polished[0], lpol));
    let w = Weighted {
        points: raw
            .into_iter()
            .map(|(u, l, c, width)| (vec![u], (l - lmax).exp() * width, c, width))
            .collect(),
    };
    let intervals = w.intervals(1);
    let log_z_laplace = curvature_sd(target, mode)
        .map(|s| lmax + 0.5 * (2.0 * std::f64::consts::PI).ln() + s.ln())
        .unwrap_or(f64::NAN);
    Evidence {
        log_z: lmax + w.total().ln(),
        log_z_laplace,
        chi2_mode: target.eval(&[mode]).1,
        mode: vec![mode],
        marginal: intervals.clone(),
        intervals,
        fit_p: w.fit_p(target.obs.len()),
        ess: w.ess(),
    }
}

/// The negative log density (a large finite cost outside the support), for the solver.
struct Cost<'a, 'b>(&'a Target<'b>);

impl argmin::core::CostFunction for Cost<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Self::Param) -> Result<f64, argmin::core::Error> {
        let l = self.0.eval(u).0;
        Ok(if l.is_finite() { -l } else { 1e100 })
    }
}

/// The mode near `start` (unit coordinates): argmin's Nelder–Mead with a simplex of edge
/// `step`; (mode, log density there).
fn polish(target: &Target<'_>, start: &[f64], step: f64) -> (Vec<f64>, f64) {
    let l0 = target.eval(start).0;
    let (u, _) = super::solver::nelder_mead(Cost(target), -l0, start, step, 400, 1e-10);
    let l = target.eval(&u).0;
    if l.is_finite() && l >= l0 {
        (u, l)
    } else {
        (start.to_vec(), l0)
    }
}

/// The posterior sd from the second difference of the log density at the mode (None where
/// it is not negative or a neighbour is outside the support).
fn curvature_sd(target: &Target<'_>, mode: f64) -> Option<f64> {
    let h = 1e-4;
    let (l0, lm, lp) = (
        target.eval(&[mode]).0,
        target.eval(&[mode - h]).0,
        target.eval(&[mode + h]).0,
    );
    let second = (lp - 2.0 * l0 + lm) / (h * h);
    (second.is_finite() && second < 0.0).then(|| 1.0 / (-second).sqrt())
}

/// A Student-t component of the proposal: centre, Cholesky factor of its scale, log
/// normaliser, weight.
struct Component {
    centre: [f64; 2],
    chol: [[f64; 2]; 2],
    log_norm: f64,
    weight: f64,
}

impl Component {
    fn new(centre: [f64; 2], cov: [[f64; 2]; 2], weight: f64) -> Option<Component> {
        let a = cov[0][0];
        if a <= 0.0 {
            return None;
        }
        let l00 = a.sqrt();
        let l10 = cov[1][0] / l00;
        let r = cov[1][1] - l10 * l10;
        if r <= 0.0 {
            return None;
        }
        let l11 = r.sqrt();
        // Γ(3)/(Γ(2)·ν·π) for ν = 4, d = 2.
        let log_norm = (1.0 / (2.0 * std::f64::consts::PI)).ln() - (l00 * l11).ln();
        Some(Component {
            centre,
            chol: [[l00, 0.0], [l10, l11]],
            log_norm,
            weight,
        })
    }

    fn log_density(&self, u: &[f64]) -> f64 {
        let d0 = (u[0] - self.centre[0]) / self.chol[0][0];
        let d1 = (u[1] - self.centre[1] - self.chol[1][0] * d0) / self.chol[1][1];
        self.log_norm - 0.5 * (T_DOF + 2.0) * (1.0 + (d0 * d0 + d1 * d1) / T_DOF).ln()
    }

    fn draw(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
        let (z0, z1) = (normal(rng), normal(rng));
        // χ²₄ = −2 ln(U₁U₂).
        let g = -2.0 * ((1.0 - rng.random::<f64>()) * (1.0 - rng.random::<f64>())).ln();
        let s = (T_DOF / g).sqrt();
        [
            self.centre[0] + s * self.chol[0][0] * z0,
            self.centre[1] + s * (self.chol[1][0] * z0 + self.chol[1][1] * z1),
        ]
    }
}

/// Two free knobs: defensive importance sampling.
fn two_knobs(target: &Target<'_>, seed: u64) -> Evidence {
    let modes = find_modes(target);
    if modes.is_empty() {
        return Evidence::empty(2);
    }
    let lmax = modes[0].1;
    let mut comps: Vec<Component> = modes
        .iter()
        .filter_map(|(m, l)| {
            let cell = (1.0 / MODE_GRID as f64).powi(2);
            let cov = covariance_at(target, *m).unwrap_or([[cell, 0.0], [0.0, cell]]);
            let laplace = l + 0.5 * det(&cov).max(1e-300).ln();
            let scaled = cov.map(|r| r.map(|v| v * 1.5 * 1.5));
            Component::new(*m, scaled, (laplace - lmax).exp())
        })
        .collect();
    let total: f64 = comps.iter().map(|c| c.weight).sum();
    comps
        .iter_mut()
        .for_each(|c| c.weight *= (1.0 - DEFENSIVE) / total);
    let defensive = if comps.is_empty() { 1.0 } else { DEFENSIVE };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let draws: Vec<[f64; 2]> = (0..SAMPLES)
        .map(|_| {
            let pick: f64 = rng.random();
            if pick < defensive || comps.is_empty() {
                return [rng.random::<f64>(), rng.random::<f64>()];
            }
            let mut acc = defensive;
            let chosen = comps.iter().find(|c| {
                acc += c.weight;
                pick < acc
            });
            chosen.unwrap_or(&comps[comps.len() - 1]).draw(&mut rng)
        })
        .collect();
    let evaluated: Vec<(Vec<f64>, f64, f64, f64)> = draws
        .iter()
        .map(|u| {
            let inside = u.iter().all(|v| (0.0..=1.0).contains(v));
            let (l, c) = if inside {
                target.eval(u)
            } else {
                (f64::NEG_INFINITY, f64::NAN)
            };
            let q = defensive
                + comps
                    .iter()
                    .map(|k| k.weight * k.log_density(u).exp())
                    .sum::<f64>();
            (u.to_vec(), l - q.ln(), c, l)
        })
        .collect();
    let top = evaluated
        .iter()
        .map(|p| p.1)
        .fold(f64::NEG_INFINITY, f64::max);
    // The most probable point: the best mode, or a sample that beat it (a narrow ridge the
    // grid missed), polished.
    let (mut mode, mut l_mode) = (modes[0].0, modes[0].1);
    if let Some(best) = evaluated
        .iter()
        .filter(|p| p.3.is_finite())
        .max_by(|a, b| a.3.total_cmp(&b.3))
        && best.3 > l_mode
    {
        let (u, l) = polish(target, &best.0, 1.0 / (4.0 * MODE_GRID as f64));
        (mode, l_mode) = ([u[0], u[1]], l);
    }
    let intervals = region(&evaluated, top, &mode);
    let w = Weighted {
        points: evaluated
            .into_iter()
            .filter(|p| p.1.is_finite())
            .map(|(u, lw, c, _)| (u, (lw - top).exp(), c, 0.0))
            .collect(),
    };
    if w.points.is_empty() {
        return Evidence::empty(2);
    }
    let log_z_laplace = covariance_at(target, mode)
        .filter(|c| det(c) > 0.0)
        .map_or(f64::NAN, |c| {
            l_mode + (2.0 * std::f64::consts::PI).ln() + 0.5 * det(&c).ln()
        });
    Evidence {
        log_z: top + (w.total() / SAMPLES as f64).ln(),
        log_z_laplace,
        chi2_mode: target.eval(&mode).1,
        mode: mode.to_vec(),
        intervals,
        marginal: w.intervals(2),
        fit_p: w.fit_p(target.obs.len()),
        ess: w.ess(),
    }
}

/// Each knob's range over the 95 % highest-density region of importance samples (u, ln
/// weight, χ², ln density): the densest samples holding 95 % of the weight, and the mode,
/// which a marginal interval of a thin ridge can miss.
fn region(samples: &[(Vec<f64>, f64, f64, f64)], top: f64, mode: &[f64]) -> Vec<[f64; 2]> {
    let mut by_density: Vec<_> = samples.iter().filter(|p| p.1.is_finite()).collect();
    by_density.sort_by(|a, b| b.3.total_cmp(&a.3));
    let need = 0.95 * by_density.iter().map(|p| (p.1 - top).exp()).sum::<f64>();
    let (mut out, mut held) = (mode.iter().map(|m| [*m, *m]).collect::<Vec<_>>(), 0.0);
    for p in by_density {
        if held >= need {
            break;
        }
        held += (p.1 - top).exp();
        for (o, x) in out.iter_mut().zip(&p.0) {
            *o = [o[0].min(*x), o[1].max(*x)];
        }
    }
    out
}

fn det(c: &[[f64; 2]; 2]) -> f64 {
    c[0][0] * c[1][1] - c[0][1] * c[1][0]
}

/// The local maxima of the log density on a [`MODE_GRID`]² grid within 20 nats of the best,
/// each polished by Nelder–Mead; at most three, best first.
fn find_modes(target: &Target<'_>) -> Vec<([f64; 2], f64)> {
    let n = MODE_GRID;
    let at = |i: usize| (i as f64 + 0.5) / n as f64;
    let grid: Vec<f64> = (0..n * n)
        .map(|k| target.eval(&[at(k / n), at(k % n)]).0)
        .collect();
    let best = grid.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !best.is_finite() {
        return Vec::new();
    }
    let mut peaks: Vec<(usize, f64)> = (0..n * n)
        .filter(|&k| {
            let (i, j) = (k / n, k % n);
            let l = grid[k];
            l.is_finite()
                && l > best - 20.0
                && (i.saturating_sub(1)..=(i + 1).min(n - 1)).all(|a| {
                    (j.saturating_sub(1)..=(j + 1).min(n - 1)).all(|b| grid[a * n + b] <= l)
                })
        })
        .map(|k| (k, grid[k]))
        .collect();
    peaks.sort_by(|a, b| b.1.total_cmp(&a.1));
    peaks.truncate(3);
    let mut out: Vec<([f64; 2], f64)> = peaks
        .into_iter()
        .map(|(k, _)| {
            let (u, l) = polish(target, &[at(k / n), at(k % n)], 1.0 / n as f64);
            ([u[0], u[1]], l)
        })
        .collect();
    out.sort_by(|a, b| b.1.total_cmp(&a.1));
    out
}

/// The negative log density's Hessian at `u` by central differences (step 1e-4).
fn hessian(target: &Target<'_>, u: [f64; 2]) -> [[f64; 2]; 2] {
    let h = 1e-4;
    let f = |a: f64, b: f64| target.eval(&[u[0] + a, u[1] + b]).0;
    let f0 = f(0.0, 0.0);
    let d00 = -(f(h, 0.0) - 2.0 * f0 + f(-h, 0.0)) / (h * h);
    let d11 = -(f(0.0, h) - 2.0 * f0 + f(0.0, -h)) / (h * h);
    let d01 = -(f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4.0 * h * h);
    [[d00, d01], [d01, d11]]
}

/// The posterior covariance at a mode: the inverse Hessian, where it is positive definite.
fn covariance_at(target: &Target<'_>, u: [f64; 2]) -> Option<[[f64; 2]; 2]> {
    let h = hessian(target, u);
    let d = det(&h);
    (h.iter().flatten().all(|v| v.is_finite()) && h[0][0] > 0.0 && d > 0.0)
        .then(|| [[h[1][1] / d, -h[0][1] / d], [-h[1][0] / d, h[0][0] / d]])
}

/// "Something outside these": beside an explanation's predictions, an independent Gaussian
/// discrepancy of sd κ·aᵢ per observation (aᵢ: its scale, [`scales`]), with ln κ uniform from
/// where the discrepancy becomes detectable ([`detectable_kappa`]) up to `max_relative`.
#[derive(Clone, Debug)]
pub struct Discrepancy {
    scales: Vec<f64>,
    lo: f64,
    hi: f64,
}

impl Discrepancy {
    /// The discrepancy of `obs`, its scales from the `nominal` walks; `None` when its range
    /// is empty (the trials cannot detect any discrepancy up to `max_relative`).
    pub fn new(obs: &[Observation], nominal: &[Walked], max_relative: f64) -> Option<Self> {
        let scales = scales(obs, nominal);
        let (lo, hi) = (detectable_kappa(obs, &scales)?.ln(), max_relative.ln());
        (lo.is_finite() && hi > lo).then_some(Discrepancy { scales, lo, hi })
    }

    /// (ln κ, log likelihood with κ, χ²) at each of the quadrature's cells, for the
    /// predictions `pred` (one per observation); the cells' width and largest log likelihood.
    fn cells(&self, obs: &[Observation], pred: &[f64]) -> (Vec<(f64, f64, f64)>, f64, f64) {
        let n = SLAB_CELLS;
        let h = (self.hi - self.lo) / n as f64;
        let cells: Vec<(f64, f64, f64)> = (0..n)
            .map(|i| {
                let t = self.lo + (i as f64 + 0.5) * h;
                let k2 = (2.0 * t).exp();
                let (mut ll, mut chi2) = (0.0, 0.0);
                for ((o, a), y) in obs.iter().zip(&self.scales).zip(pred) {
                    let var = o.total_sd().powi(2) + k2 * a * a;
                    let z2 = if y.is_finite() {
                        ((y - o.value).powi(2) / var).min(FELL_Z2)
                    } else {
                        FELL_Z2
                    };
                    chi2 += z2;
                    ll += -0.5 * z2 - 0.5 * (2.0 * std::f64::consts::PI * var).ln();
                }
                (t, ll - (self.hi - self.lo).ln(), chi2)
            })
            .collect();
        let lmax = cells.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
        (cells, h, lmax)
    }

    /// ln of the Bayes factor of "these predictions plus a discrepancy" over the predictions
    /// alone: the likelihood averaged over κ's prior, over the likelihood at κ = 0.
    pub fn log_bayes_factor(&self, obs: &[Observation], pred: &[f64]) -> f64 {
        let (cells, h, lmax) = self.cells(obs, pred);
        let log_z = lmax
            + cells
                .iter()
                .map(|c| (c.1 - lmax).exp() * h)
                .sum::<f64>()
                .ln();
        let chi2: f64 = obs.iter().zip(pred).map(|(o, y)| o.z2(*y)).sum();
        log_z - (super::likelihood::log_normaliser(obs) - 0.5 * chi2)
    }

    /// The discrepancy's posterior beside the predictions `pred`: κ's most probable value
    /// and 95 % interval (in `mode` and `intervals`), the evidence and its fit.
    pub fn posterior(&self, obs: &[Observation], pred: &[f64]) -> Evidence {
        let (lo, hi) = (self.lo, self.hi);
        let (cells, h, lmax) = self.cells(obs, pred);
        let du = h / (hi - lo);
        let w = Weighted {
            points: cells
                .iter()
                .map(|&(t, l, c)| (vec![(t - lo) / (hi - lo)], (l - lmax).exp() * h, c, du))
                .collect(),
        };
        let unit = w.intervals(1);
        let best = cells
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .copied()
            .unwrap_or((lo, lmax, f64::NAN));
        Evidence {
            log_z: lmax + w.total().ln(),
            log_z_laplace: f64::NAN,
            mode: vec![best.0.exp()],
            chi2_mode: best.2,
            intervals: unit
                .iter()
                .map(|[a, b]| [(lo + a * (hi - lo)).exp(), (lo + b * (hi - lo)).exp()])
                .collect(),
            marginal: unit,
            fit_p: w.fit_p(obs.len()),
            ess: w.ess(),
        }
    }
}

/// The smallest κ at which "something outside these" is detectable: the Kullback–Leibler
/// divergence of its predictive distribution from the nominal's reaches ½, as a suspect's
/// does at Σ z² = 1 ([`Slab`]). Per observation it is ½(u − ln(1 + u)), u = κ²aᵢ²/σᵢ².
/// Bisection in ln κ; None when no κ ≤ 10 reaches it.
fn detectable_kappa(obs: &[Observation], a: &[f64]) -> Option<f64> {
    let kl = |k: f64| -> f64 {
        obs.iter()
            .zip(a)
            .map(|(o, a)| {
                let u = (k * a / o.total_sd()).powi(2);
                0.5 * (u - u.ln_1p())
            })
            .sum()
    };
    let (mut lo, mut hi) = (-30.0f64, 10f64.ln());
    if kl(hi.exp()) < 0.5 {
        return None;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if kl(mid.exp()) < 0.5 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi.exp())
}

/// The scale of each observation for "something outside these": a metric's nominal value
/// (its measured value where the nominal fell); a cycle coefficient's signal RMS in the
/// nominal walk (the measured one where the nominal has none).
pub fn scales(obs: &[Observation], nominal: &[Walked]) -> Vec<f64> {
    use super::likelihood::Block;
    obs.iter()
        .map(|o| match o.block {
            Block::Metric(_) => {
                let y0 = nominal[o.trial].channel(o.channel);
                if y0.is_finite() {
                    y0.abs()
                } else {
                    o.value.abs()
                }
            }
            Block::Cycle(signal) => {
                let rms = |get: &dyn Fn(usize) -> f64| {
                    let s: f64 = (1..1 + 2 * super::waveform::HARMONICS)
                        .map(|c| get(signal.channel(c)).powi(2))
                        .sum();
                    (s / 2.0).sqrt()
                };
                let w = &nominal[o.trial];
                let r = rms(&|c| w.channel(super::trials::Metric::ALL.len() + c));
                if r.is_finite() && r > 0.0 {
                    r
                } else {
                    o.value.abs().max(o.sd)
                }
            }
        })
        .collect()
}
