//! Running a walk and measuring its gait.

use std::io::Write;
use std::path::Path;

use nalgebra::Matrix3;
use serde::Serialize;

use super::design::{CriteriaSpec, Design};
use super::error::SimError;
use super::model::{GRAVITY_MPS2, Model, Simulator, StepInfo};
use super::similarity::{ContactScaling, MassLaw};
use super::state::State;

/// Share of the normal load a foot must carry to become the stance foot (step counting).
const STANCE_LOAD_SHARE: f64 = 0.75;

/// Longest walk accepted [s]: an hour of simulated time (the trajectory is kept in memory).
pub const MAX_DURATION_S: f64 = 3600.0;
/// Leg lengths a design may be scaled to [m].
pub const LEG_LENGTH_RANGE_M: (f64, f64) = (1e-3, 100.0);
/// Largest ω·dt accepted for the stiffest physical oscillation, the foot bouncing on its
/// contact. The integrator is implicit in the contact stiffness, so larger steps do not
/// blow up linearly, but the nonlinear contact (force ∝ δ², switching on and off within a
/// step) does: the bundled designs run at ω·dt = 0.14–0.28, and a 0.5 s step (ω·dt ≈ 70)
/// diverges.
pub const MAX_CONTACT_OMEGA_DT: f64 = 1.0;

/// Largest stable time step of a (scaled) design [s]: ω·dt ≤ [`MAX_CONTACT_OMEGA_DT`] for
/// ω² = k/m, k = dF/dδ of one foot carrying the whole weight upright. For the pressure
/// field p = E(1 − r) of an ellipsoid (a, b, c) pressed by δ ≪ c along c,
/// F = π·E·a·b·δ²/c², so k = 2F/δ = 2·√(π·E·a·b·m·g)/c.
pub fn stable_time_step_s(d: &Design) -> f64 {
    let [a, b, c] = d.geometry.foot_semi_axes_m;
    let m = d.mass.total_mass_kg;
    let e = d.contact.hydroelastic_modulus_pa;
    let k = 2.0 * (std::f64::consts::PI * e * a * b * m * GRAVITY_MPS2).sqrt() / c;
    let omega = (k / m).sqrt();
    MAX_CONTACT_OMEGA_DT / omega
}

/// Options of a walk (defaults: design's own size, m ∝ L², similar contact, 25 s, no seed).
#[derive(Clone, Debug, PartialEq)]
pub struct WalkOptions {
    /// Scale the design to this leg length [m] (None: the design's own).
    pub leg_length_m: Option<f64>,
    pub mass_law: MassLaw,
    pub contact_scaling: ContactScaling,
    /// Servo torque limit or bang-bang torque magnitude [N·m] (None: the design's, scaled).
    pub torque_limit_nm: Option<f64>,
    /// Drive frequency [Hz] (None: the design's, scaled ∝ L^(−1/2)).
    pub frequency_hz: Option<f64>,
    pub duration_s: f64,
    /// Deterministic perturbation of the initial state.
    pub seed: Option<u64>,
    /// Keep the sampled trajectory in the result.
    pub record_trajectory: bool,
}

impl Default for WalkOptions {
    fn default() -> Self {
        WalkOptions {
            leg_length_m: None,
            mass_law: MassLaw::L2,
            contact_scaling: ContactScaling::Similar,
            torque_limit_nm: None,
            frequency_hz: None,
            duration_s: 25.0,
            seed: None,
            record_trajectory: true,
        }
    }
}

