//! The two legs of a robot file in the walker's frame: which bodies make each leg, the hip
//! axis and point, each leg's mass properties and foot (see `import.rs` for the rules).

use nalgebra::{Matrix3, Vector3};

use super::InteropError;
use super::mesh::{MassProps, TriMesh, ellipsoid_section, fit_ellipsoid};
use super::robot_file::{Body, Frame, Geom, Joint, RobotFile, Shape};
use crate::sim::GRAVITY_MPS2;

mod foot_shapes;

/// A leg as read: mass properties and foot in the walker's frame (hip point at the origin).
pub(super) struct LegRead {
    pub(super) name: String,
    pub(super) mass: MassProps,
    pub(super) foot_center: Vector3<f64>,
    pub(super) foot_semi: Vector3<f64>,
    pub(super) foot_name: String,
    pub(super) foot_how: String,
    /// Inner lateral edge of a mesh foot (side·y), when it cuts the ellipsoid.
    pub(super) cut: Option<f64>,
}

pub(super) fn topo(f: &RobotFile, message: String) -> InteropError {
    InteropError::Topology {
        file: f.path.display().to_string(),
        message,
    }
}

/// World pose of every body at the file's configuration (joints at zero).
pub(super) fn world_frames(f: &RobotFile) -> Vec<Frame> {
    let mut out: Vec<Frame> = Vec::with_capacity(f.bodies.len());
    for b in &f.bodies {
        let parent = b.parent.map(|p| out[p]).unwrap_or(Frame::IDENTITY);
        out.push(parent.then(&b.frame));
    }
    out
}

/// The hinge's body, when the file moves by one revolute hip and at most one free base;
/// else what its moving joints are and what is missing.
fn the_hinge(f: &RobotFile) -> Result<usize, InteropError> {
    let moving: Vec<(usize, &Body)> = f
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| !matches!(b.joint, Joint::Weld))
        .collect();
    let kinds: Vec<String> = moving
        .iter()
        .map(|(_, b)| {
            let k = match &b.joint {
                Joint::Free => "free".to_string(),
                Joint::Hinge { .. } => "revolute".into(),
                Joint::Other(o) => o.clone(),
                Joint::Weld => unreachable!("filtered"),
            };
            format!("`{}` ({k}) on body `{}`", b.joint_name, b.name)
        })
        .collect();
    let hinges: Vec<usize> = moving
        .iter()
        .filter(|(_, b)| matches!(b.joint, Joint::Hinge { .. }))
        .map(|(i, _)| *i)
        .collect();
    let frees: Vec<usize> = moving
        .iter()
        .filter(|(_, b)| matches!(b.joint, Joint::Free))
        .map(|(i, _)| *i)
        .collect();
    let others = moving.len() - hinges.len() - frees.len();
    if hinges.len() != 1 || frees.len() > 1 || others > 0 {
        return Err(topo(
            f,
            format!(
                "a walker is two legs joined by one revolute hip, with the first leg free; found {} moving joint(s): {}{}",
                moving.len(),
                if kinds.is_empty() {
                    "none".to_string()
                } else {
                    kinds.join(", ")
                },
                if hinges.is_empty() {
                    " — the revolute hip is missing"
                } else if hinges.len() > 1 {
                    " — more than one revolute joint (extra links must be fixed to a leg)"
                } else if others > 0 {
                    " — only a free base and a revolute hip are read"
                } else {
                    " — more than one free body"
                }
            ),
        ));
    }
    Ok(hinges[0])
}

