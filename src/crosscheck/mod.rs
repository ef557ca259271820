//! Cross-check of the walker simulator against Drake on identical models.
//!
//! The Drake side is a Python harness (`tools/drake/`) that reads the same design TOMLs and
//! the same case definitions (`tests/golden/drake/cases.toml`) and writes goldens
//! (`tests/golden/drake/elementary.json`, `walks/*.csv`, `walks/*.json`). This module is
//! the project side: it runs each elementary case in the project's engine and measures it
//! exactly as the harness does (the same windows, fits and crossings), and it re-analyses
//! Drake's walk trajectories with the project's own gait metrics
//! ([`crate::sim::report_from_trajectory`]) so both engines' walks are measured by one code.
//! The Rust build never needs Python or Drake.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::progress::Observer;
use crate::sim::{
    Controller, Design, FrictionCone, GRAVITY_MPS2, SimError, Simulator, State, WalkOptions,
    WalkReport, hip_frame_attitude, read_trajectory_csv, report_from_trajectory, simulate_walk,
    upright_sinkage_m,
};

/// Errors of the cross-check (reading goldens, running cases).
#[derive(Debug, thiserror::Error)]
pub enum CrosscheckError {
    #[error("cannot read {path}: {message}")]
    Read { path: PathBuf, message: String },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
    #[error(transparent)]
    Sim(#[from] SimError),
}

fn read(path: &Path) -> Result<String, CrosscheckError> {
    std::fs::read_to_string(path).map_err(|e| CrosscheckError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Initial condition of a case (cases.toml `initial`).
#[derive(Clone, Debug, Deserialize, Serialize)]
pub struct CaseInitial {
    #[serde(default)]
    pub roll_deg: f64,
    #[serde(default)]
    pub pitch_deg: f64,
    #[serde(default)]
    pub yaw_deg: f64,
    /// Left-leg angular velocity in the left-leg frame [rad/s].
    #[serde(default)]
    pub angular_velocity_rad_s: [f64; 3],
    /// Hip-point velocity, world [m/s].
    #[serde(default)]
    pub linear_velocity_mps: [f64; 3],
    /// "design", "touch" or "static" (see cases.toml).
    #[serde(default = "default_placement")]
    pub placement: String,
}

fn default_placement() -> String {
    "design".into()
}

/// One elementary case of cases.toml.
#[derive(Clone, Debug, Deserialize, Serialize)]
pub struct Case {
    pub design: String,
    #[serde(default)]
    pub overrides: toml::Table,
    #[serde(default = "default_drive")]
    pub drive: String,
    #[serde(default = "default_true")]
    pub ground_contact: bool,
    #[serde(default = "default_gravity")]
    pub gravity_mps2: f64,
    pub duration_s: f64,
    pub initial: CaseInitial,
    #[serde(default)]
    pub measure: Vec<String>,
    #[serde(default)]
    pub method: String,
}

fn default_drive() -> String {
    "design".into()
}
fn default_true() -> bool {
    true
}
fn default_gravity() -> f64 {
    GRAVITY_MPS2
}

#[derive(Deserialize)]
struct CasesFile {
    cases: BTreeMap<String, Case>,
}

/// Reads cases.toml.
pub fn load_cases(path: &Path) -> Result<BTreeMap<String, Case>, CrosscheckError> {
    let text = read(path)?;
    let f: CasesFile = toml::from_str(&text).map_err(|e| CrosscheckError::Invalid {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok(f.cases)
}

/// Applies dotted-key overrides ("a.b" = v sets [a] b = v) to a design TOML table.
fn apply_overrides(design: &mut toml::Table, overrides: &toml::Table) {
    for (key, value) in overrides {
        let parts: Vec<&str> = key.split('.').collect();
        let mut node = &mut *design;
        for p in &parts[..parts.len() - 1] {
            let entry = node
                .entry(p.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            if !entry.is_table() {
                *entry = toml::Value::Table(toml::Table::new());
            }
            node = match entry {
                toml::Value::Table(t) => t,
                _ => unreachable!("just made a table"),
            };
        }
        node.insert(parts[parts.len() - 1].to_string(), value.clone());
    }
}

/// The design of a case with its overrides applied (paths relative to `root`).
pub fn case_design(root: &Path, case: &Case) -> Result<Design, CrosscheckError> {
    let path = root.join(&case.design);
    let text = read(&path)?;
    let mut table: toml::Table = toml::from_str(&text).map_err(|e| CrosscheckError::Invalid {
        path: path.clone(),
        message: e.to_string(),
    })?;
    apply_overrides(&mut table, &case.overrides);
    // A case turns the walker into an elementary body (a sphere on an incline, a sliding
    // box): the design's [[uncertain]] ranges describe the walker, not these bodies, and
    // an override outside them is the case, not an error.
    table.remove("uncertain");
    table.remove("audit");
    let text = toml::to_string(&table).map_err(|e| CrosscheckError::Invalid {
        path: path.clone(),
        message: e.to_string(),
    })?;
    Ok(Design::from_toml_str(
        &text,
        &format!("{} (with the case's overrides)", path.display()),
    )?)
}

/// Every step of a case: what the measurements need.
#[derive(Default)]
struct Trace {
    t: Vec<f64>,
    hip: Vec<Vector3<f64>>,
    roll_deg: Vec<f64>,
    hip_angle_rad: Vec<f64>,
    omega_left_w: Vec<Vector3<f64>>,
    com: Vec<Vector3<f64>>,
    vcom: Vec<Vector3<f64>>,
    normal_n: Vec<[f64; 2]>,
    feet: Vec<u8>,
    torque_nm: Vec<f64>,
}

fn record(tr: &mut Trace, sim: &Simulator, normal: [f64; 2], feet: u8, torque: f64) {
    let s = &sim.state;
    let model = &sim.model;
    let kin = model.kinematics(s);
    let (roll, _, _) = hip_frame_attitude(model, s);
    let m = model.total_mass_kg();
    let mut com = Vector3::zeros();
    let mut vcom = Vector3::zeros();
    for k in 0..2 {
        let mk = model.legs[k].mass_kg;
        let r = kin.com_offset_w[k];
        com += (s.hip_position_m + r) * mk;
        vcom += (s.hip_velocity_mps + kin.omega_w[k].cross(&r)) * mk;
    }
    tr.t.push(sim.time_s);
    tr.hip.push(s.hip_position_m);
    tr.roll_deg.push(roll.to_degrees());
    tr.hip_angle_rad.push(s.hip_angle_rad);
    tr.omega_left_w.push(kin.omega_w[0]);
    tr.com.push(com / m);
    tr.vcom.push(vcom / m);
    tr.normal_n.push(normal);
    tr.feet.push(feet);
    tr.torque_nm.push(torque);
}

/// Runs a case in the project's engine and records every step.
fn run_trace(design: &Design, case: &Case) -> Result<(Trace, Design), CrosscheckError> {
    let mut d = design.clone();
    let controller = match case.drive.as_str() {
        "design" => d.controller(),
        "hold" => {
            match &mut d.control {
                crate::sim::design::ControlSpec::ServoSine { amplitude_deg, .. } => {
                    *amplitude_deg = 0.0
                }
                _ => {
                    return Err(CrosscheckError::Invalid {
                        path: PathBuf::from(&case.design),
                        message: "drive = \"hold\" needs a servo_sine design".into(),
                    });
                }
            }
            d.controller()
        }
        "passive" => Controller::Passive,
        other => {
            return Err(CrosscheckError::Invalid {
                path: PathBuf::from(&case.design),
                message: format!("unknown drive `{other}` (design, hold or passive)"),
            });
        }
    };
    let mut model = d.model();
    model.ground_contact = case.ground_contact;
    let slope = d.ground.slope_deg.to_radians();
    model.gravity_mps2 = Vector3::new(slope.sin(), 0.0, -slope.cos()) * case.gravity_mps2;
    let init = &case.initial;
    let orientation = UnitQuaternion::from_euler_angles(
        init.roll_deg.to_radians(),
        init.pitch_deg.to_radians(),
        init.yaw_deg.to_radians(),
    );
    let r = *orientation.to_rotation_matrix().matrix();
    let mut hip_z = model.touch_height_m(&r);
    let e = model.contact.modulus_pa;
    match init.placement.as_str() {
        "design" => hip_z -= model.single_foot_sinkage_m(),
        "static" => {
            let semi = model.legs[0].foot_semi_axes_m;
            let load = model.total_mass_kg() * model.gravity_mps2.z.abs() / 2.0;
            hip_z -= upright_sinkage_m(e, [semi.x, semi.y, semi.z], load);
        }
        "touch" => {}
        other => {
            return Err(CrosscheckError::Invalid {
                path: PathBuf::from(&case.design),
                message: format!("unknown placement `{other}` (design, touch or static)"),
            });
        }
    }
    let v = init.linear_velocity_mps;
    let w = init.angular_velocity_rad_s;
    let state = State {
        hip_position_m: Vector3::new(0.0, 0.0, hip_z),
        orientation,
        hip_angle_rad: 0.0,
        hip_velocity_mps: Vector3::new(v[0], v[1], v[2]),
        angular_velocity_rad_s: Vector3::new(w[0], w[1], w[2]),
        hip_rate_rad_s: 0.0,
    };
    let effects = d.effects.iter().filter_map(|e| e.build()).collect();
    let dt = d.numerics.time_step_s;
    let mut sim = Simulator::new(model, controller, effects, state, dt);
    let mut tr = Trace::default();
    record(&mut tr, &sim, [0.0, 0.0], 0, 0.0);
    let n = (case.duration_s / dt).round() as usize;
    for _ in 0..n {
        let info = sim.step();
        if !sim.state.is_finite() {
            return Err(SimError::Diverged { time_s: sim.time_s }.into());
        }
        record(
            &mut tr,
            &sim,
            info.normal_force_n,
            info.feet_in_contact,
            info.actuator_torque_nm,
        );
    }
    Ok((tr, d))
}

fn zero_crossings(t: &[f64], y: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for i in 1..y.len() {
        if (y[i - 1] > 0.0) != (y[i] > 0.0) && y[i - 1] != y[i] {
            out.push(t[i - 1] + (t[i] - t[i - 1]) * (0.0 - y[i - 1]) / (y[i] - y[i - 1]));
        }
    }
    out
}

/// Local maxima > 0, refined by a parabola through the 3 samples around each.
fn positive_peaks(t: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let mut pk = Vec::new();
    for i in 1..y.len().saturating_sub(1) {
        if y[i] > 0.0 && y[i] >= y[i - 1] && y[i] > y[i + 1] {
            let (a, b, c) = (y[i - 1], y[i], y[i + 1]);
            let den = a - 2.0 * b + c;
            let off = if den != 0.0 { 0.5 * (a - c) / den } else { 0.0 };
            pk.push((t[i] + off * (t[i + 1] - t[i]), b - 0.25 * (a - c) * off));
        }
    }
    pk
}

/// Least-squares slope of y on t.
fn line_slope(t: &[f64], y: &[f64]) -> Option<f64> {
    let n = t.len() as f64;
    if t.len() < 2 {
        return None;
    }
    let (mt, my) = (t.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = t.iter().zip(y).map(|(a, b)| (a - mt) * (b - my)).sum();
    let sxx: f64 = t.iter().map(|a| (a - mt) * (a - mt)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

fn first_below(t: &[f64], y: &[f64], level: f64) -> Option<f64> {
    for i in 1..y.len() {
        if (y[i] <= level && level < y[i - 1]) || (y[i] <= level && i == 1 && y[0] <= level) {
            if y[i - 1] == y[i] {
                return Some(t[i]);
            }
            return Some(t[i - 1] + (t[i] - t[i - 1]) * (y[i - 1] - level) / (y[i - 1] - y[i]));
        }
    }
    None
}

fn interp_at(t: &[f64], y: &[f64], tq: f64) -> f64 {
    let i = t.partition_point(|&x| x < tq);
    if i == 0 {
        return y[0];
    }
    if i >= t.len() {
        return y[y.len() - 1];
    }
    let f = (tq - t[i - 1]) / (t[i] - t[i - 1]);
    y[i - 1] + f * (y[i] - y[i - 1])
}

/// Least squares of x on (1, t, t²/2): the acceleration.
fn quadratic_acceleration(t: &[f64], x: &[f64]) -> Option<f64> {
    let n = t.len();
    if n < 3 {
        return None;
    }
    let mut a = nalgebra::DMatrix::<f64>::zeros(n, 3);
    for (i, &ti) in t.iter().enumerate() {
        a[(i, 0)] = 1.0;
        a[(i, 1)] = ti;
        a[(i, 2)] = 0.5 * ti * ti;
    }
    let b = nalgebra::DVector::from_column_slice(x);
    a.svd(true, true).solve(&b, 1e-14).ok().map(|s| s[2])
}

/// Amplitude, phase lag and offset of q ≈ a·sin(wt) + b·cos(wt) + c.
fn fit_sine(t: &[f64], q: &[f64], w: f64) -> Option<(f64, f64, f64)> {
    let n = t.len();
    let mut a = nalgebra::DMatrix::<f64>::zeros(n, 3);
    for (i, &ti) in t.iter().enumerate() {
        a[(i, 0)] = (w * ti).sin();
        a[(i, 1)] = (w * ti).cos();
        a[(i, 2)] = 1.0;
    }
    let b = nalgebra::DVector::from_column_slice(q);
    let s = a.svd(true, true).solve(&b, 1e-14).ok()?;
    Some(((s[0] * s[0] + s[1] * s[1]).sqrt(), -s[1].atan2(s[0]), s[2]))
}

fn window(t: &[f64], lo: f64, hi: f64) -> std::ops::Range<usize> {
    let i0 = t.partition_point(|&x| x < lo - 1e-12);
    let i1 = t.partition_point(|&x| x <= hi + 1e-12);
    i0..i1
}

/// Measured quantities of one case (the names of cases.toml `measure`, plus a few extra
/// diagnostics); `None` where a quantity is undefined (e.g. never stopped).
pub type Measured = BTreeMap<String, Option<f64>>;

/// The cases the project knows how to measure (by their name in cases.toml).
#[derive(Clone, Copy, Debug, PartialEq)]
enum CaseKind {
    /// Any case whose name starts with `sinkage`.
    Sinkage,
    FreeRocking,
    RollingIncline,
    SpinDown,
    Slide,
    Creep,
    ServoInAir,
}

impl CaseKind {
    fn of(name: &str) -> Option<CaseKind> {
        Some(match name {
            n if n.starts_with("sinkage") => CaseKind::Sinkage,
            "free_rocking" => CaseKind::FreeRocking,
            "rolling_incline" => CaseKind::RollingIncline,
            "spin_down" => CaseKind::SpinDown,
            "slide" => CaseKind::Slide,
            "creep" => CaseKind::Creep,
            "servo_in_air" => CaseKind::ServoInAir,
            _ => return None,
        })
    }
}

/// The case with the project's convex friction cone (`contact.friction_cone = "convex"`,
/// the relaxation Drake's SAP and `similar` solve with) in place of Coulomb friction.
pub fn with_convex_cone(case: &Case) -> Case {
    let mut c = case.clone();
    c.overrides.insert(
        "contact.friction_cone".to_string(),
        toml::Value::String("convex".to_string()),
    );
    c
}

/// Runs a case in the project's engine and measures it as the Drake harness does.
pub fn run_case(root: &Path, name: &str, case: &Case) -> Result<Measured, CrosscheckError> {
    let design = case_design(root, case)?;
    let (tr, d) = run_trace(&design, case)?;
    let unknown = || CrosscheckError::Invalid {
        path: PathBuf::from("cases.toml"),
        message: format!("case `{name}`: no measurement defined for it in the project"),
    };
    let mut m = Measured::new();
    let mut put = |k: &str, v: Option<f64>| {
        m.insert(k.to_string(), v);
    };
    match CaseKind::of(name).ok_or_else(unknown)? {
        CaseKind::Sinkage => measure_sinkage(&tr, &mut put),
        CaseKind::FreeRocking => measure_free_rocking(&tr, &mut put),
        CaseKind::RollingIncline => measure_rolling_incline(&tr, &d, &mut put),
        CaseKind::SpinDown => measure_spin_down(&tr, case, &mut put),
        CaseKind::Slide => measure_slide(&tr, case, &mut put),
        CaseKind::Creep => measure_creep(&tr, &mut put),
        CaseKind::ServoInAir => measure_servo_in_air(&tr, &d, &mut put).ok_or_else(unknown)?,
    }
    Ok(m)
}

/// Where each measurement goes: a quantity's name and value.
type Put<'a> = dyn FnMut(&str, Option<f64>) + 'a;

/// Sinkage: hip height lost, normal forces and feet in contact over the last 0.2 s.
fn measure_sinkage(tr: &Trace, put: &mut Put) {
    let t = &tr.t;
    let w = window(t, t[t.len() - 1] - 0.2, f64::INFINITY);
    let n = w.len() as f64;
    let z0 = tr.hip[0].z;
    let z_end = tr.hip[w.clone()].iter().map(|p| p.z).sum::<f64>() / n;
    put("sinkage_m", Some(z0 - z_end));
    put(
        "left_normal_force_n",
        Some(tr.normal_n[w.clone()].iter().map(|f| f[0]).sum::<f64>() / n),
    );
    put(
        "right_normal_force_n",
        Some(tr.normal_n[w.clone()].iter().map(|f| f[1]).sum::<f64>() / n),
    );
    put(
        "feet_in_contact",
        Some((tr.feet[w].iter().map(|&f| f as f64).sum::<f64>() / n).round()),
    );
}

/// Free rocking: roll period (mean of up to seven full periods between zero crossings),
/// decay per cycle over four peaks, time with both feet down.
fn measure_free_rocking(tr: &Trace, put: &mut Put) {
    let t = &tr.t;
    let zc = zero_crossings(t, &tr.roll_deg);
    let mut pk = vec![(0.0, tr.roll_deg[0])];
    pk.extend(positive_peaks(t, &tr.roll_deg));
    let period = if zc.len() >= 9 {
        Some((0..7).map(|k| zc[k + 2] - zc[k]).sum::<f64>() / 7.0)
    } else if zc.len() >= 3 {
        Some((0..zc.len() - 2).map(|k| zc[k + 2] - zc[k]).sum::<f64>() / (zc.len() - 2) as f64)
    } else {
        None
    };
    put("roll_period_s", period);
    put(
        "roll_decay_ratio_per_cycle",
        (pk.len() >= 5).then(|| (pk[4].1 / pk[0].1).powf(0.25)),
    );
    put(
        "both_feet_in_contact_fraction",
        Some(tr.feet[1..].iter().filter(|&&f| f == 2).count() as f64 / (t.len() - 1) as f64),
    );
}

/// Rolling down an incline: centre-of-mass acceleration (quadratic fits, whole and early),
/// velocity and slip at the end.
fn measure_rolling_incline(tr: &Trace, d: &Design, put: &mut Put) {
    let t = &tr.t;
    let x: Vec<f64> = tr.com.iter().map(|c| c.x).collect();
    for (key, lo, hi) in [
        ("com_acceleration_mps2", 0.05, 1.0),
        ("com_acceleration_early_mps2", 0.05, 0.25),
    ] {
        let w = window(t, lo, hi);
        put(key, quadratic_acceleration(&t[w.clone()], &x[w]));
    }
    let r = d.geometry.foot_semi_axes_m[2];
    let last = t.len() - 1;
    put("com_velocity_at_end_mps", Some(tr.vcom[last].x));
    put(
        "slip_velocity_at_end_mps",
        Some(tr.vcom[last].x - tr.omega_left_w[last].y * r),
    );
}

/// Spin-down: yaw deceleration fitted between 90 % and 10 % of the initial rate, the
/// time to 1 %, the rate at the end.
fn measure_spin_down(tr: &Trace, case: &Case, put: &mut Put) {
    let t = &tr.t;
    let wz: Vec<f64> = tr.omega_left_w.iter().map(|w| w.z).collect();
    let w0 = case.initial.angular_velocity_rad_s[2];
    let (ts, ys): (Vec<f64>, Vec<f64>) = t
        .iter()
        .zip(&wz)
        .filter(|&(&ti, &y)| ti > 0.0 && y >= 0.1 * w0 && y <= 0.9 * w0)
        .map(|(&a, &b)| (a, b))
        .unzip();
    put("yaw_deceleration_rad_s2", line_slope(&ts, &ys).map(|s| -s));
    put("stop_time_s", first_below(t, &wz, 0.01 * w0));
    put("yaw_rate_at_end_rad_s", Some(wz[wz.len() - 1]));
}

/// Sliding to a stop: stop time and distance, deceleration three ways, hops and the
/// airborne fraction while sliding.
fn measure_slide(tr: &Trace, case: &Case, put: &mut Put) {
    let t = &tr.t;
    let v: Vec<f64> = tr.vcom.iter().map(|c| c.x).collect();
    let x: Vec<f64> = tr.com.iter().map(|c| c.x).collect();
    let v0 = case.initial.linear_velocity_mps[0];
    let (ts, ys): (Vec<f64>, Vec<f64>) = t
        .iter()
        .zip(&v)
        .filter(|&(&ti, &y)| ti > 0.0 && y >= 0.1 * v0 && y <= 0.9 * v0)
        .map(|(&a, &b)| (a, b))
        .unzip();
    let stop = first_below(t, &v, 0.01 * v0);
    let distance = stop.map(|ts| interp_at(t, &x, ts) - x[0]);
    put("stop_time_s", stop);
    put("stopping_distance_m", distance);
    put("deceleration_mps2", stop.map(|ts| v0 / ts));
    put(
        "deceleration_from_distance_mps2",
        distance.map(|d| v0 * v0 / (2.0 * d)),
    );
    put(
        "deceleration_linefit_mps2",
        line_slope(&ts, &ys).map(|s| -s),
    );
    let z0 = tr.hip[0].z;
    put(
        "max_hop_height_m",
        Some(
            tr.hip
                .iter()
                .map(|p| p.z - z0)
                .fold(f64::NEG_INFINITY, f64::max),
        ),
    );
    put(
        "airborne_fraction_while_sliding",
        stop.map(|ts| {
            let k = t[1..].iter().filter(|&&ti| ti < ts).count();
            let air = t[1..]
                .iter()
                .zip(&tr.feet[1..])
                .filter(|&(&ti, &f)| ti < ts && f == 0)
                .count();
            air as f64 / k.max(1) as f64
        }),
    );
    put("velocity_at_end_mps", Some(v[v.len() - 1]));
}

/// Creep: speed between 0.5 s and 1 s, at the end, and the displacement.
fn measure_creep(tr: &Trace, put: &mut Put) {
    let t = &tr.t;
    let x: Vec<f64> = tr.com.iter().map(|c| c.x).collect();
    put(
        "creep_speed_mps",
        Some((interp_at(t, &x, 1.0) - interp_at(t, &x, 0.5)) / 0.5),
    );
    put("creep_speed_at_end_mps", Some(tr.vcom[tr.vcom.len() - 1].x));
    put("displacement_m", Some(x[x.len() - 1] - x[0]));
}

/// A servo driving the legs in the air: a sine fitted to the hip angle over 2–3 s
/// (amplitude, ratio, phase lag) and the peak torque. `None` when the design is not
/// servo-driven (then the case has no measurement).
fn measure_servo_in_air(tr: &Trace, d: &Design, put: &mut Put) -> Option<()> {
    let t = &tr.t;
    let (amp_rad, freq) = match d.control {
        crate::sim::design::ControlSpec::ServoSine {
            amplitude_deg,
            frequency_hz,
            ..
        } => (amplitude_deg.to_radians(), frequency_hz),
        _ => return None,
    };
    let w = window(t, 2.0, 3.0);
    let fit = fit_sine(
        &t[w.clone()],
        &tr.hip_angle_rad[w.clone()],
        std::f64::consts::TAU * freq,
    );
    put("amplitude_deg", fit.map(|f| f.0.to_degrees()));
    put("amplitude_ratio", fit.map(|f| f.0 / amp_rad));
    put("phase_lag_deg", fit.map(|f| f.1.to_degrees()));
    put(
        "peak_abs_torque_nm_last_second",
        Some(tr.torque_nm[w].iter().fold(0.0, |a: f64, b| a.max(b.abs()))),
    );
    Some(())
}

/// A walk compared in both engines: the same design TOML and options.
#[derive(Clone, Debug, Serialize)]
pub struct WalkComparison {
    /// Golden file stem (tests/golden/drake/walks/STEM.csv).
    pub name: String,
    pub design: String,
    pub leg_length_m: f64,
    pub drive_frequency_hz: f64,
    /// Drake's discrete contact approximation for this walk (sap, similar, lagged).
    pub drake_approximation: Option<String>,
    /// The project's walk.
    pub project: WalkReport,
    /// The project's walk with the convex friction cone (`friction_cone = "convex"`), for
    /// a golden whose Drake approximation is convex (SAP, `similar`); `None` for `lagged`.
    pub project_convex: Option<WalkReport>,
    /// Drake's trajectory measured by the project's gait metrics.
    pub drake: WalkReport,
    /// MuJoCo's walk of the design's MJCF export (`tests/golden/mujoco/walks/` under the
    /// same stem), measured by the same code; None where there is none.
    pub mujoco: Option<WalkReport>,
}

/// A MuJoCo walk golden without a Drake twin (the bundled designs, whose section-cut feet
/// Drake's harness refuses): the project's walk, with both friction cones, beside MuJoCo's.
#[derive(Clone, Debug, Serialize)]
pub struct PeerWalk {
    pub name: String,
    pub design: String,
    pub leg_length_m: f64,
    pub drive_frequency_hz: f64,
    pub project: WalkReport,
    pub project_convex: WalkReport,
    pub mujoco: WalkReport,
}

/// The options a Drake walk golden was run with (walks/STEM.json `options`).
#[derive(Clone, Debug, Deserialize)]
pub struct WalkGoldenOptions {
    #[serde(default)]
    pub leg_length_m: Option<f64>,
    #[serde(default)]
    pub mass_law: Option<String>,
    #[serde(default)]
    pub frequency_hz: Option<f64>,
    #[serde(default)]
    pub duration_s: Option<f64>,
    /// Relaxation time and time step multiplied by these (sensitivity variants).
    #[serde(default = "one")]
    pub relaxation_scale: f64,
    #[serde(default = "one")]
    pub time_step_scale: f64,
    /// Initial roll of the run [deg] (None: the design's).
    #[serde(default)]
    pub initial_roll_deg: Option<f64>,
}

fn one() -> f64 {
    1.0
}

/// Drake's engine settings of a walk golden (walks/STEM.json `engine`).
#[derive(Clone, Debug, Deserialize)]
pub struct WalkGoldenEngine {
    /// "sap", "similar", "lagged" or "tamsi".
    #[serde(default)]
    pub discrete_contact_approximation: Option<String>,
}

/// How a Drake walk golden was made (walks/STEM.json, written by the harness).
#[derive(Clone, Debug, Deserialize)]
pub struct WalkGoldenMeta {
    pub design_file: String,
    pub options: WalkGoldenOptions,
    #[serde(default)]
    pub engine: Option<WalkGoldenEngine>,
}

/// A Drake walk golden, read: the design and options it was run with, and Drake's
/// trajectory measured by the project's gait metrics.
pub struct WalkGolden {
    pub meta: WalkGoldenMeta,
    /// The design with the golden's relaxation-time, time-step and initial-roll changes.
    pub design: Design,
    pub options: WalkOptions,
    /// Drake's trajectory (STEM.csv) measured by [`report_from_trajectory`].
    pub drake: WalkReport,
}

/// Reads a Drake walk golden (STEM.json + STEM.csv) and measures its trajectory.
pub fn read_walk_golden(root: &Path, json_path: &Path) -> Result<WalkGolden, CrosscheckError> {
    let text = read(json_path)?;
    let meta: WalkGoldenMeta =
        serde_json::from_str(&text).map_err(|e| CrosscheckError::Invalid {
            path: json_path.to_path_buf(),
            message: e.to_string(),
        })?;
    let design_path = root.join(&meta.design_file);
    let mut design = if design_path.exists() {
        Design::from_file(&design_path)?
    } else {
        Design::resolve(&meta.design_file)?
    };
    let o = &meta.options;
    design.contact.relaxation_time_s *= o.relaxation_scale;
    design.numerics.time_step_s *= o.time_step_scale;
    if let Some(roll) = o.initial_roll_deg {
        design.initial.roll_deg = roll;
    }
    let mass_law = match o.mass_law.as_deref() {
        None | Some("l2") => crate::sim::MassLaw::L2,
        Some("l3") => crate::sim::MassLaw::L3,
        Some(other) => {
            return Err(CrosscheckError::Invalid {
                path: json_path.to_path_buf(),
                message: format!("options.mass_law `{other}` (l2 or l3)"),
            });
        }
    };
    let options = WalkOptions {
        leg_length_m: o.leg_length_m,
        mass_law,
        frequency_hz: o.frequency_hz,
        duration_s: o.duration_s.unwrap_or(25.0),
        record_trajectory: false,
        ..WalkOptions::default()
    };
    let samples = read_trajectory_csv(&json_path.with_extension("csv"))?;
    let drake = report_from_trajectory(&design, &options, &samples)?;
    Ok(WalkGolden {
        meta,
        design,
        options,
        drake,
    })
}

/// Runs the project's walk for a Drake walk golden (STEM.json + STEM.csv) and measures
/// both with the project's metrics.
pub fn compare_walk(root: &Path, json_path: &Path) -> Result<WalkComparison, CrosscheckError> {
    let g = read_walk_golden(root, json_path)?;
    let project = simulate_walk(&g.design, &g.options)?.report;
    let approximation = g
        .meta
        .engine
        .as_ref()
        .and_then(|e| e.discrete_contact_approximation.clone());
    // The harness's default approximation is SAP (convex); only `lagged` and `tamsi`
    // keep Coulomb friction.
    let convex = !matches!(approximation.as_deref(), Some("lagged") | Some("tamsi"));
    let project_convex = if convex {
        let mut d = g.design.clone();
        d.contact.friction_cone = FrictionCone::Convex;
        Some(simulate_walk(&d, &g.options)?.report)
    } else {
        None
    };
    Ok(WalkComparison {
        name: json_path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        design: g.meta.design_file,
        drake_approximation: approximation,
        leg_length_m: project.leg_length_m,
        drive_frequency_hz: project.drive_frequency_hz,
        project,
        project_convex,
        drake: g.drake,
        mujoco: None,
    })
}

/// The project's walk beside a MuJoCo walk golden (STEM.json + STEM.csv, written by
/// `tools/mujoco/harness.py`, the same JSON fields as Drake's).
pub fn compare_peer_walk(root: &Path, json_path: &Path) -> Result<PeerWalk, CrosscheckError> {
    let g = read_walk_golden(root, json_path)?;
    let project = simulate_walk(&g.design, &g.options)?.report;
    let mut d = g.design.clone();
    d.contact.friction_cone = FrictionCone::Convex;
    let project_convex = simulate_walk(&d, &g.options)?.report;
    Ok(PeerWalk {
        name: stem_of(json_path),
        design: g.meta.design_file,
        leg_length_m: project.leg_length_m,
        drive_frequency_hz: project.drive_frequency_hz,
        project,
        project_convex,
        mujoco: g.drake,
    })
}

fn stem_of(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The walk goldens of a folder (STEM.json with a STEM.csv beside it), sorted.
fn walk_goldens(dir: &Path) -> Result<Vec<PathBuf>, CrosscheckError> {
    if !dir.is_dir() {
        return Ok(Vec::new());
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| CrosscheckError::Read {
            path: dir.to_path_buf(),
            message: e.to_string(),
        })?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "json") && p.with_extension("csv").exists())
        .collect();
    files.sort();
    Ok(files)
}

/// One measured quantity of an elementary case in both engines and, where one exists,
/// its analytic value.
#[derive(Clone, Debug, Serialize)]
pub struct QuantityRow {
    pub case: String,
    pub quantity: String,
    pub project: Option<f64>,
    /// The project with the convex friction cone ([`with_convex_cone`]).
    pub project_convex: Option<f64>,
    pub drake: Option<f64>,
    pub analytic: Option<f64>,
}

impl QuantityRow {
    /// (project − Drake)/|Drake|.
    pub fn relative_difference(&self) -> Option<f64> {
        relative(self.project, self.drake)
    }

    /// (project with the convex cone − Drake)/|Drake|.
    pub fn convex_relative_difference(&self) -> Option<f64> {
        relative(self.project_convex, self.drake)
    }
}

fn relative(ours: Option<f64>, drake: Option<f64>) -> Option<f64> {
    match (ours, drake) {
        (Some(p), Some(d)) if d != 0.0 => Some((p - d) / d.abs()),
        _ => None,
    }
}

/// The whole cross-check: every elementary case and every walk golden.
#[derive(Clone, Debug, Serialize)]
pub struct Crosscheck {
    pub drake_version: Option<String>,
    pub mujoco_version: Option<String>,
    pub elementary: Vec<QuantityRow>,
    pub walks: Vec<WalkComparison>,
    /// MuJoCo walks of designs without a Drake golden.
    pub mujoco_walks: Vec<PeerWalk>,
}

fn number(v: Option<&serde_json::Value>) -> Option<f64> {
    v.and_then(serde_json::Value::as_f64)
}

/// Runs the project's side of every case in `golden/cases.toml` and every walk in
/// `golden/walks/*.json`, beside Drake's and the analytic values from
/// `golden/elementary.json`, and every MuJoCo walk golden of `mujoco/walks/` (beside the
/// Drake walk of the same stem, or on its own). `root` is the repository (design paths are
/// relative to it); `progress` hears a stage ("running NAME") as each case or walk begins.
pub fn run(
    root: &Path,
    golden: &Path,
    mujoco: Option<&Path>,
    progress: &dyn Observer,
) -> Result<Crosscheck, CrosscheckError> {
    let cases = load_cases(&golden.join("cases.toml"))?;
    let elementary_path = golden.join("elementary.json");
    let drake: serde_json::Value = if elementary_path.exists() {
        serde_json::from_str(&read(&elementary_path)?).map_err(|e| CrosscheckError::Invalid {
            path: elementary_path.clone(),
            message: e.to_string(),
        })?
    } else {
        serde_json::Value::Null
    };
    let mut rows = Vec::new();
    for (name, case) in &cases {
        progress.stage(&format!("running {name}"));
        let ours = run_case(root, name, case)?;
        let convex = run_case(root, name, &with_convex_cone(case))?;
        let theirs = &drake["cases"][name.as_str()];
        for (q, v) in &ours {
            rows.push(QuantityRow {
                case: name.clone(),
                quantity: q.clone(),
                project: *v,
                project_convex: convex.get(q).copied().flatten(),
                drake: number(theirs["measured"].get(q)),
                analytic: number(theirs["analytic"].get(q)),
            });
        }
    }
    let mut walks = Vec::new();
    let mujoco_dir = mujoco.map(|m| m.join("walks"));
    let mujoco_files = match &mujoco_dir {
        Some(d) => walk_goldens(d)?,
        None => Vec::new(),
    };
    for f in walk_goldens(&golden.join("walks"))? {
        progress.stage(&format!("running {}", f.display()));
        let mut w = compare_walk(root, &f)?;
        if let Some(m) = mujoco_files.iter().find(|m| stem_of(m) == w.name) {
            w.mujoco = Some(read_walk_golden(root, m)?.drake);
        }
        walks.push(w);
    }
    let mut mujoco_walks = Vec::new();
    for m in &mujoco_files {
        if walks.iter().any(|w| w.name == stem_of(m)) {
            continue;
        }
        progress.stage(&format!("running {}", m.display()));
        mujoco_walks.push(compare_peer_walk(root, m)?);
    }
    let mujoco_version = mujoco_files
        .first()
        .and_then(|f| std::fs::read_to_string(f).ok())
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v["engine"]["version"].as_str().map(str::to_string));
    Ok(Crosscheck {
        drake_version: drake["drake_version"].as_str().map(str::to_string),
        mujoco_version,
        elementary: rows,
        walks,
        mujoco_walks,
    })
}
