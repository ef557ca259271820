//! The trials as observations: every measured metric the simulator computes, and for a
//! trial that names a log, the Fourier coefficients of its steady cycle (one more block of
//! the same likelihood). Through a reference, each is carried onto the model as nominal +
//! (trial − reference) ([`super::reference`]).

use super::error::GapError;
use super::library::EffectLibrary;
use super::likelihood::{Block, Observation};
use super::reference::{carry, like_gait};
use super::simulate::{Condition, SETTLE_CYCLES, Walked, resolve};
use super::trials::{Measurement, Metric, Trial, TrialSet};
use super::waveform::{self, CycleSignature, LogSample, Signal};

/// Robot logs in memory in place of the files the trials' `trajectory` column names (the
/// benchmark's, each case with its own sensor noise), by trial; and the reference's.
#[derive(Clone, Debug, Default)]
pub struct Logs {
    pub trials: Vec<Option<Vec<LogSample>>>,
    pub reference: Vec<Option<Vec<LogSample>>>,
}

/// The observations of a trial set, the set as observed (metrics filled from full
/// trajectories; carried through a reference), and notes on what was done.
pub struct Observed {
    pub set: TrialSet,
    pub obs: Vec<Observation>,
    pub notes: Vec<String>,
}

/// How trials are observed: through a reference or not, with logs in memory or not, and the
/// relative sd a measurement without one is given.
pub struct Observing<'a> {
    pub reference: Option<&'a TrialSet>,
    pub logs: Option<&'a Logs>,
    pub default_relative_sd: f64,
}

/// Observes `set` at its resolved `conditions`; `nominal`: the nominal model's walks there.
pub fn observe(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
    nominal: &[Walked],
    opts: &Observing<'_>,
) -> Result<Observed, GapError> {
    let filled = fill_from_trajectories(set, conditions, lib)?;
    let memory = opts.logs;
    let sigs = signatures(set, conditions, memory.map(|l| l.trials.as_slice()))?;
    let mut notes = Vec::new();
    let (observed_set, cycles) = match opts.reference {
        Some(reference) => {
            let rc = resolve(reference)?;
            let rf = fill_from_trajectories(reference, &rc, lib)?;
            let metrics: Vec<_> = nominal.iter().map(|w| w.metrics).collect();
            let carried = carry(
                &filled,
                conditions,
                &rf,
                &rc,
                &metrics,
                opts.default_relative_sd,
            )?;
            notes.extend(carried.notes);
            let rsigs = signatures(reference, &rc, memory.map(|l| l.reference.as_slice()))?;
            let cycles = carry_cycles(
                &filled, conditions, &rf, &rc, &sigs, &rsigs, nominal, opts, &mut notes,
            );
            (carried.set, cycles)
        }
        None => (filled, cycle_observations(&sigs)),
    };
    let mut obs = metric_observations(&observed_set, opts.default_relative_sd, &mut notes);
    obs.extend(cycles);
    if obs.is_empty() {
        return Err(GapError::file(
            &set.origin,
            "no trial has a measured metric the simulator computes (velocity_mps, \
             step_frequency_hz, roll/pitch/yaw_pp_deg, peak_torque_nm, cot) or a log",
        ));
    }
    Ok(Observed {
        set: observed_set,
        obs,
        notes,
    })
}

/// An error about trial `t` of `set`, in its `trajectory` column.
fn at_trajectory(set: &TrialSet, t: &Trial, message: String) -> GapError {
    GapError::at(&set.origin, t.line, 0, message)
}

