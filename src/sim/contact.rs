//! Pressure-field ("hydroelastic") contact between a compliant ellipsoidal foot and the
//! rigid ground plane z = 0.
//!
//! Model (Elandt et al. 2019, as in Drake for a compliant ellipsoid): the foot carries the
//! pressure field p = E·(1 − r), where r is the ellipsoidal radius r² = Σ (xᵢ/aᵢ)² in the
//! foot frame (r = 1 on the surface, 0 at the centre). The ground is rigid, so the contact
//! surface is the part of the plane inside the foot, an ellipse, and the traction on it is
//! the foot's pressure there.
//!
//! On the plane r² is a quadratic, r² = r₀² + (s − s₀)ᵀ A (s − s₀), with r₀ = h/ρₙ
//! (h: height of the foot centre, ρₙ = √Σ aᵢ²nᵢ² the ellipsoid's support distance along
//! the plane normal n in foot axes) and s₀ the point of the plane deepest in the field.
//! Substituting s − s₀ = L⁻ᵀu (A = LLᵀ) maps the patch to the disk |u|² ≤ 1 − r₀² with a
//! radially symmetric pressure, which gives closed forms:
//! * normal force  F = (π/3)·E·a_x a_y a_z/ρₙ · (1 − r₀)²(1 + 2r₀)
//!   (sphere of radius R pressed by δ: F = πEδ²(1 − 2δ/3R) → πEδ² for δ ≪ R);
//! * centre of pressure = s₀ (the field is symmetric about it);
//! * second moment ∫ p (s−s₀)(s−s₀)ᵀ dA = π·E·J₂(r₀)·A⁻¹/√det A,
//!   J₂ = 1/20 − r₀²/6 + r₀⁴/4 − 2r₀⁵/15;
//! * stored energy U = ∫_overlap p dV = (π/3)·E·a_x a_y a_z·(1/2 − r₀ + r₀³ − r₀⁴/2), whose
//!   gradient is exactly the force and moment above (the rigid-plane case is conservative).
//!
//! A foot may be a *section* of its ellipsoid (the part beyond a cut plane, [`Cut`]); the
//! patch is then the ellipse clipped by a line, a disc segment in u, integrated by an
//! 8 × 4 Gauss rule in (angle, chord) coordinates that is smooth up to the patch rim; its
//! stored energy uses vertical columns (exact while the cut plane is vertical).
//!
//! Dissipation is Hunt–Crossley on the local normal velocity, p = p_e·(1 − d·vₙ(s)) with
//! vₙ > 0 separating. Because vₙ is linear over the patch, its integral is closed form too:
//! the centre velocity scales the force by (1 − d·vₙ₀)₊ and the gradient of vₙ (from the
//! tangential angular velocity) gives a rolling-resistance moment d·n×(S·(n×ω)).
//!
//! Drake's SAP solver models dissipation differently, as a Kelvin–Voigt relaxation time τ_d
//! (`relaxation_time_s`): the dissipative pressure is −τ_d·g·vₙ(s), with g = E/ρₙ the
//! pressure field's gradient along the normal, i.e. proportional to the local penetration
//! *rate* but not to the local pressure. It acts over the whole patch up to its rim (where
//! Hunt–Crossley's vanishes with p_e), so it damps a foot touching down at once and resists
//! rolling more for the same bounce damping. Both forms may be set; the total pressure is
//! clamped at zero point by point over the patch quadrature (a separating rim carries
//! nothing), as Drake clamps each contact polygon's force. With τ_d = 0 the closed forms
//! above are used unchanged.
//!
//! Friction is Coulomb over the patch, t(s) = −μ·p(s)·v(s)/√(|v(s)|² + v_s²), a smooth
//! stiction regularisation: below the stiction speed v_s the traction is viscous with
//! coefficient μp/v_s (micro-slip), above it it saturates at μp. The tangential velocity
//! varies over the patch through the spin ωₙ, so there is no closed form and the traction is
//! integrated by a polar quadrature rule (Gauss–Legendre in radius × uniform in angle)
//! whose weights are normalised to the closed-form normal force; this yields the friction
//! force and the torsional (spin) moment that point contact lacks.
//!
//! An optional rolling resistance (the `rolling_resistance` effect, length e) models what
//! the pressure field lacks, e.g. a floor covering's hysteresis: the centre of pressure
//! shifts by e ahead of the rolling direction, a moment −e·Fₙ·ω_t/|ω_t| in the ground plane
//! (regularised below the rate ω_s and capped as the Hunt–Crossley moment), in both
//! dissipation forms.

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// Material/interface parameters of the foot–ground contact (all SI).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContactParams {
    /// Hydroelastic modulus E [Pa]: pressure at the foot centre.
    pub modulus_pa: f64,
    /// Hunt–Crossley dissipation d [s/m].
    pub dissipation_s_per_m: f64,
    /// Coulomb friction coefficient (static = dynamic).
    pub friction_mu: f64,
    /// Stiction regularisation speed v_s [m/s].
    pub stiction_speed_mps: f64,
    /// Kelvin–Voigt relaxation time τ_d [s] (Drake SAP's `relaxation_time`; 0: none).
    pub relaxation_time_s: f64,
    /// Convex-cone coupling time t_c [s] (0: physical Coulomb friction). With t_c > 0 the
    /// contact works as Drake's SAP does (an engine's artefact, not physics): each patch
    /// point's pressure reacts to vₙ − μ·s instead of vₙ, s the point's slip speed
    /// (regularised, 0 at rest), through the coefficient p_e·d + g·t_c — the pressure
    /// then rises while the point slides and the foot lifts off at about μ·s, as a
    /// convex (Anitescu) relaxation of the friction cone makes it. `Design::model` sets
    /// t_c = τ_d + δt for `friction_cone = "convex"`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub convex_coupling_time_s: f64,
    /// Rolling-resistance length e [m]: the centre of pressure shifts this far ahead of
    /// the rolling direction (0: none; the `rolling_resistance` effect sets it).
    #[serde(default)]
    pub rolling_resistance_m: f64,
    /// Regularisation rate ω_s of the rolling resistance [rad/s]: below it the moment is
    /// viscous, as friction below the stiction speed (`Design::model`: v_s/L).
    #[serde(default)]
    pub rolling_resistance_rate_rad_s: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// Depth [m] at which one upright ellipsoid foot (semi-axes `semi`, vertical last) carries
