//! The walker simulator against Drake on identical models (goldens in tests/golden/drake/,
//! made by tools/drake/harness.py with Drake 1.51.1 from the same design TOMLs and the
//! same case definitions, cases.toml; the whole comparison with its explanations is
//! reports/drake-crosscheck.md). Each tolerance is stated with its reason. Neither Python
//! nor Drake is needed here: the Drake numbers are the committed goldens.

use std::collections::BTreeMap;
use std::path::PathBuf;

use robot_survey::crosscheck::{self, Case, Measured};
use serde_json::Value;

use crate::common;

fn golden() -> PathBuf {
    common::repo().join("tests/golden/drake")
}

fn cases() -> BTreeMap<String, Case> {
    crosscheck::load_cases(&golden().join("cases.toml")).expect("cases.toml")
}

fn drake() -> Value {
    let text = std::fs::read_to_string(golden().join("elementary.json")).expect("elementary.json");
    serde_json::from_str(&text).expect("elementary.json parses")
}

fn ours(name: &str) -> Measured {
    crosscheck::run_case(&common::repo(), name, &cases()[name]).expect("case runs")
}

fn ours_with(name: &str, key: &str, value: f64) -> Measured {
    let mut case = cases()[name].clone();
    case.overrides
        .insert(key.to_string(), toml::Value::Float(value));
    crosscheck::run_case(&common::repo(), name, &case).expect("case runs")
}

fn get(m: &Measured, q: &str) -> f64 {
    m.get(q)
        .copied()
        .flatten()
        .unwrap_or_else(|| panic!("project measured no `{q}`: {m:?}"))
}

fn drake_measured(d: &Value, case: &str, q: &str) -> f64 {
    d["cases"][case]["measured"][q]
        .as_f64()
        .unwrap_or_else(|| panic!("golden has no {case}.measured.{q}"))
}

fn drake_analytic(d: &Value, case: &str, q: &str) -> f64 {
    d["cases"][case]["analytic"][q]
        .as_f64()
        .unwrap_or_else(|| panic!("golden has no {case}.analytic.{q}"))
}

