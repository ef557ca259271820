//! Forward selection over knobs: which parameters are off and which effects are missing.
//!
//! From the nominal model, each step fits every knob not yet in the model and keeps the
//! best by held-out χ² if it passes every rule:
//! * **significant**: the likelihood-ratio statistic, scaled by the over-dispersion left
//!   after the fit (quasi-likelihood F test), below α/K (K candidates at the step);
//! * **better held out**: the held-out χ² (leave one condition out) falls;
//! * **material**: the held-out gap (RMS z) shrinks by ≥ 10 % at the step, or the model now
//!   fits within noise;
//! * **inside its range**: the fitted value is not at an end of the plausible range;
//! * **consistent**: one value serves every size and drive setting (no group of conditions
//!   gets worse with the knob than without it, beyond two sds of the group's χ²);
//! * for an effect, **beats the recalibration**: with every uncertain parameter free as a
//!   nuisance, adding the effect is still significant. A knob that makes the model walk but
//!   that a plausible error of the nominal parameters explains as well is not called.
//!
//! Each rule is checked on the surrogate first and confirmed with real walks. The steps form
//! the chain ("hip friction: −55 %; + soft ground: −30 % more"); candidates within a small
//! χ² of the chosen one are reported as not separable by these trials.

use serde::Serialize;

use super::error::GapError;
use super::fit::{Consistency, Fit, FitContext, dispersion, lr_p_value};
use super::knob::KnobKind;
use crate::regression::dist::{chi2_upper_p, normal_quantile};

#[derive(Clone, Debug)]
pub struct SelectOptions {
    /// Family-wise false-alarm rate of each step's tests.
    pub alpha: f64,
    /// Smallest shrink of the held-out gap a step must make (unless it reaches noise).
    pub material_shrink: f64,
    pub max_steps: usize,
    /// Recalibrate every uncertain parameter even when no effect needs the test (for the
    /// report's table); otherwise only when an effect is tested.
    pub always_recalibrate: bool,
}

impl Default for SelectOptions {
    fn default() -> Self {
        SelectOptions {
            alpha: 0.001,
            material_shrink: 0.10,
            max_steps: 4,
            always_recalibrate: true,
        }
    }
}

/// Why a candidate was not taken at a step (or "chosen").
#[derive(Clone, Debug, Serialize)]
pub struct CandidateRow {
    pub knob: String,
    pub kind: KnobKind,
    /// Fitted value in SI (the design at 1×).
    pub value_si: f64,
    /// Held-out gap (RMS z) of the model with this knob added.
    pub gap_after: f64,
    pub lr: f64,
    pub p_value: f64,
    pub verdict: String,
}

/// One step of the chain.
#[derive(Clone, Debug, Serialize)]
pub struct Step {
    pub knob: String,
    pub kind: KnobKind,
    /// Fitted value of the added knob in SI (the design at 1×), in the final model of the
    /// step; all free knobs' values are in `values_si`.
    pub value_si: f64,
    pub values_si: Vec<(String, f64)>,
    /// Held-out gap (RMS z) after the step.
    pub gap_after: f64,
    /// Shrink of the held-out gap at this step, % of the gap before the step.
    pub shrink_pct: f64,
    /// Shrink of the held-out gap from the nominal, % (cumulative).
    pub shrink_total_pct: f64,
    pub lr: f64,
    pub dispersion: f64,
    pub p_value: f64,
    /// Effects: the test against the recalibrated nominal (all parameters free).
    pub p_value_vs_recalibration: Option<f64>,
    pub consistency: Vec<Consistency>,
    /// χ²/dof and p of the model after the step: within noise when p ≥ α.
    pub within_noise_after: bool,
    /// Other candidates these trials cannot tell from the chosen one (significant, and
    /// within the identification distance (2·z₀.₉)²·φ of its χ², confirmed with walks). A
    /// step with any is ambiguous: it explains the gap, but the answer names none of them.
    pub not_separable_from: Vec<String>,
    pub candidates: Vec<CandidateRow>,
}

