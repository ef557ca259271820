//! One robot record (`dataset/robots/ID.toml`): identity, class, fit status, sources and
//! values, each value pointing at the sources that support it.
//!
//! Records are parsed by hand from a `toml::Table` rather than with serde's derive so that
//! a broken record yields *every* problem it has (unknown keys, wrong types, missing
//! sources…), each with its field and line, instead of stopping at the first.

use std::collections::BTreeMap;

use serde::Serialize;

use super::problem::{Problem, Rule};
use super::vocabulary::{FieldType, Vocabulary, line_of_offset};

/// Robot class, per the paper (Sec. II), plus `hybrid` for rows that are not purely legged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RobotClass {
    LowerBiped,
    FullBiped,
    Quadruped,
    Hexapod,
    Hybrid,
}

impl RobotClass {
    pub const ALL: [RobotClass; 5] = [
        RobotClass::LowerBiped,
        RobotClass::FullBiped,
        RobotClass::Quadruped,
        RobotClass::Hexapod,
        RobotClass::Hybrid,
    ];
    /// The classes fitted in Table 2, in the paper's column order.
    pub const FITTED: [RobotClass; 4] = [
        RobotClass::LowerBiped,
        RobotClass::FullBiped,
        RobotClass::Quadruped,
        RobotClass::Hexapod,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            RobotClass::LowerBiped => "lower-biped",
            RobotClass::FullBiped => "full-biped",
            RobotClass::Quadruped => "quadruped",
            RobotClass::Hexapod => "hexapod",
            RobotClass::Hybrid => "hybrid",
        }
    }

    /// Human label as in the paper's tables.
    pub fn label(self) -> &'static str {
        match self {
            RobotClass::LowerBiped => "Lower biped",
            RobotClass::FullBiped => "Full biped",
            RobotClass::Quadruped => "Quadruped",
            RobotClass::Hexapod => "Hexapod",
            RobotClass::Hybrid => "Hybrid",
        }
    }

    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.as_str() == s)
    }
}

impl std::fmt::Display for RobotClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// What kind of document a source is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SourceKind {
    Paper,
    Datasheet,
    Web,
    Lab,
    Dataset,
    /// A robot description file (URDF, MJCF, CAD) published by the maker or the lab.
    Model,
    /// A restatement of a primary source (news, encyclopedia, distributor, review).
    Secondary,
}

impl SourceKind {
    pub const ALL: [SourceKind; 7] = [
        SourceKind::Paper,
        SourceKind::Datasheet,
        SourceKind::Web,
        SourceKind::Lab,
        SourceKind::Dataset,
        SourceKind::Model,
        SourceKind::Secondary,
    ];
    /// Whether a source of this kind is where a value was first published (the maker's
    /// datasheet or page, the robot's paper, the lab, its description files), as opposed
    /// to a table that transcribes it (`dataset`) or a restatement (`secondary`).
    pub fn is_primary(self) -> bool {
        !matches!(self, SourceKind::Dataset | SourceKind::Secondary)
    }
    pub fn as_str(self) -> &'static str {
        match self {
            SourceKind::Paper => "paper",
            SourceKind::Datasheet => "datasheet",
            SourceKind::Web => "web",
            SourceKind::Lab => "lab",
            SourceKind::Dataset => "dataset",
            SourceKind::Model => "model",
            SourceKind::Secondary => "secondary",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.as_str() == s)
    }
}

/// A document that supports values of a record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Source {
    /// Short key that values refer to (`source = "s1"`).
    pub key: String,
    pub kind: SourceKind,
    /// URL of the document; `lab` sources may give only a `title`.
    pub url: Option<String>,
    pub title: Option<String>,
    pub note: Option<String>,
}

/// A value as given by a record.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Value {
    Number(f64),
    Integer(i64),
    Text(String),
    Bool(bool),
    /// A reported range, either end possibly open (e.g. cost "<250000").
    Range {
        min: Option<f64>,
        max: Option<f64>,
    },
}

