//! `survey diff`: what a pull request changes in the dataset, for its reviewer.
//!
//! The live records are compared with a frozen release (by default the latest): records
//! added, removed and changed (field by field, with the sources of each new value), the
//! validation problems the change brings, and every Table 2 entry before → after, flagging
//! an exponent that left its previous confidence interval.
//!
//! A release keeps the compiled table only, not the records, so "new" validation problems
//! are found by validating the live records twice: as they are, and with the release's
//! values put back into them (same vocabulary, same sources, released name, class, fit
//! status and exclusion). A problem is new when the first run reports it and the second
//! does not, matched by file, robot, field, rule and severity (messages quote values, so
//! they are not compared).

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;

use crate::analysis::table2::{DatasetRef, Group, Numeric, TABLE2_PAIRS, Var, fit_group};
use crate::dataset::release::{self, SurveyRow, SurveyTable, parse_semver};
use crate::dataset::validate::validate;
use crate::dataset::{
    Dataset, DatasetError, Datum, FieldType, Problem, Robot, Severity, SourceKind, Value,
};
use crate::regression::Method;

/// Columns of the compiled table that identify a robot rather than hold a value.
const IDENTITY_FIELDS: [&str; 5] = ["id", "name", "class", "fit", "exclusion"];
/// The compiled table's column of source URLs.
const SOURCES_COLUMN: &str = "sources";

/// Why a diff could not be made.
#[derive(Debug, thiserror::Error)]
pub enum DiffError {
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    #[error("{0}")]
    NoRelease(String),
}

/// One source of a value, resolved from the record's `[[sources]]`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceRef {
    pub key: String,
    /// paper / datasheet / web / lab / dataset; None when the key is not in the record.
    pub kind: Option<SourceKind>,
    pub url: Option<String>,
    pub title: Option<String>,
}

/// A value of a record as the compiled table holds it, with its sources.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldValue {
    pub field: String,
    pub value: String,
    pub unit: Option<String>,
    /// Sources of the value (live records only: a release keeps no per-value provenance).
    pub sources: Vec<SourceRef>,
    /// Where in the source the value is (page, table, section), when the record says.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at: Option<String>,
}

/// A record added or removed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordSummary {
    pub id: String,
    pub name: String,
    pub class: String,
    pub fit: bool,
    pub exclusion: Option<String>,
    /// The record's file (live records only).
    pub file: Option<String>,
    /// Every non-empty value of the compiled table, in column order.
    pub values: Vec<FieldValue>,
}

impl RecordSummary {
    /// The value of a field, if the record has one.
    pub fn value(&self, field: &str) -> Option<&FieldValue> {
        self.values.iter().find(|v| v.field == field)
    }
}

/// One field of a record whose value changed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldChange {
    pub field: String,
    pub unit: Option<String>,
    /// Value in the release (None: absent).
    pub old: Option<String>,
    /// Value in the live records (None: removed).
    pub new: Option<String>,
    /// new/old − 1 for a measured quantity (a `number` field) when old ≠ 0.
    pub relative_change: Option<f64>,
    /// Sources the live record gives for the new value (empty for identity fields).
    pub sources: Vec<SourceRef>,
    /// Where in the source the new value is, when the record says.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at: Option<String>,
    /// For a speed: the gait the record gives the new value in (a release keeps no gait).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gait: Option<String>,
    /// The live value's note, if any.
    pub note: Option<String>,
}

/// A record present in both, with the fields that differ.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChangedRecord {
    pub id: String,
    pub name: String,
    pub class: String,
    pub file: Option<String>,
    pub fields: Vec<FieldChange>,
}

/// One fit of Table 2.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitSummary {
    pub a: f64,
    pub b: f64,
    pub b_ci: [f64; 2],
    pub r2: f64,
    pub n: usize,
}

/// One Table 2 entry before and after.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Table2Change {
    pub class: Group,
    pub x: Var,
    pub y: Var,
    pub before: Option<FitSummary>,
    pub after: Option<FitSummary>,
    /// Why a side could not be fitted (e.g. fewer than 3 robots).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub before_error: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub after_error: Option<String>,
    /// b after − b before.
    pub delta_b: Option<f64>,
    /// The new exponent lies outside the previous confidence interval of b.
    pub outside_previous_ci: bool,
    /// Anything differs (b, A, R² or n).
    pub changed: bool,
}

/// `survey diff`: the live records against a frozen release.
#[derive(Debug, Clone, Serialize)]
pub struct DatasetDiff {
    /// The release compared against.
    pub before: DatasetRef,
    /// The live records.
    pub after: DatasetRef,
    /// Where the live records are.
    pub dataset: String,
    pub method: Method,
    pub confidence: f64,
    pub added: Vec<RecordSummary>,
    pub removed: Vec<RecordSummary>,
    pub changed: Vec<ChangedRecord>,
    /// Problems of the live records that the released values did not have.
    pub new_problems: Vec<Problem>,
    /// Problems the released values had that the live records no longer have (robots
    /// removed since are not counted).
    pub resolved_problems: Vec<Problem>,
    /// Every Table 2 entry (3 relations × 5 groups), in the table's order.
    pub table2: Vec<Table2Change>,
}

