//! Trials diagnosed relative to a reference set of the same robot: what *changed* between
//! two sets of trials, with the model's own discrepancy taken from the reference.
//!
//! When the simulator misses the robot by more than noise everywhere (another engine's
//! contact, an unmodelled structure), no knob can bring the model within noise and the
//! diagnosis, rightly, names nothing. If the robot was also measured *without* the change
//! being asked about (the same conditions before a damper was added, on the lab floor
//! before the carpet, the same Drake model without the effect), that reference measures the
//! discrepancy at every condition. Each metric is then carried onto the nominal model:
//!
//! > carried = nominal simulated + (trial − reference),
//! > sd = √(sd_trial² + sd_reference² + (change · ρ)²), ρ = |reference − nominal| / |reference|
//!
//! — an additive model discrepancy per condition and metric (Kennedy & O'Hagan 2001, with the
//! discrepancy measured rather than fitted); the third sd term is how far a relative
//! discrepancy would have carried the change otherwise ([`form_sd`]). The diagnosis of the carried trials is the
//! diagnosis of the change. It holds when the change acts on the robot as it acts on the
//! model, i.e. when the two gaits are alike (`reports/drake-crosscheck.md`: with Drake's
//! convex friction they are not, and an effect's mark differs from ours; with physical
//! friction they are). A metric is carried only where the trial, the reference and the
//! nominal walk all have it.

use super::error::GapError;
use super::fit::{Fit, FitContext};
use super::select::{Step, within_noise};
use super::simulate::{Condition, SimMetrics};
use super::trials::{Measurement, Metric, TrialSet};

/// The carried trials and what the carrying did, in words.
#[derive(Clone, Debug)]
pub struct Carried {
    pub set: TrialSet,
    pub notes: Vec<String>,
}

/// Two resolved conditions are the same trial condition (design by name, size, mass law,
/// contact scaling and every condition column).
pub fn same_condition(a: &Condition, b: &Condition) -> bool {
    a.design.name == b.design.name
        && a.leg_length_m == b.leg_length_m
        && a.mass_law == b.mass_law
        && a.contact == b.contact
        && a.mass_kg == b.mass_kg
        && a.frequency_hz == b.frequency_hz
        && a.amplitude_deg == b.amplitude_deg
        && a.torque_nm == b.torque_nm
        && a.slope_deg == b.slope_deg
}

/// The uncertainty of carrying a change additively: had the discrepancy been relative
/// (carried = nominal · trial / reference), the change would be scaled by nominal/reference,
/// i.e. differ by |change| · ρ with ρ = |reference − nominal| / |reference| (at most 1: a
/// metric the model misses by its own size, or a reference near zero, carries the change
/// with an sd as large as the change). Zero where the model matches the reference or nothing
/// changed, so a null stays a null; it grows with the change and with the discrepancy, the
/// two things that make an effect's mark on the robot differ from its mark on the model.
fn form_sd(change: f64, reference: f64, nominal: f64) -> f64 {
    let rho = if reference != 0.0 {
        ((reference - nominal) / reference).abs().min(1.0)
    } else {
        1.0
    };
    (change * rho).abs()
}

