//! Physics tests of the walker simulation: each compares the simulator with a result of
//! mechanics derived independently of the code (closed forms, conservation laws).
//!
//! The models are built directly from bodies and contact parameters (not from the walker
//! designs) so each test isolates one piece of physics.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use robot_survey::sim::{
    ContactParams, Controller, Cut, Design, Effect, EffectSpec, FootSection, Leg, Model, Simulator,
    State, WalkOptions, patch, simulate_walk,
};

const G: f64 = 9.81;

fn box_inertia(m: f64, a: f64, b: f64, c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(
        m / 12.0 * (b * b + c * c),
        m / 12.0 * (a * a + c * c),
        m / 12.0 * (a * a + b * b),
    ))
}

/// Two identical legs (mass `m_leg` each) whose COMs sit at `com` (left) and its mirror
/// image in y (right), with spherical/ellipsoidal feet of semi-axes `semi` centred at `foot`
/// (and mirror).
fn two_leg_model(
    m_leg: f64,
    com: Vector3<f64>,
    inertia: Matrix3<f64>,
    foot: Vector3<f64>,
    semi: Vector3<f64>,
    contact: ContactParams,
) -> Model {
    let mirror = |v: Vector3<f64>| Vector3::new(v.x, -v.y, v.z);
    let leg = |c: Vector3<f64>, f: Vector3<f64>| Leg {
        mass_kg: m_leg,
        com_m: c,
        inertia_com_kgm2: inertia,
        foot_center_m: f,
        foot_semi_axes_m: semi,
        foot_section: None,
    };
    Model {
        legs: [leg(com, foot), leg(mirror(com), mirror(foot))],
        contact,
        hardstop: None,
        gravity_mps2: Vector3::new(0.0, 0.0, -G),
        ground_contact: true,
    }
}

fn frictionless(modulus_pa: f64) -> ContactParams {
    ContactParams {
        modulus_pa,
        dissipation_s_per_m: 0.0,
        friction_mu: 0.0,
        stiction_speed_mps: 1e-3,
        relaxation_time_s: 0.0,
        convex_coupling_time_s: 0.0,
        rolling_resistance_m: 0.0,
        rolling_resistance_rate_rad_s: 0.0,
    }
}

fn state(hip: Vector3<f64>, rpy: (f64, f64, f64), q: f64) -> State {
    State {
        hip_position_m: hip,
        orientation: UnitQuaternion::from_euler_angles(rpy.0, rpy.1, rpy.2),
        hip_angle_rad: q,
        hip_velocity_mps: Vector3::zeros(),
        angular_velocity_rad_s: Vector3::zeros(),
        hip_rate_rad_s: 0.0,
    }
}

/// A Mugatu-like body (L = 0.153 m, 0.9 kg) whose feet are the outer halves of 120 mm
/// spheres centred on the mid-plane (so the patches get clipped at weight transfer).
fn mugatu_like(contact: ContactParams) -> Model {
    let l = 0.153;
    let mut m = two_leg_model(
        0.45,
        Vector3::new(0.0, 0.2 * l, -0.55 * l),
        box_inertia(0.45, 0.35 * l, 0.2 * l, 0.9 * l),
        Vector3::new(0.0, 0.0, -l + 0.12),
        Vector3::new(0.12, 0.12, 0.12),
        contact,
    );
    for (leg, side) in m.legs.iter_mut().zip([1.0, -1.0]) {
        leg.foot_section = Some(FootSection {
            normal: Vector3::new(0.0, side, 0.0),
            offset_m: 0.0,
        });
    }
    m
}

