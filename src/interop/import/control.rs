//! The import's `[control]`, `[hardstop]` and hip effects: the drive from the hip's
//! actuator (else the reference servo, limited by the joint's declared effort), the stop
//! from the hip's range, its damping and friction.

use super::{Builder, defaults, effect_table, from_file};
use crate::interop::InteropError;
use crate::interop::legs::{LegRead, WalkerFrame};
use crate::interop::robot_file::{Actuator, Body, Joint};
use crate::sim::{EffectSpec, GRAVITY_MPS2};
/// The free roll rocking frequency [Hz] of the walker on its feet with the legs together:
/// ω² = m·g·(R − h)/(I + m·h²), R the feet's lateral radius of curvature R_Y²/R_Z, h the COM
/// height (a rigid rocker, ../shared/research/walkers.md §4.3); None when not a rocker.
fn rocking_hz(legs: &[LegRead; 2], l: f64) -> Option<f64> {
    let m = legs[0].mass.mass_kg + legs[1].mass.mass_kg;
    let semi = 0.5 * (legs[0].foot_semi + legs[1].foot_semi);
    let r = semi.y * semi.y / semi.z;
    let both = legs[0].mass.combined(&legs[1].mass);
    let h = l + both.com_m.z;
    let i = both.inertia_com_kgm2[(0, 0)];
    let w2 = m * GRAVITY_MPS2 * (r - h) / (i + m * h * h);
    (w2 > 0.0).then(|| w2.sqrt() / std::f64::consts::TAU)
}

/// The scales the control's values are given in (m·g·L, √(L/g)) and the drive frequency
/// the file lacks, with why.
struct Scales {
    mgl: f64,
    tl: f64,
    f_drive: f64,
    why: String,
}

/// The default drive frequency: 0.97 × the free roll rocking frequency, else √(g/L)/2π;
/// with the reason given as its source.
fn drive_frequency(legs: &[LegRead; 2], l: f64) -> (f64, String) {
    match rocking_hz(legs, l) {
        Some(fr) => (
            defaults::DRIVE_OVER_ROCKING * fr,
            format!(
                "0.97 × the free roll rocking frequency {fr:.3} Hz of this walker (the bundled designs' rule)"
            ),
        ),
        None => (
            ((GRAVITY_MPS2 / l).sqrt()) / std::f64::consts::TAU,
            "√(g/L)/2π: the feet are no rocker under this COM".to_string(),
        ),
    }
}

/// `[control]` and the hip: the drive from the hip's actuator (else the reference servo),
/// the stop from its range, its damping and friction as effects.
pub(super) fn control(
    b: &mut Builder,
    legs: &[LegRead; 2],
    l: f64,
    m: f64,
    wf: &WalkerFrame,
) -> Result<(), InteropError> {
    let f = b.f;
    let (f_drive, why) = drive_frequency(legs, l);
    let s = Scales {
        mgl: m * GRAVITY_MPS2 * l,
        tl: (l / GRAVITY_MPS2).sqrt(),
        f_drive,
        why,
    };
    let hinge = f
        .bodies
        .iter()
        .find(|x| matches!(x.joint, Joint::Hinge { .. }));
    let hip_name = hinge.map(|h| h.joint_name.clone()).unwrap_or_default();
    let act = f.actuators.iter().find(|a| match a {
        Actuator::Position { joint, .. } | Actuator::Torque { joint, .. } => *joint == hip_name,
    });
    let effort = match hinge.map(|h| &h.joint) {
        Some(Joint::Hinge { effort_limit, .. }) => *effort_limit,
        _ => None,
    };
    let joint_how = match f.format {
        "URDF" => "the hip joint's `<limit effort>`",
        "SDF" => "the hip joint's `<limit><effort>`",
        _ => "the hip joint's `actuatorfrcrange`",
    };
    // The torque the hip gets: the actuator's limit and the joint's, the smaller binding.
    let limit = |actuator: Option<f64>| -> Option<(f64, String)> {
        match (actuator, effort) {
            (Some(a), Some(e)) if e < a => Some((e, format!("{joint_how} (the actuator's {a} N·m is larger)"))),
            (Some(a), _) => Some((
                a,
                "the actuator's largest torque (its force range, else its control range × gain; × its gear)".to_string(),
            )),
            (None, Some(e)) => Some((e, joint_how.to_string())),
            (None, None) => None,
        }
    };
    match act {
        Some(Actuator::Position {
            kp,
            kv,
            force_limit,
            ..
        }) => servo_from_file(b, &s, *kp, *kv, limit(*force_limit)),
        Some(Actuator::Torque {
            limit: torque,
            velocity_damping,
            ..
        }) => bang_bang_from_file(b, &s, limit(*torque), *velocity_damping),
        None => servo_by_default(b, &s, limit(None)),
    }
    if let Some(Body {
        joint:
            Joint::Hinge {
                range,
                damping,
                frictionloss,
                solreflimit,
                ..
            },
        ..
    }) = hinge
    {
        if let Some(range) = range {
            hardstop(b, legs, &s, wf, *range, *solreflimit);
        }
        hip_effects(b, l, *damping, *frictionloss);
    }
    Ok(())
}