/// Carries `set` onto the nominal model through `reference`: every trial is paired with the
/// reference trial of the same condition (an error names a trial without one), and each of
/// its metrics becomes `nominal + (trial − reference)` with the two sds and the carrying's
/// own ([`form_sd`]) combined. `nominal`
/// holds the nominal model's metrics at `conditions` (the conditions of `set`, in order).
/// The carried trials keep their conditions and lines; their trajectories are dropped (the
/// carried numbers are not a log's), and so are metrics the reference or the nominal lacks
/// (a fall), with a note.
pub fn carry(
    set: &TrialSet,
    conditions: &[Condition],
    reference: &TrialSet,
    reference_conditions: &[Condition],
    nominal: &[SimMetrics],
    default_relative_sd: f64,
) -> Result<Carried, GapError> {
    if !(default_relative_sd > 0.0 && default_relative_sd.is_finite()) {
        return Err(GapError::Invalid(
            "the default relative sd must be finite and > 0".into(),
        ));
    }
    if conditions.len() != set.trials.len()
        || nominal.len() != set.trials.len()
        || reference_conditions.len() != reference.trials.len()
    {
        return Err(GapError::Invalid(format!(
            "{}: {} trials but {} conditions and {} nominal walks; reference {}: {} trials but \
             {} conditions",
            set.origin,
            set.trials.len(),
            conditions.len(),
            nominal.len(),
            reference.origin,
            reference.trials.len(),
            reference_conditions.len()
        )));
    }
    let mut trials = Vec::with_capacity(set.trials.len());
    let mut dropped: Vec<String> = Vec::new();
    let mut carried_metrics = 0usize;
    for ((t, c), nom) in set.trials.iter().zip(conditions).zip(nominal) {
        let Some(r) = reference_conditions
            .iter()
            .position(|rc| same_condition(c, rc))
            .map(|k| &reference.trials[k])
        else {
            return Err(GapError::Trials {
                path: set.origin.clone(),
                line: t.line,
                column: 0,
                message: format!(
                    "trial {} has no reference trial of the same condition (design, size and \
                     every condition column) in {}",
                    t.name(),
                    reference.origin
                ),
            });
        };
        let mut out = t.clone();
        out.trajectory = None;
        out.measured = [None; 8];
        for m in Metric::SIMULATED {
            let Some(tm) = t.measured(m) else { continue };
            let nominal_value = nom.get(m);
            let Some(rm) = r.measured(m).filter(|_| nominal_value.is_finite()) else {
                dropped.push(format!("{} {}", t.name(), m.column()));
                continue;
            };
            let (tv, ts) = (tm.value, tm.sd_or(default_relative_sd).0);
            let (rv, rs) = (rm.value, rm.sd_or(default_relative_sd).0);
            let change = tv - rv;
            out.measured[m.index()] = Some(Measurement {
                value: nominal_value + change,
                sd: Some(ts.hypot(rs).hypot(form_sd(change, rv, nominal_value))),
            });
            carried_metrics += 1;
        }
        trials.push(out);
    }
    if carried_metrics == 0 {
        return Err(GapError::File {
            path: set.origin.clone(),
            message: format!(
                "no metric could be carried through the reference {}: each needs the trial, \
                 the reference and the nominal walk to have it",
                reference.origin
            ),
        });
    }
    let mut notes = vec![format!(
        "relative to the reference {}: each metric is the nominal model's + (trial − reference) \
         at the same condition, its sd the two sds and the change × the model's relative miss \
         of the reference combined; the answer is about what changed \
         between the reference and these trials ({carried_metrics} metrics carried)",
        reference.origin
    )];
    if !dropped.is_empty() {
        notes.push(format!(
            "{} metric(s) not carried: the reference or the nominal walk lacks them (a fall): {}",
            dropped.len(),
            dropped.join(", ")
        ));
    }
    Ok(Carried {
        set: TrialSet {
            origin: format!("{} (relative to {})", set.origin, reference.origin),
            base_dir: set.base_dir.clone(),
            trials,
        },
        notes,
    })
}

/// Single-knob rivals walked by [`rivals_within_noise`]: the best by the surrogate.
const RIVAL_WALKS: usize = 3;

/// Through a reference, a knob is named only if no knob outside the answer, alone, also
/// brings the carried trials within noise. Inside the closed world two such fits differing
/// by more than the identification distance are told apart; here the carried numbers hold
/// an error no sd counts — how the change's mark on the robot differs from its mark on the
/// model — and the distinction between two explanations that both fit rests on exactly
/// that. (Measured on Drake-Lagged's trials, `reports/gap-benchmark-drake-lagged/`: without
/// this rule hip Coulomb friction 0.05 N·m was named hip viscous damping in 3 of 3 draws.)
/// The best [`RIVAL_WALKS`] single-knob fits by the surrogate are confirmed with walks; a
/// rival within noise is added to each named step's `not_separable_from` (the answer then
/// names neither). It only takes names away.
pub fn rivals_within_noise(
    ctx: &FitContext<'_>,
    singles: &[(usize, Fit)],
    steps: &mut [Step],
    alpha: f64,
    notes: &mut Vec<String>,
) -> Result<(), GapError> {
    let in_answer: Vec<usize> = steps
        .iter()
        .filter_map(|s| ctx.knobs.index_of(&s.knob))
        .collect();
    let named: Vec<usize> = steps
        .iter()
        .enumerate()
        .filter(|(_, s)| s.not_separable_from.is_empty())
        .map(|(i, _)| i)
        .collect();
    if named.is_empty() {
        return Ok(());
    }
    let n = ctx.n();
    let mut candidates: Vec<&(usize, Fit)> = singles
        .iter()
        .filter(|(k, _)| !in_answer.contains(k))
        .collect();
    candidates.sort_by(|a, b| a.1.chi2_data.total_cmp(&b.1.chi2_data));
    let mut rivals: Vec<(String, f64)> = Vec::new();
    for (k, fit) in candidates.into_iter().take(RIVAL_WALKS) {
        let walked = ctx.refine(fit)?;
        if within_noise(&walked, n, alpha) {
            rivals.push((ctx.knobs.list[*k].label(), walked.chi2_data));
        }
    }
    if rivals.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = named.iter().map(|&i| steps[i].knob.clone()).collect();
    for &i in &named {
        steps[i]
            .not_separable_from
            .extend(rivals.iter().map(|(r, _)| r.clone()));
    }
    notes.push(format!(
        "through the reference, {} alone also fit{} the carried trials within noise ({}): {} \
         not told apart from {}, since the carried numbers hold an error of the carrying no sd \
         counts",
        rivals
            .iter()
            .map(|(r, _)| r.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        if rivals.len() == 1 { "s" } else { "" },
        rivals
            .iter()
            .map(|(r, c)| format!("{r}: χ² {c:.1} on {n} values"))
            .collect::<Vec<_>>()
            .join("; "),
        names.join(", "),
        if rivals.len() == 1 { "it" } else { "them" }
    ));
    Ok(())
}