/// `load_n` under p = E(1 − r): (π/3)·E·a·b·(1 − r₀)²(1 + 2r₀) = load with r₀ = 1 − δ/c,
/// by bisection (the closed form of [`patch`] for an upright foot).
pub fn upright_sinkage_m(modulus_pa: f64, semi: [f64; 3], load_n: f64) -> f64 {
    let force = |d: f64| {
        let r0 = (1.0 - d / semi[2]).max(0.0);
        std::f64::consts::FRAC_PI_3
            * modulus_pa
            * semi[0]
            * semi[1]
            * (1.0 - r0).powi(2)
            * (1.0 + 2.0 * r0)
    };
    let (mut lo, mut hi) = (0.0, semi[2]);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if force(mid) < load_n {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// dF/dδ [N/m] of one upright ellipsoid foot pressed by `depth_m`: 2π·E·a·b·r₀(1 − r₀)/c.
pub fn upright_stiffness_n_per_m(modulus_pa: f64, semi: [f64; 3], depth_m: f64) -> f64 {
    let r0 = (1.0 - depth_m / semi[2]).max(0.0);
    2.0 * std::f64::consts::PI * modulus_pa * semi[0] * semi[1] * r0 * (1.0 - r0) / semi[2]
}

/// Radial Gauss–Legendre nodes/weights on ξ ∈ [0, 1] (3 points).
const GL_NODES: [f64; 3] = [0.112_701_665_379_258_3, 0.5, 0.887_298_334_620_741_7];
const GL_WEIGHTS: [f64; 3] = [
    0.277_777_777_777_777_8,
    0.444_444_444_444_444_4,
    0.277_777_777_777_777_8,
];
/// Angular nodes per ring (uniform rule: exact for trigonometric polynomials of low order).
const N_ANGLE: usize = 8;
/// Gauss–Legendre rule on [−1, 1] with 8 points (clipped patches, angular direction).
const GL8_NODES: [f64; 8] = [
    -0.960_289_856_497_536_3,
    -0.796_666_477_413_626_7,
    -0.525_532_409_916_329,
    -0.183_434_642_495_649_8,
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL8_WEIGHTS: [f64; 8] = [
    0.101_228_536_290_376_3,
    0.222_381_034_453_374_5,
    0.313_706_645_877_887_3,
    0.362_683_783_378_362,
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];
/// Gauss–Legendre rule on [−1, 1] with 4 points (clipped patches, along the chords).
const GL4_NODES: [f64; 4] = [
    -0.861_136_311_594_052_6,
    -0.339_981_043_584_856_3,
    0.339_981_043_584_856_3,
    0.861_136_311_594_052_6,
];
const GL4_WEIGHTS: [f64; 4] = [
    0.347_854_845_137_453_9,
    0.652_145_154_862_546_1,
    0.652_145_154_862_546_1,
    0.347_854_845_137_453_9,
];
/// Quadrature points stored per patch (friction): 24 on a full disc, 32 on a clipped one.
pub const MAX_QUAD: usize = 32;

/// The foot as a section of its ellipsoid: only points s with `normal · s ≥ offset`
/// (world) belong to the foot. A half-space through the ellipsoid centre makes each foot
/// the outer half of its ellipsoid, so two feet centred on the mid-plane form one smooth
/// rocker when the legs are together and the unloaded foot really lifts off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cut {
    pub normal: Vector3<f64>,
    pub offset: f64,
}

/// Geometry and elastic part of one foot's contact patch.
#[derive(Clone, Copy, Debug)]
pub struct Patch {
    /// Minimum ellipsoidal radius on the plane (1 − r₀ is the relative depth).
    pub r0: f64,
    /// Support distance ρₙ of the ellipsoid along the ground normal [m].
    pub support_m: f64,
    /// Penetration depth ρₙ − h [m].
    pub depth_m: f64,
    /// Centre of pressure (world) [m].
    pub cop: Vector3<f64>,
    /// Elastic normal force [N].
    pub elastic_force_n: f64,
    /// dF/d(depth) [N/m], used by the linearly implicit integrator.
    pub stiffness_n_per_m: f64,
    /// ∫ p_e (s−c)(s−c)ᵀ dA over the patch about the centre of pressure c [N·m²].
    pub second_moment: Matrix2<f64>,
    /// Elastic energy stored in the foot [J].
    pub energy_j: f64,
    /// Largest radius of a disc about the centre of pressure inside the patch [m]
    /// (bounds the rolling-resistance moment).
    pub inner_radius_m: f64,
    /// Pressure-weighted quadrature of the patch for friction: offsets from the centre
    /// of pressure (world x, y) and weights summing to 1.
    pub quad_offsets: [Vector2<f64>; MAX_QUAD],
    pub quad_weights: [f64; MAX_QUAD],
    /// Area [m²] and elastic pressure [Pa] of each quadrature point (Kelvin–Voigt
    /// dissipation integrates the local penetration rate over area, clamped point by point).
    pub quad_area_m2: [f64; MAX_QUAD],
    pub quad_pressure_pa: [f64; MAX_QUAD],
    pub quad_len: usize,
    /// Gradient of the pressure field along the ground normal at the deepest point, E/ρₙ
    /// [Pa/m] (Kelvin–Voigt: dissipative pressure = −τ_d·g·vₙ).
    pub pressure_gradient_pa_per_m: f64,
    /// True when the section cut clips the patch.
    pub clipped: bool,
}

/// Patch of a foot (centre `center`, rotation foot→world `rot`, semi-axes `semi`, optional
/// section `cut`) on the plane z = 0, or `None` if the foot does not reach the ground.
pub fn patch(
    center: &Vector3<f64>,
    rot: &Matrix3<f64>,
    semi: &Vector3<f64>,
    modulus_pa: f64,
    cut: Option<&Cut>,
) -> Option<Patch> {
    let mut p = Patch::EMPTY;
    patch_into(&mut p, center, rot, semi, modulus_pa, cut, true).then_some(p)
}

/// As [`patch`], but without the stored energy of clipped patches (`energy_j` = 0 then):
/// the time stepper needs only forces, and the energy quadrature is the costly part.
pub fn patch_forces(
    center: &Vector3<f64>,
    rot: &Matrix3<f64>,
    semi: &Vector3<f64>,
    modulus_pa: f64,
    cut: Option<&Cut>,
) -> Option<Patch> {
    let mut p = Patch::EMPTY;
    patch_into(&mut p, center, rot, semi, modulus_pa, cut, false).then_some(p)
}

impl Patch {
    /// A zero patch (storage for [`patch_into`]).
    pub const EMPTY: Patch = Patch {
        r0: 0.0,
        support_m: 0.0,
        depth_m: 0.0,
        cop: Vector3::new(0.0, 0.0, 0.0),
        elastic_force_n: 0.0,
        stiffness_n_per_m: 0.0,
        second_moment: Matrix2::new(0.0, 0.0, 0.0, 0.0),
        energy_j: 0.0,
        inner_radius_m: 0.0,
        quad_offsets: [Vector2::new(0.0, 0.0); MAX_QUAD],
        quad_weights: [0.0; MAX_QUAD],
        quad_area_m2: [0.0; MAX_QUAD],
        quad_pressure_pa: [0.0; MAX_QUAD],
        quad_len: 0,
        pressure_gradient_pa_per_m: 0.0,
        clipped: false,
    };
}

/// (cos, sin) of the angular nodes of the full-disc rule, per ring (rings staggered by half
/// a sector), computed once: the rule is fixed, so the time stepper need not call sin/cos.
fn ring_trig() -> &'static [[(f64, f64); N_ANGLE]; 3] {
    use std::f64::consts::PI;
    static TABLE: std::sync::OnceLock<[[(f64, f64); N_ANGLE]; 3]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = [[(0.0, 0.0); N_ANGLE]; 3];
        for (i, ring) in t.iter_mut().enumerate() {
            let phase = if i == 1 { PI / N_ANGLE as f64 } else { 0.0 };
            for (j, cs) in ring.iter_mut().enumerate() {
                let th = phase + 2.0 * PI * j as f64 / N_ANGLE as f64;
                *cs = (th.cos(), th.sin());
            }
        }
        t
    })
}