impl Value {
    /// A table cell (a release's text form) as a value of the field's type; None when it
    /// does not parse as that type.
    pub fn from_cell(field_type: FieldType, cell: &str) -> Option<Value> {
        match field_type {
            FieldType::Number => cell.parse::<f64>().ok().map(Value::Number),
            FieldType::Integer => cell.parse::<i64>().ok().map(Value::Integer),
            FieldType::Bool => cell.parse::<bool>().ok().map(Value::Bool),
            FieldType::Text => Some(Value::Text(cell.to_string())),
        }
    }

    /// The value as a number, if it is a point number or integer.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Value::Number(x) => Some(*x),
            Value::Integer(i) => Some(*i as f64),
            _ => None,
        }
    }
}

/// A value with its provenance.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct Datum {
    pub value: Value,
    /// Keys of the record's sources that support this value.
    pub sources: Vec<String>,
    /// Where in the source the value is stated: page, table, section (`at = "Table I"`).
    pub at: Option<String>,
    /// For a speed: the gait it was reached in (`walk`, `trot`, `run` …; see the
    /// vocabulary's `[[gait]]` list), when the source says.
    pub gait: Option<String>,
    /// The value is not stated directly but derived from what the source states
    /// (e.g. hip height = thigh + shank + foot height); `derivation` says how.
    pub derived: bool,
    pub derivation: Option<String>,
    pub note: Option<String>,
    /// Earlier values this one replaced (e.g. the survey's value before a primary source
    /// corrected it), oldest first: kept so that no transcribed value silently disappears.
    pub history: Vec<Earlier>,
}

/// A value a record used to give, with where it came from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Earlier {
    pub value: Value,
    pub sources: Vec<String>,
    pub note: Option<String>,
}

impl Default for Value {
    fn default() -> Self {
        Value::Range {
            min: None,
            max: None,
        }
    }
}

impl Datum {
    /// A value with sources and nothing else.
    pub fn new(value: Value, sources: Vec<String>, note: Option<String>) -> Self {
        Datum {
            value,
            sources,
            note,
            ..Datum::default()
        }
    }
}

/// A parsed robot record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Robot {
    pub id: String,
    pub name: String,
    pub class: RobotClass,
    /// Used in the power-law fits.
    pub fit: bool,
    /// Why the robot is kept but not fitted (required when `fit = false`).
    pub exclusion: Option<String>,
    pub note: Option<String>,
    pub sources: Vec<Source>,
    /// Values keyed by vocabulary field name (BTreeMap: deterministic order).
    pub values: BTreeMap<String, Datum>,
}

impl Robot {
    pub fn number(&self, field: &str) -> Option<f64> {
        self.values.get(field).and_then(|d| d.value.as_f64())
    }
    pub fn integer(&self, field: &str) -> Option<i64> {
        match self.values.get(field).map(|d| &d.value) {
            Some(Value::Integer(i)) => Some(*i),
            _ => None,
        }
    }
    pub fn text(&self, field: &str) -> Option<&str> {
        match self.values.get(field).map(|d| &d.value) {
            Some(Value::Text(s)) => Some(s),
            _ => None,
        }
    }
    pub fn bool(&self, field: &str) -> Option<bool> {
        match self.values.get(field).map(|d| &d.value) {
            Some(Value::Bool(b)) => Some(*b),
            _ => None,
        }
    }
}

const TOP_KEYS: [&str; 8] = [
    "id",
    "name",
    "class",
    "fit",
    "exclusion",
    "note",
    "sources",
    "values",
];

