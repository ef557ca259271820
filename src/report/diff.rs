//! `survey diff` as Markdown, ready to paste into a pull-request review.

use crate::analysis::release_diff::{
    DatasetDiff, FieldChange, RecordSummary, SourceRef, Table2Change,
};
use crate::analysis::table2::Var;

/// A Markdown table cell: no line breaks, `|` escaped.
fn cell(s: &str) -> String {
    s.replace('\n', " ").replace('|', "\\|")
}

fn source_text(s: &SourceRef) -> String {
    let mut out = format!("`{}`", s.key);
    if let Some(k) = s.kind {
        out.push_str(&format!(" ({})", k.as_str()));
    }
    match (&s.url, &s.title) {
        (Some(u), _) => out.push_str(&format!(" <{u}>")),
        (None, Some(t)) => out.push_str(&format!(" {t}")),
        (None, None) => {
            if s.kind.is_none() {
                out.push_str(" (not in the record's sources)");
            }
        }
    }
    out
}

fn sources_text(sources: &[SourceRef]) -> String {
    if sources.is_empty() {
        "–".to_string()
    } else {
        sources
            .iter()
            .map(source_text)
            .collect::<Vec<_>>()
            .join("; ")
    }
}

fn with_unit(v: &str, unit: Option<&str>) -> String {
    match unit {
        Some(u) if !u.is_empty() && u != "1" && u != "year" => format!("{v} {u}"),
        _ => v.to_string(),
    }
}

