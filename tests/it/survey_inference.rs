//! `survey predict`, `survey test`, `survey laws` and `survey fit --explain` on frozen
//! release 1.0.0, run through the real binary.
//!
//! Expected numbers come from outside this code base:
//! - "R:" values were computed by `Rscript tests/golden/survey.R` (R 4.2.2: lm,
//!   predict.lm, confint, anova; smatr's own R functions copied into
//!   tests/golden/smatr_funcs.R) on dataset/releases/1.0.0/robots.csv;
//! - "paper:" values are quoted from the paper (seed text, Sec. VI and conclusion);
//! - "hand:" values are arithmetic done in the comment.

use crate::common;

use crate::common::{stderr, stdout, survey};
use serde_json::Value;

fn json(args: &[&str]) -> Value {
    let o = survey(args);
    assert!(o.status.success(), "survey {args:?} failed: {}", stderr(&o));
    serde_json::from_str(&stdout(&o)).expect("valid JSON")
}

fn num(v: &Value, path: &[&str]) -> f64 {
    let mut cur = v;
    for p in path {
        cur = match p.parse::<usize>() {
            Ok(i) => &cur[i],
            Err(_) => &cur[*p],
        };
    }
    cur.as_f64()
        .unwrap_or_else(|| panic!("{path:?} is not a number in {v}"))
}

fn close(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{what}: got {got}, want {want} (rel tol {rel})"
    );
}

#[test]
fn predict_lower_biped_1m_matches_r_predict_lm() {
    let p = json(&[
        "predict",
        "--release",
        "1.0.0",
        "--leg-length",
        "1.0",
        "--class",
        "lower-biped",
        "--format",
        "json",
    ]);
    let mass = &p["quantities"][0];
    assert_eq!(mass["quantity"], "mass");
    // R: 10^predict.lm(..., interval = "prediction") at log10 L = 0.
    close(num(mass, &["median"]), 24.25360243, 1e-7, "median mass");
    close(
        num(mass, &["prediction_interval", "0"]),
        5.88765813,
        1e-6,
        "PI low",
    );
    close(
        num(mass, &["prediction_interval", "1"]),
        99.91022203,
        1e-6,
        "PI high",
    );
    close(num(mass, &["median_ci", "0"]), 13.67614768, 1e-6, "CI low");
    close(num(mass, &["median_ci", "1"]), 43.01190984, 1e-6, "CI high");
    // R: mean(10^residuals(m)), Duan's smearing.
    close(
        num(mass, &["smearing_factor"]),
        1.13303096,
        1e-7,
        "smearing",
    );
    close(
        num(mass, &["mean"]),
        24.25360243 * 1.13303096,
        1e-6,
        "bias-corrected mean",
    );
    // The fit summary published with the paper: A = 24.2536 for lower bipeds.
    close(num(mass, &["law", "a"]), 24.2536, 1e-5, "A");
    assert_eq!(p["dataset"]["version"], "1.0.0");
    assert!(p["centre"].as_str().is_some_and(|c| c.contains("Duan")));
}

#[test]
fn predict_from_zippy_gives_paper_l2_and_l3_masses() {
    let p = json(&[
        "predict",
        "--release",
        "1.0.0",
        "--leg-length",
        "1.0",
        "--from",
        "zippy",
        "--format",
        "json",
    ]);
    let s = &p["scaled_reference"];
    // paper/issue: Zippy (0.025 m, 25 g) to 1 m: 40 kg by L², 1,600 kg by L³.
    // hand: 0.025 · 40² = 40; 0.025 · 40³ = 1600.
    close(num(s, &["mass_l2_kg"]), 40.0, 1e-12, "L² mass");
    close(num(s, &["mass_l3_kg"]), 1600.0, 1e-12, "L³ mass");
}

#[test]
fn predict_from_mugatu_design_gives_38_and_251_kg() {
    let p = json(&[
        "predict",
        "--leg-length",
        "1.0",
        "--from",
        "design:mugatu",
        "--format",
        "json",
    ]);
    let s = &p["scaled_reference"];
    // hand: 0.9 kg · (1/0.153)² = 38.446 kg; 0.9 · (1/0.153)³ = 251.28 kg.
    close(
        num(s, &["mass_l2_kg"]),
        0.9 / (0.153 * 0.153),
        1e-12,
        "L² mass",
    );
    close(
        num(s, &["mass_l3_kg"]),
        0.9 / (0.153f64.powi(3)),
        1e-12,
        "L³ mass",
    );
    assert!((num(s, &["mass_l2_kg"]) - 38.4).abs() < 0.1);
    assert!((num(s, &["mass_l3_kg"]) - 251.0).abs() < 0.5);
}

