//! URDF (with Drake's extensions: `drake:ellipsoid`, `drake:capsule`,
//! `<drake:proximity_properties>`, `<drake:controller_gains>`) read into the neutral form of
//! `robot_file.rs`: links, joints (fixed links merged later), inertials, collisions, and the
//! transmissions' PD gains.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use nalgebra::{Matrix3, Vector3};
use roxmltree::Node;

use super::InteropError;
use super::mesh::{MassProps, read_mesh};
use super::robot_file::{
    Actuator, Body, ContactValues, Frame, Geom, Joint, RobotFile, Shape, attr_number, bad,
    parents_first, parse_floats, rpy, vec3,
};

/// A URDF `<origin xyz rpy>` (absent: identity).
fn urdf_origin(
    path: &Path,
    doc: &roxmltree::Document,
    parent: Node,
) -> Result<Frame, InteropError> {
    let Some(o) = parent.children().find(|n| n.has_tag_name("origin")) else {
        return Ok(Frame::IDENTITY);
    };
    let get = |k: &str| -> Result<Vector3<f64>, InteropError> {
        match o.attribute(k) {
            None => Ok(Vector3::zeros()),
            Some(v) => match parse_floats(v) {
                Some(x) if x.len() == 3 => Ok(vec3(&x)),
                _ => Err(bad(
                    path,
                    doc,
                    o,
                    format!("`{k}` = \"{v}\": expected 3 numbers"),
                )),
            },
        }
    };
    let r = get("rpy")?;
    Ok(Frame {
        r: rpy(r.x, r.y, r.z),
        p: get("xyz")?,
    })
}

fn urdf_geometry(path: &Path, doc: &roxmltree::Document, g: Node) -> Result<Shape, InteropError> {
    let s = g
        .children()
        .find(|n| n.is_element())
        .ok_or_else(|| bad(path, doc, g, "empty <geometry>".into()))?;
    let v = |k: &str| attr_number(path, doc, s, k);
    Ok(match s.tag_name().name() {
        "sphere" => Shape::Sphere(v("radius")?),
        "ellipsoid" => Shape::Ellipsoid(Vector3::new(v("a")?, v("b")?, v("c")?)),
        "box" => {
            let size = s
                .attribute("size")
                .and_then(parse_floats)
                .filter(|x| x.len() == 3);
            Shape::Box(
                vec3(&size.ok_or_else(|| bad(path, doc, s, "`size` needs 3 numbers".into()))?)
                    * 0.5,
            )
        }
        "cylinder" => Shape::Cylinder(v("radius")?, 0.5 * v("length")?),
        "capsule" => Shape::Capsule(v("radius")?, 0.5 * v("length")?),
        "mesh" => {
            let f = s.attribute("filename").unwrap_or("");
            if f.starts_with("package://") || f.starts_with("model://") {
                return Err(bad(
                    path,
                    doc,
                    s,
                    format!(
                        "mesh `{f}`: package URIs are not resolved; give a path relative to the file"
                    ),
                ));
            }
            let f = f.strip_prefix("file://").unwrap_or(f);
            let scale = s
                .attribute("scale")
                .and_then(parse_floats)
                .map(|x| {
                    if x.len() == 3 {
                        vec3(&x)
                    } else {
                        Vector3::repeat(x.first().copied().unwrap_or(1.0))
                    }
                })
                .unwrap_or_else(|| Vector3::repeat(1.0));
            Shape::Mesh(
                read_mesh(&path.parent().unwrap_or(Path::new(".")).join(f), scale)
                    .map_err(|e| bad(path, doc, s, e.to_string()))?,
            )
        }
        other => return Err(bad(path, doc, s, format!("geometry <{other}> is not read"))),
    })
}

/// Drake's `<drake:proximity_properties>` values of a collision.
fn drake_values(c: Node) -> ContactValues {
    let mut v = ContactValues::default();
    let Some(pp) = c
        .children()
        .find(|n| n.tag_name().name() == "proximity_properties")
    else {
        return v;
    };
    for p in pp.children().filter(|n| n.is_element()) {
        let x = p
            .attribute("value")
            .and_then(|s| s.trim().parse::<f64>().ok());
        match p.tag_name().name() {
            "hydroelastic_modulus" => v.modulus_pa = x,
            "hunt_crossley_dissipation" => v.hunt_crossley_s_per_m = x,
            "relaxation_time" => v.relaxation_time_s = x,
            "mu_dynamic" => v.friction_mu = x,
            _ => {}
        }
    }
    v
}

