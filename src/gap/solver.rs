//! The solver of the evidence's mode search: argmin's Nelder–Mead, started inside the unit
//! box of an explanation's free knobs.
//!
//! Why Nelder–Mead (argmin): the log density is a sum of squares of monotone cubic
//! interpolants, continuous with kinks where a knob's curve crosses a node, in one or two
//! dimensions; the solver needs no gradient and tolerates the kinks. It only polishes a
//! mode found on a grid (the integral itself does not depend on it beyond where the
//! proposal is centred).

use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;

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