/// Drake's value of `q` in the variant `variant` of `case` (mesh refinement, other solvers).
fn drake_variant(d: &Value, case: &str, variant: &str, q: &str) -> f64 {
    d["variants"]
        .as_array()
        .expect("variants")
        .iter()
        .find(|v| v["case"] == case && v["variant"] == variant)
        .and_then(|v| v["measured"][q].as_f64())
        .unwrap_or_else(|| panic!("golden has no variant {case}/{variant}.{q}"))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Static sinkage: the project integrates the pressure field p = E(1 − r) in closed form,
/// so it must equal the analytic sinkage (the harness solves the same closed form
/// independently) to 0.5 %. Drake tessellates the foot (resolution hint 0.06 L): its
/// piecewise-linear field is softer, +7 % (sphere) and +10 % (ellipsoid) at the default
/// hint, converging to the analytic value as the mesh is refined; at 0.015 L the project
/// and Drake agree within 1.5 %.
#[test]
fn static_sinkage_matches_analytic_and_the_converged_drake_mesh() {
    let d = drake();
    for case in ["sinkage_sphere", "sinkage_ellipsoid"] {
        let m = ours(case);
        let sink = get(&m, "sinkage_m");
        let analytic = drake_analytic(&d, case, "sinkage_m");
        assert!(
            rel(sink, analytic) < 0.005,
            "{case}: {sink} vs analytic {analytic}"
        );
        let fine = drake_variant(&d, case, "hint_0.015L", "sinkage_m");
        assert!(
            rel(sink, fine) < 0.015,
            "{case}: {sink} vs Drake (0.015 L) {fine}"
        );
        let coarse = drake_measured(&d, case, "sinkage_m");
        assert!(
            coarse > fine && fine > analytic * 0.999,
            "{case}: Drake's sinkage should fall towards the analytic value as the mesh is refined: {coarse} → {fine} → {analytic}"
        );
        // Both feet carry half the weight (symmetry), in both engines.
        let (l, r) = (
            get(&m, "left_normal_force_n"),
            get(&m, "right_normal_force_n"),
        );
        assert!(rel(l, r) < 1e-6 && rel(l, drake_measured(&d, case, "left_normal_force_n")) < 1e-3);
    }
}

/// Free rocking with the drive holding q = 0: the period agrees within 2 % (Drake 0.618 s).
/// The decay per cycle is the dissipation: the project's Kelvin–Voigt contact at the
/// design's τ matches the harness's analytic compliant two-foot Kelvin–Voigt rocker within
/// 1 %, and Drake's SAP decays faster because its implicit step treats every contact
/// polygon's gap implicitly, f = k(−φ₀ − (δt + τ)vₙ): the effective relaxation time is
/// τ + δt. The project run at τ + δt matches Drake within 2 % (mesh-converged: Drake's
/// decay moves by < 1 % from hint 0.06 L to 0.015 L).
#[test]
fn free_rocking_period_and_decay_explained() {
    let d = drake();
    let m = ours("free_rocking");
    let period = get(&m, "roll_period_s");
    let drake_period = drake_measured(&d, "free_rocking", "roll_period_s");
    assert!(
        rel(period, drake_period) < 0.02,
        "{period} vs Drake {drake_period}"
    );
    let decay = get(&m, "roll_decay_ratio_per_cycle");
    let analytic = drake_analytic(
        &d,
        "free_rocking",
        "roll_decay_ratio_per_cycle_compliant_two_foot_kv",
    );
    assert!(
        rel(decay, analytic) < 0.01,
        "{decay} vs analytic KV {analytic}"
    );
    let design =
        crosscheck::case_design(&common::repo(), &cases()["free_rocking"]).expect("design");
    let tau_plus_dt = design.contact.relaxation_time_s + design.numerics.time_step_s;
    let m2 = ours_with("free_rocking", "contact.relaxation_time_s", tau_plus_dt);
    let decay2 = get(&m2, "roll_decay_ratio_per_cycle");
    let drake_decay = drake_measured(&d, "free_rocking", "roll_decay_ratio_per_cycle");
    assert!(
        rel(decay2, drake_decay) < 0.02,
        "project at τ + δt: {decay2} vs Drake {drake_decay}"
    );
    let fine = drake_variant(
        &d,
        "free_rocking",
        "hint_0.015L",
        "roll_decay_ratio_per_cycle",
    );
    assert!(rel(fine, drake_decay) < 0.01);
}

/// A solid sphere rolling down 10°: rigid rolling gives (5/7) g sin θ = 1.217 m/s²; the
/// Kelvin–Voigt rolling resistance (τ v Fₙ per foot) slows it, and the harness's two
/// analytic variants (linear, clipped pressure) bracket the measured acceleration. Project
/// and Drake agree within 3 % over the first 0.25 s and the whole second.
#[test]
fn sphere_rolls_down_the_incline_as_drake_and_theory() {
    let d = drake();
    let m = ours("rolling_incline");
    for q in [
        "com_acceleration_early_mps2",
        "com_acceleration_mps2",
        "com_velocity_at_end_mps",
    ] {
        let (p, k) = (get(&m, q), drake_measured(&d, "rolling_incline", q));
        assert!(rel(p, k) < 0.03, "{q}: {p} vs Drake {k}");
    }
    let a = get(&m, "com_acceleration_mps2");
    let lin = drake_analytic(&d, "rolling_incline", "com_acceleration_mps2_kv_linear");
    let clip = drake_analytic(&d, "rolling_incline", "com_acceleration_mps2_kv_clipped");
    assert!(
        a > lin.min(clip) * 0.99 && a < lin.max(clip) * 1.01,
        "{a} outside [{lin}, {clip}]"
    );
    assert!(a < 1.2168, "slower than rigid rolling");
}

/// Spin-down on the two feet: torsional (spin) friction integrated over the patches. The
/// analytic deceleration μ∫p|s|dA / I_zz is 45.8 rad/s²; Drake 46.5. The project's
/// implicit friction freezes each point's coefficient over the step (the secant, which
/// cannot reverse a slip), under-estimating a decelerating slide by the fraction the
/// speed changes in one step: within 3 % of the analytic value and 5 % of Drake.
#[test]
fn spin_down_torsional_friction() {
    let d = drake();
    let m = ours("spin_down");
    let decel = get(&m, "yaw_deceleration_rad_s2");
    let analytic = drake_analytic(&d, "spin_down", "yaw_deceleration_rad_s2");
    let theirs = drake_measured(&d, "spin_down", "yaw_deceleration_rad_s2");
    assert!(
        rel(decel, analytic) < 0.03,
        "{decel} vs analytic {analytic}"
    );
    assert!(rel(decel, theirs) < 0.05, "{decel} vs Drake {theirs}");
}

/// A flat foot sliding at 0.5 m/s stops under Coulomb friction after v₀²/(2μg) = 15.9 mm.
/// The project stops there (within 1 %), stays on the ground, and then stays at rest
/// (no stick–slip chatter: it once buzzed at ±μgh/2 = 4 mm/s after stopping). Drake's SAP
/// stops at the same distance but its convex friction lifts the sliding foot off the
/// ground for most of the slide (the velocity-level cone constraint makes a sliding
/// contact separate at a speed ∝ μ·slip); Drake's non-convex `lagged` approximation does
/// not. This is the difference that matters for the walkers (reports/drake-crosscheck.md).
#[test]
fn sliding_foot_stops_at_the_coulomb_distance_and_stays() {
    let d = drake();
    let m = ours("slide");
    let dist = get(&m, "stopping_distance_m");
    let analytic = drake_analytic(&d, "slide", "stopping_distance_m");
    assert!(rel(dist, analytic) < 0.01, "{dist} vs Coulomb {analytic}");
    assert!(get(&m, "velocity_at_end_mps").abs() < 1e-6, "{m:?}");
    assert!(get(&m, "airborne_fraction_while_sliding") == 0.0);
    assert!(get(&m, "max_hop_height_m") < 1e-4);
    assert!(drake_measured(&d, "slide", "airborne_fraction_while_sliding") > 0.5);
    assert!(drake_variant(&d, "slide", "lagged_hc5", "airborne_fraction_while_sliding") == 0.0);
    assert!(
        rel(
            get(&m, "stop_time_s"),
            drake_measured(&d, "slide", "stop_time_s")
        ) < 0.06
    );
}

/// At rest on a 20° slope (tan 20° = 0.36 < μ = 0.8) Coulomb friction holds the foot. The
/// regularised law t = μp·v/√(v² + v_s²) must creep at the speed where it balances
/// gravity, v_s·s/√(1 − s²) with s = tan θ/μ (5.1e-5 m/s at v_s = 0.1 mm/s): within 2 %.
/// Drake's SAP creeps at 2e-7 m/s (its own regularisation), Drake `lagged` with the same
/// stiction tolerance as the project at 4.8e-5 m/s.
#[test]
fn creep_on_a_slope_is_the_regularisation_speed() {
    let d = drake();
    let m = ours("creep");
    let v = get(&m, "creep_speed_mps");
    let analytic = drake_analytic(&d, "creep", "project_regularised_creep_speed_mps");
    assert!(rel(v, analytic) < 0.02, "{v} vs {analytic}");
    let lagged = drake_variant(&d, "creep", "lagged_hc5", "creep_speed_mps");
    assert!(rel(v, lagged) < 0.1, "{v} vs Drake lagged {lagged}");
}

/// The hip servo tracking its sine with the robot floating (no contact, no gravity): the
/// amplitude ratio and phase lag of the linear PD on the effective hip inertia (analytic,
/// discretised as the project steps it) agree within 0.1 % and 0.01°; the peak torque
/// actually applied over the last second equals Drake's within 1 % (the project once
/// reported the start-of-step command instead, 34 % high).
#[test]
fn servo_tracks_its_sine_in_the_air() {
    let d = drake();
    let m = ours("servo_in_air");
    let ratio = get(&m, "amplitude_ratio");
    let a = drake_analytic(
        &d,
        "servo_in_air",
        "amplitude_ratio_discrete_linearly_implicit",
    );
    assert!(rel(ratio, a) < 1e-3, "{ratio} vs {a}");
    let lag = get(&m, "phase_lag_deg");
    let a = drake_analytic(
        &d,
        "servo_in_air",
        "phase_lag_deg_discrete_linearly_implicit",
    );
    assert!((lag - a).abs() < 0.01, "{lag} vs {a}");
    let peak = get(&m, "peak_abs_torque_nm_last_second");
    let theirs = drake_measured(&d, "servo_in_air", "peak_abs_torque_nm_last_second");
    assert!(rel(peak, theirs) < 0.01, "{peak} vs Drake {theirs}");
}

/// The walks' metrics are computed by one code for both engines: the project's
/// `report_from_trajectory` on Drake's trajectory CSV must equal what the harness's own
/// Python port of the metrics computed from the same CSV (`report_from_csv`), within 1 %
/// (velocity within 1 mm/s): a check of two independent implementations of the gait metrics.
#[test]
fn gait_metrics_agree_between_the_two_implementations() {
    let dir = golden().join("walks");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).expect("walks/") {
        let path = entry.expect("entry").path();
        let csv = path.with_extension("csv");
        if path.extension().is_none_or(|e| e != "json") || !csv.exists() {
            continue;
        }
        let r = crosscheck::read_walk_golden(&common::repo(), &path)
            .expect("golden reads")
            .drake;
        let meta: Value =
            serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("json");
        let py = &meta["report_from_csv"];
        assert_eq!(Some(r.walks), py["walks"].as_bool(), "{}", path.display());
        assert_eq!(
            r.fall_reason.as_deref(),
            py["fall_reason"].as_str(),
            "{}",
            path.display()
        );
        if r.fall_reason.is_some() {
            checked += 1;
            continue;
        }
        assert!(
            (r.velocity_mps - py["velocity_mps"].as_f64().expect("v")).abs() < 1e-3,
            "{}: v {} vs {}",
            path.display(),
            r.velocity_mps,
            py["velocity_mps"]
        );
        for q in [
            "roll_pp_deg",
            "pitch_pp_deg",
            "yaw_pp_deg",
            "step_frequency_hz",
        ] {
            let ours = match q {
                "roll_pp_deg" => r.roll_pp_deg,
                "pitch_pp_deg" => r.pitch_pp_deg,
                "yaw_pp_deg" => r.yaw_pp_deg,
                _ => r.step_frequency_hz,
            };
            let theirs = py[q].as_f64().expect("metric");
            assert!(
                (ours - theirs).abs() <= 0.01 * theirs.abs().max(1.0),
                "{}: {q} {ours} vs {theirs}",
                path.display()
            );
        }
        checked += 1;
    }
    assert!(checked >= 7, "only {checked} walk goldens checked");
}