/// Total energy is conserved (actuation, contact damping, friction and effects off):
/// the robot rocks, spins and hops on its half-sphere feet with the hip joint swinging
/// freely, so the test exercises the 3D rigid-body terms (Coriolis/gyroscopic, the hip
/// coupling) and the pressure-field contact (closed-form and clipped patches), whose
/// elastic energy U = ∫ p dV has the patch force and moment as gradient. Tolerance: 1 % of
/// the peak kinetic energy over 2 s at h = 0.1 ms. What remains is mostly the vertical-column
/// approximation of U for clipped patches while the cut plane is tilted (it returns to
/// < 0.05 % whenever the feet are unclipped), not a secular drift.
#[test]
fn energy_conserved_without_actuation_damping_friction() {
    let model = mugatu_like(frictionless(3e6));
    let mut s = state(Vector3::new(0.0, 0.0, 0.1525), (0.15, -0.1, 0.0), 0.3);
    s.angular_velocity_rad_s = Vector3::new(0.5, -0.8, 2.0);
    s.hip_rate_rad_s = -3.0;
    s.hip_velocity_mps = Vector3::new(0.05, -0.02, 0.0);
    let e0 = model.energy(&s).total_j();
    let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, 1e-4);
    let mut ke_max: f64 = 0.0;
    let mut max_dev: f64 = 0.0;
    let mut touched = false;
    for _ in 0..20_000 {
        let info = sim.step();
        touched |= info.feet_in_contact > 0;
        let e = sim.model.energy(&sim.state);
        ke_max = ke_max.max(e.kinetic_j);
        max_dev = max_dev.max((e.total_j() - e0).abs());
    }
    assert!(touched, "the feet never touched the ground");
    assert!(ke_max > 0.01, "test motion too small: KE_max = {ke_max}");
    assert!(
        max_dev < 1e-2 * ke_max,
        "energy drift {max_dev:.3e} J vs KE_max {ke_max:.3e} J"
    );
}

/// The spherical rocker of the rocking tests: L = 0.153 m, two 0.45 kg legs with COMs at
/// (0, ±0.03, −0.09) m and the reference leg box, both feet the same 120 mm sphere (one
/// rocker). Returns the model, the roll inertia about the system COM I_c, the COM height h
/// and the sphere radius R, for ω² = m g (R − h)/(I_c + m h²).
fn spherical_rocker(contact: ContactParams) -> (Model, f64, f64, f64) {
    let (l, r, m_leg) = (0.153, 0.12, 0.45);
    let inertia = box_inertia(m_leg, 0.35 * l, 0.2 * l, 0.9 * l);
    let model = two_leg_model(
        m_leg,
        Vector3::new(0.0, 0.03, -0.09),
        inertia,
        Vector3::new(0.0, 0.0, -l + r),
        Vector3::new(r, r, r),
        contact,
    );
    // Inertia about the system COM about x: Σ (I_xx + m_leg·Δy²), Δy = ±0.03.
    let i_c = 2.0 * (inertia[(0, 0)] + m_leg * 0.03 * 0.03);
    (model, i_c, l - 0.09, r)
}