/// A servo from the hip's position actuator: its gains and force range (the drive's
/// amplitude and frequency are defaults).
fn servo_from_file(
    b: &mut Builder,
    s: &Scales,
    kp: f64,
    kv: f64,
    force_limit: Option<(f64, String)>,
) {
    let f = b.f;
    b.put(
        "control.kind",
        "servo_sine",
        from_file(f, "the hip's position actuator"),
    );
    b.default(
        "control.amplitude_deg",
        defaults::AMPLITUDE_DEG,
        "the reference set's servo amplitude",
    );
    b.default("control.frequency_hz", s.f_drive, &s.why);
    b.file(
        "control.kp_over_mgl",
        kp / s.mgl,
        &format!("the position actuator's kp = {kp} N·m/rad"),
    );
    b.file(
        "control.kd_over_mgl_sqrt_l_over_g",
        kv / (s.mgl * s.tl),
        &format!("the position actuator's kv = {kv} N·m·s/rad"),
    );
    servo_torque_limit(b, s, force_limit);
}

/// A bang-bang drive from the hip's torque actuator: its force range as the torque, its
/// velocity bias as the motor's torque–speed line.
fn bang_bang_from_file(
    b: &mut Builder,
    s: &Scales,
    limit: Option<(f64, String)>,
    velocity_damping: f64,
) {
    let f = b.f;
    b.put(
        "control.kind",
        "bang_bang",
        from_file(
            f,
            "the hip's torque actuator (driven bang-bang against the stops)",
        ),
    );
    torque_from(
        b,
        "control.torque_nm",
        limit,
        defaults::BANG_BANG_TORQUE_OVER_MGL * s.mgl,
        "the reference set's 0.66 m·g·L",
    );
    b.default("control.frequency_hz", s.f_drive, &s.why);
    if velocity_damping > 0.0 {
        let tau = b.num("control.torque_nm").unwrap_or(0.0);
        b.notes.push(format!("the actuator's velocity bias {velocity_damping} N·m·s/rad is a motor torque–speed line: no-load speed {:.3} rad/s", tau / velocity_damping));
        b.put(
            "effects",
            toml::Value::Array(vec![effect_table(&EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s: tau / velocity_damping,
            })]),
            from_file(
                f,
                "the actuator's velocity bias, as the motor torque–speed line",
            ),
        );
    }
}

/// The reference set's servo, for a file with no actuator on the hip: limited by the hip
/// joint's declared effort when it has one.
fn servo_by_default(b: &mut Builder, s: &Scales, limit: Option<(f64, String)>) {
    b.default(
        "control.kind",
        "servo_sine",
        "the file has no actuator on the hip",
    );
    b.default(
        "control.amplitude_deg",
        defaults::AMPLITUDE_DEG,
        "the reference set's servo amplitude",
    );
    b.default("control.frequency_hz", s.f_drive, &s.why);
    b.default(
        "control.kp_over_mgl",
        defaults::KP_OVER_MGL,
        "the reference set's stiff position servo",
    );
    b.default(
        "control.kd_over_mgl_sqrt_l_over_g",
        defaults::KD_OVER_MGL_SQRT_L_OVER_G,
        "the reference set's servo damping",
    );
    servo_torque_limit(b, s, limit);
}