fn record_line(r: &RecordSummary, with_sources: bool) -> String {
    let mut out = format!(
        "- `{}` {} ({}, {})",
        r.id,
        r.name,
        r.class,
        if r.fit { "fitted" } else { "not fitted" }
    );
    let survey: Vec<String> = Var::SIZES
        .iter()
        .filter_map(|v| {
            let fv = r.value(v.field())?;
            let mut s = format!("{} = {}", v.symbol(), with_unit(&fv.value, Some(v.unit())));
            if with_sources && !fv.sources.is_empty() {
                s.push_str(&format!(
                    " [{}]",
                    fv.sources
                        .iter()
                        .map(|s| format!("`{}`", s.key))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            Some(s)
        })
        .collect();
    if !survey.is_empty() {
        out.push_str(&format!(": {}", survey.join(", ")));
    }
    let others = r
        .values
        .iter()
        .filter(|v| v.field != "sources" && !Var::SIZES.iter().any(|x| x.field() == v.field))
        .count();
    if others > 0 {
        out.push_str(&format!("; {others} other value(s)"));
    }
    if let Some(e) = &r.exclusion {
        out.push_str(&format!("; excluded: {}", e.replace('\n', " ")));
    }
    if let Some(f) = &r.file {
        out.push_str(&format!(" — `{f}`"));
    }
    out.push('\n');
    if with_sources {
        // The documents behind the survey values, once each.
        let mut seen: Vec<&SourceRef> = Vec::new();
        for fv in r
            .values
            .iter()
            .filter(|v| Var::SIZES.iter().any(|x| x.field() == v.field))
        {
            for s in &fv.sources {
                if !seen.iter().any(|t| t.key == s.key) {
                    seen.push(s);
                }
            }
        }
        for s in seen {
            out.push_str(&format!("  - {}\n", source_text(s)));
        }
    }
    out
}

fn change_row(c: &FieldChange) -> String {
    let show = |v: &Option<String>| match v {
        Some(v) => cell(&with_unit(v, c.unit.as_deref())),
        None => "*(none)*".to_string(),
    };
    let rel = c
        .relative_change
        .map(|r| format!(" ({:+.1}%)", r * 100.0))
        .unwrap_or_default();
    let at =
        c.at.as_deref()
            .map(|a| format!(", at: {}", cell(a)))
            .unwrap_or_default();
    let at = match &c.gait {
        Some(g) => format!("{at}, gait: {}", cell(g)),
        None => at,
    };
    let note = c
        .note
        .as_deref()
        .map(|n| format!(" — {}", cell(n)))
        .unwrap_or_default();
    format!(
        "| {} | {} | {}{rel} | {}{at}{note} |\n",
        c.field,
        show(&c.old),
        show(&c.new),
        cell(&sources_text(&c.sources))
    )
}

fn fit_cell(t: &Table2Change, before: bool) -> String {
    let (fit, err) = if before {
        (&t.before, &t.before_error)
    } else {
        (&t.after, &t.after_error)
    };
    match fit {
        Some(f) if before => format!("{:.3} [{:.3}, {:.3}]", f.b, f.b_ci[0], f.b_ci[1]),
        Some(f) => format!("{:.3}", f.b),
        None => format!(
            "– ({})",
            cell(err.as_deref().unwrap_or("not fitted")).trim_end_matches('.')
        ),
    }
}

/// The diff as Markdown.
pub fn diff_md(d: &DatasetDiff) -> String {
    let pct = d.confidence * 100.0;
    let mut out = format!(
        "## Dataset diff: release {} → live records {}\n\n",
        d.before.version, d.after.version
    );
    let moved = d.moved_outside().count();
    out.push_str(&format!(
        "Table sha256 `{}` → `{}`{}.\n\n**{} added, {} removed, {} changed; {} new validation problem(s) ({} error(s)); {} Table 2 exponent(s) moved outside their previous {pct:.0}% interval.**\n\n",
        short(&d.before.sha256),
        short(&d.after.sha256),
        if d.records_differ() || d.before.sha256 != d.after.sha256 {
            ""
        } else {
            " (identical)"
        },
        d.added.len(),
        d.removed.len(),
        d.changed.len(),
        d.new_problems.len(),
        d.new_errors(),
        moved
    ));

    diff_records_md(&mut out, d);
    diff_problems_md(&mut out, d);
    diff_table2_md(&mut out, d, pct);
    out
}

/// Writes the added, removed and changed record sections.
fn diff_records_md(out: &mut String, d: &DatasetDiff) {
    out.push_str(&format!("### Added ({})\n\n", d.added.len()));
    if d.added.is_empty() {
        out.push_str("None.\n");
    }
    for r in &d.added {
        out.push_str(&record_line(r, true));
    }
    out.push_str(&format!("\n### Removed ({})\n\n", d.removed.len()));
    if d.removed.is_empty() {
        out.push_str("None.\n");
    }
    for r in &d.removed {
        out.push_str(&record_line(r, false));
    }
    out.push_str(&format!("\n### Changed ({})\n", d.changed.len()));
    if d.changed.is_empty() {
        out.push_str("\nNone.\n");
    }
    for c in &d.changed {
        out.push_str(&format!(
            "\n#### `{}` {} ({}){}\n\n| field | old | new | source of the new value |\n|---|---|---|---|\n",
            c.id,
            c.name,
            c.class,
            c.file
                .as_deref()
                .map(|f| format!(" — `{f}`"))
                .unwrap_or_default()
        ));
        for f in &c.fields {
            out.push_str(&change_row(f));
        }
    }
}

/// Writes the new and resolved validation problem sections.
fn diff_problems_md(out: &mut String, d: &DatasetDiff) {
    out.push_str(&format!(
        "\n### New validation problems ({})\n\n",
        d.new_problems.len()
    ));
    if d.new_problems.is_empty() {
        out.push_str("None.\n");
    } else {
        out.push_str("```text\n");
        for p in &d.new_problems {
            out.push_str(&p.to_line());
            out.push('\n');
        }
        out.push_str("```\n");
    }
    if !d.resolved_problems.is_empty() {
        out.push_str(&format!(
            "\n### Resolved validation problems ({})\n\n```text\n",
            d.resolved_problems.len()
        ));
        for p in &d.resolved_problems {
            out.push_str(&p.to_line());
            out.push('\n');
        }
        out.push_str("```\n");
    }
}

/// Writes the Table 2 before/after comparison table.
fn diff_table2_md(out: &mut String, d: &DatasetDiff, pct: f64) {
    out.push_str(&format!(
        "\n### Table 2 ({}, y = A·x^b), release {} → live {}\n\n| relation | class | n | b before [{pct:.0}% CI] | b after | Δb | R² | |\n|---|---|---|---|---|---|---|---|\n",
        d.method.label(),
        d.before.version,
        d.after.version
    ));
    for t in &d.table2 {
        let n = match (&t.before, &t.after) {
            (Some(b), Some(a)) if a.n == b.n => a.n.to_string(),
            (b, a) => format!(
                "{} → {}",
                b.as_ref().map(|f| f.n.to_string()).unwrap_or("–".into()),
                a.as_ref().map(|f| f.n.to_string()).unwrap_or("–".into())
            ),
        };
        let r2 = match (&t.before, &t.after) {
            (Some(b), Some(a)) if (a.r2 - b.r2).abs() < 5e-4 => format!("{:.3}", a.r2),
            (b, a) => format!(
                "{} → {}",
                b.as_ref()
                    .map(|f| format!("{:.3}", f.r2))
                    .unwrap_or("–".into()),
                a.as_ref()
                    .map(|f| format!("{:.3}", f.r2))
                    .unwrap_or("–".into())
            ),
        };
        let flag = if t.outside_previous_ci {
            format!("**⚠ outside previous {pct:.0}% CI**")
        } else if t.changed {
            "changed".to_string()
        } else {
            String::new()
        };
        out.push_str(&format!(
            "| {} ∝ {}^b | {} | {n} | {} | {} | {} | {r2} | {flag} |\n",
            t.y.symbol(),
            t.x.symbol(),
            t.class.label(),
            fit_cell(t, true),
            fit_cell(t, false),
            t.delta_b
                .map(|v| format!("{v:+.3}"))
                .unwrap_or_else(|| "–".into()),
        ));
    }
}

fn short(sha: &str) -> &str {
    sha.get(..12).unwrap_or(sha)
}