/// In-place form of [`patch`] / [`patch_forces`] (the time stepper's path: the patch is
/// large, so it is written where it is used rather than returned by value). Returns false
/// (and leaves `p` unspecified) when the foot does not reach the ground.
#[allow(clippy::too_many_arguments)]
pub fn patch_into(
    p: &mut Patch,
    center: &Vector3<f64>,
    rot: &Matrix3<f64>,
    semi: &Vector3<f64>,
    modulus_pa: f64,
    cut: Option<&Cut>,
    with_energy: bool,
) -> bool {
    // Ground normal e_z expressed in foot axes = third row of rot.
    let nf = Vector3::new(rot[(2, 0)], rot[(2, 1)], rot[(2, 2)]);
    let a2 = semi.component_mul(semi);
    let rho2 = a2.dot(&nf.component_mul(&nf));
    let rho = rho2.sqrt();
    let h = center.z;
    let r0 = (h / rho).max(0.0);
    if r0 >= 1.0 {
        return false;
    }
    // Deepest point of the plane in the field: x* = −h D⁻¹n/(nᵀD⁻¹n), D = diag(1/a²).
    let xs = a2.component_mul(&nf) * (-h / rho2);
    let s0 = center + rot * xs;
    let abc = semi.x * semi.y * semi.z;
    let one_m = 1.0 - r0;
    // A = top-left block of R·diag(1/a²)·Rᵀ (the plane's tangent basis is world x, y).
    let inv_a2 = Vector3::new(1.0 / a2.x, 1.0 / a2.y, 1.0 / a2.z);
    let w = rot * Matrix3::from_diagonal(&inv_a2) * rot.transpose();
    let (a11, a12, a22) = (w[(0, 0)], w[(0, 1)], w[(1, 1)]);
    let l11 = a11.sqrt();
    let l21 = a12 / l11;
    let l22 = (a22 - l21 * l21).max(1e-300).sqrt();
    // T maps disc coordinates u (|u|² ≤ 1 − r₀²) to plane offsets s − s₀.
    let t = Matrix2::new(1.0 / l11, -l21 / (l11 * l22), 0.0, 1.0 / l22);
    let det_t = 1.0 / (l11 * l22);
    let u_max = (1.0 - r0 * r0).sqrt();
    // Section: the half-plane m·u ≥ d of the disc (None: no clipping).
    let Some(clip) = section_clip(cut, &t, &s0, u_max) else {
        return false;
    };
    p.r0 = r0;
    p.support_m = rho;
    p.depth_m = rho - h;
    p.cop = s0;
    p.elastic_force_n = 0.0;
    p.stiffness_n_per_m = 0.0;
    p.second_moment = Matrix2::zeros();
    p.energy_j = 0.0;
    p.inner_radius_m = 0.0;
    p.quad_len = 0;
    p.pressure_gradient_pa_per_m = modulus_pa / rho;
    p.clipped = clip.is_some();
    // Smallest semi-axis of the patch ellipse = u_max·σ_min(T).
    let sigma_min = {
        let tt = t * t.transpose();
        let tr = tt.trace();
        let det = tt.determinant();
        (0.5 * (tr - (tr * tr - 4.0 * det).max(0.0).sqrt()))
            .max(0.0)
            .sqrt()
    };
    let r02 = r0 * r0;
    let f = PatchFrame {
        t,
        det_t,
        u_max,
        r0,
        r02,
        one_m,
        rho,
        rho2,
        abc,
        modulus_pa,
        sigma_min,
        s0,
        inv_a2,
    };
    match clip {
        None => full_disc(p, &f, a11, a12, a22),
        Some((m, d)) => {
            if !disc_segment(p, &f, m, d, center, rot, with_energy) {
                return false;
            }
        }
    }
    p.cop.z = 0.0;
    true
}