/// One sample of the trajectory.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TrajectorySample {
    pub t_s: f64,
    /// Hip point, world [m].
    pub x_m: f64,
    pub y_m: f64,
    pub z_m: f64,
    /// Attitude of the hip frame (left leg turned by q/2: the legs' bisector),
    /// extrinsic x-y-z (roll, pitch, yaw) [deg]; yaw unwrapped.
    pub roll_deg: f64,
    pub pitch_deg: f64,
    pub yaw_deg: f64,
    pub hip_angle_deg: f64,
    pub hip_torque_nm: f64,
    /// Largest |hip torque| since the previous sample [N·m].
    pub peak_abs_torque_nm: f64,
    /// Cumulative positive actuator work [J].
    pub positive_work_j: f64,
    pub feet_in_contact: u8,
    /// Normal contact force on each foot at this instant, [left, right] [N].
    pub normal_force_n: [f64; 2],
}

/// Gait metrics of a walk (NaN → JSON null where undefined, e.g. after an early fall).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WalkReport {
    pub design: String,
    pub leg_length_m: f64,
    pub mass_kg: f64,
    pub mass_law: MassLaw,
    pub contact_scaling: ContactScaling,
    pub drive_frequency_hz: f64,
    pub torque_limit_nm: f64,
    pub duration_s: f64,
    pub time_step_s: f64,
    pub seed: Option<u64>,
    /// No fall and steady forward speed above the design's threshold.
    pub walks: bool,
    /// Why the walk counts as a fall ("hip_low", "roll", "pitch", "diverged"), if it does.
    pub fall_reason: Option<String>,
    pub fell_at_s: Option<f64>,
    /// Start of the limit cycle on the pitch/pitch-rate Poincaré section (None: not found;
    /// metrics then use the second half of the run).
    pub converged_at_s: Option<f64>,
    /// Start of the window the metrics are computed on [s].
    pub window_start_s: f64,
    /// Drive cycles in the window.
    pub cycles: usize,
    /// Forward speed along the mean heading over the window [m/s].
    pub velocity_mps: f64,
    /// v/√(gL).
    pub froude: f64,
    /// Support transfers per second over the window: a step is counted when the other foot
    /// takes over three quarters of the normal load.
    pub step_frequency_hz: f64,
    pub roll_pp_deg: f64,
    pub roll_pp_deg_sd: f64,
    pub pitch_pp_deg: f64,
    pub pitch_pp_deg_sd: f64,
    pub yaw_pp_deg: f64,
    pub yaw_pp_deg_sd: f64,
    /// Heading change over the window per metre travelled [deg/m].
    pub turning_deg_per_m: f64,
    /// Positive actuator work over the window [J].
    pub mechanical_work_j: f64,
    /// Positive actuator work / (m·g·distance).
    pub cot: f64,
    /// Largest |hip torque| in the window [N·m].
    pub peak_torque_nm: f64,
}

/// Report plus (optionally) the trajectory.
#[derive(Clone, Debug)]
pub struct WalkResult {
    pub report: WalkReport,
    pub trajectory: Vec<TrajectorySample>,
}

/// Everything needed to run a walk, after scaling and option overrides.
pub struct WalkSetup {
    pub design: Design,
    pub simulator: Simulator,
}