impl DatasetDiff {
    /// New problems that are errors.
    pub fn new_errors(&self) -> usize {
        crate::dataset::problem::count(&self.new_problems, Severity::Error)
    }
    /// Table 2 entries whose exponent left its previous confidence interval.
    pub fn moved_outside(&self) -> impl Iterator<Item = &Table2Change> {
        self.table2.iter().filter(|t| t.outside_previous_ci)
    }
    /// Whether the records differ at all.
    pub fn records_differ(&self) -> bool {
        !(self.added.is_empty() && self.removed.is_empty() && self.changed.is_empty())
    }
}

/// The newest frozen release of the dataset.
pub fn latest_release(ds: &Dataset) -> Result<String, DiffError> {
    let manifest = ds.manifest()?;
    manifest
        .releases
        .iter()
        .filter_map(|r| parse_semver(&r.version).map(|v| (v, r.version.clone())))
        .max()
        .map(|(_, v)| v)
        .ok_or_else(|| {
            DiffError::NoRelease(format!(
                "{} lists no release to compare with (cut one with `survey dataset release X.Y.Z`)",
                ds.files.display(release::MANIFEST)
            ))
        })
}

/// Compares the live records of `ds` with release `against` (default: the latest).
pub fn diff(
    ds: &Dataset,
    against: Option<&str>,
    method: Method,
    confidence: f64,
) -> Result<DatasetDiff, DiffError> {
    let version = match against {
        Some(v) => v.to_string(),
        None => latest_release(ds)?,
    };
    let before = ds.table(Some(&version))?;
    let after = ds.table(None)?;

    let live: BTreeMap<&str, (&str, &Robot)> = ds
        .robots
        .iter()
        .map(|(rel, r)| (r.id.as_str(), (rel.as_str(), r)))
        .collect();
    let before_rows: BTreeMap<&str, &SurveyRow> =
        before.rows.iter().map(|r| (r.id.as_str(), r)).collect();
    let after_rows: BTreeMap<&str, &SurveyRow> =
        after.rows.iter().map(|r| (r.id.as_str(), r)).collect();
    let columns = value_columns(&before, &after);
    let unit = |field: &str| ds.vocab.get(field).map(|f| f.unit.clone());
    let file_of = |id: &str| live.get(id).map(|(rel, _)| ds.files.display(rel));

    let summary = |row: &SurveyRow, robot: Option<&Robot>| RecordSummary {
        id: row.id.clone(),
        name: row.name.clone(),
        class: row.class.as_str().to_string(),
        fit: row.fit,
        exclusion: row.exclusion.clone(),
        file: robot.and_then(|_| file_of(&row.id)),
        values: columns
            .iter()
            .filter_map(|c| {
                let value = row.cells.get(*c).filter(|s| !s.is_empty())?;
                Some(FieldValue {
                    field: c.to_string(),
                    value: value.clone(),
                    unit: unit(c),
                    sources: robot.map(|r| value_sources(r, c)).unwrap_or_default(),
                    at: robot
                        .and_then(|r| r.values.get(*c))
                        .and_then(|d| d.at.clone()),
                })
            })
            .collect(),
    };

    let added = after
        .rows
        .iter()
        .filter(|r| !before_rows.contains_key(r.id.as_str()))
        .map(|r| summary(r, live.get(r.id.as_str()).map(|(_, rb)| *rb)))
        .collect();
    let removed = before
        .rows
        .iter()
        .filter(|r| !after_rows.contains_key(r.id.as_str()))
        .map(|r| summary(r, None))
        .collect();

    let mut changed = Vec::new();
    for row in &after.rows {
        let Some(old) = before_rows.get(row.id.as_str()) else {
            continue;
        };
        let robot = live.get(row.id.as_str()).map(|(_, r)| *r);
        let fields = field_changes(ds, &columns, old, row, robot);
        if !fields.is_empty() {
            changed.push(ChangedRecord {
                id: row.id.clone(),
                name: row.name.clone(),
                class: row.class.as_str().to_string(),
                file: file_of(&row.id),
                fields,
            });
        }
    }

    let (new_problems, resolved_problems) = problem_changes(ds, &before, &after);

    Ok(DatasetDiff {
        before: DatasetRef::of(&before),
        after: DatasetRef::of(&after),
        dataset: ds.files.origin.clone(),
        method,
        confidence,
        added,
        removed,
        changed,
        new_problems,
        resolved_problems,
        table2: table2_changes(&before, &after, method, confidence),
    })
}

