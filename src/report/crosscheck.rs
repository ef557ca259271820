//! The Drake cross-check as Markdown (reports/drake-crosscheck.md's tables).

use crate::crosscheck::Crosscheck;

fn cell(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => super::sig(x),
        _ => "—".into(),
    }
}

fn pct(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{:+.1} %", 100.0 * x),
        _ => "—".into(),
    }
}

/// Elementary cases (project, Drake, analytic, difference) and walks (both engines
/// measured by the project's gait metrics).
pub fn crosscheck_md(c: &Crosscheck) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "Drake {}; project: this build. Walks: both trajectories measured by the project's gait metrics.\n\n",
        c.drake_version.as_deref().unwrap_or("(no goldens found)")
    ));
    out.push_str("Project (convex): the same case with `contact.friction_cone = \"convex\"`, the friction relaxation of Drake's SAP.\n\n");
    out.push_str("| case | quantity | project | project (convex) | Drake | analytic | project − Drake | convex − Drake |\n|---|---|---|---|---|---|---|---|\n");
    for r in &c.elementary {
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.case,
            r.quantity,
            cell(r.project),
            cell(r.project_convex),
            cell(r.drake),
            cell(r.analytic),
            pct(r.relative_difference()),
            pct(r.convex_relative_difference())
        ));
    }
    out.push_str(&format!(
        "\nMuJoCo {}: the design's MJCF export (`survey sim export`) walked by tools/mujoco/, measured by the same code.\n",
        c.mujoco_version.as_deref().unwrap_or("(no goldens found)")
    ));
    out.push_str("\n| walk | engine | walks | v [m/s] | step f [Hz] | roll p-p [°] | pitch p-p [°] | yaw p-p [°] |\n|---|---|---|---|---|---|---|---|\n");
    for w in &c.walks {
        let drake = match &w.drake_approximation {
            Some(a) => format!("Drake ({a})"),
            None => "Drake".to_string(),
        };
        let mut engines = vec![("project", &w.project)];
        if let Some(r) = &w.project_convex {
            engines.push(("project (convex)", r));
        }
        engines.push((drake.as_str(), &w.drake));
        if let Some(m) = &w.mujoco {
            engines.push(("MuJoCo", m));
        }
        for (engine, r) in engines {
            out.push_str(&walk_row(&w.name, engine, r));
        }
    }
    if !c.mujoco_walks.is_empty() {
        out.push_str("\nDesigns Drake's harness does not build (section-cut feet): the project beside MuJoCo.\n\n| walk | engine | walks | v [m/s] | step f [Hz] | roll p-p [°] | pitch p-p [°] | yaw p-p [°] |\n|---|---|---|---|---|---|---|---|\n");
        for w in &c.mujoco_walks {
            for (engine, r) in [
                ("project", &w.project),
                ("project (convex)", &w.project_convex),
                ("MuJoCo", &w.mujoco),
            ] {
                out.push_str(&walk_row(&w.name, engine, r));
            }
        }
    }
    out
}

fn walk_row(name: &str, engine: &str, r: &crate::sim::WalkReport) -> String {
    format!(
        "| {} | {} | {} | {} | {} | {} ± {} | {} ± {} | {} ± {} |\n",
        name,
        engine,
        match (&r.fall_reason, r.walks) {
            (Some(f), _) => format!("fell ({f})"),
            (None, true) => "yes".into(),
            (None, false) => "no".into(),
        },
        cell(Some(r.velocity_mps)),
        cell(Some(r.step_frequency_hz)),
        cell(Some(r.roll_pp_deg)),
        cell(Some(r.roll_pp_deg_sd)),
        cell(Some(r.pitch_pp_deg)),
        cell(Some(r.pitch_pp_deg_sd)),
        cell(Some(r.yaw_pp_deg)),
        cell(Some(r.yaw_pp_deg_sd)),
    )
}

/// `survey sim min-torque` as text.
pub fn min_torque_text(r: &crate::study::MinTorqueResult) -> String {
    let mut out = format!(
        "{} at L = {:.4} m, m = {:.4} kg ({:?}, {:?} contact): m·g·L = {:.4e} N·m\n",
        r.design, r.leg_length_m, r.mass_kg, r.mass_law, r.contact, r.mgl_nm
    );
    match (r.min_torque_nm, r.bracket_nm) {
        (Some(t), Some([lo, hi])) => out.push_str(&format!(
            "minimum torque       {} N·m = {:.4} m·g·L (walks at {}, not at {} N·m)\n",
            super::sig(t),
            t / r.mgl_nm,
            super::sig(hi),
            super::sig(lo)
        )),
        _ => out.push_str("does not walk consistently at any torque up to the cap\n"),
    }
    if let Some(f) = &r.failure_below {
        out.push_str(&format!("just below it        {f}\n"));
    }
    if let Some(g) = &r.gait {
        out.push_str(&format!(
            "gait at the minimum  v = {:.4} m/s, roll {:.1}°, pitch {:.1}°, yaw {:.1}° p-p\n",
            g.velocity_mps, g.roll_pp_deg, g.pitch_pp_deg, g.yaw_pp_deg
        ));
    }
    out.push_str(&format!(
        "walks evaluated      {}\ncriterion            {}\n",
        r.walks_evaluated, r.criterion
    ));
    out
}