/// Scales the design, applies the overrides and builds the simulator.
pub fn prepare_walk(design: &Design, opts: &WalkOptions) -> Result<WalkSetup, SimError> {
    if !(opts.duration_s > 0.0 && opts.duration_s <= MAX_DURATION_S) {
        return Err(SimError::InvalidOption {
            option: "duration_s".into(),
            reason: format!(
                "must be in (0, {MAX_DURATION_S}] s (an hour of simulated walking), got {}",
                opts.duration_s
            ),
        });
    }
    if let Some(l) = opts.leg_length_m
        && !(LEG_LENGTH_RANGE_M.0..=LEG_LENGTH_RANGE_M.1).contains(&l)
    {
        return Err(SimError::InvalidOption {
            option: "leg_length_m".into(),
            reason: format!(
                "must be in [{}, {}] m (a 1 mm to 100 m walker), got {l}",
                LEG_LENGTH_RANGE_M.0, LEG_LENGTH_RANGE_M.1
            ),
        });
    }
    let d = design.scaled(
        opts.leg_length_m.unwrap_or(design.geometry.leg_length_m),
        opts.mass_law,
        opts.contact_scaling,
    )?;
    let model = d.model();
    let mut controller = d.controller();
    if let Some(t) = opts.torque_limit_nm {
        if !(t >= 0.0 && t.is_finite()) {
            return Err(SimError::InvalidOption {
                option: "torque_limit_nm".into(),
                reason: format!("must be finite and ≥ 0, got {t}"),
            });
        }
        controller.set_torque_limit_nm(t);
    }
    if let Some(f) = opts.frequency_hz {
        if !(f > 0.0 && f.is_finite()) {
            return Err(SimError::InvalidOption {
                option: "frequency_hz".into(),
                reason: format!("must be finite and > 0, got {f}"),
            });
        }
        controller.set_frequency_hz(f);
    }
    let state = d.initial_state(&model, opts.seed);
    let effects = d.effects.iter().filter_map(|e| e.build()).collect();
    let dt = d.numerics.time_step_s;
    let limit = stable_time_step_s(&d);
    if dt > limit {
        return Err(SimError::InvalidValue {
            origin: d.origin_name(),
            field: "numerics.time_step_s".into(),
            value: format!("{dt} s (at L = {} m)", d.geometry.leg_length_m),
            reason: format!(
                "beyond the stable limit {limit:.3e} s of the foot contact: a foot carrying the weight \
                 (E = {} Pa, m = {} kg) vibrates at {:.1} Hz, and the step must resolve it \
                 (ω·dt ≤ {MAX_CONTACT_OMEGA_DT}); reduce the time step",
                d.contact.hydroelastic_modulus_pa,
                d.mass.total_mass_kg,
                MAX_CONTACT_OMEGA_DT / limit / std::f64::consts::TAU
            ),
        });
    }
    Ok(WalkSetup {
        simulator: Simulator::new(model, controller, effects, state, dt),
        design: d,
    })
}

/// Attitude (roll, pitch, yaw) [rad] of the hip frame: left leg turned by q/2 about y.
pub fn hip_frame_attitude(model: &Model, s: &State) -> (f64, f64, f64) {
    let _ = model;
    let r = s.orientation.to_rotation_matrix().matrix() * rot_y(0.5 * s.hip_angle_rad);
    let pitch = (-r[(2, 0)]).clamp(-1.0, 1.0).asin();
    let roll = r[(2, 1)].atan2(r[(2, 2)]);
    let yaw = r[(1, 0)].atan2(r[(0, 0)]);
    (roll, pitch, yaw)
}

