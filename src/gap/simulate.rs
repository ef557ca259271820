//! A trial condition through the simulator: the design scaled to the trial's size and
//! overridden by its condition columns, plus (optionally) one candidate effect.

use std::path::Path;

use rayon::prelude::*;

use super::error::GapError;
use super::knob::ModelSetting;
use super::library::EffectLibrary;
use super::trials::{Metric, Trial, TrialSet};
use crate::progress::Observer;
use crate::sim::design::ControlSpec;
use crate::sim::{ContactScaling, Design, MassLaw, WalkOptions, simulate_walk};

/// Drive cycles simulated per trial: the gaits converge within 2–5 cycles (Poincaré
/// section of `sim walk`), and the metrics average over the rest.
pub const CYCLES_PER_TRIAL: f64 = 16.0;

/// Drive cycles a logged condition's walk settles before its cycle is measured.
pub const SETTLE_CYCLES: usize = 6;

/// A resolved trial condition: the design at 1× and what the trial changes.
#[derive(Clone, Debug)]
pub struct Condition {
    /// The trial names a log: its walks also give the steady cycle's Fourier coefficients.
    pub cycles: bool,
    pub design: Design,
    pub leg_length_m: f64,
    pub mass_law: MassLaw,
    pub contact: ContactScaling,
    pub mass_kg: Option<f64>,
    pub frequency_hz: Option<f64>,
    pub amplitude_deg: Option<f64>,
    /// Servo torque limit or bang-bang torque magnitude.
    pub torque_nm: Option<f64>,
    pub slope_deg: Option<f64>,
}

/// What one walk of a condition gives: its metrics and, for a logged condition, the
/// Fourier coefficients of its steady cycle ([`super::waveform::flat`]; None when it fell or
/// the condition has no log). Channels 0–7 are the metrics ([`Metric::index`]), the
/// coefficients follow.
#[derive(Clone, Debug, PartialEq)]
pub struct Walked {
    pub metrics: SimMetrics,
    pub cycles: Option<std::sync::Arc<[f64]>>,
}

impl Walked {
    /// The value of a channel (NaN where the walk has none).
    pub fn channel(&self, ch: usize) -> f64 {
        if ch < Metric::ALL.len() {
            self.metrics.values[ch]
        } else {
            self.cycles
                .as_ref()
                .and_then(|c| c.get(ch - Metric::ALL.len()).copied())
                .unwrap_or(f64::NAN)
        }
    }

    /// The channels a walk of this condition has: the metrics, and the cycle's if logged.
    pub fn channels_of(condition: &Condition) -> usize {
        Metric::ALL.len()
            + if condition.cycles {
                super::waveform::CHANNELS
            } else {
                0
            }
    }
}

/// Simulated metrics of one condition, by [`Metric::index`] (NaN: not computed, or the
/// walk fell).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimMetrics {
    pub values: [f64; 8],
    pub fell: bool,
}

impl SimMetrics {
    pub fn get(&self, m: Metric) -> f64 {
        self.values[m.index()]
    }

    /// The metrics a trial measured, as if simulated (exact trials of another engine taken
    /// as the truth): NaN where it measured nothing; a trial with no measured metric fell.
    pub fn measured_by(t: &Trial) -> SimMetrics {
        let mut values = [f64::NAN; 8];
        for m in Metric::simulated() {
            if let Some(v) = t.measured(m) {
                values[m.index()] = v.value;
            }
        }
        SimMetrics {
            values,
            fell: values.iter().all(|v| v.is_nan()),
        }
    }
}

/// Resolves the trials' designs (bundled name, or a TOML path relative to the trials file)
/// and condition columns.
pub fn resolve(set: &TrialSet) -> Result<Vec<Condition>, GapError> {
    set.trials
        .iter()
        .map(|t| resolve_trial(t, &set.origin, &set.base_dir))
        .collect()
}

