//! The gap diagnosis as Markdown and figures.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::plot::{PlotError, register_font};
use super::sig;
use crate::gap::decide::{AnswerKind, Named};
use crate::gap::diagnose::Diagnosis;
use crate::gap::explore::{Exploration, PLAUSIBLE_P};
use crate::gap::knob::KnobKind;
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
    let cycles = if d.n_cycle_observations > 0 {
        format!(
            " ({} of them Fourier coefficients of logged cycles)",
            d.n_cycle_observations
        )
    } else {
        String::new()
    };
    let _ = writeln!(
        o,
        "{} trials, {} observations{cycles}. The nominal model misses them by RMS z = {:.2} \
         (χ² = {:.1}).\n",
        d.n_trials, d.n_observations, d.gap_before, d.chi2_before,
    );
    let _ = writeln!(o, "**Where:** {}.\n", d.summary);
    let _ = writeln!(
        o,
        "**Answer ({}):** {}.\n",
        answer_kind(d.answer.kind),
        d.answer.statement
    );
    explanations_md(&mut o, d);
    where_md(&mut o, d);
    spread_md(&mut o, d);
    detectable_md(&mut o, d);
    if !d.notes.is_empty() {
        let _ = writeln!(o, "\nNotes:");
        for n in &d.notes {
            let _ = writeln!(o, "- {n}");
        }
    }
    residuals_md(&mut o, d);
    o
}

/// The answer kinds in words.
pub fn answer_kind(k: AnswerKind) -> &'static str {
    match k {
        AnswerKind::NoGap => "no gap",
        AnswerKind::ParametersOff => "parameters off",
        AnswerKind::EffectMissing => "effect missing",
        AnswerKind::Both => "parameters off and effect missing",
        AnswerKind::Unexplained => "unexplained",
        AnswerKind::Ambiguous => "ambiguous",
    }
}

/// A probability as the report prints it.
pub fn probability(p: f64) -> String {
    if (0.995..1.0).contains(&p) {
        format!("{p:.3}")
    } else if p < 0.005 && p > 0.0 {
        format!("{p:.0e}")
    } else {
        format!("{p:.2}")
    }
}

/// Knobs with values and intervals: `knob = v [lo, hi] unit`.
pub fn named_values(named: &[Named]) -> String {
    named
        .iter()
        .map(|n| {
            format!(
                "{} = {}{} [{}, {}]{}",
                n.knob,
                if n.sign_identified { "" } else { "±" },
                sig(n.value),
                sig(n.interval[0]),
                sig(n.interval[1]),
                if n.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", n.unit)
                }
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn explanations_md(o: &mut String, d: &Diagnosis) {
    let _ = writeln!(o, "## Explanations, by posterior probability\n");
    let _ = writeln!(
        o,
        "{} explanations weighed, {} confirmed by walks at their most probable point. Values: \
         most probable, with the 95 % credible interval. A name needs probability ≥ {}; \
         nothing fits when even the most probable explanation's posterior-predictive p < {}.\n",
        d.weighed, d.confirmed, d.criterion.decision.threshold, d.criterion.decision.fit_level
    );
    let _ = writeln!(
        o,
        "| explanation | probability | prior | values | χ² at the mode | fit p |"
    );
    let _ = writeln!(o, "|---|---:|---:|---|---:|---:|");
    for e in &d.explanations {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {}{} | {:.2e} |",
            e.explanation,
            probability(e.probability),
            sig(e.prior),
            if e.knobs.is_empty() {
                "–".to_string()
            } else {
                named_values(&e.knobs)
            },
            sig(e.chi2),
            if e.walked { "" } else { " (surrogate)" },
            e.fit_p
        );
    }
    let _ = writeln!(
        o,
        "| something outside these | {} | {} | – | – | – |",
        probability(d.answer.outside),
        sig(d.criterion.prior.none_of_these)
    );
}

fn where_md(o: &mut String, d: &Diagnosis) {
    let _ = writeln!(o, "\n## Where the gap lies\n");
    let _ = writeln!(
        o,
        "| metric | n | RMS z | mean miss | p | trend per doubling of L | per doubling of f | RMS z after |"
    );
    let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|---:|");
    let tr = |t: &Option<crate::gap::locate::Trend>| match t {
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
                .unwrap_or_else(|| "–".into())
        );
    }
}

fn spread_md(o: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        o,
        "\n## The model's own spread\n\nThe simulator walked again from {} perturbed starts at \
         every condition; its spread counts beside each measurement's sd.\n",
        crate::gap::discrepancy::STARTS
    );
    let _ = writeln!(
        o,
        "| block | observations | RMS model sd / measurement sd | largest |"
    );
    let _ = writeln!(o, "|---|---:|---:|---:|");
    for b in &d.spread {
        let _ = writeln!(
            o,
            "| {} | {} | {:.2} | {:.2} |",
            b.block.words(),
            b.observations,
            b.rms_ratio,
            b.max_ratio
        );
    }
}