/// Trials whose `trajectory` is a full simulator trajectory get the metrics they lack
/// measured from it; at a condition whose direction the start sets
/// ([`Condition::direction_free`]) the measured velocity becomes a speed |v|, as the
/// simulated one is.
pub fn fill_from_trajectories(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
) -> Result<TrialSet, GapError> {
    let mut out = set.clone();
    for (t, c) in out.trials.iter_mut().zip(conditions) {
        if let Some(rel) = t.trajectory.clone() {
            let path = set.base_dir.join(&rel);
            let full = waveform::is_full_trajectory(&path)
                .map_err(|e| at_trajectory(set, t, format!("trajectory {rel}: {e}")))?;
            if full {
                fill_one(t, c, lib, &path).map_err(|e| at_trajectory(set, t, e))?;
            }
        }
        if c.direction_free()
            && let Some(v) = &mut t.measured[Metric::VelocityMps.index()]
        {
            v.value = v.value.abs();
        }
    }
    Ok(out)
}

fn fill_one(
    t: &mut Trial,
    c: &Condition,
    lib: &EffectLibrary,
    path: &std::path::Path,
) -> Result<(), String> {
    let samples = crate::sim::read_trajectory_csv(path)
        .map_err(|e| format!("trajectory {}: {e}", path.display()))?;
    let d = c
        .design_with(lib, &super::knob::ModelSetting::nominal())
        .map_err(|e| e.to_string())?;
    let report =
        crate::sim::report_from_trajectory(&d, &crate::sim::WalkOptions::default(), &samples)
            .map_err(|e| format!("trajectory {}: {e}", path.display()))?;
    for m in Metric::simulated() {
        let v = m.of_report(&report);
        if t.measured(m).is_none() && v.is_finite() {
            t.measured[m.index()] = Some(Measurement { value: v, sd: None });
        }
    }
    Ok(())
}

/// The cycles of the trials' logs: from memory when given, else from the files.
fn signatures(
    set: &TrialSet,
    conditions: &[Condition],
    memory: Option<&[Option<Vec<LogSample>>]>,
) -> Result<Vec<Option<CycleSignature>>, GapError> {
    let Some(logs) = memory else {
        return measured_signatures(set, conditions);
    };
    conditions
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let Some(Some(log)) = logs.get(i) else {
                return Ok(None);
            };
            Ok(waveform::signature(log, c.drive_frequency_hz()?, SETTLE_CYCLES).ok())
        })
        .collect()
}

/// The measured cycles of the trials that name a log, by trial.
pub fn measured_signatures(
    set: &TrialSet,
    conditions: &[Condition],
) -> Result<Vec<Option<CycleSignature>>, GapError> {
    set.trials
        .iter()
        .zip(conditions)
        .map(|(t, c)| {
            let Some(rel) = &t.trajectory else {
                return Ok(None);
            };
            let path = set.base_dir.join(rel);
            let log = waveform::read_log_csv(&path)
                .map_err(|e| at_trajectory(set, t, format!("trajectory {rel}: {e}")))?;
            let f = c.drive_frequency_hz()?;
            waveform::signature(&log, f, SETTLE_CYCLES)
                .map(Some)
                .map_err(|e| at_trajectory(set, t, format!("trajectory {rel}: {e}")))
        })
        .collect()
}

/// A measured coefficient's sd: its cycle-to-cycle spread over √cycles (the sd of the mean
/// cycle) and the sensor's resolution, in quadrature.
fn coefficient_sd(signal: Signal, spread: f64, cycles: usize) -> f64 {
    (spread.powi(2) / cycles.max(1) as f64 + signal.absolute_floor().powi(2)).sqrt()
}

/// The observations of measured cycles: every finite coefficient of every logged signal.
fn cycle_observations(sigs: &[Option<CycleSignature>]) -> Vec<Observation> {
    let mut out = Vec::new();
    for (trial, sig) in sigs.iter().enumerate() {
        let Some(sig) = sig else { continue };
        for s in &sig.signals {
            for (c, (&v, &spread)) in s.coefficients.iter().zip(&s.spread).enumerate() {
                let sd = coefficient_sd(s.signal, spread, sig.cycles);
                if v.is_finite() && sd > 0.0 {
                    out.push(cycle_observation(trial, s.signal, c, v, sd));
                }
            }
        }
    }
    out
}

