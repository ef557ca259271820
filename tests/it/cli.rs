//! The real binary: exit codes (0 ok, 1 problems found, 2 could not run), clear errors
//! naming what was wrong, nothing written on bad input.

use crate::common;

#[test]
fn help_explains_every_command_and_exits_0() {
    let out = common::survey(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let text = common::stdout(&out);
    for cmd in [
        "validate", "fit", "predict", "test", "laws", "dataset", "sim",
    ] {
        assert!(text.contains(cmd), "--help lacks {cmd}");
    }
}

#[test]
fn missing_dataset_dir_is_exit_2_with_its_path() {
    let out = common::survey(&["fit", "--dataset", "/nonexistent/robots"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        common::stderr(&out).contains("/nonexistent/robots"),
        "{}",
        common::stderr(&out)
    );
}

#[test]
fn unknown_release_is_exit_2_and_lists_releases() {
    let out = common::survey(&["fit", "--release", "9.9.9"]);
    assert_eq!(out.status.code(), Some(2));
    let err = common::stderr(&out);
    assert!(err.contains("9.9.9") && err.contains("1.0.0"), "{err}");
}

#[test]
fn bad_option_values_are_exit_2() {
    assert_eq!(
        common::survey(&["fit", "--confidence", "1.5"])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        common::survey(&["fit", "--format", "xlsx"]).status.code(),
        Some(2)
    );
    assert_eq!(
        common::survey(&["fit", "--explain", "tripod"])
            .status
            .code(),
        Some(2)
    );
}

#[test]
fn broken_record_makes_fit_refuse_with_the_file_name() {
    let case = common::repo().join("tests/corpus/parse-error.toml");
    let dir = common::scratch_dataset(&[case.as_path()]);
    let out = common::survey(&["fit", "--dataset", &dir.path().display().to_string()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        common::stderr(&out).contains("parse-error.toml"),
        "{}",
        common::stderr(&out)
    );
}

#[test]
fn fmt_check_reports_a_non_canonical_record_and_exits_1_without_writing() {
    let dir = common::dataset_copy();
    let f = dir.path().join("robots/cassie.toml");
    let text = std::fs::read_to_string(&f).expect("cassie");
    // Same data with an integer-looking float, which the canonical form writes as 31.0.
    let messy = text.replace("mass_kg = { value = 31.0,", "mass_kg = { value = 31,");
    assert_ne!(messy, text, "the test's edit must change cassie.toml");
    std::fs::write(&f, &messy).expect("write");
    let d = dir.path().display().to_string();
    let out = common::survey(&["dataset", "fmt", "--check", "--dataset", &d]);
    assert_eq!(out.status.code(), Some(1), "{}", common::stdout(&out));
    assert!(common::stdout(&out).contains("cassie.toml"));
    assert_eq!(
        std::fs::read_to_string(&f).expect("cassie"),
        messy,
        "--check must not write"
    );
    let out = common::survey(&["dataset", "fmt", "--dataset", &d]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(
        std::fs::read_to_string(&f).expect("cassie"),
        text,
        "fmt restores the canonical form"
    );
}

#[test]
fn release_refuses_an_existing_or_unlogged_version() {
    let dir = common::dataset_copy();
    let d = dir.path().display().to_string();
    let out = common::survey(&["dataset", "release", "1.0.0", "--dataset", &d]);
    assert_eq!(out.status.code(), Some(2));
    // Bump the live version without a changelog entry: refused, nothing written.
    let meta = dir.path().join("dataset.toml");
    let text = std::fs::read_to_string(&meta).expect("meta");
    let live = text
        .lines()
        .find(|l| l.starts_with("version"))
        .expect("version line")
        .to_string();
    std::fs::write(&meta, text.replace(&live, "version = \"9.0.0\"")).expect("bump");
    let out = common::survey(&["dataset", "release", "9.0.0", "--dataset", &d]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        common::stderr(&out).contains("CHANGELOG"),
        "{}",
        common::stderr(&out)
    );
    assert!(!dir.path().join("releases/9.0.0").exists());
}

#[test]
fn release_cuts_a_frozen_release_that_validates() {
    let dir = common::dataset_copy();
    let d = dir.path().display().to_string();
    let meta = dir.path().join("dataset.toml");
    let text = std::fs::read_to_string(&meta).expect("meta");
    let live = text
        .lines()
        .find(|l| l.starts_with("version"))
        .expect("version line")
        .to_string();
    std::fs::write(&meta, text.replace(&live, "version = \"9.0.0\"")).expect("bump");
    let log = dir.path().join("CHANGELOG.md");
    let mut cl = std::fs::read_to_string(&log).expect("changelog");
    cl.push_str("\n## 9.0.0 — test\n\n- test release\n");
    std::fs::write(&log, cl).expect("log");
    assert_eq!(
        common::survey(&["dataset", "package", "--dataset", &d])
            .status
            .code(),
        Some(0)
    );
    let out = common::survey(&[
        "dataset",
        "release",
        "9.0.0",
        "--dataset",
        &d,
        "--date",
        "2030-01-01",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    assert!(dir.path().join("releases/9.0.0/robots.csv").is_file());
    assert!(dir.path().join("releases/9.0.0/robots.parquet").is_file());
    let out = common::survey(&["validate", "--dataset", &d]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stdout(&out));
    let out = common::survey(&[
        "fit",
        "--dataset",
        &d,
        "--release",
        "9.0.0",
        "--format",
        "json",
    ]);
    assert!(out.status.success());
}

#[test]
fn fit_bootstrap_is_seeded_and_deterministic() {
    let run = |seed: &str| {
        let o = common::survey(&[
            "fit",
            "--release",
            "1.0.0",
            "--bootstrap",
            "500",
            "--seed",
            seed,
            "--format",
            "json",
        ]);
        assert!(o.status.success(), "{}", common::stderr(&o));
        common::stdout(&o)
    };
    let a = run("7");
    assert_eq!(a, run("7"), "same seed, same bytes");
    assert_ne!(a, run("8"), "another seed resamples differently");
    let v: serde_json::Value = serde_json::from_str(&a).expect("json");
    for f in v["fits"].as_array().expect("fits") {
        let ci = f["b_ci_bootstrap"]
            .as_array()
            .expect("bootstrap interval present");
        let (lo, hi) = (ci[0].as_f64().expect("lo"), ci[1].as_f64().expect("hi"));
        assert!(lo < hi, "{f}");
        let bca = f["b_ci_bootstrap_bca"]
            .as_array()
            .expect("BCa interval present");
        assert!(
            bca[0].as_f64().expect("lo") < bca[1].as_f64().expect("hi"),
            "{f}"
        );
    }
    // Without --bootstrap the key is absent, so the JSON shape of Table 2 is unchanged.
    let plain = common::stdout(&common::survey(&[
        "fit",
        "--release",
        "1.0.0",
        "--format",
        "json",
    ]));
    assert!(!plain.contains("b_ci_bootstrap"));
}
