//! Triangle meshes of robot files: reading STL, exact mass properties of a closed mesh, the
//! best-fitting ellipsoid of the convex hull a floor touches, and the half-ellipsoid foot a
//! design with a section cut exports as a convex mesh.

use std::path::Path;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::InteropError;

/// A triangle mesh (vertices in metres in some frame; triangles counter-clockwise seen from
/// outside).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub vertices: Vec<Vector3<f64>>,
    pub triangles: Vec<[usize; 3]>,
}

/// Mass, centre of mass and inertia about the centre of mass (in the frame of the input).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps {
    pub mass_kg: f64,
    pub com_m: Vector3<f64>,
    pub inertia_com_kgm2: Matrix3<f64>,
}

impl MassProps {
    pub const ZERO: MassProps = MassProps {
        mass_kg: 0.0,
        com_m: Vector3::new(0.0, 0.0, 0.0),
        inertia_com_kgm2: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };

    /// The same body seen from a frame in which this one sits at rotation `r`, offset `p`.
    pub fn transformed(&self, r: &Matrix3<f64>, p: &Vector3<f64>) -> MassProps {
        MassProps {
            mass_kg: self.mass_kg,
            com_m: r * self.com_m + p,
            inertia_com_kgm2: r * self.inertia_com_kgm2 * r.transpose(),
        }
    }

    /// Two bodies joined rigidly (parallel-axis theorem).
    pub fn combined(&self, o: &MassProps) -> MassProps {
        let m = self.mass_kg + o.mass_kg;
        if m <= 0.0 {
            return MassProps::ZERO;
        }
        let com = (self.com_m * self.mass_kg + o.com_m * o.mass_kg) / m;
        let shift = |b: &MassProps| {
            let d = b.com_m - com;
            b.inertia_com_kgm2
                + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * b.mass_kg
        };
        MassProps {
            mass_kg: m,
            com_m: com,
            inertia_com_kgm2: shift(self) + shift(o),
        }
    }
}

/// Reads an STL file (binary or ASCII), scaled per axis.
pub fn read_stl(path: &Path, scale: Vector3<f64>) -> Result<TriMesh, InteropError> {
    let bad = |message: String| InteropError::Read {
        path: path.to_path_buf(),
        message,
    };
    let mut f = std::fs::File::open(path).map_err(|e| bad(e.to_string()))?;
    let m = stl_io::read_stl(&mut f).map_err(|e| bad(format!("not a readable STL: {e}")))?;
    let vertices = m
        .vertices
        .iter()
        .map(|v| Vector3::new(v[0] as f64, v[1] as f64, v[2] as f64).component_mul(&scale))
        .collect();
    let triangles = m.faces.iter().map(|f| f.vertices).collect();
    let mesh = TriMesh {
        vertices,
        triangles,
    };
    if mesh.triangles.is_empty() {
        return Err(bad("the mesh has no triangles".into()));
    }
    Ok(mesh)
}

/// Reads a Wavefront OBJ's vertices and faces (polygons fanned into triangles), scaled per
/// axis. Read directly: a mesh needs only the `v` and `f` lines (normals, texture coordinates
/// and materials are skipped), which no crate makes shorter.
pub fn read_obj(path: &Path, scale: Vector3<f64>) -> Result<TriMesh, InteropError> {
    let text = std::fs::read_to_string(path).map_err(|e| InteropError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let bad = |line: usize, message: String| InteropError::Invalid {
        file: format!("{}:{}", path.display(), line + 1),
        message,
    };
    let mut mesh = TriMesh::default();
    for (n, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let xyz: Vec<f64> = it.take(3).filter_map(|t| t.parse().ok()).collect();
                if xyz.len() != 3 {
                    return Err(bad(n, format!("a vertex needs 3 numbers: `{line}`")));
                }
                mesh.vertices
                    .push(Vector3::new(xyz[0], xyz[1], xyz[2]).component_mul(&scale));
            }
            Some("f") => {
                let nv = mesh.vertices.len() as i64;
                let idx: Option<Vec<usize>> = it
                    .map(|t| {
                        let i: i64 = t.split('/').next()?.parse().ok()?;
                        let i = if i < 0 { nv + i } else { i - 1 };
                        (0..nv).contains(&i).then_some(i as usize)
                    })
                    .collect();
                match idx {
                    Some(v) if v.len() >= 3 => {
                        for k in 1..v.len() - 1 {
                            mesh.triangles.push([v[0], v[k], v[k + 1]]);
                        }
                    }
                    _ => return Err(bad(n, format!("a face names a missing vertex: `{line}`"))),
                }
            }
            _ => {}
        }
    }
    if mesh.triangles.is_empty() {
        return Err(bad(0, "the mesh has no faces".into()));
    }
    Ok(mesh)
}

