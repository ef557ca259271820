//! Solvers for the fits: argmin's Nelder–Mead from several starts on the surrogate's χ²
//! (cheap: no walks), and a grid scan for one coordinate (the starts, the profiles and the
//! group refits).
//!
//! Why Nelder–Mead (argmin): the cost is a sum of squares of monotone cubic interpolants,
//! continuous with kinks where a knob's curve crosses a node, bounded, and a few to a dozen
//! dimensions; the solver needs no gradient and tolerates the kinks. Multi-start covers the
//! non-convexity an effect's curve can bring (μ, a latency that makes a walker walk). The
//! solver is not where the time goes: a diagnosis spends > 95 % of it in walks
//! (reports/gap-speed.md), and every surrogate evaluation is microseconds, so a
//! population method (argmin's particle swarm, CMA-ES) would buy robustness at no walk
//! cost but has not been measured against this one here.
//!
//! And Levenberg–Marquardt in the unit box, for a fit on real walks of many knobs (the
//! residuals are walks: each Jacobian costs one walk per knob).

use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;

use super::problem::Objective;

/// Evaluations allowed per start: generous for ≤ 12 dimensions.
fn max_iters(dim: usize) -> u64 {
    (200 + 150 * dim) as u64
}

/// Minimises the objective over the unit box from each start (unit coordinates), with an
/// initial simplex of edge `step`; returns the best (point in the box, cost).
pub fn minimize(obj: &Objective<'_>, starts: &[Vec<f64>], step: f64) -> (Vec<f64>, f64) {
    let dim = obj.active.len();
    if dim == 0 {
        return (Vec::new(), obj.value(&[]));
    }
    let mut best: Option<(Vec<f64>, f64)> = None;
    for start in starts {
        let s0: Vec<f64> = start.iter().map(|v| v.clamp(0.0, 1.0)).collect();
        let (s, f) = nelder_mead(obj.clone(), obj.value(&s0), &s0, step, max_iters(dim), 1e-9);
        if best.as_ref().is_none_or(|(_, bf)| f < *bf) {
            best = Some((s, f));
        }
    }
    let (s, _) = best.unwrap_or_else(|| (vec![0.5; dim], f64::INFINITY));
    // One restart from the best point with a fresh simplex: Nelder–Mead's simplex can
    // collapse before the minimum in several dimensions (Lagarias et al. 1998).
    let s: Vec<f64> = s.iter().map(|v| v.clamp(0.0, 1.0)).collect();
    let (s, _) = if dim > 1 {
        nelder_mead(
            obj.clone(),
            obj.value(&s),
            &s,
            step / 2.0,
            max_iters(dim),
            1e-9,
        )
    } else {
        (s.clone(), obj.value(&s))
    };
    let s: Vec<f64> = s.iter().map(|v| v.clamp(0.0, 1.0)).collect();
    let f = obj.value(&s);
    (s, f)
}

/// argmin's Nelder–Mead on `cost` from `s0` (whose cost is `f0`), an initial simplex of edge
/// `step` stepping into the unit box, until `iters` iterations or the simplex's costs agree
/// within `sd_tolerance`. Returns the best point and cost, or the start if nothing beat it
/// (a cost that fails stops the search there).
pub fn nelder_mead<C>(
    cost: C,
    f0: f64,
    s0: &[f64],
    step: f64,
    iters: u64,
    sd_tolerance: f64,
) -> (Vec<f64>, f64)
where
    C: CostFunction<Param = Vec<f64>, Output = f64>,
{
    let dim = s0.len();
    let mut simplex = vec![s0.to_vec()];
    for i in 0..dim {
        let mut v = s0.to_vec();
        // Step into the box.
        v[i] = if v[i] + step <= 1.0 {
            v[i] + step
        } else {
            v[i] - step
        };
        simplex.push(v);
    }
    let solver = match NelderMead::new(simplex).with_sd_tolerance(sd_tolerance) {
        Ok(s) => s,
        Err(_) => return (s0.to_vec(), f0),
    };
    match Executor::new(cost, solver)
        .configure(|state| state.max_iters(iters))
        .run()
    {
        Ok(res) => {
            let state = res.state();
            match state.get_best_param() {
                Some(p) if state.get_best_cost() < f0 => (p.clone(), state.get_best_cost()),
                _ => (s0.to_vec(), f0),
            }
        }
        Err(_) => (s0.to_vec(), f0),
    }
}

