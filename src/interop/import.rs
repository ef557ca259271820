//! A two-body hip walker read from MJCF, URDF or SDFormat, as a design TOML whose every value says where
//! it came from: the file (with its sha256), the file's `<custom>` data or a sidecar, the
//! command line (`--set`), or the command's defaults.
//!
//! What a file gives, and how it becomes the design's symmetric model:
//! * bodies welded together are one leg; the leg with the free base is the left (legs[0]),
//!   the one on the hinge the right; any other joint, or a count other than two legs, is
//!   refused;
//! * the frame: y along the hip axis (sign: the base leg's COM on +y), z up (against gravity,
//!   made normal to y), x = y × z; the hip point on the axis, midway between the legs' COMs;
//! * each leg's foot is its contact geometry lowest along −z: a sphere or an ellipsoid along
//!   the axes as it is, a capsule within 5° of vertical as the sphere about its lower end,
//!   else (a mesh, a turned ellipsoid, a box, a cylinder, a tilted capsule) the best-fitting
//!   ellipsoid of its convex hull where a floor can touch it (a box's, cylinder's or
//!   capsule's set down on its lowest point); a mesh foot whose inner edge cuts its ellipsoid becomes a section
//!   (`foot_section_cut_over_l`); L is the hip's height above the feet;
//! * the design is symmetric: one mass split equally, the legs' COM offsets, inertia boxes
//!   and feet averaged; what that averages away is said in the file.

mod control;

use std::path::Path;

use nalgebra::Vector3;

use super::legs::{LegRead, read_legs, topo, world_frames};
use super::robot_file::{RobotFile, Shape, read_text};
use super::soft_contact::pressure_field_of;
use super::{CUSTOM_PREFIX, InteropError};
use super::{mjcf, sdf, urdf};
use crate::sim::walk::stable_time_step_s;
use crate::sim::{Design, EffectSpec, GRAVITY_MPS2};

/// The command's defaults for what a file lacks: the reference parameter set's values
/// (`dataset/walkers/reference/mugatu-ref.toml`), in the size-free form it scales by.
pub mod defaults {
    pub const MODULUS_PA: f64 = 3.0e6;
    /// Kelvin–Voigt relaxation time at L = 0.153 m, ∝ √L.
    pub const RELAXATION_TIME_S_AT_REF: f64 = 0.005;
    pub const STICTION_SPEED_OVER_SQRT_GL: f64 = 0.0001 / 1.2251;
    pub const FRICTION_MU: f64 = 0.8;
    pub const AMPLITUDE_DEG: f64 = 25.0;
    pub const KP_OVER_MGL: f64 = 20.0;
    pub const KD_OVER_MGL_SQRT_L_OVER_G: f64 = 2.0;
    /// mugatu-ref's 1 N·m at m·g·L = 1.351 N·m.
    pub const TORQUE_LIMIT_OVER_MGL: f64 = 0.74;
    /// zippy-ref's 4 mN·m at m·g·L = 6.06 mN·m.
    pub const BANG_BANG_TORQUE_OVER_MGL: f64 = 0.66;
    /// The drive at this fraction of the free roll rocking frequency (the bundled designs'
    /// rule: just below it the roll locks to the drive).
    pub const DRIVE_OVER_ROCKING: f64 = 0.97;
    pub const HARDSTOP_STIFFNESS_OVER_MGL: f64 = 100.0;
    pub const HARDSTOP_DAMPING: f64 = 2.0;
    pub const ROLL_DEG: f64 = 3.0;
    /// Time step at L = 0.153 m, ∝ √L.
    pub const TIME_STEP_S_AT_REF: f64 = 0.001;
    pub const REF_LEG_LENGTH_M: f64 = 0.153;
}

/// One value of the imported design and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub path: String,
    pub value: toml::Value,
    pub source: String,
}

/// An imported walker: the design's entries, the TOML text, the design itself.
#[derive(Clone, Debug)]
pub struct Imported {
    pub entries: Vec<Entry>,
    pub notes: Vec<String>,
    pub toml: String,
    pub design: Design,
}

