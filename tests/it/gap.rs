//! The sim-to-real gap diagnosis' inputs: trials validation (every error names file, line
//! and column), the effect library, synthetic trials, and a trajectory measured like a walk.
//! The diagnosis' answers on cases of known cause are in `gap_posterior.rs`.

use robot_survey::gap::decide::AnswerKind;
use robot_survey::gap::diagnose::{DiagnoseOptions, diagnose_conditions};
use robot_survey::gap::knob::ModelSetting;
use robot_survey::gap::simulate::resolve;
use robot_survey::gap::{EffectLibrary, TrialSet};
use robot_survey::progress::Silent;

use super::common::{bundled_walks, repo, stderr, stdout, survey};

fn parse(text: &str) -> Result<TrialSet, String> {
    TrialSet::parse(text, "t.csv", std::path::Path::new(".")).map_err(|e| e.to_string())
}

#[test]
fn trials_errors_name_file_line_and_column() {
    let head = "label,design,leg_length_m,velocity_mps,velocity_mps_sd,source\n";
    let cases = [
        (
            "label,design,leg_length_m,speed,source\na,mugatu,0.15,0.1,x\n",
            "t.csv:1:4:",
            "unknown column",
        ),
        (
            &format!("{head}a,mugatu,0.15,0.1,,x\nb,mugatu,abc,0.1,,x\n") as &str,
            "t.csv:3:3:",
            "not a number",
        ),
        (
            &format!("{head}a,mugatu,0.15,,0.01,x\n"),
            "t.csv:2:5:",
            "velocity_mps_sd given without velocity_mps",
        ),
        (
            &format!("{head}a,mugatu,0.15,0.1,-0.01,x\n"),
            "t.csv:2:5:",
            "must be > 0",
        ),
        (
            &format!("{head}a,mugatu,0.15,0.1,0.01,\n"),
            "t.csv:2:6:",
            "source: empty",
        ),
        (
            &format!("{head}a,mugatu,500,0.1,0.01,x\n"),
            "t.csv:2:3:",
            "leg length in [0.001, 100]",
        ),
        (
            "design,leg_length_m,velocity_mps\nmugatu,0.15,0.1\n",
            "t.csv:1:4:",
            "missing required column \"source\"",
        ),
        (
            "design,leg_length_m,roll_pp_deg,source\nmugatu,0.15,-3,x\n",
            "t.csv:2:3:",
            "must be ≥ 0",
        ),
    ];
    for (text, at, what) in cases {
        let e = parse(text).expect_err(text);
        assert!(e.starts_with(at), "{e:?} should start with {at}");
        assert!(e.contains(what), "{e:?} should say {what}");
    }
    // Condition columns that do not fit the design are caught when resolving, with the line.
    let set = parse(
        "design,leg_length_m,amplitude_deg,velocity_mps,source\nmugatu,0.15,20,0.1,x\nzippy,0.025,20,0.1,x\n",
    )
    .expect("parses");
    let e = resolve(&set)
        .expect_err("zippy has no amplitude")
        .to_string();
    assert!(e.starts_with("t.csv:3:"), "{e}");
    assert!(e.contains("bang-bang"), "{e}");
    let set = parse("design,leg_length_m,velocity_mps,source\nno-such-walker,0.15,0.1,x\n")
        .expect("parses");
    let e = resolve(&set).expect_err("unknown design").to_string();
    assert!(
        e.starts_with("t.csv:2:") && e.contains("no-such-walker"),
        "{e}"
    );
}

#[test]
fn cli_reports_a_bad_trials_file_and_exits_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("bad.csv");
    std::fs::write(
        &p,
        "design,leg_length_m,velocity_mps,source\nmugatu,0.15,fast,x\n",
    )
    .expect("write");
    let o = survey(&["gap", "diagnose", "--trials", p.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("bad.csv:2:3: velocity_mps: \"fast\" is not a number"),
        "{e}"
    );
}

#[test]
fn published_trials_are_valid_and_sourced() {
    let set = TrialSet::read(&repo().join("dataset/trials/published.csv")).expect("valid");
    assert_eq!(set.trials.len(), 4);
    assert!(set.trials.iter().all(|t| t.source.len() > 20));
    resolve(&set).expect("designs resolve");
}

