//! Physics tests of the switchable unmodelled effects (`EffectSpec`): each compares the
//! simulator with a result of mechanics derived independently of the code (closed forms,
//! energy balances, the definition of a delay or a lash), plus the scaling rules and a
//! walk with each effect (finite; bit-identical at the effect's neutral value).

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use robot_survey::sim::{
    ContactParams, ContactScaling, Controller, Design, Effect, EffectSpec, Leg, Model, Simulator,
    State, WalkOptions, prepare_walk, simulate_walk,
};

const G: f64 = 9.81;

fn effects(specs: &[EffectSpec]) -> Vec<Box<dyn Effect>> {
    specs.iter().filter_map(|e| e.build()).collect()
}

fn contact(modulus_pa: f64, friction_mu: f64) -> ContactParams {
    ContactParams {
        modulus_pa,
        dissipation_s_per_m: 0.0,
        friction_mu,
        stiction_speed_mps: 1e-4,
        relaxation_time_s: 0.0,
        convex_coupling_time_s: 0.0,
        rolling_resistance_m: 0.0,
        rolling_resistance_rate_rad_s: 0.0,
    }
}

fn box_inertia(m: f64, a: f64, b: f64, c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(
        m / 12.0 * (b * b + c * c),
        m / 12.0 * (a * a + c * c),
        m / 12.0 * (a * a + b * b),
    ))
}

