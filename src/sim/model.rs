//! Rigid-body model of the two-leg walker and its time integrator.
//!
//! Coordinates (reduced, the hip joint is exact): the left leg is the floating base, the
//! right leg hangs on it by a revolute joint about the left leg's y axis.
//! * positions: hip point p (world), left-leg orientation R (unit quaternion), hip angle q
//!   (rotation of the right leg relative to the left about +y);
//! * velocities ν = (v, ω, q̇): world velocity of the hip point, left-leg angular velocity in
//!   the left-leg frame, hip rate. 6 + 1 = 7 DOF.
//!
//! World: x forward, y left, z up, ground z = 0; a slope is modelled by tilting gravity.
//! Each leg frame has its origin at the hip point and is aligned with the world when the
//! robot stands upright with its legs together.
//!
//! Equations of motion M(x)·ν̇ = τ(x, ν) with M = Σ JₗᵀmJₗ + JₐᵀI_wJₐ over the two bodies and
//! τ = gravity + contact + hip torques − Coriolis/centrifugal terms, all built from the body
//! Jacobians (Newton–Euler projected on the generalized velocities).
//!
//! Integrator: linearly implicit (semi-implicit) Euler on velocities, symplectic update of
//! positions: (M + h·D)Δν = h·τ, ν⁺ = ν + Δν, x⁺ = x ⊕ h·ν⁺. D = −∂τ/∂ν − h·∂τ/∂x collects the
//! stiff contributions (contact stiffness and Hunt–Crossley damping, regularised friction,
//! hardstops, servo gains, effect dampings) so the stiff terms stay stable at a time step
//! set by the gait, not by the contact.

use nalgebra::{Matrix3, SMatrix, UnitQuaternion, Vector3};
use serde::Serialize;

use super::contact::{self, ContactParams, Cut, Patch};
use super::control::Controller;
use super::effects::{Effect, EffectContext, GeneralizedForce};
use super::state::{Kinematics, Matrix7, State, Vector7};

/// Standard gravity [m/s²]. A constant of the model (a slope tilts it, see
/// [`Model::gravity_mps2`]); the similarity rules (`similarity.rs`) keep it fixed.
pub const GRAVITY_MPS2: f64 = 9.81;

type Jac = SMatrix<f64, 3, 7>;

/// One rigid leg (frame origin at the hip point).
#[derive(Clone, Debug, PartialEq)]
pub struct Leg {
    pub mass_kg: f64,
    /// Centre of mass in the leg frame [m].
    pub com_m: Vector3<f64>,
    /// Rotational inertia about the centre of mass, leg axes [kg·m²].
    pub inertia_com_kgm2: Matrix3<f64>,
    /// Centre of the foot ellipsoid in the leg frame [m].
    pub foot_center_m: Vector3<f64>,
    /// Foot semi-axes (R_X forward, R_Y lateral, R_Z vertical) along the leg axes [m].
    pub foot_semi_axes_m: Vector3<f64>,
    /// The foot as a section of the ellipsoid (None: the whole ellipsoid).
    pub foot_section: Option<FootSection>,
}

/// Section of a foot ellipsoid: the foot is the part with `normal · x ≥ offset_m`
/// (x in the leg frame, whose origin is the hip point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FootSection {
    pub normal: Vector3<f64>,
    pub offset_m: f64,
}

/// Stiff one-sided hip limits |q| ≤ limit (spring-damper acting only beyond the limit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hardstop {
    pub limit_rad: f64,
    pub stiffness_nm_per_rad: f64,
    pub damping_nms_per_rad: f64,
}

/// Physical model: bodies, contact, limits, gravity.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// [left (floating base), right].
    pub legs: [Leg; 2],
    pub contact: ContactParams,
    pub hardstop: Option<Hardstop>,
    /// Gravity vector in world axes [m/s²] (tilted for a slope).
    pub gravity_mps2: Vector3<f64>,
    /// Contact with the ground (off for free-flight tests).
    pub ground_contact: bool,
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// D += JᵀKJ on the upper triangle (K symmetric); columns of J before `first` are zero.
fn add_jt_k_j_upper(d: &mut Matrix7, j: &Jac, k: &Matrix3<f64>, first: usize) {
    let kj = k * j;
    for a in first..7 {
        let ja = j.column(a);
        for b in a..7 {
            d[(a, b)] += ja.dot(&kj.column(b));
        }
    }
}

