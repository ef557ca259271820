//! Robot logs in the diagnosis (`survey gap synth --logs`, trials whose `trajectory` names a
//! log): the cycles' Fourier coefficients are one more block of the likelihood. Run through
//! the real binary on the six test conditions (`tests/data/gap/conditions-6.csv`) and on
//! Drake's trials with logs; plus `survey gap suggest`.

use std::path::Path;
use std::process::Output;

use robot_survey::gap::trials::{Metric, TrialSet};

use super::common::{repo, stderr, stdout, survey};

/// A scratch folder holding the six test conditions and their design.
fn scratch() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    for f in ["conditions-6.csv", "mugatu-two-uncertain.toml"] {
        std::fs::copy(repo().join("tests/data/gap").join(f), dir.path().join(f)).expect("copy");
    }
    dir
}

/// `survey gap synth` on the six conditions with logs and the effects `truth` (NAME=VALUE);
/// returns the trials path.
fn synth(dir: &Path, name: &str, truth: &[&str], seed: u64) -> String {
    let out = dir.join(format!("{name}.csv"));
    let logs = dir.join(format!("{name}-logs"));
    let cond = dir.join("conditions-6.csv");
    let seed = seed.to_string();
    let mut args = vec![
        "gap",
        "synth",
        "--conditions",
        cond.to_str().expect("utf-8"),
        "--noise",
        "0.03",
        "--seed",
        &seed,
        "--out",
        out.to_str().expect("utf-8"),
        "--logs",
        logs.to_str().expect("utf-8"),
    ];
    for t in truth {
        args.push("--effect");
        args.push(t);
    }
    let o = survey(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    out.to_str().expect("utf-8").to_string()
}

/// `survey gap diagnose --format json` with `extra` arguments.
fn diagnose(trials: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["gap", "diagnose", "--trials", trials, "--format", "json"];
    args.extend_from_slice(extra);
    let o = survey(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&stdout(&o)).expect("json")
}

const LOOK_ALIKES: [&str; 4] = [
    "--effects",
    "hip_coulomb_friction,hip_viscous_damping",
    "--no-calibration",
    "--no-undeclared",
];

fn probability(d: &serde_json::Value, explanation: &str) -> f64 {
    d["posterior"]
        .as_array()
        .expect("posterior")
        .iter()
        .find(|l| l["explanation"] == explanation)
        .and_then(|l| l["probability"].as_f64())
        .unwrap_or(0.0)
}

/// Hip Coulomb friction of 0.009 N·m: on the summaries it and viscous damping explain the
/// trials alike (nothing named); the hip-torque cycle shows the constant-magnitude friction
/// torque reversing with the swing, which a rate-proportional damping cannot draw, and with
/// the logs the posterior names Coulomb friction.
#[test]
fn the_cycles_tell_coulomb_friction_from_damping_where_the_summaries_cannot() {
    let dir = scratch();
    let trials = synth(dir.path(), "coulomb", &["hip_coulomb_friction=0.009"], 1);
    let with = diagnose(&trials, &LOOK_ALIKES);
    assert_eq!(
        with["answer"]["explanation"], "hip_coulomb_friction",
        "{}",
        with["answer"]
    );
    // The same trials without their logs.
    let text = std::fs::read_to_string(&trials).expect("trials");
    let set = TrialSet::parse(&text, "t", dir.path()).expect("parse");
    let mut bare = set.clone();
    for t in bare.trials.iter_mut() {
        t.trajectory = None;
    }
    let bare_path = dir.path().join("bare.csv");
    std::fs::write(&bare_path, bare.to_csv().expect("csv")).expect("write");
    let without = diagnose(bare_path.to_str().expect("utf-8"), &LOOK_ALIKES);
    assert_eq!(
        without["answer"]["kind"], "ambiguous",
        "{}",
        without["answer"]
    );
    let (p_with, p_without) = (
        probability(&with, "hip_coulomb_friction"),
        probability(&without, "hip_coulomb_friction"),
    );
    assert!(p_with > p_without + 0.2, "{p_with} vs {p_without}");
}

/// The logs `synth --logs` writes carry only what a robot records, the trials name them
/// relative to the trials file, and the same seed writes the same bytes.
#[test]
fn synth_logs_are_robot_logs_and_deterministic() {
    let dir = scratch();
    let a = synth(dir.path(), "a", &["hip_viscous_damping=0.01"], 3);
    let b = synth(dir.path(), "b", &["hip_viscous_damping=0.01"], 3);
    let text_a = std::fs::read_to_string(&a).expect("a");
    let text_b = std::fs::read_to_string(&b).expect("b");
    assert_eq!(text_a.replace("a-logs", "b-logs"), text_b);
    let log = std::fs::read_to_string(dir.path().join("a-logs/L1x-f0.97x.csv")).expect("log");
    assert_eq!(
        log.lines().next(),
        Some("t_s,hip_angle_deg,roll_deg,pitch_deg,yaw_deg,hip_torque_nm")
    );
    assert!(text_a.contains(",a-logs/L1x-f0.97x.csv,"), "{text_a}");
    for name in ["L1x-f0.97x.csv", "L2x-f1.03x.csv"] {
        let x = std::fs::read(dir.path().join("a-logs").join(name)).expect("log a");
        let y = std::fs::read(dir.path().join("b-logs").join(name)).expect("log b");
        assert_eq!(x, y, "{name}: same seed, same bytes");
    }
}

/// A robot's log with a bad cell: the error names the trials file and line, and the log's
/// file, line and column.
#[test]
fn a_bad_robot_log_names_its_line_and_column() {
    let dir = scratch();
    let trials = synth(dir.path(), "t", &["hip_coulomb_friction=0.02"], 4);
    let log = dir.path().join("t-logs/L1x-f1x.csv");
    let text = std::fs::read_to_string(&log).expect("log");
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<&str> = lines[5].split(',').collect();
    cells[2] = "north";
    lines[5] = cells.join(",");
    std::fs::write(&log, lines.join("\n")).expect("write");
    let o = survey(&["gap", "diagnose", "--trials", &trials]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("t.csv:3:")
            && e.contains("L1x-f1x.csv:6:3:")
            && e.contains("`north` is not a number"),
        "{e}"
    );
}

/// The documented example (`dataset/trials/example-logs.csv`, dataset/trials/README.md):
/// two trials with logs, the look-alike hip losses weighed: the posterior names Coulomb
/// friction, the truth the synth command in its `source` column withheld.
#[test]
fn the_documented_log_example_answers_as_the_readme_says() {
    let trials = repo().join("dataset/trials/example-logs.csv");
    let d = diagnose(trials.to_str().expect("utf-8"), &LOOK_ALIKES);
    assert_eq!(
        d["answer"]["explanation"], "hip_coulomb_friction",
        "{}",
        d["answer"]
    );
}

/// Another engine, a hip loss added in it: Drake-Lagged's Mugatu with hip Coulomb friction
/// 0.05 N·m or viscous damping 0.02 N·m·s/rad, diagnosed through Drake's own no-effect
/// trials with their logs (`tests/golden/drake/gap-lagged-logs/`, its README), summaries at
/// 3 % sd: the effect Drake added is the most probable explanation, its value within 15 % of
/// Drake's; on the no-effect trials through themselves, nothing is blamed.
#[test]
fn through_drakes_no_effect_trials_the_cycles_name_the_hip_loss_drake_added() {
    let dir = repo().join("tests/golden/drake/gap-lagged-logs");
    let run = |file: &str| {
        diagnose(
            dir.join(file).to_str().expect("utf-8"),
            &[
                "--reference",
                dir.join("trials-none.csv").to_str().expect("utf-8"),
                "--effects",
                "hip_viscous_damping,hip_coulomb_friction,soft_ground",
                "--no-calibration",
                "--no-undeclared",
                "--default-sd",
                "0.03",
            ],
        )
    };
    for (file, truth, value) in [
        (
            "trials-hip_coulomb_friction-0.05.csv",
            "hip_coulomb_friction",
            0.05,
        ),
        (
            "trials-hip_viscous_damping-0.02.csv",
            "hip_viscous_damping",
            0.02,
        ),
    ] {
        let d = run(file);
        assert!(d["logged_trials"].as_u64().expect("logged") >= 3, "{file}");
        let top = &d["explanations"][0];
        assert_eq!(
            top["explanation"], truth,
            "{file}: {}",
            d["answer"]["statement"]
        );
        let v = top["knobs"][0]["value"].as_f64().expect("value");
        assert!(
            (v / value - 1.0).abs() < 0.15,
            "{file}: {v} vs Drake's {value}"
        );
    }
    let none = run("trials-none.csv");
    assert_eq!(
        none["answer"]["kind"], "no_gap",
        "{}",
        none["answer"]["statement"]
    );
}

/// `survey gap suggest` between hip losses on `trials`, three trials, written to `next`.
fn suggest(trials: &str, next: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "gap",
        "suggest",
        "--trials",
        trials,
        "--effects",
        "hip_coulomb_friction,hip_viscous_damping",
        "--budget",
        "3",
        "--out",
        next.to_str().expect("utf-8"),
    ];
    args.extend_from_slice(extra);
    survey(&args)
}

