//! SDFormat 1.5–1.11 (with Drake's extensions: `<drake:proximity_properties>`,
//! `<drake:controller_gains>`) read into the neutral form of `robot_file.rs`: one `<model>`
//! (directly under `<sdf>` or the only one of a `<world>`), its links, joints (fixed links
//! merged later), inertials, collisions, and the hip's PD gains.
//!
//! Poses follow the spec: `<model><pose>` places the model in the world; a link's pose is in
//! the model frame, an inertial's or a collision's in its link's frame, a joint's in its
//! child link's frame, each unless `relative_to` names another link or `__model__` (the only
//! frames read: joint frames, `<frame>` elements and nested models are refused). A joint's
//! axis is in the joint frame unless `expressed_in` (or SDF 1.5–1.6's `use_parent_model_frame`)
//! says otherwise. Values the file leaves out take the spec's defaults (a link without
//! `<inertial>` has 1 kg and unit moments, as Drake and Gazebo give it).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use nalgebra::{Matrix3, Vector3};
use roxmltree::{Document, Node};

use super::InteropError;
use super::mesh::{MassProps, read_mesh};
use super::robot_file::{
    Actuator, Body, ContactValues, Frame, Geom, Joint, RobotFile, Shape, attr_number, bad,
    parents_first, parse_floats, rpy, vec3,
};

/// What the reader says it supports when a frame reference is not one of them.
const FRAMES_READ: &str = "only a link of this model or `__model__` is supported (not joint frames, <frame> elements or nested models)";

/// The first child element whose local name is `tag` (Drake's `drake:` ones included).
fn child<'a, 'i>(n: Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
    n.children()
        .find(|c| c.is_element() && c.tag_name().name() == tag)
}