/// What both quadratures of a patch need: the disc-to-plane map `t` (and its determinant),
/// the disc radius, the depth terms and the foot's constants.
#[derive(Clone, Copy)]
struct PatchFrame {
    t: Matrix2<f64>,
    det_t: f64,
    u_max: f64,
    r0: f64,
    r02: f64,
    one_m: f64,
    rho: f64,
    rho2: f64,
    abc: f64,
    modulus_pa: f64,
    sigma_min: f64,
    s0: Vector3<f64>,
    inv_a2: Vector3<f64>,
}

/// The section's half-plane m·u ≥ d of the disc: Some(None) when it does not clip, None
/// when it leaves no contact.
#[inline]
fn section_clip(
    cut: Option<&Cut>,
    t: &Matrix2<f64>,
    s0: &Vector3<f64>,
    u_max: f64,
) -> Option<Option<(Vector2<f64>, f64)>> {
    match cut {
        None => Some(None),
        Some(c) => {
            // n·s ≥ offset on the plane: a·(s₀ + T u) ≥ offset ⇔ (Tᵀa)·u ≥ offset − a·s₀.
            let a = Vector2::new(c.normal.x, c.normal.y);
            let b = c.offset - a.dot(&Vector2::new(s0.x, s0.y));
            let ta = t.transpose() * a;
            let n = ta.norm();
            if n <= 1e-12 {
                // Cut plane parallel to the ground: the whole patch or nothing.
                if b > 0.0 {
                    return None;
                }
                Some(None)
            } else {
                let d = b / n;
                if d >= u_max {
                    return None;
                }
                if d <= -u_max {
                    Some(None)
                } else {
                    Some(Some((ta / n, d)))
                }
            }
        }
    }
}

/// The whole disc: closed-form force, stiffness, energy and second moment, and the
/// pressure-weighted polar rule.
#[inline]
fn full_disc(p: &mut Patch, f: &PatchFrame, a11: f64, a12: f64, a22: f64) {
    use std::f64::consts::{FRAC_PI_3, PI};
    let PatchFrame {
        t,
        det_t,
        u_max,
        r0,
        r02,
        one_m,
        rho,
        rho2,
        abc,
        modulus_pa,
        sigma_min,
        ..
    } = *f;
    p.elastic_force_n = FRAC_PI_3 * modulus_pa * abc / rho * one_m * one_m * (1.0 + 2.0 * r0);
    p.stiffness_n_per_m = 2.0 * PI * modulus_pa * abc * r0 * one_m / rho2;
    p.energy_j = FRAC_PI_3 * modulus_pa * abc * (0.5 - r0 + r0.powi(3) - 0.5 * r0.powi(4));
    let det_a = 1.0 / (det_t * det_t);
    let a_inv = Matrix2::new(a22, -a12, -a12, a11) / det_a;
    let j2 = 1.0 / 20.0 - r02 / 6.0 + r02 * r02 / 4.0 - 2.0 * r02 * r02 * r0 / 15.0;
    p.second_moment = a_inv * (PI * modulus_pa * j2.max(0.0) / det_a.sqrt());
    p.inner_radius_m = u_max * sigma_min;
    // Pressure-weighted polar rule (radial Gauss–Legendre × uniform angle).
    let mut wsum = 0.0;
    // Stagger rings by half a sector so the 24 points cover the disc evenly.
    let trig = ring_trig();
    let sector = 2.0 * PI / N_ANGLE as f64 * u_max * u_max * det_t;
    for ((&xi, &wi), ring) in GL_NODES.iter().zip(GL_WEIGHTS.iter()).zip(trig.iter()) {
        let u = u_max * xi;
        let pe = (1.0 - (r02 + u * u).sqrt()).max(0.0);
        let wgt = wi * xi * pe;
        for &(c, s) in ring {
            let k = p.quad_len;
            p.quad_offsets[k] = t * Vector2::new(u * c, u * s);
            p.quad_weights[k] = wgt;
            p.quad_area_m2[k] = wi * xi * sector;
            p.quad_pressure_pa[k] = modulus_pa * pe;
            wsum += wgt;
            p.quad_len += 1;
        }
    }
    normalise(&mut p.quad_weights[..p.quad_len], wsum);
}