/// What changed in one record: its identity (name, class, fit, exclusion), then each
/// value column, with the new value's sources.
fn field_changes(
    ds: &Dataset,
    columns: &[&str],
    old: &SurveyRow,
    row: &SurveyRow,
    robot: Option<&Robot>,
) -> Vec<FieldChange> {
    let unit = |field: &str| ds.vocab.get(field).map(|f| f.unit.clone());
    let mut fields = Vec::new();
    let identity = [
        ("name", Some(old.name.clone()), Some(row.name.clone())),
        (
            "class",
            Some(old.class.as_str().to_string()),
            Some(row.class.as_str().to_string()),
        ),
        ("fit", Some(old.fit.to_string()), Some(row.fit.to_string())),
        ("exclusion", old.exclusion.clone(), row.exclusion.clone()),
    ];
    for (field, o, n) in identity {
        if !same_cell(o.as_deref(), n.as_deref()) {
            fields.push(FieldChange {
                field: field.to_string(),
                unit: None,
                relative_change: None,
                old: o,
                new: n,
                sources: Vec::new(),
                at: None,
                gait: None,
                note: None,
            });
        }
    }
    for c in columns {
        let o = old.cells.get(*c).filter(|s| !s.is_empty());
        let n = row.cells.get(*c).filter(|s| !s.is_empty());
        if same_cell(o.map(String::as_str), n.map(String::as_str)) {
            continue;
        }
        let num = |s: Option<&String>| s.and_then(|s| s.parse::<f64>().ok());
        let is_measure = ds
            .vocab
            .get(c)
            .is_some_and(|f| f.field_type == FieldType::Number);
        let relative_change = match (num(o), num(n)) {
            (Some(a), Some(b)) if is_measure && a != 0.0 && a.is_finite() && b.is_finite() => {
                Some(b / a - 1.0)
            }
            _ => None,
        };
        fields.push(FieldChange {
            field: c.to_string(),
            unit: unit(c),
            old: o.cloned(),
            new: n.cloned(),
            relative_change,
            sources: robot.map(|r| value_sources(r, c)).unwrap_or_default(),
            at: robot
                .and_then(|r| r.values.get(*c))
                .and_then(|d| d.at.clone()),
            gait: robot
                .and_then(|r| r.values.get(*c))
                .and_then(|d| d.gait.clone()),
            note: robot
                .and_then(|r| r.values.get(*c))
                .and_then(|d| d.note.clone()),
        });
    }
    fields
}

/// Value columns of both tables (after's order first, then columns only the release has),
/// without the identity columns; the `sources` column last.
fn value_columns<'a>(before: &'a SurveyTable, after: &'a SurveyTable) -> Vec<&'a str> {
    let mut seen = BTreeSet::new();
    let mut out: Vec<&str> = after
        .columns
        .iter()
        .chain(before.columns.iter())
        .map(String::as_str)
        .filter(|c| !IDENTITY_FIELDS.contains(c) && *c != SOURCES_COLUMN)
        .filter(|c| seen.insert(*c))
        .collect();
    out.push(SOURCES_COLUMN);
    out
}

/// Two cells hold the same value: the same text, or the same number written differently.
fn same_cell(a: Option<&str>, b: Option<&str>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(x), Some(y)) => {
            x == y
                || matches!(
                    (x.parse::<f64>(), y.parse::<f64>()),
                    (Ok(p), Ok(q)) if p == q
                )
        }
        _ => false,
    }
}

/// The sources a record cites for one of its values, resolved to the record's sources.
fn value_sources(robot: &Robot, field: &str) -> Vec<SourceRef> {
    let Some(d) = robot.values.get(field) else {
        return Vec::new();
    };
    d.sources
        .iter()
        .map(|key| {
            let s = robot.sources.iter().find(|s| &s.key == key);
            SourceRef {
                key: key.clone(),
                kind: s.map(|s| s.kind),
                url: s.and_then(|s| s.url.clone()),
                title: s.and_then(|s| s.title.clone()),
            }
        })
        .collect()
}

/// A release cell as a record value of the field's vocabulary type.
fn cell_value(ds: &Dataset, field: &str, text: &str) -> Value {
    ds.vocab
        .get(field)
        .and_then(|f| Value::from_cell(f.field_type, text))
        .unwrap_or_else(|| Value::Text(text.to_string()))
}

