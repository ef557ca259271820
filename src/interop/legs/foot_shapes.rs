//! The foot a leg's lowest collision geometry gives, by shape: where each shape's lowest
//! point is, the surface points the convex-hull fit of a box, cylinder or tilted capsule
//! starts from, and the lower end sphere of an upright capsule.

use std::f64::consts::{FRAC_PI_2, TAU};

use nalgebra::Vector3;

use crate::interop::robot_file::{Frame, Shape};

/// A capsule whose axis is within this angle of vertical stands on its lower end sphere.
pub(super) const UPRIGHT_CAPSULE_DEG: f64 = 5.0;

/// Points per ring of a cylinder's rims and a capsule's hemispheres.
const SEGMENTS: usize = 32;
/// Latitude rings per capsule hemisphere (pole excluded, rim included).
const LATITUDES: usize = 8;

/// The exact lowest height (walker z) of a shape at `fr` in the walker's frame; None for a
/// plane. A mesh's is its lowest vertex.
pub(super) fn lowest_z(shape: &Shape, fr: &Frame) -> Option<f64> {
    let r = &fr.r;
    // Row 2 of r: each of the shape's axes' height per unit length.
    let up = |j: usize| r[(2, j)];
    let axial = up(2).abs();
    let radial = (1.0 - axial * axial).max(0.0).sqrt();
    let depth = match shape {
        Shape::Sphere(rad) => *rad,
        Shape::Ellipsoid(s) => (0..3).map(|j| (up(j) * s[j]).powi(2)).sum::<f64>().sqrt(),
        Shape::Box(h) => (0..3).map(|j| (up(j) * h[j]).abs()).sum(),
        Shape::Cylinder(rad, h) => axial * h + radial * rad,
        Shape::Capsule(rad, h) => axial * h + rad,
        Shape::Mesh(m) => {
            return m.vertices.iter().map(|v| (r * v + fr.p).z).reduce(f64::min);
        }
        Shape::Plane => return None,
    };
    Some(fr.p.z - depth)
}

/// Surface points of a box (its 8 corners), a cylinder (a ring on each cap's rim) or a
/// capsule (latitude rings and the pole of each end's hemisphere) in the shape's frame:
/// every point of their convex hull a floor can touch is one of these or lies between
/// neighbours. None for other shapes.
pub(super) fn surface_points(shape: &Shape) -> Option<Vec<Vector3<f64>>> {
    let ring = |rad: f64, z: f64| {
        (0..SEGMENTS).map(move |j| {
            let phi = TAU * j as f64 / SEGMENTS as f64;
            Vector3::new(rad * phi.cos(), rad * phi.sin(), z)
        })
    };
    let pts = match shape {
        Shape::Box(h) => (0..8)
            .map(|k| {
                let s = |b: usize| if k & (1 << b) == 0 { -1.0 } else { 1.0 };
                Vector3::new(s(0) * h.x, s(1) * h.y, s(2) * h.z)
            })
            .collect(),
        Shape::Cylinder(rad, h) => ring(*rad, -h).chain(ring(*rad, *h)).collect(),
        Shape::Capsule(rad, h) => {
            let mut pts = Vec::new();
            for end in [-1.0, 1.0] {
                pts.push(Vector3::new(0.0, 0.0, end * (h + rad)));
                for i in 1..=LATITUDES {
                    // Polar angle from the pole down to the rim where the cylinder begins.
                    let th = FRAC_PI_2 * i as f64 / LATITUDES as f64;
                    pts.extend(ring(rad * th.sin(), end * (h + rad * th.cos())));
                }
            }
            pts
        }
        _ => return None,
    };
    Some(pts)
}

/// An upright capsule's foot: the sphere of its radius about its lower end point (exactly
/// the capsule near the ground), as centre and radius in the walker's frame; None for other
/// shapes or a capsule more than `UPRIGHT_CAPSULE_DEG` from vertical.
pub(super) fn upright_capsule_end(shape: &Shape, fr: &Frame) -> Option<(Vector3<f64>, f64)> {
    let Shape::Capsule(rad, h) = shape else {
        return None;
    };
    let axis = fr.r.column(2).into_owned();
    if axis.z.abs() < UPRIGHT_CAPSULE_DEG.to_radians().cos() {
        return None;
    }
    let down = if axis.z > 0.0 { -axis } else { axis };
    Some((fr.p + down * *h, *rad))
}