/// Small-oscillation lateral rocking of a rigid body on a spherical foot, rolling without
/// slip. With the COM a height h above the ground, the sphere (radius R) centre above it
/// and I_c the inertia about the COM about the rocking axis:
///   T = ½ (I_c + m h²) θ̇²,  U = m g (R − (R − h) cos θ) ≈ const + ½ m g (R − h) θ²,
///   ω² = m g (R − h) / (I_c + m h²).
/// Both feet are the same sphere (coincident centres) so the pair is one rocker; the hip
/// stays at q = 0 by symmetry. A stiff foot (E = 1e9 Pa, sinkage 0.03 mm) makes the
/// rigid-contact formula apply; tolerance 1 %.
#[test]
fn rocking_frequency_on_spherical_foot() {
    let (model, i_c, h, r) = spherical_rocker(ContactParams {
        modulus_pa: 1e9,
        dissipation_s_per_m: 0.0,
        friction_mu: 1.0,
        stiction_speed_mps: 1e-4,
        relaxation_time_s: 0.0,
        convex_coupling_time_s: 0.0,
        rolling_resistance_m: 0.0,
        rolling_resistance_rate_rad_s: 0.0,
    });
    let (l, m) = (0.153, model.total_mass_kg());
    let omega = (m * G * (r - h) / (i_c + m * h * h)).sqrt();
    let period = std::f64::consts::TAU / omega;

    let theta0: f64 = 0.02;
    // Start rolled by θ₀ with the sphere touching the ground (centre at height R).
    let rot = UnitQuaternion::from_euler_angles(theta0, 0.0, 0.0);
    let foot_c = rot * Vector3::new(0.0, 0.0, -l + r);
    let sink = (m * G / (std::f64::consts::PI * 2.0 * 1e9)).sqrt();
    let mut s = state(
        Vector3::new(0.0, 0.0, r - sink) - foot_c,
        (theta0, 0.0, 0.0),
        0.0,
    );
    s.hip_position_m.x = 0.0;
    let dt = 5e-5;
    let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, dt);
    // Times of downward zero crossings of the roll angle over ~6 periods.
    let mut crossings = Vec::new();
    let mut prev = theta0;
    let steps = (6.5 * period / dt) as usize;
    for _ in 0..steps {
        sim.step();
        let (roll, _, _) = sim.state.orientation.euler_angles();
        if prev > 0.0 && roll <= 0.0 {
            let t = sim.time_s - dt * roll / (roll - prev);
            crossings.push(t);
        }
        prev = roll;
    }
    assert!(crossings.len() >= 5, "too few oscillations: {crossings:?}");
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let err = (measured - period).abs() / period;
    assert!(
        err < 0.01,
        "rocking period {measured:.5} s vs analytic {period:.5} s ({:.2} %)",
        err * 100.0
    );
}

/// A uniform solid sphere rolls down an incline without slipping with a = (5/7)·g·sin θ
/// (I = 2/5 m R²; a = g sin θ/(1 + I/(m R²))). Each leg is a uniform sphere (COM at its
/// foot centre, both feet coincident); slope θ = 10°, μ = 1 > (2/7) tan θ so it must roll.
/// The acceleration is fitted over 0.2–0.6 s; tolerance 1 %.
#[test]
fn sphere_rolls_down_incline_at_five_sevenths_g_sin_theta() {
    let (r, m_leg) = (0.05, 0.5);
    let i = Matrix3::identity() * (0.4 * m_leg * r * r);
    let contact = ContactParams {
        modulus_pa: 1e9,
        dissipation_s_per_m: 0.0,
        friction_mu: 1.0,
        stiction_speed_mps: 1e-4,
        relaxation_time_s: 0.0,
        convex_coupling_time_s: 0.0,
        rolling_resistance_m: 0.0,
        rolling_resistance_rate_rad_s: 0.0,
    };
    let centre = Vector3::new(0.0, 0.0, -0.1);
    let mut model = two_leg_model(m_leg, centre, i, centre, Vector3::new(r, r, r), contact);
    let theta = 10f64.to_radians();
    model.gravity_mps2 = Vector3::new(theta.sin(), 0.0, -theta.cos()) * G;
    let sink = (2.0 * m_leg * G * theta.cos() / (std::f64::consts::PI * 2.0 * 1e9)).sqrt();
    let s = state(Vector3::new(0.0, 0.0, r - sink + 0.1), (0.0, 0.0, 0.0), 0.0);
    let dt = 5e-5;
    let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, dt);
    // Least-squares fit of x(t) = x₀ + v₀t + ½at² on samples in [0.2, 0.6] s.
    let mut rows = Vec::new();
    while sim.time_s < 0.6 {
        sim.step();
        if sim.time_s >= 0.2 {
            // The sphere centre (COM), not the hip point, translates uniformly.
            let c = sim.state.hip_position_m + sim.state.orientation * centre;
            rows.push((sim.time_s, c.x));
        }
    }
    let a_fit = quadratic_fit_acceleration(&rows);
    let expected = 5.0 / 7.0 * G * theta.sin();
    let err = (a_fit - expected).abs() / expected;
    assert!(
        err < 0.01,
        "a = {a_fit:.4} m/s² vs (5/7) g sin θ = {expected:.4} ({:.2} %)",
        err * 100.0
    );
}

