//! Output formats, in one place: every command's data is rendered here as text, Markdown,
//! LaTeX (booktabs), CSV or JSON; figures live in [`plot`] (and a walk's in [`walk_plot`]).

mod crosscheck;
mod diff;
pub mod gap;
pub mod gap_benchmark;
pub mod html;
pub mod interop;
pub mod plot;
pub mod speed;
pub mod study;
mod ticks;
pub mod walk_plot;

pub use diff::diff_md;

pub use crosscheck::{crosscheck_md, min_torque_text};

use serde::Serialize;

use crate::analysis::table2::{Group, PowerLawRow, TABLE2_PAIRS, Table2, Var};
use crate::dataset::upstream::{ImportCheck, UpstreamImport};
use crate::dataset::validate::ValidationReport;

/// Output format of tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Format {
    #[default]
    Md,
    Tex,
    Csv,
    Json,
}

/// Pretty JSON with a trailing newline.
pub fn json<T: Serialize + ?Sized>(value: &T) -> Result<String, serde_json::Error> {
    let mut s = serde_json::to_string_pretty(value)?;
    s.push('\n');
    Ok(s)
}

/// `survey predict --format json`: the prediction, with the design's required hip torque
/// beside it when asked for (`--from design:NAME` and a leg length).
pub fn prediction_json(
    prediction: &crate::analysis::prediction::Prediction,
    torque: Option<&crate::study::torque_need::TorqueNeed>,
) -> Result<String, serde_json::Error> {
    #[derive(Serialize)]
    struct WithTorque<'a> {
        #[serde(flatten)]
        prediction: &'a crate::analysis::prediction::Prediction,
        torque: &'a crate::study::torque_need::TorqueNeed,
    }
    match torque {
        Some(torque) => json(&WithTorque { prediction, torque }),
        None => json(prediction),
    }
}

/// Validation findings, one per line, then a summary.
pub fn validation_text(rep: &ValidationReport) -> String {
    let mut out = String::new();
    for p in &rep.problems {
        out.push_str(&p.to_line());
        out.push('\n');
    }
    let errors = rep.errors();
    let warnings = rep.warnings();
    out.push_str(&format!(
        "{}: {} record(s), version {}: {} error(s), {} warning(s){}\n",
        rep.dataset,
        rep.records,
        rep.version,
        errors,
        warnings,
        if errors == 0 { " — valid" } else { "" }
    ));
    out
}

/// The quirks met while importing the upstream table.
pub fn quirks_text(imp: &UpstreamImport) -> String {
    let mut out = format!(
        "upstream table sha256 {}: {} rows → {} records, {} skipped; {} quirks handled\n",
        imp.sha256,
        imp.ledger.len(),
        imp.robots.len(),
        imp.ledger.iter().filter(|l| l.skipped.is_some()).count(),
        imp.quirks.len()
    );
    for q in &imp.quirks {
        out.push_str(&format!(
            "  line {:>3} {:<22} {:<20} `{}` → {}\n",
            q.line,
            q.column.as_deref().unwrap_or("-"),
            q.kind,
            q.raw.chars().take(60).collect::<String>(),
            q.handled
        ));
    }
    out
}

pub fn import_check_text(c: &ImportCheck) -> String {
    let mut out = format!(
        "release {}: {} (release sha256 {}, import sha256 {})\nrow ledger (upstream.toml): {}\n",
        c.release,
        if c.table_matches {
            "reproduced byte for byte"
        } else {
            "DIFFERS"
        },
        c.release_sha256,
        c.import_sha256,
        if c.ledger_matches {
            "matches"
        } else {
            "DIFFERS (rerun import-upstream to regenerate)"
        }
    );
    for r in &c.differing_rows {
        out.push_str(&format!("  differs: {r}\n"));
    }
    out
}

fn find(t: &Table2, g: Group, x: Var, y: Var) -> Option<&PowerLawRow> {
    t.fits.iter().find(|f| f.class == g && f.x == x && f.y == y)
}

fn row_label(x: Var, y: Var) -> String {
    format!("{} ∝ {}^b", y.symbol(), x.symbol())
}

/// Table 2 in the requested format.
pub fn table2(t: &Table2, format: Format) -> Result<String, serde_json::Error> {
    Ok(match format {
        Format::Md => table2_md(t),
        Format::Tex => table2_tex(t),
        Format::Csv => table2_csv(t),
        Format::Json => json(t)?,
    })
}

