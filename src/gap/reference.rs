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
use super::problem::Observation;
use super::select::{Step, fit_p_value, within_noise};
use super::simulate::{Condition, SimMetrics};
use super::trials::{Measurement, Metric, Trial, TrialSet};
use super::waveform::{CycleSignature, SignalCycle};

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

/// How far the nominal model may miss a reference trial's gait and still be taken to walk
/// it: the step frequency within [`LIKE_STEP_TOLERANCE`], the speed (as the diagnosis
/// compares it) and the roll and pitch amplitudes within this fraction of the reference's.
/// Measured (`tests/golden/drake/gap-lagged-logs/README.md`): Drake-Lagged's Mugatu and the
/// project's on the same model, "the same gait within 5–15 %", miss each other by at most
/// 15 % on these four at every condition; Drake-SAP's and the project's Coulomb Mugatu,
/// whose gaits differ (one walks where the other scuffs), by 36–600 %.
pub const LIKE_GAIT_TOLERANCE: f64 = 0.25;
/// The step frequency's tolerance: the same gait steps at the same rate (a period-1 gait is
/// locked to the drive; Drake-Lagged and the project agree to 0.1 %).
pub const LIKE_STEP_TOLERANCE: f64 = 0.05;

/// Does the nominal model walk the reference trial's gait? `Ok` when it does, else why not
/// (the first metric out of tolerance). A change carried through a reference is the
/// change's mark on the robot put on the model; it stands for the change's mark on the model
/// only where the two walk the same gait (the carrying is a first-order, additive
/// correction). Each metric may miss by its tolerance of the reference's value plus twice the
/// reference's sd (stated, or `default_relative_sd` of the value): a noisy reference is not
/// another gait (measured: at 3 % noise the step frequency of Drake-Lagged's no-effect trials
/// drew 6 % off in one draw of five). A metric the reference does not state is not checked;
/// a nominal walk that fell walks no gait.
pub fn like_gait(
    reference: &Trial,
    nominal: &SimMetrics,
    default_relative_sd: f64,
) -> Result<(), String> {
    if nominal.fell {
        return Err("the nominal model falls there".into());
    }
    for (m, tol) in [
        (Metric::StepFrequencyHz, LIKE_STEP_TOLERANCE),
        (Metric::VelocityMps, LIKE_GAIT_TOLERANCE),
        (Metric::RollPpDeg, LIKE_GAIT_TOLERANCE),
        (Metric::PitchPpDeg, LIKE_GAIT_TOLERANCE),
    ] {
        let Some(r) = reference.measured(m) else {
            continue;
        };
        let n = nominal.get(m);
        let (sd, _) = r.sd_or(default_relative_sd);
        let allowed = tol * r.value.abs() + 2.0 * sd;
        let miss = (n - r.value).abs();
        // A NaN miss (a metric the model lacks) is out of tolerance too.
        if miss.is_nan() || miss > allowed {
            return Err(format!(
                "{} {:.3} (model) vs {:.3} (reference): {:.0} % apart, beyond {:.0} % + 2 sd",
                m.column(),
                n,
                r.value,
                100.0 * miss / r.value.abs(),
                100.0 * tol
            ));
        }
    }
    Ok(())
}

