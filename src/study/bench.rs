//! `survey sim bench`: how fast the simulator walks a design, on one thread and in a batch
//! on every core, with the gait it walked (a speed without the gait is no comparison). The
//! paired benchmark (`tools/mujoco/bench.py`) runs it beside MuJoCo and Drake on the design's
//! export, same model and time step.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::sim::{Design, SimError, WalkOptions, WalkReport, simulate_walk};

/// What to time.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// The walk (size, mass law, contact scaling, duration); the trajectory is not kept.
    pub walk: WalkOptions,
    /// Single-thread runs of the unperturbed walk; the best and the median are reported.
    pub repeats: usize,
    /// Independent walks of the batch (seeds 1..=N).
    pub batch_walks: usize,
    /// Threads of the batch (None: every core).
    pub threads: Option<usize>,
}

/// Wall time of a run and the steps it simulated.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    pub walks: usize,
    pub threads: usize,
    pub steps: u64,
    pub wall_s: f64,
    pub steps_per_s: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    pub design: String,
    pub leg_length_m: f64,
    pub time_step_s: f64,
    pub duration_s: f64,
    /// The best of the single-thread repeats, and their median.
    pub single_best: Timing,
    pub single_median: Timing,
    pub batch: Timing,
    /// The unperturbed walk's gait.
    pub gait: WalkReport,
}

/// Steps a walk simulated (to its fall, if it fell).
fn steps_of(r: &WalkReport) -> u64 {
    let t = r.fell_at_s.unwrap_or(r.duration_s);
    (t / r.time_step_s).round() as u64
}

/// Times the design's walk on one thread (`repeats` times) and a batch of seeded walks on
/// `threads` (every core by default).
pub fn bench(design: &Design, opts: &BenchOptions) -> Result<BenchReport, SimError> {
    let walk = WalkOptions {
        record_trajectory: false,
        seed: None,
        ..opts.walk.clone()
    };
    let mut single = Vec::new();
    let mut gait = None;
    for _ in 0..opts.repeats.max(1) {
        let t0 = Instant::now();
        let r = simulate_walk(design, &walk)?.report;
        let wall = t0.elapsed().as_secs_f64();
        let steps = steps_of(&r);
        single.push(Timing {
            walks: 1,
            threads: 1,
            steps,
            wall_s: wall,
            steps_per_s: steps as f64 / wall,
        });
        gait = Some(r);
    }
    single.sort_by(|a, b| a.wall_s.total_cmp(&b.wall_s));
    let best = single[0].clone();
    let median = single[single.len() / 2].clone();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| SimError::InvalidOption {
            option: "threads".into(),
            reason: e.to_string(),
        })?;
    let n = opts.batch_walks.max(1);
    let t0 = Instant::now();
    let reports: Result<Vec<WalkReport>, SimError> = pool.install(|| {
        (1..=n as u64)
            .into_par_iter()
            .map(|seed| {
                let o = WalkOptions {
                    seed: Some(seed),
                    ..walk.clone()
                };
                simulate_walk(design, &o).map(|r| r.report)
            })
            .collect()
    });
    let wall = t0.elapsed().as_secs_f64();
    let steps: u64 = reports?.iter().map(steps_of).sum();
    let gait = gait.ok_or_else(|| SimError::InvalidOption {
        option: "repeats".into(),
        reason: "no walk ran".into(),
    })?;
    Ok(BenchReport {
        design: gait.design.clone(),
        leg_length_m: gait.leg_length_m,
        time_step_s: gait.time_step_s,
        duration_s: gait.duration_s,
        single_best: best,
        single_median: median,
        batch: Timing {
            walks: n,
            threads: pool.current_num_threads(),
            steps,
            wall_s: wall,
            steps_per_s: steps as f64 / wall,
        },
        gait,
    })
}
