//! A design (scaled or not) as MJCF, URDF or SDF: the two legs with their masses, COMs and
//! inertias, the hip joint with its range and stop, the feet, the servo or motor and the
//! initial state; what a format cannot say goes into MJCF `<custom>` data or a sidecar TOML.

use std::collections::BTreeMap;

use nalgebra::{UnitQuaternion, Vector3};
use serde::Serialize;

use super::mesh::{TriMesh, ellipsoid_section, to_obj};
use super::soft_contact::{IMPEDANCE, SoftContact, soft_contact};
use super::xml::{El, document, num, nums};
use super::{CUSTOM_PREFIX, InteropError};
use crate::sim::design::ControlSpec;
use crate::sim::{Controller, Design, EffectSpec, Leg, Model};

/// A robot description format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// MuJoCo's MJCF (XML).
    Mjcf,
    /// URDF with Drake's extensions (hydroelastic contact, ellipsoids, PD gains).
    Urdf,
    /// SDFormat 1.9 with Drake's extensions.
    Sdf,
}

/// An exported design: the model file, the sidecar (what the format cannot carry), mesh files
/// the model names, and what differs from the design.
#[derive(Clone, Debug)]
pub struct Export {
    pub model: String,
    /// TOML: the design values the format does not carry, the drive and the initial state.
    /// MJCF carries them in `<custom>`, so its sidecar is informational.
    pub sidecar: String,
    /// (file name beside the model, OBJ text): the section-cut feet of URDF/SDF.
    pub meshes: Vec<(String, String)>,
    /// Where the exported model is not the design's, one sentence each.
    pub notes: Vec<String>,
    /// The MuJoCo contact the design maps to (MJCF; reported for the others too).
    pub soft_contact: SoftContact,
}

/// Design values no format carries exactly (they go to MJCF `<custom>` and every sidecar):
/// the pressure-field contact, the drive, the hardstop's spring, the start, the walk
/// criteria. Paths as in `[[uncertain]]`.
const CARRIED_PATHS: [&str; 19] = [
    "geometry.body_length_m",
    "contact.hydroelastic_modulus_pa",
    "contact.hunt_crossley_dissipation_s_per_m",
    "contact.relaxation_time_s",
    "contact.stiction_speed_mps",
    "control.amplitude_deg",
    "control.frequency_hz",
    "control.torque_nm",
    "hardstop.stiffness_over_mgl",
    "hardstop.damping_over_mgl_sqrt_l_over_g",
    "initial.roll_deg",
    "initial.seed_angle_sd_deg",
    "initial.seed_rate_sd_over_sqrt_g_over_l",
    "numerics.time_step_s",
    "criteria.walk_speed_threshold_over_sqrt_gl",
    "criteria.fall_hip_height_over_l",
    "criteria.fall_roll_deg",
    "criteria.fall_pitch_deg",
    "ground.slope_deg",
];

/// The design's text values no format carries: name, drive kind, friction cone, direction.
fn carried_text(d: &Design) -> Vec<(String, String)> {
    let mut out = vec![
        ("name".to_string(), d.name.clone()),
        (
            "control.kind".into(),
            match d.control {
                ControlSpec::ServoSine { .. } => "servo_sine".into(),
                ControlSpec::BangBang { .. } => "bang_bang".into(),
            },
        ),
    ];
    if !d.contact.friction_cone.is_coulomb() {
        out.push(("contact.friction_cone".into(), "convex".into()));
    }
    if !d.criteria.walking_direction.is_forward() {
        out.push(("criteria.walking_direction".into(), "either".into()));
    }
    if !d.effects.is_empty() {
        out.push((
            "effects".into(),
            serde_json::to_string(&d.effects).unwrap_or_default(),
        ));
    }
    out
}

/// The numbers of [`CARRIED_PATHS`] the design has (a servo has no `control.torque_nm`).
fn carried_numbers(d: &Design) -> Vec<(String, f64)> {
    CARRIED_PATHS
        .iter()
        .filter_map(|p| d.value_at(p).ok().map(|v| (p.to_string(), v)))
        .collect()
}

/// What the exporters need from a (scaled) design.
struct Walker<'a> {
    design: &'a Design,
    model: Model,
    controller: Controller,
    /// Base (left leg) pose at the start: hip point and orientation.
    start_position: Vector3<f64>,
    start_orientation: UnitQuaternion<f64>,
    soft: SoftContact,
    /// Effective inertia of the hip coordinate at the start, 1/(M⁻¹)₇₇ [kg·m²].
    hip_inertia_kgm2: f64,
    viscous_nms_per_rad: f64,
    coulomb_nm: f64,
    motor_no_load_rad_s: Option<f64>,
    notes: Vec<String>,
}

