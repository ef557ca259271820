//! The canonical text form of a record, so review diffs stay clean: fixed key order
//! (identity, sources, then values in vocabulary order), one value per line, floats in
//! shortest round-trip form. `survey dataset fmt` writes it; `--check` fails on records
//! that differ from it.

use std::path::Path;

use serde::Serialize;

use super::record::{Datum, Robot, Value};
use super::vocabulary::{FieldType, Vocabulary};
use super::{Dataset, DatasetError};

/// A TOML basic string, escaped by the toml crate.
fn quote(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// A float as TOML: shortest round-trip digits, always with a decimal point or exponent
/// so it reads back as a float.
pub fn float(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains(['.', 'e', 'E']) || !x.is_finite() {
        s
    } else {
        format!("{s}.0")
    }
}

fn value_parts(value: &Value, ty: Option<FieldType>, parts: &mut Vec<String>) {
    match value {
        Value::Number(x) => parts.push(format!("value = {}", float(*x))),
        Value::Integer(i) if ty == Some(FieldType::Number) => {
            parts.push(format!("value = {}", float(*i as f64)))
        }
        Value::Integer(i) => parts.push(format!("value = {i}")),
        Value::Text(s) => parts.push(format!("value = {}", quote(s))),
        Value::Bool(b) => parts.push(format!("value = {b}")),
        Value::Range { min, max } => {
            if let Some(m) = min {
                parts.push(format!("min = {}", float(*m)));
            }
            if let Some(m) = max {
                parts.push(format!("max = {}", float(*m)));
            }
        }
    }
}

fn source_part(sources: &[String], parts: &mut Vec<String>) {
    match sources {
        [] => {}
        [one] => parts.push(format!("source = {}", quote(one))),
        many => parts.push(format!(
            "source = [{}]",
            many.iter().map(|s| quote(s)).collect::<Vec<_>>().join(", ")
        )),
    }
}

/// A value as an inline table, keys in this order: value (or min, max), source, at, gait,
/// derived, derivation, note, history.
fn datum(d: &Datum, ty: Option<FieldType>) -> String {
    let mut parts = Vec::new();
    value_parts(&d.value, ty, &mut parts);
    source_part(&d.sources, &mut parts);
    if let Some(a) = &d.at {
        parts.push(format!("at = {}", quote(a)));
    }
    if let Some(g) = &d.gait {
        parts.push(format!("gait = {}", quote(g)));
    }
    if d.derived {
        parts.push("derived = true".into());
    }
    if let Some(x) = &d.derivation {
        parts.push(format!("derivation = {}", quote(x)));
    }
    if let Some(n) = &d.note {
        parts.push(format!("note = {}", quote(n)));
    }
    if !d.history.is_empty() {
        let entries: Vec<String> = d
            .history
            .iter()
            .map(|h| {
                let mut p = Vec::new();
                value_parts(&h.value, ty, &mut p);
                source_part(&h.sources, &mut p);
                if let Some(n) = &h.note {
                    p.push(format!("note = {}", quote(n)));
                }
                format!("{{ {} }}", p.join(", "))
            })
            .collect();
        parts.push(format!("history = [{}]", entries.join(", ")));
    }
    format!("{{ {} }}", parts.join(", "))
}

/// The canonical text of a record.
pub fn to_toml(robot: &Robot, vocab: &Vocabulary) -> String {
    let mut out = String::new();
    out.push_str(&format!("id = {}\n", quote(&robot.id)));
    out.push_str(&format!("name = {}\n", quote(&robot.name)));
    out.push_str(&format!("class = {}\n", quote(robot.class.as_str())));
    out.push_str(&format!("fit = {}\n", robot.fit));
    if let Some(e) = &robot.exclusion {
        out.push_str(&format!("exclusion = {}\n", quote(e)));
    }
    if let Some(n) = &robot.note {
        out.push_str(&format!("note = {}\n", quote(n)));
    }
    for s in &robot.sources {
        out.push_str("\n[[sources]]\n");
        out.push_str(&format!("key = {}\n", quote(&s.key)));
        out.push_str(&format!("kind = {}\n", quote(s.kind.as_str())));
        if let Some(u) = &s.url {
            out.push_str(&format!("url = {}\n", quote(u)));
        }
        if let Some(t) = &s.title {
            out.push_str(&format!("title = {}\n", quote(t)));
        }
        if let Some(n) = &s.note {
            out.push_str(&format!("note = {}\n", quote(n)));
        }
    }
    if !robot.values.is_empty() {
        out.push_str("\n[values]\n");
        let mut names: Vec<&String> = robot.values.keys().collect();
        names.sort_by_key(|n| (vocab.order(n), n.as_str()));
        for name in names {
            let d = &robot.values[name];
            let ty = vocab.get(name).map(|f| f.field_type);
            out.push_str(&format!("{name} = {}\n", datum(d, ty)));
        }
    }
    out
}

/// Result of `survey dataset fmt`.
#[derive(Debug, Clone, Default, Serialize)]
pub struct FmtReport {
    /// Records already canonical.
    pub canonical: Vec<String>,
    /// Records not canonical (rewritten unless checking).
    pub changed: Vec<String>,
    /// Records that could not be parsed (left untouched).
    pub unparsable: Vec<String>,
}

/// Finds records whose text is not canonical and, unless `check`, rewrites them
/// (each through a temporary file and a rename).
pub fn fmt(ds: &Dataset, check: bool) -> Result<FmtReport, DatasetError> {
    let mut report = FmtReport::default();
    let broken: std::collections::BTreeSet<&str> =
        ds.parse_problems.iter().map(|p| p.file.as_str()).collect();
    for (rel, bytes) in ds.files.files.range("robots/".to_string()..) {
        if !rel.starts_with("robots/") {
            break;
        }
        if !rel.ends_with(".toml") {
            continue;
        }
        let display = ds.files.display(rel);
        let Some((_, robot)) = ds.robots.iter().find(|(f, _)| f == rel) else {
            report.unparsable.push(display);
            continue;
        };
        if broken.contains(display.as_str()) {
            report.unparsable.push(display);
            continue;
        }
        let want = to_toml(robot, &ds.vocab);
        if want.as_bytes() == bytes.as_slice() {
            report.canonical.push(display);
            continue;
        }
        report.changed.push(display);
        if !check {
            let dir = ds.files.dir.as_ref().ok_or_else(|| {
                DatasetError::Other("cannot rewrite the bundled dataset: pass --dataset DIR".into())
            })?;
            write_atomic(&dir.join(rel), want.as_bytes())?;
        }
    }
    Ok(report)
}

/// [`crate::io::write_atomic`], its errors naming `path` (as the dataset commands report).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), DatasetError> {
    crate::io::write_atomic(path, bytes).map_err(|e| DatasetError::Io {
        path: path.display().to_string(),
        source: e.error,
    })
}
