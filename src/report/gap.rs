//! The gap diagnosis as Markdown and figures.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::plot::{PlotError, register_font};
use super::sig;
use crate::gap::benchmark::{BenchmarkSummary, CaseRow};
use crate::gap::diagnose::{AnswerKind, Diagnosis};
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
    let _ = writeln!(
        o,
        "**Answer ({}):** {}.\n",
        answer_kind(d.answer.kind),
        d.answer.statement
    );
    where_md(&mut o, d);
    explanations_md(&mut o, d);
    chain_md(&mut o, d);
    calibration_md(&mut o, d);
    single_md(&mut o, d);
    identifiability_md(&mut o, d);
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
        AnswerKind::WithinNoise => "no gap",
        AnswerKind::ParametersOff => "parameters off",
        AnswerKind::EffectMissing => "effect missing",
        AnswerKind::Both => "parameters off and effect missing",
        AnswerKind::PartlyExplained => "partly explained",
        AnswerKind::Unexplained => "unexplained",
        AnswerKind::Ambiguous => "ambiguous",
    }
}

fn where_md(o: &mut String, d: &Diagnosis) {
    let _ = writeln!(o, "## Where the gap lies\n");
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

fn explanations_md(o: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        o,
        "\n## Competing explanations (each confirmed with walks)\n"
    );
    let _ = writeln!(
        o,
        "Held-out gap: RMS z with every condition predicted by the model fitted to the others. \
         p: likelihood-ratio test against the nominal, scaled by the over-dispersion left after \
         the fit.\n"
    );
    let _ = writeln!(
        o,
        "| model | free | fitted | χ² | held-out gap | shrink | p vs nominal | within noise |"
    );
    let _ = writeln!(o, "|---|---:|---|---:|---:|---:|---:|---|");
    for e in &d.explanations {
        let fitted = if e.knobs.is_empty() {
            "–".to_string()
        } else {
            e.knobs
                .iter()
                .map(|(k, v)| format!("{k} = {}", sig(*v)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(
            o,
            "| {} | {} | {} | {:.1} | {:.2} | {:.0} % | {} | {} |",
            e.model,
            e.free,
            fitted,
            e.chi2,
            e.gap_held_out,
            e.shrink_pct,
            e.p_vs_nominal
                .map(|p| format!("{p:.1e}"))
                .unwrap_or_else(|| "–".into()),
            if e.within_noise { "yes" } else { "no" }
        );
    }
}

fn chain_md(o: &mut String, d: &Diagnosis) {
    let _ = writeln!(o, "\n## The chain (forward selection)\n");
    if d.chain.is_empty() {
        let _ = writeln!(o, "No knob passed the call rules at the first step.");
        return;
    }
    for (i, s) in d.chain.iter().enumerate() {
        let _ = writeln!(
            o,
            "{}. **{}** = {} → held-out gap {:.2} (−{:.0} % at this step, −{:.0} % in all); LR {:.1}, over-dispersion {:.2}, p = {:.1e}{}{}{}; {}",
            i + 1,
            s.knob,
            sig(s.value_si),
            s.gap_after,
            s.shrink_pct,
            s.shrink_total_pct,
            s.lr,
            s.dispersion,
            s.p_value,
            s.p_value_vs_recalibration
                .map(|p| format!(", against the recalibration p = {p:.1e}"))
                .unwrap_or_default(),
            if s.not_separable_from.is_empty() {
                String::new()
            } else {
                format!("; not separable from {}", s.not_separable_from.join(", "))
            },
            s.joint_with
                .as_ref()
                .map(|w| format!(
                    "; joint step with {w} (neither passed alone; LR and p are the pair's, 2 dof)"
                ))
                .unwrap_or_default(),
            if s.within_noise_after {
                "within noise after"
            } else {
                "still beyond noise after"
            }
        );
    }
    if let Some(last) = d.chain.last() {
        let _ = writeln!(o, "\nCandidates at the last step:\n");
        let _ = writeln!(o, "| knob | value | held-out gap | LR | p | verdict |");
        let _ = writeln!(o, "|---|---:|---:|---:|---:|---|");
        for c in &last.candidates {
            let _ = writeln!(
                o,
                "| {} | {} | {:.2} | {:.1} | {:.1e} | {} |",
                c.knob,
                sig(c.value_si),
                c.gap_after,
                c.lr,
                c.p_value,
                c.verdict
            );
        }
    }
}

fn calibration_md(o: &mut String, d: &Diagnosis) {
    if d.calibration.is_empty() {
        return;
    }
    let _ = writeln!(
        o,
        "\n## The best recalibration of the uncertain parameters\n\nWidth: the 95 % interval's share of the plausible range (near 1: these trials do not pin the parameter down).\n"
    );
    let _ = writeln!(
        o,
        "| parameter | file | recalibrated | 95 % interval | range | move (prior sd) | width | why uncertain |"
    );
    let _ = writeln!(o, "|---|---:|---:|---|---|---:|---:|---|");
    for c in &d.calibration {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} – {} | {} – {} | {} | {:.2} | {} |",
            c.parameter,
            sig(c.nominal),
            // A magnitude whose sign the trials cannot give (Calibrated::sign_identified).
            if c.sign_identified {
                sig(c.value)
            } else {
                format!("±{}", sig(c.value))
            },
            sig(c.interval[0]),
            sig(c.interval[1]),
            sig(c.range[0]),
            sig(c.range[1]),
            c.move_in_sd
                .map(|m| format!("{m:+.1}"))
                .unwrap_or_else(|| "–".into()),
            c.width_of_range,
            c.why.replace('|', "/")
        );
    }
}

fn single_md(o: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        o,
        "\n## Every knob alone (from the nominal, surrogate fit)\n"
    );
    let _ = writeln!(
        o,
        "| knob | kind | fitted | held-out gap | shrink | LR | p |"
    );
    let _ = writeln!(o, "|---|---|---:|---:|---:|---:|---:|");
    for s in &d.single {
        let _ = writeln!(
            o,
            "| {} | {} | {} {} | {:.2} | {:.0} % | {:.1} | {:.1e} |",
            s.knob,
            match s.kind {
                KnobKind::Parameter => "parameter",
                KnobKind::Effect => "effect",
            },
            sig(s.value),
            s.unit,
            s.gap_held_out,
            s.shrink_pct,
            s.lr,
            s.p_value
        );
    }
}