/// A logged cycle carried onto the nominal model as the summaries are ([`carry`]): each
/// Fourier coefficient becomes `nominal + (trial − reference)`, its sd the three means' own
/// (cycle-to-cycle spread / √cycles of the trial, the reference and the nominal walk) and the
/// carrying's ([`form_sd`] of the signal's RMS: |change| · ρ, ρ = |rms_reference − rms_nominal| /
/// rms_reference):
/// had the discrepancy been a gain (the robot's cycle a scaled copy of the model's), the change
/// would have been scaled by rms_nominal / rms_reference. A discrepancy of *shape* (a phase,
/// other harmonics) cancels in the difference and is not charged. Measured on Drake-Lagged's
/// Mugatu at 1.55 Hz (`tests/golden/drake/gap-lagged-logs/README.md`): the two engines' hip
/// torque cycles differ by 33 % of the signal's RMS, their amplitudes by 1.6 %, and the change
/// an added hip damper makes correlates 0.999 between them.
///
/// The result has `cycles = 1` and `spread` the sd of each carried coefficient, so that
/// [`super::waveform::chi2`] counts it as it counts a measured mean. Signals that one of the
/// three lacks are dropped; `None` when none is left.
pub fn carry_cycles(
    trial: &CycleSignature,
    reference: &CycleSignature,
    nominal: &CycleSignature,
) -> Option<CycleSignature> {
    let mut signals = Vec::new();
    for t in &trial.signals {
        let (Some(r), Some(n)) = (reference.signal(t.signal), nominal.signal(t.signal)) else {
            continue;
        };
        let k = t.coefficients.len();
        if r.coefficients.len() != k || n.coefficients.len() != k {
            continue;
        }
        let mean_var =
            |c: &SignalCycle, cycles: usize, i: usize| c.spread[i].powi(2) / cycles.max(1) as f64;
        let mut coefficients = Vec::with_capacity(k);
        let mut spread = Vec::with_capacity(k);
        for i in 0..k {
            let change = t.coefficients[i] - r.coefficients[i];
            let value = n.coefficients[i] + change;
            if !value.is_finite() {
                coefficients.push(f64::NAN);
                spread.push(f64::NAN);
                continue;
            }
            let var = mean_var(t, trial.cycles, i)
                + mean_var(r, reference.cycles, i)
                + mean_var(n, nominal.cycles, i)
                + form_sd(change, r.rms, n.rms).powi(2);
            coefficients.push(value);
            spread.push(var.sqrt());
        }
        signals.push(SignalCycle::from_coefficients(
            t.signal,
            coefficients,
            spread,
        ));
    }
    (!signals.is_empty()).then_some(CycleSignature {
        drive_frequency_hz: trial.drive_frequency_hz,
        cycles: 1,
        signals,
    })
}

/// A fit that is within noise once one metric is left out ([`within_noise_but_one_metric`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WithinNoiseButOne {
    /// The metric left out: the one whose removal leaves the most probable χ².
    pub metric: Metric,
    /// χ² of that metric's values, and of the rest.
    pub chi2_metric: f64,
    pub chi2_left: f64,
    /// Values left, and the χ² test's p-value on them.
    pub n_left: usize,
    pub p_left: f64,
}

/// Is the walked `fit` within noise (at `alpha`) on the observations once every value of one
/// metric is left out? The metric whose removal leaves the largest p-value, if any does (the
/// fitted value is kept, not refitted: a refit would only lower the χ²). `None` for a fit
/// without walks or within noise with nothing left out.
///
/// Why through a reference: the carried numbers hold the change's mark on the robot, and the
/// model's version of a physical effect may answer one metric differently from the robot's —
/// a sensitive one most of all, such as the yaw swing. Measured on Drake-Lagged's hip Coulomb
/// friction 0.08 N·m (`reports/gap-benchmark-drake-lagged-logs-heldout/`): carried without
/// noise, the project's Coulomb friction misses 60.8 of its χ² on 63 values, 43 of them on the
/// yaw swing at 1.55–1.6 Hz (ours −17 %, Drake's +4.5 %), while viscous damping fits at 12.8;
/// with noise drawn, viscous damping was named in 5 of 5 draws — the wrong effect. A rival that
/// only one metric rejects is rejected by one metric's model error as much as by the truth.
pub fn within_noise_but_one_metric(
    obs: &[Observation],
    fit: &Fit,
    alpha: f64,
) -> Option<WithinNoiseButOne> {
    let sims = fit.sims.as_ref()?;
    within_noise_but_one(obs, |o| sims[o.trial].get(o.metric), fit.k(), alpha)
}

