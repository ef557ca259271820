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
