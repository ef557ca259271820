//! Speed in the survey: `survey fit --y speed`, `survey test slope --y speed`, the speed in
//! `survey predict`, the speed report, and the release rule for speeds of unstated kind.
//!
//! The hand-made table: four quadrupeds at leg lengths 0.005, 0.05, 0.5 and 5 m (log10 L =
//! x, equally spaced by one decade) with top speeds v = 10^(0.3 + 0.5 x + e), e = +0.1,
//! −0.1, −0.1, +0.1. The residual pattern is orthogonal to x, so the OLS line is exactly
//! log10 v = 0.3 + 0.5 x, with SSE = 0.04, s² = 0.02, Sxx = 5, se(b) = √(0.02/5), R² =
//! 1.25/1.29 — worked by hand here. The slope tests' p-values are smatr's `slope.test` on
//! the same numbers (tests/golden/speed_slope.py, its R command speed_slope.R).

use std::path::Path;

use serde_json::Value;

use crate::common;

const LEGS: [f64; 4] = [0.005, 0.05, 0.5, 5.0];
const RESIDUALS: [f64; 4] = [0.1, -0.1, -0.1, 0.1];
/// qt(0.975, 2), R.
const T_975_2DF: f64 = 4.30265272974946;
const G: f64 = 9.80665;

fn speed_of(l: f64, e: f64) -> f64 {
    10f64.powf(0.3 + 0.5 * l.log10() + e)
}

fn record(i: usize, l: f64, e: f64) -> String {
    format!(
        r#"id = "hand-quad-{i}"
name = "Hand Quad {i}"
class = "quadruped"
fit = true

[[sources]]
key = "s"
kind = "paper"
url = "https://example.org/hand-quad"

[values]
leg_length_m = {{ value = {l:?}, source = "s" }}
body_length_m = {{ value = {:?}, source = "s" }}
mass_kg = {{ value = {:?}, source = "s" }}
speed_top_mps = {{ value = {:?}, source = "s", gait = "trot" }}
"#,
        2.0 * l,
        20.0 * l * l,
        speed_of(l, e)
    )
}

/// A scratch dataset holding the hand-made table (and the repository's scaling laws, whose
/// velocity exponents are the hypotheses tested).
fn hand_table() -> tempfile::TempDir {
    let dir = common::scratch_dataset(&[]);
    std::fs::create_dir_all(dir.path().join("laws")).expect("laws dir");
    std::fs::copy(
        common::repo().join("dataset/laws/table1.toml"),
        dir.path().join("laws/table1.toml"),
    )
    .expect("copy laws");
    for (i, (l, e)) in LEGS.iter().zip(RESIDUALS).enumerate() {
        std::fs::write(
            dir.path().join(format!("robots/hand-quad-{i}.toml")),
            record(i, *l, e),
        )
        .expect("write record");
    }
    dir
}

fn json(args: &[&str]) -> Value {
    let out = common::survey(args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{args:?}: {}",
        common::stderr(&out)
    );
    serde_json::from_str(&common::stdout(&out)).expect("json")
}

fn d(dir: &Path) -> String {
    dir.display().to_string()
}

#[track_caller]
fn close(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol * want.abs().max(1e-300),
        "{what}: {got:.15e} vs {want:.15e}"
    );
}

fn group<'a>(v: &'a Value, class: &str) -> &'a Value {
    v["groups"]
        .as_array()
        .expect("groups")
        .iter()
        .find(|g| g["class"] == class)
        .unwrap_or_else(|| panic!("no group {class}"))
}

/// The p-value of the test of exponent `b0` among a list of hypothesis tests.
fn p_of(tests: &Value, b0: f64) -> &Value {
    tests
        .as_array()
        .expect("tests")
        .iter()
        .find(|t| t["hypothesis"]["b"].as_f64() == Some(b0))
        .unwrap_or_else(|| panic!("no test of b = {b0}"))
}