/// Two identical legs of mass `m_leg`, COM at `com` (left) and its mirror image in y
/// (right), spherical feet of radius `r` centred at `foot` (and mirror).
fn two_legs(
    m_leg: f64,
    com: Vector3<f64>,
    inertia: Matrix3<f64>,
    foot: Vector3<f64>,
    r: f64,
    contact: ContactParams,
) -> Model {
    let mirror = |v: Vector3<f64>| Vector3::new(v.x, -v.y, v.z);
    let leg = |c: Vector3<f64>, f: Vector3<f64>| Leg {
        mass_kg: m_leg,
        com_m: c,
        inertia_com_kgm2: inertia,
        foot_center_m: f,
        foot_semi_axes_m: Vector3::new(r, r, r),
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

fn at_rest(hip: Vector3<f64>, rpy: (f64, f64, f64), q: f64) -> State {
    State {
        hip_position_m: hip,
        orientation: UnitQuaternion::from_euler_angles(rpy.0, rpy.1, rpy.2),
        hip_angle_rad: q,
        hip_velocity_mps: Vector3::zeros(),
        angular_velocity_rad_s: Vector3::zeros(),
        hip_rate_rad_s: 0.0,
    }
}

/// A Mugatu-sized body tumbling in free flight (no ground): its legs scissor while it
/// spins, so the hip sees a varying load (as `hip_viscous_damping_dissipates_its_work`).
fn tumbling_in_the_air(hip_rate_rad_s: f64) -> (Model, State) {
    let l = 0.153;
    let mut model = two_legs(
        0.45,
        Vector3::new(0.0, 0.2 * l, -0.55 * l),
        box_inertia(0.45, 0.35 * l, 0.2 * l, 0.9 * l),
        Vector3::new(0.0, 0.0, -l + 0.12),
        0.12,
        contact(3e6, 0.0),
    );
    model.ground_contact = false;
    let mut s = at_rest(Vector3::new(0.0, 0.0, 1.0), (0.2, 0.1, 0.0), 0.2);
    s.angular_velocity_rad_s = Vector3::new(1.0, 2.0, -1.5);
    s.hip_rate_rad_s = hip_rate_rad_s;
    (model, s)
}

/// Two legs in the air whose COMs lie on the hip axis and whose inertias are symmetric
/// about it (I_xx = I_zz): turning one leg about the hip changes nothing in the mass
/// matrix, and a hip torque τ only counter-rotates the legs about their common axis, so
/// q̈ = τ·(1/I_yy + 1/I_yy) = τ/I_eff exactly, I_eff = I_yy/2.
fn coaxial_legs_in_the_air() -> (Model, State, f64) {
    let (m_leg, a, b) = (0.45, 0.1, 0.03);
    let inertia = box_inertia(m_leg, a, b, a);
    let mut model = two_legs(
        m_leg,
        Vector3::new(0.0, 0.03, 0.0),
        inertia,
        Vector3::new(0.0, 0.0, -0.1),
        0.05,
        contact(3e6, 0.0),
    );
    model.ground_contact = false;
    let s = at_rest(Vector3::new(0.0, 0.0, 1.0), (0.0, 0.0, 0.0), 0.0);
    (model, s, 0.5 * inertia[(1, 1)])
}

/// Hip Coulomb friction, τ = −τ_f·q̇/√(q̇² + ω_s²), dissipates ∫ τ_f·q̇²/√(q̇² + ω_s²) dt
/// (the only non-conservative force of a robot tumbling in the air). The hip starts at
/// 6 rad/s and sticks within the run, so the stiction regime is exercised too. Energy
/// balance tolerance 1 % of the dissipated energy, as for the viscous damping: what
/// remains is the step's own O(h) energy error in the tumble (measured 0.58 % at
/// h = 10 µs, 0.15 % at 2.5 µs; 1e-4 J without friction). Against the ideal law
/// τ_f·∫|q̇| dt the regularisation differs by |q̇|(1 − |q̇|/s) ≤ 0.30·ω_s pointwise (the
/// maximum of x − x²/√(1 + x²)), i.e. at most 0.3·τ_f·ω_s·T, added to the 1 %.
#[test]
fn hip_coulomb_friction_dissipates_its_work() {
    let (model, s) = tumbling_in_the_air(6.0);
    let (tau_f, w_s) = (0.04, 0.01);
    let fx = effects(&[EffectSpec::HipCoulombFriction {
        friction_torque_nm: tau_f,
        stiction_rate_rad_s: w_s,
    }]);
    let energy0 = model.energy(&s);
    let dt = 1e-5;
    let steps = 50_000;
    let mut sim = Simulator::new(model, Controller::Passive, fx, s, dt);
    let (mut regularised, mut ideal) = (0.0, 0.0);
    let mut stuck_steps = 0;
    for _ in 0..steps {
        sim.step();
        // The implicit step applies the friction at the end-of-step rate.
        let w = sim.state.hip_rate_rad_s;
        regularised += tau_f * w * w / (w * w + w_s * w_s).sqrt() * dt;
        ideal += tau_f * w.abs() * dt;
        if w.abs() < w_s {
            stuck_steps += 1;
        }
    }
    let loss = energy0.total_j() - sim.model.energy(&sim.state).total_j();
    assert!(
        regularised > 0.2 * energy0.kinetic_j,
        "too little friction to test: {regularised} J of {} J",
        energy0.kinetic_j
    );
    assert!(stuck_steps > steps / 10, "the hip never stuck");
    assert!(
        (loss - regularised).abs() < 0.01 * regularised,
        "energy loss {loss:.6e} J vs ∫τ_f q̇²/√(q̇²+ω_s²) dt = {regularised:.6e} J"
    );
    let t = steps as f64 * dt;
    assert!(
        (loss - ideal).abs() < 0.01 * ideal + 0.3 * tau_f * w_s * t,
        "energy loss {loss:.6e} J vs τ_f∫|q̇| dt = {ideal:.6e} J"
    );
}

/// DC-motor torque–speed line: while motoring, the delivered torque is the command times
/// (1 − |q̇|/ω₀), checked on every step (to rounding). And its consequence, independent of
/// the code: legs counter-rotating about a common axis under a constant command τ obey
/// I_eff·q̈ = τ·(1 − q̇/ω₀), so q̇(t) = ω₀·(1 − exp(−t/t_c)), t_c = I_eff·ω₀/τ. The step is
/// explicit in the torque (bang-bang: slope 0), an Euler error ≈ h/(2 t_c) = 0.02 % at
/// h = 0.1 ms: tolerance 0.1 % of ω₀ (measured 0.006 %).
#[test]
fn motor_torque_speed_line() {
    let (model, s, i_eff) = coaxial_legs_in_the_air();
    let (tau, w0) = (0.01, 8.0);
    let fx = effects(&[EffectSpec::MotorTorqueSpeed {
        no_load_speed_rad_s: w0,
    }]);
    // 0.05 Hz: the command stays +τ for the whole 3 s run.
    let ctl = Controller::BangBang {
        torque_nm: tau,
        frequency_hz: 0.05,
    };
    let dt = 1e-4;
    let mut sim = Simulator::new(model, ctl, fx, s, dt);
    let t_c = i_eff * w0 / tau;
    let mut max_err: f64 = 0.0;
    for _ in 0..30_000 {
        let w = sim.state.hip_rate_rad_s;
        let info = sim.step();
        let expected = if tau * w > 0.0 {
            tau * (1.0 - w.abs() / w0)
        } else {
            tau
        };
        assert!(
            (info.actuator_torque_nm - expected).abs() < 1e-12 * tau,
            "delivered {} vs τ(1 − |q̇|/ω₀) = {expected} at q̇ = {w}",
            info.actuator_torque_nm
        );
        let analytic = w0 * (1.0 - (-sim.time_s / t_c).exp());
        max_err = max_err.max((sim.state.hip_rate_rad_s - analytic).abs());
    }
    assert!(
        sim.time_s > 2.0 * t_c,
        "run too short: {} s vs t_c {t_c} s",
        sim.time_s
    );
    assert!(
        max_err < 1e-3 * w0,
        "q̇ off ω₀(1 − e^(−t/t_c)) by {max_err:.3e} rad/s (ω₀ = {w0}, t_c = {t_c:.3} s)"
    );
}

/// Foot–floor friction coefficient: a body sliding on its foot with speed v, without
/// rotating, decelerates at μ·g and stops after v²/(2μg), with μ the effect's (the model's
/// own μ is 0.8). The legs' COMs sit at the bottom of their spherical feet, so the
/// friction force has no lever about the COM and the body slides instead of rolling. Stiff
/// contact (E = 1 GPa) started at its static sinkage; the regularisation (v_s = 0.1 mm/s)
/// and the step (h·v/2 = 25 µm of 25–64 mm) leave ≤ 0.1 %: tolerance 0.5 % (measured
/// +25 µm, 0.04 % and 0.1 %).
#[test]
fn friction_coefficient_sets_the_sliding_distance() {
    let (r, m_leg, e, v0) = (0.05, 0.45, 1e9, 0.5);
    for mu in [0.2, 0.5] {
        let mut c = contact(e, 0.8);
        c.dissipation_s_per_m = 10.0;
        EffectSpec::FrictionCoefficient { friction_mu: mu }.apply_to_contact(&mut c, 0.15);
        let centre = Vector3::new(0.0, 0.0, -0.1);
        let com = centre - Vector3::new(0.0, 0.0, r);
        let model = two_legs(
            m_leg,
            com,
            Matrix3::identity() * (0.4 * m_leg * r * r),
            centre,
            r,
            c,
        );
        // Two coincident feet, each carrying m_leg·g: π E δ² (1 − 2δ/3R) = m_leg·g.
        let delta = sphere_sinkage(e, r, m_leg * G);
        let mut s = at_rest(
            Vector3::new(0.0, 0.0, 0.1 + r - delta),
            (0.0, 0.0, 0.0),
            0.0,
        );
        s.hip_velocity_mps.x = v0;
        let com_x = |st: &State| (st.hip_position_m + st.orientation * com).x;
        let x0 = com_x(&s);
        let dt = 1e-4;
        let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, dt);
        let t_stop = v0 / (mu * G);
        while sim.time_s < t_stop + 0.2 {
            sim.step();
        }
        let st = &sim.state;
        let com_v = st.hip_velocity_mps
            + (st.orientation * st.angular_velocity_rad_s).cross(&(st.orientation * com));
        let distance = com_x(st) - x0;
        let expected = v0 * v0 / (2.0 * mu * G);
        assert!(
            com_v.x.abs() < 1e-3 * v0,
            "μ = {mu}: still sliding at {} m/s",
            com_v.x
        );
        assert!(
            (distance - expected).abs() < 5e-3 * expected,
            "μ = {mu}: slid {distance:.6} m vs v²/(2μg) = {expected:.6} m"
        );
    }
    // Through a design, the effect's μ replaces the design's.
    let mut d = Design::builtin("mugatu").expect("bundled design");
    assert_ne!(d.model().contact.friction_mu, 0.2);
    d.effects
        .push(EffectSpec::FrictionCoefficient { friction_mu: 0.2 });
    assert_eq!(d.model().contact.friction_mu, 0.2);
}

/// Static sinkage δ of a sphere of radius R in the pressure field p = E(1 − r) under load
/// F: π E δ² (1 − 2δ/3R) = F (Newton; see `static_penetration_matches_contact_law`).
fn sphere_sinkage(e: f64, r: f64, f: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let mut d = (f / (pi * e)).sqrt();
    for _ in 0..30 {
        let g = pi * e * d * d * (1.0 - 2.0 * d / (3.0 * r)) - f;
        let dg = pi * e * (2.0 * d - 2.0 * d * d / r);
        d -= g / dg;
    }
    d
}

/// Soft ground: a floor of modulus E_g under a foot of modulus E_foot behaves as one
/// field of modulus E_eff = E_foot·E_g/(E_foot + E_g) (two compliant layers in series), so
/// a body resting on its spherical feet sinks δ with π E_eff δ² (1 − 2δ/3R) = F
/// (≈ √(F/(π E_eff)), the c·√(m g/(π E a b)) of an ellipsoid with a = b = c = R). Settled
/// with Hunt–Crossley damping; tolerance 0.5 % on δ, as the rigid-floor test (measured
/// < 1e-6; the rigid floor would give half the sinkage). The design path gives the same
/// modulus and start sinkage.
#[test]
fn soft_ground_sinks_by_the_series_modulus() {
    let (r, m_leg, e_foot, e_ground, l) = (0.12, 0.45, 3e6, 1e6, 0.153);
    let e_eff = e_foot * e_ground / (e_foot + e_ground);
    let mut c = contact(e_foot, 0.8);
    c.dissipation_s_per_m = 20.0;
    c.stiction_speed_mps = 1e-3;
    EffectSpec::SoftGround {
        ground_modulus_pa: e_ground,
    }
    .apply_to_contact(&mut c, l);
    let model = two_legs(
        m_leg,
        Vector3::new(0.0, 0.0, -0.1),
        Matrix3::identity() * 1e-3,
        Vector3::new(0.0, 0.0, -l + r),
        r,
        c,
    );
    let s = at_rest(Vector3::new(0.0, 0.0, l), (0.0, 0.0, 0.0), 0.0);
    let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, 2e-4);
    for _ in 0..10_000 {
        sim.step();
    }
    let delta = l - sim.state.hip_position_m.z;
    // Two coincident feet, each carrying half the weight.
    let expected = sphere_sinkage(e_eff, r, m_leg * G);
    assert!(
        (delta - expected).abs() / expected < 5e-3,
        "sinkage {delta:.6e} m vs series-modulus law {expected:.6e} m (rigid floor: {:.6e} m)",
        sphere_sinkage(e_foot, r, m_leg * G)
    );
    let mut d = Design::builtin("mugatu").expect("bundled design");
    let e_design = d.contact.hydroelastic_modulus_pa;
    d.effects.push(EffectSpec::SoftGround {
        ground_modulus_pa: e_ground,
    });
    let m = d.model();
    let want = e_design * e_ground / (e_design + e_ground);
    assert!((m.contact.modulus_pa - want).abs() < 1e-9 * want);
    let one_foot = (m.total_mass_kg() * G / (std::f64::consts::PI * want)).sqrt();
    assert!((m.single_foot_sinkage_m() - one_foot).abs() < 1e-12);
}

