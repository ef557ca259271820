//! `survey gap separate` as Markdown, and the figure of measured vs simulated cycles.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::plot::{PlotError, register_font};
use super::sig;
use crate::gap::separate::{FollowPurpose, FollowUp, MetricLeftOut, Ranking, Separation, Verdict};
use crate::gap::suggest::{Suggested, Suggestion};
use crate::gap::waveform::{FIGURE_BINS, Signal};
use crate::gap::waveform_bench::WaveformBench;

fn verdict_text(v: &Verdict) -> String {
    match v {
        Verdict::NoGap => {
            "**no gap**: no candidate beats the nominal model significantly; nothing to separate"
                .into()
        }
        Verdict::Named { knob } => {
            format!("**{knob}**: it fits within noise and every rival is worse beyond the test")
        }
        Verdict::NamedTogether { knobs } => format!(
            "**{}** together: the pair fits within noise, each is needed beside the other, and \
             every other pair that passes as much fits worse beyond the test",
            knobs.join(" + ")
        ),
        Verdict::CannotTell { group } => format!(
            "**cannot tell** {}: the trials do not separate them",
            group.join(" from ")
        ),
        Verdict::NoneFits { rest_in } => format!(
            "**none fits**: no candidate reproduces the trials within noise (the best one's rest \
             lies in {rest_in}); nothing is named — the cause may be outside the candidates"
        ),
        Verdict::NotComparable { why } => {
            format!("**not comparable**: {why}; nothing is named")
        }
    }
}

/// The caveat of a name (`whose`: "Its", "knob: its") whose carried summaries fit only
/// without one metric.
fn left_out_text(whose: &str, l: &MetricLeftOut) -> String {
    format!(
        "{whose} carried summaries fit within noise only with {} left out (χ² {} on its {} \
         values): what lies there is another cause outside the candidates or the engines' \
         versions of the effect answering that metric apart, and these trials do not say which",
        l.metric,
        sig(l.chi2),
        l.values
    )
}

fn ranking_md(o: &mut String, r: &Ranking) {
    let _ = writeln!(o, "### {}\n", r.evidence.label());
    let _ = writeln!(o, "Answer: {}.\n", verdict_text(&r.verdict));
    if let Some(l) = &r.summaries_left_out
        && matches!(
            r.verdict,
            Verdict::Named { .. } | Verdict::CannotTell { .. }
        )
    {
        let _ = writeln!(o, "{}.\n", left_out_text("Its", l));
    }
    if r.fits.is_empty() {
        return;
    }
    let _ = writeln!(
        o,
        "{} observations; nominal χ² {}; best χ² p = {:.2e}; over-dispersion {}.\n",
        r.observations,
        sig(r.nominal_chi2),
        r.best_p_value,
        sig(r.overdispersion)
    );
    let _ = writeln!(
        o,
        "| candidate | fitted value | χ² summaries | χ² cycles | χ² ranked | Δ (LR vs best) | told apart |"
    );
    let _ = writeln!(o, "|---|---|---|---|---|---|---|");
    for (i, f) in r.fits.iter().enumerate() {
        let value = format!(
            "{} {}{}",
            sig(f.value),
            f.unit,
            if f.at_range_end { " (range end)" } else { "" }
        );
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} | {} |",
            f.knob,
            value,
            sig(f.chi2_summaries),
            sig(f.chi2_waveforms),
            sig(f.chi2),
            if i == 0 { "best".into() } else { sig(f.delta) },
            if i == 0 {
                "–"
            } else if f.separated {
                "yes"
            } else {
                "no"
            }
        );
    }
    o.push('\n');
    if r.pairs.is_empty() {
        return;
    }
    let _ = writeln!(
        o,
        "The best candidate with each rival, fitted together (the second knob's profile, the \
         first refitted at each node). Δ: the likelihood-ratio statistic of the other knob \
         beside each one alone; range: the second knob's values the profile does not reject at \
         95 %, widened to the grid nodes just outside them.\n"
    );
    let _ = writeln!(
        o,
        "| pair | fitted values | χ² summaries | χ² cycles | Δ (second needed, first needed) | range of the second | named |"
    );
    let _ = writeln!(o, "|---|---|---|---|---|---|---|");
    for p in &r.pairs {
        let _ = writeln!(
            o,
            "| {} + {} | {} {}, {} {} | {} | {} | {}, {} | {} – {} {} | {} |",
            p.knobs[0],
            p.knobs[1],
            sig(p.values[0]),
            p.units[0],
            sig(p.values[1]),
            p.units[1],
            sig(p.chi2_summaries),
            sig(p.chi2_waveforms),
            sig(p.delta[0]),
            sig(p.delta[1]),
            sig(p.second_range[0]),
            sig(p.second_range[1]),
            p.units[1],
            match &p.why_not {
                None => "yes".to_string(),
                Some(w) => format!("no: {w}"),
            }
        );
    }
    o.push('\n');
    if let Some(p) = r.pairs.iter().find(|p| p.passes)
        && let Some(l) = &p.summaries_left_out
    {
        let whose = format!("{} + {}: its", p.knobs[0], p.knobs[1]);
        let _ = writeln!(o, "{}.\n", left_out_text(&whose, l));
    }
}