pub struct Selection {
    pub steps: Vec<Step>,
    pub final_fit: Fit,
    /// The best recalibration of the nominal (every uncertain parameter free), refined;
    /// None without uncertain parameters, or when no test needed it and the options did not
    /// ask for it.
    pub recalibration: Option<Fit>,
    /// Candidates of the last step that failed only for being at a range end or
    /// inconsistent: worth telling the user.
    pub notes: Vec<String>,
    /// Every knob alone from the nominal (surrogate fits with held-out χ²).
    pub singles: Vec<(usize, Fit)>,
}

/// Held-out RMS z of a fit.
pub fn gap_of(fit: &Fit, n: usize) -> f64 {
    (fit.held_out.unwrap_or(fit.chi2_data) / n.max(1) as f64).sqrt()
}

/// The data χ² is within noise at level α (n − k dof).
pub fn within_noise(fit: &Fit, n: usize, alpha: f64) -> bool {
    let dof = n.saturating_sub(fit.k());
    dof > 0 && chi2_upper_p(fit.chi2_data, dof as f64).unwrap_or(0.0) >= alpha
}

/// χ² difference below which two candidates of one step are not separable: the
/// identification distance (2·z₀.₉)², the χ² a 90 %-sure distinction needs.
fn separable_margin() -> f64 {
    let z = 2.0 * normal_quantile(0.9).unwrap_or(1.2816);
    z * z
}

