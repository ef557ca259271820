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

use super::error::{GapError, check_default_sd};
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
    check_default_sd(default_relative_sd)?;
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
            return Err(GapError::at(
                &set.origin,
                t.line,
                0,
                format!(
                    "trial {} has no reference trial of the same condition (design, size and \
                     every condition column) in {}",
                    t.name(),
                    reference.origin
                ),
            ));
        };
        let (out, n) = carry_trial(t, r, nom, default_relative_sd, &mut dropped);
        carried_metrics += n;
        trials.push(out);
    }
    if carried_metrics == 0 {
        return Err(GapError::file(
            &set.origin,
            format!(
                "no metric could be carried through the reference {}: each needs the trial, \
                 the reference and the nominal walk to have it",
                reference.origin
            ),
        ));
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

/// One trial carried through its reference trial `r` onto the nominal walk `nom`: the carried
/// trial and how many metrics it holds (a metric the reference or the nominal lacks is
/// listed in `dropped`).
fn carry_trial(
    t: &Trial,
    r: &Trial,
    nom: &SimMetrics,
    default_relative_sd: f64,
    dropped: &mut Vec<String>,
) -> (Trial, usize) {
    let mut out = t.clone();
    out.trajectory = None;
    out.measured = [None; 8];
    let mut n = 0;
    for m in Metric::simulated() {
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
        n += 1;
    }
    (out, n)
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