/// `control.torque_limit_nm`: the file's limit, else the reference set's.
fn servo_torque_limit(b: &mut Builder, s: &Scales, limit: Option<(f64, String)>) {
    torque_from(
        b,
        "control.torque_limit_nm",
        limit,
        defaults::TORQUE_LIMIT_OVER_MGL * s.mgl,
        "the reference set's 0.74 m·g·L",
    );
}

/// A torque at `path`: the file's (with how it was read), else the reference set's `default`.
fn torque_from(b: &mut Builder, path: &str, limit: Option<(f64, String)>, default: f64, why: &str) {
    match limit {
        Some((t, how)) => b.file(path, t, &how),
        None => b.default(path, default, why),
    }
}

/// The hip's stop from its range [lo, hi]: the smaller side as the limit, the spring and
/// damper from the limit's solreflimit (else the defaults).
fn hardstop(
    b: &mut Builder,
    legs: &[LegRead; 2],
    s: &Scales,
    wf: &WalkerFrame,
    [lo, hi]: [f64; 2],
    solreflimit: Option<[f64; 2]>,
) {
    let lim = lo.abs().min(hi.abs());
    b.file("hardstop.limit_deg", lim.to_degrees(), &format!("the hip's range [{:.4}, {:.4}] rad (the smaller side; q's sign follows the walker's y, {} the file's axis)", lo, hi, if wf.axis_sign > 0.0 { "along" } else { "against" }));
    match solreflimit {
        Some([tc, zeta]) if tc > 0.0 && zeta > 0.0 => {
            // Invert the export's matching on the hip's effective inertia.
            let i = hip_inertia(legs);
            let w = 1.0 / (tc * zeta);
            b.file("hardstop.stiffness_over_mgl", i * w * w / s.mgl, &format!("the closest stop spring to the joint limit's solreflimit ({tc}, {zeta}) on the hip's inertia {i:.3e} kg·m²"));
            b.file(
                "hardstop.damping_over_mgl_sqrt_l_over_g",
                2.0 * zeta * w * i / (s.mgl * s.tl),
                "the closest stop damper: the same damping ratio on that inertia",
            );
        }
        _ => {
            b.default(
                "hardstop.stiffness_over_mgl",
                defaults::HARDSTOP_STIFFNESS_OVER_MGL,
                "a stiff stop: 1 m·g·L of torque overshoots 0.6°",
            );
            b.default(
                "hardstop.damping_over_mgl_sqrt_l_over_g",
                defaults::HARDSTOP_DAMPING,
                "a well damped stop",
            );
        }
    }
}

/// The hip joint's damping and friction loss as the design's effects (after any motor
/// line already read).
fn hip_effects(b: &mut Builder, l: f64, damping: f64, frictionloss: f64) {
    let f = b.f;
    let mut effects: Vec<toml::Value> = b
        .entries
        .iter()
        .find(|e| e.path == "effects")
        .and_then(|e| e.value.as_array().cloned())
        .unwrap_or_default();
    if damping > 0.0 {
        effects.push(effect_table(&EffectSpec::HipViscousDamping {
            damping_nms_per_rad: damping,
        }));
    }
    if frictionloss > 0.0 {
        effects.push(effect_table(&EffectSpec::HipCoulombFriction {
            friction_torque_nm: frictionloss,
            stiction_rate_rad_s: 0.05 * (GRAVITY_MPS2 / l).sqrt(),
        }));
        b.notes.push("the hip's friction loss is the design's Coulomb friction, regularised below 0.05·√(g/L) (the effect library's default)".into());
    }
    if !effects.is_empty() {
        b.put(
            "effects",
            toml::Value::Array(effects),
            from_file(
                f,
                "the hip joint's damping / friction and the actuator's velocity bias",
            ),
        );
    }
}

/// The hip coordinate's effective inertia with the legs together (free-floating): the
/// relative rotation about y of two bodies, I₀·I₁/(I₀ + I₁) about their COMs' pivot, a
/// lower bound the export's MuJoCo stop was matched on (the exact value comes from the mass
/// matrix; both give the same timeconst for a design exported by this project).
fn hip_inertia(legs: &[LegRead; 2]) -> f64 {
    let i = |k: usize| {
        let m = &legs[k].mass;
        m.inertia_com_kgm2[(1, 1)] + m.mass_kg * (m.com_m.x * m.com_m.x + m.com_m.z * m.com_m.z)
    };
    let (a, b) = (i(0), i(1));
    a * b / (a + b)
}