fn rot_y(q: f64) -> Matrix3<f64> {
    let (s, c) = q.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Runs a walk of `design` with `opts` and measures the gait.
pub fn simulate_walk(design: &Design, opts: &WalkOptions) -> Result<WalkResult, SimError> {
    let mut setup = prepare_walk(design, opts)?;
    run_setup(&mut setup, opts)
}

/// Runs a prepared walk.
pub fn run_setup(setup: &mut WalkSetup, opts: &WalkOptions) -> Result<WalkResult, SimError> {
    let d = &setup.design;
    let sim = &mut setup.simulator;
    let l = d.geometry.leg_length_m;
    let freq = sim.controller.frequency_hz().unwrap_or(1.0);
    let dt = sim.dt_s;
    let steps = (opts.duration_s / dt).round() as usize;
    // About 200 samples per drive cycle resolve the attitude peaks well.
    let record_every = ((1.0 / freq) / (200.0 * dt)).floor().max(1.0) as usize;
    let crit = &d.criteria;
    let mut samples: Vec<TrajectorySample> =
        Vec::with_capacity((steps / record_every + 2).min(1 << 16));
    let mut work = 0.0;
    let mut peak = 0.0f64;
    let mut fall: Option<(String, f64)> = None;
    let mut yaw_prev = 0.0;
    let mut yaw_unwrapped = 0.0;
    let mut push = |sim: &Simulator,
                    torque: f64,
                    peak: f64,
                    work: f64,
                    info: &StepInfo,
                    samples: &mut Vec<TrajectorySample>| {
        let s = &sim.state;
        let (roll, pitch, yaw) = hip_frame_attitude(&sim.model, s);
        let mut dy = yaw - yaw_prev;
        dy -= (dy / std::f64::consts::TAU).round() * std::f64::consts::TAU;
        yaw_unwrapped += dy;
        yaw_prev = yaw;
        samples.push(TrajectorySample {
            t_s: sim.time_s,
            x_m: s.hip_position_m.x,
            y_m: s.hip_position_m.y,
            z_m: s.hip_position_m.z,
            roll_deg: roll.to_degrees(),
            pitch_deg: pitch.to_degrees(),
            yaw_deg: yaw_unwrapped.to_degrees(),
            hip_angle_deg: s.hip_angle_rad.to_degrees(),
            hip_torque_nm: torque,
            peak_abs_torque_nm: peak,
            positive_work_j: work,
            feet_in_contact: info.feet_in_contact,
            normal_force_n: info.normal_force_n,
        });
    };
    push(sim, 0.0, 0.0, 0.0, &StepInfo::default(), &mut samples);
    for i in 1..=steps {
        let info = sim.step();
        let torque = info.actuator_torque_nm;
        work += (torque * sim.state.hip_rate_rad_s).max(0.0) * dt;
        peak = peak.max(torque.abs());
        if i % record_every == 0 || i == steps {
            // A non-finite state, or a speed no walker reaches (100 √(gL): a 0.15 m robot
            // at 120 m/s), is the integrator blowing up, not the robot falling.
            let blown_up = sim.state.hip_velocity_mps.norm() > 100.0 * (GRAVITY_MPS2 * l).sqrt();
            if !sim.state.is_finite() || blown_up {
                fall = Some(("diverged".into(), sim.time_s));
                break;
            }
            push(sim, torque, peak, work, &info, &mut samples);
            peak = 0.0;
            if let Some(r) = physical_fall(&samples[samples.len() - 1], crit, l) {
                fall = Some((r.to_string(), sim.time_s));
                break;
            }
        }
    }
    let facts = RunFacts {
        drive_frequency_hz: freq,
        torque_limit_nm: sim.controller.torque_limit_nm().unwrap_or(0.0),
        time_step_s: dt,
    };
    let report = analyze(d, &facts, opts, &samples, fall);
    Ok(WalkResult {
        report,
        trajectory: if opts.record_trajectory {
            samples
        } else {
            Vec::new()
        },
    })
}

/// Runs a walk with the given torque limit (servo) / torque magnitude (bang-bang) and
/// says whether it walks (the predicate a minimum-torque search needs).
pub fn walks_with_torque_limit(
    design: &Design,
    opts: &WalkOptions,
    torque_limit_nm: f64,
) -> Result<bool, SimError> {
    let mut o = opts.clone();
    o.torque_limit_nm = Some(torque_limit_nm);
    o.record_trajectory = false;
    Ok(simulate_walk(design, &o)?.report.walks)
}

fn interp(samples: &[TrajectorySample], t: f64, f: impl Fn(&TrajectorySample) -> f64) -> f64 {
    let i = samples.partition_point(|s| s.t_s < t);
    if i == 0 {
        return f(&samples[0]);
    }
    if i >= samples.len() {
        return f(&samples[samples.len() - 1]);
    }
    let (a, b) = (&samples[i - 1], &samples[i]);
    let w = (t - a.t_s) / (b.t_s - a.t_s);
    f(a) * (1.0 - w) + f(b) * w
}

/// Mean and sample standard deviation (n − 1); NaN for no values, sd 0 for one.
pub fn mean_sd(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, var.sqrt())
}

