//! A robot file read into one neutral form (bodies, joints, inertials, collision geometry,
//! actuators): MJCF (MuJoCo), URDF and SDFormat (with Drake's extensions). The walker import
//! (`import.rs`) works on this form whatever the format.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Rotation3, Unit, UnitQuaternion, Vector3};
use roxmltree::Node;
use sha2::{Digest, Sha256};

use super::InteropError;
use super::mesh::{MassProps, TriMesh};

/// A rigid transform: a child frame's rotation and origin in its parent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub r: Matrix3<f64>,
    pub p: Vector3<f64>,
}

impl Frame {
    pub const IDENTITY: Frame = Frame {
        r: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        p: Vector3::new(0.0, 0.0, 0.0),
    };

    /// This frame followed by `child` (child given in this frame).
    pub fn then(&self, child: &Frame) -> Frame {
        Frame {
            r: self.r * child.r,
            p: self.r * child.p + self.p,
        }
    }

    /// The parent's frame in this one.
    pub fn inverse(&self) -> Frame {
        let rt = self.r.transpose();
        Frame {
            r: rt,
            p: -(rt * self.p),
        }
    }
}

/// A collision or mass geometry's shape (sizes in metres).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Sphere(f64),
    Ellipsoid(Vector3<f64>),
    /// Half sizes.
    Box(Vector3<f64>),
    /// Radius and half length along z.
    Capsule(f64, f64),
    Cylinder(f64, f64),
    Mesh(TriMesh),
    Plane,
}