fn resolve_trial(t: &Trial, origin: &str, base: &Path) -> Result<Condition, GapError> {
    let at = |message: String| GapError::at(origin, t.line, 0, message);
    let design = match Design::builtin(&t.design) {
        Ok(d) => d,
        Err(crate::sim::SimError::UnknownDesign(_)) => {
            let p = base.join(&t.design);
            if !p.exists() {
                let bundled: Vec<&str> = crate::sim::BUILTIN_DESIGNS
                    .iter()
                    .map(|(n, _, _)| *n)
                    .collect();
                return Err(at(format!(
                    "design {:?} is neither a bundled design ({}) nor a file {}",
                    t.design,
                    bundled.join(", "),
                    p.display()
                )));
            }
            Design::from_file(&p).map_err(|e| at(e.to_string()))?
        }
        Err(e) => return Err(at(e.to_string())),
    };
    let is_servo = matches!(design.control, ControlSpec::ServoSine { .. });
    // A drive column the design's controller does not have.
    let foreign = match (is_servo, t.amplitude_deg, t.torque_limit_nm, t.torque_nm) {
        (false, Some(_), _, _) => Some((
            "amplitude_deg",
            "is driven by bang-bang torque (no amplitude)",
        )),
        (false, _, Some(_), _) => Some(("torque_limit_nm", "is bang-bang: use torque_nm")),
        (true, _, _, Some(_)) => Some(("torque_nm", "is a position servo: use torque_limit_nm")),
        _ => None,
    };
    if let Some((column, why)) = foreign {
        return Err(at(format!("{column} given, but design {} {why}", t.design)));
    }
    let c = Condition {
        cycles: t.trajectory.is_some(),
        design,
        leg_length_m: t.leg_length_m,
        mass_law: t.mass_law.unwrap_or_default(),
        contact: t.contact.unwrap_or_default(),
        mass_kg: t.mass_kg,
        frequency_hz: t.frequency_hz,
        amplitude_deg: t.amplitude_deg,
        torque_nm: t.torque_limit_nm.or(t.torque_nm),
        slope_deg: t.slope_deg,
    };
    c.check_drive().map_err(at)?;
    Ok(c)
}

impl Condition {
    /// The drive must be one the design's time step resolves: 2π·f·dt ≤ 1 at the trial's
    /// size (the bound every oscillation of the simulator keeps).
    fn check_drive(&self) -> Result<(), String> {
        let d = self.scaled_design().map_err(|e| e.to_string())?;
        let f = match (self.frequency_hz, d.controller().frequency_hz()) {
            (Some(f), _) | (None, Some(f)) => f,
            (None, None) => return Ok(()),
        };
        let dt = d.numerics.time_step_s;
        let omega_dt = std::f64::consts::TAU * f * dt;
        if omega_dt.is_finite() && omega_dt <= 1.0 {
            Ok(())
        } else {
            Err(format!(
                "frequency_hz = {f}: the design's time step ({dt} s at this size) cannot resolve \
                 a drive that fast (2π·f·dt = {omega_dt:.3e} > 1; at most {:.4} Hz)",
                1.0 / (std::f64::consts::TAU * dt)
            ))
        }
    }

    /// The design scaled to the condition, with the setting's parameter values (on the 1×
    /// design) and effects added (at the design's 1×, scaled with it by each effect's rule).
    pub fn design_with(
        &self,
        lib: &EffectLibrary,
        setting: &ModelSetting,
    ) -> Result<Design, GapError> {
        let values: Vec<(&str, f64)> = setting.params_of(&self.design.name).collect();
        let mut d = self
            .design
            .with_values(&values)
            .map_err(GapError::sim(&self.design.name))?;
        // Effect magnitudes are in the nominal design's units (its m·g·L, foot modulus, …):
        // the SI value of an effect does not move when a parameter is recalibrated.
        for e in &setting.effects {
            let def = lib.get(&e.effect)?;
            d.effects.push(def.spec(&self.design, &e.nondimensional)?);
        }
        if let (Some(a), ControlSpec::ServoSine { amplitude_deg, .. }) =
            (self.amplitude_deg, &mut d.control)
        {
            *amplitude_deg = a;
        }
        if let Some(s) = self.slope_deg {
            d.ground.slope_deg = s;
        }
        let mut d = d
            .scaled(self.leg_length_m, self.mass_law, self.contact)
            .map_err(GapError::sim(&self.design.name))?;
        if let Some(m) = self.mass_kg {
            d.carrying(m);
        }
        let (frequency_hz, torque_nm) = match &mut d.control {
            ControlSpec::ServoSine {
                frequency_hz,
                torque_limit_nm,
                ..
            } => (frequency_hz, torque_limit_nm),
            ControlSpec::BangBang {
                frequency_hz,
                torque_nm,
            } => (frequency_hz, torque_nm),
        };
        if let Some(f) = self.frequency_hz {
            *frequency_hz = f;
        }
        if let Some(t) = self.torque_nm {
            *torque_nm = t;
        }
        Ok(d)
    }

