//! The model's own trial-to-trial spread (`gap::discrepancy::model_spread`, counted in every
//! diagnosis' likelihood):
//! the sd of a condition's metrics over walks from perturbed starts, checked against walks
//! made independently through the simulator's API, and exactly zero when the design's
//! start is not perturbed.

use robot_survey::gap::cache::SimCache;
use robot_survey::gap::discrepancy::model_spread;
use robot_survey::gap::knob::ModelSetting;
use robot_survey::gap::simulate::resolve;
use robot_survey::gap::trials::Metric;
use robot_survey::gap::{EffectLibrary, TrialSet};
use robot_survey::sim::{WalkOptions, simulate_walk};

use crate::common::repo;

const TRIAL: &str = "label,design,leg_length_m,source\nA,DESIGN,0.0247,hand\n";

#[test]
fn the_model_spread_is_the_sd_of_walks_from_perturbed_starts() {
    let lib = EffectLibrary::bundled().expect("library");
    let set = TrialSet::parse(
        &TRIAL.replace("DESIGN", "zippy"),
        "t.csv",
        std::path::Path::new("."),
    )
    .expect("trials");
    let conditions = resolve(&set).expect("conditions");
    let spread = model_spread(
        &conditions,
        &lib,
        &ModelSetting::nominal(),
        3,
        &SimCache::default(),
    )
    .expect("walks");

    // Independently: the design at the condition walked through the simulator's API for the
    // diagnosis' 16 drive cycles, from the unperturbed start and from seeds 1, 2, 3; the
    // sample sd (n − 1) of each metric by hand.
    let d = conditions[0]
        .design_with(&lib, &ModelSetting::nominal())
        .expect("design");
    let f = d.controller().frequency_hz().expect("a periodic drive");
    let runs: Vec<_> = [None, Some(1), Some(2), Some(3)]
        .into_iter()
        .map(|seed| {
            let opts = WalkOptions {
                duration_s: 16.0 / f,
                seed,
                record_trajectory: false,
                ..WalkOptions::default()
            };
            simulate_walk(&d, &opts).expect("walk").report
        })
        .collect();
    assert!(runs.iter().all(|r| r.fall_reason.is_none()), "Zippy walks");
    let mut some_spread = false;
    for m in Metric::simulated() {
        let v: Vec<f64> = runs.iter().map(|r| m.of_report(r)).collect();
        let mean = v.iter().sum::<f64>() / 4.0;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 3.0).sqrt();
        let got = spread[0][m.index()];
        assert!(
            (got - sd).abs() <= 1e-12 * sd.max(1e-300),
            "{}: {got} vs {sd}",
            m.column()
        );
        some_spread |= sd > 1e-6 * mean.abs();
    }
    // Zippy's bang-bang gait is irregular: its summaries remember the start.
    assert!(some_spread, "Zippy's metrics should depend on the start");
}

#[test]
fn an_unperturbed_start_has_no_spread() {
    let dir = tempfile::tempdir().expect("tempdir");
    let zippy =
        std::fs::read_to_string(repo().join("dataset/walkers/zippy.toml")).expect("zippy.toml");
    let still = zippy
        .replace("seed_angle_sd_deg = 0.5", "seed_angle_sd_deg = 0.0")
        .replace(
            "seed_rate_sd_over_sqrt_g_over_l = 0.02",
            "seed_rate_sd_over_sqrt_g_over_l = 0.0",
        );
    assert_ne!(
        still, zippy,
        "zippy.toml's seed table changed: update this test"
    );
    std::fs::write(dir.path().join("still.toml"), still).expect("write");
    let lib = EffectLibrary::bundled().expect("library");
    let set = TrialSet::parse(&TRIAL.replace("DESIGN", "still.toml"), "t.csv", dir.path())
        .expect("trials");
    let conditions = resolve(&set).expect("conditions");
    // Every seed then starts from the same state: the same walk, bit for bit.
    let spread = model_spread(
        &conditions,
        &lib,
        &ModelSetting::nominal(),
        2,
        &SimCache::default(),
    )
    .expect("walks");
    assert_eq!(spread[0], vec![0.0; 8]);
}