fn walk(stem: &str) -> crosscheck::WalkComparison {
    crosscheck::compare_walk(
        &common::repo(),
        &golden().join("walks").join(format!("{stem}.json")),
    )
    .expect("walk golden compares")
}

fn within(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs()
}

/// The walkers' difference, isolated: one model (mugatu-ref with Hunt–Crossley d = 40 s/m,
/// tests/golden/drake/designs/) in Drake under its two Hunt–Crossley approximations. With
/// the convex `similar` (like SAP, a sliding contact separates) it walks, 0.17 m/s, yaw
/// 19°; with the non-convex `lagged` it scuffs in place, as it does in the project. So
/// the friction approximation, not the contact dissipation, the patch or the integrator,
/// decides whether the reference set walks.
#[test]
fn convex_friction_is_what_makes_the_reference_set_walk_in_drake() {
    let similar = walk("mugatu-ref-hc40-similar");
    let lagged = walk("mugatu-ref-hc40-lagged");
    assert_eq!(similar.drake_approximation.as_deref(), Some("similar"));
    assert_eq!(lagged.drake_approximation.as_deref(), Some("lagged"));
    let threshold = 0.1 * (9.81f64 * 0.153).sqrt();
    assert!(
        similar.drake.velocity_mps > threshold,
        "{:?}",
        similar.drake
    );
    assert!(
        lagged.drake.velocity_mps.abs() < threshold,
        "{:?}",
        lagged.drake
    );
    assert!(similar.drake.yaw_pp_deg > 1.5 * lagged.drake.yaw_pp_deg);
}