/// A disc segment (the foot's section clips the patch): Gauss rule over the segment;
/// false when no pressure is left.
#[inline]
fn disc_segment(
    p: &mut Patch,
    f: &PatchFrame,
    m: Vector2<f64>,
    d: f64,
    center: &Vector3<f64>,
    rot: &Matrix3<f64>,
    with_energy: bool,
) -> bool {
    use std::f64::consts::{FRAC_PI_3, PI};
    let PatchFrame {
        t,
        det_t,
        u_max,
        r0,
        one_m,
        rho,
        rho2,
        abc,
        modulus_pa,
        sigma_min,
        s0,
        ..
    } = *f;
    let cos_d = (d / u_max).clamp(-1.0, 1.0);
    let (f0, f1, e_sum, k) = segment_quadrature(p, f, m, cos_d, center, rot, with_energy);
    if f0 <= 0.0 {
        return false;
    }
    let shift = f1 / f0;
    let scale = modulus_pa * det_t;
    p.elastic_force_n = scale * f0;
    p.cop = Vector3::new(s0.x + shift.x, s0.y + shift.y, 0.0);
    p.energy_j = modulus_pa * det_t * e_sum;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (off, &wgt) in p.quad_offsets[..k].iter_mut().zip(&p.quad_weights[..k]) {
        *off -= shift;
        sxx += off.x * off.x * wgt;
        sxy += off.x * off.y * wgt;
        syy += off.y * off.y * wgt;
    }
    let s2 = Matrix2::new(sxx, sxy, sxy, syy);
    p.second_moment = s2 * scale;
    p.quad_len = k;
    normalise(&mut p.quad_weights[..k], f0);
    // Slope for the implicit step: the full patch's, scaled by the clipped share.
    let f_full = FRAC_PI_3 * modulus_pa * abc / rho * one_m * one_m * (1.0 + 2.0 * r0);
    let k_full = 2.0 * PI * modulus_pa * abc * r0 * one_m / rho2;
    p.stiffness_n_per_m = k_full * (p.elastic_force_n / f_full.max(1e-300)).min(1.0);
    // Distance from the centre of pressure to the cut line bounds the inner disc.
    let to_cut = (m.dot(&(t.try_inverse().unwrap_or_else(Matrix2::identity) * shift)) - d).max(0.0);
    p.inner_radius_m = (to_cut * sigma_min).min(u_max * sigma_min);
    true
}

/// Fills `p`'s quadrature nodes with the 8 × 4 Gauss rule over the disc segment
/// m·u ≥ d (`cos_d` = d/u_max); returns (Σw, Σw·offset, energy integrand sum, node count).
#[inline]
fn segment_quadrature(
    p: &mut Patch,
    f: &PatchFrame,
    m: Vector2<f64>,
    cos_d: f64,
    center: &Vector3<f64>,
    rot: &Matrix3<f64>,
    with_energy: bool,
) -> (f64, Vector2<f64>, f64, usize) {
    let PatchFrame {
        t,
        det_t,
        u_max,
        r02,
        modulus_pa,
        s0,
        inv_a2,
        ..
    } = *f;
    // Disc segment m·u ≥ d in polar-like coordinates about m: u = U cosφ m +
    // U sinφ σ m⊥, φ ∈ [0, acos(d/U)], σ ∈ [−1, 1]; dA_u = U² sin²φ dφ dσ. The
    // integrand is smooth in (φ, σ), so an 8 × 4 Gauss rule is accurate to ~1e-6.
    let mp = Vector2::new(-m.y, m.x);
    let phi_d = cos_d.acos();
    // Angular nodes φ = h(1 ± ξⱼ), h = φ_d/2 (the Gauss nodes are symmetric): sin/cos
    // by the addition theorem from h (half-angle formulas) and the four hξⱼ.
    let h = 0.5 * phi_d;
    let (ch, sh) = ((0.5 * (1.0 + cos_d)).sqrt(), (0.5 * (1.0 - cos_d)).sqrt());
    let mut trig = [(0.0, 0.0); 8];
    for jn in 0..4 {
        let (sd, cd) = (h * GL8_NODES[4 + jn]).sin_cos();
        trig[4 + jn] = (sh * cd + ch * sd, ch * cd - sh * sd);
        trig[3 - jn] = (sh * cd - ch * sd, ch * cd + sh * sd);
    }
    let mut f0 = 0.0;
    let mut f1 = Vector2::zeros();
    let mut e_sum = 0.0;
    let mut k = 0;
    for (&wp, &(sp, cp)) in GL8_WEIGHTS.iter().zip(trig.iter()) {
        let base = m * (u_max * cp);
        let side = mp * (u_max * sp);
        let jac_p = h * wp * u_max * u_max * sp * sp;
        // The four chord nodes as lanes (packed arithmetic).
        let mut ux = [0.0; 4];
        let mut uy = [0.0; 4];
        let mut wgt = [0.0; 4];
        let mut jac = [0.0; 4];
        for l in 0..4 {
            ux[l] = base.x + side.x * GL4_NODES[l];
            uy[l] = base.y + side.y * GL4_NODES[l];
            jac[l] = jac_p * GL4_WEIGHTS[l];
            let pe = (1.0 - (r02 + ux[l] * ux[l] + uy[l] * uy[l]).sqrt()).max(0.0);
            wgt[l] = jac[l] * pe;
        }
        for l in 0..4 {
            let off = t * Vector2::new(ux[l], uy[l]);
            f0 += wgt[l];
            f1 += off * wgt[l];
            if with_energy {
                let sp_world = Vector3::new(s0.x + off.x, s0.y + off.y, 0.0);
                e_sum += jac[l] * column_energy(&sp_world, center, rot, &inv_a2);
            }
            p.quad_offsets[k] = off;
            p.quad_weights[k] = wgt[l];
            p.quad_area_m2[k] = jac[l] * det_t;
            p.quad_pressure_pa[k] = modulus_pa * wgt[l] / jac[l].max(1e-300);
            k += 1;
        }
    }
    (f0, f1, e_sum, k)
}

