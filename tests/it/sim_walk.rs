//! Gait tests of the bundled walker designs against the paper's Drake results
//! (Oke et al., Table IV, m ∝ L²): each design walks steadily forward at 1× with body
//! attitude amplitudes of the paper's magnitude (bands: a factor 2 either way) and a
//! Froude number v/√(gL) in 0.05–0.7; scaled Mugatus walk and v ∝ L^½.
//!
//! Known gaps are kept as `#[ignore]`d tests stating what fails (run them with
//! `cargo test -- --ignored`), rather than loosened bands.

use robot_survey::sim::{ContactScaling, Design, MassLaw, WalkOptions, WalkReport, simulate_walk};

fn walk(name: &str, opts: WalkOptions) -> WalkReport {
    let d = Design::builtin(name).expect("bundled design");
    let opts = WalkOptions {
        record_trajectory: false,
        ..opts
    };
    simulate_walk(&d, &opts).expect("walk runs").report
}

/// A design scaled to leg length `l` with its own foot material at every size.
fn walk_fixed_material(name: &str, l: f64) -> WalkReport {
    walk(
        name,
        WalkOptions {
            leg_length_m: Some(l),
            contact_scaling: ContactScaling::FixedMaterial,
            ..WalkOptions::default()
        },
    )
}

/// `value` within a factor `k` of `paper`.
fn within_factor(what: &str, value: f64, paper: f64, k: f64) {
    assert!(
        value >= paper / k && value <= paper * k,
        "{what} = {value:.2}, paper {paper:.2} (allowed ×1/{k}–×{k})"
    );
}

fn assert_walks_steadily(r: &WalkReport) {
    assert!(r.walks, "does not walk: {r:?}");
    assert!(r.fall_reason.is_none(), "fell: {r:?}");
    assert!(
        r.converged_at_s.is_some(),
        "no limit cycle found on the Poincaré section: {r:?}"
    );
    assert!(
        (0.05..=0.7).contains(&r.froude),
        "Froude v/√(gL) = {:.3} outside 0.05–0.7",
        r.froude
    );
}

#[test]
fn mugatu_walks_at_1x_like_the_paper() {
    let r = walk("mugatu", WalkOptions::default());
    assert_walks_steadily(&r);
    within_factor("roll p-p [deg]", r.roll_pp_deg, 19.91, 2.0);
    within_factor("pitch p-p [deg]", r.pitch_pp_deg, 10.83, 2.0);
    within_factor("yaw p-p [deg]", r.yaw_pp_deg, 10.06, 2.0);
    // Since the leg inertia fix (dataset/walkers/mugatu.toml) all three match to 25 %
    // (measured 18.6 / 10.6 / 9.2 deg).
    within_factor("roll p-p [deg]", r.roll_pp_deg, 19.91, 1.25);
    within_factor("pitch p-p [deg]", r.pitch_pp_deg, 10.83, 1.25);
    within_factor("yaw p-p [deg]", r.yaw_pp_deg, 10.06, 1.25);
    // Steady: cycle-to-cycle spread small against the amplitude.
    assert!(r.roll_pp_deg_sd < 0.2 * r.roll_pp_deg && r.pitch_pp_deg_sd < 0.2 * r.pitch_pp_deg);
    // Hardware speed 0.16 m/s [robot-dataset]; one step per leg per drive cycle.
    within_factor("velocity [m/s]", r.velocity_mps, 0.16, 1.5);
    within_factor(
        "step frequency [Hz]",
        r.step_frequency_hz,
        2.0 * r.drive_frequency_hz,
        1.1,
    );
    assert!(r.peak_torque_nm > 0.0 && r.cot > 0.0 && r.mechanical_work_j > 0.0);
}

#[test]
fn zippy_walks_at_1x() {
    let r = walk("zippy", WalkOptions::default());
    assert_walks_steadily(&r);
    within_factor("roll p-p [deg]", r.roll_pp_deg, 9.28, 2.0);
    within_factor("pitch p-p [deg]", r.pitch_pp_deg, 25.02, 2.0);
}

/// The yaw oscillation of the ellipsoidal Zippy (paper 7.14 deg p-p). It was ~55 deg before
/// the design got its motor torque–speed line, hip-height COM and near-resonant drive (see
/// dataset/walkers/zippy.toml); also checked from seeded initial states.
#[test]
fn zippy_yaw_like_the_paper() {
    for seed in [None, Some(1), Some(2)] {
        let r = walk(
            "zippy",
            WalkOptions {
                seed,
                ..WalkOptions::default()
            },
        );
        assert_walks_steadily(&r);
        within_factor("yaw p-p [deg]", r.yaw_pp_deg, 7.14, 2.0);
    }
}