fn detectable_md(o: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        o,
        "\n## What these trials can detect\n\nThe value nearest the design's (or the effect's \
         absence) at which a suspect alone moves the predictions by one standard deviation in \
         all; smaller changes are not an explanation these trials can tell from nothing.\n"
    );
    let _ = writeln!(o, "| suspect | kind | detectable from |");
    let _ = writeln!(o, "|---|---|---:|");
    for k in &d.detectable {
        let kind = match k.kind {
            KnobKind::Parameter => "declared parameter",
            KnobKind::Effect => "effect",
            KnobKind::Undeclared => "undeclared number",
        };
        let from = match k.from {
            Some(v) => format!(
                "{}{}",
                sig(v),
                if k.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", k.unit)
                }
            ),
            None => "not in its range".into(),
        };
        let _ = writeln!(o, "| {} | {kind} | {from} |", k.knob);
    }
}

fn residuals_md(o: &mut String, d: &Diagnosis) {
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

/// Standardised residuals per condition and metric, before (left) and after the chain's
/// model (right); ±2 marked. SVG or PNG by extension.
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
                match d.explanations.first() {
                    Some(e) if !e.knobs.is_empty() => format!(
                        "after: {} (probability {})",
                        e.explanation,
                        probability(e.probability)
                    ),
                    _ => "after: nothing changed".to_string(),
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

/// An exploration of the uncertain parameters as markdown.
pub fn exploration_md(e: &Exploration) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# Exploration of the uncertain parameters: {}\n",
        e.origin
    );
    let _ = writeln!(
        o,
        "{} settings (Latin hypercube over every declared [[uncertain]] range, seed {}), {} \
         measurements, {} walks. Plausible: χ² p ≥ {PLAUSIBLE_P} ({} df).\n",
        e.samples, e.seed, e.observations, e.walks, e.observations
    );
    let verdict = exploration_verdict(e);
    let _ = writeln!(o, "{verdict}\n");
    exploration_metrics_md(&mut o, e);
    exploration_parameters_md(&mut o, e);
    if !e.notes.is_empty() {
        let _ = writeln!(o, "\nNotes:");
        for n in &e.notes {
            let _ = writeln!(o, "- {n}");
        }
    }
    o
}

/// Writes the verdict sentence: how many sampled settings fit the trials.
fn exploration_verdict(e: &Exploration) -> String {
    if e.plausible > 0 {
        format!(
            "**{} of {} sampled settings fit the trials within noise** (nominal χ² = {}, best χ² = {}, p = {:.2}).",
            e.plausible,
            e.samples,
            sig(e.nominal_chi2),
            sig(e.best_chi2),
            e.best_p
        )
    } else if e.too_sparse {
        format!(
            "**Cannot tell: every sampled setting fits worse than the file's values** (nominal χ² = \
             {}{}, best of {} samples χ² = {}): the sample is too sparse for these trials; use \
             `survey gap diagnose` (a local fit) or more samples.",
            sig(e.nominal_chi2),
            if e.nominal_plausible {
                ", within noise"
            } else {
                ""
            },
            e.samples,
            sig(e.best_chi2)
        )
    } else {
        format!(
            "**None of the {} sampled settings fits the trials within noise** (nominal χ² = {}, \
             best χ² = {}, p = {:.1e}): either a parameter lies outside its declared range, a \
             parameter not declared uncertain is off, or the model lacks an effect — unless the \
             settings that fit lie between the samples (the reach below is what the sample \
             attains, a lower bound on the box's).",
            e.samples,
            sig(e.nominal_chi2),
            sig(e.best_chi2),
            e.best_p
        )
    }
}