/// Rolling resistance: a uniform solid sphere rolling on a level floor with its centre of
/// pressure shifted by e ahead feels the moment e·m·g about the contact, so
/// (I + m R²)·α = −e·m·g and a = −(5/7)·g·e/R (I = 2/5 m R²). Each leg is a uniform sphere
/// (COM at its foot centre, feet coincident); stiff contact without dissipation, whose
/// own rolling resistance is nil, so without the effect a ≈ 0. Both dissipation forms
/// (Kelvin–Voigt with τ = 1 µs adds a rolling moment 1e-3 of the effect's). The sinkage
/// (rolling radius R − δ, δ/R < 0.1 %) and the regularisation (ω_s = v_s/L ≪ ω) leave
/// < 0.2 %: tolerance 1 % of the effect's deceleration (measured 0.05 % and 0.1 %).
#[test]
fn rolling_resistance_decelerates_a_rolling_sphere() {
    let (r, m_leg, e_len, v0) = (0.05, 0.5, 5e-4, 0.3);
    let expected = -5.0 / 7.0 * G * e_len / r;
    for relaxation_time_s in [0.0, 1e-6] {
        let run = |with_effect: bool| {
            let mut c = contact(1e9, 1.0);
            c.relaxation_time_s = relaxation_time_s;
            if with_effect {
                EffectSpec::RollingResistance {
                    rolling_resistance_length_m: e_len,
                }
                .apply_to_contact(&mut c, 0.15);
            }
            let centre = Vector3::new(0.0, 0.0, -0.1);
            let model = two_legs(
                m_leg,
                centre,
                Matrix3::identity() * (0.4 * m_leg * r * r),
                centre,
                r,
                c,
            );
            let delta = sphere_sinkage(1e9, r, m_leg * G);
            let mut s = at_rest(
                Vector3::new(0.0, 0.0, r - delta + 0.1),
                (0.0, 0.0, 0.0),
                0.0,
            );
            // Rolling without slip along +x: ω_y = v/R, the sphere centre (0.1 m below
            // the hip point) moving at v.
            let w = Vector3::new(0.0, v0 / (r - delta), 0.0);
            s.angular_velocity_rad_s = w;
            s.hip_velocity_mps = Vector3::new(v0, 0.0, 0.0) - w.cross(&centre);
            let dt = 5e-5;
            let mut sim = Simulator::new(model, Controller::Passive, Vec::new(), s, dt);
            let mut rows = Vec::new();
            while sim.time_s < 1.5 {
                sim.step();
                if sim.time_s >= 0.1 {
                    let c = sim.state.hip_position_m + sim.state.orientation * centre;
                    rows.push((sim.time_s, c.x));
                }
            }
            quadratic_fit_acceleration(&rows)
        };
        let a_plain = run(false);
        let a = run(true);
        assert!(
            a_plain.abs() < 0.01 * expected.abs(),
            "τ_d = {relaxation_time_s}: a sphere without the effect decelerates at {a_plain:.3e} m/s²"
        );
        assert!(
            (a - expected).abs() < 0.01 * expected.abs(),
            "τ_d = {relaxation_time_s}: a = {a:.5} m/s² vs −(5/7) g e/R = {expected:.5} m/s²"
        );
    }
}