/// Golden-section search of `eval` on [a, b]: two evaluations open the bracket, then one per
/// reduction (`reductions` of them). Returns the better of the final pair (x, cost, payload);
/// every point the search discarded was worse than one it kept, so that is the best point
/// it evaluated. `eval` returns the cost and whatever the caller keeps of the evaluation
/// (the walks), so a refinement on real walks does not walk the winner twice.
///
/// Hand-written, not argmin's `GoldenSectionSearch`: the callers need the winner's payload
/// and a fallible cost, and the evaluations are walks, so the exact sequence of points is
/// part of what the benchmark reports.
pub fn golden_section<T, E>(
    a: f64,
    b: f64,
    reductions: usize,
    mut eval: impl FnMut(f64) -> Result<(f64, T), E>,
) -> Result<(f64, f64, T), E> {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (a, b);
    let (mut c, mut d) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fc, mut fd) = (eval(c)?, eval(d)?);
    for _ in 0..reductions {
        if fc.0 < fd.0 {
            hi = d;
            d = c;
            fd = fc;
            c = hi - g * (hi - lo);
            fc = eval(c)?;
        } else {
            lo = c;
            c = d;
            fc = fd;
            d = lo + g * (hi - lo);
            fd = eval(d)?;
        }
    }
    Ok(if fc.0 < fd.0 {
        (c, fc.0, fc.1)
    } else {
        (d, fd.0, fd.1)
    })
}

/// Scans unit coordinate `i` of the active knobs over `n` evenly spaced values with the
/// others at `s`: the values and costs.
pub fn scan(obj: &Objective<'_>, s: &[f64], i: usize, n: usize) -> Vec<(f64, f64)> {
    let n = n.max(2);
    (0..n)
        .map(|k| {
            let t = k as f64 / (n - 1) as f64;
            let mut v = s.to_vec();
            v[i] = t;
            (t, obj.value(&v))
        })
        .collect()
}

/// The local minima of a scan, best first (at most `k`).
pub fn scan_minima(scan: &[(f64, f64)], k: usize) -> Vec<f64> {
    let mut minima: Vec<(f64, f64)> = Vec::new();
    for j in 0..scan.len() {
        let left = if j > 0 { scan[j - 1].1 } else { f64::INFINITY };
        let right = scan.get(j + 1).map(|p| p.1).unwrap_or(f64::INFINITY);
        if scan[j].1 <= left && scan[j].1 <= right {
            minima.push(scan[j]);
        }
    }
    minima.sort_by(|a, b| a.1.total_cmp(&b.1));
    minima.into_iter().take(k).map(|m| m.0).collect()
}

/// Settings of [`levenberg_marquardt`].
#[derive(Clone, Copy, Debug)]
pub struct LmSettings {
    /// Jacobians at most.
    pub iters: usize,
    /// Damped steps tried per Jacobian before giving up.
    pub tries: usize,
    /// Forward-difference step (unit coordinates), taken into the box.
    pub step: f64,
    /// First damping: the share of JᵀJ's diagonal added to it (Marquardt's scaling).
    pub lambda0: f64,
}

/// One damped Gauss–Newton step for residuals `r` with Jacobian `jac`: the δ that solves
/// (JᵀJ + λ·diag(JᵀJ))·δ = −Jᵀr (Marquardt's scaling), or `None` where that matrix is
/// not positive definite.
pub fn gauss_newton_step(jac: &nalgebra::DMatrix<f64>, r: &[f64], lambda: f64) -> Option<Vec<f64>> {
    let jtj = jac.transpose() * jac;
    let g = jac.transpose() * nalgebra::DVector::from_column_slice(r);
    let mut a = jtj.clone();
    for i in 0..jac.ncols() {
        a[(i, i)] += lambda * jtj[(i, i)].max(1e-12);
    }
    let delta = a.cholesky()?.solve(&(-g));
    Some(delta.iter().copied().collect())
}

/// The forward-difference Jacobian of `residuals` at `s` in the unit box, whose residuals are
/// `r0`: one evaluation per coordinate, moved by `step` (backward where forward would leave
/// the box). `None` where a moved point's residuals are not as many as `r0`.
pub fn forward_jacobian<E>(
    mut residuals: impl FnMut(&[f64]) -> Result<Vec<f64>, E>,
    s: &[f64],
    r0: &[f64],
    step: f64,
) -> Result<Option<nalgebra::DMatrix<f64>>, E> {
    let mut jac = nalgebra::DMatrix::<f64>::zeros(r0.len(), s.len());
    for i in 0..s.len() {
        let h = if s[i] + step <= 1.0 { step } else { -step };
        let mut u = s.to_vec();
        u[i] += h;
        let ri = residuals(&u)?;
        if ri.len() != r0.len() {
            return Ok(None);
        }
        for (row, (a, b)) in ri.iter().zip(r0).enumerate() {
            jac[(row, i)] = (a - b) / h;
        }
    }
    Ok(Some(jac))
}