/// A trial's `mass_kg` is a payload on the same robot: the servo's gains and the hardstop
/// keep their SI values. Hand-derived: the bundled Mugatu's kp = 20·m·g·L = 20 × 0.9 kg ×
/// 9.81 m/s² × 0.153 m = 27.02 N·m/rad and kd = 2·m·g·L·√(L/g) = 0.3375 N·m·s/rad, with
/// or without 0.27 kg more; only the mass (and so the weight on the feet) changes.
#[test]
fn a_payload_leaves_the_servo_and_the_hardstop_as_they_are() {
    use robot_survey::sim::Controller;
    let text = "label,design,leg_length_m,mass_kg,source\n\
                bare,mugatu,0.153,,x\nloaded,mugatu,0.153,1.17,x\n";
    let set = parse(text).expect("valid");
    let conditions = resolve(&set).expect("resolve");
    let lib = EffectLibrary::bundled().expect("library");
    let designs: Vec<_> = conditions
        .iter()
        .map(|c| {
            c.design_with(&lib, &ModelSetting::default())
                .expect("design")
        })
        .collect();
    let gains = |d: &robot_survey::sim::Design| match d.controller() {
        Controller::ServoSine {
            kp_nm_per_rad,
            kd_nms_per_rad,
            ..
        } => (kp_nm_per_rad, kd_nms_per_rad),
        other => panic!("a servo, not {other:?}"),
    };
    let (kp0, kd0) = gains(&designs[0]);
    let (kp1, kd1) = gains(&designs[1]);
    let mgl = 0.9 * 9.81 * 0.153;
    assert!((kp0 - 20.0 * mgl).abs() < 0.01 * kp0, "kp {kp0}");
    assert!(
        (kd0 - 2.0 * mgl * (0.153f64 / 9.81).sqrt()).abs() < 0.01 * kd0,
        "kd {kd0}"
    );
    assert!(
        (kp1 - kp0).abs() < 1e-9 * kp0,
        "payload changed kp: {kp0} → {kp1}"
    );
    assert!(
        (kd1 - kd0).abs() < 1e-9 * kd0,
        "payload changed kd: {kd0} → {kd1}"
    );
    assert!((designs[1].mass.total_mass_kg - 1.17).abs() < 1e-12);
    let stop = |d: &robot_survey::sim::Design| {
        d.model()
            .hardstop
            .map(|h| (h.stiffness_nm_per_rad, h.damping_nms_per_rad))
            .expect("a hardstop")
    };
    let (k0, c0) = stop(&designs[0]);
    let (k1, c1) = stop(&designs[1]);
    assert!((k1 - k0).abs() < 1e-9 * k0 && (c1 - c0).abs() < 1e-9 * c0);
}

