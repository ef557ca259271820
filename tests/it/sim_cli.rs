//! `survey sim` through the real binary: JSON keys the issue names, outputs written,
//! bad input refused with exit 2 and a message naming what was wrong.

use crate::common;

use crate::common::{stderr, stdout, survey};

#[test]
fn walk_json_has_the_documented_keys() {
    let o = survey(&[
        "sim",
        "walk",
        "--design",
        "mugatu",
        "--duration",
        "8",
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    for k in [
        "walks",
        "velocity_mps",
        "froude",
        "step_frequency_hz",
        "roll_pp_deg",
        "roll_pp_deg_sd",
        "pitch_pp_deg",
        "pitch_pp_deg_sd",
        "yaw_pp_deg",
        "yaw_pp_deg_sd",
        "cot",
        "peak_torque_nm",
        "converged_at_s",
        "fall_reason",
    ] {
        assert!(v.get(k).is_some(), "missing key {k} in {v}");
    }
    // Froude = v/√(gL) (hand: definition, g = 9.80665 m/s²).
    let v_mps = v["velocity_mps"].as_f64().expect("v");
    let l = v["leg_length_m"].as_f64().expect("L");
    let fr = v["froude"].as_f64().expect("Froude");
    assert!((fr - v_mps / (9.80665 * l).sqrt()).abs() < 1e-3 * fr.abs().max(1e-9));
}

#[test]
fn walk_writes_trajectory_and_plot() {
    let dir = tempfile::tempdir().expect("tempdir");
    let csv = dir.path().join("walk.csv");
    let svg = dir.path().join("walk.svg");
    let o = survey(&[
        "sim",
        "walk",
        "--duration",
        "3",
        "--trajectory",
        csv.to_str().expect("utf8"),
        "--plot",
        svg.to_str().expect("utf8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).expect("csv");
    assert!(text.starts_with("t_s,"));
    assert!(text.lines().count() > 100);
    assert!(std::fs::read_to_string(&svg).expect("svg").contains("<svg"));
}

#[test]
fn bad_sim_input_is_exit_2_with_a_clear_message() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bad = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(common::repo().join("dataset/walkers/mugatu.toml"))
        .expect("mugatu design")
        .replace("total_mass_kg = 0.9", "total_mass_kg = -0.9");
    std::fs::write(&bad, text).expect("write");
    let bad_s = bad.to_str().expect("utf8");
    // A 0.5 s step (once: ran, and reported `"walks": false` as if the robot fell) and a
    // modulus of 1e30 Pa (likewise).
    let mugatu = std::fs::read_to_string(common::repo().join("dataset/walkers/mugatu.toml"))
        .expect("read mugatu.toml");
    let step = dir.path().join("step.toml");
    std::fs::write(
        &step,
        mugatu.replace("time_step_s = 0.002", "time_step_s = 0.5"),
    )
    .expect("write");
    let step_s = step.to_str().expect("utf8");
    let stiff = dir.path().join("stiff.toml");
    std::fs::write(
        &stiff,
        mugatu.replace(
            "hydroelastic_modulus_pa = 3.0e6",
            "hydroelastic_modulus_pa = 1e30",
        ),
    )
    .expect("write");
    let stiff_s = stiff.to_str().expect("utf8");
    // A trajectory whose second data row (line 3) has a non-number.
    let traj = dir.path().join("traj.csv");
    std::fs::write(
        &traj,
        "t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,hip_angle_deg,hip_torque_nm,peak_abs_torque_nm,positive_work_j,feet_in_contact,left_normal_force_n,right_normal_force_n\n\
         0,0,0,0.15,0,0,0,0,0,0,0,2,4,4\n\
         0.01,0,0,abc,0,0,0,0,0,0,0,2,4,4\n",
    )
    .expect("write");
    let traj_s = traj.to_str().expect("utf8");
    for (args, needle) in [
        (
            vec!["sim", "walk", "--design", "no-such-walker"],
            "no-such-walker",
        ),
        (vec!["sim", "walk", "--leg-length=-1"], "leg"),
        (vec!["sim", "walk", "--duration", "0"], "duration"),
        (vec!["sim", "walk", "--design", bad_s], "total_mass_kg"),
        (vec!["sim", "scale", "--leg-lengths", "0.1,-2"], "-2"),
        // Once aborted with "memory allocation of 28000000000224 bytes failed" (exit 134).
        (vec!["sim", "walk", "--duration", "1e9"], "duration"),
        (vec!["sim", "walk", "--leg-length", "1e4"], "leg_length"),
        (vec!["sim", "walk", "--frequency", "nan"], "frequency"),
        (vec!["sim", "walk", "--design", step_s], "stable limit"),
        (
            vec!["sim", "walk", "--design", stiff_s],
            "hydroelastic_modulus_pa",
        ),
        (
            vec![
                "sim",
                "analyze",
                "--design",
                "mugatu",
                "--trajectory",
                traj_s,
            ],
            "line 3",
        ),
    ] {
        let o = survey(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(needle),
            "{args:?}: `{needle}` not in {}",
            stderr(&o)
        );
        assert!(!stderr(&o).contains("panicked"));
    }
}

#[test]
fn scale_reports_the_similarity_exponents() {
    let o = survey(&[
        "sim",
        "scale",
        "--leg-lengths",
        "0.05,0.153,0.6",
        "--duration",
        "15",
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    let b = v["velocity_law"]["b"].as_f64().expect("velocity exponent");
    // Dynamic similarity (hand-derived, see tests/sim_scaling.rs): v ∝ L^0.5.
    assert!((b - 0.5).abs() < 0.01, "v ∝ L^{b}");
    assert_eq!(v["walks"].as_array().map(Vec::len), Some(3));
}