/// Reads an MJCF (`.xml`, root `<mujoco>`), URDF (root `<robot>`) or SDFormat (root `<sdf>`)
/// file.
pub fn read_robot_file(path: &Path) -> Result<RobotFile, InteropError> {
    let (text, sha) = read_text(path)?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| InteropError::Invalid {
        file: path.display().to_string(),
        message: format!("not well-formed XML: {e}"),
    })?;
    let root = doc.root_element();
    match root.tag_name().name() {
        "mujoco" => mjcf::read(path, &doc, sha),
        "robot" => urdf::read(path, &doc, sha),
        "sdf" => sdf::read(path, &doc, sha),
        other => Err(InteropError::Invalid {
            file: path.display().to_string(),
            message: format!(
                "root element <{other}> is none of <mujoco> (MJCF), <robot> (URDF), <sdf> (SDFormat)"
            ),
        }),
    }
}

/// Options of an import: design values given on the command line and a sidecar file.
#[derive(Clone, Debug, Default)]
pub struct ImportOptions {
    /// `PATH=VALUE` pairs (dotted design paths; text for name, control.kind,
    /// contact.friction_cone, criteria.walking_direction).
    pub set: Vec<(String, String)>,
    pub sidecar: Option<std::path::PathBuf>,
    /// The design's name (default: the file's stem).
    pub name: Option<String>,
}

/// The provenance tag of a value read from the file.
fn from_file(f: &RobotFile, how: &str) -> String {
    format!("[{} sha256:{}] {how}", file_name(&f.path), &f.sha256[..12])
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

struct Builder<'a> {
    f: &'a RobotFile,
    entries: Vec<Entry>,
    notes: Vec<String>,
}

impl Builder<'_> {
    fn put(&mut self, path: &str, value: impl Into<toml::Value>, source: String) {
        let value = value.into();
        self.entries.retain(|e| e.path != path);
        self.entries.push(Entry {
            path: path.to_string(),
            value,
            source,
        });
    }
    fn file(&mut self, path: &str, value: f64, how: &str) {
        let s = from_file(self.f, how);
        self.put(path, value, s);
    }
    fn default(&mut self, path: &str, value: impl Into<toml::Value>, why: &str) {
        self.put(path, value, format!("[DEFAULT] not in the file: {why}"));
    }
    fn num(&self, path: &str) -> Option<f64> {
        self.entries
            .iter()
            .find(|e| e.path == path)
            .and_then(|e| e.value.as_float())
    }
    fn has(&self, path: &str) -> bool {
        self.entries.iter().any(|e| e.path == path)
    }
}

/// Imports a walker file (MJCF or URDF) as a design.
pub fn import(path: &Path, opts: &ImportOptions) -> Result<Imported, InteropError> {
    let f = read_robot_file(path)?;
    let (legs, wf) = read_legs(&f)?;
    let mut b = Builder {
        f: &f,
        entries: Vec::new(),
        notes: Vec::new(),
    };
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "imported".into());
    let name = opts.name.clone().unwrap_or(stem);
    b.put(
        "name",
        name.clone(),
        "[SET] the design's name (the file's stem unless --name)".into(),
    );
    b.put(
        "description",
        format!(
            "{} imported from {} (sha256 {})",
            name,
            file_name(&f.path),
            f.sha256
        ),
        from_file(&f, "the file this design was read from"),
    );
    geometry_and_mass(&mut b, &legs)?;
    let l = b.num("geometry.leg_length_m").unwrap_or(1.0);
    let m = b.num("mass.total_mass_kg").unwrap_or(1.0);
    contact(&mut b, &legs, l, m);
    control::control(&mut b, &legs, l, m, &wf)?;
    start_and_criteria(&mut b, &legs, l, m);
    custom_values(&mut b)?;
    if let Some(sc) = &opts.sidecar {
        sidecar_values(&mut b, sc)?;
    }
    for (p, v) in &opts.set {
        let value = v
            .trim()
            .parse::<f64>()
            .map(toml::Value::Float)
            .unwrap_or_else(|_| toml::Value::String(v.clone()));
        b.put(p, value, format!("[SET] --set {p}={v}"));
    }
    finish(b, &name)
}

/// The design's geometry and mass sections from the two legs.
fn geometry_and_mass(b: &mut Builder, legs: &[LegRead; 2]) -> Result<(), InteropError> {
    let l = geometry(b, legs)?;
    mass(b, legs, l);
    Ok(())
}