/// The project against Drake on the same Hunt–Crossley model with Drake's non-convex
/// friction (`lagged`): walker metrics within 25 % (the tolerance for walks: the
/// gait is irregular, ±2–5° cycle to cycle), neither walks, and the speeds agree within
/// 0.05 √(gL). Measured: roll 6.4 vs 8.0°, pitch 17.5 vs 16.5°, yaw 11.7 vs 10.7°,
/// steps 3.30 vs 3.11 Hz, speed 0.011 vs 0.012 m/s.
#[test]
fn project_walk_agrees_with_drake_lagged_on_the_same_model() {
    let w = walk("mugatu-ref-hc40-lagged");
    let (p, d) = (&w.project, &w.drake);
    assert!(!p.walks && !d.walks, "{p:?} / {d:?}");
    assert!((p.velocity_mps - d.velocity_mps).abs() < 0.05 * (9.81f64 * 0.153).sqrt());
    for (name, a, b) in [
        ("roll", p.roll_pp_deg, d.roll_pp_deg),
        ("pitch", p.pitch_pp_deg, d.pitch_pp_deg),
        ("yaw", p.yaw_pp_deg, d.yaw_pp_deg),
        ("step frequency", p.step_frequency_hz, d.step_frequency_hz),
    ] {
        assert!(
            within(a, b, 0.25),
            "{name}: project {a} vs Drake lagged {b}"
        );
    }
}