/// Reads an STL or OBJ mesh by its extension.
pub fn read_mesh(path: &Path, scale: Vector3<f64>) -> Result<TriMesh, InteropError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "stl" => read_stl(path, scale),
        "obj" => read_obj(path, scale),
        other => Err(InteropError::Read {
            path: path.to_path_buf(),
            message: format!("mesh format `.{other}`: only STL and OBJ meshes are read"),
        }),
    }
}

impl TriMesh {
    /// Volume [m³], centroid and the inertia about the centroid per unit density, of the solid
    /// the closed mesh bounds (signed tetrahedra from the origin; an inside-out mesh is
    /// taken with its orientation flipped). None for a mesh enclosing no volume.
    pub fn volume_props(&self) -> Option<(f64, Vector3<f64>, Matrix3<f64>)> {
        let mut vol = 0.0;
        let mut first = Vector3::zeros();
        // Covariance ∫ x xᵀ dV of the canonical tetrahedron, scaled by det A: A C Aᵀ.
        let canon = Matrix3::new(2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 2.0) / 120.0;
        let mut cov = Matrix3::zeros();
        for t in &self.triangles {
            let (a, b, c) = (
                self.vertices[t[0]],
                self.vertices[t[1]],
                self.vertices[t[2]],
            );
            let m = Matrix3::from_columns(&[a, b, c]);
            let det = m.determinant();
            vol += det / 6.0;
            first += (a + b + c) * (det / 24.0);
            cov += m * canon * m.transpose() * det;
        }
        if vol.abs() < 1e-300 {
            return None;
        }
        let s = vol.signum();
        let (vol, first, cov) = (vol * s, first * s, cov * s);
        let com = first / vol;
        let cov_com = cov - com * com.transpose() * vol;
        let inertia = Matrix3::identity() * cov_com.trace() - cov_com;
        Some((vol, com, inertia))
    }