/// The separation as Markdown.
pub fn separation_md(s: &Separation) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "## Separating the candidates\n");
    let _ = writeln!(
        o,
        "{} trials, {} with a log; each candidate fitted alone by walks (the other knobs at the \
         design file's values); cycle coefficients compared with a model-error floor of {} % of \
         each measured signal's RMS; tests at α = {}. {} walks.\n",
        s.trials,
        s.trials_with_logs,
        sig(100.0 * s.relative_floor),
        sig(s.alpha),
        s.walks
    );
    for r in &s.rankings {
        ranking_md(&mut o, r);
    }
    for n in &s.notes {
        let _ = writeln!(o, "Note: {n}\n");
    }
    o
}

/// What the logged cycles add to a diagnosis: each separation, then the names that stand.
/// Empty when nothing was separated.
pub fn follow_up_md(f: &FollowUp) -> String {
    let mut o = String::new();
    if f.groups.is_empty() && f.not_separated.is_empty() {
        return o;
    }
    for n in &f.not_separated {
        let _ = writeln!(o, "\nNot separated with the logged cycles: {n}.");
    }
    for g in &f.groups {
        match &g.purpose {
            FollowPurpose::Ambiguous => {
                o.push_str("\n## The look-alike group, with the logged cycles\n\n")
            }
            FollowPurpose::Explore => o.push_str(
                "\n## The gap the summaries leave, with the logged cycles (the leads and the best \
                 single knobs)\n\n",
            ),
            FollowPurpose::Confirm { knob } => {
                let _ = write!(
                    o,
                    "\n## The named knob ({knob}) against its closest rivals, with the logged \
                     cycles\n\n"
                );
            }
        }
        o.push_str(&separation_md(&g.separation));
    }
    let _ = writeln!(
        o,
        "**With the logged cycles:** {}.{}\n",
        if f.named.is_empty() {
            "nothing named".to_string()
        } else {
            format!("named {}", f.named.join(", "))
        },
        if f.withdrawn.is_empty() {
            String::new()
        } else {
            format!(" Withdrawn: {}.", f.withdrawn.join("; "))
        }
    );
    for (knob, l) in &f.left_out {
        let _ = writeln!(o, "{}.\n", left_out_text(&format!("{knob}: its"), l));
    }
    o
}

/// Measured cycles (black) against the nominal (grey) and the waveform ranking's best
/// candidate (blue), one row per signal, up to three trials (first, middle, last with a log).
pub fn cycles_plot(s: &Separation, path: &Path) -> Result<(), PlotError> {
    register_font();
    let err = |m: String| PlotError {
        path: path.display().to_string(),
        message: m,
    };
    if s.cycles.is_empty() {
        return Err(err(
            "no trial has a log (`trajectory` column): there are no cycles to draw".into(),
        ));
    }
    let n = s.cycles.len();
    let mut picks = vec![0, n / 2, n - 1];
    picks.dedup();
    let signals: Vec<Signal> = Signal::ALL
        .into_iter()
        .filter(|g| s.cycles[0].measured.signal(*g).is_some())
        .collect();
    let size = (
        380 * picks.len() as u32 + 40,
        210 * signals.len() as u32 + 40,
    );
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "png" {
        draw_cycles(
            BitMapBackend::new(path, size).into_drawing_area(),
            s,
            &picks,
            &signals,
        )
        .map_err(err)
    } else {
        draw_cycles(
            SVGBackend::new(path, size).into_drawing_area(),
            s,
            &picks,
            &signals,
        )
        .map_err(err)
    }
}