/// The reference Mugatu against Drake's SAP with the project's convex friction cone
/// (`friction_cone = "convex"`, SAP's relaxation: a sliding contact is pushed apart at
/// μ·|slip|), the criterion for walks: speed and attitudes within 25 %. With
/// Coulomb friction the project scuffs in place at 1.4 Hz (roll 66°, pitch 90°) where SAP
/// walks; with the convex cone both walk. Measured: 1.4 Hz |v| 0.165 vs 0.165 m/s, roll
/// 11.1 vs 11.8°, pitch 12.0 vs 12.3°, yaw 16.0 vs 16.1°; the scaled walks (0.5×, 2×) and
/// the −3° start within 13 %. The speed's sign is not compared: the fore–aft-symmetric
/// rocker's direction is set by its first cycles, and Drake itself walks this model
/// forward or backward with the relaxation time (reports/drake-crosscheck.md).
#[test]
fn reference_walk_within_25_percent_of_drake_sap_with_the_convex_cone() {
    for stem in [
        "mugatu-ref-1x-f1.4",
        "mugatu-ref-1x-f1.4-roll-minus3",
        "mugatu-ref-L0.05",
        "mugatu-ref-L0.5",
    ] {
        let w = walk(stem);
        assert_eq!(w.drake_approximation.as_deref(), Some("sap"), "{stem}");
        let p = w
            .project_convex
            .as_ref()
            .expect("a SAP golden has a convex run");
        let d = &w.drake;
        let sqrt_gl = (9.81 * w.leg_length_m).sqrt();
        assert!(
            p.velocity_mps.abs() > 0.1 * sqrt_gl && d.velocity_mps.abs() > 0.1 * sqrt_gl,
            "{stem}: both walk: {p:?} / {d:?}"
        );
        for (name, a, b) in [
            ("|v|", p.velocity_mps.abs(), d.velocity_mps.abs()),
            ("roll", p.roll_pp_deg, d.roll_pp_deg),
            ("pitch", p.pitch_pp_deg, d.pitch_pp_deg),
            ("yaw", p.yaw_pp_deg, d.yaw_pp_deg),
            ("step frequency", p.step_frequency_hz, d.step_frequency_hz),
        ] {
            assert!(within(a, b, 0.25), "{stem} {name}: convex {a} vs SAP {b}");
        }
        // With Coulomb friction the 1× walks scuff in place instead (the gap this closes).
        if stem == "mugatu-ref-1x-f1.4" {
            assert!(
                w.project.velocity_mps.abs() < 0.1 * sqrt_gl,
                "{:?}",
                w.project
            );
            assert!(
                w.project.roll_pp_deg > 3.0 * d.roll_pp_deg,
                "{:?}",
                w.project
            );
        }
    }
}