/// Solves A x = b for symmetric positive definite A (Cholesky, unrolled for 7×7); None
/// when A is not numerically positive definite. (Index loops read best for the
/// triangular factors.)
#[allow(clippy::needless_range_loop)]
fn cholesky_solve(a: &Matrix7, b: &Vector7) -> Option<Vector7> {
    let mut l = [[0.0f64; 7]; 7];
    // Reciprocals of the diagonal of L: one division per row.
    let mut inv = [0.0f64; 7];
    for i in 0..7 {
        for j in 0..=i {
            let mut sum = a[(i, j)];
            for k in 0..j {
                sum -= l[i][k] * l[j][k];
            }
            if i == j {
                if sum.is_nan() || sum <= 0.0 {
                    return None;
                }
                l[i][i] = sum.sqrt();
                inv[i] = 1.0 / l[i][i];
            } else {
                l[i][j] = sum * inv[j];
            }
        }
    }
    let mut y = [0.0f64; 7];
    for i in 0..7 {
        let mut sum = b[i];
        for k in 0..i {
            sum -= l[i][k] * y[k];
        }
        y[i] = sum * inv[i];
    }
    let mut x = Vector7::zeros();
    for i in (0..7).rev() {
        let mut sum = y[i];
        for k in i + 1..7 {
            sum -= l[k][i] * x[k];
        }
        x[i] = sum * inv[i];
    }
    Some(x)
}

