//! Walker simulation speed: one 25 s walk per bundled design (single thread). Reports the
//! wall time per walk; steps/s and simulated seconds per wall second follow from the
//! design's time step (printed once before the benchmark).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use robot_survey::sim::{Design, WalkOptions, simulate_walk};

fn bench_walks(c: &mut Criterion) {
    let opts = WalkOptions {
        duration_s: 25.0,
        record_trajectory: false,
        ..WalkOptions::default()
    };
    let mut group = c.benchmark_group("walk_25s");
    group.sample_size(20);
    for name in ["mugatu", "zippy", "zippy-spherical"] {
        let Ok(design) = Design::builtin(name) else {
            continue;
        };
        let steps = (opts.duration_s / design.numerics.time_step_s).round();
        let t0 = std::time::Instant::now();
        let ok = simulate_walk(&design, &opts).is_ok();
        let wall = t0.elapsed().as_secs_f64();
        println!(
            "{name}: {steps} steps, {:.0} steps/s, {:.0} simulated s per wall s (ok = {ok}; a fall ends the run early)",
            steps / wall,
            opts.duration_s / wall
        );
        group.bench_function(name, |b| {
            b.iter(|| simulate_walk(black_box(&design), black_box(&opts)))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_walks);
criterion_main!(benches);