#[test]
fn effect_list_has_every_candidate_with_ranges() {
    let o = survey(&["gap", "effects", "--format", "json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    let list = v.as_array().expect("a list");
    let names: Vec<&str> = list.iter().filter_map(|e| e["name"].as_str()).collect();
    for n in [
        "hip_viscous_damping",
        "hip_coulomb_friction",
        "motor_torque_speed",
        "friction_coefficient",
        "soft_ground",
        "rolling_resistance",
        "actuation_latency",
        "hip_backlash",
    ] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    for e in list {
        assert!(!e["description"].as_str().unwrap_or("").is_empty());
        for p in e["params"].as_array().expect("params") {
            let (d, lo, hi) = (
                p["default"].as_f64().expect("default"),
                p["min"].as_f64().expect("min"),
                p["max"].as_f64().expect("max"),
            );
            assert!(lo < hi && lo <= d && d <= hi, "{e}");
            assert!(!p["unit"].as_str().unwrap_or("").is_empty());
        }
    }
    // Mugatu at 1×: m·g·L = 0.9·9.81·0.153 = 1.3508 N·m, the unit of the friction torque range.
    let cf = list
        .iter()
        .find(|e| e["name"] == "hip_coulomb_friction")
        .expect("coulomb");
    let scale = cf["params"][0]["scale_value"].as_f64().expect("scale");
    assert!((scale - 0.9 * 9.81 * 0.153).abs() < 1e-9, "{scale}");
}

#[test]
fn synth_is_deterministic_and_its_noise_is_stated() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cond = dir.path().join("c.csv");
    std::fs::write(
        &cond,
        "design,leg_length_m,frequency_hz,source\nmugatu,0.153,1.24,x\nmugatu,0.306,0.877,x\n",
    )
    .expect("write");
    let run_with = |out: &str, extra: &[&str]| {
        let p = dir.path().join(out);
        let mut args = vec![
            "gap",
            "synth",
            "--conditions",
            cond.to_str().expect("utf-8"),
            "--effect",
            "hip_viscous_damping=0.01",
            "--noise",
            "0.05",
            "--seed",
            "4",
            "--out",
            p.to_str().expect("utf-8"),
        ];
        args.extend_from_slice(extra);
        let o = survey(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read_to_string(p).expect("read")
    };
    let run = |out: &str| run_with(out, &[]);
    let (a, b) = (run("a.csv"), run("b.csv"));
    assert_eq!(a, b, "same seed, same bytes");
    let set = TrialSet::parse(&a, "a.csv", dir.path()).expect("synth output parses");
    assert_eq!(set.trials.len(), 2);
    for t in &set.trials {
        let v = t.measured[0].expect("velocity measured");
        // sd = 0.05·|truth| and value = truth·(1 + 0.05·e): sd/value = 0.05/(1 + 0.05e).
        let ratio = v.sd.expect("sd") / v.value.abs();
        assert!((0.04..0.065).contains(&ratio), "{ratio}");
        assert!(t.source.contains("--effect hip_viscous_damping=0.01"));
    }
    // --expected: the truth itself, with the same sd (0.05·|truth|, as the noisy file
    // states): sd/value = 0.05 up to the file's rounding, and the noisy value differs.
    let e = run_with("e.csv", &["--expected"]);
    let expected = TrialSet::parse(&e, "e.csv", dir.path()).expect("expected output parses");
    let mut drawn = 0;
    for (x, t) in expected.trials.iter().zip(&set.trials) {
        assert!(x.source.contains("--expected"), "{}", x.source);
        for (mx, mt) in x.measured.iter().zip(&t.measured) {
            let (Some(mx), Some(mt)) = (mx, mt) else {
                assert_eq!(mx.is_some(), mt.is_some());
                continue;
            };
            let sd = mx.sd.expect("sd");
            assert!(
                (sd / mx.value.abs() - 0.05).abs() < 1e-5,
                "{sd} vs {}",
                mx.value
            );
            assert!(
                (sd / mt.sd.expect("sd") - 1.0).abs() < 1e-5,
                "same sd in both files"
            );
            drawn += usize::from(mx.value != mt.value);
        }
    }
    assert!(
        drawn > 0,
        "the seeded file has noise the expected one has not"
    );
}

#[test]
fn a_trajectory_file_is_measured_like_a_walk() {
    // A "measurement" that is the nominal model's own trajectory (sim walk --trajectory):
    // its metrics, measured by the walk code, must match the nominal simulation.
    let dir = tempfile::tempdir().expect("tempdir");
    let traj = dir.path().join("walk.csv");
    let o = survey(&[
        "sim",
        "walk",
        "--design",
        "mugatu",
        "--duration",
        "13",
        "--trajectory",
        traj.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = "label,design,leg_length_m,trajectory,source\nmocap,mugatu,0.153,walk.csv,x\n";
    let set = TrialSet::parse(text, "t.csv", dir.path()).expect("parses");
    let lib = EffectLibrary::bundled().expect("library");
    let conditions = resolve(&set).expect("resolve");
    let mut opts = DiagnoseOptions::new().expect("criterion");
    opts.effects = vec!["hip_viscous_damping".into()];
    opts.grid_points = 2;
    opts.calibrate = false;
    opts.undeclared = false;
    let (d, _) = diagnose_conditions(&set, &conditions, &lib, &opts, bundled_walks(), &Silent)
        .expect("diagnosis");
    assert_eq!(
        d.n_observations - d.n_cycle_observations,
        7,
        "every walk metric measured from the file"
    );
    assert!(
        d.n_cycle_observations > 100,
        "and its cycle: {}",
        d.n_cycle_observations
    );
    assert!(d.gap_before < 0.3, "gap {}", d.gap_before);
    assert_eq!(d.answer.kind, AnswerKind::NoGap, "{}", d.answer.statement);
}