#[test]
fn zippy_spherical_walks_at_1x() {
    let r = walk("zippy-spherical", WalkOptions::default());
    assert_walks_steadily(&r);
    within_factor("roll p-p [deg]", r.roll_pp_deg, 16.27, 2.0);
    within_factor("pitch p-p [deg]", r.pitch_pp_deg, 25.02, 2.0);
    within_factor("yaw p-p [deg]", r.yaw_pp_deg, 7.45, 2.0);
}

/// A period-1 gait transfers support once per half drive period (one step per leg swing),
/// so the step frequency counted from the feet's normal loads is twice the drive frequency.
/// For the bang-bang Zippys this is the hardstop-to-hardstop swing.
#[test]
fn steps_lock_to_the_drive() {
    for name in ["mugatu", "zippy", "zippy-spherical"] {
        let r = walk(name, WalkOptions::default());
        assert_walks_steadily(&r);
        within_factor(
            &format!("{name} step frequency [Hz]"),
            r.step_frequency_hz,
            2.0 * r.drive_frequency_hz,
            1.02,
        );
    }
}

/// Vertical momentum balance: over a limit cycle the body neither rises nor sinks, so the
/// time-averaged normal load of the two feet equals the weight m·g (flat ground).
#[test]
fn feet_carry_the_weight_on_average() {
    for name in ["mugatu", "zippy"] {
        let d = Design::builtin(name).expect("bundled design");
        let out = simulate_walk(&d, &WalkOptions::default()).expect("walk runs");
        let r = &out.report;
        assert_walks_steadily(r);
        let t0 = r.converged_at_s.expect("converged");
        let window: Vec<f64> = out
            .trajectory
            .iter()
            .filter(|s| s.t_s >= t0)
            .map(|s| s.normal_force_n[0] + s.normal_force_n[1])
            .collect();
        let mean = window.iter().sum::<f64>() / window.len() as f64;
        let weight = r.mass_kg * 9.81;
        assert!(
            (mean / weight - 1.0).abs() < 0.01,
            "{name}: mean normal load {mean:.4} N vs weight {weight:.4} N"
        );
    }
}

#[test]
fn scaled_mugatu_walks_with_both_mass_laws() {
    for law in [MassLaw::L2, MassLaw::L3] {
        let r = walk(
            "mugatu",
            WalkOptions {
                leg_length_m: Some(0.5),
                mass_law: law,
                ..WalkOptions::default()
            },
        );
        assert_walks_steadily(&r);
        within_factor("roll p-p [deg]", r.roll_pp_deg, 19.91, 2.0);
    }
}

/// Least-squares slope of ln y against ln x.
fn log_log_slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = pts.iter().map(|p| (p.0.ln(), p.1.ln())).unzip();
    let mx = lx.iter().sum::<f64>() / n;
    let my = ly.iter().sum::<f64>() / n;
    lx.iter()
        .zip(&ly)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum::<f64>()
        / lx.iter().map(|x| (x - mx).powi(2)).sum::<f64>()
}

/// Dynamic similarity (f ∝ L^−½, similar contact): v ∝ L^½. Least-squares exponent over
/// L = 0.05, 0.153, 0.5 m must be 0.5 ± 0.05 (paper: 0.50, R² = 1.000).
#[test]
fn mugatu_velocity_scales_as_sqrt_leg_length() {
    let pts: Vec<(f64, f64)> = [0.05, 0.153, 0.5]
        .iter()
        .map(|&l| {
            let r = walk(
                "mugatu",
                WalkOptions {
                    leg_length_m: Some(l),
                    ..WalkOptions::default()
                },
            );
            assert!(r.walks, "L = {l} m does not walk");
            (l, r.velocity_mps)
        })
        .collect();
    let b = log_log_slope(&pts);
    assert!((b - 0.5).abs() < 0.05, "velocity exponent {b:.3}");
}

/// A real robot's foot material (fixed modulus and damping, m ∝ L²: the sinkage stays the
/// same fraction of L, only the Hunt–Crossley damping d·v grows as contact speeds ∝ √L):
/// Mugatu still walks from L = 0.05 to 1.0 m with v ∝ L^½ (measured 0.512) and the peak hip
/// torque ∝ m·L (measured exponent 0.965). Bands ± 0.05 / ± 0.1.
#[test]
fn mugatu_fixed_material_m_l2_scales_like_froude() {
    let runs: Vec<WalkReport> = [0.05, 0.153, 0.5, 1.0]
        .iter()
        .map(|&l| {
            let r = walk_fixed_material("mugatu", l);
            assert!(r.walks, "L = {l} m does not walk: {r:?}");
            r
        })
        .collect();
    let v: Vec<(f64, f64)> = runs
        .iter()
        .map(|r| (r.leg_length_m, r.velocity_mps))
        .collect();
    let b = log_log_slope(&v);
    assert!((b - 0.5).abs() < 0.05, "velocity exponent {b:.3}");
    let t: Vec<(f64, f64)> = runs
        .iter()
        .map(|r| (r.mass_kg * r.leg_length_m, r.peak_torque_nm))
        .collect();
    let bt = log_log_slope(&t);
    assert!(
        (bt - 1.0).abs() < 0.1,
        "peak torque exponent vs m·L {bt:.3}"
    );
}