impl<'a> Walker<'a> {
    fn new(design: &'a Design) -> Walker<'a> {
        let model = design.model();
        let state = design.initial_state(&model, None);
        let kin = model.kinematics(&state);
        let m = model.mass_matrix(&kin);
        let hip_inertia_kgm2 = m
            .try_inverse()
            .map(|inv| 1.0 / inv[(6, 6)])
            .unwrap_or(f64::NAN);
        let mut w = Walker {
            design,
            controller: design.controller(),
            start_position: state.hip_position_m,
            start_orientation: state.orientation,
            soft: soft_contact(design),
            hip_inertia_kgm2,
            viscous_nms_per_rad: 0.0,
            coulomb_nm: 0.0,
            motor_no_load_rad_s: None,
            notes: Vec::new(),
            model,
        };
        for e in &design.effects {
            match *e {
                EffectSpec::HipViscousDamping {
                    damping_nms_per_rad,
                } => w.viscous_nms_per_rad += damping_nms_per_rad,
                EffectSpec::HipCoulombFriction {
                    friction_torque_nm, ..
                } => {
                    w.coulomb_nm += friction_torque_nm;
                    w.notes.push("hip Coulomb friction is the formats' hard friction loss (the design's is regularised below its stiction rate)".into());
                }
                EffectSpec::MotorTorqueSpeed {
                    no_load_speed_rad_s,
                } => w.motor_no_load_rad_s = Some(no_load_speed_rad_s),
                EffectSpec::FrictionCoefficient { .. } | EffectSpec::SoftGround { .. } => {}
                EffectSpec::RollingResistance { .. }
                | EffectSpec::ActuationLatency { .. }
                | EffectSpec::HipBacklash { .. } => w.notes.push(format!(
                    "effect `{}` has no counterpart in these formats: it is in the custom data / sidecar only",
                    effect_name(e)
                )),
            }
        }
        w
    }

    fn l(&self) -> f64 {
        self.design.geometry.leg_length_m
    }

    fn mu(&self) -> f64 {
        self.model.contact.friction_mu
    }

    /// The servo's (kp, kd, limit) or the bang-bang torque.
    fn servo(&self) -> Option<(f64, f64, f64)> {
        match self.controller {
            Controller::ServoSine {
                kp_nm_per_rad,
                kd_nms_per_rad,
                torque_limit_nm,
                ..
            } => Some((kp_nm_per_rad, kd_nms_per_rad, torque_limit_nm)),
            _ => None,
        }
    }

    fn effort_nm(&self) -> f64 {
        self.controller.torque_limit_nm().unwrap_or(0.0)
    }

    /// The hip's stop as a soft joint limit: (limit, timeconst, dampratio) from the stop's
    /// spring and damper on the hip's effective inertia (the same matching as the feet).
    fn limit(&self) -> Option<(f64, f64, f64)> {
        let h = self.model.hardstop?;
        let i = self.hip_inertia_kgm2;
        let omega = (h.stiffness_nm_per_rad / i).sqrt();
        let zeta = (h.damping_nms_per_rad / (2.0 * (h.stiffness_nm_per_rad * i).sqrt())).max(1e-3);
        Some((h.limit_rad, 1.0 / (zeta * omega), zeta))
    }
}

/// An effect's name as in `dataset/effects/` (its serde tag).
fn effect_name(e: &EffectSpec) -> String {
    toml::Value::try_from(e)
        .ok()
        .and_then(|v| v.get("effect").and_then(|n| n.as_str()).map(str::to_string))
        .unwrap_or_default()
}

/// Exports a (scaled) design. `stem` names the mesh files of section-cut feet
/// (`STEM.left_foot.obj`).
pub fn export(design: &Design, format: Format, stem: &str) -> Result<Export, InteropError> {
    let mut w = Walker::new(design);
    if w.soft.timeconst_clamped && format == Format::Mjcf {
        w.notes.push(format!(
            "the contact's MuJoCo time constant {:.3e} s is below 2·dt = {:.3e} s; MuJoCo uses 2·dt (a softer, slower contact)",
            w.soft.timeconst_s,
            2.0 * design.numerics.time_step_s
        ));
    }
    let mut meshes = Vec::new();
    let model = match format {
        Format::Mjcf => mjcf(&mut w),
        Format::Urdf | Format::Sdf => {
            for (k, leg) in w.model.legs.iter().enumerate() {
                if let Some(m) = section_mesh(leg) {
                    meshes.push((
                        format!("{stem}.{}_foot.obj", LEG_NAMES[k]),
                        to_obj(
                            &m,
                            &format!(
                                "{} {} foot: the section of its ellipsoid (robot-survey export)",
                                design.name, LEG_NAMES[k]
                            ),
                        ),
                    ));
                }
            }
            if format == Format::Urdf {
                urdf(&mut w, &meshes)
            } else {
                sdf(&mut w, &meshes)
            }
        }
    };
    Ok(Export {
        sidecar: sidecar(&w, format),
        model,
        meshes,
        notes: w.notes,
        soft_contact: w.soft,
    })
}

const LEG_NAMES: [&str; 2] = ["left", "right"];

/// A section-cut foot as a convex mesh in its leg's frame (None: a whole ellipsoid).
fn section_mesh(leg: &Leg) -> Option<TriMesh> {
    let s = leg.foot_section?;
    let side = s.normal.y.signum();
    Some(ellipsoid_section(
        &leg.foot_center_m,
        &leg.foot_semi_axes_m,
        side,
        s.offset_m,
    ))
}

fn wxyz(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// The header every export starts with: what made it and what to read about the mapping.
fn header(w: &Walker, format: Format) -> Vec<String> {
    let d = w.design;
    let mut h = vec![
        format!(
            "robot-survey export of design `{}` at L = {} m, m = {} kg ({:?}); `survey sim import` reads it back",
            d.name,
            num(d.geometry.leg_length_m),
            num(d.mass.total_mass_kg),
            format
        ),
        "Frames: x forward, y left, z up; each leg's frame has its origin at the hip point; the right leg turns about +y by the hip angle q".into(),
    ];
    match format {
        Format::Mjcf => h.push(format!(
            "Contact: the closest MuJoCo soft contact to the design's pressure field, not the same law: solref = (1/(zeta*omega), zeta) with omega = {:.1} rad/s, zeta = {:.3} the linearised bounce of the whole weight on one foot; static sinkage {:.3e} m here, {:.3e} m in the design",
            w.soft.frequency_rad_s, w.soft.damping_ratio, w.soft.mujoco_sinkage_m, w.soft.sinkage_m
        )),
        Format::Urdf | Format::Sdf => h.push(
            "Contact: Drake hydroelastic (compliant feet of the design's modulus and dissipation; the ground must be rigid hydroelastic with the same friction)".into(),
        ),
    }
    h
}

/// Whether a foot's semi-axes are all equal (written as a sphere).
fn is_sphere(a: &Vector3<f64>) -> bool {
    a.x == a.y && a.y == a.z
}

/// Adds the soft contact's attributes (condim, friction, solref, solimp) the feet and the
/// ground share.
fn mjcf_contact(w: &Walker, el: El) -> El {
    let s = &w.soft;
    el.attr("condim", "4")
        .attr("friction", nums(&[w.mu(), s.torsional_m, 0.0]))
        .attr("solref", nums(&[s.timeconst_s, s.dampratio]))
        .attr("solimp", nums(&[IMPEDANCE, IMPEDANCE, 0.001, 0.5, 2.0]))
}

/// A leg's foot geom: a section mesh, a sphere or an ellipsoid, with the soft contact.
fn mjcf_geom(w: &Walker, k: usize, leg: &Leg) -> El {
    let base = El::new("geom")
        .attr("name", format!("{}_foot", LEG_NAMES[k]))
        .attr("mass", "0");
    let base = mjcf_contact(w, base);
    let a = leg.foot_semi_axes_m;
    if leg.foot_section.is_some() {
        base.attr("type", "mesh")
            .attr("mesh", format!("{}_foot", LEG_NAMES[k]))
    } else if is_sphere(&a) {
        base.attr("type", "sphere")
            .attr("size", num(a.x))
            .attr("pos", nums(leg.foot_center_m.as_slice()))
    } else {
        base.attr("type", "ellipsoid")
            .attr("size", nums(a.as_slice()))
            .attr("pos", nums(leg.foot_center_m.as_slice()))
    }
}

/// A leg's `<inertial>`: mass, COM and principal moments.
fn mjcf_inertial(leg: &Leg) -> El {
    let i = leg.inertia_com_kgm2;
    El::new("inertial")
        .attr("pos", nums(leg.com_m.as_slice()))
        .attr("mass", num(leg.mass_kg))
        .attr("diaginertia", nums(&[i[(0, 0)], i[(1, 1)], i[(2, 2)]]))
}

/// A touch sensor's site: the foot's ellipsoid grown by 5 %, so the contact points (between
/// the surfaces) lie inside it.
fn mjcf_touch_site(k: usize, leg: &Leg) -> El {
    El::new("site")
        .attr("name", format!("{}_foot_touch", LEG_NAMES[k]))
        .attr("type", "ellipsoid")
        .attr("size", nums((leg.foot_semi_axes_m * 1.05).as_slice()))
        .attr("pos", nums(leg.foot_center_m.as_slice()))
        .attr("rgba", "0 0 0 0")
}

fn mjcf(w: &mut Walker) -> String {
    let d = w.design;
    let dt = d.numerics.time_step_s;
    let g = w.model.gravity_mps2;
    let mut root = El::new("mujoco").attr("model", d.name.clone());
    root.push(
        El::new("compiler")
            .attr("angle", "radian")
            .attr("autolimits", "true"),
    );
    root.push(
        El::new("option")
            .attr("timestep", num(dt))
            .attr("gravity", nums(g.as_slice()))
            .attr("integrator", "implicitfast")
            .attr("cone", "elliptic")
            .attr("impratio", "10")
            .comment("implicitfast: the servo's damping implicit, as in the design's integrator; elliptic cone: Coulomb's circle of friction; impratio 10 makes friction harder than the normal contact (less creep)"),
    );
    root.push(mjcf_custom(d));
    if let Some(asset) = mjcf_asset(w) {
        root.push(asset);
    }
    root.push(mjcf_worldbody(w));
    root.push(mjcf_actuator(w));
    root.push(mjcf_sensors());
    root.push(mjcf_keyframe(w));
    document(&header(w, Format::Mjcf), &root)
}

/// `<custom>`: the design values MJCF does not carry, as numeric and text data.
fn mjcf_custom(d: &Design) -> El {
    let mut custom = El::new("custom").comment(format!(
        "Design values MJCF does not carry (read back by survey sim import); names are `{CUSTOM_PREFIX}` + the design path"
    ));
    for (p, v) in carried_numbers(d) {
        custom.push(
            El::new("numeric")
                .attr("name", format!("{CUSTOM_PREFIX}{p}"))
                .attr("data", num(v)),
        );
    }
    for (p, v) in carried_text(d) {
        custom.push(
            El::new("text")
                .attr("name", format!("{CUSTOM_PREFIX}{p}"))
                .attr("data", v),
        );
    }
    custom
}

/// `<asset>` with the section-cut feet as inline meshes (None: no foot is cut).
fn mjcf_asset(w: &Walker) -> Option<El> {
    let mut asset = El::new("asset");
    for (k, leg) in w.model.legs.iter().enumerate() {
        if let Some(m) = section_mesh(leg) {
            let v: Vec<f64> = m.vertices.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
            let f: Vec<String> = m
                .triangles
                .iter()
                .flat_map(|t| t.map(|i| i.to_string()))
                .collect();
            asset.push(
                El::new("mesh")
                    .attr("name", format!("{}_foot", LEG_NAMES[k]))
                    .attr("vertex", nums(&v))
                    .attr("face", f.join(" ")),
            );
        }
    }
    (!asset.children.is_empty()).then(|| {
        asset.comment(
            "the feet are sections of their ellipsoids (the design's section cut): convex meshes",
        )
    })
}

/// The hip hinge: its soft limit (the stop), damping and friction loss.
fn mjcf_hip_joint(w: &Walker) -> El {
    let mut joint = El::new("joint")
        .attr("name", "hip")
        .attr("type", "hinge")
        .attr("axis", "0 1 0");
    if let Some((lim, tc, zeta)) = w.limit() {
        joint = joint
            .attr("range", nums(&[-lim, lim]))
            .attr("solreflimit", nums(&[tc, zeta]))
            .attr(
                "solimplimit",
                nums(&[IMPEDANCE, IMPEDANCE, 0.001, 0.5, 2.0]),
            );
    }
    if w.viscous_nms_per_rad > 0.0 {
        joint = joint.attr("damping", num(w.viscous_nms_per_rad));
    }
    if w.coulomb_nm > 0.0 {
        joint = joint.attr("frictionloss", num(w.coulomb_nm));
    }
    joint
}

/// `<worldbody>`: the ground plane and the free left leg carrying the hinged right leg.
fn mjcf_worldbody(w: &Walker) -> El {
    let [left, right] = &w.model.legs;
    let right_body = El::new("body")
        .attr("name", "right_leg")
        .child(mjcf_hip_joint(w))
        .child(mjcf_inertial(right))
        .child(mjcf_geom(w, 1, right))
        .child(mjcf_touch_site(1, right));
    let left_body = El::new("body")
        .attr("name", "left_leg")
        .attr("pos", nums(w.start_position.as_slice()))
        .attr("quat", nums(&wxyz(&w.start_orientation)))
        .child(El::new("freejoint").attr("name", "base"))
        .child(mjcf_inertial(left))
        .child(mjcf_geom(w, 0, left))
        .child(mjcf_touch_site(0, left))
        .child(right_body);
    let ground = El::new("geom")
        .attr("name", "ground")
        .attr("type", "plane")
        .attr("size", "0 0 1");
    El::new("worldbody")
        .comment("the ground: the same contact parameters as the feet, so MuJoCo's pair mixing keeps them")
        .child(mjcf_contact(w, ground))
        .child(left_body)
}

/// `<sensor>`: the hip torque and each foot's touch force.
fn mjcf_sensors() -> El {
    El::new("sensor")
        .child(
            El::new("actuatorfrc")
                .attr("name", "hip_torque")
                .attr("actuator", "hip"),
        )
        .child(
            El::new("touch")
                .attr("name", "left_foot_force")
                .attr("site", "left_foot_touch"),
        )
        .child(
            El::new("touch")
                .attr("name", "right_foot_force")
                .attr("site", "right_foot_touch"),
        )
}

/// `<keyframe>`: the initial state (base pose, hip angle 0, at rest).
fn mjcf_keyframe(w: &Walker) -> El {
    let mut qpos: Vec<f64> = w.start_position.as_slice().to_vec();
    qpos.extend(wxyz(&w.start_orientation));
    qpos.push(0.0);
    El::new("keyframe").child(
        El::new("key")
            .attr("name", "initial")
            .attr("qpos", nums(&qpos))
            .attr("qvel", nums(&[0.0; 7])),
    )
}

/// The hip actuator: a position servo whose target the driver sets to
/// q_d + (kd/kp)·q̇_d (so kp·(ctrl − q) − kv·q̇ is the design's PD law exactly), or a motor
/// whose control is the bang-bang torque; a motor torque–speed line as a velocity bias.
fn mjcf_actuator(w: &mut Walker) -> El {
    let act = El::new("actuator");
    match w.servo() {
        Some((kp, kd, limit)) => {
            let mut el = El::new("position")
                .attr("name", "hip")
                .attr("joint", "hip")
                .attr("kp", num(kp))
                .attr("kv", num(kd))
                .attr("forcerange", nums(&[-limit, limit]));
            if w.motor_no_load_rad_s.is_some() {
                w.notes.push("the motor's torque–speed line is not expressible on a position servo: left out of the MJCF (in its custom data)".into());
            }
            el = el.comment(format!(
                "drive: ctrl(t) = A·sin(2πft) + (kd/kp)·A·2πf·cos(2πft), A = {} rad, f = {} Hz",
                num(servo_amplitude(w.design)),
                num(w.controller.frequency_hz().unwrap_or(0.0))
            ));
            act.child(el)
        }
        None => {
            let tau = w.effort_nm();
            let mut el = El::new("general")
                .attr("name", "hip")
                .attr("joint", "hip")
                .attr("gainprm", "1");
            if let Some(w0) = w.motor_no_load_rad_s {
                el = el
                    .attr("biastype", "affine")
                    .attr("biasprm", nums(&[0.0, 0.0, -tau / w0]));
                w.notes.push(format!(
                    "the motor torque–speed line is MuJoCo's linear DC motor, τ = u − (τ₀/ω₀)·q̇ with ω₀ = {} rad/s: it also brakes when driven backward, where the design's line acts only while motoring",
                    num(w0)
                ));
            }
            act.child(el.comment(format!(
                "drive: ctrl(t) = +{} N·m for the first half of each period 1/f, −{} after, f = {} Hz",
                num(tau),
                num(tau),
                num(w.controller.frequency_hz().unwrap_or(0.0))
            )))
        }
    }
}

fn servo_amplitude(d: &Design) -> f64 {
    match d.control {
        ControlSpec::ServoSine { amplitude_deg, .. } => amplitude_deg.to_radians(),
        ControlSpec::BangBang { .. } => 0.0,
    }
}

/// Drake's hydroelastic properties of a foot: URDF gives each value as a `value` attribute,
/// SDF as the element's text.
fn drake_properties(w: &Walker, format: Format) -> El {
    let c = &w.model.contact;
    let value = |name: &str, x: f64| {
        let e = El::new(&format!("drake:{name}"));
        if format == Format::Urdf {
            e.attr("value", num(x))
        } else {
            e.text(num(x))
        }
    };
    let mut p = El::new("drake:proximity_properties")
        .child(El::new("drake:compliant_hydroelastic"))
        .child(value("hydroelastic_modulus", c.modulus_pa))
        .child(value("mesh_resolution_hint", 0.06 * w.l()));
    if c.relaxation_time_s > 0.0 {
        p.push(value("relaxation_time", c.relaxation_time_s));
    }
    if c.dissipation_s_per_m > 0.0 {
        p.push(value("hunt_crossley_dissipation", c.dissipation_s_per_m));
    }
    p.child(value("mu_dynamic", w.mu()))
        .child(value("mu_static", w.mu()))
}

fn rpy_zero() -> String {
    "0 0 0".into()
}

/// The exported mesh file of leg `k`'s section-cut foot, if it has one.
fn foot_mesh(meshes: &[(String, String)], k: usize) -> Option<&(String, String)> {
    meshes
        .iter()
        .find(|(f, _)| f.ends_with(&format!(".{}_foot.obj", LEG_NAMES[k])))
}

/// Where a foot's collision sits in its leg's frame: a mesh at the origin (its vertices are
/// in the leg's frame), a sphere or ellipsoid at the foot's centre.
fn foot_origin(leg: &Leg, mesh: Option<&(String, String)>) -> Vector3<f64> {
    if mesh.is_some() {
        Vector3::zeros()
    } else {
        leg.foot_center_m
    }
}

/// A leg's `<inertia>` (principal moments, no products): URDF gives each value as an
/// attribute, SDF as a child element.
fn inertia(leg: &Leg, format: Format) -> El {
    let i = leg.inertia_com_kgm2;
    let values = [
        ("ixx", num(i[(0, 0)])),
        ("ixy", "0".to_string()),
        ("ixz", "0".to_string()),
        ("iyy", num(i[(1, 1)])),
        ("iyz", "0".to_string()),
        ("izz", num(i[(2, 2)])),
    ];
    values
        .into_iter()
        .fold(El::new("inertia"), |e, (k, v)| match format {
            Format::Urdf => e.attr(k, v),
            Format::Mjcf | Format::Sdf => e.child(El::leaf(k, v)),
        })
}

/// Drake's `<drake:controller_gains>` of the servo (None: a bang-bang motor has none).
fn controller_gains(w: &Walker) -> Option<El> {
    w.servo().map(|(kp, kd, _)| {
        El::new("drake:controller_gains")
            .attr("p", num(kp))
            .attr("d", num(kd))
    })
}

/// A foot's URDF `<geometry>`: the section mesh, a sphere or a Drake ellipsoid.
fn urdf_geometry(leg: &Leg, mesh: Option<&(String, String)>) -> El {
    let a = leg.foot_semi_axes_m;
    let g = El::new("geometry");
    match mesh {
        Some((file, _)) => g.child(
            El::new("mesh")
                .attr("filename", file.clone())
                .child(El::new("drake:declare_convex")),
        ),
        None if is_sphere(&a) => g.child(El::new("sphere").attr("radius", num(a.x))),
        None => g.child(
            El::new("drake:ellipsoid")
                .attr("a", num(a.x))
                .attr("b", num(a.y))
                .attr("c", num(a.z)),
        ),
    }
}

/// A leg's URDF `<link>`: its inertial and its foot's collision.
fn urdf_link(w: &Walker, k: usize, leg: &Leg, mesh: Option<&(String, String)>) -> El {
    El::new("link")
        .attr("name", format!("{}_leg", LEG_NAMES[k]))
        .child(
            El::new("inertial")
                .child(
                    El::new("origin")
                        .attr("xyz", nums(leg.com_m.as_slice()))
                        .attr("rpy", rpy_zero()),
                )
                .child(El::new("mass").attr("value", num(leg.mass_kg)))
                .child(inertia(leg, Format::Urdf)),
        )
        .child(
            El::new("collision")
                .attr("name", format!("{}_foot", LEG_NAMES[k]))
                .child(
                    El::new("origin")
                        .attr("xyz", nums(foot_origin(leg, mesh).as_slice()))
                        .attr("rpy", rpy_zero()),
                )
                .child(urdf_geometry(leg, mesh))
                .child(drake_properties(w, Format::Urdf)),
        )
}

/// The URDF hip joint: revolute with the stop's limits (continuous without a stop), the
/// effort limit, damping and friction.
fn urdf_hip_joint(w: &Walker) -> El {
    let mut joint = El::new("joint")
        .attr("name", "hip")
        .attr(
            "type",
            if w.model.hardstop.is_some() {
                "revolute"
            } else {
                "continuous"
            },
        )
        .child(El::new("parent").attr("link", "left_leg"))
        .child(El::new("child").attr("link", "right_leg"))
        .child(
            El::new("origin")
                .attr("xyz", "0 0 0")
                .attr("rpy", rpy_zero()),
        )
        .child(El::new("axis").attr("xyz", "0 1 0"));
    let mut limit = El::new("limit")
        .attr("effort", num(w.effort_nm()))
        .attr("velocity", "1000");
    if let Some(h) = w.model.hardstop {
        limit = limit
            .attr("lower", num(-h.limit_rad))
            .attr("upper", num(h.limit_rad));
    }
    joint.push(limit);
    joint.push(
        El::new("dynamics")
            .attr("damping", num(w.viscous_nms_per_rad))
            .attr("friction", num(w.coulomb_nm)),
    );
    joint
}

/// The hip's `<transmission>`, with the servo's PD gains on its actuator.
fn urdf_transmission(w: &Walker) -> El {
    let mut actuator = El::new("actuator")
        .attr("name", "hip")
        .child(El::leaf("mechanicalReduction", "1"));
    if let Some(gains) = controller_gains(w) {
        actuator.push(gains);
    }
    El::new("transmission")
        .attr("name", "hip_transmission")
        .child(El::leaf(
            "type",
            "transmission_interface/SimpleTransmission",
        ))
        .child(
            El::new("joint")
                .attr("name", "hip")
                .child(El::leaf("hardwareInterface", "EffortJointInterface")),
        )
        .child(actuator)
}

fn urdf(w: &mut Walker, meshes: &[(String, String)]) -> String {
    let d = w.design;
    let mut root = El::new("robot")
        .attr("name", d.name.clone())
        .attr("xmlns:drake", "http://drake.mit.edu");
    for (k, leg) in w.model.legs.iter().enumerate() {
        root.push(urdf_link(w, k, leg, foot_mesh(meshes, k)));
    }
    root.push(urdf_hip_joint(w));
    root.push(urdf_transmission(w));
    w.notes
        .push("URDF has no initial pose or drive: both are in the sidecar".into());
    limit_note(w);
    document(&header(w, Format::Urdf), &root)
}

fn limit_note(w: &mut Walker) {
    if w.model.hardstop.is_some() {
        w.notes.push("the hip stop is the format's joint limit (Drake: a stiff constraint), not the design's spring-damper (its constants are in the sidecar)".into());
    }
}

fn pose(p: &Vector3<f64>, q: &UnitQuaternion<f64>) -> String {
    let (r, pi, y) = q.euler_angles();
    nums(&[p.x, p.y, p.z, r, pi, y])
}

/// An SDF pose at a point, unrotated: `x y z 0 0 0`.
fn pose_at(p: &Vector3<f64>) -> String {
    nums(&[p.x, p.y, p.z, 0.0, 0.0, 0.0])
}

/// A foot's SDF geometry: the section mesh, a sphere or an ellipsoid.
fn sdf_geometry(leg: &Leg, mesh: Option<&(String, String)>) -> El {
    let a = leg.foot_semi_axes_m;
    match mesh {
        Some((file, _)) => El::new("mesh")
            .child(El::leaf("uri", file.clone()))
            .child(El::new("drake:declare_convex")),
        None if is_sphere(&a) => El::new("sphere").child(El::leaf("radius", num(a.x))),
        None => El::new("ellipsoid").child(El::leaf("radii", nums(a.as_slice()))),
    }
}

/// A leg's SDF `<link>`: its inertial and its foot's collision.
fn sdf_link(w: &Walker, k: usize, leg: &Leg, mesh: Option<&(String, String)>) -> El {
    El::new("link")
        .attr("name", format!("{}_leg", LEG_NAMES[k]))
        .child(
            El::new("inertial")
                .child(El::leaf("pose", pose_at(&leg.com_m)))
                .child(El::leaf("mass", num(leg.mass_kg)))
                .child(inertia(leg, Format::Sdf)),
        )
        .child(
            El::new("collision")
                .attr("name", format!("{}_foot", LEG_NAMES[k]))
                .child(El::leaf("pose", pose_at(&foot_origin(leg, mesh))))
                .child(El::new("geometry").child(sdf_geometry(leg, mesh)))
                .child(drake_properties(w, Format::Sdf)),
        )
}

/// The SDF hip joint: revolute about y with the stop's limits, effort, damping, friction and
/// the servo's PD gains.
fn sdf_hip_joint(w: &Walker) -> El {
    let mut limit = El::new("limit").child(El::leaf("effort", num(w.effort_nm())));
    if let Some(h) = w.model.hardstop {
        limit = El::new("limit")
            .child(El::leaf("lower", num(-h.limit_rad)))
            .child(El::leaf("upper", num(h.limit_rad)))
            .child(El::leaf("effort", num(w.effort_nm())));
    }
    let mut joint = El::new("joint")
        .attr("name", "hip")
        .attr("type", "revolute")
        .child(El::leaf("parent", "left_leg"))
        .child(El::leaf("child", "right_leg"))
        .child(
            El::new("axis")
                .child(El::leaf("xyz", "0 1 0"))
                .child(limit)
                .child(
                    El::new("dynamics")
                        .child(El::leaf("damping", num(w.viscous_nms_per_rad)))
                        .child(El::leaf("friction", num(w.coulomb_nm))),
                ),
        );
    if let Some(gains) = controller_gains(w) {
        joint.push(gains);
    }
    joint
}

fn sdf(w: &mut Walker, meshes: &[(String, String)]) -> String {
    let d = w.design;
    let mut model = El::new("model")
        .attr("name", d.name.clone())
        .child(El::leaf(
            "pose",
            pose(&w.start_position, &w.start_orientation),
        ));
    for (k, leg) in w.model.legs.iter().enumerate() {
        model.push(sdf_link(w, k, leg, foot_mesh(meshes, k)));
    }
    model.push(sdf_hip_joint(w));
    w.notes.push(
        "SDF carries the initial pose (the model's pose) but not the drive: it is in the sidecar"
            .into(),
    );
    limit_note(w);
    let root = El::new("sdf")
        .attr("version", "1.9")
        .attr("xmlns:drake", "http://drake.mit.edu")
        .child(model);
    document(&header(w, Format::Sdf), &root)
}

/// The sidecar: the design values the format does not carry (by design path), how the
/// hip is driven, and the start, as TOML.
#[derive(Serialize)]
struct Sidecar {
    format: Format,
    /// Read by `survey sim import FILE --sidecar THIS` as design values.
    design: BTreeMap<String, toml::Value>,
    drive: BTreeMap<String, toml::Value>,
    initial_state: BTreeMap<String, toml::Value>,
    hardstop_spring: Option<BTreeMap<String, f64>>,
    mujoco_contact: SoftContact,
    notes: Vec<String>,
}

fn sidecar(w: &Walker, format: Format) -> String {
    let d = w.design;
    let mut design = BTreeMap::new();
    for (p, v) in carried_numbers(d) {
        design.insert(p, toml::Value::Float(v));
    }
    for (p, v) in carried_text(d) {
        design.insert(p, toml::Value::String(v));
    }
    let mut drive = BTreeMap::new();
    let f = w.controller.frequency_hz().unwrap_or(0.0);
    drive.insert("frequency_hz".into(), toml::Value::Float(f));
    match w.servo() {
        Some((kp, kd, limit)) => {
            drive.insert("kind".into(), "servo_sine".into());
            drive.insert(
                "amplitude_rad".into(),
                toml::Value::Float(servo_amplitude(d)),
            );
            drive.insert("kp_nm_per_rad".into(), toml::Value::Float(kp));
            drive.insert("kd_nms_per_rad".into(), toml::Value::Float(kd));
            drive.insert("torque_limit_nm".into(), toml::Value::Float(limit));
            drive.insert(
                "law".into(),
                "tau = clamp(kp*(A sin(2 pi f t) - q) + kd*(A 2 pi f cos(2 pi f t) - qdot), +-torque_limit)".into(),
            );
        }
        None => {
            drive.insert("kind".into(), "bang_bang".into());
            drive.insert("torque_nm".into(), toml::Value::Float(w.effort_nm()));
            drive.insert(
                "law".into(),
                "tau = +torque for frac(f t) < 0.5, else -torque".into(),
            );
        }
    }
    let mut initial_state = BTreeMap::new();
    let arr = |xs: &[f64]| toml::Value::Array(xs.iter().map(|x| toml::Value::Float(*x)).collect());
    initial_state.insert("hip_position_m".into(), arr(w.start_position.as_slice()));
    initial_state.insert("orientation_wxyz".into(), arr(&wxyz(&w.start_orientation)));
    initial_state.insert("hip_angle_rad".into(), toml::Value::Float(0.0));
    let hardstop_spring = w.model.hardstop.map(|h| {
        BTreeMap::from([
            ("limit_rad".to_string(), h.limit_rad),
            ("stiffness_nm_per_rad".to_string(), h.stiffness_nm_per_rad),
            ("damping_nms_per_rad".to_string(), h.damping_nms_per_rad),
        ])
    });
    let s = Sidecar {
        format,
        design,
        drive,
        initial_state,
        hardstop_spring,
        mujoco_contact: w.soft,
        notes: w.notes.clone(),
    };
    format!(
        "# robot-survey sidecar of the {:?} export of `{}`: what the model file does not carry.\n# `survey sim import MODEL --sidecar THIS` reads [design] back; [drive] and [initial_state] say how to run it.\n{}",
        format,
        d.name,
        toml::to_string(&s).unwrap_or_default()
    )
}
