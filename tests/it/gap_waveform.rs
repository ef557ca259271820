//! Waveform evidence (`survey gap separate`, `survey gap synth --logs`), run through the real
//! binary on the six test conditions (`tests/data/gap/conditions-6.csv`): look-alike effects
//! the summaries cannot tell apart and the logged cycles can; a truth outside the candidates
//! named by neither; robot logs with only the columns a robot records; clear errors.

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

/// `survey gap synth` on the six conditions with logs and the effects `truth`
/// (NAME=VALUE); returns the trials path.
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

/// `survey gap suggest` between hip Coulomb friction and viscous damping on `trials`, three
/// trials, written to `next`; `extra` arguments after those.
fn suggest(trials: &str, next: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "gap",
        "suggest",
        "--trials",
        trials,
        "--candidates",
        "hip_coulomb_friction,hip_viscous_damping",
        "--budget",
        "3",
        "--out",
        next.to_str().expect("utf-8"),
    ];
    args.extend_from_slice(extra);
    survey(&args)
}

/// The verdict kinds of `survey gap separate --format json`: (summaries, with waveforms),
/// each as (kind, named knob or group).
fn separate(trials: &str, candidates: &str) -> Vec<(String, String, serde_json::Value)> {
    let o = survey(&[
        "gap",
        "separate",
        "--trials",
        trials,
        "--candidates",
        candidates,
        "--grid",
        "5",
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    v["rankings"]
        .as_array()
        .expect("rankings")
        .iter()
        .map(|r| {
            (
                r["evidence"].as_str().unwrap_or("").to_string(),
                r["verdict"]["kind"].as_str().unwrap_or("").to_string(),
                r["verdict"].clone(),
            )
        })
        .collect()
}

/// Hip Coulomb friction of 0.009 N·m (below the summaries' identification distance from
/// viscous damping on six conditions): on the summaries the two fit alike ("cannot tell");
/// the hip-torque cycle shows the constant-magnitude friction torque reversing with the
/// swing, which a rate-proportional damping cannot draw, and the waveforms name Coulomb.
#[test]
fn waveforms_tell_coulomb_from_damping_where_the_summaries_cannot() {
    let dir = scratch();
    let trials = synth(dir.path(), "coulomb", &["hip_coulomb_friction=0.009"], 1);
    let r = separate(&trials, "hip_coulomb_friction,hip_viscous_damping");
    assert_eq!(r.len(), 2, "{r:?}");
    assert_eq!(r[0].0, "summaries");
    assert_eq!(r[0].1, "cannot_tell", "{r:?}");
    assert_eq!(r[1].0, "summaries_and_waveforms");
    assert_eq!(r[1].1, "named", "{r:?}");
    assert_eq!(r[1].2["knob"], "hip_coulomb_friction");
}

/// The truth is outside the candidates: hip backlash of 8° (far beyond noise), candidates
/// Coulomb friction and damping. Neither evidence may name one: the best of two wrong
/// candidates does not fit within noise.
#[test]
fn separate_names_nothing_when_the_truth_is_outside_the_candidates() {
    let dir = scratch();
    let trials = synth(dir.path(), "backlash", &["hip_backlash=8"], 2);
    let r = separate(&trials, "hip_coulomb_friction,hip_viscous_damping");
    for (evidence, kind, v) in &r {
        assert!(
            kind == "none_fits" || kind == "cannot_tell",
            "{evidence}: {v} — a wrong candidate was named"
        );
    }
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
    // Only the log folder's name differs.
    assert_eq!(text_a.replace("a-logs", "b-logs"), text_b);
    let first_log = dir.path().join("a-logs/L1x-f0.97x.csv");
    let log = std::fs::read_to_string(&first_log).expect("log");
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

/// A robot's log with a bad cell: the error names the log's file, line and column; a
/// trials file naming a robot log (no hip position or contact forces) still diagnoses.
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
    let o = survey(&[
        "gap",
        "separate",
        "--trials",
        &trials,
        "--candidates",
        "hip_coulomb_friction,hip_viscous_damping",
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("L1x-f1x.csv:6:3:") && e.contains("`north` is not a number"),
        "{e}"
    );
    // Fewer than two candidates, an unknown one: clear errors (the log mended first).
    std::fs::write(&log, &text).expect("restore");
    let o = survey(&[
        "gap",
        "separate",
        "--trials",
        &trials,
        "--candidates",
        "hip_coulomb_friction",
    ]);
    assert!(stderr(&o).contains("at least two"), "{}", stderr(&o));
    let o = survey(&[
        "gap",
        "separate",
        "--trials",
        &trials,
        "--candidates",
        "hip_coulomb_friction,gremlins",
    ]);
    assert!(
        stderr(&o).contains("\"gremlins\"") && stderr(&o).contains("hip_viscous_damping"),
        "{}",
        stderr(&o)
    );
}

/// `survey gap suggest`: every suggested condition lies in the pool's ranges (drive
/// 0.85–1.15× the design's at the robot's size, amplitude 0.8–1.2×, payload 0–30 %, slope
/// ±2°) at the robot's own leg length, the nominal walks forward there, the first separates
/// the two candidates better than the design's own drive, and two runs print the same bytes.
#[test]
fn suggest_stays_in_range_beats_the_default_and_is_deterministic() {
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
    // The test design at 0.153 m: drive 1.24 Hz, amplitude 25°, mass 0.9 kg.
    let total = |x: &serde_json::Value| {
        x["separation_summaries"].as_f64().unwrap_or(0.0)
            + x["separation_waveforms"].as_f64().unwrap_or(0.0)
    };
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
    assert!(total(&s[0]) >= total(&s[1]) && total(&s[1]) >= total(&s[2]));
    assert!(
        total(&s[0]) > total(&v["default_condition"]),
        "the best suggestion separates better than the design's own drive"
    );
    let csv = std::fs::read_to_string(&next).expect("next.csv");
    assert!(csv.lines().count() == 4 && csv.contains("next-1,mugatu-two-uncertain.toml,0.153"));
    // The nominal model walks forward on every suggestion: walked again by `gap synth`
    // (noise-free), its speed beats the design's criterion 0.1·√(gL) = 0.1225 m/s at 0.153 m.
    let walked = dir.path().join("walked.csv");
    let o = survey(&[
        "gap",
        "synth",
        "--conditions",
        next.to_str().expect("utf-8"),
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
    assert_eq!(speeds.len(), 3);
    assert!(speeds.iter().all(|v| *v > 0.1225), "{speeds:?}");
}

/// Where no model walks forward there is nothing to suggest: with the test design's walking
/// threshold raised to 5·√(gL) (a Froude number of 25, beyond any walker) after the trials
/// were made, `suggest` says so, succeeds, and writes no file.
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
    assert!(
        out.contains("0 where the nominal and both walk forward")
            && out.contains("No condition of the pool qualifies"),
        "{out}"
    );
    assert!(!next.exists() && stderr(&o).contains("nothing written"));
}

/// The documented example (`dataset/trials/example-logs.csv`, dataset/trials/README.md):
/// two trials, the summaries cannot tell Coulomb friction from damping, the cycles name
/// Coulomb (the truth the synth command in its `source` column withheld).
#[test]
fn the_documented_log_example_answers_as_the_readme_says() {
    let trials = repo().join("dataset/trials/example-logs.csv");
    let r = separate(
        trials.to_str().expect("utf-8"),
        "hip_coulomb_friction,hip_viscous_damping",
    );
    assert_eq!(r[0].1, "cannot_tell", "{r:?}");
    assert_eq!(r[1].1, "named", "{r:?}");
    assert_eq!(r[1].2["knob"], "hip_coulomb_friction");
}

/// `survey gap diagnose` on trials with logs: the summaries leave Coulomb friction and damping
/// as a look-alike group (answer "ambiguous", nothing named); the diagnosis then separates the
/// group with the logged cycles and says which one the cycles name (the truth).
#[test]
fn diagnose_separates_its_look_alike_group_with_the_logs() {
    let dir = scratch();
    let trials = synth(dir.path(), "d", &["hip_coulomb_friction=0.009"], 1);
    let o = survey(&["gap", "diagnose", "--trials", &trials]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("**Answer (ambiguous):**"), "{text}");
    let follow = text
        .split("## The look-alike group, with the logged cycles")
        .nth(1)
        .expect("a follow-up section");
    let waveforms = follow
        .split("### summaries + waveforms")
        .nth(1)
        .expect("the waveform ranking");
    assert!(
        waveforms.contains("Answer: **hip_coulomb_friction**: it fits within noise"),
        "{follow}"
    );
}

/// Another engine's data, no effect added: four Drake walks of the reference Mugatu
/// (`tests/data/gap/drake-walks.csv`, the golden trajectories). The gap there is the
/// engines' friction model (reports/drake-crosscheck.md), a cause in no library; so for
/// the look-alike pairs neither the summaries nor the cycles may name a candidate.
#[test]
fn separate_names_nothing_on_drake_walks_without_an_added_effect() {
    let trials = repo().join("tests/data/gap/drake-walks.csv");
    for pair in [
        "hip_coulomb_friction,hip_viscous_damping",
        "actuation_latency,hip_backlash",
    ] {
        let r = separate(trials.to_str().expect("utf-8"), pair);
        assert_eq!(
            r.len(),
            2,
            "{pair}: both rankings (the trajectories are logs)"
        );
        for (evidence, kind, v) in &r {
            assert_ne!(
                kind, "named",
                "{pair}, {evidence}: {v} named on Drake's data"
            );
        }
    }
}