#[test]
fn speed_fit_recovers_the_hand_made_exponent_interval_and_froude_numbers() {
    let data = hand_table();
    let v = json(&[
        "fit",
        "--dataset",
        &d(data.path()),
        "--y",
        "speed",
        "--format",
        "json",
    ]);
    assert_eq!(v["y"], "speed_top");
    let q = group(&v, "quadruped");
    assert_eq!(q["n"], 4);
    let fit = &q["fit"];
    close(fit["b"].as_f64().unwrap(), 0.5, 1e-12, "b");
    close(fit["a"].as_f64().unwrap(), 10f64.powf(0.3), 1e-12, "A");
    let half = T_975_2DF * (0.02f64 / 5.0).sqrt();
    close(fit["b_ci"][0].as_f64().unwrap(), 0.5 - half, 1e-9, "CI low");
    close(
        fit["b_ci"][1].as_f64().unwrap(),
        0.5 + half,
        1e-9,
        "CI high",
    );
    close(fit["r2"].as_f64().unwrap(), 1.25 / 1.29, 1e-12, "R²");
    // smatr slope.test, OLS (tests/golden/speed_slope.py): b0 = 0.5 fits exactly.
    let tests = &q["tests"];
    close(
        p_of(tests, 0.5)["test"]["p_value"].as_f64().unwrap(),
        1.0,
        1e-12,
        "p(0.5)",
    );
    close(
        p_of(tests, 0.25)["test"]["p_value"].as_f64().unwrap(),
        0.0584455285566132,
        1e-9,
        "p(0.25)",
    );
    close(
        p_of(tests, 0.0)["test"]["p_value"].as_f64().unwrap(),
        0.0156259613023028,
        1e-9,
        "p(0)",
    );
    assert_eq!(p_of(tests, 0.0)["rejected"], true);
    assert_eq!(p_of(tests, 0.25)["rejected"], false);
    // Froude numbers v²/(gL), computed here.
    let mut fr: Vec<f64> = LEGS
        .iter()
        .zip(RESIDUALS)
        .map(|(l, e)| speed_of(*l, e).powi(2) / (G * l))
        .collect();
    fr.sort_by(f64::total_cmp);
    let f = &q["froude"];
    close(
        f["median"].as_f64().unwrap(),
        (fr[1] + fr[2]) / 2.0,
        1e-12,
        "Froude median",
    );
    close(f["min"].as_f64().unwrap(), fr[0], 1e-12, "Froude min");
    close(f["max"].as_f64().unwrap(), fr[3], 1e-12, "Froude max");
    assert_eq!(f["above_1"], fr.iter().filter(|x| **x > 1.0).count());
    // Classes without speeds are reported, not fitted.
    let h = group(&v, "hexapod");
    assert_eq!(h["n"], 0);
    assert!(h["fit"].is_null());
    assert!(h["not_fitted"].as_str().unwrap().contains("a fit needs 3"));
}

#[test]
fn speed_slope_tests_match_smatr_for_ols_sma_and_ma() {
    let data = hand_table();
    // (method, b0, smatr's r, p): tests/golden/speed_slope.py (smatr slope.test formulas).
    let cases = [
        ("ols", 0.25, 0.941554471443387, 0.0584455285566132),
        ("ols", 0.0, 0.984374038697697, 0.0156259613023028),
        ("sma", 0.5, 0.0890870806374748, 0.910912919362525),
        ("sma", 0.25, 0.974819883292282, 0.0251801167077178),
        ("ma", 0.5, 0.035754212261929, 0.964245787738071),
        ("ma", 0.25, 0.948062716751543, 0.0519372832484566),
        ("ma", 0.0, 0.984374038697697, 0.0156259613023028),
    ];
    let dataset = d(data.path());
    // `survey test slope` of the quadrupeds' speeds, as JSON, with `extra` flags.
    let slope = |extra: &[&str]| {
        let mut args = vec![
            "test",
            "slope",
            "--dataset",
            &dataset,
            "--class",
            "quadruped",
            "--y",
            "speed",
            "--format",
            "json",
        ];
        args.extend_from_slice(extra);
        json(&args)
    };
    for method in ["ols", "sma", "ma"] {
        let v = slope(&["--method", method]);
        assert_eq!(v["y"], "speed_top");
        // The laws' exponents by default: 0.5 (dynamic similarity), 0.25 (biology), 0.
        let b0s: Vec<f64> = v["tests"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["hypothesis"]["b"].as_f64().unwrap())
            .collect();
        assert_eq!(b0s, vec![0.5, 0.25, 0.0], "{method}");
        for (m, b0, r, p) in cases.iter().filter(|c| c.0 == method) {
            let t = &p_of(&v["tests"], *b0)["test"];
            close(
                t["test_correlation"].as_f64().unwrap().abs(),
                *r,
                1e-9,
                &format!("{m} r({b0})"),
            );
            close(
                t["p_value"].as_f64().unwrap(),
                *p,
                1e-8,
                &format!("{m} p({b0})"),
            );
        }
    }
    // An explicit exponent replaces the laws'.
    let v = slope(&["--value", "0.25"]);
    assert_eq!(v["tests"].as_array().unwrap().len(), 1);
}