/// Line of the first line of `text` that assigns `key` (`key =` at line start), if any.
/// The line finder is deliberately simple: canonical records put one key per line.
pub fn line_of_key(text: &str, key: &str) -> Option<usize> {
    text.lines()
        .position(|l| {
            let t = l.trim_start();
            t.strip_prefix(key)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
        .map(|i| i + 1)
}

/// Parses a record, collecting every problem. Returns the robot when it is usable
/// (identity, class and fit status readable), even if some values had problems.
pub fn parse_record(
    text: &str,
    file: &str,
    vocab: &Vocabulary,
    problems: &mut Vec<Problem>,
) -> Option<Robot> {
    let table = parse_table(text, file, problems)?;
    let robot_hint = table.get("id").and_then(|v| v.as_str()).map(str::to_string);
    let p = |rule, field: &str, msg: String| {
        let mut pr = Problem::error(file, rule, msg)
            .field(field)
            .line(line_of_key(text, field.rsplit('.').next().unwrap_or(field)));
        pr.robot = robot_hint.clone();
        pr
    };

    check_top_keys(&table, &p, problems);

    let id = required_str(&table, "id", &p, problems);
    let name = required_str(&table, "name", &p, problems);
    let class_text = required_str(&table, "class", &p, problems);
    let class = parse_class(class_text.as_deref(), &p, problems);
    let fit = parse_fit(&table, &p, problems);
    let exclusion = optional_str(&table, "exclusion", &p, problems);
    let note = optional_str(&table, "note", &p, problems);

    let sources = parse_sources(&table, file, text, &robot_hint, problems);
    let values = parse_values(&table, file, text, &robot_hint, vocab, problems);

    Some(Robot {
        id: id?,
        name: name?,
        class: class?,
        fit: fit?,
        exclusion,
        note,
        sources,
        values,
    })
}

/// Parses the record's TOML, or records a parse problem and returns `None`.
fn parse_table(text: &str, file: &str, problems: &mut Vec<Problem>) -> Option<toml::Table> {
    match text.parse::<toml::Table>() {
        Ok(t) => Some(t),
        Err(e) => {
            problems.push(
                Problem::error(
                    file,
                    Rule::Parse,
                    format!("not valid TOML: {}", e.message()),
                )
                .line(e.span().map(|s| line_of_offset(text, s.start))),
            );
            None
        }
    }
}

/// Records an unknown-field problem for every top-level key not in `TOP_KEYS`.
fn check_top_keys(
    table: &toml::Table,
    p: &impl Fn(Rule, &str, String) -> Problem,
    problems: &mut Vec<Problem>,
) {
    for key in table.keys() {
        if !TOP_KEYS.contains(&key.as_str()) {
            problems.push(p(
                Rule::UnknownField,
                key,
                format!(
                    "unknown key `{key}` (top-level keys: {}; measured values go under [values])",
                    TOP_KEYS.join(", ")
                ),
            ));
        }
    }
}

/// A required non-empty string key; records a problem when missing, empty or not a string.
fn required_str(
    table: &toml::Table,
    key: &str,
    p: &impl Fn(Rule, &str, String) -> Problem,
    problems: &mut Vec<Problem>,
) -> Option<String> {
    match table.get(key) {
        None => {
            problems.push(p(
                Rule::MissingField,
                key,
                format!("required key `{key}` is missing"),
            ));
            None
        }
        Some(toml::Value::String(s)) if !s.trim().is_empty() => Some(s.clone()),
        Some(toml::Value::String(_)) => {
            problems.push(p(Rule::MissingField, key, format!("`{key}` is empty")));
            None
        }
        Some(other) => {
            problems.push(p(
                Rule::Type,
                key,
                format!("`{key}` must be a string, found {}", other.type_str()),
            ));
            None
        }
    }
}

/// The robot class named by `class_text`; records a problem when it is unknown.
fn parse_class(
    class_text: Option<&str>,
    p: &impl Fn(Rule, &str, String) -> Problem,
    problems: &mut Vec<Problem>,
) -> Option<RobotClass> {
    class_text.and_then(|c| {
        let parsed = RobotClass::parse(c);
        if parsed.is_none() {
            problems.push(p(
                Rule::Type,
                "class",
                format!(
                    "unknown class `{c}` (one of: {})",
                    RobotClass::ALL.map(|c| c.as_str()).join(", ")
                ),
            ));
        }
        parsed
    })
}

/// The required boolean `fit`; records a problem when missing or not a boolean.
fn parse_fit(
    table: &toml::Table,
    p: &impl Fn(Rule, &str, String) -> Problem,
    problems: &mut Vec<Problem>,
) -> Option<bool> {
    match table.get("fit") {
        None => {
            problems.push(p(
                Rule::MissingField,
                "fit",
                "required key `fit` (true/false) is missing".into(),
            ));
            None
        }
        Some(toml::Value::Boolean(b)) => Some(*b),
        Some(other) => {
            problems.push(p(
                Rule::Type,
                "fit",
                format!("`fit` must be true or false, found {}", other.type_str()),
            ));
            None
        }
    }
}

/// An optional string key; records a problem when present but not a string.
fn optional_str(
    table: &toml::Table,
    key: &str,
    p: &impl Fn(Rule, &str, String) -> Problem,
    problems: &mut Vec<Problem>,
) -> Option<String> {
    match table.get(key) {
        None => None,
        Some(toml::Value::String(s)) => Some(s.clone()),
        Some(other) => {
            problems.push(p(
                Rule::Type,
                key,
                format!("`{key}` must be a string, found {}", other.type_str()),
            ));
            None
        }
    }
}

fn parse_sources(
    table: &toml::Table,
    file: &str,
    text: &str,
    robot: &Option<String>,
    problems: &mut Vec<Problem>,
) -> Vec<Source> {
    let mut out = Vec::new();
    let err = |field: String, rule, msg: String| {
        let mut pr = Problem::error(file, rule, msg)
            .field(field)
            .line(line_of_key(text, "key"));
        pr.robot = robot.clone();
        pr
    };
    let Some(raw) = table.get("sources") else {
        return out;
    };
    let Some(list) = raw.as_array() else {
        problems.push(err(
            "sources".into(),
            Rule::Type,
            "`sources` must be an array of tables ([[sources]])".into(),
        ));
        return out;
    };
    for (i, item) in list.iter().enumerate() {
        let field = format!("sources[{i}]");
        let Some(t) = item.as_table() else {
            problems.push(err(field, Rule::Type, "each source must be a table".into()));
            continue;
        };
        for k in t.keys() {
            if !["key", "kind", "url", "title", "note"].contains(&k.as_str()) {
                problems.push(err(
                    format!("{field}.{k}"),
                    Rule::UnknownField,
                    format!("unknown source key `{k}` (key, kind, url, title, note)"),
                ));
            }
        }
        let s = |k: &str| t.get(k).and_then(|v| v.as_str()).map(str::to_string);
        let Some(key) = s("key") else {
            problems.push(err(
                format!("{field}.key"),
                Rule::MissingField,
                "source has no `key`".into(),
            ));
            continue;
        };
        let kind = match s("kind").as_deref().map(SourceKind::parse) {
            Some(Some(k)) => k,
            Some(None) | None => {
                problems.push(err(
                    format!("{field}.kind"),
                    Rule::Provenance,
                    format!(
                        "source `{key}` needs `kind` = one of {}",
                        SourceKind::ALL.map(|k| k.as_str()).join(", ")
                    ),
                ));
                continue;
            }
        };
        out.push(Source {
            key,
            kind,
            url: s("url"),
            title: s("title"),
            note: s("note"),
        });
    }
    out
}

fn parse_values(
    table: &toml::Table,
    file: &str,
    text: &str,
    robot: &Option<String>,
    vocab: &Vocabulary,
    problems: &mut Vec<Problem>,
) -> BTreeMap<String, Datum> {
    let mut out = BTreeMap::new();
    let Some(raw) = table.get("values") else {
        return out;
    };
    let Some(values) = raw.as_table() else {
        let mut pr =
            Problem::error(file, Rule::Type, "`values` must be a table ([values])").field("values");
        pr.robot = robot.clone();
        problems.push(pr);
        return out;
    };
    for (name, raw) in values {
        let at = ValueAt {
            file,
            text,
            robot,
            name,
        };
        if let Some(datum) = parse_value(&at, raw, vocab, problems) {
            out.insert(name.clone(), datum);
        }
    }
    out
}

/// Where a value sits, to locate its problems.
struct ValueAt<'a> {
    file: &'a str,
    text: &'a str,
    robot: &'a Option<String>,
    name: &'a str,
}

impl ValueAt<'_> {
    /// An error about this value, with its field name and line.
    fn problem(&self, rule: Rule, msg: String) -> Problem {
        let mut pr = Problem::error(self.file, rule, msg)
            .field(format!("values.{}", self.name))
            .line(line_of_key(self.text, self.name));
        pr.robot = self.robot.clone();
        pr
    }
}

