//! The gap diagnosis as Markdown and figures.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::plot::{PlotError, register_font};
use super::sig;
use crate::gap::benchmark::BenchmarkResult;
use crate::gap::diagnose::Diagnosis;
use crate::gap::library::EffectSummary;
use crate::gap::trials::Metric;

/// `survey gap effects` as text.
pub fn effects_text(list: &[EffectSummary], design: &str) -> String {
    let mut out = format!("Candidate unmodelled effects (SI values for {design} at 1×)\n\n");
    for e in list {
        let _ = writeln!(out, "{}: {}", e.name, e.description);
        let _ = writeln!(out, "  models:  {}", e.models);
        let _ = writeln!(out, "  scaling: {}", e.scaling);
        for p in &e.params {
            let _ = writeln!(
                out,
                "  {} [{}]: default {}, plausible {} … {}, off {}{}",
                p.name,
                p.unit,
                sig(p.default),
                sig(p.min),
                sig(p.max),
                sig(p.off),
                if p.scale.is_empty() {
                    String::new()
                } else {
                    format!(" (range written in {} = {})", p.scale, sig(p.scale_value))
                }
            );
        }
        out.push('\n');
    }
    out
}

fn opt(v: Option<f64>) -> String {
    v.map(sig).unwrap_or_else(|| "–".into())
}

/// `survey gap diagnose` as Markdown.
pub fn diagnosis_md(d: &Diagnosis) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "# Gap diagnosis: {}\n", d.trials);
    let _ = writeln!(
        o,
        "{} trials, {} observations. Nominal gap: RMS z = {:.2} (χ² = {:.1}, p = {:.2e}{}).\n",
        d.n_trials,
        d.n_observations,
        d.gap_before,
        d.chi2_before,
        d.p_value_before,
        if d.within_noise {
            ", within noise"
        } else {
            ", beyond noise"
        }
    );
    let _ = writeln!(o, "**Where:** {}.\n", d.summary);
    let _ = writeln!(o, "**Verdict:** {}.\n", d.verdict);
    let _ = writeln!(o, "## Where the gap lies\n");
    let _ = writeln!(
        o,
        "| metric | n | RMS z | mean miss | p | trend per doubling of L | per doubling of f | RMS z after |"
    );
    let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|---:|");
    let tr = |t: &Option<crate::gap::diagnose::Trend>| match t {
        Some(t) => format!(
            "{:+.0} ± {:.0} pts",
            t.slope * std::f64::consts::LN_2 * 100.0,
            t.se * std::f64::consts::LN_2 * 100.0
        ),
        None => "–".into(),
    };
    for g in &d.where_ {
        let _ = writeln!(
            o,
            "| {} | {} | {:.2} | {:+.1} % | {:.2e} | {} | {} | {} |",
            g.metric.column(),
            g.n,
            g.rms_z,
            g.mean_relative_pct,
            g.p_value,
            tr(&g.trend_with_leg_length),
            tr(&g.trend_with_frequency),
            g.rms_z_after
                .map(|v| format!("{v:.2}"))
                .unwrap_or("–".into())
        );
    }
    let _ = writeln!(o, "\n## Which effect\n");
    let _ = writeln!(
        o,
        "Ranked by held-out χ²/n (leave one condition out) plus a BIC penalty; significant = \
         likelihood-ratio p below α/K and a held-out gap below the nominal's.\n"
    );
    let _ = writeln!(
        o,
        "| effect | fitted | held-out gap | shrink | score | LR | p | significant |"
    );
    let _ = writeln!(o, "|---|---|---:|---:|---:|---:|---:|---|");
    for r in &d.ranking {
        let params = match r.magnitude_nondimensional {
            Some(_) => r
                .params
                .iter()
                .map(|(k, v)| format!("{k} = {}", sig(*v)))
                .collect::<Vec<_>>()
                .join(", "),
            None => "off (nominal fits best)".into(),
        };
        let _ = writeln!(
            o,
            "| {} | {} | {:.2} | {:.0} % | {:.3} | {:.1} | {:.1e} | {} |",
            r.effect,
            params,
            r.gap_after,
            r.shrink_pct,
            r.score,
            r.lr,
            r.p_value,
            if r.significant { "yes" } else { "no" }
        );
    }
    if let Some(b) = &d.best {
        let _ = writeln!(o, "\n**Best: {}**", b.effect);
        for (k, v) in &b.params {
            let ci = b
                .params_ci
                .get(k)
                .map(|[lo, hi]| format!(" (95 % interval {} – {})", sig(*lo), sig(*hi)))
                .unwrap_or_default();
            let _ = writeln!(o, "- {k} = {}{ci}", sig(*v));
        }
        let _ = writeln!(
            o,
            "- held-out gap {:.2} → {:.2}, {:.0} % smaller (in-sample {:.2}){}",
            d.gap_before,
            b.gap_after,
            b.shrink_pct,
            b.gap_after_in_sample,
            if b.ci_at_range_edge {
                "; the interval reaches the end of the plausible range"
            } else {
                ""
            }
        );
    }
    let _ = writeln!(o, "\n## Identifiability with these trials\n");
    let _ = writeln!(
        o,
        "| effect | parameter | detected from | identified from | closest mimic | shows in |"
    );
    let _ = writeln!(o, "|---|---|---:|---:|---|---|");
    for i in &d.identifiability {
        let _ = writeln!(
            o,
            "| {} | {} [{}] | {} | {} | {} | {} |",
            i.effect,
            i.parameter,
            i.unit,
            opt(i.detection_threshold),
            opt(i.identification_threshold),
            i.closest_mimic.clone().unwrap_or_else(|| "–".into()),
            i.identifiable_from
                .iter()
                .map(|m| m.column())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if !d.notes.is_empty() {
        let _ = writeln!(o, "\nNotes:");
        for n in &d.notes {
            let _ = writeln!(o, "- {n}");
        }
    }
    let _ = writeln!(o, "\n## Residuals\n");
    let _ = writeln!(
        o,
        "| trial | design | L [m] | f [Hz] | metric | measured | sd | simulated | z | after | z after |"
    );
    let _ = writeln!(o, "|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|");
    for r in &d.residuals {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} | {}{} | {} | {} | {} | {} |",
            r.label,
            r.design,
            sig(r.leg_length_m),
            sig(r.frequency_hz),
            r.metric.column(),
            sig(r.measured),
            sig(r.sd),
            if r.sd_assumed { " (assumed)" } else { "" },
            opt(r.simulated),
            r.z.map(|z| format!("{z:+.1}")).unwrap_or("fell".into()),
            opt(r.simulated_after),
            r.z_after.map(|z| format!("{z:+.1}")).unwrap_or("–".into()),
        );
    }
    o
}

