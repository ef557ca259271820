//! Benchmarks of the survey fit.
//!
//! - `survey_fit_process`: the whole `survey fit` process (start, load the bundled
//!   dataset, fit 15 power laws, print), as a user runs it. Target < 50 ms.
//! - `survey_fit_bootstrap_2000_process`: the same with `--bootstrap 2000` (percentile and
//!   BCa intervals of all 15 exponents).
//! - `power_law_1m`: one OLS power-law fit (with intervals) over 1,000,000 synthetic robots.
//! - `table2_1m`: all 15 Table 2 fits over a synthetic 1,000,000-robot survey table.
//!   Target < 1 s.

use std::collections::BTreeMap;
use std::hint::black_box;
use std::process::Command;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robot_survey::analysis::table2;
use robot_survey::dataset::{RobotClass, SurveyRow, SurveyTable};
use robot_survey::regression::{Method, fit_power_law};

const N: usize = 1_000_000;

/// Synthetic robots on m = 60·L^2.1 and L_B = 1.5·L^0.86 with log-normal scatter.
fn synthetic(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<RobotClass>) {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut leg = Vec::with_capacity(n);
    let mut body = Vec::with_capacity(n);
    let mut mass = Vec::with_capacity(n);
    let mut class = Vec::with_capacity(n);
    for i in 0..n {
        let l: f64 = 10f64.powf(rng.random_range(-1.7..0.1));
        leg.push(l);
        body.push(1.5 * l.powf(0.86) * 10f64.powf(rng.random_range(-0.1..0.1)));
        mass.push(60.0 * l.powf(2.1) * 10f64.powf(rng.random_range(-0.3..0.3)));
        class.push(RobotClass::FITTED[i % 4]);
    }
    (leg, body, mass, class)
}

/// Runs the real binary (from a directory without `dataset/`, so it uses the bundled
/// copy) and returns the length of what it printed.
fn run_survey(exe: &str, args: &[&str]) -> usize {
    let out = Command::new(exe)
        .args(args)
        .current_dir(std::env::temp_dir())
        .output()
        .expect("survey runs");
    assert!(out.status.success());
    out.stdout.len()
}

fn bench(c: &mut Criterion) {
    let exe = env!("CARGO_BIN_EXE_survey");
    let mut g = c.benchmark_group("fit");
    g.measurement_time(Duration::from_secs(8));
    g.bench_function("survey_fit_process", |b| {
        b.iter(|| black_box(run_survey(exe, &["fit", "--format", "json"])))
    });
    // The same with 2000 bootstrap resamples of each of the 15 fits (percentile and BCa,
    // with the jackknife), as `survey fit --bootstrap 2000` is run.
    g.bench_function("survey_fit_bootstrap_2000_process", |b| {
        b.iter(|| {
            black_box(run_survey(
                exe,
                &["fit", "--bootstrap", "2000", "--format", "json"],
            ))
        })
    });
    g.sample_size(10);
    let (leg, body, mass, class) = synthetic(N);
    g.bench_function("power_law_1m", |b| {
        b.iter(|| {
            black_box(
                fit_power_law(&leg, &mass, Method::Ols, 0.95)
                    .expect("fit")
                    .b,
            )
        })
    });
    let rows: Vec<SurveyRow> = (0..N)
        .map(|i| {
            let mut cells = BTreeMap::new();
            cells.insert("leg_length_m".to_string(), leg[i].to_string());
            cells.insert("body_length_m".to_string(), body[i].to_string());
            cells.insert("mass_kg".to_string(), mass[i].to_string());
            SurveyRow {
                id: format!("r{i}"),
                name: format!("R{i}"),
                class: class[i],
                fit: true,
                exclusion: None,
                cells,
            }
        })
        .collect();
    let table = SurveyTable {
        version: "synthetic".into(),
        frozen: false,
        sha256: String::new(),
        columns: vec![],
        rows,
    };
    g.bench_function("table2_1m", |b| {
        b.iter(|| {
            black_box(
                table2::table2(&table, Method::Ols, 0.95)
                    .expect("table2")
                    .fits
                    .len(),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