/// One entry of `[values]`: checks the field against the vocabulary and reads its keys;
/// `None` when it has no usable value (the problems say why).
fn parse_value(
    at: &ValueAt,
    raw: &toml::Value,
    vocab: &Vocabulary,
    problems: &mut Vec<Problem>,
) -> Option<Datum> {
    let name = at.name;
    let Some(spec) = vocab.get(name) else {
        let hint = vocab
            .fields
            .iter()
            .find(|f| f.name.split('_').next() == name.split('_').next())
            .map(|f| format!(" (did you mean `{}`?)", f.name))
            .unwrap_or_default();
        problems.push(at.problem(
            Rule::UnknownField,
            format!("unknown field `{name}`{hint}; fields are listed in dataset/vocabulary.toml"),
        ));
        return None;
    };
    let Some(t) = raw.as_table() else {
        problems.push(at.problem(
            Rule::Type,
            format!("`{name}` must be an inline table like {{ value = ..., source = \"s1\" }}"),
        ));
        return None;
    };
    for k in t.keys() {
        if !VALUE_KEYS.contains(&k.as_str()) {
            problems.push(at.problem(
                Rule::UnknownField,
                format!("unknown key `{k}` in `{name}` ({})", VALUE_KEYS.join(", ")),
            ));
        }
    }
    let sources = source_keys(t.get("source"), &mut |m| {
        problems.push(at.problem(Rule::Type, m))
    });
    let note = t.get("note").and_then(|v| v.as_str()).map(str::to_string);
    let text_key = |key: &str, problems: &mut Vec<Problem>| match t.get(key) {
        None => None,
        Some(toml::Value::String(s)) => Some(s.clone()),
        Some(other) => {
            problems.push(at.problem(
                Rule::Type,
                format!(
                    "`{key}` of `{name}` must be a string, found {}",
                    other.type_str()
                ),
            ));
            None
        }
    };
    let at_key = text_key("at", problems);
    let derivation = text_key("derivation", problems);
    let gait = text_key("gait", problems);
    if gait.is_some() && spec.speed_kind.is_none() {
        problems.push(at.problem(
            Rule::UnknownField,
            format!("`gait` applies to speeds (speed_*_mps fields) only, not to `{name}`"),
        ));
    }
    let derived = match t.get("derived") {
        None => false,
        Some(toml::Value::Boolean(b)) => *b,
        Some(other) => {
            problems.push(at.problem(
                Rule::Type,
                format!(
                    "`derived` of `{name}` must be true or false, found {}",
                    other.type_str()
                ),
            ));
            false
        }
    };
    let history = parse_history(at, t.get("history"), problems);
    let value = parse_value_itself(at, t, spec.field_type, problems)?;
    Some(Datum {
        value,
        sources,
        at: at_key,
        gait,
        derived,
        derivation,
        note,
        history,
    })
}