/// Writes the table of what each measurement can reach.
fn exploration_metrics_md(o: &mut String, e: &Exploration) {
    let _ = writeln!(o, "## What each measurement can reach\n");
    let _ = writeln!(
        o,
        "| trial | metric | measured | sd | nominal | lowest – highest over the sample | best setting | reachable by the sample |"
    );
    let _ = writeln!(o, "|---|---|---:|---:|---:|---|---:|---|");
    for m in &e.metrics {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} – {} | {} | {} |",
            m.trial,
            m.metric.column(),
            sig(m.measured),
            sig(m.sd),
            sig(m.nominal),
            sig(m.reach[0]),
            sig(m.reach[1]),
            sig(m.best),
            if m.reachable { "yes" } else { "**no**" }
        );
    }
}

/// Writes the table of the parameters' plausible values.
fn exploration_parameters_md(o: &mut String, e: &Exploration) {
    let _ = writeln!(o, "\n## The parameters\n");
    let _ = writeln!(
        o,
        "Plausible: lowest – highest value among the plausible settings; width: its share of the \
         declared range (near 1: these trials do not pin the parameter down). ρ: Spearman rank \
         correlation of the value with χ² over the walking settings (negative: higher values fit \
         better).\n"
    );
    let _ = writeln!(
        o,
        "| parameter | nominal | range | best setting | plausible | width | ρ with χ² | why uncertain |"
    );
    let _ = writeln!(o, "|---|---:|---|---:|---|---:|---:|---|");
    for p in &e.parameters {
        let (plaus, width) = match (p.plausible, p.plausible_width) {
            (Some([a, b]), Some(w)) => (format!("{} – {}", sig(a), sig(b)), format!("{w:.2}")),
            _ => ("–".to_string(), "–".to_string()),
        };
        let _ = writeln!(
            o,
            "| {} | {} | {} – {} | {} | {} | {} | {:+.2} | {} |",
            p.parameter,
            sig(p.nominal),
            sig(p.range[0]),
            sig(p.range[1]),
            sig(p.best),
            plaus,
            width,
            p.rank_correlation_with_chi2,
            p.why.replace('|', "/")
        );
    }
}

/// `survey gap suggest` as Markdown.
pub fn suggestion_md(s: &crate::gap::suggest::Suggestion) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "# Next trials for {}\n", s.design);
    let leads = s
        .leading
        .iter()
        .map(|(l, p)| format!("{l} ({})", probability(*p)))
        .collect::<Vec<_>>()
        .join(", ");
    let _ = writeln!(
        o,
        "Leading explanations: {leads}; the posterior's entropy over them is {:.3} nats. {} of \
         {} pool conditions offered ({} where an explanation falls, {} where one does not walk \
         forward{}); new trials at {:.1} % relative sd.\n",
        s.entropy_now,
        s.offered,
        s.pool,
        s.fell,
        s.not_forward,
        if s.any_gait { ", offered anyway" } else { "" },
        100.0 * s.relative_sd
    );
    let _ = writeln!(
        o,
        "| trial | L [m] | f [Hz] | amplitude [deg] | mass [kg] | slope [deg] | expected entropy after |"
    );
    let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|");
    for x in &s.suggested {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} | {:.3} |",
            x.label,
            sig(x.leg_length_m),
            sig(x.frequency_hz),
            x.amplitude_deg.map(sig).unwrap_or_else(|| "–".into()),
            sig(x.mass_kg),
            x.slope_deg,
            x.expected_entropy
        );
    }
    if let Some(h) = s.default_entropy {
        let _ = writeln!(
            o,
            "\nOne trial at the design's own condition would leave {h:.3} nats."
        );
    }
    o
}