fn draw_cycles<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    s: &Separation,
    picks: &[usize],
    signals: &[Signal],
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let best_knob = s.cycles[0].best_knob.clone();
    let root = root
        .titled(
            &format!("measured cycles (black) vs nominal (grey) and {best_knob} (blue)"),
            ("sans-serif", 18),
        )
        .map_err(|e| e.to_string())?;
    let areas = root.split_evenly((signals.len(), picks.len()));
    let phase = |b: usize| (b as f64 + 0.5) / FIGURE_BINS as f64;
    for (r, signal) in signals.iter().enumerate() {
        for (c, &ti) in picks.iter().enumerate() {
            let tc = &s.cycles[ti];
            let curve = |sig: Option<&crate::gap::waveform::CycleSignature>| {
                sig.and_then(|x| x.signal(*signal)).map(|x| {
                    // Yaw has no mean (the heading): centre each curve.
                    let mean = if *signal == Signal::Yaw {
                        x.cycle.iter().sum::<f64>() / x.cycle.len() as f64
                    } else {
                        0.0
                    };
                    x.cycle
                        .iter()
                        .enumerate()
                        .map(|(b, y)| (phase(b), y - mean))
                        .collect::<Vec<_>>()
                })
            };
            let meas = curve(Some(&tc.measured));
            let nom = curve(tc.nominal.as_ref());
            let best = curve(tc.best.as_ref());
            let all: Vec<f64> = [&meas, &nom, &best]
                .iter()
                .filter_map(|c| c.as_ref())
                .flat_map(|c| c.iter().map(|p| p.1))
                .collect();
            let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let pad = ((hi - lo) * 0.08).max(1e-3);
            let (lo, hi) = if lo.is_finite() {
                (lo - pad, hi + pad)
            } else {
                (-1.0, 1.0)
            };
            let mut chart = ChartBuilder::on(&areas[r * picks.len() + c])
                .caption(
                    format!("{} — {}", tc.trial, signal.column()),
                    ("sans-serif", 13),
                )
                .margin(6)
                .x_label_area_size(26)
                .y_label_area_size(46)
                .build_cartesian_2d(0.0..1.0, lo..hi)
                .map_err(|e| e.to_string())?;
            chart
                .configure_mesh()
                .x_desc("drive phase [cycles]")
                .y_desc(signal.unit())
                .label_style(("sans-serif", 11))
                .x_labels(5)
                .y_labels(5)
                .draw()
                .map_err(|e| e.to_string())?;
            if let Some(p) = nom {
                chart
                    .draw_series(LineSeries::new(p, RGBColor(150, 150, 150).stroke_width(2)))
                    .map_err(|e| e.to_string())?;
            }
            if let Some(p) = best {
                chart
                    .draw_series(LineSeries::new(p, RGBColor(31, 119, 180).stroke_width(2)))
                    .map_err(|e| e.to_string())?;
            }
            if let Some(p) = meas {
                chart
                    .draw_series(LineSeries::new(p, BLACK.stroke_width(2)))
                    .map_err(|e| e.to_string())?;
            }
        }
    }
    root.present().map_err(|e| e.to_string())
}