/// A value's `history`: earlier values with their sources.
fn parse_history(
    at: &ValueAt,
    raw: Option<&toml::Value>,
    problems: &mut Vec<Problem>,
) -> Vec<Earlier> {
    let name = at.name;
    let mut history = Vec::new();
    match raw {
        None => {}
        Some(toml::Value::Array(items)) => {
            for item in items {
                if let Some(earlier) = parse_earlier(at, item, problems) {
                    history.push(earlier);
                }
            }
        }
        Some(other) => problems.push(at.problem(
            Rule::Type,
            format!(
                "`history` of `{name}` must be a list of inline tables, found {}",
                other.type_str()
            ),
        )),
    }
    history
}

/// One `history` entry.
fn parse_earlier(at: &ValueAt, item: &toml::Value, problems: &mut Vec<Problem>) -> Option<Earlier> {
    let name = at.name;
    let Some(h) = item.as_table() else {
        problems.push(at.problem(
            Rule::Type,
            format!("each `history` entry of `{name}` must be an inline table {{ value = ..., source = ... }}"),
        ));
        return None;
    };
    for k in h.keys() {
        if !["value", "min", "max", "source", "note"].contains(&k.as_str()) {
            problems.push(at.problem(
                Rule::UnknownField,
                format!("unknown key `{k}` in a `history` entry of `{name}` (value, min, max, source, note)"),
            ));
        }
    }
    let value = match (h.get("value"), h.get("min"), h.get("max")) {
        (Some(v), None, None) => toml_scalar(v),
        (None, lo, hi) if lo.is_some() || hi.is_some() => Some(Value::Range {
            min: lo.and_then(num),
            max: hi.and_then(num),
        }),
        _ => None,
    };
    let Some(value) = value else {
        problems.push(at.problem(
            Rule::MissingField,
            format!("a `history` entry of `{name}` needs a `value` (or `min`/`max`)"),
        ));
        return None;
    };
    let sources = source_keys(h.get("source"), &mut |m| {
        problems.push(at.problem(Rule::Type, m))
    });
    Some(Earlier {
        value,
        sources,
        note: h.get("note").and_then(|v| v.as_str()).map(str::to_string),
    })
}

