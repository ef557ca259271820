//! `survey diff` on a changed copy of the dataset: a release of the live records is cut in
//! the copy (so the baseline is whatever the records are today), then one value is changed
//! (with a new source), one robot added and one removed. Expected records and values come
//! from the files the test writes; expected exponents are OLS slopes of log10 m on log10 L
//! computed here, from the release's CSV (before) and the changed TOML records (after),
//! not by the crate.

use std::path::Path;

use serde_json::Value;

use crate::common;

/// The release the test cuts of the copy's live records (newer than any real one).
const AGAINST: &str = "900.0.0";
const CHANGED: &str = "hamr-f";
const REMOVED: &str = "solo";
const ADDED: &str = "test-quad";
const NEW_URL: &str = "https://example.org/hamr-f-remeasured.pdf";
const ADDED_URL: &str = "https://example.org/test-quad-datasheet.pdf";

const ADDED_RECORD: &str = r#"id = "test-quad"
name = "Test Quad"
class = "quadruped"
fit = true

[[sources]]
key = "spec"
kind = "datasheet"
url = "https://example.org/test-quad-datasheet.pdf"

[values]
leg_length_m = { value = 0.3, source = "spec" }
body_length_m = { value = 0.5, source = "spec" }
mass_kg = { value = 8.0, source = "spec" }
speed_walking_mps = { value = 3.0, source = "spec" }
"#;

/// A copy of the dataset with its live records frozen as release `AGAINST`, the latest.
fn released_copy() -> tempfile::TempDir {
    let dir = common::dataset_copy();
    let meta = dir.path().join("dataset.toml");
    let text = std::fs::read_to_string(&meta).expect("dataset.toml");
    let version = text
        .lines()
        .find(|l| l.starts_with("version = "))
        .expect("version line")
        .to_string();
    std::fs::write(
        &meta,
        text.replace(&version, &format!("version = \"{AGAINST}\"")),
    )
    .expect("bump");
    let log = dir.path().join("CHANGELOG.md");
    let mut changelog = std::fs::read_to_string(&log).expect("changelog");
    changelog.push_str(&format!(
        "\n## {AGAINST}\n\nA release cut by tests/it/diff.rs.\n"
    ));
    std::fs::write(&log, changelog).expect("changelog");
    let d = dir.path().to_str().expect("utf-8 path");
    for args in [
        vec!["dataset", "package", "--dataset", d],
        vec![
            "dataset",
            "release",
            AGAINST,
            "--dataset",
            d,
            "--note",
            "test",
        ],
    ] {
        let out = common::survey(&args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{args:?}: {}",
            common::stderr(&out)
        );
    }
    dir
}

/// HAMR-F's mass as its record gives it.
fn record_mass(path: &Path) -> f64 {
    let t: toml::Table = std::fs::read_to_string(path)
        .expect("read")
        .parse()
        .expect("toml");
    toml_number(&t["values"]["mass_kg"]["value"]).expect("mass_kg")
}