/// The live dataset with the release's values put back into its records (records removed
/// since are rebuilt from their row, with no sources; records added since are left out).
fn released_state(ds: &Dataset, before: &SurveyTable, after: &SurveyTable) -> Dataset {
    let after_rows: BTreeMap<&str, &SurveyRow> =
        after.rows.iter().map(|r| (r.id.as_str(), r)).collect();
    let mut robots = Vec::new();
    for row in &before.rows {
        let live = ds.robots.iter().find(|(_, r)| r.id == row.id);
        let (rel, mut robot) = match live {
            Some((rel, r)) => (rel.clone(), r.clone()),
            None => (
                format!("robots/{}.toml", row.id),
                row.robot(Vec::new(), BTreeMap::new()),
            ),
        };
        robot.name = row.name.clone();
        robot.class = row.class;
        robot.fit = row.fit;
        robot.exclusion = row.exclusion.clone();
        let all_keys: Vec<String> = robot.sources.iter().map(|s| s.key.clone()).collect();
        let now = after_rows.get(row.id.as_str());
        for col in before
            .columns
            .iter()
            .filter(|c| !IDENTITY_FIELDS.contains(&c.as_str()) && *c != SOURCES_COLUMN)
        {
            if ds.vocab.get(col).is_none() {
                continue;
            }
            let old = row.cells.get(col).filter(|s| !s.is_empty());
            let new = now.and_then(|r| r.cells.get(col)).filter(|s| !s.is_empty());
            if now.is_some() && same_cell(old.map(String::as_str), new.map(String::as_str)) {
                continue;
            }
            match old {
                None => {
                    robot.values.remove(col);
                }
                Some(text) => {
                    // The release does not say which source backed an old value; keep the
                    // live value's sources (or all of the record's), so provenance rules
                    // neither invent nor hide problems.
                    let sources = robot
                        .values
                        .get(col)
                        .map(|d| d.sources.clone())
                        .filter(|s| !s.is_empty())
                        .unwrap_or_else(|| all_keys.clone());
                    robot.values.insert(
                        col.clone(),
                        Datum::new(cell_value(ds, col, text), sources, None),
                    );
                }
            }
        }
        robots.push((rel, robot));
    }
    robots.sort_by(|a, b| a.0.cmp(&b.0));
    let kept: BTreeSet<String> = robots
        .iter()
        .map(|(rel, _)| ds.files.display(rel))
        .collect();
    let mut state = ds.clone();
    state.parse_problems.retain(|p| kept.contains(&p.file));
    state.robots = robots;
    state
}

type ProblemKey = (String, Option<String>, Option<String>, String, Severity);

fn key(p: &Problem) -> ProblemKey {
    (
        p.file.clone(),
        p.robot.clone(),
        p.field.clone(),
        p.rule.name(),
        p.severity,
    )
}

/// (new, resolved) validation problems of the live records against the release.
fn problem_changes(
    ds: &Dataset,
    before: &SurveyTable,
    after: &SurveyTable,
) -> (Vec<Problem>, Vec<Problem>) {
    let now = validate(ds).problems;
    let then = validate(&released_state(ds, before, after)).problems;
    let now_keys: BTreeSet<ProblemKey> = now.iter().map(key).collect();
    let then_keys: BTreeSet<ProblemKey> = then.iter().map(key).collect();
    let live_ids: BTreeSet<&str> = after.rows.iter().map(|r| r.id.as_str()).collect();
    let new = now
        .iter()
        .filter(|p| !then_keys.contains(&key(p)))
        .cloned()
        .collect();
    let resolved = then
        .iter()
        .filter(|p| !now_keys.contains(&key(p)))
        .filter(|p| p.robot.as_deref().is_none_or(|id| live_ids.contains(id)))
        .cloned()
        .collect();
    (new, resolved)
}

/// Every Table 2 entry fitted on both tables.
fn table2_changes(
    before: &SurveyTable,
    after: &SurveyTable,
    method: Method,
    confidence: f64,
) -> Vec<Table2Change> {
    let (nb, na) = (Numeric::of(before), Numeric::of(after));
    let fit = |data: &Numeric, g, x, y| match fit_group(data, g, x, y, method, confidence, None) {
        Ok(f) => (
            Some(FitSummary {
                a: f.a,
                b: f.b,
                b_ci: f.b_ci,
                r2: f.r2,
                n: f.n,
            }),
            None,
        ),
        Err(e) => (None, Some(e.to_string())),
    };
    let mut out = Vec::new();
    for (x, y) in TABLE2_PAIRS {
        for g in Group::TABLE2 {
            let (b, before_error) = fit(&nb, g, x, y);
            let (a, after_error) = fit(&na, g, x, y);
            let (delta_b, outside, changed) = match (&b, &a) {
                (Some(b), Some(a)) => (
                    Some(a.b - b.b),
                    !(b.b_ci[0] <= a.b && a.b <= b.b_ci[1]),
                    b != a,
                ),
                (None, None) => (None, false, false),
                _ => (None, false, true),
            };
            out.push(Table2Change {
                class: g,
                x,
                y,
                before: b,
                after: a,
                before_error,
                after_error,
                delta_b,
                outside_previous_ci: outside,
                changed,
            });
        }
    }
    out
}
