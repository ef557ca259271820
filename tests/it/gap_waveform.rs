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
    synth_robot(dir, name, truth, &[], seed)
}

/// [`synth`] of a robot that differs from its design file at `set` (PATH=VALUE each).
fn synth_robot(dir: &Path, name: &str, truth: &[&str], set: &[&str], seed: u64) -> String {
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
    for p in set {
        args.push("--set");
        args.push(p);
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

/// The rankings of `survey gap separate --format json` (default grid), through `reference`
/// when given.
fn separate_rankings(
    trials: &str,
    candidates: &str,
    reference: Option<&str>,
) -> Vec<serde_json::Value> {
    let mut args = vec![
        "gap",
        "separate",
        "--trials",
        trials,
        "--candidates",
        candidates,
        "--format",
        "json",
    ];
    if let Some(r) = reference {
        args.extend_from_slice(&["--reference", r]);
    }
    let o = survey(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("json");
    v["rankings"].as_array().expect("rankings").clone()
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

/// `survey gap separate --format json` on a Drake-Lagged file of
/// `tests/golden/drake/gap-lagged-logs/` through its no-effect trials, summaries at 3 % sd:
/// the two rankings as JSON (summaries; summaries + waveforms).
fn separate_drake_through_none(file: &str, candidates: &str) -> Vec<serde_json::Value> {
    separate_drake_in("gap-lagged-logs", file, candidates)
}

/// The same in another folder of `tests/golden/drake/`.
fn separate_drake_in(folder: &str, file: &str, candidates: &str) -> Vec<serde_json::Value> {
    let v = separate_drake_json(folder, file, candidates);
    assert_eq!(v["trials_with_logs"], 3, "the three 1x trials have logs");
    v["rankings"].as_array().expect("rankings").clone()
}

/// `survey gap separate --format json` of `tests/golden/drake/<folder>/<file>` through the
/// folder's `trials-none.csv`, summaries at 3 % sd: the whole answer.
fn separate_drake_json(folder: &str, file: &str, candidates: &str) -> serde_json::Value {
    let dir = repo().join("tests/golden/drake").join(folder);
    let o = survey(&[
        "gap",
        "separate",
        "--trials",
        dir.join(file).to_str().expect("utf-8"),
        "--reference",
        dir.join("trials-none.csv").to_str().expect("utf-8"),
        "--candidates",
        candidates,
        "--default-sd",
        "0.03",
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&stdout(&o)).expect("json")
}

/// Another engine, a hip loss added in it: Drake-Lagged's Mugatu with hip Coulomb friction
/// 0.05 N·m, against the same Drake model without it (`tests/golden/drake/gap-lagged-logs/`,
/// its README). Drake's hip-torque cycle differs from the project's by 33 % of its RMS, so
/// the cycles fit only through the reference: there the engines' discrepancy cancels and
/// the change Drake's friction makes is the change ours makes (correlation 0.996). The
/// summaries alone do not name Coulomb friction (they name its look-alike, viscous damping,
/// at 0.015 N·m·s/rad); the cycles name it, at Drake's value within 10 %.
#[test]
fn the_cycles_through_drakes_no_effect_trials_name_the_friction_drake_added() {
    let r = separate_drake_through_none(
        "trials-hip_coulomb_friction-0.05.csv",
        "hip_viscous_damping,hip_coulomb_friction",
    );
    assert_eq!(r.len(), 2);
    assert_eq!(r[0]["evidence"], "summaries");
    assert_ne!(
        r[0]["verdict"]["knob"], "hip_coulomb_friction",
        "the summaries alone were not expected to tell the look-alikes apart: {}",
        r[0]["verdict"]
    );
    assert_eq!(r[1]["evidence"], "summaries_and_waveforms");
    assert_eq!(r[1]["verdict"]["kind"], "named", "{}", r[1]["verdict"]);
    assert_eq!(r[1]["verdict"]["knob"], "hip_coulomb_friction");
    let best = &r[1]["fits"][0];
    assert_eq!(best["knob"], "hip_coulomb_friction");
    let v = best["value"].as_f64().expect("value");
    assert!((0.045..=0.055).contains(&v), "fitted {v} N·m, Drake's 0.05");
}

/// The same with damping (0.006 N·m·s/rad, 1.8× the summaries' identification threshold):
/// the cycles name viscous damping at Drake's value within 10 %.
#[test]
fn the_cycles_through_drakes_no_effect_trials_name_the_damping_drake_added() {
    let r = separate_drake_through_none(
        "trials-hip_viscous_damping-0.006.csv",
        "hip_coulomb_friction,hip_viscous_damping",
    );
    assert_eq!(r[1]["verdict"]["kind"], "named", "{}", r[1]["verdict"]);
    assert_eq!(r[1]["verdict"]["knob"], "hip_viscous_damping");
    let v = r[1]["fits"][0]["value"].as_f64().expect("value");
    assert!((0.0054..=0.0066).contains(&v), "fitted {v}, Drake's 0.006");
}

/// Outside what the rule assumes: Drake lowered the foot–floor μ from 0.8 to 0.4, or made
/// the floor soft, a cause that is neither candidate. Through the reference, neither hip loss
/// may be named, on the summaries or with the cycles. The 30 MPa floor is where the
/// one-metric rule's leniency bites: both hip losses miss the carried summaries mostly in the
/// yaw swing (χ² 127 on 63 values), so both are plausible but for it, and the cycles cannot
/// tell them apart; the answer is "cannot tell" between two wrong candidates (before the rule:
/// "none fits"), never a name.
#[test]
fn the_cycles_through_drakes_no_effect_trials_name_no_hip_loss_for_a_floor_change() {
    for file in [
        "trials-friction_coefficient-0.4.csv",
        "trials-soft_ground-6e6.csv",
        "trials-soft_ground-3e7.csv",
    ] {
        let r = separate_drake_through_none(file, "hip_viscous_damping,hip_coulomb_friction");
        for ranking in &r {
            for kind in ["named", "named_together"] {
                assert_ne!(
                    ranking["verdict"]["kind"], kind,
                    "{file}, {}: {} named",
                    ranking["evidence"], ranking["verdict"]
                );
            }
        }
    }
}

/// `survey gap diagnose` of a Drake-Lagged file through Drake's no-effect trials, three
/// candidate effects, the design's parameters as they are, summaries at 3 % sd: the text,
/// whose last section says what the logged cycles added.
fn diagnose_drake_through_none(file: &str) -> String {
    diagnose_drake_in("gap-lagged-logs", file)
}

/// The same in another folder of `tests/golden/drake/`.
fn diagnose_drake_in(folder: &str, file: &str) -> String {
    let dir = repo().join("tests/golden/drake").join(folder);
    let o = survey(&[
        "gap",
        "diagnose",
        "--trials",
        dir.join(file).to_str().expect("utf-8"),
        "--reference",
        dir.join("trials-none.csv").to_str().expect("utf-8"),
        "--effects",
        "hip_viscous_damping,hip_coulomb_friction,soft_ground",
        "--no-calibration",
        "--no-audit-undeclared",
        "--default-sd",
        "0.03",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    stdout(&o)
}

/// An effect added in Drake, named on top of the engine difference: on Drake-Lagged's
/// summaries, carried through Drake's own no-effect trials, hip viscous damping and hip
/// Coulomb friction explain the change alike (the answer is "ambiguous", nothing named);
/// the diagnosis then separates the group with the logged cycles, carried through the
/// reference's, and names the effect Drake added — for either of the two.
#[test]
fn diagnose_through_drakes_no_effect_trials_names_the_hip_loss_drake_added_with_the_cycles() {
    for (file, truth) in [
        (
            "trials-hip_coulomb_friction-0.05.csv",
            "hip_coulomb_friction",
        ),
        ("trials-hip_viscous_damping-0.02.csv", "hip_viscous_damping"),
    ] {
        let text = diagnose_drake_through_none(file);
        assert!(text.contains("**Answer (ambiguous):**"), "{file}: {text}");
        assert!(
            text.contains(&format!("**With the logged cycles:** named {truth}.")),
            "{file}: {text}"
        );
    }
}

/// Outside what the cycles can name: Drake lowered the foot–floor μ (0.8 → 0.4), an effect
/// outside these candidates whose mark on Drake's gait our model does not share closely. The
/// summaries leave it unexplained; the cycles, looking at the best single knobs, name
/// nothing either.
#[test]
fn diagnose_through_drakes_no_effect_trials_names_nothing_for_a_cause_outside_the_candidates() {
    let text = diagnose_drake_through_none("trials-friction_coefficient-0.4.csv");
    assert!(
        text.contains("**With the logged cycles:** nothing named."),
        "{text}"
    );
}

/// Held out from the cycles' rules (`tests/golden/drake/gap-lagged-logs-heldout/`, made after
/// them): Drake's hip Coulomb friction at 0.08 N·m, beyond the magnitudes the rules were fixed
/// on. There Drake's friction changes the summaries unlike ours, and carried through the
/// no-effect trials they favour its look-alike, viscous damping (χ² 12.8 against 60.8 on 63
/// values, 43 of it on the yaw swing). Through a reference a rival that fits within noise
/// (or would but for one metric) is not told apart on the summaries, so they answer "cannot
/// tell" — before that rule they named viscous damping, here and in 5 of 5 noisy draws. The
/// cycles change as ours do, and summaries and cycles together name Coulomb friction at
/// Drake's value within 10 %.
#[test]
fn held_out_drakes_large_hip_friction_is_not_called_damping_and_the_cycles_name_it() {
    not_called_damping_and_named_by_the_cycles(
        "gap-lagged-logs-heldout",
        "trials-hip_coulomb_friction-0.08.csv",
        0.08,
    );
}

/// Drake's hip Coulomb friction of `drake_nm` in `folder`, separated from viscous damping
/// through the no-effect trials: the summaries alone answer "cannot tell" (not damping), the
/// summaries and cycles name Coulomb friction within 10 % of Drake's value.
fn not_called_damping_and_named_by_the_cycles(folder: &str, file: &str, drake_nm: f64) {
    let r = separate_drake_in(folder, file, "hip_viscous_damping,hip_coulomb_friction");
    assert_eq!(r[0]["evidence"], "summaries");
    assert_eq!(
        r[0]["verdict"]["kind"], "cannot_tell",
        "{file}: the summaries alone cannot tell the look-alikes apart here: {}",
        r[0]["verdict"]
    );
    assert_eq!(r[1]["evidence"], "summaries_and_waveforms");
    assert_eq!(
        r[1]["verdict"]["kind"], "named",
        "{file}: {}",
        r[1]["verdict"]
    );
    assert_eq!(r[1]["verdict"]["knob"], "hip_coulomb_friction", "{file}");
    let v = r[1]["fits"][0]["value"].as_f64().expect("value");
    assert!(
        (v - drake_nm).abs() <= 0.1 * drake_nm,
        "{file}: fitted {v} N·m, Drake's {drake_nm}"
    );
}

/// Held out from the one-metric rule (`tests/golden/drake/gap-lagged-logs-heldout2/`, made
/// after it): Drake's hip Coulomb friction at 0.12 N·m, beyond every magnitude seen. Carried
/// through Drake's no-effect trials the summaries favour viscous damping (χ² 28.9 against 133
/// on 63 values); they must not name it (a rival within noise but for one metric is not told
/// apart), and the cycles name Coulomb friction at Drake's value within 10 %.
#[test]
fn held_out_again_drakes_largest_hip_friction_is_not_called_damping() {
    not_called_damping_and_named_by_the_cycles(
        "gap-lagged-logs-heldout2",
        "trials-hip_coulomb_friction-0.12.csv",
        0.12,
    );
}

/// Outside what a single-knob rule assumes: Drake added both hip losses at once (viscous
/// damping 0.01 N·m·s/rad and Coulomb friction 0.03 N·m). Viscous damping alone explains the
/// carried summaries within noise (at 0.019, not the truth's 0.01), so the chain stops there
/// and the answer is the look-alike group. With the cycles the pair is fitted together
/// (`separate::check_pairs`): damping alone leaves the cycles at χ² 17.7, the pair at 4.3,
/// and both losses are named.
#[test]
fn held_out_two_hip_losses_at_once_are_named_together_by_the_cycles() {
    let text = diagnose_drake_in(
        "gap-lagged-logs-heldout",
        "trials-hip_viscous_damping-0.01+hip_coulomb_friction-0.03.csv",
    );
    assert!(text.contains("**Answer (ambiguous):**"), "{text}");
    assert!(
        text.contains(
            "**With the logged cycles:** named hip_viscous_damping, hip_coulomb_friction."
        ),
        "{text}"
    );
}

/// The pair rule on Drake files held out from it (`tests/golden/drake/gap-lagged-logs-heldout2/`,
/// made before it): both hip losses at once (damping 0.02 N·m·s/rad with Coulomb friction
/// 0.05 N·m), where damping alone fits the summaries and the cycles within noise (at 0.034)
/// and was named alone. The pair is named, each value within 25 % of Drake's (the two trade
/// off along one ridge of the profile), and the profile's range of Coulomb friction beside
/// damping holds Drake's 0.05 and excludes nothing-at-all. Each loss alone, the other is not
/// added beside it: the pair's fits say the second knob is not needed.
#[test]
fn held_out_two_hip_losses_are_named_together_and_one_loss_gets_no_partner() {
    let r = separate_drake_in(
        "gap-lagged-logs-heldout2",
        "trials-hip_viscous_damping-0.02+hip_coulomb_friction-0.05.csv",
        "hip_viscous_damping,hip_coulomb_friction",
    );
    let w = &r[1];
    assert_eq!(w["evidence"], "summaries_and_waveforms");
    assert_eq!(w["verdict"]["kind"], "named_together", "{}", w["verdict"]);
    let pair = &w["pairs"][0];
    assert_eq!(pair["knobs"][0], "hip_viscous_damping", "{pair}");
    assert_eq!(pair["knobs"][1], "hip_coulomb_friction", "{pair}");
    let (damping, friction) = (
        pair["values"][0].as_f64().expect("value"),
        pair["values"][1].as_f64().expect("value"),
    );
    assert!(
        (0.015..=0.025).contains(&damping),
        "damping {damping}, Drake's 0.02"
    );
    assert!(
        (0.0375..=0.0625).contains(&friction),
        "friction {friction}, Drake's 0.05"
    );
    let range = (
        pair["second_range"][0].as_f64().expect("low"),
        pair["second_range"][1].as_f64().expect("high"),
    );
    assert!(range.0 < 0.05 && 0.05 < range.1, "{range:?}");
    for (file, truth) in [
        (
            "trials-hip_viscous_damping-0.025.csv",
            "hip_viscous_damping",
        ),
        (
            "trials-hip_coulomb_friction-0.065.csv",
            "hip_coulomb_friction",
        ),
    ] {
        let r = separate_drake_in(
            "gap-lagged-logs-heldout2",
            file,
            "hip_viscous_damping,hip_coulomb_friction",
        );
        let w = &r[1];
        assert_eq!(w["verdict"]["kind"], "named", "{file}: {}", w["verdict"]);
        assert_eq!(w["verdict"]["knob"], truth, "{file}");
        let pair = &w["pairs"][0];
        assert_eq!(pair["passes"], false, "{file}: {pair}");
    }
}

/// Where the rule's premise fails: Drake-SAP's Mugatu (`tests/golden/drake/gap-sap-logs/`,
/// convex friction) walks where the project's Coulomb Mugatu scuffs, at every condition.
/// Carried through Drake-SAP's no-effect trials, a change would not be its mark on our model,
/// so the separation refuses ("not comparable": the model walks none of the reference's
/// gaits) instead of naming a hip loss. Before this check it named hip Coulomb friction for
/// Drake's added viscous damping, on the summaries and with the cycles.
#[test]
fn separate_through_a_reference_the_model_does_not_walk_like_is_not_comparable() {
    for file in [
        "trials-hip_viscous_damping-0.02.csv",
        "trials-hip_coulomb_friction-0.05.csv",
    ] {
        let v = separate_drake_json(
            "gap-sap-logs",
            file,
            "hip_viscous_damping,hip_coulomb_friction",
        );
        let rankings = v["rankings"].as_array().expect("rankings");
        assert_eq!(rankings.len(), 1, "{file}: {v}");
        assert_eq!(rankings[0]["verdict"]["kind"], "not_comparable", "{file}");
        let why = rankings[0]["verdict"]["why"].as_str().expect("why");
        assert!(why.contains("L1x-f1x: velocity_mps"), "{file}: {why}");
    }
}

/// The cycles through a reference where the model misses the robot: the robot's foot–floor
/// μ is 0.5, not the design's 0.35 (a number the test design does not declare). Reference:
/// the robot at 3 % noise with its logs; trials (another seed): the robot with hip Coulomb
/// friction 0.02 N·m, or hip viscous damping 0.006 N·m·s/rad, added. On the carried summaries
/// the two hip losses are look-alikes ("cannot tell"); the carried cycles name the one added,
/// each time.
#[test]
fn the_cycles_through_a_reference_name_the_hip_loss_where_the_model_misses_the_robot() {
    let dir = scratch();
    let reference = synth_robot(
        dir.path(),
        "reference",
        &[],
        &["contact.friction_mu=0.5"],
        11,
    );
    for (effect, truth) in [
        ("hip_coulomb_friction=0.02", "hip_coulomb_friction"),
        ("hip_viscous_damping=0.006", "hip_viscous_damping"),
    ] {
        let trials = synth_robot(
            dir.path(),
            truth,
            &[effect],
            &["contact.friction_mu=0.5"],
            12,
        );
        let r = separate_rankings(
            &trials,
            "hip_viscous_damping,hip_coulomb_friction",
            Some(&reference),
        );
        assert_eq!(r[0]["verdict"]["kind"], "cannot_tell", "{effect}: {}", r[0]);
        assert_eq!(r[1]["verdict"]["kind"], "named", "{effect}: {}", r[1]);
        assert_eq!(r[1]["verdict"]["knob"], truth);
    }
}

/// Through a reference, changes outside the candidates (hip viscous damping, hip Coulomb
/// friction) on our own trials: reference the nominal robot (seed 11), trials the robot with
/// the change (seed 12), both at 3 % with logs.
/// * An actuation latency of 4 ms moves only the peak hip torque beyond noise (χ² 287 on the
///   6 values; the cycles within noise). Leaving that one metric out, the summaries of a
///   candidate at its range end, that is the nominal, "fit": this once answered **no gap**
///   on the cycles — false, the robot changed. Now none fits, the rest in the peak torque.
/// * Hip Coulomb friction 0.02 N·m with a backlash of 10.5° (not offered): whatever the
///   cycles answer, it says that the carried summaries fit only with the peak hip torque left
///   out (where the backlash shows), and damping, in neither, is not named.
#[test]
fn through_a_reference_a_change_outside_the_candidates_is_a_gap_left_in_its_metric() {
    let dir = scratch();
    let reference = synth(dir.path(), "reference", &[], 11);
    let run = |trials: &str| {
        separate_rankings(
            trials,
            "hip_viscous_damping,hip_coulomb_friction",
            Some(&reference),
        )
    };
    let latency = synth(dir.path(), "latency", &["actuation_latency=0.004"], 12);
    for r in run(&latency) {
        assert_eq!(r["verdict"]["kind"], "none_fits", "{r}");
        let rest = r["verdict"]["rest_in"].as_str().unwrap_or("");
        assert!(rest.starts_with("peak_torque_nm"), "{r}");
    }
    let backlash = synth(
        dir.path(),
        "coulomb-backlash",
        &["hip_coulomb_friction=0.02", "hip_backlash=10.5"],
        12,
    );
    let r = run(&backlash);
    let cycles = &r[1];
    assert_eq!(cycles["evidence"], "summaries_and_waveforms", "{cycles}");
    assert_ne!(cycles["verdict"]["knob"], "hip_viscous_damping", "{cycles}");
    assert_eq!(
        cycles["summaries_left_out"]["metric"], "peak_torque_nm",
        "{cycles}"
    );
    assert_eq!(cycles["summaries_left_out"]["values"], 6, "{cycles}");
}

/// A declared parameter off and a hip loss at once, on the six conditions with logs (3 %
/// noise, seed 12): the test design's hip half-width 0.23 L (file 0.2) or an unreported 1.5°
/// slope, each with hip Coulomb friction 0.02 N·m. Candidates: the two hip losses and one
/// parameter. The best single knob (the parameter) fitted with each hip loss: both pairs fit
/// within noise and need both knobs, so "the only passing pair" named none. The pair with
/// Coulomb friction fits the cycles at χ² 10–15 and the one with damping at 55–87, beyond the
/// test by the best pair's own over-dispersion: the truth is named, within 5 % of its
/// values. Outside the premise (the parameter offered is not the one that is off), no pair
/// passes and nothing is named.
#[test]
fn of_two_passing_pairs_the_one_the_cycles_prefer_beyond_the_test_is_named() {
    let dir = scratch();
    let trials = |name: &str, set: &str| {
        synth_robot(dir.path(), name, &["hip_coulomb_friction=0.02"], &[set], 12)
    };
    let width = "mugatu-two-uncertain:geometry.hip_half_width_over_l";
    let slope = "mugatu-two-uncertain:ground.slope_deg";
    let wide = trials("wide", "geometry.hip_half_width_over_l=0.23");
    let sloped = trials("sloped", "ground.slope_deg=1.5");
    let cycles = |trials: &str, parameter: &str| {
        let candidates = format!("hip_coulomb_friction,hip_viscous_damping,{parameter}");
        separate_rankings(trials, &candidates, None)[1].clone()
    };
    for (trials, parameter, truth) in [(&wide, width, 0.23), (&sloped, slope, 1.5)] {
        let r = cycles(trials, parameter);
        assert_eq!(r["verdict"]["kind"], "named_together", "{r}");
        let named: Vec<&str> = r["verdict"]["knobs"]
            .as_array()
            .expect("knobs")
            .iter()
            .filter_map(|k| k.as_str())
            .collect();
        assert_eq!(named, [parameter, "hip_coulomb_friction"], "{r}");
        let pairs = r["pairs"].as_array().expect("pairs");
        let named_pair = pairs.iter().find(|p| p["passes"] == true).expect("named");
        let values = named_pair["values"].as_array().expect("values");
        let (x, c) = (
            values[0].as_f64().unwrap_or(0.0),
            values[1].as_f64().unwrap_or(0.0),
        );
        assert!((x / truth - 1.0).abs() < 0.05, "{parameter} {x} vs {truth}");
        assert!((c / 0.02 - 1.0).abs() < 0.05, "Coulomb {c} vs 0.02");
        let damping = pairs
            .iter()
            .find(|p| p["knobs"][1] == "hip_viscous_damping")
            .expect("the damping pair");
        let why = damping["why_not"].as_str().unwrap_or("");
        assert!(why.contains("fits better beyond the test"), "{damping}");
    }
    // The parameter offered is not the one that is off: nothing named, no pair passes.
    for (trials, parameter) in [(&wide, slope), (&sloped, width)] {
        let r = cycles(trials, parameter);
        assert_ne!(r["verdict"]["kind"], "named_together", "{r}");
        assert_ne!(r["verdict"]["kind"], "named", "{r}");
        let pairs = r["pairs"].as_array().cloned().unwrap_or_default();
        assert!(pairs.iter().all(|p| p["passes"] == false), "{r}");
    }
}