/// The changed copy: HAMR-F's mass ×10, now citing a new source (`remeasured`, a paper);
/// Test Quad added; Solo removed.
fn changed_copy() -> tempfile::TempDir {
    let dir = released_copy();
    let robots = dir.path().join("robots");
    let hamr = robots.join(format!("{CHANGED}.toml"));
    let mass = record_mass(&hamr);
    let text = std::fs::read_to_string(&hamr).expect("hamr-f record");
    let mut out = String::new();
    for line in text.lines() {
        if line == "[values]" {
            out.push_str(&format!(
                "[[sources]]\nkey = \"remeasured\"\nkind = \"paper\"\nurl = \"{NEW_URL}\"\n\n"
            ));
        }
        if line.starts_with("mass_kg = ") {
            out.push_str(&format!(
                "mass_kg = {{ value = {:?}, source = \"remeasured\" }}\n",
                mass * 10.0
            ));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    std::fs::write(&hamr, out).expect("write hamr-f");
    assert_eq!(record_mass(&hamr), mass * 10.0);
    std::fs::write(robots.join(format!("{ADDED}.toml")), ADDED_RECORD).expect("write new robot");
    std::fs::remove_file(robots.join(format!("{REMOVED}.toml"))).expect("remove solo");
    dir
}

fn diff_json(dir: &Path, extra: &[&str]) -> (Option<i32>, Value) {
    let mut args = vec![
        "diff",
        "--dataset",
        dir.to_str().expect("utf-8 path"),
        "--format",
        "json",
    ];
    args.extend_from_slice(extra);
    let out = common::survey(&args);
    let v = serde_json::from_str(&common::stdout(&out))
        .unwrap_or_else(|e| panic!("{e}: {}{}", common::stdout(&out), common::stderr(&out)));
    (out.status.code(), v)
}

/// Quadruped (leg length, mass) pairs of the fitted robots in release `AGAINST`'s CSV.
fn release_quadrupeds(dir: &Path) -> Vec<(f64, f64)> {
    let path = dir.join(format!("releases/{AGAINST}/robots.csv"));
    let mut rdr = csv::Reader::from_path(&path).expect("release csv");
    let headers = rdr.headers().expect("header").clone();
    let col = |name: &str| headers.iter().position(|h| h == name).expect(name);
    let (class, fit, l, m) = (
        col("class"),
        col("fit"),
        col("leg_length_m"),
        col("mass_kg"),
    );
    rdr.records()
        .map(|r| r.expect("row"))
        .filter(|r| &r[class] == "quadruped" && &r[fit] == "true")
        .filter_map(|r| Some((r[l].parse().ok()?, r[m].parse().ok()?)))
        .collect()
}

fn toml_number(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// Quadruped (leg length, mass) pairs of the fitted robots in a directory of TOML records.
fn record_quadrupeds(dir: &Path) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir.join("robots")).expect("robots") {
        let p = e.expect("entry").path();
        if p.extension().and_then(|x| x.to_str()) != Some("toml") {
            continue;
        }
        let t: toml::Table = std::fs::read_to_string(&p)
            .expect("read")
            .parse()
            .expect("toml");
        if t["class"].as_str() != Some("quadruped") || t["fit"].as_bool() != Some(true) {
            continue;
        }
        let v = |f: &str| toml_number(t.get("values")?.get(f)?.get("value")?);
        if let (Some(l), Some(m)) = (v("leg_length_m"), v("mass_kg")) {
            out.push((l, m));
        }
    }
    out
}

/// OLS of log10 y on log10 x: (slope, 95% CI of the slope, n).
fn ols_slope(points: &[(f64, f64)]) -> (f64, [f64; 2], usize) {
    let n = points.len();
    let xs: Vec<f64> = points.iter().map(|p| p.0.log10()).collect();
    let ys: Vec<f64> = points.iter().map(|p| p.1.log10()).collect();
    let mx = xs.iter().sum::<f64>() / n as f64;
    let my = ys.iter().sum::<f64>() / n as f64;
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let b = sxy / sxx;
    let sse: f64 = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (y - my - b * (x - mx)).powi(2))
        .sum();
    let se = (sse / (n as f64 - 2.0) / sxx).sqrt();
    // R's qt(0.975, df) for df = 6..60 (the quadruped class has n = 28 since dataset 1.4.0).
    const T975: [f64; 55] = [
        2.446_912, 2.364_624, 2.306_004, 2.262_157, 2.228_139, 2.200_985, 2.178_813, 2.160_369,
        2.144_787, 2.131_450, 2.119_905, 2.109_816, 2.100_922, 2.093_024, 2.085_963, 2.079_614,
        2.073_873, 2.068_658, 2.063_899, 2.059_539, 2.055_529, 2.051_831, 2.048_407, 2.045_230,
        2.042_272, 2.039_513, 2.036_933, 2.034_515, 2.032_245, 2.030_108, 2.028_094, 2.026_192,
        2.024_394, 2.022_691, 2.021_075, 2.019_541, 2.018_082, 2.016_692, 2.015_368, 2.014_103,
        2.012_896, 2.011_741, 2.010_635, 2.009_575, 2.008_559, 2.007_584, 2.006_647, 2.005_746,
        2.004_879, 2.004_045, 2.003_241, 2.002_465, 2.001_717, 2.000_995, 2.000_298,
    ];
    let t = *T975
        .get((n - 2).checked_sub(6).unwrap_or(usize::MAX))
        .unwrap_or_else(|| panic!("no t quantile tabulated for df = {}", n - 2));
    (b, [b - t * se, b + t * se], n)
}