fn metric_color(m: Metric) -> RGBColor {
    match m {
        Metric::VelocityMps => RGBColor(31, 119, 180),
        Metric::StepFrequencyHz => RGBColor(255, 127, 14),
        Metric::RollPpDeg => RGBColor(44, 160, 44),
        Metric::PitchPpDeg => RGBColor(214, 39, 40),
        Metric::YawPpDeg => RGBColor(148, 103, 189),
        Metric::PeakTorqueNm => RGBColor(140, 86, 75),
        Metric::MinTorqueNm => RGBColor(127, 127, 127),
        Metric::Cot => RGBColor(23, 190, 207),
    }
}

/// Standardised residuals per condition and metric, before (left) and after the best
/// effect (right); ±2 marked. SVG or PNG by extension.
pub fn residual_plot(d: &Diagnosis, path: &Path) -> Result<(), PlotError> {
    register_font();
    let err = |m: String| PlotError {
        path: path.display().to_string(),
        message: m,
    };
    let size = (1200, 520);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "png" {
        draw_residuals(BitMapBackend::new(path, size).into_drawing_area(), d).map_err(err)
    } else {
        draw_residuals(SVGBackend::new(path, size).into_drawing_area(), d).map_err(err)
    }
}

fn draw_residuals<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    d: &Diagnosis,
) -> Result<(), String> {
    {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let panels = root.split_evenly((1, 2));
        let n = d.n_trials.max(1) as f64;
        for (k, area) in panels.iter().enumerate() {
            let after = k == 1;
            let zs: Vec<(f64, f64, Metric)> = d
                .residuals
                .iter()
                .filter_map(|r| {
                    let z = if after { r.z_after } else { r.z };
                    z.map(|z| (r.trial as f64, z, r.metric))
                })
                .collect();
            let zmax = zs
                .iter()
                .map(|z| z.1.abs())
                .fold(3.0f64, f64::max)
                .min(60.0)
                * 1.1;
            let title = if after {
                match &d.best {
                    Some(b) => format!("after: + {} (held-out RMS z {:.2})", b.effect, b.gap_after),
                    None => "after: no effect called".to_string(),
                }
            } else {
                format!("nominal model (RMS z {:.2})", d.gap_before)
            };
            let mut chart = ChartBuilder::on(area)
                .caption(title, ("sans-serif", 18))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(50)
                .build_cartesian_2d(-0.5..(n - 0.5), -zmax..zmax)
                .map_err(|e| e.to_string())?;
            chart
                .configure_mesh()
                .x_desc("trial (row of the trials file)")
                .y_desc("z = (simulated − measured)/sd")
                .label_style(("sans-serif", 13))
                .draw()
                .map_err(|e| e.to_string())?;
            for y in [-2.0, 2.0] {
                chart
                    .draw_series(LineSeries::new(
                        vec![(-0.5, y), (n - 0.5, y)],
                        BLACK.mix(0.4).stroke_width(1),
                    ))
                    .map_err(|e| e.to_string())?;
            }
            for m in Metric::ALL {
                let pts: Vec<(f64, f64)> = zs
                    .iter()
                    .filter(|z| z.2 == m)
                    .map(|z| {
                        // Spread the metrics of a trial side by side.
                        (
                            z.0 + (m.index() as f64 - 3.5) * 0.08,
                            z.1.clamp(-zmax, zmax),
                        )
                    })
                    .collect();
                if pts.is_empty() {
                    continue;
                }
                let c = metric_color(m);
                chart
                    .draw_series(pts.iter().map(|p| Circle::new(*p, 4, c.filled())))
                    .map_err(|e| e.to_string())?
                    .label(m.column())
                    .legend(move |(x, y)| Circle::new((x + 8, y), 4, c.filled()));
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 12))
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())
    }
}