/// Poincaré-section convergence: the section is taken once per drive cycle (phase 0); the
/// gait has converged to a limit cycle at the first section from which three consecutive
/// returns (lag 1, or lag 2 for a period-2 gait) stay within 10 % of the cycle's pitch
/// amplitude in (pitch, pitch-rate/ω) space.
fn detect_convergence(samples: &[TrajectorySample], freq: f64, t_end: f64) -> Option<f64> {
    let period = 1.0 / freq;
    let n = (t_end / period).floor() as usize;
    if n < 5 {
        return None;
    }
    let w = std::f64::consts::TAU * freq;
    let h = 0.01 * period;
    let mut pts = Vec::with_capacity(n);
    let mut amp = Vec::with_capacity(n);
    for k in 0..n {
        let t = k as f64 * period;
        let p = interp(samples, t, |s| s.pitch_deg);
        let rate = (interp(samples, t + h, |s| s.pitch_deg)
            - interp(samples, (t - h).max(0.0), |s| s.pitch_deg))
            / (2.0 * h);
        pts.push((p, rate / w));
        let (lo, hi) = cycle_range(samples, t, t + period, |s| s.pitch_deg);
        amp.push((hi - lo).max(1.0));
    }
    let close = |a: usize, b: usize| {
        let (pa, ra) = pts[a];
        let (pb, rb) = pts[b];
        ((pa - pb).powi(2) + (ra - rb).powi(2)).sqrt() <= 0.1 * amp[b]
    };
    (2..n.saturating_sub(3))
        .find(|&k| (k..k + 3).all(|j| close(j, j - 1)) || (k..k + 3).all(|j| close(j, j - 2)))
        .map(|k| (k - 1) as f64 * period)
}

fn cycle_range(
    samples: &[TrajectorySample],
    t0: f64,
    t1: f64,
    f: impl Fn(&TrajectorySample) -> f64,
) -> (f64, f64) {
    let i0 = samples.partition_point(|s| s.t_s < t0);
    let i1 = samples.partition_point(|s| s.t_s <= t1);
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for s in &samples[i0..i1.max(i0)] {
        let v = f(s);
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (lo, hi)
}

/// The design's fall criteria on one sample: the hip below `fall_hip_height_over_l`·L, or
/// the hip frame's |roll| or |pitch| beyond its limit (the same checks for a live run and
/// for a trajectory recorded elsewhere).
fn physical_fall(s: &TrajectorySample, crit: &CriteriaSpec, l: f64) -> Option<&'static str> {
    if s.z_m < crit.fall_hip_height_over_l * l {
        Some("hip_low")
    } else if s.roll_deg.abs() > crit.fall_roll_deg {
        Some("roll")
    } else if s.pitch_deg.abs() > crit.fall_pitch_deg {
        Some("pitch")
    } else {
        None
    }
}

/// What the metrics need of the run besides its samples.
struct RunFacts {
    drive_frequency_hz: f64,
    torque_limit_nm: f64,
    time_step_s: f64,
}

/// Gait metrics of a trajectory recorded elsewhere (another simulator, e.g. Drake through
/// tools/drake/, or a motion-capture export in the same CSV format), computed by exactly
/// the code that measures the project's own walks. `design` and `opts` give the scaled
/// design (size, mass, drive frequency, thresholds); falls are detected on the samples with
/// the design's criteria, as during a run.
pub fn report_from_trajectory(
    design: &Design,
    opts: &WalkOptions,
    samples: &[TrajectorySample],
) -> Result<WalkReport, SimError> {
    let setup = prepare_walk(design, opts)?;
    let d = &setup.design;
    let sim = &setup.simulator;
    let l = d.geometry.leg_length_m;
    let crit = &d.criteria;
    let mut fall = None;
    for s in samples {
        let finite = [s.x_m, s.y_m, s.z_m, s.roll_deg, s.pitch_deg, s.yaw_deg]
            .iter()
            .all(|x| x.is_finite());
        let reason = if finite {
            physical_fall(s, crit, l)
        } else {
            Some("diverged")
        };
        if let Some(r) = reason {
            fall = Some((r.to_string(), s.t_s));
            break;
        }
    }
    let mut o = opts.clone();
    o.duration_s = samples.last().map(|s| s.t_s).unwrap_or(0.0);
    let facts = RunFacts {
        drive_frequency_hz: sim.controller.frequency_hz().unwrap_or(1.0),
        torque_limit_nm: sim.controller.torque_limit_nm().unwrap_or(0.0),
        time_step_s: sim.dt_s,
    };
    let end = fall.as_ref().map_or(samples.len(), |f: &(String, f64)| {
        samples.partition_point(|s| s.t_s <= f.1)
    });
    Ok(analyze(d, &facts, &o, &samples[..end], fall))
}