/// Which leg (0 base, 1 hip) each body belongs to, and the hinge's body; or what is missing.
fn legs_of(f: &RobotFile) -> Result<(Vec<Option<usize>>, usize), InteropError> {
    let hinge = the_hinge(f)?;
    // Each body's leg: walk up welded parents to the nearest moving body.
    let mut leg = vec![None; f.bodies.len()];
    for (i, slot) in leg.iter_mut().enumerate() {
        let mut j = i;
        loop {
            match &f.bodies[j].joint {
                Joint::Weld => match f.bodies[j].parent {
                    Some(p) => j = p,
                    None => break,
                },
                _ => {
                    *slot = Some(if j == hinge { 1 } else { 0 });
                    break;
                }
            }
        }
    }
    // The hinge must hang on the base leg (or, in a URDF, on the root link: the base).
    let parent = f.bodies[hinge].parent.ok_or_else(|| {
        topo(
            f,
            format!("the hip `{}` has no parent leg", f.bodies[hinge].joint_name),
        )
    })?;
    if leg[parent] != Some(0) {
        return Err(topo(
            f,
            format!(
                "the hip `{}` does not hang on the free base leg",
                f.bodies[hinge].joint_name
            ),
        ));
    }
    if !leg.contains(&Some(0)) {
        return Err(topo(f, "no free base leg".into()));
    }
    Ok((leg, hinge))
}

/// The walker's frame: rotation (columns x, y, z in world) and hip point.
pub(super) struct WalkerFrame {
    pub(super) r: Matrix3<f64>,
    pub(super) hip: Vector3<f64>,
    /// −1 when y is opposite the file's hinge axis (q then has the opposite sign).
    pub(super) axis_sign: f64,
}

impl WalkerFrame {
    pub(super) fn point(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.r.transpose() * (p - self.hip)
    }
}

fn walker_frame(
    f: &RobotFile,
    frames: &[Frame],
    hinge: usize,
    coms: [Vector3<f64>; 2],
) -> Result<WalkerFrame, InteropError> {
    let Joint::Hinge { axis, anchor, .. } = &f.bodies[hinge].joint else {
        unreachable!("legs_of found a hinge")
    };
    let fr = &frames[hinge];
    let a = (fr.r * axis).normalize();
    let anchor_w = fr.r * anchor + fr.p;
    let up = -f
        .gravity
        .unwrap_or(Vector3::new(0.0, 0.0, -GRAVITY_MPS2))
        .normalize();
    if a.dot(&up).abs() > 0.5 {
        return Err(topo(
            f,
            format!(
                "the hip axis is {:.0}° from vertical at the file's pose: a walker's hip axis is lateral (horizontal)",
                a.dot(&up).abs().acos().to_degrees()
            ),
        ));
    }
    let d = coms[0] - coms[1];
    let sign = if d.dot(&a) < 0.0 { -1.0 } else { 1.0 };
    let y = a * sign;
    let z = (up - y * up.dot(&y)).normalize();
    let x = y.cross(&z);
    let mid = 0.5 * (coms[0] + coms[1]);
    let hip = anchor_w + a * (mid - anchor_w).dot(&a);
    Ok(WalkerFrame {
        r: Matrix3::from_columns(&[x, y, z]),
        hip,
        axis_sign: sign,
    })
}

/// A geometry's surface at `fr` (its frame in the walker's), for the fit: a sphere's or
/// ellipsoid's as a mesh, a mesh as it is, a box's, cylinder's or capsule's surface points
/// (no triangles: only the hull's support points are used). None for a plane.
fn geom_points(g: &Geom, fr: &Frame) -> Option<TriMesh> {
    let whole =
        |semi: Vector3<f64>| ellipsoid_section(&Vector3::zeros(), &semi, 1.0, -semi.y * 2.0);
    let m = match &g.shape {
        Shape::Sphere(r) => whole(Vector3::repeat(*r)),
        Shape::Ellipsoid(s) => whole(*s),
        Shape::Mesh(m) => m.clone(),
        other => TriMesh {
            vertices: foot_shapes::surface_points(other)?,
            triangles: Vec::new(),
        },
    };
    Some(m.transformed(&fr.r, &fr.p))
}

/// Is `r` a signed permutation (the geometry's axes along the walker's)?
fn axis_permutation(r: &Matrix3<f64>) -> Option<[usize; 3]> {
    let mut perm = [0; 3];
    for (i, p) in perm.iter_mut().enumerate() {
        let row = r.row(i);
        let (j, v) = row.iter().enumerate().fold((0, 0.0f64), |acc, (j, v)| {
            if v.abs() > acc.1.abs() { (j, *v) } else { acc }
        });
        if (v.abs() - 1.0).abs() > 1e-6 {
            return None;
        }
        *p = j;
    }
    Some(perm)
}