/// The convex cone on the slide case (a flat foot sliding at 0.5 m/s): like Drake's SAP
/// and unlike Coulomb friction, the sliding foot is lifted off the ground for most of the
/// slide, in hops of millimetres. Drake: airborne 86 % of the slide, hops of 2.19 mm,
/// velocity line-fit deceleration 4.08 m/s²; project (convex): 80 %, 2.83 mm, 4.33 m/s²
/// (tolerances 0.1, 50 %, 15 %). Known difference, asserted as a bound: the project's
/// foot stops 43 % farther (22.3 vs 15.5 mm; SAP stops at the Coulomb distance, as rigid
/// Anitescu contact predicts for this case). The project solves the cone by a linearly
/// implicit step with friction rescaled to the step's normal force (4 passes), not by
/// SAP's convex optimisation, and its hops land harder.
#[test]
fn convex_cone_lifts_a_sliding_foot_as_drake_sap_does() {
    let d = drake();
    let case = crosscheck::with_convex_cone(&cases()["slide"]);
    let m = crosscheck::run_case(&common::repo(), "slide", &case).expect("case runs");
    let air = get(&m, "airborne_fraction_while_sliding");
    let sap_air = drake_measured(&d, "slide", "airborne_fraction_while_sliding");
    assert!(
        (air - sap_air).abs() < 0.1,
        "airborne {air} vs SAP {sap_air}"
    );
    let hop = get(&m, "max_hop_height_m");
    let sap_hop = drake_measured(&d, "slide", "max_hop_height_m");
    assert!(rel(hop, sap_hop) < 0.5, "hop {hop} vs SAP {sap_hop}");
    let fit = get(&m, "deceleration_linefit_mps2");
    let sap_fit = drake_measured(&d, "slide", "deceleration_linefit_mps2");
    assert!(rel(fit, sap_fit) < 0.15, "line fit {fit} vs SAP {sap_fit}");
    let dist = get(&m, "stopping_distance_m");
    let sap_dist = drake_measured(&d, "slide", "stopping_distance_m");
    assert!(
        dist > sap_dist && dist < 1.6 * sap_dist,
        "distance {dist} vs SAP {sap_dist}"
    );
    // The cone changes nothing where nothing slides: the sinkage case is Coulomb's.
    let still = crosscheck::run_case(
        &common::repo(),
        "sinkage_sphere",
        &crosscheck::with_convex_cone(&cases()["sinkage_sphere"]),
    )
    .expect("case runs");
    let coulomb = ours("sinkage_sphere");
    assert!(rel(get(&still, "sinkage_m"), get(&coulomb, "sinkage_m")) < 1e-6);
}