/// `survey gap waveform-benchmark` as Markdown.
pub fn waveform_bench_md(b: &WaveformBench, command: &str) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# What the logged cycles buy: look-alike pairs, summaries vs waveforms\n"
    );
    let _ = writeln!(
        o,
        "Generated by `{command}` (`survey gap waveform-benchmark --help`).\n"
    );
    let _ = writeln!(
        o,
        "Design {}; the default conditions of `survey gap synth`; summaries with {} % noise; logs \
         with {}° white noise on every angle sample and {} % of the peak on the torque; cycle \
         floor {} % of each signal's RMS; {} seeds per cell; {} walks. Each side of a pair is the \
         truth in turn, at multiples of its identification threshold from the summaries \
         (against every other effect of the library); the candidates are the pair.\n",
        b.design,
        sig(100.0 * b.noise),
        sig(b.sensor_angle_deg),
        sig(100.0 * b.sensor_torque_fraction),
        sig(100.0 * b.relative_floor),
        b.seeds,
        b.walks
    );
    let _ = writeln!(o, "## Per pair\n");
    let _ = writeln!(
        o,
        "| truth | rival | threshold (summaries, SI) | smallest multiple named ≥ 90 %: summaries | + waveforms | rival named at 1×: summaries | + waveforms |"
    );
    let _ = writeln!(o, "|---|---|---:|---:|---:|---:|---:|");
    let m = |x: Option<f64>| {
        x.map(|v| format!("{}×", sig(v)))
            .unwrap_or_else(|| "none tested".into())
    };
    for p in &b.pairs {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {}/{} | {}/{} |",
            p.truth,
            p.rival,
            p.threshold.map(sig).unwrap_or_else(|| "–".into()),
            m(p.smallest_multiple_90[0]),
            m(p.smallest_multiple_90[1]),
            p.confusion_at_1x[0],
            b.seeds,
            p.confusion_at_1x[1],
            b.seeds
        );
    }
    let _ = writeln!(
        o,
        "\n## Every cell (counts over the seeds: summaries / + waveforms)\n"
    );
    let _ = writeln!(
        o,
        "| truth | × threshold | magnitude (SI) | truth named | rival named | cannot tell | none fits | no gap |"
    );
    let _ = writeln!(o, "|---|---:|---:|---|---|---|---|---|");
    for c in &b.cells {
        let pair = |v: [u64; 2]| format!("{} / {}", v[0], v[1]);
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            c.truth,
            sig(c.multiple),
            sig(c.magnitude),
            pair(c.correct),
            pair(c.confused),
            pair(c.cannot_tell),
            pair(c.none_fits),
            pair(c.no_gap)
        );
    }
    o
}

fn suggested_row(o: &mut String, s: &Suggested) {
    let _ = writeln!(
        o,
        "| {} | {} | {} | {} | {} | {} | {} | {} |",
        s.label,
        sig(s.leg_length_m),
        sig(s.frequency_hz),
        s.amplitude_deg.map(sig).unwrap_or_else(|| "–".into()),
        sig(s.mass_kg),
        sig(s.slope_deg),
        sig(s.separation_summaries),
        sig(s.separation_waveforms)
    );
}

/// `survey gap suggest` as Markdown.
pub fn suggestion_md(s: &Suggestion) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "## The next trials\n");
    let lead: Vec<String> = s
        .leading
        .iter()
        .map(|(k, v)| format!("{k} = {}", sig(*v)))
        .collect();
    let gait = if s.any_gait {
        "none falls (any gait: --any-gait)".to_string()
    } else {
        format!(
            "the nominal and both walk forward ({} more where one stands, scuffs or walks \
             backward)",
            s.not_forward
        )
    };
    let _ = writeln!(
        o,
        "Leading explanations (fitted to the trials): {}. Pool: {} conditions of {} at the robot's \
         size, {} where {gait}, of which {} left out as knife-edge (a leader's metrics bend by \
         more than 2 sd within ±2 % of its range); summaries scored at {} % relative sd. {} \
         walks.\n",
        lead.join(" vs "),
        s.pool,
        s.design,
        s.walkable + s.knife_edge,
        s.knife_edge,
        sig(100.0 * s.relative_sd),
        s.walks
    );
    if s.suggested.is_empty() {
        let _ = writeln!(
            o,
            "No condition of the pool qualifies: in every one a model falls, does not walk \
             forward, or walks on a knife edge. Nothing to suggest at this size; the trials \
             themselves, or logs (`survey gap separate`), are what can tell the two apart.\n"
        );
        return o;
    }
    let _ = writeln!(
        o,
        "| trial | leg length [m] | drive [Hz] | amplitude [deg] | mass [kg] | slope [deg] | expected LR, summaries | expected LR, cycles |"
    );
    let _ = writeln!(o, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for x in &s.suggested {
        suggested_row(&mut o, x);
    }
    if let Some(d) = &s.default_condition {
        let mut d = d.clone();
        d.label = "(the design's own drive, for comparison)".into();
        suggested_row(&mut o, &d);
    }
    let _ = writeln!(
        o,
        "\nAn expected LR of 10.8 is the 0.1 % critical value of χ²₁: one such trial would \
         tell the two apart on its own, if the leading pair holds the truth."
    );
    o
}