fn quadratic_fit_acceleration(rows: &[(f64, f64)]) -> f64 {
    // Normal equations for [1, t, t²].
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut atb = nalgebra::Vector3::<f64>::zeros();
    let t0 = rows[0].0;
    for &(t, x) in rows {
        let t = t - t0;
        let v = nalgebra::Vector3::new(1.0, t, t * t);
        ata += v * v.transpose();
        atb += v * x;
    }
    let c = ata.lu().solve(&atb).expect("well-posed fit");
    2.0 * c[2]
}

/// Closed-form patch of the linear pressure field p = E(1 − r) (r: ellipsoidal radius)
/// against a brute-force integral of the same field over the plane, for a tilted,
/// yawed ellipsoid: normal force, centre of pressure and stored energy. Tolerance 0.3 %.
#[test]
fn patch_closed_form_matches_brute_force_integral() {
    let semi: Vector3<f64> = Vector3::new(0.025, 0.03, 0.02);
    let rot = *UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7)
        .to_rotation_matrix()
        .matrix();
    let e = 2e6;
    let n_f = rot.transpose() * Vector3::z();
    let support = (semi.component_mul(&semi))
        .dot(&n_f.component_mul(&n_f))
        .sqrt();
    let center = Vector3::new(0.01, -0.02, support - 0.002);
    let p = patch(&center, &rot, &semi, e, None).expect("in contact");
    // Brute force on a fine grid around the centre.
    let n = 1200;
    let half = 0.04;
    let da = (2.0 * half / n as f64).powi(2);
    let (mut f, mut mx, mut my) = (0.0, 0.0, 0.0);
    for i in 0..n {
        for j in 0..n {
            let x = center.x - half + (i as f64 + 0.5) * 2.0 * half / n as f64;
            let y = center.y - half + (j as f64 + 0.5) * 2.0 * half / n as f64;
            let local = rot.transpose() * (Vector3::new(x, y, 0.0) - center);
            let rr = (local.component_div(&semi)).norm();
            if rr < 1.0 {
                let pr = e * (1.0 - rr);
                f += pr * da;
                mx += pr * x * da;
                my += pr * y * da;
            }
        }
    }
    let (cx, cy) = (mx / f, my / f);
    assert!(
        (p.elastic_force_n - f).abs() / f < 3e-3,
        "F closed {} vs brute {f}",
        p.elastic_force_n
    );
    let patch_size = (f / e).sqrt();
    assert!((p.cop.x - cx).abs() < 3e-3 * patch_size && (p.cop.y - cy).abs() < 3e-3 * patch_size);
    // Stored energy: dU/d(depth) must equal the force (finite difference in height).
    let dz = 1e-7;
    let up =
        patch(&(center + Vector3::new(0.0, 0.0, dz)), &rot, &semi, e, None).expect("in contact");
    let dn =
        patch(&(center - Vector3::new(0.0, 0.0, dz)), &rot, &semi, e, None).expect("in contact");
    let du = (dn.energy_j - up.energy_j) / (2.0 * dz);
    assert!((du - p.elastic_force_n).abs() / p.elastic_force_n < 1e-5);
}