#[test]
fn predict_inverse_mass_budget_matches_r() {
    let p = json(&[
        "predict",
        "--release",
        "1.0.0",
        "--mass-budget",
        "30",
        "--class",
        "lower-biped",
        "--format",
        "json",
    ]);
    // R: 10^((log10(30) − a)/b) on the lower-biped OLS line.
    close(
        num(&p, &["inverse", "leg_length_m"]),
        1.115218399,
        1e-7,
        "inverse leg length",
    );
    assert!(
        p["inverse"]["extrapolation"]
            .as_str()
            .is_some_and(|w| w.contains("outside"))
    );
}

#[test]
fn predict_warns_on_extrapolation_in_text() {
    let o = survey(&["predict", "--release", "1.0.0", "--leg-length", "3.0"]);
    assert!(o.status.success());
    assert!(
        stdout(&o).contains("warning: extrapolation"),
        "{}",
        stdout(&o)
    );
}

#[test]
fn predict_rejects_bad_requests_with_exit_2() {
    for args in [
        vec!["predict"],
        vec!["predict", "--leg-length", "-1"],
        vec!["predict", "--leg-length", "1", "--class", "octopod"],
        vec!["predict", "--leg-length", "1", "--from", "no-such-robot"],
        vec![
            "predict",
            "--leg-length",
            "1",
            "--from",
            "design:no-such-design",
        ],
        vec!["predict", "--from", "zippy"],
    ] {
        let o = survey(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).is_empty());
        assert!(!stderr(&o).contains("panicked"), "{args:?}");
    }
}

#[test]
fn slope_test_rejects_isometry_for_bipeds_as_r_does() {
    let t = json(&[
        "test",
        "slope",
        "--release",
        "1.0.0",
        "--class",
        "lower-biped",
        "--x",
        "leg_length",
        "--y",
        "mass",
        "--format",
        "json",
    ]);
    // R: t = (b − 3)/se(b) = −7.678479, p = 5.8596e-05 on 8 df.
    close(
        num(&t, &["tests", "0", "test", "t_statistic"]),
        -7.678479186,
        1e-7,
        "t",
    );
    close(
        num(&t, &["tests", "0", "test", "p_value"]),
        5.859636041e-05,
        1e-6,
        "p",
    );
    // R: confint(m)[2, ].
    close(num(&t, &["b_ci", "0"]), 1.634475336, 1e-7, "CI low");
    close(num(&t, &["b_ci", "1"]), 2.26523517, 1e-7, "CI high");

    let f = json(&[
        "test",
        "slope",
        "--release",
        "1.0.0",
        "--class",
        "full-biped",
        "--value",
        "3",
        "--format",
        "json",
    ]);
    // R: full bipeds, t = −2.494964, p = 0.02475.
    close(
        num(&f, &["tests", "0", "test", "p_value"]),
        0.02475055534,
        1e-6,
        "full-biped p",
    );

    let s = json(&[
        "test",
        "slope",
        "--release",
        "1.0.0",
        "--class",
        "lower-biped",
        "--method",
        "sma",
        "--format",
        "json",
    ]);
    // smatr slope.test(method = "SMA", test.value = 3): r = −0.90858, p = 2.7333e-4.
    close(
        num(&s, &["tests", "0", "test", "test_correlation"]),
        -0.9085794813,
        1e-7,
        "SMA r",
    );
    close(
        num(&s, &["tests", "0", "test", "p_value"]),
        0.0002733342898,
        1e-6,
        "SMA p",
    );
}

#[test]
fn common_slope_and_elevation_match_r_and_smatr() {
    let c = json(&[
        "test",
        "common-slope",
        "--release",
        "1.0.0",
        "--method",
        "sma",
        "--format",
        "json",
    ]);
    // smatr slope.com(method = "SMA"): LR = 8.715786, p = 0.033318, b = 2.388120.
    close(
        num(&c, &["common_slope", "statistic"]),
        8.715785975,
        1e-5,
        "LR",
    );
    close(
        num(&c, &["common_slope", "p_value"]),
        0.03331835342,
        1e-5,
        "p",
    );
    close(
        num(&c, &["common_slope", "b"]),
        2.388120312,
        1e-5,
        "common b",
    );

    let o = json(&[
        "test",
        "common-slope",
        "--release",
        "1.0.0",
        "--format",
        "json",
    ]);
    // R: anova(lm(Y ~ X + G), lm(Y ~ X * G)): F = 2.516859, p = 0.072269.
    close(
        num(&o, &["common_slope", "statistic"]),
        2.516859068,
        1e-7,
        "F slopes",
    );
    close(
        num(&o, &["common_slope", "p_value"]),
        0.07226893465,
        1e-6,
        "p slopes",
    );
    close(
        num(&o, &["common_slope", "b"]),
        2.239341513,
        1e-7,
        "pooled slope",
    );
    // R: anova(lm(Y ~ X), lm(Y ~ X + G)): F = 5.375603, p = 0.0031834.
    close(
        num(&o, &["elevation", "statistic"]),
        5.375603228,
        1e-7,
        "F elevation",
    );
    close(
        num(&o, &["elevation", "p_value"]),
        0.003183405244,
        1e-6,
        "p elevation",
    );
}