pub fn select(
    ctx: &FitContext<'_>,
    opts: &SelectOptions,
    nominal: &Fit,
    groupings: &[(String, Vec<usize>)],
    labels: &[String],
) -> Result<Selection, GapError> {
    let n = ctx.n();
    let knobs = &ctx.knobs.list;
    let params: Vec<usize> = (0..knobs.len())
        .filter(|k| knobs[*k].kind == KnobKind::Parameter)
        .collect();
    // Every knob alone from the nominal: the first step's candidates, and starts for the
    // recalibration.
    (ctx.progress)("fitting every knob alone");
    let singles: Vec<(usize, Fit)> = (0..knobs.len())
        .map(|c| {
            let starts = ctx.starts_adding(nominal, c);
            (c, ctx.with_held_out(ctx.screen(&[c], &starts, nominal)))
        })
        .collect();
    // The recalibration of every uncertain parameter, the baseline of the effect tests: made
    // when first needed.
    let mut recalibration: Option<Fit> = None;
    let mut baseline: Option<Fit> = None;
    let recalibrated = |recalibration: &mut Option<Fit>| -> Result<Fit, GapError> {
        if let Some(r) = recalibration {
            return Ok(r.clone());
        }
        (ctx.progress)("recalibrating the nominal parameters");
        let r = ctx.with_held_out(recalibrate(ctx, nominal, &params, &singles)?);
        *recalibration = Some(r.clone());
        Ok(r)
    };
    let mut current = nominal.clone();
    let mut steps: Vec<Step> = Vec::new();
    let mut notes = Vec::new();
    let gap0 = gap_of(nominal, n);
    for _ in 0..opts.max_steps {
        let cands: Vec<usize> = (0..knobs.len())
            .filter(|k| !current.active.contains(k))
            .collect();
        if cands.is_empty() || n <= current.k() + 1 {
            break;
        }
        let alpha_step = opts.alpha / cands.len() as f64;
        (ctx.progress)(&format!(
            "step {}: fitting {} candidates",
            steps.len() + 1,
            cands.len()
        ));
        let mut screened: Vec<(usize, Fit)> = if current.active.is_empty() {
            singles.clone()
        } else {
            cands
                .iter()
                .map(|&c| {
                    let mut active = current.active.clone();
                    active.push(c);
                    let starts = ctx.starts_adding(&current, c);
                    let f = ctx.screen(&active, &starts, &current);
                    (c, ctx.with_held_out(f))
                })
                .collect()
        };
        screened.sort_by(|a, b| {
            a.1.held_out
                .unwrap_or(f64::INFINITY)
                .total_cmp(&b.1.held_out.unwrap_or(f64::INFINITY))
        });
        let mut rows: Vec<CandidateRow> = Vec::new();
        let mut chosen: Option<Step> = None;
        let mut next: Option<(Fit, Option<Fit>)> = None;
        let mut attempts = 0;
        // Candidates confirmed with walks at this step (for the ambiguity check).
        let mut walked: Vec<(usize, Fit)> = Vec::new();
        for (c, f) in &screened {
            let knob = &knobs[*c];
            let pos = f.active.len() - 1;
            let row = |verdict: String, f: &Fit, lr: f64, p: f64| CandidateRow {
                knob: knob.label(),
                kind: knob.kind,
                value_si: f.point[*c].map(|x| knob.si(x)).unwrap_or(f64::NAN),
                gap_after: gap_of(f, n),
                lr,
                p_value: p,
                verdict,
            };
            let test = |f: &Fit, base: &Fit| -> (f64, f64, f64) {
                let lr = base.chi2 - f.chi2;
                let phi = dispersion(f.chi2_data, n, f.k());
                (lr, phi, lr_p_value(lr, 1, phi, n.saturating_sub(f.k())))
            };
            let (lr, _, p) = test(f, &current);
            if chosen.is_some() || attempts >= 3 {
                rows.push(row("not tried (another was chosen first)".into(), f, lr, p));
                continue;
            }
            if p >= alpha_step {
                rows.push(row(
                    format!("not significant (p ≥ α/K = {alpha_step:.1e})"),
                    f,
                    lr,
                    p,
                ));
                continue;
            }
            if f.held_out.unwrap_or(f64::INFINITY) >= current.held_out.unwrap_or(f64::INFINITY) {
                rows.push(row("no better on held-out conditions".into(), f, lr, p));
                continue;
            }
            attempts += 1;
            (ctx.progress)(&format!("confirming {} with walks", knob.label()));
            let starts = ctx.starts_adding(&current, *c);
            let real =
                ctx.with_held_out(ctx.fit_walked(&f.active, &starts, Some(f), Some(&current))?);
            walked.push((*c, real.clone()));
            let (lr_r, phi_r, p_r) = test(&real, &current);
            let t = real.unit[pos];
            if p_r >= alpha_step {
                rows.push(row(
                    format!("not significant once walked (p = {p_r:.1e} ≥ {alpha_step:.1e})"),
                    &real,
                    lr_r,
                    p_r,
                ));
                continue;
            }
            let gap_before = gap_of(&current, n);
            let gap_after = gap_of(&real, n);
            let noise_after = within_noise(&real, n, opts.alpha);
            if gap_after >= gap_before {
                rows.push(row(
                    "no better on held-out conditions once walked".into(),
                    &real,
                    lr_r,
                    p_r,
                ));
                continue;
            }
            if (1.0 - gap_after / gap_before) < opts.material_shrink && !noise_after {
                rows.push(row(
                    format!(
                        "not material: the held-out gap shrinks by {:.0} % (< {:.0} %) and the rest stays beyond noise",
                        100.0 * (1.0 - gap_after / gap_before),
                        100.0 * opts.material_shrink
                    ),
                    &real,
                    lr_r,
                    p_r,
                ));
                continue;
            }
            if !(0.01..=0.99).contains(&t) {
                let why = format!(
                    "fitted at the {} end of its plausible range ({:.3e} {}): the trials want more than the range allows",
                    if t < 0.5 { "lower" } else { "upper" },
                    real.point[*c].map(|x| knob.si(x)).unwrap_or(f64::NAN),
                    knob.unit
                );
                notes.push(format!("{}: {why}; not called", knob.label()));
                rows.push(row(why, &real, lr_r, p_r));
                continue;
            }
            let mut p_recal = None;
            let mut new_baseline = None;
            if knob.kind == KnobKind::Effect && !params.is_empty() {
                if baseline.is_none() {
                    baseline = Some(recalibrated(&mut recalibration)?);
                }
                let Some(base) = baseline.as_ref() else {
                    continue;
                };
                (ctx.progress)(&format!(
                    "testing {} against the recalibration",
                    knob.label()
                ));
                let starts = ctx.starts_adding(base, *c);
                let mut active = base.active.clone();
                active.push(*c);
                let nf = ctx.fit_walked(&active, &starts, None, Some(base))?;
                let (lr_n, _, p_n) = test(&nf, base);
                p_recal = Some(p_n);
                if p_n >= alpha_step {
                    rows.push(row(
                        format!(
                            "does not beat the recalibrated nominal (LR {lr_n:.1}, p = {p_n:.1e}): \
                             a plausible error of the uncertain parameters explains it as well"
                        ),
                        &real,
                        lr_r,
                        p_r,
                    ));
                    continue;
                }
                new_baseline = Some(nf);
            }
            let het = ctx.consistency(&real, &current, groupings, labels, phi_r);
            if let Some(h) = het.iter().find(|h| !h.consistent) {
                let why = format!(
                    "not one value for all conditions: it makes the {} group of {} worse than \
                     without it (χ² +{:.1}, allowed {:.1})",
                    h.worst_group, h.by, h.worst_rise, h.allowed
                );
                notes.push(format!("{}: {why}; not called", knob.label()));
                rows.push(row(why, &real, lr_r, p_r));
                continue;
            }
            // Ambiguity: another significant candidate (of either kind, including an effect
            // the recalibration explains as well) fits within the identification distance
            // of this one, confirmed with walks. The step then explains the gap but names
            // nothing: "one of these".
            let margin = separable_margin() * phi_r;
            let mut not_separable: Vec<String> = walked
                .iter()
                .filter(|(o, of)| {
                    o != c && test(of, &current).2 < alpha_step && of.chi2 - real.chi2 < margin
                })
                .map(|(o, _)| knobs[*o].label())
                .collect();
            let mut close: Vec<&(usize, Fit)> = screened
                .iter()
                .filter(|(o, of)| {
                    o != c
                        && !walked.iter().any(|(w, _)| w == o)
                        && test(of, &current).2 < alpha_step
                        && of.chi2 - real.chi2 < 2.0 * margin
                })
                .collect();
            close.sort_by(|a, b| a.1.chi2.total_cmp(&b.1.chi2));
            for (o, of) in close.into_iter().take(2) {
                (ctx.progress)(&format!(
                    "is {} separable from {}?",
                    knob.label(),
                    knobs[*o].label()
                ));
                let starts = ctx.starts_adding(&current, *o);
                let of_real = ctx.fit_walked(&of.active, &starts, Some(of), Some(&current))?;
                if test(&of_real, &current).2 < alpha_step && of_real.chi2 - real.chi2 < margin {
                    not_separable.push(knobs[*o].label());
                }
            }
            // A close candidate that still explains something once this one is in the model
            // is a second cause (a complement), not a rival: with two causes present, each
            // alone explains a similar share of the gap.
            let mut rivals = Vec::new();
            for label in not_separable {
                let Some(o) = ctx.knobs.index_of(&label) else {
                    continue;
                };
                let mut both_active = real.active.clone();
                both_active.push(o);
                let starts = ctx.starts_adding(&real, o);
                let both = ctx.fit_walked(&both_active, &starts, None, Some(&real))?;
                let (_, _, p_both) = test(&both, &real);
                if p_both >= alpha_step {
                    rivals.push(label);
                }
            }
            let not_separable = rivals;
            rows.push(row("chosen".into(), &real, lr_r, p_r));
            chosen = Some(Step {
                knob: knob.label(),
                kind: knob.kind,
                value_si: real.point[*c].map(|x| knob.si(x)).unwrap_or(f64::NAN),
                values_si: real
                    .active
                    .iter()
                    .filter_map(|k| real.point[*k].map(|x| (knobs[*k].label(), knobs[*k].si(x))))
                    .collect(),
                gap_after,
                shrink_pct: 100.0 * (1.0 - gap_after / gap_before),
                shrink_total_pct: 100.0 * (1.0 - gap_after / gap0),
                lr: lr_r,
                dispersion: phi_r,
                p_value: p_r,
                p_value_vs_recalibration: p_recal,
                consistency: het,
                within_noise_after: noise_after,
                not_separable_from: not_separable,
                candidates: Vec::new(),
            });
            next = Some((real, new_baseline));
        }
        match (chosen, next) {
            (Some(mut step), Some((real, nb))) => {
                step.candidates = rows;
                steps.push(step);
                current = real;
                if let Some(nb) = nb {
                    baseline = Some(nb);
                }
            }
            _ => {
                // Nothing passes: the last step's table is the record of why.
                if let Some(last) = steps.last_mut() {
                    last.candidates.extend(rows.into_iter().map(|mut r| {
                        r.verdict = format!("next step: {}", r.verdict);
                        r
                    }));
                } else {
                    steps_rejected(&mut notes, rows);
                }
                break;
            }
        }
    }
    // Backward elimination: a knob picked early, on a model still far from the data, may be
    // redundant once later knobs are in (it mimicked part of their signature). Each knob of
    // the final model must still be significant given all the others.
    let mut dropped = Vec::new();
    loop {
        if current.active.len() < 2 {
            break;
        }
        let alpha_drop = opts.alpha / knobs.len().max(1) as f64;
        let mut weakest: Option<(usize, f64, Fit)> = None;
        for &k in &current.active {
            let rest: Vec<usize> = current.active.iter().copied().filter(|x| *x != k).collect();
            let mut start = current.point.clone();
            start[k] = None;
            let starts = vec![(start, current.correction.clone())];
            let reduced = ctx.fit_walked(&rest, &starts, None, None)?;
            let lr = reduced.chi2 - current.chi2;
            let phi = dispersion(current.chi2_data, n, current.k());
            let p = lr_p_value(lr, 1, phi, n.saturating_sub(current.k()));
            if weakest.as_ref().is_none_or(|(_, wp, _)| p > *wp) {
                weakest = Some((k, p, reduced));
            }
        }
        match weakest {
            Some((k, p, reduced)) if p >= alpha_drop => {
                let label = knobs[k].label();
                notes.push(format!(
                    "{label} dropped from the answer: once the other knobs are in, it is no longer \
                     significant (p = {p:.1e}); it had mimicked part of their signature"
                ));
                dropped.push(label);
                current = ctx.with_held_out(reduced);
            }
            _ => break,
        }
    }
    steps.retain(|s| !dropped.contains(&s.knob));
    if opts.always_recalibrate && !params.is_empty() {
        recalibrated(&mut recalibration)?;
    }
    Ok(Selection {
        steps,
        final_fit: current,
        recalibration,
        notes,
        singles,
    })
}