/// Contact values a file gives a geometry (each only if the file sets it).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactValues {
    pub friction_mu: Option<f64>,
    /// MuJoCo's solref (timeconst, dampratio), when set explicitly.
    pub solref: Option<[f64; 2]>,
    pub modulus_pa: Option<f64>,
    pub hunt_crossley_s_per_m: Option<f64>,
    pub relaxation_time_s: Option<f64>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Geom {
    pub name: String,
    pub shape: Shape,
    /// Pose in its body's frame.
    pub frame: Frame,
    /// Takes part in contact (MJCF contype/conaffinity not both 0; URDF `<collision>`).
    pub contact: bool,
    /// Mass properties it lends its body (MJCF geoms of a body without `<inertial>`), in
    /// the body's frame.
    pub mass: Option<MassProps>,
    pub values: ContactValues,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Joint {
    /// Welded to its parent.
    Weld,
    /// Free (a floating base).
    Free,
    /// A revolute joint: axis and anchor in the body's frame, range [rad].
    Hinge {
        axis: Vector3<f64>,
        anchor: Vector3<f64>,
        range: Option<[f64; 2]>,
        damping: f64,
        frictionloss: f64,
        solreflimit: Option<[f64; 2]>,
        /// The largest actuator torque the joint declares [N·m] (URDF `<limit effort>`,
        /// MJCF `actuatorfrcrange`): a limit on whatever drives the joint.
        effort_limit: Option<f64>,
    },
    /// Any other kind, by its name in the file.
    Other(String),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub name: String,
    /// Index of the parent body; None: the world.
    pub parent: Option<usize>,
    /// Pose in the parent's frame (the world's for a root).
    pub frame: Frame,
    pub joint: Joint,
    pub joint_name: String,
    /// Explicit inertial (body frame); else the geoms' masses.
    pub inertial: Option<MassProps>,
    pub geoms: Vec<Geom>,
}

impl Body {
    /// A link as a URDF or SDF file states it, before a joint hangs it on its parent: free,
    /// at the origin, with its inertial and collisions.
    pub fn link(name: &str, inertial: MassProps, geoms: Vec<Geom>) -> Body {
        Body {
            name: name.to_string(),
            parent: None,
            frame: Frame::IDENTITY,
            joint: Joint::Free,
            joint_name: String::new(),
            inertial: Some(inertial),
            geoms,
        }
    }

    /// The body's mass properties in its frame.
    pub fn mass_props(&self) -> MassProps {
        self.inertial.unwrap_or_else(|| {
            self.geoms
                .iter()
                .filter_map(|g| g.mass)
                .fold(MassProps::ZERO, |a, b| a.combined(&b))
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Actuator {
    /// A position servo kp·(ctrl − q) − kv·q̇ (MJCF `position`; Drake's PD gains).
    Position {
        joint: String,
        kp: f64,
        kv: f64,
        force_limit: Option<f64>,
    },
    /// A torque source (MJCF `motor`/`general`; URDF transmission without gains).
    Torque {
        joint: String,
        limit: Option<f64>,
        /// −∂τ/∂q̇ of a `general` actuator's affine bias (a DC motor's back-EMF line).
        velocity_damping: f64,
    },
}

/// A robot file in the neutral form.
#[derive(Clone, Debug)]
pub struct RobotFile {
    pub path: PathBuf,
    /// Lower-case hex sha256 of the file's bytes.
    pub sha256: String,
    /// Included files (MJCF `<include>`) with their sha256.
    pub includes: Vec<(PathBuf, String)>,
    pub format: &'static str,
    pub bodies: Vec<Body>,
    /// Geometry fixed to the world (a floor).
    pub world_geoms: Vec<Geom>,
    pub actuators: Vec<Actuator>,
    /// Gravity when the file sets it.
    pub gravity: Option<Vector3<f64>>,
    pub timestep_s: Option<f64>,
    /// MJCF `<custom>` numerics and texts by name.
    pub custom_numbers: BTreeMap<String, f64>,
    pub custom_texts: BTreeMap<String, String>,
}

pub(crate) fn sha256_hex(bytes: &[u8]) -> String {
    let h = Sha256::digest(bytes);
    h.iter().map(|b| format!("{b:02x}")).collect()
}

pub(super) fn read_text(path: &Path) -> Result<(String, String), InteropError> {
    let bytes = std::fs::read(path).map_err(|e| InteropError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let sha = sha256_hex(&bytes);
    let text = String::from_utf8(bytes).map_err(|_| InteropError::Read {
        path: path.to_path_buf(),
        message: "not UTF-8 text".into(),
    })?;
    Ok((text, sha))
}

/// An error about an element of a file, naming the file and the element's line.
pub(super) fn bad(
    path: &Path,
    doc: &roxmltree::Document,
    node: Node,
    message: String,
) -> InteropError {
    let pos = doc.text_pos_at(node.range().start);
    InteropError::Invalid {
        file: format!("{}:{}", path.display(), pos.row),
        message: format!("<{}>: {message}", node.tag_name().name()),
    }
}

/// Attribute `key` of element `n` as a finite number (an error naming the file and the
/// element when it is missing or not a number).
pub(super) fn attr_number(
    path: &Path,
    doc: &roxmltree::Document,
    n: Node,
    key: &str,
) -> Result<f64, InteropError> {
    let v = n
        .attribute(key)
        .ok_or_else(|| bad(path, doc, n, format!("no `{key}`")))?;
    v.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| bad(path, doc, n, format!("`{key}` = \"{v}\" is not a number")))
}

pub(super) fn parse_floats(s: &str) -> Option<Vec<f64>> {
    s.split_whitespace()
        .map(|t| t.parse::<f64>().ok())
        .collect()
}

pub(super) fn vec3(v: &[f64]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

pub(super) fn quat(w: f64, x: f64, y: f64, z: f64) -> Matrix3<f64> {
    *UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
        .to_rotation_matrix()
        .matrix()
}

pub(super) fn axis_angle(axis: Vector3<f64>, angle: f64) -> Matrix3<f64> {
    *Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle).matrix()
}

/// URDF roll-pitch-yaw: R = Rz(yaw)·Ry(pitch)·Rx(roll).
pub(super) fn rpy(r: f64, p: f64, y: f64) -> Matrix3<f64> {
    *Rotation3::from_euler_angles(r, p, y).matrix()
}

/// Mass properties of a shape in its frame: `mass` if given, else density × volume.
pub(super) fn shape_mass(shape: &Shape, mass: Option<f64>, density: f64) -> Option<MassProps> {
    use std::f64::consts::PI;
    let (vol, com, unit) = match shape {
        Shape::Sphere(r) => {
            let v = 4.0 / 3.0 * PI * r.powi(3);
            (v, Vector3::zeros(), Matrix3::identity() * (0.4 * r * r))
        }
        Shape::Ellipsoid(s) => {
            let v = 4.0 / 3.0 * PI * s.x * s.y * s.z;
            let d = Vector3::new(
                s.y * s.y + s.z * s.z,
                s.x * s.x + s.z * s.z,
                s.x * s.x + s.y * s.y,
            ) * 0.2;
            (v, Vector3::zeros(), Matrix3::from_diagonal(&d))
        }
        Shape::Box(h) => {
            let v = 8.0 * h.x * h.y * h.z;
            let d = Vector3::new(
                h.y * h.y + h.z * h.z,
                h.x * h.x + h.z * h.z,
                h.x * h.x + h.y * h.y,
            ) / 3.0;
            (v, Vector3::zeros(), Matrix3::from_diagonal(&d))
        }
        Shape::Cylinder(r, h) => {
            let v = PI * r * r * 2.0 * h;
            let ix = (3.0 * r * r + 4.0 * h * h) / 12.0;
            (
                v,
                Vector3::zeros(),
                Matrix3::from_diagonal(&Vector3::new(ix, ix, 0.5 * r * r)),
            )
        }
        Shape::Capsule(r, h) => {
            let vc = PI * r * r * 2.0 * h;
            let vs = 4.0 / 3.0 * PI * r.powi(3);
            let v = vc + vs;
            let iz = (vc * 0.5 * r * r + vs * 0.4 * r * r) / v;
            let ix =
                (vc * (r * r / 4.0 + h * h / 3.0) + vs * (0.4 * r * r + h * h + 0.75 * h * r)) / v;
            (
                v,
                Vector3::zeros(),
                Matrix3::from_diagonal(&Vector3::new(ix, ix, iz)),
            )
        }
        Shape::Mesh(m) => {
            let (v, c, i) = m.volume_props()?;
            (v, c, i / v)
        }
        Shape::Plane => return None,
    };
    let m = mass.unwrap_or(density * vol);
    (m > 0.0).then_some(MassProps {
        mass_kg: m,
        com_m: com,
        inertia_com_kgm2: unit * m,
    })
}

/// The links reordered so that every parent comes before its children (a file may list its
/// links in any order; world poses are composed parent first), with parent indices
/// renumbered; links whose joints form a loop are refused (`whose`: the format, for the
/// message, e.g. "a URDF's").
pub(super) fn parents_first(
    path: &Path,
    bodies: Vec<Body>,
    whose: &str,
) -> Result<Vec<Body>, InteropError> {
    let n = bodies.len();
    let mut order: Vec<usize> = (0..n).filter(|&i| bodies[i].parent.is_none()).collect();
    let mut k = 0;
    while k < order.len() {
        let p = order[k];
        order.extend((0..n).filter(|&i| bodies[i].parent == Some(p)));
        k += 1;
    }
    if order.len() < n {
        let looped: Vec<String> = (0..n)
            .filter(|i| !order.contains(i))
            .map(|i| format!("`{}`", bodies[i].name))
            .collect();
        return Err(InteropError::Invalid {
            file: path.display().to_string(),
            message: format!(
                "the joints of links {} form a loop ({whose} links form a tree)",
                looped.join(", ")
            ),
        });
    }
    let mut new_index = vec![0; n];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new;
    }
    let mut slots: Vec<Option<Body>> = bodies.into_iter().map(Some).collect();
    Ok(order
        .iter()
        .filter_map(|&old| slots[old].take())
        .map(|mut b| {
            b.parent = b.parent.map(|p| new_index[p]);
            b
        })
        .collect())
}