/// The same for a foot that is a section of its ellipsoid (the patch clipped by the cut
/// plane, integrated by quadrature): force and centre of pressure against the brute-force
/// integral for several cut positions, and dU/d(depth) = F (vertical cut plane).
#[test]
fn clipped_patch_matches_brute_force_integral() {
    let semi: Vector3<f64> = Vector3::new(0.025, 0.03, 0.025);
    let rot = *UnitQuaternion::from_euler_angles(0.1, 0.15, 0.4)
        .to_rotation_matrix()
        .matrix();
    let e = 2e6;
    let n_f = rot.transpose() * Vector3::z();
    let support = (semi.component_mul(&semi))
        .dot(&n_f.component_mul(&n_f))
        .sqrt();
    let center = Vector3::new(0.0, 0.0, support - 0.0015);
    let full = patch(&center, &rot, &semi, e, None).expect("in contact");
    for shift in [-0.004, -0.001, 0.0, 0.002, 0.005] {
        // Cut plane through the point centre + shift·(leg y axis), normal = leg y axis.
        let normal = rot * Vector3::y();
        let cut = Cut {
            normal,
            offset: normal.dot(&(center + normal * shift)),
        };
        let p = patch(&center, &rot, &semi, e, Some(&cut)).expect("in contact");
        let n = 1000;
        let half = 0.012;
        let step = 2.0 * half / n as f64;
        let (mut f, mut mx, mut my) = (0.0, 0.0, 0.0);
        for i in 0..n {
            for j in 0..n {
                let x = full.cop.x - half + (i as f64 + 0.5) * step;
                let y = full.cop.y - half + (j as f64 + 0.5) * step;
                let sp = Vector3::new(x, y, 0.0);
                if normal.dot(&sp) < cut.offset {
                    continue;
                }
                let rr = (rot.transpose() * (sp - center))
                    .component_div(&semi)
                    .norm();
                if rr < 1.0 {
                    let pr = e * (1.0 - rr) * step * step;
                    f += pr;
                    mx += pr * x;
                    my += pr * y;
                }
            }
        }
        let size = (full.elastic_force_n / e).sqrt();
        assert!(
            (p.elastic_force_n - f).abs() < 3e-3 * full.elastic_force_n,
            "shift {shift}: F {} vs brute {f}",
            p.elastic_force_n
        );
        assert!((p.cop.x - mx / f).abs() < 5e-3 * size && (p.cop.y - my / f).abs() < 5e-3 * size);
    }
    // Vertical cut plane (leg upright in roll): the stored energy's gradient is the force.
    let rot = *UnitQuaternion::from_euler_angles(0.0, 0.2, 0.3)
        .to_rotation_matrix()
        .matrix();
    let n_f = rot.transpose() * Vector3::z();
    let support = (semi.component_mul(&semi))
        .dot(&n_f.component_mul(&n_f))
        .sqrt();
    let center = Vector3::new(0.0, 0.0, support - 0.0015);
    let normal = rot * Vector3::y();
    let cut = Cut {
        normal,
        offset: normal.dot(&(center + normal * 0.001)),
    };
    let at = |dz: f64| {
        patch(
            &(center + Vector3::new(0.0, 0.0, dz)),
            &rot,
            &semi,
            e,
            Some(&cut),
        )
        .expect("in contact")
    };
    let dz = 1e-7;
    let du = (at(-dz).energy_j - at(dz).energy_j) / (2.0 * dz);
    let f = at(0.0).elastic_force_n;
    assert!((du - f).abs() < 1e-4 * f, "dU/dδ {du} vs F {f}");
}

