//! The live records: valid, canonical, with an up-to-date data package and intact releases.

use crate::common;

use robot_survey::dataset::{Dataset, DatasetFiles, Severity, canonical, validate::validate};

fn live() -> Dataset {
    Dataset::load(DatasetFiles::from_dir(&common::repo().join("dataset")).expect("read dataset"))
        .expect("load")
}

#[test]
fn live_records_validate_without_errors() {
    let rep = validate(&live());
    let errors: Vec<String> = rep
        .problems
        .iter()
        .filter(|p| p.severity == Severity::Error)
        .map(|p| p.to_line())
        .collect();
    assert!(errors.is_empty(), "{}", errors.join("\n"));
    assert!(rep.records >= 59);
}

#[test]
fn every_record_is_canonical() {
    let rep = canonical::fmt(&live(), true).expect("fmt --check");
    assert!(
        rep.changed.is_empty() && rep.unparsable.is_empty(),
        "{:?} {:?}",
        rep.changed,
        rep.unparsable
    );
}

#[test]
fn bundled_dataset_equals_the_checkout() {
    let disk = DatasetFiles::from_dir(&common::repo().join("dataset")).expect("read");
    let bundled = DatasetFiles::bundled();
    assert_eq!(
        disk.files, bundled.files,
        "rebuild: the binary bundles a stale dataset"
    );
}

/// The live records are the released 1.1.0 table.
#[test]
fn live_records_compile_to_the_latest_release() {
    let ds = live();
    let live = ds.table(None).expect("live table");
    let frozen = ds
        .table(Some(&ds.meta.version))
        .expect("release of the live version");
    assert_eq!(live.sha256, frozen.sha256);
}

#[test]
fn every_fitted_value_has_a_source() {
    let ds = live();
    for (_, r) in ds.robots.iter().filter(|(_, r)| r.fit) {
        for f in ["leg_length_m", "body_length_m", "mass_kg"] {
            let d = &r.values[f];
            assert!(!d.sources.is_empty(), "{} {f}", r.id);
            for k in &d.sources {
                assert!(
                    r.sources.iter().any(|s| &s.key == k),
                    "{} {f} cites unknown {k}",
                    r.id
                );
            }
        }
    }
}
