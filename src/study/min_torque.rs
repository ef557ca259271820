//! The minimum hip torque at which a design walks consistently (the paper's Table III
//! quantity, "minimum torque for consistent walking", which the paper tuned by hand).
//!
//! The *problem* ([`WalksAt`]) answers one question — does the design walk at this torque
//! limit (servo) or torque magnitude (bang-bang)? — and the *solver* ([`min_torque`])
//! brackets and bisects on it, in the spirit of argmin's split of problem and solver.
//!
//! Definition (stated so a user can reproduce it): at torque τ the design *walks
//! consistently* when, for every one of `seeds` deterministic perturbations of the initial
//! state (and the unperturbed start), the walk does not fall and its steady forward speed
//! exceeds the design's threshold (`criteria.walk_speed_threshold_over_sqrt_gl` ·√(gL)).
//! The minimum torque is the smallest such τ, found to a relative tolerance by bisection
//! between a failing and a walking torque; the search starts at the design's own torque
//! (or a warm start, e.g. the neighbouring size's answer scaled by m·g·L) and halves or
//! doubles it to bracket. Above `cap_over_mgl`·m·g·L the design is declared not to walk at
//! that size with its 1× control. Walking need not be monotonic in torque; the search
//! reports the walking torque it converged to and the failing one below it.

use serde::Serialize;

use crate::sim::{
    ContactScaling, Design, GRAVITY_MPS2, MassLaw, SimError, WalkOptions, WalkReport, simulate_walk,
};

/// Settings of the search.
#[derive(Clone, Debug)]
pub struct MinTorqueOptions {
    /// Size, mass law, contact rule, duration (its `torque_limit_nm` and `seed` are set by
    /// the search).
    pub walk: WalkOptions,
    /// Number of seeded perturbations besides the unperturbed start (seeds 1..=k).
    pub seeds: u64,
    /// Relative width of the final bracket, (hi − lo)/hi.
    pub rel_tol: f64,
    /// Largest torque tried, in units of m·g·L.
    pub cap_over_mgl: f64,
    /// First torque tried [N·m] (None: the scaled design's own).
    pub start_nm: Option<f64>,
    /// Warm start: a bracket [failing, walking] expected to hold (e.g. the neighbouring
    /// size's, rescaled by m·g·L). Its walking end is tried first and its width is the
    /// first step; the step squares (up to ×2) while the bracket is not confirmed.
    pub start_bracket_nm: Option<[f64; 2]>,
}

impl Default for MinTorqueOptions {
    fn default() -> Self {
        MinTorqueOptions {
            walk: WalkOptions {
                record_trajectory: false,
                ..WalkOptions::default()
            },
            seeds: 2,
            rel_tol: 0.02,
            cap_over_mgl: 2.0,
            start_nm: None,
            start_bracket_nm: None,
        }
    }
}

/// The answer for one design, size and mass law.
#[derive(Clone, Debug, Serialize)]
pub struct MinTorqueResult {
    pub design: String,
    pub leg_length_m: f64,
    pub mass_kg: f64,
    pub mass_law: MassLaw,
    pub contact: ContactScaling,
    /// m·g·L [N·m], the torque unit of dynamic similarity.
    pub mgl_nm: f64,
    /// False when no torque up to the cap walks consistently.
    pub walks: bool,
    pub min_torque_nm: Option<f64>,
    pub min_torque_over_mgl: Option<f64>,
    /// [failing, walking] torques of the final bracket [N·m].
    pub bracket_nm: Option<[f64; 2]>,
    /// Walks simulated (each seed counts).
    pub walks_evaluated: usize,
    /// The walk at the minimum torque (unperturbed start).
    pub gait: Option<WalkReport>,
    /// What goes wrong just below it: the first failing walk's fall reason, or
    /// "no_progress" when it stays up but does not move forward.
    pub failure_below: Option<String>,
    /// The definition used, in words.
    pub criterion: String,
}

/// The problem: does the design walk consistently at torque τ?
pub struct WalksAt<'a> {
    pub design: &'a Design,
    pub walk: &'a WalkOptions,
    pub seeds: u64,
    /// Walks simulated so far.
    pub evaluated: usize,
}

/// One evaluation: Ok(report of the unperturbed start) when every start walks, else the
/// first failing report.
type Verdict = Result<WalkReport, WalkReport>;

impl WalksAt<'_> {
    fn run(&mut self, torque_nm: f64, seed: Option<u64>) -> Result<WalkReport, SimError> {
        let o = WalkOptions {
            torque_limit_nm: Some(torque_nm),
            seed,
            record_trajectory: false,
            ..self.walk.clone()
        };
        self.evaluated += 1;
        Ok(simulate_walk(self.design, &o)?.report)
    }

    /// Runs the unperturbed start, then the seeded ones, stopping at the first failure.
    pub fn evaluate(&mut self, torque_nm: f64) -> Result<Verdict, SimError> {
        let base = self.run(torque_nm, None)?;
        if !base.walks {
            return Ok(Err(base));
        }
        for seed in 1..=self.seeds {
            let r = self.run(torque_nm, Some(seed))?;
            if !r.walks {
                return Ok(Err(r));
            }
        }
        Ok(Ok(base))
    }
}

fn failure(r: &WalkReport) -> String {
    r.fall_reason
        .clone()
        .unwrap_or_else(|| "no_progress".into())
}