/// Static penetration against the contact law. For the linear field p = E(1 − r) on a
/// sphere of radius R pressed δ into a rigid plane, the patch is the disc of radius
/// a = √(2Rδ − δ²) and at distance ρ from the sphere centre p = E(1 − ρ/R), so
///   F = ∫₀ᵃ E (1 − √((R−δ)² + s²)/R) 2πs ds = πEδ²(1 − 2δ/(3R)) ≈ πEδ²  (δ ≪ R).
/// (Drake's elastic-foundation check f = πEx² is the δ ≪ R limit.) A body resting on one
/// spherical foot, settled with Hunt–Crossley damping, must sink exactly this δ for
/// F = m g. Tolerance 0.5 % on δ.
#[test]
fn static_penetration_matches_contact_law() {
    let (r, m_leg, e) = (0.12, 0.45, 3e6);
    let i = Matrix3::identity() * 1e-3;
    let contact = ContactParams {
        modulus_pa: e,
        dissipation_s_per_m: 20.0,
        friction_mu: 0.8,
        stiction_speed_mps: 1e-3,
        relaxation_time_s: 0.0,
        convex_coupling_time_s: 0.0,
        rolling_resistance_m: 0.0,
        rolling_resistance_rate_rad_s: 0.0,
    };
    // Both COMs directly above the (coincident) foot centres: no rocking torque.
    let model = two_leg_model(
        m_leg,
        Vector3::new(0.0, 0.0, -0.1),
        i,
        Vector3::new(0.0, 0.0, -0.153 + r),
        Vector3::new(r, r, r),
        contact,
    );
    let s = state(Vector3::new(0.0, 0.0, 0.153), (0.0, 0.0, 0.0), 0.0);
    let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, 2e-4);
    for _ in 0..10_000 {
        sim.step();
    }
    // Two coincident feet, each carrying half the weight.
    let delta = 0.153 - sim.state.hip_position_m.z;
    let f_each = m_leg * G;
    // Solve πEδ²(1 − 2δ/3R) = F by Newton.
    let mut d = (f_each / (std::f64::consts::PI * e)).sqrt();
    for _ in 0..20 {
        let g = std::f64::consts::PI * e * d * d * (1.0 - 2.0 * d / (3.0 * r)) - f_each;
        let dg = std::f64::consts::PI * e * (2.0 * d - 2.0 * d * d / r);
        d -= g / dg;
    }
    assert!(
        (delta - d).abs() / d < 5e-3,
        "sinkage {delta:.6e} m vs law {d:.6e} m"
    );
}

/// Two runs of the same walk give bit-identical trajectories (no hidden randomness,
/// no thread-dependent reductions), also with a seeded initial perturbation.
#[test]
fn walk_is_bitwise_deterministic() {
    let d = Design::builtin("mugatu").expect("bundled design");
    let opts = WalkOptions {
        duration_s: 2.0,
        seed: Some(7),
        ..WalkOptions::default()
    };
    let a = simulate_walk(&d, &opts).expect("walk");
    let b = simulate_walk(&d, &opts).expect("walk");
    assert_eq!(a.trajectory.len(), b.trajectory.len());
    for (x, y) in a.trajectory.iter().zip(&b.trajectory) {
        for (u, v) in [
            (x.x_m, y.x_m),
            (x.y_m, y.y_m),
            (x.z_m, y.z_m),
            (x.roll_deg, y.roll_deg),
            (x.pitch_deg, y.pitch_deg),
            (x.yaw_deg, y.yaw_deg),
            (x.hip_angle_deg, y.hip_angle_deg),
        ] {
            assert_eq!(u.to_bits(), v.to_bits());
        }
    }
    let ja = serde_json::to_string(&a.report).expect("json");
    let jb = serde_json::to_string(&b.report).expect("json");
    assert_eq!(ja, jb);
}

/// Hip viscous damping (the `hip_viscous_damping` effect, τ = −c·q̇) removes exactly the
/// energy ∫ c·q̇² dt: the robot tumbles in free fall (no ground, so nothing else
/// dissipates) with its legs scissoring, for 0.5 s. Tolerance 1 % of the dissipated energy.
#[test]
fn hip_viscous_damping_dissipates_its_work() {
    let mut model = mugatu_like(frictionless(3e6));
    model.ground_contact = false;
    let mut s = state(Vector3::new(0.0, 0.0, 1.0), (0.2, 0.1, 0.0), 0.2);
    s.angular_velocity_rad_s = Vector3::new(1.0, 2.0, -1.5);
    s.hip_rate_rad_s = 6.0;
    let c = 0.02;
    let effects: Vec<Box<dyn Effect>> = [EffectSpec::HipViscousDamping {
        damping_nms_per_rad: c,
    }]
    .iter()
    .filter_map(|e| e.build())
    .collect();
    let energy0 = model.energy(&s);
    let e0 = energy0.total_j();
    // Small step: the integrator's own O(h) energy error must be ≪ 1 % of the loss.
    let dt = 1e-5;
    let mut sim = Simulator::new(model, Controller::Passive, effects, s, dt);
    let mut dissipated = 0.0;
    for _ in 0..50_000 {
        sim.step();
        // The implicit step applies the damping at the end-of-step rate.
        dissipated += c * sim.state.hip_rate_rad_s.powi(2) * dt;
    }
    let loss = e0 - sim.model.energy(&sim.state).total_j();
    assert!(
        dissipated > 0.2 * energy0.kinetic_j,
        "too little damping to test: {dissipated} J of {} J",
        energy0.kinetic_j
    );
    assert!(
        (loss - dissipated).abs() < 0.01 * dissipated,
        "energy loss {loss:.6e} J vs ∫c q̇² dt = {dissipated:.6e} J"
    );
}