/// `[geometry]`: the leg length (hip height above the feet), the body's extent, the feet and
/// where they and the legs sit; returns the leg length.
fn geometry(b: &mut Builder, legs: &[LegRead; 2]) -> Result<f64, InteropError> {
    let f = b.f;
    let heights: Vec<f64> = legs
        .iter()
        .map(|g| g.foot_semi.z - g.foot_center.z)
        .collect();
    let l = 0.5 * (heights[0] + heights[1]);
    if l.is_nan() || l <= 0.0 {
        return Err(topo(
            f,
            format!(
                "the feet are above the hip (hip height {l:.4} m): not a standing walker at the file's pose"
            ),
        ));
    }
    b.file(
        "geometry.leg_length_m",
        l,
        &format!(
            "hip height above the feet' lowest points, legs together (legs {:.5} / {:.5} m)",
            heights[0], heights[1]
        ),
    );
    let extent = body_extent(f);
    b.file(
        "geometry.body_length_m",
        extent,
        "the closest estimate: the largest extent of all the file's geometry along x, y, z",
    );
    let semi = 0.5 * (legs[0].foot_semi + legs[1].foot_semi);
    b.put(
        "geometry.foot_semi_axes_m",
        toml::Value::Array(semi.iter().map(|x| toml::Value::Float(*x)).collect()),
        from_file(
            f,
            &format!(
                "left: {}; right: {} (mean of the two)",
                legs[0].foot_how, legs[1].foot_how
            ),
        ),
    );
    let lateral = 0.5 * (legs[0].foot_center.y - legs[1].foot_center.y) / l;
    let forward = 0.5 * (legs[0].foot_center.x + legs[1].foot_center.x) / l;
    let com = [legs[0].mass.com_m, legs[1].mass.com_m];
    let width = 0.5 * (com[0].y - com[1].y) / l;
    b.file(
        "geometry.hip_half_width_over_l",
        width.max(0.0),
        &format!(
            "the legs' COMs at y = {:.4} / {:.4} m (mean |y|)",
            com[0].y, com[1].y
        ),
    );
    b.file(
        "geometry.foot_center_lateral_over_l",
        lateral,
        &format!(
            "foot centres at y = {:.4} / {:.4} m",
            legs[0].foot_center.y, legs[1].foot_center.y
        ),
    );
    b.file(
        "geometry.foot_center_forward_over_l",
        forward,
        &format!(
            "foot centres at x = {:.4} / {:.4} m",
            legs[0].foot_center.x, legs[1].foot_center.x
        ),
    );
    if let (Some(c0), Some(c1)) = (legs[0].cut, legs[1].cut) {
        b.file("geometry.foot_section_cut_over_l", 0.5 * (c0 + c1) / l, &format!("each foot mesh's inner edge at |y| = {c0:.4} / {c1:.4} m: the foot is its ellipsoid beyond that plane"));
    }
    Ok(l)
}

/// `[mass]`: the total mass, the legs' mean COM and inertia box; a note when the legs differ.
fn mass(b: &mut Builder, legs: &[LegRead; 2], l: f64) {
    let com = [legs[0].mass.com_m, legs[1].mass.com_m];
    let m0 = legs[0].mass.mass_kg;
    let m1 = legs[1].mass.mass_kg;
    let m = m0 + m1;
    b.file("mass.total_mass_kg", m, &format!("sum of the legs' inertials: {} {m0:.5} kg + {} {m1:.5} kg (the design splits it equally)", legs[0].name, legs[1].name));
    let h = 1.0 + 0.5 * (com[0].z + com[1].z) / l;
    b.file(
        "mass.leg_com_height_over_l",
        h,
        &format!(
            "the legs' COMs {:.4} / {:.4} m below the hip",
            -com[0].z, -com[1].z
        ),
    );
    b.file(
        "mass.leg_com_forward_over_l",
        0.5 * (com[0].x + com[1].x) / l,
        &format!("the legs' COMs at x = {:.4} / {:.4} m", com[0].x, com[1].x),
    );
    inertia_box(b, legs, l);
    if (m0 - m1).abs() > 0.02 * m
        || (com[0].z - com[1].z).abs() > 0.02 * l
        || (com[0].x - com[1].x).abs() > 0.02 * l
    {
        b.notes.push(format!(
            "the legs differ (masses {m0:.4} / {m1:.4} kg, COMs ({:.4}, {:.4}, {:.4}) / ({:.4}, {:.4}, {:.4}) m): the design's legs are mirror images, so these are averaged",
            com[0].x, com[0].y, com[0].z, com[1].x, com[1].y, com[1].z
        ));
    }
}