#[test]
fn explain_full_biped_names_the_robots_that_move_the_exponent() {
    let e = json(&[
        "fit",
        "--release",
        "1.0.0",
        "--explain",
        "full-biped",
        "--format",
        "json",
    ]);
    let rel = e["relations"]
        .as_array()
        .expect("relations")
        .iter()
        .find(|r| r["x"] == "leg_length" && r["y"] == "mass")
        .expect("m vs L");
    // paper Table 2: full bipeds m ∝ L^1.91, n = 17.
    close(num(rel, &["b"]), 1.90914, 1e-5, "b");
    let robots = rel["robots"].as_array().expect("robots");
    assert_eq!(robots.len(), 17);
    // Sorted by |Δb|, and each Δb is b_without − b (hand: by definition).
    let d: Vec<f64> = robots.iter().map(|r| num(r, &["delta_b"]).abs()).collect();
    assert!(d.windows(2).all(|w| w[0] >= w[1]));
    for r in robots {
        close(
            num(r, &["b_without"]) - num(rel, &["b"]),
            num(r, &["delta_b"]),
            1e-9,
            "Δb",
        );
    }
    // R: lm() refitted without each full biped: KHR-3 moves b most, to 1.580126298.
    assert_eq!(robots[0]["id"], "kondo-khr-3");
    close(
        num(&robots[0], &["b_without"]),
        1.580126298,
        1e-8,
        "b without KHR-3",
    );
    // R: R² of L_B ~ L without Unitree H1 = 0.9116387229.
    let body = e["relations"]
        .as_array()
        .expect("relations")
        .iter()
        .find(|r| r["x"] == "leg_length" && r["y"] == "body_length")
        .expect("L_B vs L");
    let h1 = body["robots"]
        .as_array()
        .expect("robots")
        .iter()
        .find(|r| r["id"] == "unitree-h1")
        .expect("H1");
    close(
        num(h1, &["r2_without"]),
        0.9116387229,
        1e-8,
        "R² without H1",
    );
    let text = stdout(&survey(&[
        "fit",
        "--release",
        "1.0.0",
        "--explain",
        "full-biped",
    ]));
    assert!(text.contains("b without") && text.contains(robots[0]["id"].as_str().expect("id")));
}

#[test]
fn laws_table_recomputes_robotics_exponents() {
    let l = json(&["laws", "--release", "1.0.0", "--format", "json"]);
    let laws = l["laws"].as_array().expect("laws");
    // paper Table 1: 12 laws (4 quantities × isometric, biology, robotics).
    assert_eq!(laws.len(), 12);
    let mass = laws
        .iter()
        .find(|r| r["quantity"] == "mass" && r["basis"] == "robotics")
        .expect("robotics mass law");
    let lower = mass["from_data"]
        .as_array()
        .expect("from_data")
        .iter()
        .find(|d| d["class"] == "lower-biped")
        .expect("lower");
    // Published fit summary: lower biped m ∝ L^1.94986; R: CI [1.6345, 2.2652] contains 2.
    close(num(lower, &["b"]), 1.94986, 1e-5, "b");
    assert_eq!(lower["law_in_ci"], true);
    let iso = laws
        .iter()
        .find(|r| r["quantity"] == "mass" && r["basis"] == "isometric")
        .expect("iso");
    assert_eq!(num(iso, &["exponent"]), 3.0);
    assert!(iso["sources"].as_array().is_some_and(|s| !s.is_empty()));
}

#[test]
fn predict_plot_writes_svg() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("bands.svg");
    let o = survey(&[
        "predict",
        "--release",
        "1.0.0",
        "--leg-length",
        "1.0",
        "--from",
        "zippy",
        "--plot",
        path.to_str().expect("utf8 path"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = std::fs::read_to_string(&path).expect("svg written");
    assert!(svg.contains("<svg") && (svg.contains("polygon") || svg.contains("<path")));
}

/// Regression: a syntax error in laws/table1.toml was reported one line too early when
/// the offending value started a line (the line was counted as complete lines before it).
#[test]
fn laws_parse_error_names_the_right_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    common::copy_tree(&common::repo().join("dataset"), dir.path());
    let path = dir.path().join("laws/table1.toml");
    let text = std::fs::read_to_string(&path).expect("laws file");
    let (index, _) = text
        .lines()
        .enumerate()
        .find(|(_, l)| l.starts_with("exponent = 3.0"))
        .expect("an isometric exponent line");
    let broken: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == index {
                "= 3.0".to_string()
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(&path, broken.join("\n")).expect("write");
    let o = survey(&["laws", "--dataset", dir.path().to_str().expect("utf8")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let want = format!("table1.toml:{}:", index + 1);
    assert!(stderr(&o).contains(&want), "`{want}` not in {}", stderr(&o));
}