fn identifiability_md(o: &mut String, d: &Diagnosis) {
    if d.identifiability.is_empty() {
        return;
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
                match d.chain.last() {
                    Some(s) => format!(
                        "after: {} (held-out RMS z {:.2})",
                        d.chain
                            .iter()
                            .map(|s| s.knob.as_str())
                            .collect::<Vec<_>>()
                            .join(" + "),
                        s.gap_after
                    ),
                    None => "after: nothing called".to_string(),
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

/// The benchmark as Markdown: scores against targets, thresholds, confusion matrices, and
/// the cases outside the library one by one.
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
    let verdict = if e.plausible > 0 {
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
    };
    let _ = writeln!(o, "{verdict}\n");
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
    if !e.notes.is_empty() {
        let _ = writeln!(o, "\nNotes:");
        for n in &e.notes {
            let _ = writeln!(o, "- {n}");
        }
    }
    o
}

pub fn benchmark_md(b: &BenchmarkSummary, rows: &[CaseRow], command: &str) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# Gap-diagnosis benchmark ({}, {} cases)\n",
        b.design, b.cases
    );
    let _ = writeln!(
        o,
        "Generated by `{command}` (resumable and shardable: `--points FILE`, `--shard i/n`, \
         `--merge`). Rates with their 95 % Clopper–Pearson interval and one-sided 95 % upper \
         bound. A case *names* a knob when the diagnosis' answer lists it (parameters off, \
         effect missing, both, or partly explained); an effect whose quantity the design \
         declares uncertain (friction_coefficient ↔ contact.friction_mu) counts as named when \
         that parameter is.\n"
    );
    scores_md(&mut o, b);
    thresholds_md(&mut o, b);
    confusions_md(&mut o, b);
    outside_cases_md(&mut o, rows);
    o
}