fn table2_entry<'a>(v: &'a Value, class: &str, x: &str, y: &str) -> &'a Value {
    v["table2"]
        .as_array()
        .expect("table2")
        .iter()
        .find(|t| t["class"] == class && t["x"] == x && t["y"] == y)
        .unwrap_or_else(|| panic!("no Table 2 entry {class} {y}~{x}"))
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + b.abs())
}

#[test]
fn diff_reports_the_changed_added_and_removed_records() {
    let dir = changed_copy();
    // The default baseline is the latest release.
    let (code, v) = diff_json(dir.path(), &[]);
    assert_eq!(code, Some(0), "no new validation errors: {v}");
    assert_eq!(v["before"]["version"], AGAINST);
    assert_eq!(v["before"]["frozen"], true);
    assert_eq!(v["after"]["frozen"], false);

    // Added: the new record, with the values and source it gives.
    let added = v["added"].as_array().expect("added");
    assert_eq!(added.len(), 1, "{added:?}");
    let a = &added[0];
    assert_eq!(a["id"], ADDED);
    assert_eq!(a["name"], "Test Quad");
    assert_eq!(a["class"], "quadruped");
    assert_eq!(a["fit"], true);
    for (field, value) in [
        ("leg_length_m", "0.3"),
        ("body_length_m", "0.5"),
        ("mass_kg", "8"),
        ("speed_walking_mps", "3"),
    ] {
        let fv = a["values"]
            .as_array()
            .expect("values")
            .iter()
            .find(|f| f["field"] == field)
            .unwrap_or_else(|| panic!("added robot lacks {field}: {a}"));
        assert_eq!(fv["value"], value, "{field}");
        assert_eq!(fv["sources"][0]["key"], "spec");
        assert_eq!(fv["sources"][0]["kind"], "datasheet");
        assert_eq!(fv["sources"][0]["url"], ADDED_URL);
    }

    // Removed: Solo, as the release has it.
    let removed = v["removed"].as_array().expect("removed");
    assert_eq!(removed.len(), 1, "{removed:?}");
    assert_eq!(removed[0]["id"], REMOVED);
    assert_eq!(removed[0]["name"], "Solo");
    assert_eq!(removed[0]["fit"], true);

    // Changed: HAMR-F, its mass (old and new value, the new value's source).
    let changed = v["changed"].as_array().expect("changed");
    assert_eq!(changed.len(), 1, "{changed:?}");
    let c = &changed[0];
    assert_eq!(c["id"], CHANGED);
    let fields = c["fields"].as_array().expect("fields");
    // The mass, then the compiled table's list of source URLs (one source added).
    assert_eq!(fields.len(), 2, "mass_kg and sources changed: {fields:?}");
    assert_eq!(fields[1]["field"], "sources");
    let urls = |k: &str| {
        fields[1][k]
            .as_str()
            .unwrap_or("")
            .split(" ; ")
            .collect::<Vec<_>>()
    };
    let (mut old_urls, new_urls) = (urls("old"), urls("new"));
    old_urls.push(NEW_URL);
    assert_eq!(new_urls, old_urls);
    let f = &fields[0];
    let base = common::repo().join(format!("dataset/robots/{CHANGED}.toml"));
    let old_mass = record_mass(&base);
    assert_eq!(f["field"], "mass_kg");
    assert_eq!(f["unit"], "kg");
    let num = |k: &str| f[k].as_str().and_then(|s| s.parse::<f64>().ok());
    assert_eq!(num("old"), Some(old_mass), "{f}");
    assert_eq!(num("new"), Some(old_mass * 10.0), "{f}");
    assert!(close(f["relative_change"].as_f64().expect("relative"), 9.0));
    assert_eq!(f["sources"].as_array().map(Vec::len), Some(1));
    assert_eq!(f["sources"][0]["key"], "remeasured");
    assert_eq!(f["sources"][0]["kind"], "paper");
    assert_eq!(f["sources"][0]["url"], NEW_URL);
}