fn normalise(w: &mut [f64], sum: f64) {
    if sum > 0.0 {
        let inv = 1.0 / sum;
        for x in w.iter_mut() {
            *x *= inv;
        }
    }
}

/// ∫ (1 − r) dz along the vertical through the ground point `s`, from the ellipsoid's
/// lower surface up to the ground (the part of the foot below the plane), i.e. the
/// elastic energy per unit area / E. With x(z) = x_s + z·n in foot axes,
/// r² = A z² + 2B z + C and ∫√(Az²+2Bz+C) dz has a closed form.
fn column_energy(
    s: &Vector3<f64>,
    center: &Vector3<f64>,
    rot: &Matrix3<f64>,
    inv_a2: &Vector3<f64>,
) -> f64 {
    let xs = rot.transpose() * (s - center);
    let n = Vector3::new(rot[(2, 0)], rot[(2, 1)], rot[(2, 2)]);
    let a = n.component_mul(inv_a2).dot(&n);
    let b = n.component_mul(inv_a2).dot(&xs);
    let c = xs.component_mul(inv_a2).dot(&xs);
    if c >= 1.0 {
        return 0.0;
    }
    // Lower root of A z² + 2B z + C = 1.
    let disc = (b * b - a * (c - 1.0)).max(0.0);
    let z1 = (-b - disc.sqrt()) / a;
    let k = (a * c - b * b).max(0.0);
    let prim = |z: f64| {
        let q = (a * z * z + 2.0 * b * z + c).max(0.0);
        let sq = q.sqrt();
        let lin = a * z + b;
        let sa = a.sqrt() * sq;
        // lin + √(lin² + k) without cancellation for lin < 0.
        let arg = if lin >= 0.0 { lin + sa } else { k / (sa - lin) };
        let log_term = if k > 0.0 && arg > 0.0 {
            k / (2.0 * a * a.sqrt()) * arg.ln()
        } else {
            0.0
        };
        lin * sq / (2.0 * a) + log_term
    };
    ((0.0 - z1) - (prim(0.0) - prim(z1))).max(0.0)
}

/// Contact wrench of one patch and its velocity derivatives.
#[derive(Clone, Copy, Debug)]
pub struct PatchWrench {
    /// Force on the foot, applied at the centre of pressure (world) [N].
    pub force: Vector3<f64>,
    /// Moment on the foot about the centre of pressure (world) [N·m].
    pub moment: Vector3<f64>,
    /// −∂Fₙ/∂vₙ at the centre of pressure [N·s/m] (normal damping).
    pub normal_damping: f64,
    /// Friction damping over (v_x, v_y, ω_z) for the implicit step: the secant of the
    /// regularised Coulomb law (symmetric PSD; see `patch_friction`).
    pub friction_damping: Matrix3<f64>,
    /// −∂M/∂ω of the rolling-resistance moment (symmetric PSD).
    pub rolling_damping: Matrix3<f64>,
    /// ∂Fₙ/∂(v_x, v_y, ω_z) of the convex cone's lift (zero with Coulomb friction): the
    /// step makes the lift implicit in the slip, as SAP's cone projection is, so a foot
    /// slowed by friction within a step is lifted by its slip at the step's end. Taken at
    /// the start of the step it lifted a sliding foot at μ·(its slip before friction), and
    /// the slide case hopped 2.5× higher than Drake's.
    pub lift_slip_gradient: Vector3<f64>,
}

/// Forces on the patch given the velocity `v_cop` of the foot's material point at the
/// centre of pressure and the foot's angular velocity `omega` (both world).
pub fn patch_wrench(
    p: &Patch,
    params: &ContactParams,
    v_cop: &Vector3<f64>,
    omega: &Vector3<f64>,
) -> PatchWrench {
    if params.relaxation_time_s > 0.0 || params.convex_coupling_time_s > 0.0 {
        return patch_wrench_pointwise(p, params, v_cop, omega);
    }
    let d = params.dissipation_s_per_m;
    let hc = 1.0 - d * v_cop.z;
    let (fn_total, normal_damping) = if hc > 0.0 {
        (p.elastic_force_n * hc, d * p.elastic_force_n)
    } else {
        (0.0, 0.0)
    };
    // Rolling resistance from the normal-velocity gradient g = n × ω across the patch:
    // M = d·n×(S g) = d·[n]ₓ S [n]ₓ ω; with n = e_z this is (−d(Sg)_y, d(Sg)_x, 0).
    let mut moment = Vector3::zeros();
    let mut rolling_damping = Matrix3::zeros();
    if hc > 0.0 && d > 0.0 {
        let s = &p.second_moment;
        let g = Vector2::new(-omega.y, omega.x);
        let sg = s * g;
        let mut m = Vector2::new(-d * sg.y, d * sg.x);
        // Keep the shifted centre of pressure inside the patch (the closed form ignores
        // the clamp p ≥ 0, valid while d·|g|·patch radius < 1): |M|/Fₙ ≤ inner radius.
        let cap = fn_total * p.inner_radius_m;
        let mn = m.norm();
        if mn > cap && mn > 0.0 {
            m *= cap / mn;
        }
        moment.x = m.x;
        moment.y = m.y;
        // −∂M/∂ω = d·adj(S) in the x, y block.
        rolling_damping[(0, 0)] = d * s[(1, 1)];
        rolling_damping[(0, 1)] = -d * s[(1, 0)];
        rolling_damping[(1, 0)] = -d * s[(0, 1)];
        rolling_damping[(1, 1)] = d * s[(0, 0)];
    }
    add_rolling_resistance(
        p,
        params,
        fn_total,
        omega,
        &mut moment,
        &mut rolling_damping,
    );
    let weights = &p.quad_weights[..p.quad_len];
    with_friction(p, weights, params, fn_total, v_cop, omega, moment)
        .damped(normal_damping, rolling_damping)
}