fn rot_y(q: f64) -> Matrix3<f64> {
    let (s, c) = q.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Breakdown of the mechanical energy [J].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Energy {
    pub kinetic_j: f64,
    pub gravity_j: f64,
    pub contact_j: f64,
    pub hardstop_j: f64,
}

impl Energy {
    pub fn total_j(&self) -> f64 {
        self.kinetic_j + self.gravity_j + self.contact_j + self.hardstop_j
    }
}

/// What happened during one step (for metrics).
#[derive(Clone, Copy, Debug, Default)]
pub struct StepInfo {
    /// Hip torque delivered by the actuator (after effects) [N·m].
    pub actuator_torque_nm: f64,
    /// Number of feet in contact.
    pub feet_in_contact: u8,
    /// Normal contact force on each foot, [left, right] [N] (0 when off the ground).
    pub normal_force_n: [f64; 2],
}

/// A foot's contact under the convex cone, for the step's second pass. The first pass
/// weighs friction with the start-of-step normal force Fₙ⁰, but under the convex cone
/// Fₙ changes a lot within a step (a sliding foot is pushed off the ground), and SAP's
/// friction impulse is μ times the normal impulse the step applies. So the step solves
/// again with friction scaled by Fₙ/Fₙ⁰, Fₙ = Fₙ⁰ + ∂Fₙ/∂ν·Δν (clamped at 0): friction is
/// linear in Fₙ at frozen weights, so the scaled force and secant are exact. With friction
/// at Fₙ⁰ (no second pass) the slide case's foot stayed down and stopped 8× sooner than
/// SAP's; the passes alternate around their fixed point (stopping distance after 1, 2, 4,
/// 8 passes: 45.6, 20.2, 22.3, 23.0 mm), so 4 are taken.
#[derive(Clone, Copy, Debug)]
struct ConvexContact {
    /// ∂Fₙ/∂ν: −cₙ·J_n (normal damping and implicit stiffness) + the lift's G·J_c.
    normal_row: SMatrix<f64, 1, 7>,
    /// Fₙ⁰ [N].
    normal_force_n: f64,
    /// Friction's generalized force at Fₙ⁰, J_cᵀ(f_x, f_y, m_z).
    friction_force: Vector7,
    /// Friction's secant damping at Fₙ⁰ in generalized coordinates, J_cᵀ K J_c.
    friction_damping: Matrix7,
    /// The contact's whole generalized force and damping (normal, friction, rolling and
    /// lift), taken out for the step once the step would pull on the foot (Fₙ < 0), as
    /// SAP clamps its impulse at zero; otherwise the linearised force turns adhesive while
    /// friction, scaled by Fₙ/Fₙ⁰, is clamped at zero. (It seldom acts: the slide's
    /// distance moved by 1.5 % with it.)
    force: Vector7,
    damping: Matrix7,
}

/// Passes of the convex cone's friction rescaling after the first solve.
const CONVEX_FRICTION_PASSES: usize = 4;

impl Model {
    /// Gravity and velocity-product (Coriolis/centrifugal) terms, as wrenches at the COMs.
    #[inline]
    fn add_body_forces(&self, s: &State, kin: &Kinematics, tau: &mut Vector7) {
        let w0 = kin.omega_w[0];
        let alpha_bias = [Vector3::zeros(), w0.cross(&kin.axis_w) * s.hip_rate_rad_s];
        for (k, (leg, alpha_b)) in self.legs.iter().zip(alpha_bias.iter()).enumerate() {
            let r = kin.com_offset_w[k];
            let w = kin.omega_w[k];
            // I_w·x = R (I_c (Rᵀx)) (cheaper than forming I_w).
            let rk = kin.rot[k];
            let iw_mul = |x: &Vector3<f64>| rk * (leg.inertia_com_kgm2 * (rk.transpose() * x));
            let a_bias = alpha_b.cross(&r) + w.cross(&w.cross(&r));
            let f = self.gravity_mps2 * leg.mass_kg - a_bias * leg.mass_kg;
            let m = -(iw_mul(alpha_b) + w.cross(&iw_mul(&w)));
            Model::add_wrench(tau, k, kin, &r, &f, &m);
        }
    }

    /// Foot contacts: their wrenches into `tau`, their damping (normal, with h × stiffness,
    /// friction and rolling) into the upper triangle of `damp`.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn add_contacts(
        &self,
        s: &State,
        kin: &Kinematics,
        nu: &Vector7,
        h: f64,
        tau: &mut Vector7,
        damp: &mut Matrix7,
        lift: &mut Matrix7,
        convex: &mut [Option<ConvexContact>; 2],
        info: &mut StepInfo,
    ) {
        let mut patch = Patch::EMPTY;
        for (k, convex_k) in convex.iter_mut().enumerate() {
            if !self.patch_of_foot(k, s, kin, false, &mut patch) {
                continue;
            }
            let p = &patch;
            info.feet_in_contact += 1;
            let r = p.cop - s.hip_position_m;
            let jp = Model::point_jacobian(k, kin, &r);
            let ja = Model::angular_jacobian(k, kin);
            let v_cop = jp * nu;
            let wr = contact::patch_wrench(p, &self.contact, &v_cop, &kin.omega_w[k]);
            info.normal_force_n[k] = wr.force.z.max(0.0);
            Model::add_wrench(tau, k, kin, &r, &wr.force, &wr.moment);
            // Normal: damping plus h × stiffness (implicit in position along the normal).
            let cn = wr.normal_damping + h * p.stiffness_n_per_m;
            for a in 0..7 {
                let ja_n = jp[(2, a)] * cn;
                for b in a..7 {
                    damp[(a, b)] += ja_n * jp[(2, b)];
                }
            }
            // Friction acts on (v_x, v_y, ω_z) of the patch.
            let mut jc = Jac::zeros();
            jc.row_mut(0).copy_from(&jp.row(0));
            jc.row_mut(1).copy_from(&jp.row(1));
            jc.row_mut(2).copy_from(&ja.row(2));
            add_jt_k_j_upper(damp, &jc, &wr.friction_damping, 0);
            if wr.rolling_damping[(0, 0)] != 0.0 || wr.rolling_damping[(1, 1)] != 0.0 {
                // J_a is zero in the translational columns.
                add_jt_k_j_upper(damp, &ja, &wr.rolling_damping, 3);
            }
            if self.contact.convex_coupling_time_s > 0.0 && wr.force.z > 0.0 {
                // The convex cone's lift, Fₙ rising with the slip (∂Fₙ/∂v_c = G), implicit
                // in the slip as in SAP's cone projection: −J_nᵀ G J_c, not symmetric, so
                // kept apart from `damp`'s triangle. What friction needs for the step's
                // second pass is kept in `convex` (see `ConvexContact`).
                let slip_row = wr.lift_slip_gradient.transpose() * jc;
                let lift_k = -(jp.row(2).transpose() * slip_row);
                *lift += lift_k;
                let mut force = Vector7::zeros();
                Model::add_wrench(&mut force, k, kin, &r, &wr.force, &wr.moment);
                let jn = jp.row(2);
                let friction_damping = jc.transpose() * wr.friction_damping * jc;
                let damping = jn.transpose() * jn * cn
                    + friction_damping
                    + ja.transpose() * wr.rolling_damping * ja
                    + lift_k;
                *convex_k = Some(ConvexContact {
                    normal_row: slip_row - jn * cn,
                    normal_force_n: wr.force.z,
                    friction_force: jc.transpose()
                        * Vector3::new(wr.force.x, wr.force.y, wr.moment.z),
                    friction_damping,
                    force,
                    damping,
                });
            }
        }
    }

    /// The hip's hardstops: a one-sided spring and damper beyond the limit.
    #[inline]
    fn add_hardstop(&self, s: &State, h: f64, tau: &mut Vector7, damp: &mut Matrix7) {
        if let Some(hs) = self.hardstop {
            let q = s.hip_angle_rad;
            let e = q.abs() - hs.limit_rad;
            if e > 0.0 {
                // One-sided (Hunt–Crossley-like) stop: spring plus damping on the inward rate,
                // never pulling the leg back onto the stop while it leaves.
                let sign = q.signum();
                let push =
                    hs.stiffness_nm_per_rad * e + hs.damping_nms_per_rad * sign * s.hip_rate_rad_s;
                if push > 0.0 {
                    tau[6] -= sign * push;
                    damp[(6, 6)] += hs.damping_nms_per_rad + h * hs.stiffness_nm_per_rad;
                }
            }
        }
    }

    pub fn total_mass_kg(&self) -> f64 {
        self.legs[0].mass_kg + self.legs[1].mass_kg
    }

    pub fn kinematics(&self, s: &State) -> Kinematics {
        let r0 = *s.orientation.to_rotation_matrix().matrix();
        let r1 = r0 * rot_y(s.hip_angle_rad);
        let axis_w = r0.column(1).into_owned();
        let w0 = r0 * s.angular_velocity_rad_s;
        let w1 = w0 + axis_w * s.hip_rate_rad_s;
        Kinematics {
            rot: [r0, r1],
            axis_w,
            omega_w: [w0, w1],
            com_offset_w: [r0 * self.legs[0].com_m, r1 * self.legs[1].com_m],
        }
    }

    /// Linear Jacobian of a point of body k at offset r (world) from the hip point.
    fn point_jacobian(k: usize, kin: &Kinematics, r: &Vector3<f64>) -> Jac {
        let mut j = Jac::zeros();
        j.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&Matrix3::identity());
        j.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-skew(r) * kin.rot[0]));
        if k == 1 {
            j.fixed_view_mut::<3, 1>(0, 6)
                .copy_from(&kin.axis_w.cross(r));
        }
        j
    }

    /// Angular Jacobian of body k.
    fn angular_jacobian(k: usize, kin: &Kinematics) -> Jac {
        let mut j = Jac::zeros();
        j.fixed_view_mut::<3, 3>(0, 3).copy_from(&kin.rot[0]);
        if k == 1 {
            j.fixed_view_mut::<3, 1>(0, 6).copy_from(&kin.axis_w);
        }
        j
    }

    /// Adds the generalized force of a wrench (force `f` at offset `r` from the hip point,
    /// plus moment `m`, world) acting on body k.
    fn add_wrench(
        tau: &mut Vector7,
        k: usize,
        kin: &Kinematics,
        r: &Vector3<f64>,
        f: &Vector3<f64>,
        m: &Vector3<f64>,
    ) {
        let moment = r.cross(f) + m;
        tau[0] += f.x;
        tau[1] += f.y;
        tau[2] += f.z;
        let mb = kin.rot[0].transpose() * moment;
        tau[3] += mb.x;
        tau[4] += mb.y;
        tau[5] += mb.z;
        if k == 1 {
            tau[6] += kin.axis_w.dot(&moment);
        }
    }

    /// Mass matrix M(x) = Σₖ mₖ JₗᵀJₗ + JₐᵀI_wJₐ, assembled block by block from the
    /// structure of the Jacobians (J_l = [I | −[r]ₓR₀ | a×r], J_a = [0 | R₀ | a]): with
    /// r_b = R₀ᵀr the COM offset in the left-leg frame, the (ω, ω) block is
    /// m(|r_b|²I − r_b r_bᵀ) + R_y(q) I_c R_y(q)ᵀ (right leg; I_c for the left), the (ω, q)
    /// column m·r_b×(e_y×r_b) + R_y I_c e_y and the (q, q) entry m|e_y×r_b|² + I_c,yy.
    pub fn mass_matrix(&self, kin: &Kinematics) -> Matrix7 {
        let mut m = Matrix7::zeros();
        let r0 = &kin.rot[0];
        let r0t = r0.transpose();
        // R_y(q) = R₀ᵀR₁.
        let ry = r0t * kin.rot[1];
        for k in 0..2 {
            let leg = &self.legs[k];
            let mass = leg.mass_kg;
            let r = kin.com_offset_w[k];
            let rb = r0t * r;
            for i in 0..3 {
                m[(i, i)] += mass;
            }
            // (v, ω): m·B, B = −[r]ₓR₀ (column j = R₀ⱼ × r).
            for j in 0..3 {
                let col = r0.column(j).cross(&r) * mass;
                for i in 0..3 {
                    m[(i, 3 + j)] += col[i];
                }
            }
            // (ω, ω).
            let ib = if k == 1 {
                ry * leg.inertia_com_kgm2 * ry.transpose()
            } else {
                leg.inertia_com_kgm2
            };
            let rr = rb.norm_squared();
            for i in 0..3 {
                for j in 0..3 {
                    let delta = if i == j { rr } else { 0.0 };
                    m[(3 + i, 3 + j)] += mass * (delta - rb[i] * rb[j]) + ib[(i, j)];
                }
            }
            if k == 1 {
                let ey = Vector3::y();
                let c_b = ey.cross(&rb);
                // (v, q): m·(a × r) in world.
                let c = kin.axis_w.cross(&r) * mass;
                for i in 0..3 {
                    m[(i, 6)] += c[i];
                }
                // (ω, q).
                let wq = rb.cross(&c_b) * mass + ib.column(1);
                for i in 0..3 {
                    m[(3 + i, 6)] += wq[i];
                }
                m[(6, 6)] += mass * c_b.norm_squared() + ib[(1, 1)];
            }
        }
        // Symmetric: mirror the upper triangle.
        for i in 0..7 {
            for j in 0..i {
                m[(i, j)] = m[(j, i)];
            }
        }
        m
    }

    /// Foot patches [left, right] (None when off the ground or contact disabled).
    pub fn patches(&self, s: &State, kin: &Kinematics) -> [Option<Patch>; 2] {
        self.patches_impl(s, kin, true)
    }

    fn patches_impl(&self, s: &State, kin: &Kinematics, with_energy: bool) -> [Option<Patch>; 2] {
        let mut out = [None, None];
        for (k, slot) in out.iter_mut().enumerate() {
            let mut p = Patch::EMPTY;
            if self.patch_of_foot(k, s, kin, with_energy, &mut p) {
                *slot = Some(p);
            }
        }
        out
    }

    /// Writes foot k's patch into `p`; false when the foot is off the ground (or contact
    /// is disabled).
    fn patch_of_foot(
        &self,
        k: usize,
        s: &State,
        kin: &Kinematics,
        with_energy: bool,
        p: &mut Patch,
    ) -> bool {
        if !self.ground_contact {
            return false;
        }
        let leg = &self.legs[k];
        let c = s.hip_position_m + kin.rot[k] * leg.foot_center_m;
        // normal·x ≥ offset with x = Rᵀ(s − hip) ⇔ (R normal)·s ≥ offset + (R normal)·hip.
        let cut = leg.foot_section.map(|f| {
            let n = kin.rot[k] * f.normal;
            Cut {
                normal: n,
                offset: f.offset_m + n.dot(&s.hip_position_m),
            }
        });
        let (semi, e) = (&leg.foot_semi_axes_m, self.contact.modulus_pa);
        contact::patch_into(p, &c, &kin.rot[k], semi, e, cut.as_ref(), with_energy)
    }

    /// Lowest hip height at which every foot is at or above the ground with the left leg
    /// at orientation `r` (leg → world) and the legs together (q = 0): the highest
    /// foot-touch height over the legs, from each ellipsoid's support distance.
    pub fn touch_height_m(&self, r: &Matrix3<f64>) -> f64 {
        let nf = r.transpose() * Vector3::z();
        self.legs
            .iter()
            .map(|leg| {
                let a = leg.foot_semi_axes_m;
                let support =
                    (a.x * a.x * nf.x * nf.x + a.y * a.y * nf.y * nf.y + a.z * a.z * nf.z * nf.z)
                        .sqrt();
                support - (r * leg.foot_center_m).z
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Static sinkage of one spherical foot carrying the whole weight, √(m g/(π E))
    /// (F = π E δ² for δ ≪ R): how far a start is lowered below just touching.
    pub fn single_foot_sinkage_m(&self) -> f64 {
        (self.total_mass_kg() * GRAVITY_MPS2 / (std::f64::consts::PI * self.contact.modulus_pa))
            .sqrt()
    }

    /// Mechanical energy (kinetic + gravity + elastic contact + hardstop springs).
    pub fn energy(&self, s: &State) -> Energy {
        let kin = self.kinematics(s);
        let m = self.mass_matrix(&kin);
        let nu = s.velocity();
        let kinetic_j = 0.5 * nu.dot(&(m * nu));
        let mut gravity_j = 0.0;
        for k in 0..2 {
            gravity_j -= self.legs[k].mass_kg
                * self
                    .gravity_mps2
                    .dot(&(s.hip_position_m + kin.com_offset_w[k]));
        }
        let contact_j = self
            .patches(s, &kin)
            .iter()
            .flatten()
            .map(|p| p.energy_j)
            .sum();
        let hardstop_j = match self.hardstop {
            Some(h) => {
                let e = (s.hip_angle_rad.abs() - h.limit_rad).max(0.0);
                0.5 * h.stiffness_nm_per_rad * e * e
            }
            None => 0.0,
        };
        Energy {
            kinetic_j,
            gravity_j,
            contact_j,
            hardstop_j,
        }
    }
}

/// A model with its controller, effects and state, advanced by fixed steps.
pub struct Simulator {
    pub model: Model,
    pub controller: Controller,
    pub effects: Vec<Box<dyn Effect>>,
    pub state: State,
    pub time_s: f64,
    pub dt_s: f64,
}

impl Simulator {
    pub fn new(
        model: Model,
        controller: Controller,
        effects: Vec<Box<dyn Effect>>,
        state: State,
        dt_s: f64,
    ) -> Self {
        Simulator {
            model,
            controller,
            effects,
            state,
            time_s: 0.0,
            dt_s,
        }
    }

    /// Advances the state by one time step.
    pub fn step(&mut self) -> StepInfo {
        let h = self.dt_s;
        let model = &self.model;
        let s = self.state;
        let kin = model.kinematics(&s);
        let mass = model.mass_matrix(&kin);
        let nu = s.velocity();
        let mut tau = Vector7::zeros();
        let mut damp = Matrix7::zeros();
        let mut lift = Matrix7::zeros();
        let mut convex = [None; 2];
        let mut info = StepInfo::default();
        model.add_body_forces(&s, &kin, &mut tau);
        model.add_contacts(
            &s,
            &kin,
            &nu,
            h,
            &mut tau,
            &mut damp,
            &mut lift,
            &mut convex,
            &mut info,
        );
        // The contact terms filled the upper triangle only.
        for a in 0..7 {
            for b in 0..a {
                damp[(a, b)] = damp[(b, a)];
            }
        }
        let symmetric = model.contact.convex_coupling_time_s == 0.0;
        if !symmetric {
            damp += lift;
        }
        model.add_hardstop(&s, h, &mut tau, &mut damp);
        let (torque, torque_slope, limit) =
            self.actuator_and_effects(&s, &kin, &mut tau, &mut damp);
        let actuator = (torque, torque_slope, limit);
        let (mut dnu, mut applied) = velocity_change(&mass, &damp, &tau, h, actuator, symmetric);
        if convex.iter().any(Option::is_some) {
            let mut released = [false; 2];
            for _ in 0..CONVEX_FRICTION_PASSES {
                let (mut tau2, mut damp2) = (tau, damp);
                for (k, c) in convex.iter().enumerate() {
                    let Some(c) = c else { continue };
                    let f = c.normal_force_n + (c.normal_row * dnu)[0];
                    released[k] |= f <= 0.0;
                    if released[k] {
                        tau2 -= c.force;
                        damp2 -= c.damping;
                    } else {
                        let scale = f / c.normal_force_n - 1.0;
                        tau2 += c.friction_force * scale;
                        damp2 += c.friction_damping * scale;
                    }
                }
                (dnu, applied) = velocity_change(&mass, &damp2, &tau2, h, actuator, false);
            }
        }
        let nu_new = nu + dnu;
        info.actuator_torque_nm = applied;
        let mut ns = s;
        ns.set_velocity(&nu_new);
        ns.hip_position_m += ns.hip_velocity_mps * h;
        ns.orientation *= UnitQuaternion::from_scaled_axis(ns.angular_velocity_rad_s * h);
        ns.orientation.renormalize_fast();
        ns.hip_angle_rad += ns.hip_rate_rad_s * h;
        self.state = ns;
        self.time_s += h;
        info
    }

    /// Actuator, then effects (which may reshape the actuator torque and add forces): the
    /// hip torque, its slope against the hip rate and the servo's torque limit; the effects'
    /// generalized forces are added to `tau` and `damp`.
    #[inline]
    fn actuator_and_effects(
        &mut self,
        s: &State,
        kin: &Kinematics,
        tau: &mut Vector7,
        damp: &mut Matrix7,
    ) -> (f64, f64, Option<f64>) {
        let h = self.dt_s;
        let ctx = EffectContext {
            time_s: self.time_s,
            dt_s: h,
            state: s,
            kinematics: kin,
        };
        // The servo's PD torque is implicit in the hip motion (slope k_d + h·k_p); its
        // torque limit bounds the torque the step *applies*, τ₀ − slope·Δq̇, as Drake's
        // implicit PD actuator does: solve with the unclamped command, and if the applied
        // torque exceeds the limit, solve again with the limit as a constant torque.
        // (Clamping the start-of-step command instead applied up to 46 % more than the
        // implicit torque whenever it saturated.)
        let cmd = self
            .controller
            .command_unclamped(self.time_s, s.hip_angle_rad, s.hip_rate_rad_s);
        let limit = match self.controller {
            Controller::ServoSine {
                torque_limit_nm, ..
            } => Some(torque_limit_nm),
            _ => None,
        };
        let mut torque = cmd.torque_nm;
        let mut torque_slope = cmd.damping_nms_per_rad + h * cmd.stiffness_nm_per_rad;
        for e in self.effects.iter_mut() {
            let (t, scale) = e.actuator_torque(&ctx, torque);
            torque = t;
            torque_slope *= scale;
        }
        let mut gf = GeneralizedForce::default();
        for e in self.effects.iter_mut() {
            e.generalized_force(&ctx, &mut gf);
        }
        *tau += gf.force;
        *damp += gf.damping;
        (torque, torque_slope, limit)
    }
}

/// Linearly implicit velocity update: Δν from (M + h·D)Δν = h·τ with the hip torque and
/// its slope, and the torque the step applies (clamped to the servo's limit by solving
/// again with the limit as a constant torque).
/// `symmetric` is false when the convex cone's lift makes `damp` non-symmetric; the
/// system is then solved by LU.
#[inline]
fn velocity_change(
    mass: &Matrix7,
    damp: &Matrix7,
    tau: &Vector7,
    h: f64,
    (torque, torque_slope, limit): (f64, f64, Option<f64>),
    symmetric: bool,
) -> (Vector7, f64) {
    let a0 = mass + damp * h;
    let solve = |torque: f64, slope: f64| {
        let mut a = a0;
        a[(6, 6)] += slope * h;
        let mut rhs = tau * h;
        rhs[6] += torque * h;
        match symmetric.then(|| cholesky_solve(&a, &rhs)).flatten() {
            Some(x) => x,
            None => a.lu().solve(&rhs).unwrap_or_else(Vector7::zeros),
        }
    };
    let mut dnu = solve(torque, torque_slope);
    let mut applied = torque - torque_slope * dnu[6];
    if let Some(lim) = limit
        && applied.abs() > lim
    {
        applied = lim.copysign(applied);
        dnu = solve(applied, 0.0);
    }
    (dnu, applied)
}