/// `mass.leg_inertia_box_over_l`: the box with the legs' mean inertia per unit mass about
/// their COMs, and how much its products of inertia leave out.
fn inertia_box(b: &mut Builder, legs: &[LegRead; 2], l: f64) {
    let f = b.f;
    let m0 = legs[0].mass.mass_kg;
    let m1 = legs[1].mass.mass_kg;
    // The inertia box: edges from the principal moments per unit mass along the walker's axes.
    let j = 0.5 * (legs[0].mass.inertia_com_kgm2 / m0 + legs[1].mass.inertia_com_kgm2 / m1);
    let d = j.diagonal();
    let edges = Vector3::new(d.y + d.z - d.x, d.x + d.z - d.y, d.x + d.y - d.z)
        .map(|e| (6.0 * e.max(1e-12 * d.max())).sqrt() / l);
    let off = [j[(0, 1)], j[(0, 2)], j[(1, 2)]]
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()))
        / d.max();
    b.put(
        "mass.leg_inertia_box_over_l",
        toml::Value::Array(edges.iter().map(|x| toml::Value::Float(*x)).collect()),
        from_file(f, &format!("the box with the legs' mean inertia per unit mass about their COMs, along x, y, z (largest product of inertia left out: {:.1} % of the largest moment)", 100.0 * off)),
    );
}

/// The largest extent of the file's geometry (vertices of meshes, the exact bounding boxes
/// of primitives as they are turned).
fn body_extent(f: &RobotFile) -> f64 {
    let frames = world_frames(f);
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for (b, fr) in f.bodies.iter().zip(&frames) {
        for g in &b.geoms {
            let gf = fr.then(&g.frame);
            let r = &gf.r;
            // Half extents along the world's axes of a primitive centred on its frame.
            let half = |i: usize| -> f64 {
                match &g.shape {
                    Shape::Sphere(s) => *s,
                    Shape::Ellipsoid(s) => (0..3)
                        .map(|j| (r[(i, j)] * s[j]).powi(2))
                        .sum::<f64>()
                        .sqrt(),
                    Shape::Box(s) => (0..3).map(|j| (r[(i, j)] * s[j]).abs()).sum(),
                    Shape::Capsule(rad, h) => r[(i, 2)].abs() * h + rad,
                    Shape::Cylinder(rad, h) => {
                        r[(i, 2)].abs() * h + rad * (1.0 - r[(i, 2)].powi(2)).max(0.0).sqrt()
                    }
                    Shape::Mesh(_) | Shape::Plane => 0.0,
                }
            };
            let pts: Vec<Vector3<f64>> = match &g.shape {
                Shape::Mesh(m) => m.vertices.iter().map(|p| r * p + gf.p).collect(),
                Shape::Plane => vec![],
                _ => {
                    let h = Vector3::new(half(0), half(1), half(2));
                    vec![gf.p - h, gf.p + h]
                }
            };
            for w in pts {
                lo = lo.inf(&w);
                hi = hi.sup(&w);
            }
        }
    }
    (hi - lo).max()
}