/// A link's `<inertial>`: mass and inertia about the COM, in the link's frame (products
/// of inertia absent are zero).
fn read_inertial(
    path: &Path,
    doc: &roxmltree::Document,
    i: Node,
) -> Result<MassProps, InteropError> {
    let f = urdf_origin(path, doc, i)?;
    let m = i
        .children()
        .find(|n| n.has_tag_name("mass"))
        .ok_or_else(|| bad(path, doc, i, "no <mass>".into()))?;
    let t = i
        .children()
        .find(|n| n.has_tag_name("inertia"))
        .ok_or_else(|| bad(path, doc, i, "no <inertia>".into()))?;
    let g = |k: &str| {
        attr_number(path, doc, t, k).or_else(|e| {
            if t.attribute(k).is_none() && k.len() == 3 && k.as_bytes()[1] != k.as_bytes()[2] {
                Ok(0.0)
            } else {
                Err(e)
            }
        })
    };
    let inertia = Matrix3::new(
        g("ixx")?,
        g("ixy")?,
        g("ixz")?,
        g("ixy")?,
        g("iyy")?,
        g("iyz")?,
        g("ixz")?,
        g("iyz")?,
        g("izz")?,
    );
    Ok(MassProps {
        mass_kg: attr_number(path, doc, m, "value")?,
        com_m: Vector3::zeros(),
        inertia_com_kgm2: inertia,
    }
    .transformed(&f.r, &f.p))
}

/// A `<link>` as a body (free until a joint names it as a child): its inertial and its
/// collisions.
fn read_link(path: &Path, doc: &roxmltree::Document, l: Node) -> Result<Body, InteropError> {
    let name = l
        .attribute("name")
        .ok_or_else(|| bad(path, doc, l, "no `name`".into()))?;
    let inertial = match l.children().find(|n| n.has_tag_name("inertial")) {
        None => None,
        Some(i) => Some(read_inertial(path, doc, i)?),
    };
    let mut geoms = Vec::new();
    for c in l.children().filter(|n| n.has_tag_name("collision")) {
        let g = c
            .children()
            .find(|n| n.has_tag_name("geometry"))
            .ok_or_else(|| bad(path, doc, c, "no <geometry>".into()))?;
        geoms.push(Geom {
            name: c.attribute("name").unwrap_or(name).to_string(),
            shape: urdf_geometry(path, doc, g)?,
            frame: urdf_origin(path, doc, c)?,
            contact: true,
            mass: None,
            values: drake_values(c),
        });
    }
    Ok(Body::link(name, inertial.unwrap_or(MassProps::ZERO), geoms))
}

/// A joint's kind: fixed (a weld), floating, revolute or continuous (a hinge with its axis,
/// a revolute one's limits, damping and friction), or another kind by name.
fn joint_kind(
    path: &Path,
    doc: &roxmltree::Document,
    j: Node,
    kind: &str,
    limit: Option<Node>,
) -> Result<Joint, InteropError> {
    let dynamics = j.children().find(|n| n.has_tag_name("dynamics"));
    let dyn_value = |k: &str| match dynamics.filter(|d| d.attribute(k).is_some()) {
        Some(d) => attr_number(path, doc, d, k),
        None => Ok(0.0),
    };
    Ok(match kind {
        "fixed" => Joint::Weld,
        "floating" => Joint::Free,
        "revolute" | "continuous" => {
            let axis = match j.children().find(|n| n.has_tag_name("axis")) {
                None => Vector3::x(),
                Some(a) => {
                    let v = a.attribute("xyz").unwrap_or("");
                    match parse_floats(v) {
                        Some(x) if x.len() == 3 && x.iter().all(|c| c.is_finite()) => vec3(&x),
                        _ => {
                            return Err(bad(
                                path,
                                doc,
                                a,
                                format!("`xyz` = \"{v}\": expected 3 numbers"),
                            ));
                        }
                    }
                }
            };
            if axis.norm() == 0.0 {
                return Err(bad(path, doc, j, "the joint's axis is zero".into()));
            }
            let range = match (kind, limit) {
                ("revolute", Some(l)) => Some([
                    attr_number(path, doc, l, "lower")?,
                    attr_number(path, doc, l, "upper")?,
                ]),
                _ => None,
            };
            let effort_limit = match limit.filter(|l| l.attribute("effort").is_some()) {
                Some(l) => Some(attr_number(path, doc, l, "effort")?).filter(|e| *e > 0.0),
                None => None,
            };
            Joint::Hinge {
                axis: axis.normalize(),
                anchor: Vector3::zeros(),
                range,
                damping: dyn_value("damping")?,
                frictionloss: dyn_value("friction")?,
                solreflimit: None,
                effort_limit,
            }
        }
        other => Joint::Other(other.to_string()),
    })
}