#[test]
fn predict_gives_the_speed_with_its_prediction_interval_and_froude_number() {
    let data = hand_table();
    let l0: f64 = 0.5;
    let v = json(&[
        "predict",
        "--dataset",
        &d(data.path()),
        "--class",
        "quadruped",
        "--leg-length",
        "0.5",
        "--format",
        "json",
    ]);
    let q = v["quantities"]
        .as_array()
        .unwrap()
        .iter()
        .find(|q| q["quantity"] == "speed_top")
        .expect("a speed among the quantities");
    assert_eq!(q["unit"], "m/s");
    // By hand: the OLS line, and its prediction interval t·s·√(1 + 1/n + (x0 − x̄)²/Sxx).
    let x: Vec<f64> = LEGS.iter().map(|l| l.log10()).collect();
    let xbar = x.iter().sum::<f64>() / 4.0;
    let x0 = l0.log10();
    let median = 10f64.powf(0.3 + 0.5 * x0);
    let half = T_975_2DF * 0.02f64.sqrt() * (1.0 + 0.25 + (x0 - xbar).powi(2) / 5.0).sqrt();
    close(q["median"].as_f64().unwrap(), median, 1e-12, "median");
    close(
        q["prediction_interval"][0].as_f64().unwrap(),
        median / 10f64.powf(half),
        1e-9,
        "PI low",
    );
    close(
        q["prediction_interval"][1].as_f64().unwrap(),
        median * 10f64.powf(half),
        1e-9,
        "PI high",
    );
    close(
        v["froude"]["median"].as_f64().unwrap(),
        median * median / (G * l0),
        1e-12,
        "Fr",
    );
    assert_eq!(v["speed_kind"], "top");
    assert!(v["speed_unavailable"].is_null());

    // A kind no robot has: no speed, and the reason.
    let w = json(&[
        "predict",
        "--dataset",
        &d(data.path()),
        "--class",
        "quadruped",
        "--leg-length",
        "0.5",
        "--speed-kind",
        "walking",
        "--format",
        "json",
    ]);
    assert!(
        !w["quantities"]
            .as_array()
            .unwrap()
            .iter()
            .any(|q| q["quantity"] == "speed_walking")
    );
    assert!(
        w["speed_unavailable"]
            .as_str()
            .unwrap()
            .contains("walking speed")
    );
}