/// The normal force `fn_total` and `moment` completed with the patch friction (weighted
/// over the quadrature points by `weights`, which sum to 1); dampings zero, set by
/// [`PatchWrench::damped`].
fn with_friction(
    p: &Patch,
    weights: &[f64],
    params: &ContactParams,
    fn_total: f64,
    v_cop: &Vector3<f64>,
    omega: &Vector3<f64>,
    mut moment: Vector3<f64>,
) -> PatchWrench {
    let mut force = Vector3::new(0.0, 0.0, fn_total);
    let mut friction_damping = Matrix3::zeros();
    if fn_total > 0.0 && params.friction_mu > 0.0 {
        let (f, m_z, k) = patch_friction(p, weights, params, fn_total, v_cop, omega.z);
        force.x = f.x;
        force.y = f.y;
        moment.z += m_z;
        friction_damping = k;
    }
    PatchWrench {
        force,
        moment,
        normal_damping: 0.0,
        friction_damping,
        rolling_damping: Matrix3::zeros(),
        lift_slip_gradient: Vector3::zeros(),
    }
}

impl PatchWrench {
    fn damped(mut self, normal_damping: f64, rolling_damping: Matrix3<f64>) -> PatchWrench {
        self.normal_damping = normal_damping;
        self.rolling_damping = rolling_damping;
        self
    }
}

/// Patch wrench with Kelvin–Voigt (and optionally Hunt–Crossley) dissipation integrated
/// point by point over the patch quadrature: pᵢ = max(p_e,ᵢ(1 − d·vₙ,ᵢ) − τ_d·g·vₙ,ᵢ, 0),
/// with vₙ,ᵢ = vₙ(c) + (n×ω)·rᵢ the local normal velocity. Friction is then weighted by the
/// same point forces, so a point that lifts off carries no friction (as a Drake contact
/// polygon whose force is clamped to zero).
fn patch_wrench_pointwise(
    p: &Patch,
    params: &ContactParams,
    v_cop: &Vector3<f64>,
    omega: &Vector3<f64>,
) -> PatchWrench {
    let d = params.dissipation_s_per_m;
    let kv = params.relaxation_time_s * p.pressure_gradient_pa_per_m;
    let g_n = p.pressure_gradient_pa_per_m;
    let n = p.quad_len;
    // Elastic force and centre of pressure are the closed form's; the quadrature's elastic
    // pressures are rescaled to it so that at rest both paths agree exactly.
    let quad_elastic: f64 = (0..n)
        .map(|i| p.quad_pressure_pa[i] * p.quad_area_m2[i])
        .sum();
    let scale = if quad_elastic > 0.0 {
        p.elastic_force_n / quad_elastic
    } else {
        0.0
    };
    let g = Vector2::new(-omega.y, omega.x);
    let mut weights = [0.0; MAX_QUAD];
    let (mut fz, mut mx, mut my) = (0.0, 0.0, 0.0);
    let mut normal_damping = 0.0;
    let (mut cxx, mut cxy, mut cyy) = (0.0, 0.0, 0.0);
    let mut lift_slip_gradient = Vector3::zeros();
    let tc = params.convex_coupling_time_s;
    let mu = params.friction_mu;
    let vs = params.stiction_speed_mps;
    for (i, w) in weights.iter_mut().enumerate().take(n) {
        let off = p.quad_offsets[i];
        let area = p.quad_area_m2[i];
        let pe = p.quad_pressure_pa[i] * scale;
        let vn = v_cop.z + g.dot(&off);
        let slope = pe * d + kv;
        let mut pi = pe - slope * vn;
        let mut lift = Vector3::zeros();
        if tc > 0.0 {
            // The convex cone's lift: the point's slip speed (as the friction sees it,
            // spin included), regularised like the friction so it is smooth and 0 at rest.
            let vx = v_cop.x - off.y * omega.z;
            let vy = v_cop.y + off.x * omega.z;
            let r = (vx * vx + vy * vy + vs * vs).sqrt();
            let c = (pe * d + g_n * tc) * mu;
            pi += c * (r - vs);
            // ∂(c·slip)/∂(v_x, v_y, ω_z), slip's gradient being its direction û.
            let (ux, uy) = (vx / r, vy / r);
            lift = Vector3::new(ux, uy, -ux * off.y + uy * off.x) * c;
        }
        if pi <= 0.0 {
            continue;
        }
        lift_slip_gradient += lift * area;
        let f = pi * area;
        *w = f;
        fz += f;
        mx += off.y * f;
        my -= off.x * f;
        let c = slope * area;
        normal_damping += c;
        cxx += c * off.x * off.x;
        cxy += c * off.x * off.y;
        cyy += c * off.y * off.y;
    }
    let mut rolling_damping = Matrix3::zeros();
    rolling_damping[(0, 0)] = cyy;
    rolling_damping[(0, 1)] = -cxy;
    rolling_damping[(1, 0)] = -cxy;
    rolling_damping[(1, 1)] = cxx;
    if fz > 0.0 {
        for w in weights[..n].iter_mut() {
            *w /= fz;
        }
    }
    let mut moment = Vector3::new(mx, my, 0.0);
    add_rolling_resistance(p, params, fz, omega, &mut moment, &mut rolling_damping);
    let mut w = with_friction(p, &weights[..n], params, fz, v_cop, omega, moment)
        .damped(normal_damping, rolling_damping);
    w.lift_slip_gradient = lift_slip_gradient;
    w
}