/// The benchmark as Markdown.
pub fn benchmark_md(b: &BenchmarkResult) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# Gap-diagnosis benchmark ({}, {} conditions, {} seeds per case, {} null cases per noise level)\n",
        b.design, b.conditions, b.seeds, b.null_seeds
    );
    let _ = writeln!(
        o,
        "Generated by `survey gap benchmark` ({} walks, {:.0} s, {:.1} s per diagnosis).\n",
        b.walks, b.seconds, b.seconds_per_diagnosis
    );
    let _ = writeln!(o, "## Summary per noise level\n");
    let _ = writeln!(
        o,
        "| noise | correct above threshold | false alarms | interval coverage | median \\|ln(fit/true)\\| | median shrink |"
    );
    let _ = writeln!(o, "|---:|---:|---:|---:|---:|---:|");
    for c in &b.confusion {
        let _ = writeln!(
            o,
            "| {:.0} % | {:.0} % ({} cases) | {} / {} | {:.0} % | {:.3} | {:.0} % |",
            c.noise * 100.0,
            c.identification_rate_above_threshold * 100.0,
            c.cases_above_threshold,
            c.false_alarms,
            c.null_cases,
            c.coverage * 100.0,
            c.median_log_error,
            c.median_shrink_pct
        );
    }
    let _ = writeln!(o, "\n## Thresholds (SI, {} at 1×)\n", b.design);
    let _ = writeln!(
        o,
        "Detection: the likelihood-ratio test finds the effect with 90 % power at the noise level. \
         Identification: the effect is also told from its closest mimic with 90 % probability.\n"
    );
    let _ = writeln!(
        o,
        "| effect | noise | parameter | detected from | identified from | closest mimic | shows in |"
    );
    let _ = writeln!(o, "|---|---:|---|---:|---:|---|---|");
    for t in &b.thresholds {
        let i = &t.identifiability;
        let _ = writeln!(
            o,
            "| {} | {:.0} % | {} [{}] | {} | {} | {} | {} |",
            i.effect,
            t.noise * 100.0,
            i.parameter,
            i.unit,
            opt(i.detection_threshold),
            opt(i.identification_threshold),
            i.closest_mimic.clone().unwrap_or("–".into()),
            i.identifiable_from
                .iter()
                .map(|m| m.column())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    for c in &b.confusion {
        let _ = writeln!(
            o,
            "\n## Confusion at {:.0} % noise (rows: true effect, above threshold, and null; columns: called)\n",
            c.noise * 100.0
        );
        let _ = write!(o, "| true \\ called |");
        for l in &c.labels {
            let _ = write!(o, " {l} |");
        }
        let _ = writeln!(o);
        let _ = write!(o, "|---|");
        for _ in &c.labels {
            let _ = write!(o, "---:|");
        }
        let _ = writeln!(o);
        for (l, row) in c.labels.iter().zip(&c.counts) {
            let name = if l == "none" { "null (no effect)" } else { l };
            let _ = write!(o, "| {name} |");
            for v in row {
                let _ = write!(o, " {v} |");
            }
            let _ = writeln!(o);
        }
    }
    let _ = writeln!(o, "\n## Cases\n");
    let _ = writeln!(
        o,
        "| noise | true | ×thr | magnitude | above | called | fitted | interval | covered | shrink |"
    );
    let _ = writeln!(o, "|---:|---|---:|---:|---|---|---:|---|---|---:|");
    for c in &b.cases {
        let _ = writeln!(
            o,
            "| {:.0} % | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.noise * 100.0,
            c.true_effect.clone().unwrap_or("null".into()),
            c.multiple.map(|m| format!("{m}")).unwrap_or("–".into()),
            opt(c.magnitude),
            if c.above_threshold { "yes" } else { "no" },
            c.called.clone().unwrap_or("none".into()),
            opt(c.fitted),
            c.ci.map(|[a, b]| format!("{} – {}", sig(a), sig(b)))
                .unwrap_or("–".into()),
            c.covered
                .map(|v| if v { "yes" } else { "no" })
                .unwrap_or("–"),
            c.shrink_pct
                .map(|s| format!("{s:.0} %"))
                .unwrap_or("–".into())
        );
    }
    o
}

/// Confusion matrices as heat maps, one panel per noise level.
pub fn confusion_plot(b: &BenchmarkResult, path: &Path) -> Result<(), PlotError> {
    register_font();
    let err = |m: String| PlotError {
        path: path.display().to_string(),
        message: m,
    };
    let n = b.confusion.len().max(1) as u32;
    let root = SVGBackend::new(path, (520 * n, 560)).into_drawing_area();
    let draw = || -> Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let panels = root.split_evenly((1, n as usize));
        for (c, area) in b.confusion.iter().zip(panels.iter()) {
            let k = c.labels.len();
            let mut chart = ChartBuilder::on(area)
                .caption(
                    format!(
                        "{:.0} % noise: {:.0} % correct, {} false alarms",
                        c.noise * 100.0,
                        c.identification_rate_above_threshold * 100.0,
                        c.false_alarms
                    ),
                    ("sans-serif", 16),
                )
                .margin(10)
                .x_label_area_size(150)
                .y_label_area_size(150)
                .build_cartesian_2d(0..k, 0..k)
                .map_err(|e| e.to_string())?;
            let labels = c.labels.clone();
            let labels2 = c.labels.clone();
            chart
                .configure_mesh()
                .disable_mesh()
                .x_labels(k)
                .y_labels(k)
                .x_label_formatter(&|i| labels.get(*i).cloned().unwrap_or_default())
                .y_label_formatter(&|i| {
                    labels2
                        .get(k - 1 - (*i).min(k - 1))
                        .cloned()
                        .unwrap_or_default()
                })
                .x_label_style(
                    ("sans-serif", 11)
                        .into_font()
                        .transform(FontTransform::Rotate90),
                )
                .y_label_style(("sans-serif", 11))
                .x_desc("called")
                .y_desc("true")
                .draw()
                .map_err(|e| e.to_string())?;
            for (i, row) in c.counts.iter().enumerate() {
                let total: usize = row.iter().sum();
                for (j, v) in row.iter().enumerate() {
                    let share = if total > 0 {
                        *v as f64 / total as f64
                    } else {
                        0.0
                    };
                    let y = k - 1 - i;
                    let color = if i == j {
                        RGBColor(44, 160, 44)
                    } else {
                        RGBColor(214, 39, 40)
                    };
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(j, y), (j + 1, y + 1)],
                            color.mix(share * 0.9).filled(),
                        )))
                        .map_err(|e| e.to_string())?;
                    if *v > 0 {
                        chart
                            .draw_series(std::iter::once(Text::new(
                                format!("{v}"),
                                (j, y + 1),
                                ("sans-serif", 12),
                            )))
                            .map_err(|e| e.to_string())?;
                    }
                }
            }
        }
        root.present().map_err(|e| e.to_string())
    };
    draw().map_err(err)
}