    /// The mesh moved by rotation `r` and offset `p`.
    pub fn transformed(&self, r: &Matrix3<f64>, p: &Vector3<f64>) -> TriMesh {
        TriMesh {
            vertices: self.vertices.iter().map(|v| r * v + p).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The points of the mesh's convex hull that a flat floor can touch when the body tilts
    /// up to `max_tilt_rad` from upright: for directions d within that angle of `down`, the
    /// support point argmax v·d (each once). A floor meets a body only on its convex hull
    /// (as MuJoCo collides meshes), so a foot with steps, holes or an inner shell is fitted
    /// by the surface it rolls on.
    pub fn support_points(&self, down: &Vector3<f64>, max_tilt_rad: f64) -> Vec<Vector3<f64>> {
        let d = down.normalize();
        let a = if d.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = d.cross(&a).normalize();
        let v = d.cross(&u);
        let mut seen = std::collections::BTreeSet::new();
        const RINGS: usize = 24;
        const SEGMENTS: usize = 48;
        for i in 0..=RINGS {
            let tilt = max_tilt_rad * i as f64 / RINGS as f64;
            let n = if i == 0 { 1 } else { SEGMENTS };
            for j in 0..n {
                let phi = std::f64::consts::TAU * j as f64 / n as f64;
                let dir = d * tilt.cos() + (u * phi.cos() + v * phi.sin()) * tilt.sin();
                let best = self
                    .vertices
                    .iter()
                    .enumerate()
                    .max_by(|(_, p), (_, q)| p.dot(&dir).total_cmp(&q.dot(&dir)));
                if let Some((k, _)) = best {
                    seen.insert(k);
                }
            }
        }
        seen.into_iter().map(|k| self.vertices[k]).collect()
    }
}

/// An ellipsoid with axes along the frame's axes, fitted to points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EllipsoidFit {
    pub center_m: Vector3<f64>,
    pub semi_axes_m: Vector3<f64>,
    /// Root-mean-square distance of the points from the surface [m] (radial, approximate).
    pub rms_m: f64,
    /// True when the sphere fit was kept (the axis-aligned ellipsoid fitted no better, or was
    /// not a closed ellipsoid: a shallow cap does not pin its third axis).
    pub sphere: bool,
}

impl EllipsoidFit {
    /// The same ellipsoid moved `dz` along z, its rms recomputed over `points` as placed.
    pub fn moved_z(&self, dz: f64, points: &[Vector3<f64>]) -> EllipsoidFit {
        let center = self.center_m + Vector3::z() * dz;
        EllipsoidFit {
            center_m: center,
            rms_m: rms_of(points, &center, &self.semi_axes_m),
            ..*self
        }
    }
}

fn rms_of(points: &[Vector3<f64>], c: &Vector3<f64>, s: &Vector3<f64>) -> f64 {
    let n = points.len().max(1) as f64;
    let sum: f64 = points
        .iter()
        .map(|p| {
            let d = p - c;
            let r = d.component_div(s).norm();
            // Radial distance from the surface along the ray from the centre.
            let dist = d.norm() * (1.0 - 1.0 / r.max(1e-300));
            dist * dist
        })
        .sum();
    (sum / n).sqrt()
}

/// Best-fitting ellipsoid (axes along the frame's) of `points` by algebraic least squares,
/// A x² + B y² + C z² + D x + E y + F z = 1, against the best sphere
/// x² + y² + z² = 2a·x + 2b·y + 2c·z + k; the ellipsoid is kept when it is closed and fits
/// at least 20 % better (rms distance) than a sphere that does not already fit to rounding.
/// None with fewer than 4 points or a degenerate set.
pub fn fit_ellipsoid(points: &[Vector3<f64>]) -> Option<EllipsoidFit> {
    if points.len() < 4 {
        return None;
    }
    let n = points.len();
    // Centre the points for conditioning.
    let mean = points.iter().sum::<Vector3<f64>>() / n as f64;
    let scale = points
        .iter()
        .map(|p| (p - mean).norm())
        .fold(0.0, f64::max)
        .max(1e-300);
    let q: Vec<Vector3<f64>> = points.iter().map(|p| (p - mean) / scale).collect();
    let sphere = {
        let a = DMatrix::from_fn(n, 4, |i, j| if j < 3 { 2.0 * q[i][j] } else { 1.0 });
        let b = DVector::from_fn(n, |i, _| q[i].norm_squared());
        let x = a.svd(true, true).solve(&b, 1e-12).ok()?;
        let c = Vector3::new(x[0], x[1], x[2]);
        let r2 = x[3] + c.norm_squared();
        (r2 > 0.0).then(|| {
            let r = r2.sqrt() * scale;
            let center = c * scale + mean;
            let s = Vector3::repeat(r);
            EllipsoidFit {
                center_m: center,
                semi_axes_m: s,
                rms_m: rms_of(points, &center, &s),
                sphere: true,
            }
        })
    };
    let ellipsoid = (n >= 6)
        .then(|| {
            let a = DMatrix::from_fn(n, 6, |i, j| {
                if j < 3 {
                    q[i][j] * q[i][j]
                } else {
                    q[i][j - 3]
                }
            });
            let b = DVector::from_element(n, 1.0);
            let x = a.svd(true, true).solve(&b, 1e-12).ok()?;
            let quad = Vector3::new(x[0], x[1], x[2]);
            if quad.iter().any(|v| v.is_nan() || *v <= 0.0) {
                return None;
            }
            let c = Vector3::new(
                -x[3] / (2.0 * x[0]),
                -x[4] / (2.0 * x[1]),
                -x[5] / (2.0 * x[2]),
            );
            let g = 1.0 + x[0] * c.x * c.x + x[1] * c.y * c.y + x[2] * c.z * c.z;
            if g.is_nan() || g <= 0.0 {
                return None;
            }
            let s = Vector3::new((g / x[0]).sqrt(), (g / x[1]).sqrt(), (g / x[2]).sqrt()) * scale;
            let center = c * scale + mean;
            Some(EllipsoidFit {
                center_m: center,
                semi_axes_m: s,
                rms_m: rms_of(points, &center, &s),
                sphere: false,
            })
        })
        .flatten();
    match (sphere, ellipsoid) {
        // A sphere fitting to rounding (a capsule's end, a sphere as a mesh) is kept: there
        // an ellipsoid's "better" rms is rounding too.
        (Some(s), Some(e)) if e.rms_m < 0.8 * s.rms_m && s.rms_m > 1e-9 * scale => Some(e),
        (Some(s), _) => Some(s),
        (None, e) => e,
    }
}

/// The outer part of an ellipsoid beyond a plane normal to y: the points with
/// `side·y ≥ offset`, as a closed convex mesh (rings about the y axis from the cut to the
/// tip, a fan at the tip, a flat cap on the cut). `center` and the offset are in the frame
/// the semi-axes are along.
pub fn ellipsoid_section(
    center: &Vector3<f64>,
    semi: &Vector3<f64>,
    side: f64,
    offset: f64,
) -> TriMesh {
    const RINGS: usize = 12;
    const SEGMENTS: usize = 32;
    // s = the section plane's y offset from the centre in semi-axes, toward the tip.
    let s0 = ((offset - side * center.y) / semi.y).clamp(-0.999, 0.999);
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for k in 0..RINGS {
        let s = s0 + (1.0 - s0) * (k as f64 / RINGS as f64);
        // Denser rings toward the tip keep the curvature there.
        let rho = (1.0 - s * s).max(0.0).sqrt();
        for j in 0..SEGMENTS {
            let phi = std::f64::consts::TAU * j as f64 / SEGMENTS as f64;
            vertices.push(Vector3::new(
                center.x + semi.x * rho * phi.cos(),
                center.y + side * semi.y * s,
                center.z + semi.z * rho * phi.sin(),
            ));
        }
    }
    let tip = vertices.len();
    vertices.push(Vector3::new(center.x, center.y + side * semi.y, center.z));
    let cap = vertices.len();
    vertices.push(Vector3::new(
        center.x,
        center.y + side * semi.y * s0,
        center.z,
    ));
    let idx = |k: usize, j: usize| k * SEGMENTS + j % SEGMENTS;
    // Orientation: outward for side = +1 with (ring k, k+1, j, j+1) ordered so the normal
    // points away from the centre; mirrored for side = −1.
    let mut push = |a: usize, b: usize, c: usize| {
        if side > 0.0 {
            triangles.push([a, c, b]);
        } else {
            triangles.push([a, b, c]);
        }
    };
    for k in 0..RINGS - 1 {
        for j in 0..SEGMENTS {
            push(idx(k, j), idx(k + 1, j), idx(k + 1, j + 1));
            push(idx(k, j), idx(k + 1, j + 1), idx(k, j + 1));
        }
    }
    for j in 0..SEGMENTS {
        push(idx(RINGS - 1, j), tip, idx(RINGS - 1, j + 1));
        push(cap, idx(0, j), idx(0, j + 1));
    }
    TriMesh {
        vertices,
        triangles,
    }
}

/// Wavefront OBJ text of a mesh (vertices and triangles only; written directly: the format
/// is two kinds of line).
pub fn to_obj(mesh: &TriMesh, comment: &str) -> String {
    let mut out = format!("# {comment}\n");
    for v in &mesh.vertices {
        out.push_str(&format!("v {} {} {}\n", v.x, v.y, v.z));
    }
    for t in &mesh.triangles {
        out.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_ellipsoid_volume_is_half_the_ellipsoids() {
        let semi = Vector3::new(0.03, 0.04, 0.05);
        let m = ellipsoid_section(&Vector3::zeros(), &semi, 1.0, 0.0);
        let (vol, com, _) = m.volume_props().unwrap();
        let exact = 4.0 / 3.0 * std::f64::consts::PI * semi.x * semi.y * semi.z / 2.0;
        assert!((vol - exact).abs() / exact < 0.02, "{vol} vs {exact}");
        // Centroid of a half ellipsoid: 3/8 of the semi-axis out.
        assert!((com.y - 0.375 * semi.y).abs() < 0.02 * semi.y, "{com}");
        let mirrored = ellipsoid_section(&Vector3::zeros(), &semi, -1.0, 0.0);
        let (vol2, com2, _) = mirrored.volume_props().unwrap();
        assert!((vol2 - vol).abs() < 1e-12 && (com2.y + com.y).abs() < 1e-12);
    }

    #[test]
    fn a_stepped_foot_is_fitted_by_the_hull_a_floor_touches() {
        // A 120 mm sphere as a mesh, plus "steps": vertices inside it (a flat
        // shelf 5 mm above the bottom) that a floor never touches.
        let c = Vector3::new(0.0, 0.0, 0.12);
        let mut m = ellipsoid_section(&c, &Vector3::repeat(0.12), 1.0, -0.12);
        for i in 0..50 {
            let a = i as f64 * 0.1;
            m.vertices
                .push(Vector3::new(0.03 * a.cos(), 0.03 * a.sin(), 0.005));
        }
        let pts = m.support_points(&-Vector3::z(), 60f64.to_radians());
        assert!(pts.iter().all(|p| ((p - c).norm() - 0.12).abs() < 1e-12));
        let f = fit_ellipsoid(&pts).unwrap();
        assert!(
            (f.semi_axes_m - Vector3::repeat(0.12)).norm() < 1e-9,
            "{f:?}"
        );
    }

    #[test]
    fn a_cap_of_a_sphere_fits_the_sphere() {
        // Points on the lower 40° cap of a 120 mm sphere centred at (0.01, 0, 0.1).
        let c = Vector3::new(0.01, 0.0, 0.1);
        let mut pts = Vec::new();
        for i in 0..20 {
            for j in 0..36 {
                let th = (40f64).to_radians() * i as f64 / 19.0;
                let ph = std::f64::consts::TAU * j as f64 / 36.0;
                pts.push(
                    c + Vector3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), -th.cos()) * 0.12,
                );
            }
        }
        let f = fit_ellipsoid(&pts).unwrap();
        assert!((f.center_m - c).norm() < 1e-9, "{f:?}");
        assert!(
            (f.semi_axes_m - Vector3::repeat(0.12)).norm() < 1e-9,
            "{f:?}"
        );
    }
}