/// The best recalibration of every uncertain parameter: Nelder–Mead on the surrogate from
/// the nominal, from each of the three best single-parameter fits, and from all
/// single-parameter optima at once, then confirmed and refined with walks.
fn recalibrate(
    ctx: &FitContext<'_>,
    nominal: &Fit,
    params: &[usize],
    singles: &[(usize, Fit)],
) -> Result<Fit, GapError> {
    let zero = nominal.correction.clone();
    let mut starts = vec![(nominal.point.clone(), zero.clone())];
    let mut by_gain: Vec<&(usize, Fit)> =
        singles.iter().filter(|(k, _)| params.contains(k)).collect();
    by_gain.sort_by(|a, b| a.1.chi2.total_cmp(&b.1.chi2));
    let mut all = nominal.point.clone();
    for (k, f) in &by_gain {
        all[*k] = f.point[*k];
    }
    starts.push((all, zero.clone()));
    for (k, f) in by_gain.iter().take(3) {
        let mut p = nominal.point.clone();
        p[*k] = f.point[*k];
        starts.push((p, zero.clone()));
    }
    ctx.fit_walked(params, &starts, None, Some(nominal))
}

/// With no step taken, the rejected first-step candidates become notes of the strongest
/// reasons (the top three by held-out gap).
fn steps_rejected(notes: &mut Vec<String>, rows: Vec<CandidateRow>) {
    for r in rows.into_iter().take(3) {
        notes.push(format!(
            "{} (held-out gap {:.2}, LR {:.1}, p = {:.1e}): {}",
            r.knob, r.gap_after, r.lr, r.p_value, r.verdict
        ));
    }
}