/// Peak ratio of successive positive peaks of `x(t)` (geometric mean over the first `n`).
fn decay_per_cycle(xs: &[f64], n: usize) -> f64 {
    let peaks: Vec<f64> = (1..xs.len() - 1)
        .filter(|&i| xs[i] > 0.0 && xs[i] > xs[i - 1] && xs[i] >= xs[i + 1])
        .map(|i| xs[i])
        .collect();
    assert!(peaks.len() > n, "too few peaks: {peaks:?}");
    (peaks[n] / peaks[0]).powf(1.0 / n as f64)
}

/// Kelvin–Voigt (Drake SAP's relaxation time τ) on the pressure field: the dissipative
/// pressure is τ·(E/R)·(penetration rate) over the patch, so for a sphere pressed by δ the
/// damping is c = τ·(E/R)·π(2Rδ − δ²) while the stiffness is k = dF/dδ = 2πEδ(1 − δ/R):
/// c = k·τ·(1 − δ/2R)/(1 − δ/R) ≈ k·τ, a Kelvin–Voigt element (SAP: c = τ·k per contact).
/// Small vertical oscillation about the static sinkage is then a damped oscillator with
/// ζ = c/(2√(k m)) and per-cycle amplitude ratio exp(−2πζ/√(1 − ζ²)). Two coincident
/// spherical feet (each carrying m g/2), no friction, a 10 µs step (numerical damping of
/// the implicit step ≈ ω·dt/2 = 0.1 % of ζ); tolerance 0.5 % (measured 0.03 %).
#[test]
fn kelvin_voigt_bounce_decays_as_a_linear_damper() {
    let (l, r, m_leg, e, tau) = (0.153, 0.12, 0.45, 3e6, 1e-3);
    let contact = ContactParams {
        modulus_pa: e,
        dissipation_s_per_m: 0.0,
        friction_mu: 0.0,
        stiction_speed_mps: 1e-4,
        relaxation_time_s: tau,
        convex_coupling_time_s: 0.0,
        rolling_resistance_m: 0.0,
        rolling_resistance_rate_rad_s: 0.0,
    };
    let model = two_leg_model(
        m_leg,
        Vector3::new(0.0, 0.0, -0.09),
        box_inertia(m_leg, 0.35 * l, 0.2 * l, 0.9 * l),
        Vector3::new(0.0, 0.0, -l + r),
        Vector3::new(r, r, r),
        contact,
    );
    let m = 2.0 * m_leg;
    // Static sinkage per foot: π E δ² (1 − 2δ/3R) = m g / 2 (Newton on the exact form).
    let mut d0 = (m * G / 2.0 / (std::f64::consts::PI * e)).sqrt();
    for _ in 0..20 {
        let f = std::f64::consts::PI * e * d0 * d0 * (1.0 - 2.0 * d0 / (3.0 * r)) - m * G / 2.0;
        let df = std::f64::consts::PI * e * (2.0 * d0 - 2.0 * d0 * d0 / r);
        d0 -= f / df;
    }
    let k = 2.0 * 2.0 * std::f64::consts::PI * e * d0 * (1.0 - d0 / r);
    let c = 2.0 * tau * (e / r) * std::f64::consts::PI * (2.0 * r * d0 - d0 * d0);
    let zeta = c / (2.0 * (k * m).sqrt());
    let expected = (-std::f64::consts::TAU * zeta / (1.0 - zeta * zeta).sqrt()).exp();
    // Start 2 % of the sinkage above equilibrium, at rest.
    let s = state(
        Vector3::new(0.0, 0.0, l - d0 + 0.02 * d0),
        (0.0, 0.0, 0.0),
        0.0,
    );
    let dt = 1e-5;
    let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, dt);
    let z_eq = l - d0;
    let mut xs = Vec::new();
    for _ in 0..20_000 {
        sim.step();
        xs.push(sim.state.hip_position_m.z - z_eq);
    }
    let measured = decay_per_cycle(&xs, 3);
    assert!(
        (measured - expected).abs() / expected < 0.005,
        "bounce decay per cycle {measured:.4} vs Kelvin–Voigt {expected:.4} (ζ = {zeta:.4})"
    );
}