/// `survey gap suggest`: every suggested condition lies in the pool's ranges (drive
/// 0.85–1.15× the design's at the robot's size, amplitude 0.8–1.2×, payload 0–30 %, slope
/// ±2°) at the robot's own leg length; the expected entropy falls with each trial added and
/// the first beats one trial at the design's own drive; the robot that made the trials (hip
/// Coulomb friction 0.006 N·m, the leading explanation) walks forward on each, as the pool
/// requires of every leading explanation; two runs print the same bytes.
#[test]
fn suggest_stays_in_range_lowers_the_entropy_and_is_deterministic() {
    let dir = scratch();
    let trials = synth(dir.path(), "s", &["hip_coulomb_friction=0.006"], 3);
    let next = dir.path().join("next.csv");
    let run = || {
        let o = suggest(&trials, &next, &["--format", "json"]);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let first = run();
    assert_eq!(first, run(), "same trials, same suggestion");
    let v: serde_json::Value = serde_json::from_str(&first).expect("json");
    let s = v["suggested"].as_array().expect("suggested");
    assert_eq!(s.len(), 3);
    for x in s {
        assert_eq!(x["leg_length_m"].as_f64(), Some(0.153));
        let f = x["frequency_hz"].as_f64().expect("f") / 1.24;
        assert!((0.85 - 1e-9..=1.15 + 1e-9).contains(&f), "{x}");
        let a = x["amplitude_deg"].as_f64().expect("a") / 25.0;
        assert!((0.8 - 1e-9..=1.2 + 1e-9).contains(&a), "{x}");
        let m = x["mass_kg"].as_f64().expect("m") / 0.9;
        assert!((1.0 - 1e-9..=1.3 + 1e-9).contains(&m), "{x}");
        assert!(x["slope_deg"].as_f64().expect("slope").abs() <= 2.0);
    }
    let h = |x: &serde_json::Value| x["expected_entropy"].as_f64().expect("entropy");
    let now = v["entropy_now"].as_f64().expect("now");
    // Once a trial settles the question the expected entropy is zero up to the sampler's
    // rounding (1e-14 against 8e-14 nats): "falls" allows a micro-nat of it.
    const ROUNDING_NATS: f64 = 1e-6;
    assert!(
        h(&s[0]) <= now
            && h(&s[1]) <= h(&s[0]) + ROUNDING_NATS
            && h(&s[2]) <= h(&s[1]) + ROUNDING_NATS,
        "{v}"
    );
    assert!(h(&s[0]) <= v["default_entropy"].as_f64().expect("default"));
    let csv = std::fs::read_to_string(&next).expect("next.csv");
    assert!(csv.lines().count() == 4 && csv.contains("next-1,mugatu-two-uncertain.toml,0.153"));
    let walked = dir.path().join("walked.csv");
    let o = survey(&[
        "gap",
        "synth",
        "--conditions",
        next.to_str().expect("utf-8"),
        "--effect",
        "hip_coulomb_friction=0.006",
        "--noise",
        "0",
        "--out",
        walked.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let speeds: Vec<f64> = TrialSet::read(&walked)
        .expect("walked.csv")
        .trials
        .iter()
        .map(|t| t.measured(Metric::VelocityMps).expect("speed").value)
        .collect();
    // The design's walking criterion: 0.1·√(gL) = 0.1225 m/s at 0.153 m.
    assert!(speeds.iter().all(|v| *v > 0.1225), "{speeds:?}");
}

/// Where no explanation walks forward there is nothing to suggest: with the test design's
/// walking threshold raised to 5·√(gL) after the trials were made, `suggest` says so,
/// succeeds, and writes no file.
#[test]
fn suggest_offers_nothing_where_no_model_walks_forward() {
    let dir = scratch();
    let trials = synth(dir.path(), "s", &["hip_coulomb_friction=0.006"], 3);
    let design = dir.path().join("mugatu-two-uncertain.toml");
    let text = std::fs::read_to_string(&design).expect("design");
    let raised = text.replace(
        "walk_speed_threshold_over_sqrt_gl = 0.1 ",
        "walk_speed_threshold_over_sqrt_gl = 5.0 ",
    );
    assert_ne!(raised, text);
    std::fs::write(&design, raised).expect("write design");
    let next = dir.path().join("next.csv");
    let o = suggest(&trials, &next, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("0 of 189 pool conditions offered"), "{out}");
    assert!(!next.exists() && stderr(&o).contains("nothing written"));
}