/// Reads a trajectory CSV in the format [`write_trajectory_csv`] writes (header names the
/// columns; extra columns are ignored). Errors name the file, line and column.
pub fn read_trajectory_csv(path: &Path) -> Result<Vec<TrajectorySample>, SimError> {
    let text = std::fs::read_to_string(path).map_err(|source| SimError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let bad = |line: usize, message: String| SimError::Trajectory {
        origin: format!("{}, line {line}", path.display()),
        message,
    };
    let mut lines = text.lines().enumerate();
    let header: Vec<&str> = match lines.next() {
        Some((_, h)) => h.split(',').map(str::trim).collect(),
        None => return Err(bad(1, "empty file: expected a header line".into())),
    };
    const COLUMNS: [&str; 14] = [
        "t_s",
        "x_m",
        "y_m",
        "z_m",
        "roll_deg",
        "pitch_deg",
        "yaw_deg",
        "hip_angle_deg",
        "hip_torque_nm",
        "peak_abs_torque_nm",
        "positive_work_j",
        "feet_in_contact",
        "left_normal_force_n",
        "right_normal_force_n",
    ];
    let mut idx = [0usize; 14];
    for (k, name) in COLUMNS.iter().enumerate() {
        idx[k] = header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| bad(1, format!("missing column `{name}`")))?;
    }
    let mut out = Vec::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let mut v = [0.0f64; 14];
        for (k, name) in COLUMNS.iter().enumerate() {
            let cell = cells
                .get(idx[k])
                .ok_or_else(|| bad(i + 1, format!("column `{name}`: missing cell")))?;
            v[k] = cell
                .parse::<f64>()
                .map_err(|_| bad(i + 1, format!("column `{name}`: `{cell}` is not a number")))?;
        }
        if out.last().is_some_and(|p: &TrajectorySample| v[0] <= p.t_s) {
            return Err(bad(
                i + 1,
                format!("column `t_s`: time {} does not increase", v[0]),
            ));
        }
        out.push(TrajectorySample {
            t_s: v[0],
            x_m: v[1],
            y_m: v[2],
            z_m: v[3],
            roll_deg: v[4],
            pitch_deg: v[5],
            yaw_deg: v[6],
            hip_angle_deg: v[7],
            hip_torque_nm: v[8],
            peak_abs_torque_nm: v[9],
            positive_work_j: v[10],
            feet_in_contact: v[11].clamp(0.0, 2.0) as u8,
            normal_force_n: [v[12], v[13]],
        });
    }
    if out.len() < 3 {
        return Err(bad(
            1,
            format!("{} samples: too few to measure a gait", out.len()),
        ));
    }
    Ok(out)
}

