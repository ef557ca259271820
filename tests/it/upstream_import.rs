//! The upstream survey table (read from ../shared, never committed) is imported with all
//! its quirks, every row is accounted for, and the import reproduces frozen release 1.0.0
//! byte for byte.

use crate::common;

use robot_survey::dataset::upstream::{self, import};
use robot_survey::dataset::{RobotClass, Value};

fn imported() -> upstream::UpstreamImport {
    let path = common::upstream_csv();
    let bytes =
        std::fs::read(&path).expect("../shared/upstream/robot-dataset/robot_scaling_dataset.csv");
    import(&bytes, &path.display().to_string()).expect("import")
}

#[test]
fn every_upstream_row_is_accounted_for() {
    let imp = imported();
    // The raw file has 60 data rows: 59 robots and one blank row (counted by hand).
    assert_eq!(imp.ledger.len(), 60);
    assert_eq!(imp.robots.len(), 59);
    let skipped: Vec<_> = imp.ledger.iter().filter(|l| l.skipped.is_some()).collect();
    assert_eq!(skipped.len(), 1);
    assert_eq!(skipped[0].skipped.as_deref(), Some("blank row"));
    // 47 robots are fitted, as in the paper: 10 lower bipeds, 17 full, 14 quadrupeds, 6 hexapods.
    let count = |c| imp.robots.iter().filter(|r| r.fit && r.class == c).count();
    assert_eq!(
        [
            count(RobotClass::LowerBiped),
            count(RobotClass::FullBiped),
            count(RobotClass::Quadruped),
            count(RobotClass::Hexapod)
        ],
        [10, 17, 14, 6]
    );
    // Every kept-but-unfitted robot says why.
    assert!(
        imp.robots
            .iter()
            .filter(|r| !r.fit)
            .all(|r| r.exclusion.as_deref().is_some_and(|e| !e.is_empty()))
    );
}

#[test]
fn each_quirk_of_the_raw_file_is_handled_and_reported() {
    let imp = imported();
    let kinds: std::collections::BTreeSet<&str> = imp.quirks.iter().map(|q| q.kind).collect();
    for k in [
        "bom",
        "crlf",
        "trailing-column",
        "blank-row",
        "whitespace",
        "thousands-separator",
        "range",
        "spreadsheet-date",
        "inequality",
        "name-note",
        "text-in-numeric",
        "mojibake",
        "ambiguous-class",
        "hybrid-class",
        "lab-reference",
        "leading-decimal-point",
        "missing-leg-length",
    ] {
        assert!(kinds.contains(k), "quirk `{k}` not reported; got {kinds:?}");
    }
    let robot = |id: &str| {
        imp.robots
            .iter()
            .find(|r| r.id == id)
            .unwrap_or_else(|| panic!("{id}"))
    };
    // "160,000" → 160000 (Atlas HD cost).
    assert_eq!(robot("atlas-hd").number("cost_usd"), Some(160_000.0));
    // "<250000" → a price range with only an upper end (Digit).
    assert_eq!(
        robot("digit").values["cost_usd"].value,
        Value::Range {
            min: None,
            max: Some(250_000.0)
        }
    );
    // "2-Jan" was the range "1-2" hours (Unitree Go2 battery life) before a spreadsheet made it a date.
    assert_eq!(
        robot("unitree-go2").values["battery_life_h"].value,
        Value::Range {
            min: Some(1.0),
            max: Some(2.0)
        }
    );
    assert_eq!(
        robot("unitree-b2").values["battery_life_h"].value,
        Value::Range {
            min: Some(4.0),
            max: Some(6.0)
        }
    );
    // "0.27-0.42" and ".25-.5".
    assert_eq!(
        robot("daisy").values["actuator_mass_kg"].value,
        Value::Range {
            min: Some(0.27),
            max: Some(0.42)
        }
    );
    assert_eq!(
        robot("nimbro-op2").values["battery_life_h"].value,
        Value::Range {
            min: Some(0.25),
            max: Some(0.5)
        }
    );
    // "4 to 5" hours.
    assert_eq!(
        robot("tesla-optimus-gen-2").values["battery_life_h"].value,
        Value::Range {
            min: Some(4.0),
            max: Some(5.0)
        }
    );
    // "Maxon‚Ñ¢" is UTF-8 "™" decoded as Mac Roman.
    assert!(
        robot("nao")
            .text("actuator_name")
            .is_some_and(|s| s.starts_with("Maxon™ coreless")),
        "{:?}",
        robot("nao").text("actuator_name")
    );
    // A battery description in the battery-mass column moves to `battery`.
    assert_eq!(
        robot("unitree-g1").text("battery"),
        Some("13 string lithium battery")
    );
    assert!(!robot("unitree-g1").values.contains_key("battery_mass_kg"));
    // "120 (standing) 40 (walking)" → payload range 40..120 with the text kept.
    assert_eq!(
        robot("unitree-b2").values["payload_kg"].value,
        Value::Range {
            min: Some(40.0),
            max: Some(120.0)
        }
    );
    // Name notes: "(excluded from power laws)" leaves the name and becomes the exclusion reason.
    let thorwin = robot("thorwin");
    assert_eq!(thorwin.name, "ThorwIn");
    assert!(!thorwin.fit);
    // "Tappy " is trimmed; SiLVIA (no leg length) is kept but not fitted.
    assert_eq!(robot("tappy").name, "Tappy");
    assert!(!robot("silvia").fit);
    // Hybrids are kept, not fitted.
    assert_eq!(robot("m4").class, RobotClass::Hybrid);
    assert!(!robot("m4").fit);
}