/// Adds the rolling-resistance moment of the `rolling_resistance` effect: the centre of
/// pressure shifted by e ahead of the rolling direction, M = −e·Fₙ·ω_t/√(|ω_t|² + ω_s²)
/// in the ground plane (ω_t = (ω_x, ω_y)), and its frozen-coefficient secant e·Fₙ/s on the
/// (x, y) diagonal of −∂M/∂ω: as for friction, the implicit step can then stop a rolling
/// foot but never reverse it. No-op while e = 0, so the plain model is unchanged.
fn add_rolling_resistance(
    p: &Patch,
    params: &ContactParams,
    fn_total: f64,
    omega: &Vector3<f64>,
    moment: &mut Vector3<f64>,
    rolling_damping: &mut Matrix3<f64>,
) {
    let e = params.rolling_resistance_m;
    if !(e > 0.0 && fn_total > 0.0) {
        return;
    }
    let ws = params.rolling_resistance_rate_rad_s;
    let wt2 = omega.x * omega.x + omega.y * omega.y;
    let s = (wt2 + ws * ws).sqrt();
    if s == 0.0 {
        // At rest without regularisation: no rolling direction, no moment.
        return;
    }
    let mut c = e * fn_total / s;
    // The shifted centre of pressure stays inside the patch: |M| ≤ Fₙ·inner radius.
    let m = c * wt2.sqrt();
    let cap = fn_total * p.inner_radius_m;
    if m > cap {
        c *= cap / m;
    }
    moment.x -= c * omega.x;
    moment.y -= c * omega.y;
    rolling_damping[(0, 0)] += c;
    rolling_damping[(1, 1)] += c;
}

/// Regularised Coulomb friction integrated over the patch: returns the tangential force,
/// the spin moment about the normal through the centre of pressure and the friction's
/// frozen (secant) damping matrix over (v_x, v_y, ω_z), for the implicit step.
fn patch_friction(
    p: &Patch,
    quad_weights: &[f64],
    params: &ContactParams,
    fn_total: f64,
    v_cop: &Vector3<f64>,
    spin: f64,
) -> (Vector2<f64>, f64, Matrix3<f64>) {
    let mu_f = params.friction_mu * fn_total;
    let vs2 = params.stiction_speed_mps * params.stiction_speed_mps;
    let (vx0, vy0) = (v_cop.x, v_cop.y);
    // Per point i (offset r, weight w): v = v_t + spin·r⊥, s = √(|v|² + v_s²), û = v/s,
    // cᵢ = μF w/s; fᵢ = −μF w û = −cᵢ v; moment r × fᵢ = −μF w (û·r⊥).
    // The step treats each point's friction as the viscous force −cᵢ·v with cᵢ frozen
    // over the step (the secant, not the tangent −∂fᵢ/∂v = cᵢ(I − û ûᵀ)): mapped with
    // B = [I | r⊥] this adds cᵢ·BᵀB, i.e. cᵢ, cᵢ·r⊥ and cᵢ|r|². The tangent has no
    // stiffness along the slip, so a sliding point saturated at μ·p reverses in one step
    // whenever μ g h > 2v_s and then chatters at ±μ g h/2 (a period-2 cycle; seen as a
    // 4 mm/s buzz of a stopped foot at h = 1 ms, v_s = 0.1 mm/s); with the secant the
    // implicit update v⁺ = v/(1 + h c/m) can stop a slide but never reverse it.
    // Scalar accumulators keep the loop in registers (the time stepper's hot spot).
    // Four lanes (points i mod 4): element-wise array arithmetic that compiles to packed
    // SIMD instructions.
    const W: usize = 4;
    let mut acc = [[0.0f64; W]; 9];
    let n = p.quad_len;
    let mut i = 0;
    while i < n {
        let m = (n - i).min(W);
        let mut px = [0.0; W];
        let mut py = [0.0; W];
        let mut cw = [0.0; W];
        for l in 0..m {
            px[l] = -p.quad_offsets[i + l].y;
            py[l] = p.quad_offsets[i + l].x;
            cw[l] = mu_f * quad_weights[i + l];
        }
        for l in 0..W {
            let vx = vx0 + px[l] * spin;
            let vy = vy0 + py[l] * spin;
            let inv_s = 1.0 / (vx * vx + vy * vy + vs2).sqrt();
            let (ux, uy) = (vx * inv_s, vy * inv_s);
            let ci = cw[l] * inv_s;
            let a = ux * px[l] + uy * py[l];
            acc[0][l] -= cw[l] * ux;
            acc[1][l] -= cw[l] * uy;
            acc[2][l] -= cw[l] * a;
            acc[3][l] += ci;
            acc[5][l] += ci;
            acc[6][l] += ci * px[l];
            acc[7][l] += ci * py[l];
            acc[8][l] += ci * (px[l] * px[l] + py[l] * py[l]);
        }
        i += W;
    }
    let [fx, fy, mz, k00, k01, k11, k02, k12, k22] = acc.map(|a| (a[0] + a[1]) + (a[2] + a[3]));
    let k = Matrix3::new(k00, k01, k02, k01, k11, k12, k02, k12, k22);
    (Vector2::new(fx, fy), mz, k)
}