fn analyze(
    d: &Design,
    facts: &RunFacts,
    opts: &WalkOptions,
    samples: &[TrajectorySample],
    fall: Option<(String, f64)>,
) -> WalkReport {
    let l = d.geometry.leg_length_m;
    let m = d.mass.total_mass_kg;
    let freq = facts.drive_frequency_hz;
    let period = 1.0 / freq;
    let t_end = samples.last().map(|s| s.t_s).unwrap_or(0.0);
    let converged_at_s = if fall.is_none() {
        detect_convergence(samples, freq, t_end)
    } else {
        None
    };
    // Metrics window: from convergence, else the second half of the run; whole cycles.
    let start = converged_at_s.unwrap_or(0.5 * t_end);
    let cycles = ((t_end - start) / period).floor().max(0.0) as usize;
    let stop = start + cycles as f64 * period;
    let nan = f64::NAN;
    let mut r = unmeasured_report(d, facts, opts, &fall, converged_at_s, start, cycles);
    if fall.is_some() || cycles < 2 {
        return r;
    }
    let i0 = samples.partition_point(|s| s.t_s < start);
    let i1 = samples.partition_point(|s| s.t_s <= stop + 1e-9);
    let win = &samples[i0..i1];
    if win.len() < 3 {
        return r;
    }
    // Per-cycle peak-to-valley attitude. Yaw is first detrended over the cycle (minus the
    // straight line between its values at the cycle's ends) so a slowly turning walker
    // reports its yaw oscillation, not its heading change.
    let pp = attitude_pp(samples, start, period, cycles);
    (r.roll_pp_deg, r.roll_pp_deg_sd) = mean_sd(&pp[0]);
    (r.pitch_pp_deg, r.pitch_pp_deg_sd) = mean_sd(&pp[1]);
    (r.yaw_pp_deg, r.yaw_pp_deg_sd) = mean_sd(&pp[2]);
    // Speed along the mean heading (circular mean of yaw).
    let (sx, sy) = win.iter().fold((0.0, 0.0), |(a, b), s| {
        (
            a + s.yaw_deg.to_radians().cos(),
            b + s.yaw_deg.to_radians().sin(),
        )
    });
    let heading = sy.atan2(sx);
    let (a, b) = (win[0], win[win.len() - 1]);
    let dt = b.t_s - a.t_s;
    let (dx, dy) = (b.x_m - a.x_m, b.y_m - a.y_m);
    let forward = dx * heading.cos() + dy * heading.sin();
    r.velocity_mps = forward / dt;
    r.froude = r.velocity_mps / (GRAVITY_MPS2 * l).sqrt();
    let distance = (dx * dx + dy * dy).sqrt();
    r.turning_deg_per_m = if distance > 0.0 {
        (b.yaw_deg - a.yaw_deg) / distance
    } else {
        nan
    };
    // Steps: transfers of support. A step is taken when the other foot carries more than
    // three quarters of the normal load (weight acceptance); the hysteresis keeps contact
    // chatter and double support from counting, and samples in flight (< 20 % of m·g on the
    // ground) keep the current stance. This is the definition of a step itself; roll-side
    // crossings (used before) agree on the bundled gaits but are only a proxy for it.
    let crossings = count_steps(win, m);
    r.step_frequency_hz = crossings as f64 / dt;
    r.mechanical_work_j = b.positive_work_j - a.positive_work_j;
    r.cot = if distance > 0.0 {
        r.mechanical_work_j / (m * GRAVITY_MPS2 * distance)
    } else {
        nan
    };
    r.peak_torque_nm = win[1..]
        .iter()
        .map(|s| s.peak_abs_torque_nm)
        .fold(0.0, f64::max);
    // A design that walks either way (fore–aft symmetric, flat) walks backward as well as
    // forward.
    let speed = if d.walks_either_way() {
        r.velocity_mps.abs()
    } else {
        r.velocity_mps
    };
    r.walks = speed > d.criteria.walk_speed_threshold_mps(l);
    r
}