/// `opts`' tolerance and cap in range, or which one is not.
fn check_options(opts: &MinTorqueOptions) -> Result<(), SimError> {
    if !(opts.rel_tol > 0.0 && opts.rel_tol < 0.5) {
        return Err(SimError::InvalidOption {
            option: "rel_tol".into(),
            reason: format!("must be in (0, 0.5), got {}", opts.rel_tol),
        });
    }
    if !(opts.cap_over_mgl > 0.0 && opts.cap_over_mgl.is_finite()) {
        return Err(SimError::InvalidOption {
            option: "cap_over_mgl".into(),
            reason: format!("must be finite and > 0, got {}", opts.cap_over_mgl),
        });
    }
    Ok(())
}

/// A bracket: the failing torque, the walking one, the walk there and the failure below.
type Bracket = (f64, f64, WalkReport, WalkReport);

/// Brackets the minimum torque from `start`, stepping by `ratio`, which squares (up to 2) at
/// every step that does not close the bracket. None when the search ends without one, with
/// `result` filled: a passive gait (walks with almost no torque), or no walk up to `cap`.
fn bracket(
    problem: &mut WalksAt<'_>,
    start: f64,
    mut ratio: f64,
    [mgl, cap]: [f64; 2],
    result: &mut MinTorqueResult,
) -> Result<Option<Bracket>, SimError> {
    match problem.evaluate(start)? {
        Ok(g) => {
            let (mut hi, mut gait) = (start, g);
            loop {
                let t = hi / ratio;
                if t < 1e-4 * mgl {
                    result.walks = true;
                    result.min_torque_nm = Some(t);
                    result.min_torque_over_mgl = Some(t / mgl);
                    result.bracket_nm = Some([0.0, t]);
                    result.gait = Some(gait);
                    return Ok(None);
                }
                match problem.evaluate(t)? {
                    Ok(g) => {
                        hi = t;
                        gait = g;
                        ratio = (ratio * ratio).min(2.0);
                    }
                    Err(f) => return Ok(Some((t, hi, gait, f))),
                }
            }
        }
        Err(f) => {
            let (mut lo, mut fail) = (start, f);
            loop {
                if lo >= cap {
                    result.failure_below = Some(failure(&fail));
                    return Ok(None);
                }
                let t = (lo * ratio).min(cap);
                match problem.evaluate(t)? {
                    Ok(g) => return Ok(Some((lo, t, g, fail))),
                    Err(f) => {
                        lo = t;
                        fail = f;
                        ratio = (ratio * ratio).min(2.0);
                    }
                }
            }
        }
    }
}

/// The solver: bracket, then bisect to `rel_tol`.
pub fn min_torque(design: &Design, opts: &MinTorqueOptions) -> Result<MinTorqueResult, SimError> {
    check_options(opts)?;
    let scaled = design.scaled(
        opts.walk
            .leg_length_m
            .unwrap_or(design.geometry.leg_length_m),
        opts.walk.mass_law,
        opts.walk.contact_scaling,
    )?;
    let l = scaled.geometry.leg_length_m;
    let m = scaled.mass.total_mass_kg;
    let mgl = m * GRAVITY_MPS2 * l;
    let cap = opts.cap_over_mgl * mgl;
    // First torque and first step ratio: the warm bracket's walking end and width, or the
    // design's own torque and a factor 2.
    let (start, ratio) = match opts.start_bracket_nm {
        Some([lo, hi]) if lo > 0.0 && hi > lo && hi.is_finite() => {
            (hi, (hi / lo).max(1.0 + 0.5 * opts.rel_tol))
        }
        _ => (
            opts.start_nm
                .unwrap_or_else(|| scaled.controller().torque_limit_nm().unwrap_or(mgl)),
            2.0,
        ),
    };
    let start = start.clamp(1e-6 * mgl, cap);
    let mut problem = WalksAt {
        design,
        walk: &opts.walk,
        seeds: opts.seeds,
        evaluated: 0,
    };
    let criterion = format!(
        "no fall and steady forward speed > {} √(gL) from the unperturbed start and {} seeded \
         perturbations; bisection to {:.1} % relative; cap {} m·g·L",
        scaled.criteria.walk_speed_threshold_over_sqrt_gl,
        opts.seeds,
        100.0 * opts.rel_tol,
        opts.cap_over_mgl
    );
    let mut result = MinTorqueResult {
        design: scaled.name.clone(),
        leg_length_m: l,
        mass_kg: m,
        mass_law: opts.walk.mass_law,
        contact: opts.walk.contact_scaling,
        mgl_nm: mgl,
        walks: false,
        min_torque_nm: None,
        min_torque_over_mgl: None,
        bracket_nm: None,
        walks_evaluated: 0,
        gait: None,
        failure_below: None,
        criterion,
    };
    let Some((mut lo, mut hi, mut gait, mut below)) =
        bracket(&mut problem, start, ratio, [mgl, cap], &mut result)?
    else {
        result.walks_evaluated = problem.evaluated;
        return Ok(result);
    };
    while (hi - lo) / hi > opts.rel_tol {
        let mid = 0.5 * (lo + hi);
        match problem.evaluate(mid)? {
            Ok(g) => {
                hi = mid;
                gait = g;
            }
            Err(f) => {
                lo = mid;
                below = f;
            }
        }
    }
    result.walks = true;
    result.min_torque_nm = Some(hi);
    result.min_torque_over_mgl = Some(hi / mgl);
    result.bracket_nm = Some([lo, hi]);
    result.walks_evaluated = problem.evaluated;
    result.gait = Some(gait);
    result.failure_below = Some(failure(&below));
    Ok(result)
}