/// A `<pose>` as a frame, with the `<pose>` element and the frame it names in `relative_to`
/// (None: the element's default frame).
type Pose<'a, 'i> = (Frame, Option<(Node<'a, 'i>, &'a str)>);

/// The file being read: its path, document and the model's links by name.
struct Sdf<'a, 'i> {
    path: &'a Path,
    doc: &'a Document<'i>,
    links: HashMap<&'a str, Node<'a, 'i>>,
}

impl<'a, 'i> Sdf<'a, 'i> {
    fn err(&self, n: Node, message: String) -> InteropError {
        bad(self.path, self.doc, n, message)
    }

    /// An element's text as a finite number.
    fn number(&self, n: Node) -> Result<f64, InteropError> {
        let t = n.text().unwrap_or("").trim();
        t.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| self.err(n, format!("\"{t}\" is not a number")))
    }

    /// The number of child `tag` of `n`, if it has one.
    fn opt(&self, n: Node, tag: &str) -> Result<Option<f64>, InteropError> {
        child(n, tag).map(|c| self.number(c)).transpose()
    }

    /// The number of child `tag` of `n`, which must be there.
    fn req(&self, n: Node, tag: &str) -> Result<f64, InteropError> {
        self.opt(n, tag)?
            .ok_or_else(|| self.err(n, format!("no <{tag}>")))
    }

    /// An element's text as `k` finite numbers.
    fn numbers(&self, n: Node, k: usize) -> Result<Vec<f64>, InteropError> {
        let t = n.text().unwrap_or("").trim();
        parse_floats(t)
            .filter(|x| x.len() == k && x.iter().all(|c| c.is_finite()))
            .ok_or_else(|| self.err(n, format!("\"{t}\": expected {k} numbers")))
    }

    /// `n`'s `<pose>` as a frame and the frame it is relative to (None: the default one).
    fn pose(&self, n: Node<'a, 'i>) -> Result<Pose<'a, 'i>, InteropError> {
        let Some(p) = child(n, "pose") else {
            return Ok((Frame::IDENTITY, None));
        };
        if let Some(f) = p.attribute("rotation_format").filter(|f| *f != "euler_rpy") {
            return Err(self.err(
                p,
                format!("rotation_format=\"{f}\": only euler_rpy (x y z roll pitch yaw) is read"),
            ));
        }
        let v = if p.text().unwrap_or("").trim().is_empty() {
            vec![0.0; 6]
        } else {
            self.numbers(p, 6)?
        };
        let deg = match p.attribute("degrees") {
            None | Some("false") | Some("0") => false,
            Some("true") | Some("1") => true,
            Some(o) => return Err(self.err(p, format!("degrees=\"{o}\" is not true or false"))),
        };
        let a = if deg { 1f64.to_radians() } else { 1.0 };
        let frame = Frame {
            r: rpy(v[3] * a, v[4] * a, v[5] * a),
            p: Vector3::new(v[0], v[1], v[2]),
        };
        // SDFormat 1.5/1.6 name the frame in `frame` (Gazebo writes `frame=''`: the default).
        let rel = p
            .attribute("relative_to")
            .or_else(|| p.attribute("frame"))
            .filter(|r| !r.is_empty())
            .map(|r| (p, r));
        Ok((frame, rel))
    }

    /// The pose of the named frame in the model frame (`at` is the element naming it).
    fn frame_in_model(
        &self,
        at: Node,
        name: &str,
        stack: &mut Vec<String>,
    ) -> Result<Frame, InteropError> {
        if name == "__model__" {
            return Ok(Frame::IDENTITY);
        }
        let Some(&l) = self.links.get(name) else {
            let attr = if at.has_attribute("expressed_in") {
                "expressed_in"
            } else {
                "relative_to"
            };
            return Err(self.err(
                at,
                format!("{attr}=\"{name}\" is not a link of this model: {FRAMES_READ}"),
            ));
        };
        if stack.iter().any(|s| s == name) {
            return Err(self.err(
                at,
                format!(
                    "the link poses of {} are relative to each other in a loop",
                    stack.join(" → ")
                ),
            ));
        }
        stack.push(name.to_string());
        let (pose, rel) = self.pose(l)?;
        let out = match rel {
            None => pose,
            Some((p, r)) => self.frame_in_model(p, r, stack)?.then(&pose),
        };
        stack.pop();
        Ok(out)
    }

    /// A link's pose in the model frame.
    fn link_in_model(&self, name: &str) -> Result<Frame, InteropError> {
        let l = self.links[name];
        self.frame_in_model(l, name, &mut Vec::new())
    }

    /// The pose of `n`'s `<pose>` in link `link`'s frame, its default frame being that link.
    fn pose_in_link(&self, n: Node<'a, 'i>, link: &str) -> Result<Frame, InteropError> {
        let (pose, rel) = self.pose(n)?;
        match rel {
            None => Ok(pose),
            Some((_, r)) if r == link => Ok(pose),
            Some((p, r)) => {
                let x_mr = self.frame_in_model(p, r, &mut Vec::new())?;
                Ok(self.link_in_model(link)?.inverse().then(&x_mr.then(&pose)))
            }
        }
    }
}

impl<'a, 'i> Sdf<'a, 'i> {
    /// A `<geometry>`'s shape.
    fn geometry(&self, g: Node) -> Result<Shape, InteropError> {
        let s = g
            .children()
            .find(|n| n.is_element())
            .ok_or_else(|| self.err(g, "empty <geometry>".into()))?;
        Ok(match s.tag_name().name() {
            "sphere" => Shape::Sphere(self.req(s, "radius")?),
            "box" => {
                let size = child(s, "size").ok_or_else(|| self.err(s, "no <size>".into()))?;
                Shape::Box(vec3(&self.numbers(size, 3)?) * 0.5)
            }
            "cylinder" => Shape::Cylinder(self.req(s, "radius")?, 0.5 * self.req(s, "length")?),
            "capsule" => Shape::Capsule(self.req(s, "radius")?, 0.5 * self.req(s, "length")?),
            "ellipsoid" => {
                let r = child(s, "radii").ok_or_else(|| self.err(s, "no <radii>".into()))?;
                Shape::Ellipsoid(vec3(&self.numbers(r, 3)?))
            }
            "plane" => Shape::Plane,
            "mesh" => self.mesh(s)?,
            other => {
                return Err(self.err(
                    s,
                    format!("geometry <{other}> is not read (sphere, box, cylinder, capsule, ellipsoid, mesh, plane are)"),
                ));
            }
        })
    }

    /// A `<mesh>`: its `<uri>` relative to the file (or `file://`), scaled by `<scale>`.
    fn mesh(&self, s: Node) -> Result<Shape, InteropError> {
        let u = child(s, "uri").ok_or_else(|| self.err(s, "no <uri>".into()))?;
        let uri = u.text().unwrap_or("").trim();
        if uri.starts_with("model://")
            || uri.starts_with("package://")
            || uri.contains("://") && !uri.starts_with("file://")
        {
            return Err(self.err(
                u,
                format!("mesh `{uri}`: model://, package:// and other URIs are not resolved; give a path relative to the file (or file://)"),
            ));
        }
        let f = uri.strip_prefix("file://").unwrap_or(uri);
        let scale = match child(s, "scale") {
            Some(c) => vec3(&self.numbers(c, 3)?),
            None => Vector3::repeat(1.0),
        };
        let file = self.path.parent().unwrap_or(Path::new(".")).join(f);
        Ok(Shape::Mesh(
            read_mesh(&file, scale).map_err(|e| self.err(u, e.to_string()))?,
        ))
    }

    /// A collision's contact values: Drake's proximity properties, else ODE's μ.
    fn contact_values(&self, c: Node) -> Result<ContactValues, InteropError> {
        let mut v = ContactValues::default();
        let ode_mu = child(c, "surface")
            .and_then(|s| child(s, "friction"))
            .and_then(|f| child(f, "ode"))
            .and_then(|o| child(o, "mu"));
        if let Some(m) = ode_mu {
            v.friction_mu = Some(self.number(m)?);
        }
        let Some(pp) = child(c, "proximity_properties") else {
            return Ok(v);
        };
        for p in pp.children().filter(|n| n.is_element()) {
            let slot = match p.tag_name().name() {
                "hydroelastic_modulus" => &mut v.modulus_pa,
                "hunt_crossley_dissipation" => &mut v.hunt_crossley_s_per_m,
                "relaxation_time" => &mut v.relaxation_time_s,
                "mu_dynamic" => &mut v.friction_mu,
                _ => continue,
            };
            *slot = Some(self.number(p)?);
        }
        Ok(v)
    }

    /// A link's `<inertial>` in its frame (the spec's 1 kg, unit moments when absent).
    fn inertial(&self, l: Node<'a, 'i>, link: &str) -> Result<MassProps, InteropError> {
        let Some(i) = child(l, "inertial") else {
            return Ok(MassProps {
                mass_kg: 1.0,
                com_m: Vector3::zeros(),
                inertia_com_kgm2: Matrix3::identity(),
            });
        };
        let f = self.pose_in_link(i, link)?;
        let mass = self.opt(i, "mass")?.unwrap_or(1.0);
        let m = match child(i, "inertia") {
            None => Matrix3::identity(),
            Some(t) => {
                let g = |k: &str, d: f64| self.opt(t, k).map(|x| x.unwrap_or(d));
                let (xy, xz, yz) = (g("ixy", 0.0)?, g("ixz", 0.0)?, g("iyz", 0.0)?);
                Matrix3::new(
                    g("ixx", 1.0)?,
                    xy,
                    xz,
                    xy,
                    g("iyy", 1.0)?,
                    yz,
                    xz,
                    yz,
                    g("izz", 1.0)?,
                )
            }
        };
        Ok(MassProps {
            mass_kg: mass,
            com_m: Vector3::zeros(),
            inertia_com_kgm2: m,
        }
        .transformed(&f.r, &f.p))
    }

    /// A `<link>` as a body (free until a joint names it as a child; its frame is set once
    /// the tree is known): its inertial and its collisions.
    fn link(&self, l: Node<'a, 'i>) -> Result<Body, InteropError> {
        let name = l.attribute("name").unwrap_or("");
        if let Some(n) = child(l, "frame") {
            return Err(self.err(n, "<frame> in a link is not read".into()));
        }
        let mut geoms = Vec::new();
        for c in l.children().filter(|n| n.has_tag_name("collision")) {
            let g = child(c, "geometry").ok_or_else(|| self.err(c, "no <geometry>".into()))?;
            geoms.push(Geom {
                name: c.attribute("name").unwrap_or(name).to_string(),
                shape: self.geometry(g)?,
                frame: self.pose_in_link(c, name)?,
                contact: true,
                mass: None,
                values: self.contact_values(c)?,
            });
        }
        Ok(Body::link(name, self.inertial(l, name)?, geoms))
    }
}

/// A joint read: the child's index, the parent's, the joint, and its PD gains if it has them.
struct JointRead {
    parent: usize,
    child: usize,
    name: String,
    joint: Joint,
    gains: Option<(f64, f64)>,
}

impl<'a, 'i> Sdf<'a, 'i> {
    /// The link a joint's `<parent>`/`<child>` names.
    fn joint_link(
        &self,
        j: Node,
        tag: &str,
        index: &HashMap<String, usize>,
    ) -> Result<usize, InteropError> {
        let n = child(j, tag).ok_or_else(|| self.err(j, format!("no <{tag}>")))?;
        let l = n.text().unwrap_or("").trim();
        if l == "world" {
            return Err(self.err(
                n,
                "the joint fixes the model to the world: a walker is two links, the first free"
                    .into(),
            ));
        }
        index
            .get(l)
            .copied()
            .ok_or_else(|| self.err(n, format!("link `{l}` is not defined ({FRAMES_READ})")))
    }

    /// A hinge's axis in its child link's frame (`x_cj`: the joint frame in the child's).
    fn axis(
        &self,
        a: Option<Node<'a, 'i>>,
        x_cj: &Frame,
        child_name: &str,
    ) -> Result<Vector3<f64>, InteropError> {
        let Some(a) = a else {
            return Ok(x_cj.r * Vector3::z());
        };
        let x = child(a, "xyz").ok_or_else(|| self.err(a, "no <xyz>".into()))?;
        let v = vec3(&self.numbers(x, 3)?);
        if v.norm() == 0.0 {
            return Err(self.err(x, "the joint's axis is zero".into()));
        }
        let parent_model = match child(a, "use_parent_model_frame") {
            Some(u) => matches!(u.text().map(str::trim), Some("true" | "1")),
            None => false,
        };
        let expressed = x.attribute("expressed_in").filter(|e| !e.is_empty());
        let frame = match (expressed, parent_model) {
            (Some(e), _) => Some(e),
            (None, true) => Some("__model__"),
            (None, false) => None,
        };
        Ok(match frame {
            None => x_cj.r * v,
            Some(e) => {
                let x_me = self.frame_in_model(x, e, &mut Vec::new())?;
                self.link_in_model(child_name)?.r.transpose() * x_me.r * v
            }
        }
        .normalize())
    }

    /// A revolute or continuous joint's hinge (in the child's frame): axis, anchor, a
    /// revolute one's limits, its effort, damping and friction.
    fn hinge(&self, j: Node<'a, 'i>, kind: &str, child_name: &str) -> Result<Joint, InteropError> {
        let x_cj = self.pose_in_link(j, child_name)?;
        let a = child(j, "axis");
        let axis = self.axis(a, &x_cj, child_name)?;
        let limit = a.and_then(|a| child(a, "limit"));
        let dynamics = a.and_then(|a| child(a, "dynamics"));
        let range = match limit {
            Some(l) if kind == "revolute" => match (self.opt(l, "lower")?, self.opt(l, "upper")?) {
                // The spec's ±1e16 defaults say "no limit".
                (Some(lo), Some(hi)) if lo.abs() < 1e15 && hi.abs() < 1e15 => Some([lo, hi]),
                _ => None,
            },
            _ => None,
        };
        let effort_limit = match limit {
            Some(l) => self.opt(l, "effort")?.filter(|e| *e > 0.0),
            None => None,
        };
        let dyn_value = |k: &str| match dynamics {
            Some(d) => self.opt(d, k).map(|x| x.unwrap_or(0.0)),
            None => Ok(0.0),
        };
        Ok(Joint::Hinge {
            axis,
            anchor: x_cj.p,
            range,
            damping: dyn_value("damping")?,
            frictionloss: dyn_value("friction")?,
            solreflimit: None,
            effort_limit,
        })
    }

    /// A `<joint>`: its links, kind and Drake's PD gains.
    fn joint(
        &self,
        j: Node<'a, 'i>,
        index: &HashMap<String, usize>,
        names: &[String],
    ) -> Result<JointRead, InteropError> {
        let (parent, child_index) = (
            self.joint_link(j, "parent", index)?,
            self.joint_link(j, "child", index)?,
        );
        let kind = j.attribute("type").unwrap_or("");
        let joint = match kind {
            "fixed" => Joint::Weld,
            "revolute" | "continuous" => self.hinge(j, kind, &names[child_index])?,
            other => Joint::Other(other.to_string()),
        };
        let gains = match j
            .children()
            .find(|n| n.tag_name().name() == "controller_gains")
        {
            Some(g) => Some((
                attr_number(self.path, self.doc, g, "p")?,
                attr_number(self.path, self.doc, g, "d")?,
            )),
            None => None,
        };
        Ok(JointRead {
            parent,
            child: child_index,
            name: j.attribute("name").unwrap_or("").to_string(),
            joint,
            gains,
        })
    }
}

/// The `<model>` of the file: under `<sdf>`, or the only one of its `<world>`; with the
/// world's gravity if it sets one.
fn the_model<'a, 'i>(
    path: &Path,
    doc: &'a Document<'i>,
) -> Result<(Node<'a, 'i>, Option<Node<'a, 'i>>), InteropError> {
    let root = doc.root_element();
    let version = root.attribute("version").unwrap_or("");
    let minor = version
        .strip_prefix("1.")
        .and_then(|m| m.parse::<u32>().ok());
    if !matches!(minor, Some(5..=11)) {
        return Err(bad(
            path,
            doc,
            root,
            format!("version=\"{version}\": SDFormat 1.5 to 1.11 is read"),
        ));
    }
    let mut holder = root;
    let worlds: Vec<Node> = root
        .children()
        .filter(|n| n.has_tag_name("world"))
        .collect();
    let mut world = None;
    if root.children().all(|n| !n.has_tag_name("model")) && worlds.len() == 1 {
        holder = worlds[0];
        world = Some(worlds[0]);
    }
    if let Some(n) = holder.children().find(|n| n.has_tag_name("include")) {
        return Err(bad(
            path,
            doc,
            n,
            "<include> is not resolved: give the model in the file".into(),
        ));
    }
    let models: Vec<Node> = holder
        .children()
        .filter(|n| n.has_tag_name("model"))
        .collect();
    match models.as_slice() {
        [m] => Ok((*m, world.and_then(|w| child(w, "gravity")))),
        _ => Err(bad(
            path,
            doc,
            holder,
            format!(
                "{} models (and {} worlds): one <model> is read, under <sdf> or as the only model of one <world>",
                models.len(),
                worlds.len()
            ),
        )),
    }
}

/// Refuses what a model may hold that this reader does not read: `<frame>`s, nested models,
/// includes, and a static model (fixed to the world).
fn refuse_unread(path: &Path, doc: &Document, model: Node) -> Result<(), InteropError> {
    for tag in ["frame", "model", "include"] {
        if let Some(n) = child(model, tag) {
            return Err(bad(
                path,
                doc,
                n,
                format!("<{tag}> in a model is not read ({FRAMES_READ})"),
            ));
        }
    }
    if let Some(s) =
        child(model, "static").filter(|s| matches!(s.text().map(str::trim), Some("true" | "1")))
    {
        return Err(bad(
            path,
            doc,
            s,
            "a static model is fixed to the world: a walker moves".into(),
        ));
    }
    Ok(())
}

pub(super) fn read(path: &Path, doc: &Document, sha: String) -> Result<RobotFile, InteropError> {
    let (model, gravity) = the_model(path, doc)?;
    refuse_unread(path, doc, model)?;
    let links: Vec<Node> = model
        .children()
        .filter(|n| n.has_tag_name("link"))
        .collect();
    let sdf = Sdf {
        path,
        doc,
        links: links
            .iter()
            .map(|l| (l.attribute("name").unwrap_or(""), *l))
            .collect(),
    };
    let (x_wm, rel) = sdf.pose(model)?;
    if let Some((p, r)) = rel.filter(|(_, r)| *r != "world") {
        return Err(sdf.err(
            p,
            format!("relative_to=\"{r}\": a model is placed in the world"),
        ));
    }
    let mut bodies = Vec::new();
    let mut index = HashMap::new();
    let mut x_ml = Vec::new();
    for l in &links {
        let body = sdf.link(*l)?;
        index.insert(body.name.clone(), bodies.len());
        x_ml.push(sdf.link_in_model(&body.name)?);
        bodies.push(body);
    }
    let names: Vec<String> = bodies.iter().map(|b| b.name.clone()).collect();
    let mut actuators = Vec::new();
    for j in model.children().filter(|n| n.has_tag_name("joint")) {
        let r = sdf.joint(j, &index, &names)?;
        if bodies[r.child].parent.is_some() {
            return Err(sdf.err(
                j,
                format!("link `{}` is the child of two joints", names[r.child]),
            ));
        }
        if let Some((kp, kv)) = r.gains {
            let force_limit = match r.joint {
                Joint::Hinge { effort_limit, .. } => effort_limit,
                _ => None,
            };
            actuators.push(Actuator::Position {
                joint: r.name.clone(),
                kp,
                kv,
                force_limit,
            });
        }
        let b = &mut bodies[r.child];
        b.parent = Some(r.parent);
        b.joint = r.joint;
        b.joint_name = r.name;
    }
    // Each body's frame in its parent's: a root's in the world (through the model's pose).
    for (i, b) in bodies.iter_mut().enumerate() {
        b.frame = match b.parent {
            None => x_wm.then(&x_ml[i]),
            Some(p) => x_ml[p].inverse().then(&x_ml[i]),
        };
    }
    Ok(RobotFile {
        path: path.to_path_buf(),
        sha256: sha,
        includes: Vec::new(),
        format: "SDF",
        bodies: parents_first(path, bodies, "an SDFormat model's")?,
        world_geoms: Vec::new(),
        actuators,
        gravity: gravity
            .map(|g| sdf.numbers(g, 3).map(|v| vec3(&v)))
            .transpose()?,
        timestep_s: None,
        custom_numbers: BTreeMap::new(),
        custom_texts: BTreeMap::new(),
    })
}