fn table2_md(t: &Table2) -> String {
    let mut out = format!(
        "# Power laws of the robot survey (Table 2)\n\nDataset {} ({}), sha256 `{}`; {} fit in log–log space, y = A·x^b.\n\n",
        t.dataset.version,
        if t.dataset.frozen {
            "frozen release"
        } else {
            "live records"
        },
        t.dataset.sha256,
        t.method.label()
    );
    out.push_str("| |");
    for g in Group::TABLE2 {
        out.push_str(&format!(" {} |", g.label()));
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(Group::TABLE2.len()));
    out.push_str("\n| n |");
    for g in Group::TABLE2 {
        let n = find(t, g, Var::LegLength, Var::Mass)
            .map(|f| f.n)
            .unwrap_or(0);
        out.push_str(&format!(" {n} |"));
    }
    out.push('\n');
    for (x, y) in TABLE2_PAIRS {
        out.push_str(&format!("| {} [{}] |", row_label(x, y), y.unit()));
        for g in Group::TABLE2 {
            match find(t, g, x, y) {
                Some(f) => {
                    out.push_str(&format!(" {}^{:.2} (R² = {:.3}) |", x.symbol(), f.b, f.r2))
                }
                None => out.push_str(" – |"),
            }
        }
        out.push('\n');
    }
    out.push_str(&format!(
        "\n## All coefficients\n\n| class | x | y | A | b | {:.0}% CI of b | R² | n | p(b = isometric) |\n|---|---|---|---|---|---|---|---|---|\n",
        t.fits.first().map(|f| f.confidence * 100.0).unwrap_or(95.0)
    ));
    for f in &t.fits {
        let bca = f
            .b_ci_bootstrap_bca
            .map(|c| format!(", BCa [{:.3}, {:.3}]", c[0], c[1]))
            .unwrap_or_default();
        let boot = f
            .b_ci_bootstrap
            .map(|c| format!(" (bootstrap [{:.3}, {:.3}]{bca})", c[0], c[1]))
            .unwrap_or_default();
        out.push_str(&format!(
            "| {} | {} | {} | {:.6} | {:.6} | [{:.3}, {:.3}]{boot} | {:.4} | {} | {:.2e} |\n",
            f.class.as_str(),
            f.x.as_str(),
            f.y.as_str(),
            f.a,
            f.b,
            f.b_ci[0],
            f.b_ci[1],
            f.r2,
            f.n,
            f.p_isometry
        ));
    }
    out
}

fn table2_tex(t: &Table2) -> String {
    let mut out = String::from(
        "% Generated by `survey fit --format tex`; needs \\usepackage{booktabs,siunitx}.\n\\begin{tabular}{rlllll}\n\\toprule\n",
    );
    out.push_str(" & \\textbf{Lower Bipedal Robot} & \\textbf{Full Bipedal Robot} & \\textbf{Quadrupedal Robot} & \\textbf{Hexapedal Robot} & \\textbf{Global}\\\\\n\\midrule\n");
    out.push_str("Number in group $n=$");
    for g in Group::TABLE2 {
        out.push_str(&format!(
            " & {}",
            find(t, g, Var::LegLength, Var::Mass)
                .map(|f| f.n)
                .unwrap_or(0)
        ));
    }
    out.push_str("\\\\\n");
    for (x, y) in TABLE2_PAIRS {
        let lhs = match y {
            Var::BodyLength => "Body Length [\\si{\\meter}] $L_B \\propto$",
            _ => "Body Mass [\\si{\\kilo\\gram}] $m \\propto$",
        };
        out.push_str(lhs);
        let xs = if x == Var::LegLength { "L" } else { "L_B" };
        for g in Group::TABLE2 {
            match find(t, g, x, y) {
                Some(f) => out.push_str(&format!(" & ${xs}^{{{:.2}}}$ ($R^2$ = {:.3})", f.b, f.r2)),
                None => out.push_str(" & --"),
            }
        }
        out.push_str("\\\\\n");
    }
    out.push_str("\\bottomrule\n\\end{tabular}\n");
    out
}

