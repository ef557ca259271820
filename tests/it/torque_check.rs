//! `survey torque-check` (src/study/torque_check.rs) and the torque of `survey predict
//! --from design:NAME` (src/study/torque_need.rs), checked on hand-built Table III chains
//! whose crossovers follow in closed form, and on the bundled study.

use robot_survey::motors::MotorCatalogue;
use robot_survey::sim::{ContactScaling, GRAVITY_MPS2, MassLaw};
use robot_survey::study::table3::{Table3Point, rows_from_points};
use robot_survey::study::torque_check::{Bridge, torque_check};
use robot_survey::study::torque_need::torque_need;

use crate::common::{stderr, stdout, survey};

/// A chain where τ_min = c·L³ exactly (m ∝ L², τ/(mgL) constant) at 8 sizes.
fn chain(c: f64) -> Vec<Table3Point> {
    [0.02, 0.05, 0.1, 0.153, 0.3, 0.5, 0.8, 1.2]
        .iter()
        .map(|&l: &f64| {
            let m = 0.9 * (l / 0.153f64).powi(2);
            let mgl = m * GRAVITY_MPS2 * l;
            let tau = c * l.powi(3);
            Table3Point {
                design: "mugatu".into(),
                mass_law: MassLaw::L2,
                contact: ContactScaling::Similar,
                leg_length_m: l,
                mass_kg: m,
                mgl_nm: mgl,
                duration_s: 25.0,
                walks: true,
                walks_at_design_torque: true,
                min_torque_nm: Some(tau),
                min_torque_over_mgl: Some(tau / mgl),
                bracket_lo_nm: Some(0.98 * tau),
                bracket_hi_nm: Some(tau),
                walks_evaluated: 5,
                failure_below: Some("no_progress".into()),
                gait_at: Some("design_torque".into()),
                gait_torque_nm: Some(tau),
                velocity_mps: Some(0.4 * l.sqrt()),
                froude: Some(0.128),
                step_frequency_hz: Some(1.0),
                roll_pp_deg: Some(18.0),
                pitch_pp_deg: Some(10.0),
                yaw_pp_deg: Some(9.0),
                peak_torque_nm: Some(tau),
            }
        })
        .collect()
}

/// Required τ = c·L³; a law τ ∝ L_m^k pinned at the anchor (L₀ = 0.153 m, τ₀ = 0.52 N·m at
/// 5 V, the XL330-M288-T datasheet) gives, with an isometric actuator, margin
/// M(L) = (τ₀/(c·L₀³))·(L/L₀)^(k−3), so M = 1 at L* = L₀·(c·L₀³/τ₀)^(1/(k−3)); with a fixed
/// mass fraction and m ∝ L², the law becomes L^(2k/3) and L* = L₀·(c·L₀³/τ₀)^(1/(2k/3−3)).
#[test]
fn crossovers_follow_the_closed_form_under_both_bridges() {
    let cat = MotorCatalogue::bundled().expect("bundled motor catalogue");
    // c chosen so the requirement at L₀ is 0.26 N·m: half the anchor's stall torque.
    let (l0, tau0) = (0.153f64, 0.52f64);
    let c = 0.26 / l0.powi(3);
    let rows = rows_from_points(&chain(c));
    let mass_at = |l: f64| 0.9 * (l / l0).powi(2);
    let check = torque_check(&rows[0], &cat, None, None, &mass_at).expect("check");
    assert_eq!(check.anchor.stall_torque_nm, 0.52);
    assert!((check.anchor.required_nm.expect("at anchor") - 0.26).abs() < 1e-12);
    let ratio = c * l0.powi(3) / tau0; // 0.5
    for b in &check.bridges {
        for law_id in ["theory-lm-5", "empirical-lm-4"] {
            let law = b
                .laws
                .iter()
                .find(|l| l.law == law_id)
                .expect("law present");
            let k = law.law_exponent;
            let p = match b.bridge {
                Bridge::IsometricActuator => k,
                Bridge::FixedMassFraction => 2.0 * k / 3.0,
            };
            assert!(
                (law.exponent_vs_leg_length - p).abs() < 1e-12,
                "{law_id} {p}"
            );
            let expect = l0 * ratio.powf(1.0 / (p - 3.0));
            if (0.02..=1.2).contains(&expect) {
                assert_eq!(law.crossovers_m.len(), 1, "{law_id} {:?}", b.bridge);
                let got = law.crossovers_m[0];
                assert!(
                    (got / expect - 1.0).abs() < 1e-9,
                    "{law_id} {:?}: {got} vs {expect}",
                    b.bridge
                );
            } else {
                assert!(
                    law.crossovers_m.is_empty(),
                    "{law_id}: {:?}",
                    law.crossovers_m
                );
            }
        }
    }
    // Isometric actuator: actuator mass ∝ L³ over robot mass ∝ L², fraction ∝ L.
    let iso = &check.bridges[0];
    let f = |i: usize| iso.actuator_mass_fraction[i].expect("fraction");
    assert!((f(7) / f(0) - 1.2 / 0.02).abs() < 1e-9);
    assert!((f(3) - 0.018 / 0.9).abs() < 1e-12, "anchor's 18 g of 900 g");
}