fn quadratic_fit_acceleration(rows: &[(f64, f64)]) -> f64 {
    // Normal equations for [1, t, t²].
    let mut ata = Matrix3::<f64>::zeros();
    let mut atb = Vector3::<f64>::zeros();
    let t0 = rows[0].0;
    for &(t, x) in rows {
        let t = t - t0;
        let v = Vector3::new(1.0, t, t * t);
        ata += v * v.transpose();
        atb += v * x;
    }
    let c = ata.lu().solve(&atb).expect("well-posed fit");
    2.0 * c[2]
}

/// Actuation latency T: the delivered torque at t is the command of t − T, zero before
/// t = T. A square wave (bang-bang, 5 Hz) delayed by T = 12.3 steps: wherever the delayed
/// time t − T lies between two commands of equal sign the delivered torque is exactly that
/// command; within the one step after a delayed edge it is the linear interpolation
/// between the two buffered commands. Exact to rounding (1e-12 of τ₀).
#[test]
fn actuation_latency_delays_a_square_wave() {
    let (model, s) = tumbling_in_the_air(0.0);
    let (tau, freq, dt) = (0.05, 5.0, 1e-3);
    let latency = 12.3 * dt;
    let fx = effects(&[EffectSpec::ActuationLatency { latency_s: latency }]);
    let ctl = Controller::BangBang {
        torque_nm: tau,
        frequency_hz: freq,
    };
    let mut sim = Simulator::new(model, ctl, fx, s, dt);
    let mut times = Vec::new();
    let (mut exact, mut interpolated, mut before) = (0, 0, 0);
    for _ in 0..500 {
        let t = sim.time_s;
        times.push(t);
        let delivered = sim.step().actuator_torque_nm;
        let td = t - latency;
        if td < 0.0 {
            assert_eq!(delivered, 0.0, "torque before the first command arrives");
            before += 1;
            continue;
        }
        let j = times.partition_point(|&x| x <= td) - 1;
        let (t0, t1) = (times[j], times[j + 1]);
        let (c0, c1) = (ctl.command(t0, 0.0, 0.0), ctl.command(t1, 0.0, 0.0));
        let (c0, c1) = (c0.torque_nm, c1.torque_nm);
        if c0 == c1 {
            // The square wave itself, delayed by T.
            let want = ctl.command(td, 0.0, 0.0).torque_nm;
            assert!(
                (delivered - want).abs() < 1e-12 * tau,
                "t = {t}: delivered {delivered} vs command(t − T) = {want}"
            );
            exact += 1;
        } else {
            let want = c0 + (td - t0) / (t1 - t0) * (c1 - c0);
            assert!(
                (delivered - want).abs() < 1e-12 * tau,
                "t = {t}: delivered {delivered} vs interpolated {want}"
            );
            interpolated += 1;
        }
    }
    // t < T for the steps at t = 0 … 12 ms: 13 of them.
    assert_eq!(before, 13);
    // Edges every 0.1 s: the delayed wave crosses four of them in the 0.5 s run.
    assert_eq!(interpolated, 4);
    assert!(exact > 400);
}