#[test]
fn diff_moves_the_quadruped_exponent_by_the_independently_computed_amount() {
    let dir = changed_copy();
    let (_, v) = diff_json(dir.path(), &["--against", AGAINST]);
    let (b0, ci0, n0) = ols_slope(&release_quadrupeds(dir.path()));
    let (b1, _, n1) = ols_slope(&record_quadrupeds(dir.path()));
    let t = table2_entry(&v, "quadruped", "leg_length", "mass");
    let got = |side: &str, k: &str| t[side][k].as_f64().unwrap_or_else(|| panic!("{side}.{k}"));
    assert!(close(got("before", "b"), b0), "before {} vs {b0}", t);
    assert!(close(got("after", "b"), b1), "after {} vs {b1}", t);
    assert!(close(t["delta_b"].as_f64().expect("delta"), b1 - b0));
    assert_eq!(t["before"]["n"].as_u64(), Some(n0 as u64));
    assert_eq!(t["after"]["n"].as_u64(), Some(n1 as u64));
    // The tabulated t has 7 significant digits.
    for (i, want) in ci0.iter().enumerate() {
        let got = t["before"]["b_ci"][i].as_f64().expect("ci");
        assert!((got - want).abs() < 1e-5, "CI limit {got} vs {want}");
    }
    // A tenfold mass on the smallest quadruped flattens the law out of its old interval.
    assert!(b1 < ci0[0], "b {b1} should leave [{}, {}]", ci0[0], ci0[1]);
    assert_eq!(t["outside_previous_ci"], true);
    assert_eq!(t["changed"], true);

    // Classes the change does not touch keep their exponents exactly, unflagged.
    for class in ["lower-biped", "full-biped", "hexapod"] {
        for (x, y) in [
            ("leg_length", "body_length"),
            ("leg_length", "mass"),
            ("body_length", "mass"),
        ] {
            let e = table2_entry(&v, class, x, y);
            assert_eq!(e["delta_b"].as_f64(), Some(0.0), "{class} {y}~{x}");
            assert_eq!(e["outside_previous_ci"], false);
            assert_eq!(e["changed"], false);
        }
    }
    assert_eq!(v["table2"].as_array().map(Vec::len), Some(15));
}

#[test]
fn diff_lists_the_new_validation_problems_only() {
    let dir = changed_copy();
    let (_, v) = diff_json(dir.path(), &["--against", AGAINST]);
    let new = v["new_problems"].as_array().expect("new_problems");
    let has = |robot: &str, rule: &str, field: &str| {
        new.iter()
            .any(|p| p["robot"] == robot && p["rule"] == rule && p["field"] == field)
    };
    // Walking at 3 m/s on a 0.3 m leg: Froude 3²/(9.81·0.3) ≈ 3.1 > 1.
    assert!(
        has(ADDED, "consistency", "values.speed_walking_mps"),
        "{new:?}"
    );
    // HAMR-F's new mass is not its only reported bound (mass_min_kg) any more.
    let hamr: toml::Table = std::fs::read_to_string(dir.path().join("robots/hamr-f.toml"))
        .expect("read")
        .parse()
        .expect("toml");
    let values = hamr["values"].as_table().expect("values");
    if values.contains_key("mass_min_kg") && !values.contains_key("mass_max_kg") {
        assert!(has(CHANGED, "definition", "values.mass_kg"), "{new:?}");
    }
    // Nothing else but outliers that the changed fits may bring; problems the release
    // already had (e.g. Valkyrie's one-bound mass) are not new.
    for p in new {
        let r = p["robot"].as_str().unwrap_or("");
        assert!(
            r == ADDED || r == CHANGED || p["rule"] == "outlier",
            "unexpected new problem {p}"
        );
        assert_ne!(r, "valkyrie", "{p}");
    }
}