/// Free lateral rocking with Kelvin–Voigt dissipation: rolling by θ̇ about the contact
/// line makes the normal velocity over the patch vary linearly, vₙ = θ̇·Δy, so the
/// dissipative pressure τ·(E/R)·θ̇·Δy gives a rolling-resistance moment
/// c_θ·θ̇ with c_θ = τ·(E/R)·∫Δy² dA = τ·(E/R)·πa⁴/4 per foot (patch radius a² = 2Rδ − δ²).
/// The rocker (frequency as in `rocking_frequency_on_spherical_foot`) is then a damped
/// oscillator, ζ = c_θ/(2·I·ω), I = I_c + m h². This is the dissipation that sets the
/// free-rocking decay compared with Drake (reports/drake-crosscheck.md). Soft feet
/// (E = 3 MPa, as the walkers) shift the rolling radius by the sinkage: tolerance 2 %
/// (measured 0.7 %).
#[test]
fn kelvin_voigt_rocking_decay_matches_rolling_resistance() {
    let (e, tau) = (3e6, 0.01);
    let (model, i_c, h, r) = spherical_rocker(ContactParams {
        modulus_pa: e,
        dissipation_s_per_m: 0.0,
        friction_mu: 1.0,
        stiction_speed_mps: 1e-4,
        relaxation_time_s: tau,
        convex_coupling_time_s: 0.0,
        rolling_resistance_m: 0.0,
        rolling_resistance_rate_rad_s: 0.0,
    });
    let (l, m) = (0.153, model.total_mass_kg());
    let i_contact = i_c + m * h * h;
    let omega = (m * G * (r - h) / i_contact).sqrt();
    let d0 = (m * G / 2.0 / (std::f64::consts::PI * e)).sqrt();
    let a2 = 2.0 * r * d0 - d0 * d0;
    let c_theta = 2.0 * tau * (e / r) * std::f64::consts::PI * a2 * a2 / 4.0;
    let zeta = c_theta / (2.0 * i_contact * omega);
    let expected = (-std::f64::consts::TAU * zeta / (1.0 - zeta * zeta).sqrt()).exp();

    let theta0: f64 = 0.03;
    let rot = UnitQuaternion::from_euler_angles(theta0, 0.0, 0.0);
    let foot_c = rot * Vector3::new(0.0, 0.0, -l + r);
    let s = state(
        Vector3::new(0.0, 0.0, r - d0) - foot_c,
        (theta0, 0.0, 0.0),
        0.0,
    );
    let dt = 1e-4;
    let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, dt);
    let mut xs = Vec::new();
    for _ in 0..40_000 {
        sim.step();
        xs.push(sim.state.orientation.euler_angles().0);
    }
    let measured = decay_per_cycle(&xs, 3);
    assert!(
        (measured - expected).abs() / expected < 0.02,
        "rocking decay per cycle {measured:.4} vs Kelvin–Voigt rolling resistance {expected:.4} (ζ = {zeta:.4})"
    );
}