fn contact(b: &mut Builder, legs: &[LegRead; 2], l: f64, m: f64) {
    let f = b.f;
    let foot = |name: &str| {
        f.bodies
            .iter()
            .flat_map(|x| x.geoms.iter())
            .find(|g| g.name == name)
            .map(|g| g.values.clone())
            .unwrap_or_default()
    };
    let v = foot(&legs[0].foot_name);
    let semi: [f64; 3] = (0.5 * (legs[0].foot_semi + legs[1].foot_semi)).into();
    let scale = (l / defaults::REF_LEG_LENGTH_M).sqrt();
    match (v.modulus_pa, v.solref) {
        (Some(e), _) => b.file("contact.hydroelastic_modulus_pa", e, "the foot's drake:hydroelastic_modulus"),
        (None, Some([tc, zeta])) if tc > 0.0 && zeta > 0.0 => {
            let (e, tau) = pressure_field_of(tc, zeta, m, semi);
            b.file("contact.hydroelastic_modulus_pa", e, &format!("the closest pressure field to the foot's MuJoCo solref ({tc}, {zeta}): the same bounce frequency of the whole weight on one foot (not an identity)"));
            if v.relaxation_time_s.is_none() && v.hunt_crossley_s_per_m.is_none() {
                b.file("contact.relaxation_time_s", tau, "the closest Kelvin–Voigt damping: the same bounce damping ratio as the MuJoCo solref");
            }
        }
        _ => b.default("contact.hydroelastic_modulus_pa", defaults::MODULUS_PA, "the reference set's soft rubber (MuJoCo's default solref is no statement about the foot)"),
    }
    if let Some(t) = v.relaxation_time_s {
        b.file(
            "contact.relaxation_time_s",
            t,
            "the foot's drake:relaxation_time",
        );
    }
    if let Some(d) = v.hunt_crossley_s_per_m {
        b.file(
            "contact.hunt_crossley_dissipation_s_per_m",
            d,
            "the foot's drake:hunt_crossley_dissipation",
        );
    }
    if !b.has("contact.relaxation_time_s") && !b.has("contact.hunt_crossley_dissipation_s_per_m") {
        b.default(
            "contact.relaxation_time_s",
            defaults::RELAXATION_TIME_S_AT_REF * scale,
            "the reference set's 5 ms at L = 0.153 m, ∝ √L",
        );
    }
    match v.friction_mu {
        Some(mu) => b.file("contact.friction_mu", mu, "the foot's friction coefficient"),
        None if f.format == "MJCF" => b.file("contact.friction_mu", 1.0, "MuJoCo's default friction 1 (the file sets none; MuJoCo takes the larger of the pair's)"),
        None => b.default("contact.friction_mu", defaults::FRICTION_MU, "the reference set's μ"),
    }
    b.default(
        "contact.stiction_speed_mps",
        defaults::STICTION_SPEED_OVER_SQRT_GL * (GRAVITY_MPS2 * l).sqrt(),
        "the reference set's 0.1 mm/s at L = 0.153 m, ∝ √(gL)",
    );
}

fn effect_table(e: &EffectSpec) -> toml::Value {
    toml::Value::try_from(e).unwrap_or(toml::Value::Table(Default::default()))
}

fn start_and_criteria(b: &mut Builder, legs: &[LegRead; 2], l: f64, m: f64) {
    let _ = (legs, m);
    let f = b.f;
    b.default(
        "initial.roll_deg",
        defaults::ROLL_DEG,
        "at rest, legs together, rolled onto the right foot (a symmetric start never rocks)",
    );
    b.default(
        "initial.seed_angle_sd_deg",
        0.5,
        "the bundled designs' seed perturbation",
    );
    b.default(
        "initial.seed_rate_sd_over_sqrt_g_over_l",
        0.02,
        "the bundled designs' seed perturbation",
    );
    match f.timestep_s {
        Some(dt) => b.file("numerics.time_step_s", dt, "the file's time step"),
        None => b.default(
            "numerics.time_step_s",
            defaults::TIME_STEP_S_AT_REF * (l / defaults::REF_LEG_LENGTH_M).sqrt(),
            "the reference set's 1 ms at L = 0.153 m, ∝ √L",
        ),
    }
    b.default(
        "criteria.walk_speed_threshold_over_sqrt_gl",
        0.1,
        "the reference set's: walking above 0.1 √(gL)",
    );
    b.default(
        "criteria.fall_hip_height_over_l",
        0.5,
        "the reference set's",
    );
    b.default("criteria.fall_roll_deg", 60.0, "the reference set's");
    b.default("criteria.fall_pitch_deg", 75.0, "the reference set's");
    if let Some(g) = f.gravity {
        let slope = (g.x / g.norm()).asin().to_degrees();
        if slope.abs() > 1e-9 {
            b.file(
                "ground.slope_deg",
                slope,
                "the file's gravity tilted along x",
            );
        }
    }
}

