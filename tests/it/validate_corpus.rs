//! A corpus of broken records, one per validation rule (tests/corpus): each must be
//! rejected with the right file, field and rule. The expectation is written in the record
//! itself (`# expect: SEVERITY RULE FILE FIELD [line=N]`) or in `expect.txt` for cases
//! that need several records (duplicates, outliers).

use crate::common;

use std::path::PathBuf;

use robot_survey::dataset::{Dataset, DatasetFiles, validate::validate};
use serde_json::Value;

struct Expect {
    severity: String,
    rule: String,
    file: String,
    field: String,
    line: Option<usize>,
}

fn parse_expect(line: &str) -> Expect {
    let parts: Vec<&str> = line.split_whitespace().collect();
    assert!(parts.len() >= 4, "bad expectation `{line}`");
    Expect {
        severity: parts[0].into(),
        rule: parts[1].into(),
        file: parts[2].into(),
        field: parts[3].into(),
        line: parts
            .get(4)
            .and_then(|l| l.strip_prefix("line="))
            .and_then(|n| n.parse().ok()),
    }
}

fn cases() -> Vec<(String, Vec<PathBuf>, Expect)> {
    let corpus = common::repo().join("tests/corpus");
    let mut out = Vec::new();
    let mut entries: Vec<_> = std::fs::read_dir(&corpus)
        .expect("corpus")
        .map(|e| e.expect("entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            let expect = std::fs::read_to_string(p.join("expect.txt")).expect("expect.txt");
            let mut files: Vec<PathBuf> = std::fs::read_dir(&p)
                .expect("case dir")
                .map(|e| e.expect("entry").path())
                .filter(|f| f.extension().is_some_and(|e| e == "toml"))
                .collect();
            files.sort();
            out.push((p.display().to_string(), files, parse_expect(expect.trim())));
        } else {
            let text = std::fs::read_to_string(&p).expect("case");
            let first = text.lines().next().unwrap_or("");
            let exp = first
                .strip_prefix("# expect: ")
                .unwrap_or_else(|| panic!("{}: no `# expect:` line", p.display()));
            out.push((p.display().to_string(), vec![p.clone()], parse_expect(exp)));
        }
    }
    out
}

#[test]
fn every_broken_record_is_rejected_with_its_rule_file_and_field() {
    let cases = cases();
    assert!(cases.len() >= 15, "corpus shrank to {}", cases.len());
    for (name, files, exp) in cases {
        let refs: Vec<&std::path::Path> = files.iter().map(PathBuf::as_path).collect();
        let dir = common::scratch_dataset(&refs);
        let ds = Dataset::load(DatasetFiles::from_dir(dir.path()).expect("read")).expect("load");
        let rep = validate(&ds);
        let hit = rep.problems.iter().find(|p| {
            p.rule.name() == exp.rule
                && p.file.ends_with(&exp.file)
                && (exp.field == "-" || p.field.as_deref() == Some(exp.field.as_str()))
                && format!("{:?}", p.severity).to_lowercase() == exp.severity
        });
        let Some(hit) = hit else {
            panic!(
                "{name}: expected {} {} in {} field {}, got:\n{}",
                exp.severity,
                exp.rule,
                exp.file,
                exp.field,
                rep.problems
                    .iter()
                    .map(|p| p.to_line())
                    .collect::<Vec<_>>()
                    .join("\n")
            );
        };
        if let Some(l) = exp.line {
            assert_eq!(hit.line, Some(l), "{name}: line of {}", hit.to_line());
        }
        if exp.severity == "error" {
            assert!(rep.errors() > 0, "{name}: must fail validation");
        }
    }
}