/// [`within_noise_but_one_metric`] of a model with `k` free knobs whose simulated value of an
/// observation is `simulated(o)`.
pub fn within_noise_but_one(
    obs: &[Observation],
    simulated: impl Fn(&Observation) -> f64,
    k: usize,
    alpha: f64,
) -> Option<WithinNoiseButOne> {
    let z2 = |o: &Observation| o.z2(simulated(o));
    let total: f64 = obs.iter().map(z2).sum();
    let p_of = |chi2: f64, n: usize| fit_p_value(chi2, n, k);
    if p_of(total, obs.len()) >= alpha {
        return None;
    }
    let mut best: Option<(f64, WithinNoiseButOne)> = None;
    for m in Metric::SIMULATED {
        let of_m: Vec<&Observation> = obs.iter().filter(|o| o.metric == m).collect();
        if of_m.is_empty() || of_m.len() == obs.len() {
            continue;
        }
        let chi2_metric: f64 = of_m.iter().map(|o| z2(o)).sum();
        let chi2_left = (total - chi2_metric).max(0.0);
        let n_left = obs.len() - of_m.len();
        let p = p_of(chi2_left, n_left);
        if p >= alpha && best.is_none_or(|(bp, _)| p > bp) {
            best = Some((
                p,
                WithinNoiseButOne {
                    metric: m,
                    chi2_metric,
                    chi2_left,
                    n_left,
                    p_left: p,
                },
            ));
        }
    }
    best.map(|(_, b)| b)
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
/// rival within noise, or within noise once one metric is left out
/// ([`within_noise_but_one_metric`]: the error no sd counts may sit in one metric), is added
/// to each named step's `not_separable_from` (the answer then names neither). It only takes
/// names away.
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
    let mut rivals: Vec<(String, String)> = Vec::new();
    for (k, fit) in candidates.into_iter().take(RIVAL_WALKS) {
        let walked = ctx.refine(fit)?;
        let label = ctx.knobs.list[*k].label();
        if within_noise(&walked, n, alpha) {
            rivals.push((label, format!("χ² {:.1} on {n} values", walked.chi2_data)));
        } else if let Some(b) = within_noise_but_one_metric(ctx.obs, &walked, alpha) {
            rivals.push((
                label,
                format!(
                    "χ² {:.1} on {n} values, {:.1} on the {} left without {} (χ² {:.1} there)",
                    walked.chi2_data,
                    b.chi2_left,
                    b.n_left,
                    b.metric.column(),
                    b.chi2_metric
                ),
            ));
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
            .map(|(r, c)| format!("{r}: {c}"))
            .collect::<Vec<_>>()
            .join("; "),
        names.join(", "),
        if rivals.len() == 1 { "it" } else { "them" }
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gap::waveform::{FIGURE_BINS, Signal};

    /// A signal whose coefficients are `head` then zeros, with the same spread everywhere
    /// and the RMS of its cycle about its mean (Parseval: √(Σ_{k≥1} c²/2)).
    fn signal(signal: Signal, head: &[f64], spread: f64) -> SignalCycle {
        let mut coefficients = vec![0.0; 25];
        coefficients[..head.len()].copy_from_slice(head);
        let rms = (coefficients[1..].iter().map(|a| a * a).sum::<f64>() / 2.0).sqrt();
        SignalCycle {
            signal,
            coefficients,
            spread: vec![spread; 25],
            rms,
            cycle: Vec::new(),
        }
    }

    fn sig(cycles: usize, signals: Vec<SignalCycle>) -> CycleSignature {
        CycleSignature {
            drive_frequency_hz: 1.5,
            cycles,
            signals,
        }
    }

    /// Hand-derived: trial [1, 2], reference [1, 1], nominal [0.5, 1.2] (mean, first cosine).
    /// The change is [0, 1], so the carried cycle is [0.5, 2.2]. ρ = |rms_R − rms_N| / rms_R =
    /// |1/√2 − 1.2/√2| / (1/√2) = 0.2. Variance of the first cosine: 0.3²/4 (trial) + 0.4²/4
    /// (reference) + 0 (nominal) + (1 · 0.2)² = 0.0225 + 0.04 + 0.04 = 0.1025; of the mean,
    /// whose change is 0: 0.0625. Yaw's mean (NaN: the heading) stays NaN, and a signal the
    /// reference lacks is dropped.
    #[test]
    fn carried_cycle_is_nominal_plus_change_with_hand_derived_sds() {
        let trial = sig(
            4,
            vec![
                signal(Signal::HipTorque, &[1.0, 2.0], 0.3),
                signal(Signal::Yaw, &[f64::NAN, 3.0], 0.3),
                signal(Signal::Roll, &[0.0, 5.0], 0.3),
            ],
        );
        let reference = sig(
            4,
            vec![
                signal(Signal::HipTorque, &[1.0, 1.0], 0.4),
                signal(Signal::Yaw, &[f64::NAN, 3.0], 0.4),
            ],
        );
        let nominal = sig(
            16,
            vec![
                signal(Signal::HipTorque, &[0.5, 1.2], 0.0),
                signal(Signal::Yaw, &[f64::NAN, 2.0], 0.0),
                signal(Signal::Roll, &[0.0, 4.0], 0.0),
            ],
        );
        let c = carry_cycles(&trial, &reference, &nominal).expect("carried");
        assert_eq!(c.cycles, 1);
        assert_eq!(c.signals.len(), 2, "roll has no reference cycle");
        let t = c.signal(Signal::HipTorque).expect("torque");
        assert!((t.coefficients[0] - 0.5).abs() < 1e-12);
        assert!((t.coefficients[1] - 2.2).abs() < 1e-12);
        assert!((t.spread[0] - 0.0625f64.sqrt()).abs() < 1e-12);
        assert!((t.spread[1] - 0.1025f64.sqrt()).abs() < 1e-12);
        assert!((t.rms - 2.2 / 2f64.sqrt()).abs() < 1e-12);
        // The figure's cycle is the carried coefficients evaluated: 0.5 + 2.2·cos 2πφ.
        let phi = 0.5 / FIGURE_BINS as f64;
        assert!((t.cycle[0] - (0.5 + 2.2 * (std::f64::consts::TAU * phi).cos())).abs() < 1e-12);
        let y = c.signal(Signal::Yaw).expect("yaw");
        assert!(y.coefficients[0].is_nan() && y.spread[0].is_nan());
        // Yaw: reference and nominal amplitudes 3 and 2 → ρ = 1/3; the change is 0.
        assert!((y.coefficients[1] - 2.0).abs() < 1e-12);
    }

    /// Drake-Lagged's Mugatu at 1.55 Hz against the project's (`tests/golden/drake/
    /// gap-lagged/README.md`, "Do the engines agree here?"): the same gait, within 11 % on
    /// roll, 8 % on pitch, 0.4 % on speed. Drake-SAP's at its design frequency against the
    /// project's Coulomb Mugatu (`tests/golden/drake/gap/trials-none.csv`, L1x-f1x, and the
    /// project's 0.013 m/s scuff, roll 64°): not the same gait, and the first metric out
    /// (the speed) says why. A fallen
    /// nominal walks no gait; a metric the reference does not state is not checked.
    #[test]
    fn like_gait_holds_for_drake_lagged_and_not_for_a_gait_the_model_does_not_walk() {
        let mut reference = Trial::condition("mugatu-ref", 0.153);
        let set = |t: &mut Trial, m: Metric, v: f64| {
            t.measured[m.index()] = Some(Measurement { value: v, sd: None });
        };
        set(&mut reference, Metric::VelocityMps, 0.2023);
        set(&mut reference, Metric::StepFrequencyHz, 3.1);
        set(&mut reference, Metric::RollPpDeg, 13.1);
        set(&mut reference, Metric::PitchPpDeg, 14.5);
        let mut values = [f64::NAN; 8];
        values[Metric::VelocityMps.index()] = 0.2014;
        values[Metric::StepFrequencyHz.index()] = 3.1;
        values[Metric::RollPpDeg.index()] = 14.6;
        values[Metric::PitchPpDeg.index()] = 15.7;
        let lagged = SimMetrics {
            values,
            fell: false,
        };
        assert_eq!(like_gait(&reference, &lagged, 0.0), Ok(()));
        // Roll 30 % above the reference's: another gait.
        let mut rocking = lagged;
        rocking.values[Metric::RollPpDeg.index()] = 13.1 * 1.3;
        let why = like_gait(&reference, &rocking, 0.0).expect_err("unlike");
        assert!(
            why.starts_with("roll_pp_deg") && why.contains("30 %"),
            "{why}"
        );
        // With the reference's noise counted (3 % sd: 2 sd = 6 % more), roll 30 % above is
        // within 25 % + 2 sd; 40 % is not.
        assert_eq!(like_gait(&reference, &rocking, 0.03), Ok(()));
        let mut rocking_more = lagged;
        rocking_more.values[Metric::RollPpDeg.index()] = 13.1 * 1.4;
        assert!(like_gait(&reference, &rocking_more, 0.03).is_err());
        // A step every other drive cycle (half the step frequency): another gait, however
        // close the rest.
        let mut skipping = lagged;
        skipping.values[Metric::StepFrequencyHz.index()] = 1.55;
        assert!(like_gait(&reference, &skipping, 0.0).is_err());
        // Drake-SAP at the design frequency (1x): walks backward at 0.167 m/s with roll 13.7°;
        // the project's Coulomb Mugatu scuffs (0.0016 m/s here as a stand-in, roll 64°).
        let mut sap = Trial::condition("mugatu-ref", 0.153);
        set(&mut sap, Metric::VelocityMps, -0.167);
        set(&mut sap, Metric::RollPpDeg, 13.65);
        let mut scuff = [f64::NAN; 8];
        scuff[Metric::VelocityMps.index()] = 0.0016;
        scuff[Metric::RollPpDeg.index()] = 64.2;
        let why = like_gait(
            &sap,
            &SimMetrics {
                values: scuff,
                fell: false,
            },
            0.0,
        )
        .expect_err("unlike");
        assert!(why.starts_with("velocity_mps"), "{why}");
        let fell = SimMetrics {
            fell: true,
            ..lagged
        };
        assert!(like_gait(&reference, &fell, 0.0).is_err());
        // Nothing stated, nothing checked.
        let bare = Trial::condition("mugatu-ref", 0.153);
        assert_eq!(like_gait(&bare, &rocking, 0.0), Ok(()));
    }

    /// Observations of sd 1 whose model value is 10, each measured `z` sd below it:
    /// `(trial, metric, z)`.
    fn residuals(rows: &[(usize, Metric, f64)]) -> Vec<Observation> {
        rows.iter()
            .map(|&(trial, metric, z)| Observation {
                trial,
                metric,
                value: 10.0 - z,
                sd: 1.0,
                sd_assumed: false,
            })
            .collect()
    }

    /// Hand-derived: 3 trials × 3 metrics, all within noise but the yaw swing, 4 sd off in
    /// every trial (χ² 48 of 48.75 on 9 values: p ≈ 10⁻⁷ on 8 dof). Left out, 0.75 remains on
    /// 6 values (5 dof: p = 0.98011, from the closed form for odd dof, 2(1 − Φ(√x)) +
    /// 2φ(√x)(√x + x^{3/2}/3)): within noise but one metric, the yaw swing. Spread over two
    /// metrics instead (z = 4 on the yaw swing of trial 0 and on the speed of trials 1 and 2),
    /// leaving out either leaves χ² ≥ 16 on 6 values (p ≤ 0.007 on 5 dof): not within noise.
    #[test]
    fn a_rival_rejected_by_one_metric_alone_is_within_noise_but_that_metric() {
        let model = |_: &Observation| 10.0;
        let mut rows = Vec::new();
        for t in 0..3 {
            rows.push((t, Metric::VelocityMps, 0.5));
            rows.push((t, Metric::PeakTorqueNm, 0.0));
            rows.push((t, Metric::YawPpDeg, 4.0));
        }
        let b = within_noise_but_one(&residuals(&rows), model, 1, 0.01)
            .expect("within noise but the yaw swing");
        assert_eq!(b.metric, Metric::YawPpDeg);
        assert!((b.chi2_metric - 48.0).abs() < 1e-9 && (b.chi2_left - 0.75).abs() < 1e-9);
        assert_eq!(b.n_left, 6);
        assert!((b.p_left - 0.98011).abs() < 1e-4, "p {}", b.p_left);

        let mut spread = rows.clone();
        spread[2].2 = 4.0; // trial 0's yaw
        spread[5].2 = 0.0;
        spread[8].2 = 0.0;
        spread[3].2 = 4.0; // trial 1's speed
        spread[6].2 = 4.0; // trial 2's speed
        assert_eq!(
            within_noise_but_one(&residuals(&spread), model, 1, 0.01),
            None
        );

        // Within noise with nothing left out: not this rule's case.
        let fine: Vec<_> = rows.iter().map(|&(t, m, _)| (t, m, 0.5)).collect();
        assert_eq!(
            within_noise_but_one(&residuals(&fine), model, 1, 0.01),
            None
        );
    }

    /// The null: trials that are their reference carry exactly onto the nominal walk.
    #[test]
    fn a_trial_equal_to_its_reference_carries_onto_the_nominal() {
        let t = sig(5, vec![signal(Signal::HipTorque, &[0.2, 1.0, -0.5], 0.1)]);
        let n = sig(16, vec![signal(Signal::HipTorque, &[0.1, 0.7, 0.3], 0.0)]);
        let c = carry_cycles(&t, &t, &n).expect("carried");
        let s = c.signal(Signal::HipTorque).expect("torque");
        assert_eq!(&s.coefficients[..3], &[0.1, 0.7, 0.3]);
        assert!(carry_cycles(&t, &sig(5, Vec::new()), &n).is_none());
    }
}