/// The file's `<custom>` data written by `survey sim export`: the design values MJCF does
/// not carry, taken where the file's structure does not already give them.
fn custom_values(b: &mut Builder) -> Result<(), InteropError> {
    let f = b.f;
    let tag = |p: &str| from_file(f, &format!("custom data `{CUSTOM_PREFIX}{p}`"));
    for (k, v) in &f.custom_numbers {
        if let Some(p) = k.strip_prefix(CUSTOM_PREFIX) {
            let structural = b.entries.iter().any(|e| {
                e.path == p
                    && !e.source.starts_with("[DEFAULT]")
                    && !e.source.contains("closest")
                    && !e.source.contains("MuJoCo's default")
            });
            if !structural {
                b.put(p, *v, tag(p));
            }
        }
    }
    for (k, v) in &f.custom_texts {
        let Some(p) = k.strip_prefix(CUSTOM_PREFIX) else {
            continue;
        };
        match p {
            "name" => {}
            "effects" => {
                let effects: Vec<EffectSpec> =
                    serde_json::from_str(v).map_err(|e| InteropError::Invalid {
                        file: f.path.display().to_string(),
                        message: format!("custom text `{k}`: {e}"),
                    })?;
                b.put(
                    "effects",
                    toml::Value::Array(effects.iter().map(effect_table).collect()),
                    tag(p),
                );
            }
            _ => b.put(p, v.clone(), tag(p)),
        }
    }
    Ok(())
}

/// `[design]` of an export's sidecar TOML.
fn sidecar_values(b: &mut Builder, path: &Path) -> Result<(), InteropError> {
    let text = std::fs::read(path).map_err(|e| InteropError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let sha = super::robot_file::sha256_hex(&text);
    let t: toml::Table = std::str::from_utf8(&text)
        .ok()
        .and_then(|s| toml::from_str(s).ok())
        .ok_or_else(|| InteropError::Invalid {
            file: path.display().to_string(),
            message: "not a TOML sidecar".into(),
        })?;
    let Some(d) = t.get("design").and_then(|d| d.as_table()) else {
        return Err(InteropError::Invalid {
            file: path.display().to_string(),
            message: "no [design] table".into(),
        });
    };
    let tag = |p: &str| {
        format!(
            "[{} sha256:{}] sidecar value `{p}`",
            file_name(path),
            &sha[..12]
        )
    };
    for (p, v) in d {
        if p == "name" {
            continue;
        }
        if p == "effects" {
            if let Some(s) = v.as_str() {
                let effects: Vec<EffectSpec> =
                    serde_json::from_str(s).map_err(|e| InteropError::Invalid {
                        file: path.display().to_string(),
                        message: format!("design.effects: {e}"),
                    })?;
                b.put(
                    "effects",
                    toml::Value::Array(effects.iter().map(effect_table).collect()),
                    tag(p),
                );
            }
            continue;
        }
        let structural = b.entries.iter().any(|e| {
            e.path == *p
                && e.source.starts_with('[')
                && !e.source.starts_with("[DEFAULT]")
                && !e.source.contains("closest")
        });
        if !structural {
            b.put(p, v.clone(), tag(p));
        }
    }
    Ok(())
}

/// Sections of a design file, in order, with the keys of each.
const SECTIONS: [&str; 9] = [
    "geometry", "mass", "contact", "control", "hardstop", "initial", "numerics", "criteria",
    "ground",
];

fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(x) => format!("{x:?}"),
        other => other.to_string(),
    }
}

/// Keeps the control keys of the final kind (a servo's and a bang-bang's are exclusive),
/// with defaults for those the kind needs and lacks.
fn settle_control_kind(b: &mut Builder) {
    // A servo's keys and a bang-bang's are exclusive: keep those of the final kind.
    let kind = b
        .entries
        .iter()
        .find(|e| e.path == "control.kind")
        .and_then(|e| e.value.as_str().map(str::to_string))
        .unwrap_or_default();
    let l = b.num("geometry.leg_length_m").unwrap_or(1.0);
    let m = b.num("mass.total_mass_kg").unwrap_or(1.0);
    let mgl = m * GRAVITY_MPS2 * l;
    if kind == "bang_bang" {
        b.entries.retain(|e| {
            ![
                "control.amplitude_deg",
                "control.kp_over_mgl",
                "control.kd_over_mgl_sqrt_l_over_g",
                "control.torque_limit_nm",
            ]
            .contains(&e.path.as_str())
        });
        if !b.has("control.torque_nm") {
            b.default(
                "control.torque_nm",
                defaults::BANG_BANG_TORQUE_OVER_MGL * mgl,
                "the reference set's 0.66 m·g·L",
            );
        }
        if !b.has("hardstop.limit_deg") {
            b.default(
                "hardstop.limit_deg",
                25.0,
                "the reference set's stops (a bang-bang hip needs them)",
            );
            b.default(
                "hardstop.stiffness_over_mgl",
                defaults::HARDSTOP_STIFFNESS_OVER_MGL,
                "a stiff stop",
            );
            b.default(
                "hardstop.damping_over_mgl_sqrt_l_over_g",
                defaults::HARDSTOP_DAMPING,
                "a well damped stop",
            );
        }
    } else {
        b.entries.retain(|e| e.path != "control.torque_nm");
        for (p, v, why) in [
            (
                "control.amplitude_deg",
                defaults::AMPLITUDE_DEG,
                "the reference set's servo amplitude",
            ),
            (
                "control.kp_over_mgl",
                defaults::KP_OVER_MGL,
                "the reference set's stiff servo",
            ),
            (
                "control.kd_over_mgl_sqrt_l_over_g",
                defaults::KD_OVER_MGL_SQRT_L_OVER_G,
                "the reference set's servo damping",
            ),
            (
                "control.torque_limit_nm",
                defaults::TORQUE_LIMIT_OVER_MGL * mgl,
                "the reference set's 0.74 m·g·L",
            ),
        ] {
            if !b.has(p) {
                b.default(p, v, why);
            }
        }
    }
}