/// The value proper: `value` of the field's type, or a numeric range `min`/`max`.
fn parse_value_itself(
    at: &ValueAt,
    t: &toml::Table,
    field_type: FieldType,
    problems: &mut Vec<Problem>,
) -> Option<Value> {
    let name = at.name;
    match (t.get("value"), t.get("min"), t.get("max")) {
        (Some(v), None, None) => match (field_type, v) {
            (FieldType::Number, v) if num(v).is_some() => num(v).map(Value::Number),
            (FieldType::Integer, toml::Value::Integer(i)) => Some(Value::Integer(*i)),
            (FieldType::Text, toml::Value::String(s)) => Some(Value::Text(s.clone())),
            (FieldType::Bool, toml::Value::Boolean(b)) => Some(Value::Bool(*b)),
            (ty, v) => {
                problems.push(at.problem(
                    Rule::Type,
                    format!(
                        "`{name}` must be {} , found {} `{v}`",
                        match ty {
                            FieldType::Number => "a number",
                            FieldType::Integer => "an integer",
                            FieldType::Text => "a string",
                            FieldType::Bool => "true or false",
                        },
                        v.type_str()
                    ),
                ));
                None
            }
        },
        (None, lo, hi) if (lo.is_some() || hi.is_some()) && field_type == FieldType::Number => {
            let lo_v = lo.and_then(num);
            let hi_v = hi.and_then(num);
            if (lo.is_some() && lo_v.is_none()) || (hi.is_some() && hi_v.is_none()) {
                problems
                    .push(at.problem(Rule::Type, format!("`{name}` range ends must be numbers")));
                None
            } else {
                Some(Value::Range {
                    min: lo_v,
                    max: hi_v,
                })
            }
        }
        (None, None, None) => {
            problems.push(at.problem(Rule::MissingField, format!("`{name}` has no `value`")));
            None
        }
        _ => {
            problems.push(at.problem(
                Rule::Type,
                format!("`{name}` takes either `value` or a numeric range `min`/`max`, not both"),
            ));
            None
        }
    }
}

/// Keys a value may carry.
pub const VALUE_KEYS: [&str; 10] = [
    "value",
    "min",
    "max",
    "source",
    "at",
    "gait",
    "derived",
    "derivation",
    "note",
    "history",
];

fn num(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// A TOML scalar as a value, keeping its own type (history entries are not typed by the
/// vocabulary: they record what a record used to say).
fn toml_scalar(v: &toml::Value) -> Option<Value> {
    match v {
        toml::Value::Float(x) => Some(Value::Number(*x)),
        toml::Value::Integer(i) => Some(Value::Integer(*i)),
        toml::Value::String(s) => Some(Value::Text(s.clone())),
        toml::Value::Boolean(b) => Some(Value::Bool(*b)),
        _ => None,
    }
}

/// `source = "key"` or `source = ["a", "b"]`.
fn source_keys(raw: Option<&toml::Value>, bad: &mut dyn FnMut(String)) -> Vec<String> {
    match raw {
        None => Vec::new(),
        Some(toml::Value::String(s)) => vec![s.clone()],
        Some(toml::Value::Array(a)) if a.iter().all(|v| v.is_str()) => a
            .iter()
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect(),
        Some(_) => {
            bad("`source` must be a key or a list of keys".into());
            Vec::new()
        }
    }
}