/// A foot as read: centre, semi-axes, geometry name, how it was read, the inner edge of a
/// section.
type Foot = (Vector3<f64>, Vector3<f64>, String, String, Option<f64>);

/// A leg's lowest collision geometry: its lowest height, the geometry, its frame in the
/// walker's and its surface there; or the error saying the leg has none.
fn lowest_geom<'a>(
    f: &RobotFile,
    geoms: &'a [(Geom, Frame)],
    leg_name: &str,
) -> Result<(f64, &'a Geom, Frame, TriMesh), InteropError> {
    let mut best: Option<(f64, &Geom, Frame, TriMesh)> = None;
    for (g, to_w) in geoms.iter().filter(|(g, _)| g.contact) {
        let fr = to_w.then(&g.frame);
        let (Some(m), Some(low)) = (geom_points(g, &fr), foot_shapes::lowest_z(&g.shape, &fr))
        else {
            continue;
        };
        if best.as_ref().is_none_or(|b| low < b.0) {
            best = Some((low, g, fr, m));
        }
    }
    best.ok_or_else(|| {
        let kinds: Vec<String> = geoms
            .iter()
            .filter(|(g, _)| g.contact)
            .map(|(g, _)| format!("`{}` ({})", g.name, shape_word(&g.shape)))
            .collect();
        topo(
            f,
            format!(
                "leg `{leg_name}` has no foot: {}; a foot is a leg's lowest sphere, ellipsoid, capsule, box, cylinder or mesh collision geometry",
                if kinds.is_empty() {
                    "it has no collision geometry".to_string()
                } else {
                    format!("its only collision geometry is {}", kinds.join(", "))
                }
            ),
        )
    })
}

fn read_foot(
    f: &RobotFile,
    geoms: &[(Geom, Frame)],
    leg_name: &str,
    side: f64,
) -> Result<Foot, InteropError> {
    let (low, g, fr, m) = lowest_geom(f, geoms, leg_name)?;
    let exact = match &g.shape {
        Shape::Sphere(r) => Some((fr.p, Vector3::repeat(*r), "as it is".to_string())),
        Shape::Ellipsoid(s) => axis_permutation(&fr.r).map(|p| {
            let semi = Vector3::new(s[p[0]], s[p[1]], s[p[2]]);
            (fr.p, semi, "as it is".to_string())
        }),
        other => foot_shapes::upright_capsule_end(other, &fr).map(|(c, r)| {
            let how = format!(
                "within {}° of vertical: the sphere of its radius about its lower end point (exactly the capsule near the ground)",
                foot_shapes::UPRIGHT_CAPSULE_DEG
            );
            (c, Vector3::repeat(r), how)
        }),
    };
    if let Some((c, semi, how)) = exact {
        return Ok((
            c,
            semi,
            g.name.clone(),
            format!("{} `{}` {how}", shape_word(&g.shape), g.name),
            None,
        ));
    }
    // The hull's support points within 60° of straight down: the walkers roll and pitch
    // well within that.
    let pts = m.support_points(&-Vector3::z(), 60f64.to_radians());
    let mut fit = fit_ellipsoid(&pts).ok_or_else(|| {
        topo(
            f,
            format!(
                "foot `{}` of leg `{leg_name}`: too few ground-facing points to fit an ellipsoid",
                g.name
            ),
        )
    })?;
    // A box, cylinder or capsule: the fit of its few corner or rim points need not stand
    // where the geometry does (four corners of a flat face pin no height), so it is set
    // down on the geometry's lowest point: the file's standing height is kept.
    let primitive = !matches!(g.shape, Shape::Mesh(_) | Shape::Ellipsoid(_));
    let placed = if primitive {
        let dz = low - (fit.center_m.z - fit.semi_axes_m.z);
        fit = fit.moved_z(dz, &pts);
        format!(
            ", moved {:.2} mm {} so its lowest point is the {}'s",
            dz.abs() * 1e3,
            if dz >= 0.0 { "up" } else { "down" },
            shape_word(&g.shape)
        )
    } else {
        String::new()
    };
    let how = format!(
        "best-fitting {} of the {} convex-hull points of {} `{}` a floor touches within 60° of upright{placed} (rms {:.2} mm{}; the file's geometry replaced)",
        if fit.sphere { "sphere" } else { "ellipsoid" },
        pts.len(),
        shape_word(&g.shape),
        g.name,
        fit.rms_m * 1e3,
        if primitive { " as placed" } else { "" },
    );
    let inner = m
        .vertices
        .iter()
        .map(|v| side * v.y)
        .fold(f64::INFINITY, f64::min);
    let edge = side * fit.center_m.y - fit.semi_axes_m.y;
    // A section is the design's outer part of a foot on its own leg's side; a foot under the
    // other leg (crossed) has none the design can say.
    let own_side = side * fit.center_m.y >= -0.01 * fit.semi_axes_m.y;
    let cut =
        (matches!(g.shape, Shape::Mesh(_)) && own_side && inner > edge + 0.02 * fit.semi_axes_m.y)
            .then_some(inner);
    Ok((fit.center_m, fit.semi_axes_m, g.name.clone(), how, cut))
}

