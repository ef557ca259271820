//! `survey sim export`, `import` and `bench` as text.

use crate::interop::{Export, Imported};
use crate::study::bench::BenchReport;

/// What an export wrote and where it differs from the design.
pub fn export_text(e: &Export, files: &[String]) -> String {
    let mut out = String::new();
    for f in files {
        out.push_str(&format!("wrote {f}\n"));
    }
    let s = &e.soft_contact;
    out.push_str(&format!(
        "contact: pressure-field bounce on one foot ω = {:.1} rad/s, ζ = {:.3}, sinkage {:.3} mm → MuJoCo solref ({:.4e}, {:.3}), sinkage {:.4} mm, torsional friction {:.3e} m\n",
        s.frequency_rad_s,
        s.damping_ratio,
        s.sinkage_m * 1e3,
        s.timeconst_s,
        s.dampratio,
        s.mujoco_sinkage_m * 1e3,
        s.torsional_m
    ));
    for n in &e.notes {
        out.push_str(&format!("note: {n}\n"));
    }
    out
}

/// The imported design: its size and mass, and the notes on what the import averaged or
/// replaced.
pub fn import_text(i: &Imported) -> String {
    let d = &i.design;
    let from = |tag: &str| {
        i.entries
            .iter()
            .filter(|e| e.source.starts_with(tag))
            .count()
    };
    let mut out = format!(
        "{}: L = {:.4} m, m = {:.4} kg, feet {:.4} × {:.4} × {:.4} m, {} values from the file, {} from the command line, {} defaults\n",
        d.name,
        d.geometry.leg_length_m,
        d.mass.total_mass_kg,
        d.geometry.foot_semi_axes_m[0],
        d.geometry.foot_semi_axes_m[1],
        d.geometry.foot_semi_axes_m[2],
        i.entries.len() - from("[SET]") - from("[DEFAULT]"),
        from("[SET]"),
        from("[DEFAULT]")
    );
    for n in &i.notes {
        out.push_str(&format!("note: {n}\n"));
    }
    out
}

/// Steps per second, single thread and batch, beside the gait.
pub fn bench_text(b: &BenchReport) -> String {
    let g = &b.gait;
    format!(
        "{} at L = {:.4} m, dt = {:.3e} s, {} s per walk\n\
         single thread   {:>10.0} steps/s (best of the repeats; median {:.0}), {:.2} ms per walk\n\
         batch           {:>10.0} steps/s ({} walks on {} threads, {:.3} s)\n\
         gait            walks {}, v = {:.4} m/s, step f = {:.3} Hz, roll / pitch / yaw p-p = {:.2} / {:.2} / {:.2}°\n",
        b.design,
        b.leg_length_m,
        b.time_step_s,
        b.duration_s,
        b.single_best.steps_per_s,
        b.single_median.steps_per_s,
        b.single_best.wall_s * 1e3,
        b.batch.steps_per_s,
        b.batch.walks,
        b.batch.threads,
        b.batch.wall_s,
        g.walks,
        g.velocity_mps,
        g.step_frequency_hz,
        g.roll_pp_deg,
        g.pitch_pp_deg,
        g.yaw_pp_deg
    )
}
