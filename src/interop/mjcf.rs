//! MJCF (MuJoCo's XML) read into the neutral form of `robot_file.rs`: compiler settings,
//! `<default>` classes (with `class` and `childclass`), meshes, bodies with their joints,
//! inertials and geoms (masses from `mass` or density), actuators, `<custom>` data and
//! top-level `<include>`s.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use roxmltree::Node;

use super::InteropError;
use super::mesh::{MassProps, TriMesh, read_mesh};
use super::robot_file::{
    Actuator, Body, ContactValues, Frame, Geom, Joint, RobotFile, Shape, axis_angle, bad,
    parse_floats, quat, read_text, shape_mass, vec3,
};

/// Reads a parsed MJCF document.
pub(super) fn read(
    path: &Path,
    doc: &roxmltree::Document,
    sha: String,
) -> Result<RobotFile, InteropError> {
    Mjcf::read_file(path, doc, sha)
}

/// MJCF's `<default>` classes: per class, per element kind, the attributes it sets
/// (inherited from the enclosing class).
type Defaults = HashMap<String, HashMap<String, Vec<(String, String)>>>;

struct Mjcf<'a> {
    path: &'a Path,
    dir: PathBuf,
    degrees: bool,
    eulerseq: String,
    meshdir: PathBuf,
    defaults: Defaults,
    meshes: HashMap<String, TriMesh>,
    includes: Vec<(PathBuf, String)>,
    out: RobotFile,
}

impl<'a> Mjcf<'a> {
    fn read_file(
        path: &'a Path,
        doc: &roxmltree::Document,
        sha: String,
    ) -> Result<RobotFile, InteropError> {
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut m = Mjcf {
            path,
            meshdir: dir.clone(),
            dir,
            degrees: true,
            eulerseq: "xyz".into(),
            defaults: HashMap::new(),
            meshes: HashMap::new(),
            includes: Vec::new(),
            out: RobotFile {
                path: path.to_path_buf(),
                sha256: sha,
                includes: Vec::new(),
                format: "MJCF",
                bodies: Vec::new(),
                world_geoms: Vec::new(),
                actuators: Vec::new(),
                gravity: None,
                timestep_s: None,
                custom_numbers: BTreeMap::new(),
                custom_texts: BTreeMap::new(),
            },
        };
        m.section_pass(doc, path, 0)?;
        m.section_pass(doc, path, 1)?;
        m.out.includes = std::mem::take(&mut m.includes);
        Ok(m.out)
    }

    /// Reads the top-level sections of `doc` (from `file`): pass 0 the compiler, defaults
    /// and assets, pass 1 the rest (bodies need the assets, which may come later).
    fn section_pass(
        &mut self,
        doc: &roxmltree::Document,
        file: &Path,
        pass: u8,
    ) -> Result<(), InteropError> {
        for sec in doc.root_element().children().filter(|n| n.is_element()) {
            match (pass, sec.tag_name().name()) {
                (_, "include") => {
                    let Some(f) = sec.attribute("file") else {
                        return Err(bad(file, doc, sec, "no `file` attribute".into()));
                    };
                    let inc = self.dir.join(f);
                    let (text, sha) =
                        read_text(&inc).map_err(|e| bad(file, doc, sec, e.to_string()))?;
                    let idoc =
                        roxmltree::Document::parse(&text).map_err(|e| InteropError::Invalid {
                            file: inc.display().to_string(),
                            message: format!("not well-formed XML: {e}"),
                        })?;
                    if pass == 0 {
                        self.includes.push((inc.clone(), sha));
                    }
                    self.section_pass(&idoc, &inc, pass)?;
                }
                (0, "compiler") => {
                    if let Some(a) = sec.attribute("angle") {
                        self.degrees = a != "radian";
                    }
                    if let Some(e) = sec.attribute("eulerseq") {
                        self.eulerseq = e.to_string();
                    }
                    if let Some(d) = sec.attribute("meshdir").or(sec.attribute("assetdir")) {
                        self.meshdir = self.dir.join(d);
                    }
                }
                (0, "default") => self.read_defaults(sec, "main", &HashMap::new()),
                (0, "asset") => self.read_assets(doc, file, sec)?,
                (1, "option") => {
                    if let Some(t) = self.floats(doc, file, sec, "timestep", None, 1)? {
                        self.out.timestep_s = Some(t[0]);
                    }
                    if let Some(g) = self.floats(doc, file, sec, "gravity", None, 3)? {
                        self.out.gravity = Some(vec3(&g));
                    }
                }
                (1, "custom") => self.read_custom(doc, file, sec)?,
                (1, "worldbody") => self.read_world(doc, file, sec)?,
                (1, "actuator") => self.read_actuators(doc, file, sec)?,
                _ => {}
            }
        }
        Ok(())
    }