/// Levenberg–Marquardt on residuals r(s) over the unit box (cost Σr²), from `start` whose
/// residuals are `r0`: a forward-difference Jacobian, the damped normal equations
/// (JᵀJ + λ·diag JᵀJ) δ = −Jᵀr solved by Cholesky, the step clipped to the box and taken
/// if it lowers the cost (λ / 3), otherwise λ × 4 and another try. Returns the best point
/// and its residuals.
///
/// Hand-written: argmin has Gauss–Newton but no Levenberg–Marquardt and no bounds, and
/// here each residual evaluation is a dozen walks, so the count of evaluations (at most
/// iters · (dim + tries)) must be fixed by the caller.
pub fn levenberg_marquardt<E>(
    mut residuals: impl FnMut(&[f64]) -> Result<Vec<f64>, E>,
    start: &[f64],
    r0: Vec<f64>,
    set: &LmSettings,
) -> Result<(Vec<f64>, Vec<f64>), E> {
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut s: Vec<f64> = start.iter().map(|v| v.clamp(0.0, 1.0)).collect();
    let mut r = r0;
    let mut f = cost(&r);
    let mut lambda = set.lambda0;
    for _ in 0..set.iters {
        let Some(jac) = forward_jacobian(&mut residuals, &s, &r, set.step)? else {
            break;
        };
        let mut accepted = false;
        for _ in 0..set.tries {
            let Some(delta) = gauss_newton_step(&jac, &r, lambda) else {
                lambda *= 4.0;
                continue;
            };
            let u: Vec<f64> = s
                .iter()
                .zip(delta.iter())
                .map(|(x, d)| (x + d).clamp(0.0, 1.0))
                .collect();
            let ru = residuals(&u)?;
            let fu = cost(&ru);
            if fu < f - 1e-9 {
                (s, r, f) = (u, ru, fu);
                lambda = (lambda / 3.0).max(1e-9);
                accepted = true;
                break;
            }
            lambda *= 4.0;
        }
        if !accepted {
            break;
        }
    }
    Ok((s, r))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (x − 0.3)² on [0, 1]: after n reductions the bracket is 0.618ⁿ⁺¹ wide, so 30 of them
    /// place the minimum within 1e-6; the evaluations are 2 + n.
    #[test]
    fn golden_section_finds_a_parabola_minimum() {
        let mut calls = 0;
        let (x, f, payload) = golden_section(0.0, 1.0, 30, |x| {
            calls += 1;
            Ok::<_, ()>(((x - 0.3f64).powi(2), x * 2.0))
        })
        .expect("no error");
        assert!((x - 0.3).abs() < 1e-6, "{x}");
        assert!(f < 1e-12 && (payload - 2.0 * x).abs() < 1e-15);
        assert_eq!(calls, 32);
    }

    /// Levenberg–Marquardt from `start` with `iters` Jacobians (tight difference step).
    fn solve(
        mut res: impl FnMut(&[f64]) -> Result<Vec<f64>, ()>,
        start: &[f64],
        iters: usize,
    ) -> (Vec<f64>, Vec<f64>) {
        let set = LmSettings {
            iters,
            tries: 8,
            step: 1e-7,
            lambda0: 1e-3,
        };
        let r0 = res(start).expect("r0");
        levenberg_marquardt(res, start, r0, &set).expect("lm")
    }

    /// r(s) = (2·s₀ + s₁, 3·s₁) has the Jacobian [[2, 1], [0, 3]] everywhere (by hand), and
    /// forward differences are exact on a linear map: at s = (0.5, 1) the second coordinate
    /// is moved backward (the map refuses points outside the box) and must give the same
    /// column. Residuals that change in number have no Jacobian.
    #[test]
    fn forward_jacobian_of_a_linear_map_is_its_matrix() {
        let lin = |s: &[f64]| {
            if s.iter().any(|v| !(0.0..=1.0).contains(v)) {
                return Err(format!("{s:?} is outside the box"));
            }
            Ok(vec![2.0 * s[0] + s[1], 3.0 * s[1]])
        };
        let s = [0.5, 1.0];
        let r0 = lin(&s).expect("residuals");
        let jac = forward_jacobian(lin, &s, &r0, 1.0 / 64.0)
            .expect("residuals")
            .expect("same count");
        let want = [[2.0, 1.0], [0.0, 3.0]];
        for (i, row) in want.iter().enumerate() {
            for (j, w) in row.iter().enumerate() {
                assert!(
                    (jac[(i, j)] - w).abs() < 1e-9,
                    "({i}, {j}): {}",
                    jac[(i, j)]
                );
            }
        }
        let ragged = |s: &[f64]| Ok::<_, String>(vec![s[0]; if s[0] > 0.5 { 3 } else { 2 }]);
        assert!(
            forward_jacobian(ragged, &s, &r0, 1.0 / 64.0)
                .expect("residuals")
                .is_none()
        );
    }

    /// J = [[1, 0], [0, 2], [1, 1]], r = (1, 2, 3): JᵀJ = [[2, 1], [1, 5]], Jᵀr = (4, 7), so
    /// the undamped step is −(JᵀJ)⁻¹Jᵀr = −(13, 10)/9 (by hand); damped by λ = 1 the
    /// matrix is [[4, 1], [1, 10]] and the step −(33, 24)/39. A zero Jacobian has none.
    #[test]
    fn gauss_newton_step_solves_the_normal_equations_by_hand() {
        let jac = nalgebra::DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 2.0, 1.0, 1.0]);
        let r = [1.0, 2.0, 3.0];
        let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        let d0 = gauss_newton_step(&jac, &r, 0.0).expect("positive definite");
        assert!(close(&d0, &[-13.0 / 9.0, -10.0 / 9.0]), "{d0:?}");
        let d1 = gauss_newton_step(&jac, &r, 1.0).expect("positive definite");
        assert!(close(&d1, &[-33.0 / 39.0, -24.0 / 39.0]), "{d1:?}");
        let zero = nalgebra::DMatrix::<f64>::zeros(3, 2);
        assert!(gauss_newton_step(&zero, &r, 0.0).is_none());
    }

    /// Linear least squares r = A s − b, whose minimum (A's normal equations, solved by
    /// hand: s = (0.25, 0.75)) lies inside the box: forward differences are exact on a
    /// linear map, so a few damped Gauss–Newton steps land on it.
    #[test]
    fn levenberg_marquardt_solves_a_linear_least_squares_problem() {
        // A = [[1, 0], [0, 2], [1, 1]], b = A·(0.25, 0.75) + a residual orthogonal to A's
        // columns, (1, 0.5, −1)·0.1 (Aᵀ·(1, 0.5, −1) = (0, 0)).
        let res = |s: &[f64]| -> Result<Vec<f64>, ()> {
            let b = [0.25 + 0.1, 1.5 + 0.05, 1.0 - 0.1];
            Ok(vec![s[0] - b[0], 2.0 * s[1] - b[1], s[0] + s[1] - b[2]])
        };
        let (s, r) = solve(res, &[0.9, 0.1], 20);
        assert!(
            (s[0] - 0.25).abs() < 1e-6 && (s[1] - 0.75).abs() < 1e-6,
            "{s:?}"
        );
        let cost: f64 = r.iter().map(|v| v * v).sum();
        // The orthogonal residual is all that is left: 0.01 · (1 + 0.25 + 1).
        assert!((cost - 0.0225).abs() < 1e-9, "{cost}");
    }

    /// Rosenbrock's valley shifted into the box, r = (10 (s₁ − s₀²), 0.6 − s₀): the minimum
    /// is s = (0.6, 0.36) with cost 0, reached along the curved valley from (0.1, 0.9).
    #[test]
    fn levenberg_marquardt_follows_rosenbrocks_valley() {
        let res = |s: &[f64]| -> Result<Vec<f64>, ()> {
            Ok(vec![10.0 * (s[1] - s[0] * s[0]), 0.6 - s[0]])
        };
        let (s, _) = solve(res, &[0.1, 0.9], 200);
        assert!(
            (s[0] - 0.6).abs() < 1e-4 && (s[1] - 0.36).abs() < 1e-4,
            "{s:?}"
        );
    }

    /// A minimum outside the box (r = s₀ − 1.5, s₁ − 0.5): the step is clipped, so the
    /// answer is the box's face s₀ = 1 with s₁ free, and nothing leaves the box.
    #[test]
    fn levenberg_marquardt_stays_in_the_box() {
        let mut seen_outside = false;
        let res = |s: &[f64]| -> Result<Vec<f64>, ()> {
            seen_outside |= s.iter().any(|v| !(0.0..=1.0).contains(v));
            Ok(vec![s[0] - 1.5, s[1] - 0.5])
        };
        let (s, r) = solve(res, &[0.2, 0.2], 30);
        assert!(!seen_outside);
        assert_eq!(s[0], 1.0);
        assert!((s[1] - 0.5).abs() < 1e-6, "{s:?}");
        assert!((r[0] + 0.5).abs() < 1e-12);
    }
}