/// A `<joint>`: hangs its child link on its parent (noting its effort limit by name).
fn read_joint(
    path: &Path,
    doc: &roxmltree::Document,
    j: Node,
    index: &HashMap<String, usize>,
    bodies: &mut [Body],
    efforts: &mut HashMap<String, f64>,
) -> Result<(), InteropError> {
    let link = |tag: &str| -> Result<usize, InteropError> {
        let n = j
            .children()
            .find(|n| n.has_tag_name(tag))
            .ok_or_else(|| bad(path, doc, j, format!("no <{tag}>")))?;
        let l = n.attribute("link").unwrap_or("");
        index
            .get(l)
            .copied()
            .ok_or_else(|| bad(path, doc, n, format!("link `{l}` is not defined")))
    };
    let (parent, child) = (link("parent")?, link("child")?);
    let name = j.attribute("name").unwrap_or("").to_string();
    let kind = j.attribute("type").unwrap_or("");
    let limit = j.children().find(|n| n.has_tag_name("limit"));
    let joint = joint_kind(path, doc, j, kind, limit)?;
    if let Joint::Hinge {
        effort_limit: Some(e),
        ..
    } = joint
    {
        efforts.insert(name.clone(), e);
    }
    let b = &mut bodies[child];
    if b.parent.is_some() {
        return Err(bad(
            path,
            doc,
            j,
            format!("link `{}` is the child of two joints", b.name),
        ));
    }
    b.parent = Some(parent);
    b.frame = urdf_origin(path, doc, j)?;
    b.joint = joint;
    b.joint_name = name;
    Ok(())
}

/// A `<transmission>`'s actuator: a position servo with Drake's PD gains, else a torque
/// motor, limited by its joint's effort.
fn read_transmission(
    path: &Path,
    doc: &roxmltree::Document,
    t: Node,
    efforts: &HashMap<String, f64>,
) -> Result<Actuator, InteropError> {
    let joint = t
        .children()
        .find(|n| n.has_tag_name("joint"))
        .and_then(|j| j.attribute("name"))
        .unwrap_or("")
        .to_string();
    let gains = t
        .descendants()
        .find(|n| n.tag_name().name() == "controller_gains");
    let limit = efforts.get(&joint).copied().filter(|e| *e > 0.0);
    Ok(match gains {
        Some(g) => Actuator::Position {
            kp: attr_number(path, doc, g, "p")?,
            kv: attr_number(path, doc, g, "d")?,
            force_limit: limit,
            joint,
        },
        None => Actuator::Torque {
            joint,
            limit,
            velocity_damping: 0.0,
        },
    })
}

pub(super) fn read(
    path: &Path,
    doc: &roxmltree::Document,
    sha: String,
) -> Result<RobotFile, InteropError> {
    let root = doc.root_element();
    let mut bodies = Vec::new();
    let mut index = HashMap::new();
    for l in root.children().filter(|n| n.has_tag_name("link")) {
        let body = read_link(path, doc, l)?;
        index.insert(body.name.clone(), bodies.len());
        bodies.push(body);
    }
    let mut efforts = HashMap::new();
    for j in root.children().filter(|n| n.has_tag_name("joint")) {
        read_joint(path, doc, j, &index, &mut bodies, &mut efforts)?;
    }
    let bodies = parents_first(path, bodies, "a URDF's")?;
    let mut actuators = Vec::new();
    for t in root.children().filter(|n| n.has_tag_name("transmission")) {
        actuators.push(read_transmission(path, doc, t, &efforts)?);
    }
    Ok(RobotFile {
        path: path.to_path_buf(),
        sha256: sha,
        includes: Vec::new(),
        format: "URDF",
        bodies,
        world_geoms: Vec::new(),
        actuators,
        gravity: None,
        timestep_s: None,
        custom_numbers: BTreeMap::new(),
        custom_texts: BTreeMap::new(),
    })
}