fn cycle_observation(trial: usize, signal: Signal, c: usize, value: f64, sd: f64) -> Observation {
    Observation {
        trial,
        channel: Metric::ALL.len() + signal.channel(c),
        block: Block::Cycle(signal),
        value,
        sd,
        sd_assumed: false,
        model_sd: 0.0,
    }
}

/// Logged cycles carried through the reference's logs ([`super::reference::carry_cycles`]:
/// each coefficient becomes nominal + (trial − reference)). Only where the nominal model
/// walks the reference's gait ([`like_gait`]): the change's mark on the robot stands for its
/// mark on the model only there.
#[allow(clippy::too_many_arguments)]
fn carry_cycles(
    set: &TrialSet,
    conditions: &[Condition],
    reference: &TrialSet,
    reference_conditions: &[Condition],
    sigs: &[Option<CycleSignature>],
    reference_sigs: &[Option<CycleSignature>],
    nominal: &[Walked],
    opts: &Observing<'_>,
    notes: &mut Vec<String>,
) -> Vec<Observation> {
    let mut carried: Vec<Option<CycleSignature>> = vec![None; sigs.len()];
    let mut unlike = Vec::new();
    for (trial, (sig, c)) in sigs.iter().zip(conditions).enumerate() {
        let Some(sig) = sig else { continue };
        let Some(r) = reference_conditions
            .iter()
            .position(|rc| super::reference::same_condition(c, rc))
        else {
            continue;
        };
        let (Some(rsig), Some(nsig)) = (&reference_sigs[r], nominal_signature(&nominal[trial]))
        else {
            continue;
        };
        match like_gait(
            &reference.trials[r],
            &nominal[trial].metrics,
            opts.default_relative_sd,
        ) {
            Ok(()) => carried[trial] = super::reference::carry_cycles(sig, rsig, &nsig),
            Err(why) => unlike.push(format!("{} ({why})", set.trials[trial].name())),
        }
    }
    if !unlike.is_empty() {
        notes.push(format!(
            "logged cycles not carried where the model does not walk the reference's gait: {}",
            unlike.join("; ")
        ));
    }
    cycle_observations(&carried)
}

/// The nominal walk's cycle as a signature (its spread 0: the model's own spread is counted
/// in the likelihood).
fn nominal_signature(w: &Walked) -> Option<CycleSignature> {
    let flat = w.cycles.as_ref()?;
    let n = flat.len() / Signal::ALL.len();
    let signals = Signal::ALL
        .iter()
        .filter_map(|&s| {
            let c: Vec<f64> = (0..n).map(|k| flat[s.channel(k)]).collect();
            c.iter()
                .skip(1)
                .any(|v| v.is_finite())
                .then(|| waveform::SignalCycle::from_coefficients(s, c, vec![0.0; n]))
        })
        .collect();
    Some(CycleSignature {
        drive_frequency_hz: f64::NAN,
        cycles: 1,
        signals,
    })
}

/// Observations of the trials' metrics (every measured metric a walk simulates).
pub fn metric_observations(
    set: &TrialSet,
    default_relative_sd: f64,
    notes: &mut Vec<String>,
) -> Vec<Observation> {
    let mut obs = Vec::new();
    let mut min_torque = 0;
    for (i, t) in set.trials.iter().enumerate() {
        for m in Metric::ALL {
            let Some(meas) = t.measured(m) else { continue };
            if m == Metric::MinTorqueNm {
                min_torque += 1;
                continue;
            }
            let (sd, assumed) = meas.sd_or(default_relative_sd);
            obs.push(Observation::metric(i, m, meas.value, sd, assumed));
        }
    }
    if min_torque > 0 {
        notes.push(format!(
            "{min_torque} min_torque_nm measurement(s) not used: the minimum walking torque needs \
             a bisection of walks per candidate (compare them with `survey sim min-torque`)"
        ));
    }
    obs
}