/// The score table.
fn scores_md(o: &mut String, b: &BenchmarkSummary) {
    let _ = writeln!(o, "## Scores\n");
    let _ = writeln!(
        o,
        "| what | k / n | rate | 95 % interval | upper 95 % | target |"
    );
    let _ = writeln!(o, "|---|---:|---:|---|---:|---|");
    for sc in &b.scores {
        // No case to count (a run of some kinds only): no rate, rather than "NaN %".
        if sc.n == 0 {
            let _ = writeln!(o, "| {} | 0 / 0 | – | – | – | {} |", sc.what, sc.target);
            continue;
        }
        let _ = writeln!(
            o,
            "| {} | {} / {} | {:.1} % | {:.1}–{:.1} % | {:.1} % | {} |",
            sc.what,
            sc.k,
            sc.n,
            sc.rate * 100.0,
            sc.interval[0] * 100.0,
            sc.interval[1] * 100.0,
            sc.upper_95 * 100.0,
            sc.target
        );
    }
}

/// The identification thresholds, one column per noise level.
fn thresholds_md(o: &mut String, b: &BenchmarkSummary) {
    let _ = writeln!(
        o,
        "\n## Identification thresholds (SI, {} at 1×: against the other effects, each uncertain parameter, and the recalibration of all of them, confirmed with walks; an effect the design calibrates as a parameter: against the other effects)\n",
        b.design
    );
    let names: Vec<String> = b
        .thresholds
        .values()
        .next()
        .map(|v| v.iter().map(|(e, _)| e.clone()).collect())
        .unwrap_or_default();
    let _ = write!(o, "| effect |");
    for n in b.thresholds.keys() {
        let noise: f64 = n.parse().unwrap_or(f64::NAN);
        let _ = write!(o, " {:.0} % noise |", noise * 100.0);
    }
    let _ = writeln!(o);
    let _ = write!(o, "|---|");
    for _ in b.thresholds.keys() {
        let _ = write!(o, "---:|");
    }
    let _ = writeln!(o);
    for e in &names {
        let _ = write!(o, "| {e} |");
        for v in b.thresholds.values() {
            let t = v.iter().find(|(n, _)| n == e).and_then(|(_, t)| *t);
            let _ = write!(o, " {} |", opt(t));
        }
        let _ = writeln!(o);
    }
}

/// The confusion matrices.
fn confusions_md(o: &mut String, b: &BenchmarkSummary) {
    for c in &b.confusions {
        let _ = writeln!(
            o,
            "\n## Confusion: {} (rows: truth; columns: named first)\n",
            c.title
        );
        let _ = write!(o, "| truth \\ named |");
        for l in &c.columns {
            let _ = write!(o, " {l} |");
        }
        let _ = writeln!(o);
        let _ = write!(o, "|---|");
        for _ in &c.columns {
            let _ = write!(o, "---:|");
        }
        let _ = writeln!(o);
        for (l, row) in c.rows.iter().zip(&c.counts) {
            let _ = write!(o, "| {l} |");
            for v in row {
                let _ = write!(o, " {v} |");
            }
            let _ = writeln!(o);
        }
    }
}