/// The binary reports the same problems as JSON with the documented keys, and exits 1.
#[test]
fn validate_json_lists_problems_and_exits_1_on_errors() {
    let case = common::repo().join("tests/corpus/definition-leg-exceeds-body.toml");
    let dir = common::scratch_dataset(&[case.as_path()]);
    let out = common::survey(&[
        "validate",
        "--dataset",
        &dir.path().display().to_string(),
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", common::stderr(&out));
    let v: Value = serde_json::from_str(&common::stdout(&out)).expect("json");
    let list = v.as_array().expect("a list");
    let p = list
        .iter()
        .find(|p| p["rule"] == "definition")
        .expect("a definition problem");
    for key in ["file", "robot", "field", "severity", "rule", "message"] {
        assert!(p.get(key).is_some(), "missing key {key} in {p}");
    }
    assert_eq!(p["robot"], "definition-leg-exceeds-body");
    assert_eq!(p["field"], "values.leg_length_m");
    assert_eq!(p["severity"], "error");
}

/// Warnings alone do not fail validation (exit 0).
#[test]
fn warnings_only_exit_0() {
    let case = common::repo().join("tests/corpus/consistency-walking-froude.toml");
    let dir = common::scratch_dataset(&[case.as_path()]);
    let out = common::survey(&["validate", "--dataset", &dir.path().display().to_string()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        common::stdout(&out),
        common::stderr(&out)
    );
    assert!(common::stdout(&out).contains("[consistency]"));
}

/// A release whose bytes changed is caught, and `--release` refuses to use it.
#[test]
fn tampered_release_is_an_integrity_error() {
    let dir = common::dataset_copy();
    let csv = dir.path().join("releases/1.0.0/robots.csv");
    let mut bytes = std::fs::read(&csv).expect("release csv");
    let i = bytes.iter().position(|&b| b == b'0').expect("a digit");
    bytes[i] = b'1';
    std::fs::write(&csv, bytes).expect("tamper");
    let ds = Dataset::load(DatasetFiles::from_dir(dir.path()).expect("read")).expect("load");
    let rep = validate(&ds);
    assert!(
        rep.problems
            .iter()
            .any(|p| p.rule.name() == "release-integrity"
                && p.file.ends_with("releases/1.0.0/robots.csv")),
        "{:?}",
        rep.problems
    );
    let out = common::survey(&[
        "fit",
        "--dataset",
        &dir.path().display().to_string(),
        "--release",
        "1.0.0",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        common::stderr(&out).contains("changed"),
        "{}",
        common::stderr(&out)
    );
}

/// A data package description that no longer matches the vocabulary is caught.
#[test]
fn stale_datapackage_is_a_metadata_error() {
    let dir = common::dataset_copy();
    let vocab = dir.path().join("vocabulary.toml");
    let text = std::fs::read_to_string(&vocab).expect("vocab");
    std::fs::write(&vocab, text.replace("max = 5.0", "max = 6.0")).expect("edit");
    let ds = Dataset::load(DatasetFiles::from_dir(dir.path()).expect("read")).expect("load");
    let rep = validate(&ds);
    assert!(
        rep.problems.iter().any(|p| p.rule.name() == "metadata"),
        "{:?}",
        rep.problems
    );
}

/// Writes a record into a scratch dataset's robots/ directory.
fn write_record(dir: &std::path::Path, id: &str, text: &str) {
    std::fs::write(dir.join("robots").join(format!("{id}.toml")), text).expect("write record");
}

/// Provenance coverage counts, by hand: of three fitted quadrupeds, leg lengths cite a
/// paper twice (once derived) and the survey table once; body lengths cite the survey
/// table, a secondary restatement and a datasheet; masses cite a paper, a model file and
/// the survey table. A robot that is not fitted is not counted.
#[test]
fn coverage_counts_fitted_values_with_a_primary_source() {
    let dir = common::scratch_dataset(&[]);
    let record = |id: &str, fit: bool, leg: &str, body: &str, mass: &str| {
        format!(
            r#"id = "{id}"
name = "{id}"
class = "quadruped"
fit = {fit}
{excl}
[[sources]]
key = "survey"
kind = "dataset"
url = "https://github.com/robomechanics/robot-dataset"

[[sources]]
key = "paper"
kind = "paper"
url = "https://example.org/paper"

[[sources]]
key = "news"
kind = "secondary"
url = "https://example.org/news"

[[sources]]
key = "spec"
kind = "datasheet"
url = "https://example.org/spec.pdf"

[[sources]]
key = "urdf"
kind = "model"
url = "https://example.org/robot.urdf"

[values]
leg_length_m = {leg}
body_length_m = {body}
mass_kg = {mass}
"#,
            excl = if fit {
                ""
            } else {
                "exclusion = \"kept for its mass\"\n"
            }
        )
    };
    write_record(
        dir.path(),
        "qa",
        &record(
            "qa",
            true,
            r#"{ value = 0.3, source = "paper" }"#,
            r#"{ value = 0.6, source = "survey" }"#,
            r#"{ value = 9.0, source = ["survey", "paper"] }"#,
        ),
    );
    write_record(
        dir.path(),
        "qb",
        &record(
            "qb",
            true,
            r#"{ value = 0.4, source = "paper", derived = true, derivation = "thigh + shank" }"#,
            r#"{ value = 0.8, source = "news" }"#,
            r#"{ value = 20.0, source = "urdf", derived = true, derivation = "sum of link masses" }"#,
        ),
    );
    write_record(
        dir.path(),
        "qc",
        &record(
            "qc",
            true,
            r#"{ value = 0.5, source = "survey" }"#,
            r#"{ value = 1.0, source = "spec" }"#,
            r#"{ value = 40.0, source = "survey" }"#,
        ),
    );
    write_record(
        dir.path(),
        "qd",
        &record(
            "qd",
            false,
            r#"{ value = 0.2, source = "paper" }"#,
            r#"{ value = 0.5, source = "paper" }"#,
            r#"{ value = 3.0, source = "paper" }"#,
        ),
    );
    let ds = Dataset::load(DatasetFiles::from_dir(dir.path()).expect("read")).expect("load");
    let cov = robot_survey::dataset::validate::coverage(&ds);
    let field = |f: &str| cov.per_field.iter().find(|(n, _)| n == f).expect(f).1;
    assert_eq!(
        (field("leg_length_m").primary, field("leg_length_m").values),
        (2, 3)
    );
    assert_eq!(
        (
            field("body_length_m").primary,
            field("body_length_m").values
        ),
        (1, 3)
    );
    assert_eq!((field("mass_kg").primary, field("mass_kg").values), (2, 3));
    assert_eq!(
        (cov.total.primary, cov.total.values, cov.total.derived),
        (5, 9, 2)
    );
    // The report names the share per field and class, and overall.
    let out = common::survey(&["validate", "--dataset", &dir.path().display().to_string()]);
    let text = common::stdout(&out);
    assert!(text.contains("provenance coverage"), "{text}");
    assert!(text.contains("5 of 9 fitted values (55.6%)"), "{text}");
    assert!(text.contains(" 67%  2/3 "), "{text}");
}

/// `validate --release X` names the release it checked and says what it checked; with
/// `--rows` it lists the problems the release was frozen with. Release 1.0.0 keeps the
/// survey's three impossible leg lengths (CHANGELOG 1.1.0: BigDog 1.25 m > 1.0 m,
/// Cheetah 3 0.68 m > 0.6 m, Mini Cheetah 0.40 m > 0.38 m) and nothing else is an error.
#[test]
fn validate_release_names_it_and_rows_lists_its_known_errors() {
    let ds = common::repo().join("dataset").display().to_string();
    let out = common::survey(&["validate", "--dataset", &ds, "--release", "1.0.0"]);
    let text = common::stdout(&out);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("version 1.0.0"), "{text}");
    assert!(
        text.contains("checked release 1.0.0: integrity only"),
        "{text}"
    );
    assert!(!text.contains("version 1.1.0"), "{text}");

    let out = common::survey(&[
        "validate",
        "--dataset",
        &ds,
        "--release",
        "1.0.0",
        "--rows",
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", common::stderr(&out));
    let v: Value = serde_json::from_str(&common::stdout(&out)).expect("json");
    let mut errors: Vec<(String, String, String)> = v
        .as_array()
        .expect("list")
        .iter()
        .filter(|p| p["severity"] == "error")
        .map(|p| {
            (
                p["robot"].as_str().unwrap_or("").to_string(),
                p["field"].as_str().unwrap_or("").to_string(),
                p["rule"].as_str().unwrap_or("").to_string(),
            )
        })
        .collect();
    errors.sort();
    let want = |r: &str| {
        (
            r.to_string(),
            "values.leg_length_m".to_string(),
            "definition".to_string(),
        )
    };
    assert_eq!(
        errors,
        vec![want("bigdog"), want("cheetah-3"), want("mini-cheetah")]
    );
    assert!(v.as_array().expect("list").iter().all(|p| {
        p["file"]
            .as_str()
            .unwrap_or("")
            .ends_with("releases/1.0.0/robots.csv")
            || p["rule"] == "release-integrity"
    }));
}