/// The TOML text with each value's source, then the design parsed back from it.
fn finish(mut b: Builder, name: &str) -> Result<Imported, InteropError> {
    let f = b.f;
    settle_control_kind(&mut b);
    // The time step must resolve the contact: halve a default one until it does.
    let mut text = render(&b, f, name);
    let mut design = parse(&text, name)?;
    let stable = stable_time_step_s(&design);
    if design.numerics.time_step_s > stable {
        let dt = b.num("numerics.time_step_s").unwrap_or(stable);
        let fixed = dt * (stable / dt).min(1.0) * 0.9;
        b.put("numerics.time_step_s", fixed, format!("[DEFAULT] 0.9 × the stable step {stable:.3e} s of the foot contact ({dt:.3e} s from {} is beyond it)", file_name(&f.path)));
        text = render(&b, f, name);
        design = parse(&text, name)?;
    }
    Ok(Imported {
        entries: b.entries,
        notes: b.notes,
        toml: text,
        design,
    })
}

fn parse(text: &str, name: &str) -> Result<Design, InteropError> {
    Design::from_toml_str(text, &format!("{name} (imported)")).map_err(InteropError::Sim)
}

fn render(b: &Builder, f: &RobotFile, name: &str) -> String {
    let mut out = format!(
        "# Design `{name}` imported by `survey sim import` from {} ({} file)\n# sha256 {}\n",
        file_name(&f.path),
        f.format,
        f.sha256
    );
    for (p, sha) in &f.includes {
        out.push_str(&format!("# includes {} (sha256 {sha})\n", file_name(p)));
    }
    out.push_str("# Every value names its source: [FILE sha256:…] read from the file, [SET] the command line,\n# [DEFAULT] the command's default for what the file lacks.\n");
    for n in &b.notes {
        out.push_str(&format!("# Note: {n}\n"));
    }
    let line = |e: &Entry, key: &str| {
        format!(
            "{key} = {}  # {}\n",
            value_text(&e.value),
            e.source.replace('\n', " ")
        )
    };
    for key in ["name", "description"] {
        if let Some(e) = b.entries.iter().find(|e| e.path == key) {
            out.push_str(&line(e, key));
        }
    }
    for sec in SECTIONS {
        let items: Vec<&Entry> = b
            .entries
            .iter()
            .filter(|e| e.path.split_once('.').is_some_and(|(s, _)| s == sec))
            .collect();
        if items.is_empty() {
            continue;
        }
        out.push_str(&format!("\n[{sec}]\n"));
        // `kind` first: the control table is tagged by it.
        let mut items = items;
        items.sort_by_key(|e| !e.path.ends_with(".kind"));
        for e in items {
            let key = e.path.split_once('.').map(|(_, k)| k).unwrap_or(&e.path);
            out.push_str(&line(e, key));
        }
    }
    if let Some(e) = b.entries.iter().find(|e| e.path == "effects")
        && let Some(arr) = e.value.as_array()
    {
        for v in arr {
            out.push_str(&format!("\n[[effects]]  # {}\n", e.source));
            if let Some(t) = v.as_table() {
                for (k, x) in t {
                    out.push_str(&format!("{k} = {}  # {}\n", value_text(x), e.source));
                }
            }
        }
    }
    out
}