#[test]
fn speed_report_and_figure_are_written() {
    let data = hand_table();
    let out_dir = tempfile::tempdir().expect("tempdir");
    let out = common::survey(&[
        "fit",
        "--dataset",
        &d(data.path()),
        "--y",
        "speed",
        "--out",
        &d(out_dir.path()),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let md = std::fs::read_to_string(out_dir.path().join("speed.md")).expect("speed.md");
    // Four quadrupeds with a top speed, each citing a paper (primary).
    assert!(md.contains("| quadruped | 4 (4) | 0 (0) |"), "{md}");
    assert!(
        md.contains("4 fitted robots carry a speed of stated kind, 4 of them"),
        "{md}"
    );
    assert!(
        md.contains("quadruped (n = 4): b = 0.50 [0.23, 0.77]"),
        "{md}"
    );
    let svg = std::fs::read_to_string(out_dir.path().join("speed-froude.svg")).expect("svg");
    assert!(svg.contains("Froude number"), "figure title");
    assert!(out_dir.path().join("speed-froude.png").is_file());
    let rep: Value = serde_json::from_str(
        &std::fs::read_to_string(out_dir.path().join("speed.json")).expect("json"),
    )
    .expect("json");
    assert_eq!(rep["robots_with_stated_speed"], 4);
    assert!(
        rep["paper"].is_null(),
        "a dataset without release 1.0.0 has no paper fit"
    );
}

/// The paper's speeds (release 1.0.0, of unstated kind) still load and fit.
#[test]
fn old_releases_fit_their_speeds_of_unstated_kind() {
    let v = json(&[
        "fit",
        "--release",
        "1.0.0",
        "--y",
        "speed",
        "--speed-kind",
        "unstated",
        "--format",
        "json",
    ]);
    assert_eq!(v["y"], "speed_unstated");
    // 41 fitted robots of 1.0.0 give a speed (the survey's normal_speed column).
    assert_eq!(group(&v, "all")["n"], 41);
    let top = json(&[
        "fit",
        "--release",
        "1.0.0",
        "--y",
        "speed",
        "--format",
        "json",
    ]);
    assert_eq!(group(&top, "all")["n"], 0, "no top speeds before 1.5.0");
}

/// A speed of unstated kind is a warning in the live records, an error when a release is
/// cut and in the rows of a release from 1.5.0 (not in older ones, frozen before the rule).
#[test]
fn a_speed_of_unstated_kind_blocks_a_release() {
    let dir = common::dataset_copy();
    let p = dir.path();
    std::fs::write(
        p.join("robots/unstated-speed-quad.toml"),
        r#"id = "unstated-speed-quad"
name = "Unstated Speed Quad"
class = "quadruped"
fit = true

[[sources]]
key = "s"
kind = "paper"
url = "https://example.org/unstated"

[values]
leg_length_m = { value = 0.3, source = "s" }
body_length_m = { value = 0.6, source = "s" }
mass_kg = { value = 12.0, source = "s" }
speed_normal_mps = { value = 1.2, source = "s" }
"#,
    )
    .expect("record");
    let meta = p.join("dataset.toml");
    let text = std::fs::read_to_string(&meta).expect("meta");
    let line = text
        .lines()
        .find(|l| l.starts_with("version = "))
        .unwrap()
        .to_string();
    std::fs::write(&meta, text.replace(&line, "version = \"900.0.0\"")).expect("bump");
    let log = p.join("CHANGELOG.md");
    let mut cl = std::fs::read_to_string(&log).expect("changelog");
    cl.push_str("\n## 900.0.0\n\nA release cut by tests/it/speed.rs.\n");
    std::fs::write(&log, cl).expect("changelog");
    let ds = d(p);
    let out = common::survey(&["dataset", "package", "--dataset", &ds]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));

    let live = common::survey(&["validate", "--dataset", &ds]);
    assert_eq!(
        live.status.code(),
        Some(0),
        "a warning only: {}",
        common::stdout(&live)
    );
    assert!(common::stdout(&live).contains("[speed-kind]"));

    let out = common::survey(&[
        "dataset",
        "release",
        "900.0.0",
        "--dataset",
        &ds,
        "--note",
        "t",
    ]);
    assert_ne!(out.status.code(), Some(0), "the release must be refused");
    assert!(
        common::stderr(&out).contains("unstated kind"),
        "{}",
        common::stderr(&out)
    );
    assert!(!p.join("releases/900.0.0").exists(), "nothing half-written");

    let out = common::survey(&[
        "dataset",
        "release",
        "900.0.0",
        "--dataset",
        &ds,
        "--note",
        "t",
        "--allow-errors",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let rows = |version: &str| -> Vec<Value> {
        let out = common::survey(&[
            "validate",
            "--dataset",
            &ds,
            "--release",
            version,
            "--rows",
            "--format",
            "json",
        ]);
        let v: Value = serde_json::from_str(&common::stdout(&out)).expect("json");
        v.as_array()
            .expect("list")
            .iter()
            .filter(|p| p["rule"] == "speed-kind")
            .cloned()
            .collect()
    };
    let new = rows("900.0.0");
    assert_eq!(new.len(), 1, "{new:?}");
    assert_eq!(new[0]["severity"], "error");
    assert_eq!(new[0]["robot"], "unstated-speed-quad");
    let old = rows("1.0.0");
    assert!(!old.is_empty() && old.iter().all(|p| p["severity"] == "warning"));
}