/// Hip backlash b crossed at ω_c: after the command reverses, the motor side travels the
/// whole lash b at ω_c and delivers nothing for b/ω_c, then the full command. With
/// b/ω_c = 26.18 steps, 26 steps deliver zero, the 27th delivers the command times the
/// part of the step after engagement (0.82), then the command; each reversal therefore
/// loses exactly τ₀·b/ω_c of torque impulse (to rounding). Starts engaged on the positive
/// side, so the first half period delivers the full +τ₀.
#[test]
fn hip_backlash_delays_torque_after_a_reversal() {
    let (model, s) = tumbling_in_the_air(0.0);
    let (tau, freq, dt) = (0.05, 2.0, 1e-3);
    let (b_deg, w_c) = (3.0, 2.0);
    let lag = f64::to_radians(b_deg) / w_c;
    let fx = effects(&[EffectSpec::HipBacklash {
        backlash_deg: b_deg,
        crossing_rate_rad_s: w_c,
    }]);
    let ctl = Controller::BangBang {
        torque_nm: tau,
        frequency_hz: freq,
    };
    let mut sim = Simulator::new(model, ctl, fx, s, dt);
    // (command, delivered) per step.
    let mut rows = Vec::new();
    for _ in 0..1000 {
        let cmd = ctl.command(sim.time_s, 0.0, 0.0).torque_nm;
        rows.push((cmd, sim.step().actuator_torque_nm));
    }
    let reversals: Vec<usize> = (1..rows.len())
        .filter(|&k| rows[k].0 != rows[k - 1].0)
        .collect();
    assert_eq!(reversals.len(), 3, "reversals at 0.25, 0.5, 0.75 s");
    assert!(rows[..reversals[0]].iter().all(|&(c, d)| c == d));
    let zero_steps = (lag / dt).floor() as usize;
    let partial = 1.0 - (lag / dt).fract();
    for (n, &k) in reversals.iter().enumerate() {
        let end = reversals.get(n + 1).copied().unwrap_or(rows.len());
        let seg = &rows[k..end];
        let zeros = seg.iter().take_while(|&&(_, d)| d == 0.0).count();
        assert_eq!(zeros, zero_steps, "reversal at step {k}: zero-torque steps");
        let (c, d) = seg[zeros];
        assert!(
            (d - c * partial).abs() < 1e-9 * tau,
            "reversal at step {k}: engaging step delivers {d} vs {}",
            c * partial
        );
        assert!(seg[zeros + 1..].iter().all(|&(c, d)| c == d));
        let deficit: f64 = seg.iter().map(|&(c, d)| (c - d) * dt).sum();
        let want = seg[0].0 * lag;
        assert!(
            (deficit - want).abs() < 1e-9 * tau * lag,
            "reversal at step {k}: impulse lost {deficit:.6e} N·m·s vs τ₀·b/ω_c = {want:.6e}"
        );
    }
}