    /// The design scaled to the condition's size, before the condition's own settings
    /// (drive, amplitude, payload, slope): its defaults at that size.
    pub fn scaled_design(&self) -> Result<Design, GapError> {
        self.design
            .scaled(self.leg_length_m, self.mass_law, self.contact)
            .map_err(GapError::sim(&self.design.name))
    }

    /// Whether the condition's walking direction is set by the walker's start, not by the
    /// model: its design walks either way ([`crate::sim::WalkingDirection::Either`]) and the
    /// condition sets no slope. Its velocity is then compared as a speed |v|, simulated and
    /// measured alike.
    pub fn direction_free(&self) -> bool {
        !self.design.criteria.walking_direction.is_forward()
            && self.slope_deg.is_none_or(|s| s == 0.0)
    }

    /// The drive frequency the condition runs at: its own, or the design's scaled to its size.
    pub fn drive_frequency_hz(&self) -> Result<f64, GapError> {
        if let Some(f) = self.frequency_hz {
            return Ok(f);
        }
        let d = self.scaled_design()?;
        Ok(d.controller().frequency_hz().unwrap_or(f64::NAN))
    }

    /// Simulates the condition under `setting` and measures the metrics (and the cycle, for
    /// a logged condition).
    pub fn simulate(
        &self,
        lib: &EffectLibrary,
        setting: &ModelSetting,
    ) -> Result<Walked, GapError> {
        self.simulate_from(lib, setting, None)
    }

    /// Simulates the condition under `setting`: the metrics and the trajectory (kept when
    /// `record`; the drive phase is f·t).
    pub fn walk(
        &self,
        lib: &EffectLibrary,
        setting: &ModelSetting,
        record: bool,
    ) -> Result<(SimMetrics, Vec<crate::sim::TrajectorySample>), GapError> {
        self.walk_from(lib, setting, record, None)
    }

    /// As [`Condition::simulate`], from the design's initial state perturbed by `seed`
    /// (`initial.seed_*` of the design; None: the unperturbed start every fit uses).
    pub fn simulate_from(
        &self,
        lib: &EffectLibrary,
        setting: &ModelSetting,
        seed: Option<u64>,
    ) -> Result<Walked, GapError> {
        let (metrics, trajectory) = self.walk_from(lib, setting, self.cycles, seed)?;
        let cycles = if self.cycles && !metrics.fell {
            let f = self
                .design_with(lib, setting)?
                .controller()
                .frequency_hz()
                .unwrap_or(1.0);
            super::waveform::signature(&super::waveform::log_of(&trajectory), f, SETTLE_CYCLES)
                .ok()
                .map(|sig| super::waveform::flat(&sig).into())
        } else {
            None
        };
        Ok(Walked { metrics, cycles })
    }

    fn walk_from(
        &self,
        lib: &EffectLibrary,
        setting: &ModelSetting,
        record: bool,
        seed: Option<u64>,
    ) -> Result<(SimMetrics, Vec<crate::sim::TrajectorySample>), GapError> {
        let d = self.design_with(lib, setting)?;
        let f = d.controller().frequency_hz().unwrap_or(1.0);
        let opts = WalkOptions {
            duration_s: CYCLES_PER_TRIAL / f,
            record_trajectory: record,
            seed,
            ..WalkOptions::default()
        };
        let r = simulate_walk(&d, &opts).map_err(|e| GapError::Sim {
            origin: format!("{} at L = {} m", self.design.name, self.leg_length_m),
            source: e,
        })?;
        let fell = r.report.fall_reason.is_some();
        let mut values = [f64::NAN; 8];
        if !fell {
            for m in Metric::simulated() {
                values[m.index()] = m.of_report(&r.report);
            }
            if self.direction_free() {
                let v = &mut values[Metric::VelocityMps.index()];
                *v = v.abs();
            }
        }
        Ok((SimMetrics { values, fell }, r.trajectory))
    }
}

/// Simulates many (condition, setting) jobs in parallel, in order.
pub fn simulate_jobs(
    jobs: &[(usize, ModelSetting)],
    conditions: &[Condition],
    lib: &EffectLibrary,
    progress: &dyn Observer,
) -> Result<Vec<Walked>, GapError> {
    jobs.par_iter()
        .map(|(i, s)| {
            let r = conditions[*i].simulate(lib, s);
            progress.tick();
            r
        })
        .collect()
}