#[test]
fn diff_markdown_is_ready_for_a_review() {
    let dir = changed_copy();
    let out = common::survey(&[
        "diff",
        "--dataset",
        dir.path().to_str().expect("utf-8"),
        "--against",
        AGAINST,
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let md = common::stdout(&out);
    assert!(md.contains(&format!(
        "## Dataset diff: release {AGAINST} → live records"
    )));
    assert!(md.contains("**1 added, 1 removed, 1 changed;"), "{md}");
    let (_, v) = diff_json(dir.path(), &["--against", AGAINST]);
    let f = &v["changed"][0]["fields"][0];
    let (old, new) = (
        f["old"].as_str().expect("old"),
        f["new"].as_str().expect("new"),
    );
    assert!(
        md.contains(&format!(
            "| mass_kg | {old} kg | {new} kg (+900.0%) | `remeasured` (paper) <{NEW_URL}> |"
        )),
        "{md}"
    );
    assert!(md.contains("- `test-quad` Test Quad (quadruped, fitted): L = 0.3 m [`spec`], L_B = 0.5 m [`spec`], m = 8 kg [`spec`]"), "{md}");
    assert!(md.contains("- `solo` Solo (quadruped, fitted)"), "{md}");
    assert!(md.contains("[consistency]"), "{md}");
    let (b0, ci0, n) = ols_slope(&release_quadrupeds(dir.path()));
    let (b1, _, n1) = ols_slope(&record_quadrupeds(dir.path()));
    assert_eq!(n, n1, "one quadruped added, one removed");
    let row = format!(
        "| m ∝ L^b | Quadruped | 11 | {b0:.3} [{:.3}, {:.3}] | {b1:.3} | {:+.3} |",
        ci0[0],
        ci0[1],
        b1 - b0
    );
    let line = md
        .lines()
        .find(|l| l.starts_with(&row.replace("| 11 |", &format!("| {n} |"))))
        .unwrap_or_else(|| panic!("no row `{row}` in\n{md}"));
    assert!(line.contains("outside previous 95% CI"), "{line}");
}

#[test]
fn diff_of_unchanged_records_is_empty() {
    let dir = released_copy();
    let (code, v) = diff_json(dir.path(), &[]);
    assert_eq!(code, Some(0));
    assert_eq!(
        v["before"]["version"], AGAINST,
        "the latest release is the default"
    );
    assert_eq!(
        v["before"]["sha256"], v["after"]["sha256"],
        "{}",
        v["before"]
    );
    for k in [
        "added",
        "removed",
        "changed",
        "new_problems",
        "resolved_problems",
    ] {
        assert_eq!(v[k].as_array().map(Vec::len), Some(0), "{k}: {}", v[k]);
    }
    for t in v["table2"].as_array().expect("table2") {
        assert_eq!(t["delta_b"].as_f64(), Some(0.0), "{t}");
        assert_eq!(t["outside_previous_ci"], false);
        assert_eq!(t["changed"], false);
    }
}

#[test]
fn diff_against_an_unknown_release_is_exit_2_naming_it() {
    let out = common::survey(&["diff", "--against", "9.9.9"]);
    assert_eq!(out.status.code(), Some(2));
    let err = common::stderr(&out);
    assert!(err.contains("9.9.9") && err.contains("1.0.0"), "{err}");
    assert!(common::stdout(&out).is_empty());
}