/// Scaling rules of every effect at length ratio 4 and mass ratio 16 (m ∝ L²): torques
/// × m·L = 64, damping × m·L·√L = 128, rates ÷ √L = 2, times × √L = 2, lengths × 4, μ and
/// angles unchanged, ground modulus × m/L² = 1 (similar) or unchanged (same floor).
#[test]
fn effects_scale_by_dynamic_similarity() {
    let (s, m) = (4.0, 16.0);
    let cases = [
        (
            EffectSpec::HipViscousDamping {
                damping_nms_per_rad: 0.01,
            },
            EffectSpec::HipViscousDamping {
                damping_nms_per_rad: 1.28,
            },
        ),
        (
            EffectSpec::HipCoulombFriction {
                friction_torque_nm: 0.02,
                stiction_rate_rad_s: 0.1,
            },
            EffectSpec::HipCoulombFriction {
                friction_torque_nm: 1.28,
                stiction_rate_rad_s: 0.05,
            },
        ),
        (
            EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s: 14.0,
            },
            EffectSpec::MotorTorqueSpeed {
                no_load_speed_rad_s: 7.0,
            },
        ),
        (
            EffectSpec::FrictionCoefficient { friction_mu: 0.3 },
            EffectSpec::FrictionCoefficient { friction_mu: 0.3 },
        ),
        (
            EffectSpec::RollingResistance {
                rolling_resistance_length_m: 1e-3,
            },
            EffectSpec::RollingResistance {
                rolling_resistance_length_m: 4e-3,
            },
        ),
        (
            EffectSpec::ActuationLatency { latency_s: 0.01 },
            EffectSpec::ActuationLatency { latency_s: 0.02 },
        ),
        (
            EffectSpec::HipBacklash {
                backlash_deg: 2.0,
                crossing_rate_rad_s: 6.0,
            },
            EffectSpec::HipBacklash {
                backlash_deg: 2.0,
                crossing_rate_rad_s: 3.0,
            },
        ),
    ];
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    for (spec, want) in cases {
        for cs in [ContactScaling::Similar, ContactScaling::FixedMaterial] {
            let got = spec.scaled(s, m, cs);
            let ok = match (got, want) {
                (
                    EffectSpec::HipViscousDamping {
                        damping_nms_per_rad: a,
                    },
                    EffectSpec::HipViscousDamping {
                        damping_nms_per_rad: b,
                    },
                ) => close(a, b),
                (
                    EffectSpec::HipCoulombFriction {
                        friction_torque_nm: a,
                        stiction_rate_rad_s: x,
                    },
                    EffectSpec::HipCoulombFriction {
                        friction_torque_nm: b,
                        stiction_rate_rad_s: y,
                    },
                ) => close(a, b) && close(x, y),
                (
                    EffectSpec::MotorTorqueSpeed {
                        no_load_speed_rad_s: a,
                    },
                    EffectSpec::MotorTorqueSpeed {
                        no_load_speed_rad_s: b,
                    },
                ) => close(a, b),
                (
                    EffectSpec::RollingResistance {
                        rolling_resistance_length_m: a,
                    },
                    EffectSpec::RollingResistance {
                        rolling_resistance_length_m: b,
                    },
                ) => close(a, b),
                (
                    EffectSpec::ActuationLatency { latency_s: a },
                    EffectSpec::ActuationLatency { latency_s: b },
                ) => close(a, b),
                (
                    EffectSpec::HipBacklash {
                        backlash_deg: a,
                        crossing_rate_rad_s: x,
                    },
                    EffectSpec::HipBacklash {
                        backlash_deg: b,
                        crossing_rate_rad_s: y,
                    },
                ) => a == b && close(x, y),
                (g, w) => g == w,
            };
            assert!(ok, "{spec:?} at {cs:?}: got {got:?}, want {want:?}");
        }
    }
    let soft = EffectSpec::SoftGround {
        ground_modulus_pa: 2e6,
    };
    // m/L² = 16/16 = 1 for m ∝ L²; use m ∝ L³ too, where it is × 4.
    assert_eq!(
        soft.scaled(s, m, ContactScaling::Similar),
        EffectSpec::SoftGround {
            ground_modulus_pa: 2e6
        }
    );
    assert_eq!(
        soft.scaled(s, 64.0, ContactScaling::Similar),
        EffectSpec::SoftGround {
            ground_modulus_pa: 8e6
        }
    );
    assert_eq!(
        soft.scaled(s, 64.0, ContactScaling::FixedMaterial),
        EffectSpec::SoftGround {
            ground_modulus_pa: 2e6
        }
    );
}