// ------------------------------------------------------------------ known gaps
// Each states a published fact the model does not yet reproduce; `cargo test -- --ignored`
// runs them (they fail today, with the measured values in the comment).

/// Zippy's hardware walks at 0.11 m/s (robot dataset) and tops out at 0.25 m/s (Man et al.
/// 2025); the model walks at 0.042 m/s (Froude v/√(gL) 0.086 vs 0.22 for the hardware).
#[test]
#[ignore = "known gap: the Zippy model walks at 0.042 m/s"]
fn zippy_walks_about_as_fast_as_the_hardware() {
    let r = walk("zippy", WalkOptions::default());
    assert_walks_steadily(&r);
    within_factor("velocity [m/s]", r.velocity_mps, 0.11, 1.5);
}

/// The paper (Section V) finds ellipsoidal-foot Zippy faster than Mugatu at every scale.
/// Scaled to the same leg length the model has it slower (Froude 0.086 vs 0.128).
#[test]
#[ignore = "known gap: the Zippy model is slower than Mugatu at equal leg length"]
fn zippy_outpaces_mugatu_at_equal_leg_length() {
    let at = |name: &str| {
        walk(
            name,
            WalkOptions {
                leg_length_m: Some(0.15),
                ..WalkOptions::default()
            },
        )
    };
    let (z, m) = (at("zippy"), at("mugatu"));
    assert_walks_steadily(&z);
    assert_walks_steadily(&m);
    assert!(
        z.velocity_mps > m.velocity_mps,
        "zippy {:.3} m/s vs mugatu {:.3} m/s",
        z.velocity_mps,
        m.velocity_mps
    );
}

/// The paper's Zippy walks up to L = 1.0 m. With the design's own foot material at every
/// size the model stops rocking from L = 0.15 m (roll 0.25° p-p) and the scissoring legs
/// spin it in place (yaw 49° p-p, no progress). For m ∝ L² the fixed modulus is already
/// the similar one, so the cause is the Hunt–Crossley dissipation d = 30 s/m held fixed
/// while contact speeds grow ∝ √L: with d scaled as similarity asks (12.2 s/m at 0.15 m),
/// or with a 10× stiffer foot, it walks at 0.104 m/s. Mugatu walks at every size.
#[test]
#[ignore = "known gap: fixed-material Zippy stops rocking at L >= 0.15 m"]
fn zippy_fixed_material_walks_when_scaled_up() {
    for l in [0.15, 0.5, 1.0] {
        assert_walks_steadily(&walk_fixed_material("zippy", l));
    }
}

/// Mirror symmetry (x → −x) of a fore–aft symmetric design, derived by hand: the mirror
/// image of a gait is a gait of the opposite drive (θ → −θ, the same sine half a period
/// later) from the mirrored start (at rest rolled onto the right foot is its own mirror
/// image), so it walks the other way at the same speed with the same attitude amplitudes
/// and step frequency. Both directions therefore solve the same model, and which one a
/// walker takes is set by where its start falls against the drive's phase: what
/// `criteria.walking_direction = "either"` declares (the gap diagnosis then compares |v|).
/// `mugatu-ref-sap` has its feet and leg COMs centred fore–aft.
#[test]
fn a_fore_aft_symmetric_walker_driven_half_a_period_later_walks_the_mirror_gait() {
    let d = Design::builtin("mugatu-ref-sap").expect("bundled");
    assert!(!d.criteria.walking_direction.is_forward());
    let mirrored = d
        .with_value("control.amplitude_deg", -25.0)
        .expect("negative amplitude");
    let opts = WalkOptions::default();
    let a = simulate_walk(&d, &opts).expect("walk").report;
    let b = simulate_walk(&mirrored, &opts).expect("walk").report;
    assert!(a.velocity_mps.abs() > 0.1, "walks: {a:?}");
    assert!(
        a.velocity_mps * b.velocity_mps < 0.0,
        "opposite directions: {} vs {}",
        a.velocity_mps,
        b.velocity_mps
    );
    let same = |what: &str, x: f64, y: f64| {
        assert!(
            (x - y).abs() <= 1e-3 * x.abs().max(y.abs()),
            "{what}: {x} vs mirrored {y}"
        );
    };
    same("speed", a.velocity_mps.abs(), b.velocity_mps.abs());
    same("roll", a.roll_pp_deg, b.roll_pp_deg);
    same("pitch", a.pitch_pp_deg, b.pitch_pp_deg);
    same("yaw", a.yaw_pp_deg, b.yaw_pp_deg);
    same("steps", a.step_frequency_hz, b.step_frequency_hz);
    // Walking either way, the backward gait walks.
    assert!(a.walks && b.walks, "{a:?} / {b:?}");
}