pub(super) fn shape_word(s: &Shape) -> &'static str {
    match s {
        Shape::Sphere(_) => "sphere",
        Shape::Ellipsoid(_) => "ellipsoid",
        Shape::Mesh(_) => "mesh",
        Shape::Box(_) => "box",
        Shape::Capsule(..) => "capsule",
        Shape::Cylinder(..) => "cylinder",
        Shape::Plane => "plane",
    }
}

/// Reads the two legs in the walker's frame.
pub(super) fn read_legs(f: &RobotFile) -> Result<([LegRead; 2], WalkerFrame), InteropError> {
    let (leg, hinge) = legs_of(f)?;
    let frames = world_frames(f);
    let mut mass = [MassProps::ZERO; 2];
    for (i, b) in f.bodies.iter().enumerate() {
        if let Some(k) = leg[i] {
            let fr = &frames[i];
            mass[k] = mass[k].combined(&b.mass_props().transformed(&fr.r, &fr.p));
        }
    }
    for (k, m) in mass.iter().enumerate() {
        if m.mass_kg.is_nan() || m.mass_kg <= 0.0 {
            return Err(topo(
                f,
                format!(
                    "the {} leg has no mass (no inertial and no geometry with mass)",
                    ["base", "hip"][k]
                ),
            ));
        }
    }
    let wf = walker_frame(f, &frames, hinge, [mass[0].com_m, mass[1].com_m])?;
    let to_walker = |fr: &Frame| Frame {
        r: wf.r.transpose() * fr.r,
        p: wf.point(&fr.p),
    };
    let names = [0usize, 1].map(|k| {
        f.bodies
            .iter()
            .zip(&leg)
            .filter(|(_, l)| **l == Some(k))
            .map(|(b, _)| b.name.clone())
            .collect::<Vec<_>>()
            .join("+")
    });
    let mut out = Vec::new();
    for k in 0..2 {
        let geoms: Vec<(Geom, Frame)> = f
            .bodies
            .iter()
            .enumerate()
            .filter(|(i, _)| leg[*i] == Some(k))
            .flat_map(|(i, b)| b.geoms.iter().map(move |g| (g.clone(), i)))
            .map(|(g, i)| (g, to_walker(&frames[i])))
            .collect();
        let side = if k == 0 { 1.0 } else { -1.0 };
        let (c, s, foot_name, how, cut) = read_foot(f, &geoms, &names[k], side)?;
        let m = mass[k].transformed(&wf.r.transpose(), &(-(wf.r.transpose() * wf.hip)));
        out.push(LegRead {
            name: names[k].clone(),
            mass: m,
            foot_center: c,
            foot_semi: s,
            foot_name,
            foot_how: how,
            cut,
        });
    }
    let [a, b]: [LegRead; 2] = out
        .try_into()
        .map_err(|_| topo(f, "two legs expected".into()))?;
    Ok(([a, b], wf))
}