/// The catalogue's stall torque ∝ M^1.33 (the research note's independent fit) turns into
/// L^(3·1.33) with an isometric actuator and L^(2·1.33) with a fixed mass fraction (m ∝ L²).
#[test]
fn catalogue_fit_law_follows_the_bridge() {
    let cat = MotorCatalogue::bundled().expect("catalogue");
    let rows = rows_from_points(&chain(0.26 / 0.153f64.powi(3)));
    let check =
        torque_check(&rows[0], &cat, None, None, &|l| 0.9 * (l / 0.153).powi(2)).expect("check");
    let b = check.actuator_fit_exponent.expect("fit");
    assert!((b - 1.326).abs() < 0.001, "{b}");
    for (bridge, factor) in check.bridges.iter().zip([3.0, 2.0]) {
        let fit = bridge
            .laws
            .iter()
            .find(|l| l.law == "catalogue-fit")
            .expect("catalogue law");
        assert!((fit.exponent_vs_leg_length - factor * b).abs() < 1e-12);
    }
}

/// τ = (τ_min/mgL)·m·g·L with the Table III ratio interpolated at L: on the hand-built
/// chain the ratio is c·L³/(m g L) with m = 0.9 (L/0.153)², i.e. constant.
#[test]
fn required_torque_is_the_ratio_times_mgl_of_each_mass() {
    let c = 0.26 / 0.153f64.powi(3);
    let pts = chain(c);
    let need = torque_need(
        &pts,
        "mugatu",
        MassLaw::L2,
        ContactScaling::Similar,
        0.4,
        &[("budget".into(), 10.0, Some([5.0, 20.0]))],
        None,
        2.0,
    )
    .expect("need");
    let ratio = c * 0.153f64.powi(2) / (0.9 * GRAVITY_MPS2);
    assert!((need.min_torque_over_mgl / ratio - 1.0).abs() < 1e-12);
    let t = &need.torques[0];
    assert!((t.required_nm - ratio * 10.0 * GRAVITY_MPS2 * 0.4).abs() < 1e-9);
    assert!((t.required_interval_nm[1] - ratio * 20.0 * GRAVITY_MPS2 * 0.4).abs() < 1e-9);
    assert!((t.required_interval_nm[0] - 0.98 * ratio * 5.0 * GRAVITY_MPS2 * 0.4).abs() < 1e-9);
    // Outside the walking sizes there is nothing to interpolate.
    let err = torque_need(
        &pts,
        "mugatu",
        MassLaw::L2,
        ContactScaling::Similar,
        2.0,
        &[],
        None,
        2.0,
    )
    .map(|_| ())
    .expect_err("2 m is outside 0.02–1.2 m");
    assert!(err.to_string().contains("outside"), "{err}");
}

#[test]
fn torque_check_cli_answers_for_mugatu() {
    let out = survey(&["torque-check", "--design", "mugatu", "--format", "json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("json");
    assert_eq!(v["anchor"]["actuator"], "dynamixel-xl330-m288-t");
    assert_eq!(v["bridges"].as_array().map(|b| b.len()), Some(2));
    // Zippy's motor is not catalogued: a clear error, not a number.
    let out = survey(&["torque-check", "--design", "zippy"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--actuator"), "{}", stderr(&out));
}

#[test]
fn predict_from_a_design_gives_the_required_torque() {
    let out = survey(&[
        "predict",
        "--leg-length",
        "1.0",
        "--from",
        "design:mugatu",
        "--format",
        "json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("json");
    let t = &v["torque"];
    let ratio = t["min_torque_over_mgl"].as_f64().expect("ratio");
    let first = &t["torques"][0];
    let m = first["mass_kg"].as_f64().expect("mass");
    let tau = first["required_nm"].as_f64().expect("torque");
    assert!((tau - ratio * m * GRAVITY_MPS2 * 1.0).abs() < 1e-9 * tau);
    // Mugatu needs about 0.12 m·g·L (its 1× minimum, 0.162 N·m at 0.9 kg and 0.153 m).
    assert!((0.08..0.2).contains(&ratio), "{ratio}");
}