/// Cases outside the single-effect world (parameter errors, Drake, pairs), one per line.
fn outside_cases_md(o: &mut String, rows: &[CaseRow]) {
    let listed: Vec<&CaseRow> = rows
        .iter()
        .filter(|r| r.kind != "null" && r.kind != "effect")
        .collect();
    if !listed.is_empty() {
        let _ = writeln!(
            o,
            "\n## Cases outside the single-effect world, one by one\n"
        );
        let _ = writeln!(
            o,
            "| case | truth | answer | named | intervals | gap before → after |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|");
        for r in listed {
            let truth = [r.truth_params.as_str(), r.truth_effects.as_str()]
                .iter()
                .filter(|s| !s.is_empty())
                .copied()
                .collect::<Vec<_>>()
                .join("; ");
            let named = [r.named_params.as_str(), r.named_effects.as_str()]
                .iter()
                .filter(|s| !s.is_empty())
                .copied()
                .collect::<Vec<_>>()
                .join("; ");
            let _ = writeln!(
                o,
                "| {} | {} | {} | {} | {} | {:.2} → {} |",
                r.key,
                if truth.is_empty() { "none" } else { &truth },
                r.answer,
                if named.is_empty() { "–" } else { &named },
                intervals_cell(&r.intervals),
                r.gap_before,
                r.gap_after
                    .map(|g| format!("{g:.2}"))
                    .unwrap_or_else(|| "–".into())
            );
        }
    }
}

/// Named intervals `knob=lo..hi;…` as `knob [lo, hi]; …` (the parameter's path without
/// its design, values to a few significant digits); `–` when none.
fn intervals_cell(intervals: &str) -> String {
    if intervals.is_empty() {
        "–".to_string()
    } else {
        intervals
            .split(';')
            .map(|iv| match iv.split_once('=') {
                Some((k, v)) => {
                    let (lo, hi) = v.split_once("..").unwrap_or((v, v));
                    let f = |x: &str| x.parse::<f64>().map(sig).unwrap_or_else(|_| x.into());
                    format!(
                        "{} [{}, {}]",
                        k.rsplit(':').next().unwrap_or(k),
                        f(lo),
                        f(hi)
                    )
                }
                None => iv.to_string(),
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// The benchmark's confusion matrices as heat maps, one panel each (SVG).
pub fn confusion_plot(b: &BenchmarkSummary, path: &Path) -> Result<(), PlotError> {
    register_font();
    let err = |m: String| PlotError {
        path: path.display().to_string(),
        message: m,
    };
    let n = b.confusions.len().max(1) as u32;
    let cols = n.min(3);
    let rows_n = n.div_ceil(cols);
    let root = SVGBackend::new(path, (620 * cols, 600 * rows_n)).into_drawing_area();
    let draw = || -> Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let panels = root.split_evenly((rows_n as usize, cols as usize));
        for (c, area) in b.confusions.iter().zip(panels.iter()) {
            let (nr, nc) = (c.rows.len().max(1), c.columns.len().max(1));
            let mut chart = ChartBuilder::on(area)
                .caption(&c.title, ("sans-serif", 15))
                .margin(10)
                .x_label_area_size(170)
                .y_label_area_size(190)
                .build_cartesian_2d(0..nc, 0..nr)
                .map_err(|e| e.to_string())?;
            let xl = c.columns.clone();
            let yl = c.rows.clone();
            chart
                .configure_mesh()
                .disable_mesh()
                .x_labels(nc)
                .y_labels(nr)
                .x_label_formatter(&|i| xl.get(*i).cloned().unwrap_or_default())
                .y_label_formatter(&|i| {
                    yl.get(nr - 1 - (*i).min(nr - 1))
                        .cloned()
                        .unwrap_or_default()
                })
                .x_label_style(
                    ("sans-serif", 10)
                        .into_font()
                        .transform(FontTransform::Rotate90),
                )
                .y_label_style(("sans-serif", 10))
                .x_desc("named first")
                .y_desc("truth")
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
                    let y = nr - 1 - i;
                    let right = c.columns[j] == c.rows[i]
                        || (c.rows[i] == "null" && c.columns[j] == "none")
                        || c.columns[j].ends_with(c.rows[i].split('=').next().unwrap_or("#"));
                    let color = if right {
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
                                ("sans-serif", 11),
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