/// The report with the run's facts filled in and every gait metric NaN (not yet measured).
fn unmeasured_report(
    d: &Design,
    facts: &RunFacts,
    opts: &WalkOptions,
    fall: &Option<(String, f64)>,
    converged_at_s: Option<f64>,
    start: f64,
    cycles: usize,
) -> WalkReport {
    let l = d.geometry.leg_length_m;
    let m = d.mass.total_mass_kg;
    let freq = facts.drive_frequency_hz;
    let nan = f64::NAN;
    WalkReport {
        design: d.name.clone(),
        leg_length_m: l,
        mass_kg: m,
        mass_law: opts.mass_law,
        contact_scaling: opts.contact_scaling,
        drive_frequency_hz: freq,
        torque_limit_nm: facts.torque_limit_nm,
        duration_s: opts.duration_s,
        time_step_s: facts.time_step_s,
        seed: opts.seed,
        walks: false,
        fall_reason: fall.as_ref().map(|f| f.0.clone()),
        fell_at_s: fall.as_ref().map(|f| f.1),
        converged_at_s,
        window_start_s: start,
        cycles,
        velocity_mps: nan,
        froude: nan,
        step_frequency_hz: nan,
        roll_pp_deg: nan,
        roll_pp_deg_sd: nan,
        pitch_pp_deg: nan,
        pitch_pp_deg_sd: nan,
        yaw_pp_deg: nan,
        yaw_pp_deg_sd: nan,
        turning_deg_per_m: nan,
        mechanical_work_j: nan,
        cot: nan,
        peak_torque_nm: nan,
    }
}

/// Per-cycle peak-to-valley roll, pitch and detrended yaw over the metrics window.
fn attitude_pp(
    samples: &[TrajectorySample],
    start: f64,
    period: f64,
    cycles: usize,
) -> [Vec<f64>; 3] {
    let mut pp = [Vec::new(), Vec::new(), Vec::new()];
    for c in 0..cycles {
        let t0 = start + c as f64 * period;
        let t1 = t0 + period;
        let (lo, hi) = cycle_range(samples, t0, t1, |s| s.roll_deg);
        pp[0].push(hi - lo);
        let (lo, hi) = cycle_range(samples, t0, t1, |s| s.pitch_deg);
        pp[1].push(hi - lo);
        let (y0, y1) = (
            interp(samples, t0, |s| s.yaw_deg),
            interp(samples, t1, |s| s.yaw_deg),
        );
        let (lo, hi) = cycle_range(samples, t0, t1, |s| {
            s.yaw_deg - y0 - (y1 - y0) * (s.t_s - t0) / period
        });
        pp[2].push(hi - lo);
    }
    pp
}

/// Number of support transfers (steps) in the window `win` for a walker of mass `m`.
fn count_steps(win: &[TrajectorySample], m: f64) -> usize {
    let mut stance: Option<usize> = None;
    let mut crossings = 0usize;
    for s in win {
        let total = s.normal_force_n[0] + s.normal_force_n[1];
        if total < 0.2 * m * GRAVITY_MPS2 {
            continue;
        }
        let now = (0..2).find(|&k| s.normal_force_n[k] > STANCE_LOAD_SHARE * total);
        if let Some(k) = now {
            if stance.is_some_and(|prev| prev != k) {
                crossings += 1;
            }
            stance = Some(k);
        }
    }
    crossings
}

/// Writes the trajectory as CSV.
pub fn write_trajectory_csv(samples: &[TrajectorySample], path: &Path) -> Result<(), SimError> {
    let err = |e: std::io::Error| SimError::Output {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let file = std::fs::File::create(path).map_err(err)?;
    let mut w = std::io::BufWriter::new(file);
    writeln!(
        w,
        "t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,hip_angle_deg,hip_torque_nm,peak_abs_torque_nm,positive_work_j,feet_in_contact,left_normal_force_n,right_normal_force_n"
    )
    .map_err(err)?;
    for s in samples {
        writeln!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.t_s,
            s.x_m,
            s.y_m,
            s.z_m,
            s.roll_deg,
            s.pitch_deg,
            s.yaw_deg,
            s.hip_angle_deg,
            s.hip_torque_nm,
            s.peak_abs_torque_nm,
            s.positive_work_j,
            s.feet_in_contact,
            s.normal_force_n[0],
            s.normal_force_n[1]
        )
        .map_err(err)?;
    }
    w.flush().map_err(err)
}