/// Every new effect's serde name and fields, as a design's `[[effects]]` table spells
/// them, and validation of each parameter's range.
#[test]
fn effect_tables_parse_and_validate() {
    let parse = |text: &str| -> EffectSpec {
        #[derive(serde::Deserialize)]
        struct Wrap {
            e: EffectSpec,
        }
        toml::from_str::<Wrap>(&format!("e = {text}"))
            .expect("parses")
            .e
    };
    assert_eq!(
        parse(r#"{effect = "friction_coefficient", friction_mu = 0.2}"#),
        EffectSpec::FrictionCoefficient { friction_mu: 0.2 }
    );
    assert_eq!(
        parse(r#"{effect = "soft_ground", ground_modulus_pa = 1e6}"#),
        EffectSpec::SoftGround {
            ground_modulus_pa: 1e6
        }
    );
    assert_eq!(
        parse(r#"{effect = "rolling_resistance", rolling_resistance_length_m = 0.001}"#),
        EffectSpec::RollingResistance {
            rolling_resistance_length_m: 0.001
        }
    );
    assert_eq!(
        parse(r#"{effect = "actuation_latency", latency_s = 0.01}"#),
        EffectSpec::ActuationLatency { latency_s: 0.01 }
    );
    assert_eq!(
        parse(r#"{effect = "hip_backlash", backlash_deg = 2.0, crossing_rate_rad_s = 5.0}"#),
        EffectSpec::HipBacklash {
            backlash_deg: 2.0,
            crossing_rate_rad_s: 5.0
        }
    );
    let bad = [
        EffectSpec::FrictionCoefficient { friction_mu: 0.0 },
        EffectSpec::FrictionCoefficient {
            friction_mu: f64::INFINITY,
        },
        EffectSpec::SoftGround {
            ground_modulus_pa: -1.0,
        },
        EffectSpec::RollingResistance {
            rolling_resistance_length_m: -1e-3,
        },
        EffectSpec::RollingResistance {
            rolling_resistance_length_m: f64::NAN,
        },
        EffectSpec::ActuationLatency { latency_s: -0.01 },
        EffectSpec::ActuationLatency { latency_s: 1.5 },
        EffectSpec::HipBacklash {
            backlash_deg: 50.0,
            crossing_rate_rad_s: 5.0,
        },
        EffectSpec::HipBacklash {
            backlash_deg: 2.0,
            crossing_rate_rad_s: 0.0,
        },
    ];
    for e in bad {
        assert!(e.validate("test", "effects[0]").is_err(), "{e:?} accepted");
    }
    for e in [
        EffectSpec::RollingResistance {
            rolling_resistance_length_m: 0.0,
        },
        EffectSpec::ActuationLatency { latency_s: 0.0 },
        EffectSpec::ActuationLatency { latency_s: 1.0 },
        EffectSpec::HipBacklash {
            backlash_deg: 0.0,
            crossing_rate_rad_s: 5.0,
        },
    ] {
        assert!(e.validate("test", "effects[0]").is_ok(), "{e:?} rejected");
    }
}

fn with_effect(effect: EffectSpec) -> Design {
    let mut d = Design::builtin("mugatu").expect("bundled design");
    d.effects.push(effect);
    d
}

/// Each new effect at a moderate value in a full Mugatu walk: it runs, stays finite, and
/// changes the gait (so it is really switched on).
#[test]
fn walks_with_each_effect_stay_finite() {
    let base = Design::builtin("mugatu").expect("bundled design");
    let opts = WalkOptions {
        duration_s: 4.0,
        ..WalkOptions::default()
    };
    let plain = simulate_walk(&base, &opts).expect("walk");
    for effect in [
        EffectSpec::FrictionCoefficient { friction_mu: 0.25 },
        EffectSpec::SoftGround {
            ground_modulus_pa: 3e6,
        },
        EffectSpec::RollingResistance {
            rolling_resistance_length_m: 5e-4,
        },
        EffectSpec::ActuationLatency { latency_s: 0.0053 },
        EffectSpec::HipBacklash {
            backlash_deg: 2.0,
            crossing_rate_rad_s: 5.0,
        },
    ] {
        let r = simulate_walk(&with_effect(effect), &opts).expect("walk");
        assert_ne!(
            r.report.fall_reason.as_deref(),
            Some("diverged"),
            "{effect:?} diverged"
        );
        assert!(
            r.trajectory.iter().all(|s| [
                s.x_m,
                s.y_m,
                s.z_m,
                s.roll_deg,
                s.pitch_deg,
                s.yaw_deg,
                s.hip_angle_deg,
                s.hip_torque_nm
            ]
            .iter()
            .all(|v| v.is_finite())),
            "{effect:?}: non-finite trajectory"
        );
        let last = r.trajectory.last().expect("samples");
        let last_plain = plain.trajectory.last().expect("samples");
        assert_ne!(
            (last.x_m, last.roll_deg),
            (last_plain.x_m, last_plain.roll_deg),
            "{effect:?} changed nothing"
        );
    }
}

/// At its neutral value (latency 0, backlash 0, rolling length 0, the design's own μ) an
/// effect changes nothing: every step's state is bit-identical to the walk without it,
/// and so is the report.
#[test]
fn neutral_effects_are_bit_identical() {
    let base = Design::builtin("mugatu").expect("bundled design");
    let opts = WalkOptions {
        duration_s: 3.0,
        seed: Some(5),
        ..WalkOptions::default()
    };
    let neutral = [
        EffectSpec::FrictionCoefficient {
            friction_mu: base.contact.friction_mu,
        },
        EffectSpec::RollingResistance {
            rolling_resistance_length_m: 0.0,
        },
        EffectSpec::ActuationLatency { latency_s: 0.0 },
        EffectSpec::HipBacklash {
            backlash_deg: 0.0,
            crossing_rate_rad_s: 5.0,
        },
    ];
    let mut plain = prepare_walk(&base, &opts).expect("setup");
    let mut runs: Vec<_> = neutral
        .iter()
        .map(|&e| prepare_walk(&with_effect(e), &opts).expect("setup"))
        .collect();
    let steps = (opts.duration_s / plain.simulator.dt_s).round() as usize;
    for _ in 0..steps {
        let info = plain.simulator.step();
        for (run, e) in runs.iter_mut().zip(&neutral) {
            let i = run.simulator.step();
            let (a, b) = (&plain.simulator.state, &run.simulator.state);
            let bits = |s: &State| {
                let mut v: Vec<u64> = s.velocity().iter().map(|x| x.to_bits()).collect();
                v.extend(s.hip_position_m.iter().map(|x| x.to_bits()));
                v.extend(s.orientation.coords.iter().map(|x| x.to_bits()));
                v.push(s.hip_angle_rad.to_bits());
                v
            };
            assert_eq!(bits(a), bits(b), "{e:?} at t = {}", plain.simulator.time_s);
            assert_eq!(
                info.actuator_torque_nm.to_bits(),
                i.actuator_torque_nm.to_bits()
            );
        }
    }
    let report = |d: &Design| {
        serde_json::to_string(&simulate_walk(d, &opts).expect("walk").report).expect("json")
    };
    let want = report(&base);
    for e in neutral {
        assert_eq!(report(&with_effect(e)), want, "{e:?}");
    }
}