    fn read_defaults(
        &mut self,
        node: Node,
        class: &str,
        inherited: &HashMap<String, Vec<(String, String)>>,
    ) {
        let mut mine = inherited.clone();
        for c in node
            .children()
            .filter(|n| n.is_element() && n.tag_name().name() != "default")
        {
            let e = mine.entry(c.tag_name().name().to_string()).or_default();
            for a in c.attributes() {
                e.retain(|(k, _)| k != a.name());
                e.push((a.name().to_string(), a.value().to_string()));
            }
        }
        for c in node
            .children()
            .filter(|n| n.is_element() && n.tag_name().name() == "default")
        {
            let name = c.attribute("class").unwrap_or(class).to_string();
            self.read_defaults(c, &name, &mine);
        }
        self.defaults.insert(class.to_string(), mine);
    }

    /// An attribute of `node`, else its class's default (`class`, else `childclass`, else main).
    fn attr<'n>(&'n self, node: Node<'n, 'n>, name: &str, childclass: &str) -> Option<&'n str> {
        if let Some(v) = node.attribute(name) {
            return Some(v);
        }
        let class = node.attribute("class").unwrap_or(childclass);
        self.defaults
            .get(class)
            .and_then(|d| d.get(node.tag_name().name()))
            .and_then(|attrs| attrs.iter().find(|(k, _)| k == name))
            .map(|(_, v)| v.as_str())
    }

    /// `n` numbers of an attribute (or its default), if set.
    #[allow(clippy::too_many_arguments)]
    fn floats(
        &self,
        doc: &roxmltree::Document,
        file: &Path,
        node: Node,
        name: &str,
        cc: Option<&str>,
        n: usize,
    ) -> Result<Option<Vec<f64>>, InteropError> {
        let v = match cc {
            Some(c) => self.attr(node, name, c),
            None => node.attribute(name),
        };
        let Some(v) = v else { return Ok(None) };
        match parse_floats(v) {
            Some(xs) if xs.len() >= n && xs.iter().all(|x| x.is_finite()) => Ok(Some(xs)),
            _ => Err(bad(
                file,
                doc,
                node,
                format!("`{name}` = \"{v}\": expected {n} finite numbers"),
            )),
        }
    }

    fn angle(&self, x: f64) -> f64 {
        if self.degrees { x.to_radians() } else { x }
    }

    /// The orientation of an element (quat, axisangle, euler, xyaxes or zaxis).
    fn orientation(
        &self,
        doc: &roxmltree::Document,
        file: &Path,
        node: Node,
        cc: &str,
    ) -> Result<Matrix3<f64>, InteropError> {
        if let Some(q) = self.floats(doc, file, node, "quat", Some(cc), 4)? {
            if q[..4].iter().all(|x| *x == 0.0) {
                return Err(bad(file, doc, node, "`quat` is zero: no rotation".into()));
            }
            return Ok(quat(q[0], q[1], q[2], q[3]));
        }
        if let Some(a) = self.floats(doc, file, node, "axisangle", Some(cc), 4)? {
            return Ok(axis_angle(vec3(&a), self.angle(a[3])));
        }
        if let Some(e) = self.floats(doc, file, node, "euler", Some(cc), 3)? {
            let mut r = Matrix3::identity();
            for (i, ch) in self.eulerseq.chars().take(3).enumerate() {
                let axis = match ch.to_ascii_lowercase() {
                    'x' => Vector3::x(),
                    'y' => Vector3::y(),
                    _ => Vector3::z(),
                };
                let rot = axis_angle(axis, self.angle(e[i]));
                r = if ch.is_ascii_lowercase() {
                    r * rot
                } else {
                    rot * r
                };
            }
            return Ok(r);
        }
        if let Some(xy) = self.floats(doc, file, node, "xyaxes", Some(cc), 6)? {
            let x = vec3(&xy[..3]).normalize();
            let y0 = vec3(&xy[3..]);
            let y = (y0 - x * x.dot(&y0)).normalize();
            return Ok(Matrix3::from_columns(&[x, y, x.cross(&y)]));
        }
        if let Some(z) = self.floats(doc, file, node, "zaxis", Some(cc), 3)? {
            let z = vec3(&z).normalize();
            let r = UnitQuaternion::rotation_between(&Vector3::z(), &z).unwrap_or_else(|| {
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
            });
            return Ok(*r.to_rotation_matrix().matrix());
        }
        Ok(Matrix3::identity())
    }

    fn frame(
        &self,
        doc: &roxmltree::Document,
        file: &Path,
        node: Node,
        cc: &str,
    ) -> Result<Frame, InteropError> {
        let p = self
            .floats(doc, file, node, "pos", Some(cc), 3)?
            .map(|v| vec3(&v))
            .unwrap_or_else(Vector3::zeros);
        Ok(Frame {
            r: self.orientation(doc, file, node, cc)?,
            p,
        })
    }

    fn read_assets(
        &mut self,
        doc: &roxmltree::Document,
        file: &Path,
        sec: Node,
    ) -> Result<(), InteropError> {
        for m in sec.children().filter(|n| n.has_tag_name("mesh")) {
            let scale = self
                .floats(doc, file, m, "scale", Some("main"), 3)?
                .map(|v| vec3(&v))
                .unwrap_or_else(|| Vector3::repeat(1.0));
            let mesh = if let Some(f) = m.attribute("file") {
                let p = self.meshdir.join(f);
                read_mesh(&p, scale).map_err(|e| bad(file, doc, m, e.to_string()))?
            } else {
                let v = self.floats(doc, file, m, "vertex", None, 9)?;
                let f = self.floats(doc, file, m, "face", None, 3)?;
                match (v, f) {
                    (Some(v), Some(f)) => TriMesh {
                        vertices: v.chunks(3).map(|c| vec3(c).component_mul(&scale)).collect(),
                        triangles: f
                            .chunks(3)
                            .map(|c| [c[0] as usize, c[1] as usize, c[2] as usize])
                            .collect(),
                    },
                    _ => {
                        return Err(bad(file, doc, m, "an inline mesh needs `vertex` and `face` (its convex hull is not computed here)".into()));
                    }
                }
            };
            if mesh
                .triangles
                .iter()
                .flatten()
                .any(|&i| i >= mesh.vertices.len())
            {
                return Err(bad(
                    file,
                    doc,
                    m,
                    "a face names a vertex the mesh does not have".into(),
                ));
            }
            let name = m
                .attribute("name")
                .map(str::to_string)
                .or_else(|| {
                    m.attribute("file").map(|f| {
                        Path::new(f)
                            .file_stem()
                            .map(|s| s.to_string_lossy().into_owned())
                            .unwrap_or_default()
                    })
                })
                .unwrap_or_default();
            self.meshes.insert(name, mesh);
        }
        Ok(())
    }

    fn read_custom(
        &mut self,
        doc: &roxmltree::Document,
        file: &Path,
        sec: Node,
    ) -> Result<(), InteropError> {
        for c in sec.children().filter(|n| n.is_element()) {
            let Some(name) = c.attribute("name") else {
                continue;
            };
            match c.tag_name().name() {
                "numeric" => {
                    if let Some(v) = self.floats(doc, file, c, "data", None, 1)? {
                        self.out.custom_numbers.insert(name.to_string(), v[0]);
                    }
                }
                "text" => {
                    self.out.custom_texts.insert(
                        name.to_string(),
                        c.attribute("data").unwrap_or("").to_string(),
                    );
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn read_world(
        &mut self,
        doc: &roxmltree::Document,
        file: &Path,
        sec: Node,
    ) -> Result<(), InteropError> {
        let cc = sec.attribute("childclass").unwrap_or("main").to_string();
        for c in sec.children().filter(|n| n.is_element()) {
            match c.tag_name().name() {
                "geom" => {
                    let g = self.geom(doc, file, c, &cc)?;
                    self.out.world_geoms.push(g);
                }
                "body" => self.read_body(doc, file, c, None, &cc)?,
                _ => {}
            }
        }
        Ok(())
    }

    fn read_body(
        &mut self,
        doc: &roxmltree::Document,
        file: &Path,
        node: Node,
        parent: Option<usize>,
        cc: &str,
    ) -> Result<(), InteropError> {
        let cc = node.attribute("childclass").unwrap_or(cc).to_string();
        let frame = self.frame(doc, file, node, &cc)?;
        let mut joints = Vec::new();
        for j in node
            .children()
            .filter(|n| n.has_tag_name("joint") || n.has_tag_name("freejoint"))
        {
            let name = j.attribute("name").unwrap_or("").to_string();
            let kind = if j.has_tag_name("freejoint") {
                "free"
            } else {
                self.attr(j, "type", &cc).unwrap_or("hinge")
            };
            let joint = match kind {
                "free" => Joint::Free,
                "hinge" => self.hinge(doc, file, j, &cc)?,
                other => Joint::Other(other.to_string()),
            };
            joints.push((name, joint));
        }
        if joints.len() > 1 {
            let names: Vec<String> = joints.iter().map(|(n, _)| format!("`{n}`")).collect();
            return Err(InteropError::Topology {
                file: self.path.display().to_string(),
                message: format!(
                    "body `{}` has {} joints ({}): each leg of a walker moves by one joint (the base's free joint, the hip's hinge)",
                    node.attribute("name").unwrap_or("?"),
                    joints.len(),
                    names.join(", ")
                ),
            });
        }
        let (joint_name, joint) = joints.pop().unwrap_or_else(|| (String::new(), Joint::Weld));
        let mut geoms = Vec::new();
        for g in node.children().filter(|n| n.has_tag_name("geom")) {
            geoms.push(self.geom(doc, file, g, &cc)?);
        }
        let inertial = match node.children().find(|n| n.has_tag_name("inertial")) {
            Some(i) => Some(self.inertial(doc, file, i)?),
            None => None,
        };
        let index = self.out.bodies.len();
        self.out.bodies.push(Body {
            name: node.attribute("name").unwrap_or("").to_string(),
            parent,
            frame,
            joint,
            joint_name,
            inertial,
            geoms,
        });
        for c in node.children().filter(|n| n.has_tag_name("body")) {
            self.read_body(doc, file, c, Some(index), &cc)?;
        }
        Ok(())
    }

    /// A hinge `<joint>`: axis, anchor, range (in the compiler's angle unit), damping,
    /// friction loss and the limit's solref.
    fn hinge(
        &self,
        doc: &roxmltree::Document,
        file: &Path,
        j: Node,
        cc: &str,
    ) -> Result<Joint, InteropError> {
        let axis = self
            .floats(doc, file, j, "axis", Some(cc), 3)?
            .map(|v| vec3(&v))
            .unwrap_or_else(Vector3::z);
        if axis.norm() == 0.0 {
            return Err(bad(file, doc, j, "hinge axis is zero".into()));
        }
        let anchor = self
            .floats(doc, file, j, "pos", Some(cc), 3)?
            .map(|v| vec3(&v))
            .unwrap_or_else(Vector3::zeros);
        let limited = self.attr(j, "limited", cc);
        let range = self
            .floats(doc, file, j, "range", Some(cc), 2)?
            .and_then(|r| {
                (limited != Some("false") && r[0] < r[1])
                    .then(|| [self.angle(r[0]), self.angle(r[1])])
            });
        let one = |k: &str| -> Result<f64, InteropError> {
            Ok(self
                .floats(doc, file, j, k, Some(cc), 1)?
                .map(|v| v[0])
                .unwrap_or(0.0))
        };
        Ok(Joint::Hinge {
            axis: axis.normalize(),
            anchor,
            range,
            damping: one("damping")?,
            frictionloss: one("frictionloss")?,
            solreflimit: self
                .floats(doc, file, j, "solreflimit", Some(cc), 2)?
                .map(|v| [v[0], v[1]]),
            effort_limit: self
                .floats(doc, file, j, "actuatorfrcrange", Some(cc), 2)?
                .filter(|_| self.attr(j, "actuatorfrclimited", cc) != Some("false"))
                .map(|r| r[0].abs().min(r[1].abs())),
        })
    }

    fn inertial(
        &self,
        doc: &roxmltree::Document,
        file: &Path,
        i: Node,
    ) -> Result<MassProps, InteropError> {
        let frame = self.frame(doc, file, i, "main")?;
        let mass = self
            .floats(doc, file, i, "mass", None, 1)?
            .ok_or_else(|| bad(file, doc, i, "no `mass`".into()))?[0];
        let inertia = if let Some(d) = self.floats(doc, file, i, "diaginertia", None, 3)? {
            Matrix3::from_diagonal(&vec3(&d))
        } else if let Some(f) = self.floats(doc, file, i, "fullinertia", None, 6)? {
            Matrix3::new(f[0], f[3], f[4], f[3], f[1], f[5], f[4], f[5], f[2])
        } else {
            return Err(bad(
                file,
                doc,
                i,
                "no `diaginertia` or `fullinertia`".into(),
            ));
        };
        Ok(MassProps {
            mass_kg: mass,
            com_m: Vector3::zeros(),
            inertia_com_kgm2: inertia,
        }
        .transformed(&frame.r, &frame.p))
    }

    fn geom(
        &self,
        doc: &roxmltree::Document,
        file: &Path,
        g: Node,
        cc: &str,
    ) -> Result<Geom, InteropError> {
        let kind = self.attr(g, "type", cc).unwrap_or("sphere");
        let size = self
            .floats(doc, file, g, "size", Some(cc), 0)?
            .unwrap_or_default();
        let frame = self.frame(doc, file, g, cc)?;
        let (shape, fromto_frame) = self.shape(doc, file, g, cc, kind, &size)?;
        let frame = fromto_frame.unwrap_or(frame);
        let contype = self
            .floats(doc, file, g, "contype", Some(cc), 1)?
            .map(|v| v[0])
            .unwrap_or(1.0);
        let conaff = self
            .floats(doc, file, g, "conaffinity", Some(cc), 1)?
            .map(|v| v[0])
            .unwrap_or(1.0);
        let mass = self
            .floats(doc, file, g, "mass", Some(cc), 1)?
            .map(|v| v[0]);
        let density = self
            .floats(doc, file, g, "density", Some(cc), 1)?
            .map(|v| v[0])
            .unwrap_or(1000.0);
        let props = shape_mass(&shape, mass, density).map(|p| p.transformed(&frame.r, &frame.p));
        let values = ContactValues {
            friction_mu: self
                .floats(doc, file, g, "friction", Some(cc), 1)?
                .map(|v| v[0]),
            solref: self
                .floats(doc, file, g, "solref", Some(cc), 2)?
                .map(|v| [v[0], v[1]]),
            ..ContactValues::default()
        };
        Ok(Geom {
            name: g
                .attribute("name")
                .or(g.attribute("mesh"))
                .unwrap_or(kind)
                .to_string(),
            shape,
            frame,
            contact: contype != 0.0 || conaff != 0.0,
            mass: props,
            values,
        })
    }

    /// A geom's shape from its type and sizes; with `fromto`, a capsule's or cylinder's
    /// frame along that segment (which replaces the geom's own).
    fn shape(
        &self,
        doc: &roxmltree::Document,
        file: &Path,
        g: Node,
        cc: &str,
        kind: &str,
        size: &[f64],
    ) -> Result<(Shape, Option<Frame>), InteropError> {
        let need = |n: usize| -> Result<(), InteropError> {
            if size.len() < n {
                Err(bad(
                    file,
                    doc,
                    g,
                    format!("a {kind} needs {n} sizes, `size` has {}", size.len()),
                ))
            } else {
                Ok(())
            }
        };
        if let Some(x) = size.iter().find(|x| **x < 0.0) {
            return Err(bad(
                file,
                doc,
                g,
                format!("`size` {x} is negative: sizes are lengths"),
            ));
        }
        let fromto = self.floats(doc, file, g, "fromto", Some(cc), 6)?;
        let mut frame = None;
        let shape = match kind {
            "sphere" => {
                need(1)?;
                Shape::Sphere(size[0])
            }
            "ellipsoid" => {
                need(3)?;
                Shape::Ellipsoid(vec3(size))
            }
            "box" => {
                need(3)?;
                Shape::Box(vec3(size))
            }
            "capsule" | "cylinder" => {
                need(1)?;
                let half = if let Some(ft) = &fromto {
                    let (a, b) = (vec3(&ft[..3]), vec3(&ft[3..]));
                    if (b - a).norm() == 0.0 {
                        return Err(bad(file, doc, g, "`fromto` has zero length".into()));
                    }
                    let z = (b - a).normalize();
                    let r = UnitQuaternion::rotation_between(&Vector3::z(), &z)
                        .unwrap_or_else(UnitQuaternion::identity);
                    frame = Some(Frame {
                        r: *r.to_rotation_matrix().matrix(),
                        p: 0.5 * (a + b),
                    });
                    0.5 * (b - a).norm()
                } else {
                    need(2)?;
                    size[1]
                };
                if kind == "capsule" {
                    Shape::Capsule(size[0], half)
                } else {
                    Shape::Cylinder(size[0], half)
                }
            }
            "mesh" => {
                let name = self.attr(g, "mesh", cc).unwrap_or("");
                let m = self
                    .meshes
                    .get(name)
                    .ok_or_else(|| bad(file, doc, g, format!("mesh `{name}` is not in <asset>")))?;
                Shape::Mesh(m.clone())
            }
            "plane" => Shape::Plane,
            other => {
                return Err(bad(
                    file,
                    doc,
                    g,
                    format!("geom type `{other}` is not read"),
                ));
            }
        };
        Ok((shape, frame))
    }

    /// The hip's actuators as joint torques: MuJoCo's actuator force (gain·ctrl + bias,
    /// clamped to `forcerange`) times the `gear`, so a position servo's stiffness and
    /// damping are gear²·kp and gear²·kv and its torque limit gear·forcerange; a motor's
    /// (or a bias-free `general`'s) control range times its gain bounds its force too; a
    /// `general` with an affine bias pulling back on the joint's position is a position
    /// servo.
    fn read_actuators(
        &mut self,
        doc: &roxmltree::Document,
        file: &Path,
        sec: Node,
    ) -> Result<(), InteropError> {
        for a in sec.children().filter(|n| n.is_element()) {
            let joint = a.attribute("joint").unwrap_or("").to_string();
            let range = |s: &Self, k: &str| -> Result<Option<f64>, InteropError> {
                let limited = s.attr(a, &k.replace("range", "limited"), "main");
                Ok(s.floats(doc, file, a, k, Some("main"), 2)?
                    .filter(|_| limited != Some("false"))
                    .map(|r| r[0].abs().min(r[1].abs())))
            };
            let one = |s: &Self, k: &str, d: f64| -> Result<f64, InteropError> {
                Ok(s.floats(doc, file, a, k, Some("main"), 1)?
                    .map(|v| v[0])
                    .unwrap_or(d))
            };
            let gear = one(self, "gear", 1.0)?;
            let force = range(self, "forcerange")?;
            let ctrl = range(self, "ctrlrange")?;
            let min = |x: Option<f64>, y: Option<f64>| match (x, y) {
                (Some(x), Some(y)) => Some(x.min(y)),
                (x, y) => x.or(y),
            };
            let g2 = gear * gear;
            let actuator = match a.tag_name().name() {
                "position" => Actuator::Position {
                    joint,
                    kp: g2 * one(self, "kp", 1.0)?,
                    kv: g2 * one(self, "kv", 0.0)?,
                    force_limit: force.map(|t| gear.abs() * t),
                },
                "motor" => Actuator::Torque {
                    joint,
                    limit: min(force, ctrl).map(|t| gear.abs() * t),
                    velocity_damping: 0.0,
                },
                "general" => {
                    let num = |k: &str| -> Result<Vec<f64>, InteropError> {
                        Ok(self
                            .floats(doc, file, a, k, Some("main"), 0)?
                            .unwrap_or_default())
                    };
                    let gain = num("gainprm")?.first().copied().unwrap_or(1.0);
                    let bias = num("biasprm")?;
                    let b = |i: usize| bias.get(i).copied().unwrap_or(0.0);
                    let affine = self.attr(a, "biastype", "main") == Some("affine");
                    if affine && b(1) < 0.0 {
                        Actuator::Position {
                            joint,
                            kp: -g2 * b(1),
                            kv: -g2 * b(2),
                            force_limit: force.map(|t| gear.abs() * t),
                        }
                    } else {
                        let ctrl_force = if affine {
                            None
                        } else {
                            ctrl.map(|c| gain.abs() * c)
                        };
                        Actuator::Torque {
                            joint,
                            limit: min(force, ctrl_force).map(|t| gear.abs() * t),
                            velocity_damping: if affine { -g2 * b(2) } else { 0.0 },
                        }
                    }
                }
                _ => continue,
            };
            self.out.actuators.push(actuator);
        }
        Ok(())
    }
}