#[test]
fn import_reproduces_frozen_release_1_0_0_and_the_ledger() {
    let out = common::survey(&[
        "dataset",
        "import-upstream",
        &common::upstream_csv().display().to_string(),
        "--check",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&common::stdout(&out)).expect("json");
    assert_eq!(v["check"]["table_matches"], true, "{}", v["check"]);
    assert_eq!(v["check"]["ledger_matches"], true, "{}", v["check"]);
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn import_writes_records_that_validate_as_1_0_0_and_refuses_to_clobber() {
    let dir = common::dataset_copy();
    let d = dir.path().display().to_string();
    let csv = common::upstream_csv().display().to_string();
    // Existing records may hold corrections: no overwrite without --force, and nothing written.
    let before = std::fs::read(dir.path().join("robots/unitree-h1.toml")).expect("h1");
    let out = common::survey(&["dataset", "import-upstream", &csv, "--dataset", &d]);
    assert_eq!(out.status.code(), Some(2));
    assert!(common::stderr(&out).contains("already exist"));
    assert_eq!(
        std::fs::read(dir.path().join("robots/unitree-h1.toml")).expect("h1"),
        before
    );
    // A fresh import into an empty directory writes 59 canonical records and the ledger.
    let fresh = tempfile::tempdir().expect("tmp");
    let out = common::survey(&[
        "dataset",
        "import-upstream",
        &csv,
        "--dataset",
        &d,
        "--out",
        &fresh.path().display().to_string(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    assert_eq!(
        std::fs::read_dir(fresh.path().join("robots"))
            .expect("robots")
            .count(),
        59
    );
    assert!(fresh.path().join("upstream.toml").is_file());
}

/// Regression: "2-Jan" must not be read as the number 2 or as text.
#[test]
fn regression_spreadsheet_date_is_a_range_not_a_number() {
    let csv = "robot_name,reference,type,year,cost_dollars,total_length_inm,leg_length_inm,min_mass_inkg,max_mass_inkg,average_mass_inkg,normal_speed_inmps,walking_speed_inmps,running_speed_inmps,DOF,payload_inkg,actuator_mass_inkg,accuator_count,highest_stall_torqueorforce_on_actuators_inNm,actuator_name,actuation_type,reported_COT,battery_life_hours,battery_wt_inkg,\n\
               X,[1] https://example.org,quadruped,,,0.7,0.3,,15,15,,,,12,,,,,,motors,,12-Mar,,\n";
    let imp = import(csv.as_bytes(), "inline").expect("import");
    assert_eq!(
        imp.robots[0].values["battery_life_h"].value,
        Value::Range {
            min: Some(3.0),
            max: Some(12.0)
        }
    );
}

#[test]
fn a_file_that_is_not_the_survey_table_is_refused_with_its_name() {
    let err = import(b"a,b\n1,2\n", "other.csv").expect_err("not the survey table");
    let msg = err.to_string();
    assert!(
        msg.contains("other.csv") && msg.contains("missing column"),
        "{msg}"
    );
}

/// Regression: the leading-decimal quirk of a range was reported with a fixed text
/// ("`.25` read as 0.25") whatever the cell held; each end is now reported as read.
#[test]
fn regression_leading_decimal_point_reports_each_end_of_a_range() {
    let imp = imported();
    let hows: Vec<&str> = imp
        .quirks
        .iter()
        .filter(|q| q.kind == "leading-decimal-point" && q.raw == ".25-.5")
        .map(|q| q.handled.as_str())
        .collect();
    // Upstream NimbRo battery life ".25-.5" h: 0.25 and 0.5 by reading.
    assert_eq!(hows, ["`.25` read as 0.25", "`.5` read as 0.5"]);
}