fn table2_csv(t: &Table2) -> String {
    let mut w = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    let _ = w.write_record([
        "class",
        "x",
        "y",
        "a",
        "b",
        "r2",
        "n",
        "method",
        "se_b",
        "b_ci_low",
        "b_ci_high",
        "a_ci_low",
        "a_ci_high",
        "p_b_equals_0",
        "p_isometry",
        "dataset_version",
        "dataset_sha256",
    ]);
    let m = t.method.label().to_lowercase();
    for f in &t.fits {
        let _ = w.write_record([
            f.class.as_str().to_string(),
            f.x.as_str().to_string(),
            f.y.as_str().to_string(),
            f.a.to_string(),
            f.b.to_string(),
            f.r2.to_string(),
            f.n.to_string(),
            m.clone(),
            f.se_b.to_string(),
            f.b_ci[0].to_string(),
            f.b_ci[1].to_string(),
            f.a_ci[0].to_string(),
            f.a_ci[1].to_string(),
            f.p_b_equals_0.to_string(),
            f.p_isometry.to_string(),
            t.dataset.version.clone(),
            t.dataset.sha256.clone(),
        ]);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

/// `survey fit --explain`: per relation, the robots that move the exponent most.
pub fn explain_text(e: &crate::analysis::table2::Explanation) -> String {
    let mut out = format!(
        "Leave-one-out influence on the {} exponents ({}; dataset {}, {} fit)\n",
        e.class.label(),
        e.class.as_str(),
        e.dataset.version,
        e.method.label()
    );
    for r in &e.relations {
        out.push_str(&format!(
            "\n{} ∝ {}^b: b = {:.3}, R² = {:.3}, n = {}\n  {:<28} {:>8} {:>8} {:>9} {:>8} {:>8} {:>7}\n",
            r.y.symbol(),
            r.x.symbol(),
            r.b,
            r.r2,
            r.n,
            "robot",
            "b without",
            "Δb",
            "R² without",
            "t(LOO)",
            "leverage",
            "Cook D"
        ));
        for rb in r.robots.iter().take(8) {
            out.push_str(&format!(
                "  {:<28} {:>8.3} {:>+8.3} {:>9} {:>+8.2} {:>8.3} {:>7.3}\n",
                rb.id,
                rb.b_without,
                rb.delta_b,
                rb.r2_without
                    .map(|v| format!("{v:.3}"))
                    .unwrap_or_else(|| "-".into()),
                rb.studentized_residual,
                rb.leverage,
                rb.cooks_distance
            ));
        }
    }
    out
}

pub(crate) fn sig(v: f64) -> String {
    // Three significant figures, without scientific notation in the usual range.
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// `survey predict` as text.
pub fn prediction_text(p: &crate::analysis::prediction::Prediction) -> String {
    let pct = p.confidence * 100.0;
    let mut out = format!(
        "Prediction from the {} OLS fits of dataset {} (sha256 {}…)\n",
        p.class.as_str(),
        p.dataset.version,
        p.dataset.sha256.get(..12).unwrap_or(&p.dataset.sha256)
    );
    prediction_leg_text(&mut out, p, pct);
    prediction_scaled_text(&mut out, p);
    if let Some(inv) = &p.inverse {
        out.push_str(&format!(
            "mass budget {} kg → leg length {} m{} (median mass on the {} fit m = {:.4}·L^{:.3})\n",
            inv.mass_budget_kg,
            sig(inv.leg_length_m),
            inv.leg_length_ci
                .map(|c| format!(", {pct:.0}% CI [{}, {}]", sig(c[0]), sig(c[1])))
                .unwrap_or_else(|| ", CI unbounded (slope not significant)".into()),
            inv.law.class.as_str(),
            inv.law.a,
            inv.law.b
        ));
        if let Some(w) = &inv.extrapolation {
            out.push_str(&format!("warning: {w}\n"));
        }
    }
    if let Some(w) = &p.extrapolation {
        out.push_str(&format!("warning: {w}\n"));
    }
    out
}

/// Writes the per-quantity table (and Froude number) for the target leg length.
fn prediction_leg_text(out: &mut String, p: &crate::analysis::prediction::Prediction, pct: f64) {
    if let Some(l) = p.leg_length_m {
        out.push_str(&format!("target leg length L = {l} m\n"));
        out.push_str(&format!(
            "  {:<20} {:>10} {:>10}  {:<24} {:<24} {}\n",
            "quantity",
            "mean",
            "median",
            format!("{pct:.0}% CI of median"),
            format!("{pct:.0}% prediction"),
            "law"
        ));
        for q in &p.quantities {
            out.push_str(&format!(
                "  {:<20} {:>10} {:>10}  {:<24} {:<24} {} = {:.4}·L^{:.3} (R² {:.3}, n {})\n",
                format!("{} [{}]", q.quantity.as_str(), q.unit),
                sig(q.mean),
                sig(q.median),
                format!("[{}, {}]", sig(q.median_ci[0]), sig(q.median_ci[1])),
                format!(
                    "[{}, {}]",
                    sig(q.prediction_interval[0]),
                    sig(q.prediction_interval[1])
                ),
                q.quantity.symbol(),
                q.law.a,
                q.law.b,
                q.law.r2,
                q.law.n
            ));
        }
        if let Some(q) = p.quantities.first() {
            out.push_str(&format!(
                "  centre: bias-corrected mean (Duan smearing factor {:.3} × median)\n",
                q.smearing_factor
            ));
        }
        if let Some(f) = &p.froude {
            out.push_str(&format!(
                "  Froude number v²/(gL) of the {} speed: {} (median {}, {pct:.0}% prediction [{}, {}])\n",
                p.speed_kind,
                sig(f.mean),
                sig(f.median),
                sig(f.prediction_interval[0]),
                sig(f.prediction_interval[1])
            ));
        }
        if let Some(why) = &p.speed_unavailable {
            out.push_str(&format!("  no {} speed predicted: {why}\n", p.speed_kind));
        }
    }
}

/// Writes the masses of the reference robot scaled to the target leg length.
fn prediction_scaled_text(out: &mut String, p: &crate::analysis::prediction::Prediction) {
    if let Some(s) = &p.scaled_reference {
        let fit_mass = p
            .quantities
            .iter()
            .find(|q| q.quantity == crate::analysis::table2::Var::Mass);
        out.push_str(&format!(
            "scaling {} (L = {} m, m = {} kg; {}) by ×{}:\n",
            s.reference.name,
            s.reference.leg_length_m,
            s.reference.mass_kg,
            s.reference.source,
            sig(s.scale_factor)
        ));
        if let Some(q) = fit_mass {
            out.push_str(&format!(
                "  {:<26} m = {} kg\n",
                format!("class fit ({} ∝ L^{:.2})", q.quantity.symbol(), q.law.b),
                sig(q.mean)
            ));
        }
        out.push_str(&format!(
            "  m ∝ L² (robot survey)      m = {} kg\n",
            sig(s.mass_l2_kg)
        ));
        out.push_str(&format!(
            "  m ∝ L³ (isometric)         m = {} kg\n",
            sig(s.mass_l3_kg)
        ));
        if let Some(b) = s.body_length_isometric_m {
            out.push_str(&format!(
                "  body length, isometric     L_B = {} m\n",
                sig(b)
            ));
        }
    }
}

/// `survey test slope` as text: the fit, then one line per hypothesis.
pub fn slope_test_text(r: &crate::analysis::inference::SlopeTestReport) -> String {
    let Some(first) = r.tests.first() else {
        return String::new();
    };
    let mut out = format!(
        "{} {} ∝ {}^b (dataset {}, {}): b = {:.4}, {:.0}% CI [{:.4}, {:.4}], n = {}\n",
        r.class.as_str(),
        r.y.symbol(),
        r.x.symbol(),
        r.dataset.version,
        first.test.method.label(),
        first.test.b,
        r.confidence * 100.0,
        r.b_ci[0],
        r.b_ci[1],
        first.test.n,
    );
    for t in &r.tests {
        let h = &t.hypothesis;
        let name = if h.label == format!("b = {}", h.b) {
            h.label.clone()
        } else {
            format!("b = {} ({})", h.b, h.label)
        };
        out.push_str(&format!(
            "H0: {name}: F = {:.4} on (1, {}) df, p = {:.3e}{}\n",
            t.test.f_statistic,
            t.test.df,
            t.test.p_value,
            if t.rejected {
                " → rejected"
            } else {
                " → not rejected"
            }
        ));
    }
    out
}

/// `survey test common-slope` as text.
pub fn comparison_text(r: &crate::analysis::inference::GroupComparisonReport) -> String {
    let c = &r.common_slope;
    let mut out = format!(
        "{} ∝ {}^b across {} (dataset {}, {}):\n",
        r.y.symbol(),
        r.x.symbol(),
        r.classes
            .iter()
            .map(|g| g.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        r.dataset.version,
        c.method.label()
    );
    for g in &c.groups {
        out.push_str(&format!(
            "  {:<12} n = {:>2}  b = {:.3} [{:.3}, {:.3}]\n",
            g.label, g.n, g.b, g.b_ci.lower, g.b_ci.upper
        ));
    }
    let stat = match c.test {
        crate::regression::TestKind::F => format!(
            "F = {:.3} on ({}, {}) df",
            c.statistic,
            c.df,
            c.df_den.unwrap_or(0)
        ),
        crate::regression::TestKind::LikelihoodRatio => format!(
            "likelihood ratio (Bartlett-corrected) = {:.3} on {} df",
            c.statistic, c.df
        ),
        crate::regression::TestKind::Wald => {
            format!("Wald = {:.3} on {} df", c.statistic, c.df)
        }
    };
    out.push_str(&format!(
        "common slope: b = {:.4}{}\nH0 all slopes equal: {stat}, p = {:.3e}{}\n",
        c.b,
        c.b_ci
            .map(|i| format!(" [{:.4}, {:.4}]", i.lower, i.upper))
            .unwrap_or_default(),
        c.p_value,
        if c.p_value < 1.0 - c.level {
            " → rejected: classes scale differently"
        } else {
            " → not rejected"
        }
    ));
    if let Some(e) = &r.elevation {
        out.push_str(&format!(
            "given the common slope, H0 equal elevations: {} = {:.3} on {} df, p = {:.3e}{}\n",
            match e.test {
                crate::regression::TestKind::F => "F",
                crate::regression::TestKind::Wald => "Wald",
                crate::regression::TestKind::LikelihoodRatio => "LR",
            },
            e.statistic,
            e.df_den
                .map(|d| format!("({}, {d})", e.df))
                .unwrap_or_else(|| e.df.to_string()),
            e.p_value,
            if e.p_value < 1.0 - e.level {
                " → rejected: the classes differ by a shift"
            } else {
                " → not rejected"
            }
        ));
        for g in &e.groups {
            out.push_str(&format!(
                "  {:<12} log10 A = {:.3} [{:.3}, {:.3}]\n",
                g.label, g.elevation, g.elevation_ci.lower, g.elevation_ci.upper
            ));
        }
    }
    out
}

/// `survey laws` as Markdown.
pub fn laws_md(t: &crate::analysis::laws::LawTable) -> String {
    let mut out = format!(
        "# Scaling laws against leg length L (Table 1)\n\nDataset {}; robotics exponents recomputed by OLS with {:.0}% intervals.\n\n| quantity | isometric | biology | robotics (paper) |\n|---|---|---|---|\n",
        t.dataset.version,
        t.confidence * 100.0
    );
    let mut quantities: Vec<&str> = Vec::new();
    for r in &t.laws {
        if !quantities.contains(&r.law.quantity.as_str()) {
            quantities.push(&r.law.quantity);
        }
    }
    for q in &quantities {
        let cell = |basis: &str| {
            t.laws
                .iter()
                .find(|r| r.law.quantity == *q && r.law.basis == basis)
                .map(|r| format!("{} [{}]", r.law.expression, r.law.sources.join(", ")))
                .unwrap_or_else(|| "–".into())
        };
        out.push_str(&format!(
            "| {q} | {} | {} | {} |\n",
            cell("isometric"),
            cell("biology"),
            cell("robotics")
        ));
    }
    out.push_str("\n## Robotics exponents from the survey data\n\n| law | class | b | CI | R² | n | p(isometry) | law's exponent in CI |\n|---|---|---|---|---|---|---|---|\n");
    for r in t.laws.iter().filter(|r| !r.from_data.is_empty()) {
        for d in &r.from_data {
            out.push_str(&format!(
                "| {} | {} | {:.3} | [{:.3}, {:.3}] | {:.3} | {} | {:.2e} | {} |\n",
                r.law.expression,
                d.class.as_str(),
                d.b,
                d.b_ci[0],
                d.b_ci[1],
                d.r2,
                d.n,
                d.p_isometry,
                if d.law_in_ci { "yes" } else { "no" }
            ));
        }
    }
    out.push_str("\n## Sources\n\n");
    for s in &t.sources {
        out.push_str(&format!(
            "- **{}** ({}): {}{}\n",
            s.key,
            s.kind,
            s.title,
            s.url
                .as_deref()
                .map(|u| format!(" <{u}>"))
                .unwrap_or_default()
        ));
    }
    out
}

/// `survey sim walk` as text.
pub fn walk_text(r: &crate::sim::WalkReport) -> String {
    let opt = |v: Option<f64>| {
        v.map(|v| format!("{v:.2} s"))
            .unwrap_or_else(|| "not detected".into())
    };
    let mut out = format!(
        "{} at L = {:.4} m, m = {:.4} kg ({:?}, {:?} contact), drive {:.3} Hz, torque limit {:.4} N·m, {} s\n",
        r.design,
        r.leg_length_m,
        r.mass_kg,
        r.mass_law,
        r.contact_scaling,
        r.drive_frequency_hz,
        r.torque_limit_nm,
        r.duration_s
    );
    match (&r.fall_reason, r.walks) {
        (Some(reason), _) if reason == "diverged" => out.push_str(&format!(
            "NUMERICS DIVERGED at {} (not a physical fall: the state blew up; reduce numerics.time_step_s)\n",
            r.fell_at_s.map(|t| format!("{t:.2} s")).unwrap_or_default()
        )),
        (Some(reason), _) => out.push_str(&format!(
            "FELL ({reason}) at {}\n",
            r.fell_at_s.map(|t| format!("{t:.2} s")).unwrap_or_default()
        )),
        (None, true) => out.push_str("walks\n"),
        (None, false) => out.push_str("does not walk (upright, but no steady forward progress)\n"),
    }
    out.push_str(&format!(
        "  limit cycle from     {}\n  velocity             {:.4} m/s (Froude v/√(gL) = {:.3})\n  step frequency       {:.3} Hz\n  roll  peak-to-peak   {:.2} ± {:.2}°\n  pitch peak-to-peak   {:.2} ± {:.2}°\n  yaw   peak-to-peak   {:.2} ± {:.2}°\n  turning              {:.2}°/m\n  mechanical work      {:.4} J (cost of transport {:.3})\n  peak hip torque      {:.4} N·m\n",
        opt(r.converged_at_s),
        r.velocity_mps,
        r.froude,
        r.step_frequency_hz,
        r.roll_pp_deg,
        r.roll_pp_deg_sd,
        r.pitch_pp_deg,
        r.pitch_pp_deg_sd,
        r.yaw_pp_deg,
        r.yaw_pp_deg_sd,
        r.turning_deg_per_m,
        r.mechanical_work_j,
        r.cot,
        r.peak_torque_nm
    ));
    out
}

/// `survey sim scale` as text.
pub fn scaling_text(s: &crate::study::scaling::ScalingStudy) -> String {
    let mut out = format!(
        "Scaling study of {}\n  {:>8} {:>10} {:>6} {:>10} {:>7} {:>8} {:>8} {:>8} {:>11}\n",
        s.design,
        "L [m]",
        "m [kg]",
        "walks",
        "v [m/s]",
        "Froude",
        "roll°",
        "pitch°",
        "yaw°",
        "τ_peak [N·m]"
    );
    for w in &s.walks {
        out.push_str(&format!(
            "  {:>8.4} {:>10.4} {:>6} {:>10.4} {:>7.3} {:>8.2} {:>8.2} {:>8.2} {:>11.4e}\n",
            w.leg_length_m,
            w.mass_kg,
            if w.walks { "yes" } else { "no" },
            w.velocity_mps,
            w.froude,
            w.roll_pp_deg,
            w.pitch_pp_deg,
            w.yaw_pp_deg,
            w.peak_torque_nm
        ));
    }
    for (name, l, expect) in [
        ("velocity", &s.velocity_law, "dynamic similarity: 0.5"),
        (
            "peak torque vs L",
            &s.torque_law,
            "τ ∝ m·L: 3 with m ∝ L², 4 with m ∝ L³",
        ),
        ("peak torque vs m·L", &s.torque_vs_mass_length, "τ ∝ m·L: 1"),
    ] {
        match l {
            Some(l) => out.push_str(&format!(
                "{name}: b = {:.3} [{:.3}, {:.3}], R² = {:.4}, n = {} (expected {expect})\n",
                l.b, l.b_ci[0], l.b_ci[1], l.r2, l.n
            )),
            None => out.push_str(&format!("{name}: fewer than 3 sizes walk, no fit\n")),
        }
    }
    out
}
