//! Import of the survey table published with the paper (`robot_scaling_dataset.csv` of
//! github.com/robomechanics/robot-dataset), with all its quirks.
//!
//! The raw file is a spreadsheet export: byte-order mark, CRLF line ends, a trailing empty
//! column, thousands separators in quoted numbers, ranges ("0.27-0.42", "1.5-2", "4 to 5"),
//! ranges that the spreadsheet turned into dates ("2-Jan" for "1-2"), inequalities
//! ("<250000"), notes inside names ("(excluded from power laws)"), text in numeric
//! columns, UTF-8 mis-decoded as Mac Roman ("‚Ñ¢" for "™"), a blank row and stray spaces.
//! Every quirk met is reported with its line, column and what was done; every row ends as
//! a record or as a recorded skip ([`UpstreamImport::ledger`]), so nothing is silently lost.

use std::collections::BTreeMap;

use serde::Serialize;

use super::record::{Datum, Robot, RobotClass, Source, SourceKind, Value};
use super::{Dataset, DatasetError};

/// Where the survey table is published (cited by the paper, Sec. II).
pub const SURVEY_URL: &str = "https://github.com/robomechanics/robot-dataset";
/// The source key imported values point at.
pub const SURVEY_KEY: &str = "survey";

/// One quirk of the raw file and how it was handled.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Quirk {
    /// 1-based physical line in the raw file (0 for whole-file quirks).
    pub line: usize,
    pub column: Option<String>,
    /// Stable name: bom, crlf, trailing-column, blank-row, whitespace, thousands-separator,
    /// range, spreadsheet-date, inequality, name-note, text-in-numeric, mojibake,
    /// ambiguous-class, hybrid-class, lab-reference, leading-decimal-point, missing-leg-length.
    pub kind: &'static str,
    pub raw: String,
    pub handled: String,
}

/// What became of one upstream row.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LedgerRow {
    pub line: usize,
    pub name: String,
    /// The record id, or None when skipped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub record: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skipped: Option<String>,
}

/// `dataset/upstream.toml`: the account of every upstream row, kept with the records.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ledger {
    pub file: String,
    pub sha256: String,
    #[serde(rename = "row")]
    pub rows: Vec<LedgerRow>,
}

pub const LEDGER_FILE: &str = "upstream.toml";

impl Ledger {
    pub fn to_toml(&self) -> String {
        let body = toml::to_string(self).unwrap_or_default();
        format!(
            "# What became of every row of the upstream survey table (robot_scaling_dataset.csv):\n\
             # imported as a record, or skipped with a reason. Written by\n\
             # `survey dataset import-upstream`, checked by `survey dataset import-upstream --check`.\n\n{body}"
        )
    }
}

/// The outcome of reading the upstream table.
#[derive(Debug, Clone, Serialize)]
pub struct UpstreamImport {
    pub sha256: String,
    pub robots: Vec<Robot>,
    pub ledger: Vec<LedgerRow>,
    pub quirks: Vec<Quirk>,
}

impl UpstreamImport {
    pub fn ledger(&self) -> Ledger {
        Ledger {
            file: "robot_scaling_dataset.csv".into(),
            sha256: self.sha256.clone(),
            rows: self.ledger.clone(),
        }
    }
}

/// Upstream column → vocabulary field (numbers unless noted).
const COLUMN_MAP: [(&str, &str); 21] = [
    ("year", "year"),
    ("cost_dollars", "cost_usd"),
    ("total_length_inm", "body_length_m"),
    ("leg_length_inm", "leg_length_m"),
    ("min_mass_inkg", "mass_min_kg"),
    ("max_mass_inkg", "mass_max_kg"),
    ("average_mass_inkg", "mass_kg"),
    ("normal_speed_inmps", "speed_normal_mps"),
    ("walking_speed_inmps", "speed_walking_mps"),
    ("running_speed_inmps", "speed_running_mps"),
    ("DOF", "dof"),
    ("payload_inkg", "payload_kg"),
    ("actuator_mass_inkg", "actuator_mass_kg"),
    ("accuator_count", "actuator_count"),
    (
        "highest_stall_torqueorforce_on_actuators_inNm",
        "stall_torque_nm",
    ),
    ("actuator_name", "actuator_name"),
    ("actuation_type", "actuation"),
    ("reported_COT", "cost_of_transport"),
    ("battery_life_hours", "battery_life_h"),
    ("battery_wt_inkg", "battery_mass_kg"),
    ("reference", ""),
];
const TEXT_FIELDS: [&str; 2] = ["actuator_name", "actuation"];
const INTEGER_FIELDS: [&str; 3] = ["year", "dof", "actuator_count"];
const NAME_NOTE: &str = "(excluded from power laws)";
const MONTHS: [&str; 12] = [
    "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
];

/// A numeric cell after reading.
#[derive(Debug, Clone, PartialEq)]
enum Cell {
    Empty,
    Number(f64),
    Range(Option<f64>, Option<f64>),
    Text(String),
}

/// The record id for a robot name: lowercase ASCII words joined by `-`.
pub fn slug(name: &str) -> String {
    let mut out = String::new();
    for ch in name.chars() {
        if ch.is_ascii_alphanumeric() {
            out.push(ch.to_ascii_lowercase());
        } else if !out.ends_with('-') && !out.is_empty() {
            out.push('-');
        }
    }
    out.trim_end_matches('-').to_string()
}

/// Repairs UTF-8 that was decoded as Mac Roman (e.g. "‚Ñ¢" → "™"): re-encode as Mac Roman
/// and accept the bytes if they are valid UTF-8 that differs from the input.
pub fn fix_mojibake(s: &str) -> Option<String> {
    if s.is_ascii() {
        return None;
    }
    let (bytes, _, unmappable) = encoding_rs::MACINTOSH.encode(s);
    if unmappable {
        return None;
    }
    let fixed = std::str::from_utf8(&bytes).ok()?;
    (fixed != s).then(|| fixed.to_string())
}

fn parse_plain(t: &str) -> Option<f64> {
    t.parse::<f64>().ok().filter(|x| x.is_finite())
}

/// Reads a numeric cell, recording the quirks it needed.
fn read_numeric(raw: &str, line: usize, column: &str, quirks: &mut Vec<Quirk>) -> Cell {
    let mut q = |kind, handled: String| {
        quirks.push(Quirk {
            line,
            column: Some(column.to_string()),
            kind,
            raw: raw.to_string(),
            handled,
        })
    };
    let t = raw.trim();
    if t.is_empty() {
        return Cell::Empty;
    }
    if t != raw {
        q("whitespace", format!("trimmed to `{t}`"));
    }
    // ".25": a number without its leading zero, reported where it stands (alone or as
    // either end of a range).
    let leading_point = |part: &str, x: f64| {
        part.starts_with('.')
            .then(|| format!("`{part}` read as {x}"))
    };
    if let Some(x) = parse_plain(t) {
        if let Some(how) = leading_point(t, x) {
            q("leading-decimal-point", how);
        }
        return Cell::Number(x);
    }
    // "160,000": thousands separators inside a quoted number.
    if t.contains(',') {
        let digits = t.replace(',', "");
        let grouped = t
            .split(',')
            .skip(1)
            .all(|g| g.len() == 3 && g.bytes().all(|b| b.is_ascii_digit()));
        if grouped && let Some(x) = parse_plain(&digits) {
            q("thousands-separator", format!("read as {x}"));
            return Cell::Number(x);
        }
    }
    for (prefix, lower) in [("<", false), (">", true)] {
        if let Some(rest) = t.strip_prefix(prefix) {
            let rest = rest.trim().replace(',', "");
            if let Some(x) = parse_plain(&rest) {
                q(
                    "inequality",
                    format!(
                        "kept as a one-sided range ({} {x})",
                        if lower { "min" } else { "max" }
                    ),
                );
                return if lower {
                    Cell::Range(Some(x), None)
                } else {
                    Cell::Range(None, Some(x))
                };
            }
        }
    }
    // "2-Jan": the spreadsheet read the range "1-2" as 2 January.
    if let Some((d, m)) = t.split_once('-')
        && let (Ok(day), Some(month)) = (d.parse::<u32>(), MONTHS.iter().position(|&mm| mm == m))
    {
        let month = month as u32 + 1;
        let (lo, hi) = (day.min(month) as f64, day.max(month) as f64);
        q(
            "spreadsheet-date",
            format!(
                "a spreadsheet turned the range `{month}-{day}` into a date; read as range {lo}..{hi}"
            ),
        );
        return Cell::Range(Some(lo), Some(hi));
    }
    for sep in ["-", " to "] {
        if let Some((a, b)) = t.split_once(sep)
            && let (Some(lo), Some(hi)) = (parse_plain(a.trim()), parse_plain(b.trim()))
        {
            for (part, x) in [(a.trim(), lo), (b.trim(), hi)] {
                if let Some(how) = leading_point(part, x) {
                    q("leading-decimal-point", how);
                }
            }
            q("range", format!("read as range {lo}..{hi}"));
            return Cell::Range(Some(lo.min(hi)), Some(lo.max(hi)));
        }
    }
    Cell::Text(t.to_string())
}

/// Every decimal number in free text, in order ("120 (standing) 40 (walking)" → [120, 40]).
fn numbers_in(text: &str) -> Vec<f64> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for ch in text.chars().chain(std::iter::once(' ')) {
        if ch.is_ascii_digit() || (ch == '.' && !cur.is_empty()) {
            cur.push(ch);
        } else if !cur.is_empty() {
            if let Some(x) = parse_plain(cur.trim_end_matches('.')) {
                out.push(x);
            }
            cur.clear();
        }
    }
    out
}

/// The kind of a cited document, from its address.
fn source_kind(url: &str) -> SourceKind {
    let u = url.to_ascii_lowercase();
    let papers = [
        "ieeexplore",
        "arxiv.org",
        "journals.sagepub",
        "nature.com",
        "science.org",
        "onlinelibrary.wiley",
        "/papers/",
        "techreport",
        "ri.cmu.edu/app/uploads",
        "project5.pdf",
        "clawar",
        "ijrr",
    ];
    if papers.iter().any(|p| u.contains(p)) {
        SourceKind::Paper
    } else if u.ends_with(".pdf")
        || u.contains("spec")
        || u.contains("datasheet")
        || u.contains("_tdp")
    {
        SourceKind::Datasheet
    } else {
        SourceKind::Web
    }
}

/// Splits "[1] url [2] url" into references.
fn split_references(raw: &str) -> Vec<String> {
    let mut refs = Vec::new();
    let mut rest = raw.trim();
    // Drop everything up to the first marker, then split at each "[n]".
    let marker = |s: &str| -> Option<(usize, usize)> {
        let b = s.as_bytes();
        let mut i = 0;
        while i < b.len() {
            if b[i] == b'[' {
                let mut j = i + 1;
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
                if j > i + 1 && j < b.len() && b[j] == b']' {
                    return Some((i, j + 1));
                }
            }
            i += 1;
        }
        None
    };
    if marker(rest).is_none() {
        if !rest.is_empty() {
            refs.push(rest.to_string());
        }
        return refs;
    }
    while let Some((_, end)) = marker(rest) {
        rest = &rest[end..];
        let next = marker(rest).map(|(s, _)| s).unwrap_or(rest.len());
        let item = rest[..next].trim();
        if !item.is_empty() {
            refs.push(item.to_string());
        }
        rest = &rest[next..];
    }
    refs
}

/// Reads the raw upstream file. Fails only when the file is not a survey table at all
/// (no header, missing columns); everything else is handled and reported.
pub fn import(bytes: &[u8], file: &str) -> Result<UpstreamImport, DatasetError> {
    let mut quirks = Vec::new();
    let body = strip_file_quirks(bytes, &mut quirks);
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(body);
    let headers = read_headers(&mut rdr, file, &mut quirks)?;
    let mut robots: Vec<Robot> = Vec::new();
    let mut ledger = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| parse_error(file, e))?;
        let row = Row {
            headers: &headers,
            line: rec.position().map(|p| p.line() as usize).unwrap_or(0),
            rec: &rec,
        };
        if rec.iter().all(|c| c.trim().is_empty()) {
            quirks.push(Quirk {
                line: row.line,
                column: None,
                kind: "blank-row",
                raw: ",".repeat(rec.len().saturating_sub(1)),
                handled: "skipped (recorded in the ledger)".into(),
            });
            ledger.push(LedgerRow {
                line: row.line,
                name: String::new(),
                record: None,
                skipped: Some("blank row".into()),
            });
            continue;
        }
        let robot = import_row(&row, &mut quirks);
        ledger.push(LedgerRow {
            line: row.line,
            name: robot.name.clone(),
            record: Some(robot.id.clone()),
            skipped: None,
        });
        robots.push(robot);
    }
    check_unique_ids(&robots, file)?;
    Ok(UpstreamImport {
        sha256: super::release::sha256_hex(bytes),
        robots,
        ledger,
        quirks,
    })
}

/// A quirk about one cell (or one row when `column` is `None`).
fn quirk(
    line: usize,
    column: Option<&str>,
    kind: &'static str,
    raw: impl Into<String>,
    handled: impl Into<String>,
) -> Quirk {
    Quirk {
        line,
        column: column.map(str::to_string),
        kind,
        raw: raw.into(),
        handled: handled.into(),
    }
}

fn parse_error(file: &str, e: csv::Error) -> DatasetError {
    DatasetError::Parse {
        file: file.to_string(),
        line: e.position().map(|p| p.line() as usize),
        message: e.to_string(),
    }
}

/// Whole-file quirks: strips a byte-order mark and notes CRLF line ends (the CSV reader
/// handles those itself). Returns the body the reader should see.
fn strip_file_quirks<'a>(bytes: &'a [u8], quirks: &mut Vec<Quirk>) -> &'a [u8] {
    let mut body = bytes;
    if let Some(rest) = body.strip_prefix(b"\xEF\xBB\xBF".as_slice()) {
        body = rest;
        quirks.push(quirk(
            0,
            None,
            "bom",
            "EF BB BF",
            "byte-order mark stripped",
        ));
    }
    if body.windows(2).any(|w| w == b"\r\n") {
        quirks.push(quirk(
            0,
            None,
            "crlf",
            "\\r\\n",
            "CRLF line ends read as line ends",
        ));
    }
    body
}

/// The header row: notes an empty trailing column and fails when a column the import
/// reads is missing (then the file is not the survey table).
fn read_headers(
    rdr: &mut csv::Reader<&[u8]>,
    file: &str,
    quirks: &mut Vec<Quirk>,
) -> Result<Vec<String>, DatasetError> {
    let headers: Vec<String> = rdr
        .headers()
        .map_err(|e| parse_error(file, e))?
        .iter()
        .map(|h| h.to_string())
        .collect();
    if headers.last().is_some_and(|h| h.is_empty()) {
        quirks.push(quirk(
            1,
            None,
            "trailing-column",
            "header ends with `,`",
            "empty trailing column ignored",
        ));
    }
    let has = |name: &str| headers.iter().any(|h| h == name);
    let mut missing: Vec<&str> = COLUMN_MAP
        .iter()
        .map(|(c, _)| *c)
        .filter(|c| !has(c))
        .collect();
    for c in ["robot_name", "type"] {
        if !has(c) {
            missing.push(c);
        }
    }
    if !missing.is_empty() {
        return Err(DatasetError::Invalid {
            file: file.to_string(),
            message: format!(
                "not the survey table: missing column(s) {}",
                missing.join(", ")
            ),
        });
    }
    Ok(headers)
}

/// One non-blank data row with its physical line.
struct Row<'a> {
    headers: &'a [String],
    rec: &'a csv::StringRecord,
    line: usize,
}

impl Row<'_> {
    /// The raw cell of a column ("" when the row is short).
    fn get(&self, name: &str) -> &str {
        self.headers
            .iter()
            .position(|h| h == name)
            .and_then(|i| self.rec.get(i))
            .unwrap_or("")
    }
}

/// One record from one data row.
fn import_row(row: &Row, quirks: &mut Vec<Quirk>) -> Robot {
    let line = row.line;
    let (name, excluded_upstream) = read_name(row, quirks);
    let id = slug(&name);
    let (class, raw_type) = read_class(row, quirks);
    let hybrid = class == RobotClass::Hybrid;
    let sources = read_sources(row, quirks);
    let values = read_values(row, class, quirks);
    let (fit, exclusion) = fit_status(
        line,
        &name,
        &values,
        excluded_upstream,
        hybrid.then_some(raw_type.as_str()),
        quirks,
    );
    Robot {
        id,
        name,
        class,
        fit,
        exclusion,
        note: Some(format!(
            "Imported from the survey table (robot_scaling_dataset.csv, line {line})."
        )),
        sources,
        values,
    }
}

/// The robot's name, trimmed and without the upstream exclusion note; the flag says
/// whether the note was there.
fn read_name(row: &Row, quirks: &mut Vec<Quirk>) -> (String, bool) {
    let raw_name = row.get("robot_name");
    let mut name = raw_name.trim().to_string();
    if name != raw_name {
        quirks.push(quirk(
            row.line,
            Some("robot_name"),
            "whitespace",
            raw_name,
            format!("name trimmed to `{name}`"),
        ));
    }
    let mut excluded_upstream = false;
    if let Some(stripped) = name.strip_suffix(NAME_NOTE) {
        excluded_upstream = true;
        quirks.push(quirk(
            row.line,
            Some("robot_name"),
            "name-note",
            name.clone(),
            "note removed from the name; the record is kept with fit = false and the note as its exclusion reason",
        ));
        name = stripped.trim().to_string();
    }
    (name, excluded_upstream)
}

/// Class from the survey's `type`; anything not purely legged becomes a hybrid. Also
/// returns the trimmed raw type (the hybrid's exclusion reason quotes it).
fn read_class(row: &Row, quirks: &mut Vec<Quirk>) -> (RobotClass, String) {
    let raw_type = row.get("type").trim().to_string();
    let class = match raw_type.as_str() {
        "lower biped" => RobotClass::LowerBiped,
        "full biped" => RobotClass::FullBiped,
        "quadruped" => RobotClass::Quadruped,
        "hexapod" => RobotClass::Hexapod,
        "biped" => {
            quirks.push(quirk(
                row.line,
                Some("type"),
                "ambiguous-class",
                raw_type.clone(),
                "`biped` read as full-biped (a humanoid with torso and arms)",
            ));
            RobotClass::FullBiped
        }
        other => {
            quirks.push(quirk(
                row.line,
                Some("type"),
                "hybrid-class",
                other,
                "class hybrid (not purely legged); kept, not fitted",
            ));
            RobotClass::Hybrid
        }
    };
    (class, raw_type)
}

/// Sources: the survey table itself, then the references it cites for the row.
fn read_sources(row: &Row, quirks: &mut Vec<Quirk>) -> Vec<Source> {
    let line = row.line;
    let mut sources = vec![Source {
        key: SURVEY_KEY.into(),
        kind: SourceKind::Dataset,
        url: Some(SURVEY_URL.into()),
        title: Some(format!(
            "Oke et al. 2026, legged-robot survey table robot_scaling_dataset.csv, line {line}"
        )),
        note: Some("values transcribed from the survey table, which cites the record's other sources for the row as a whole".into()),
    }];
    for (i, r) in split_references(row.get("reference"))
        .into_iter()
        .enumerate()
    {
        let key = format!("r{}", i + 1);
        if r.starts_with("http://") || r.starts_with("https://") {
            sources.push(Source {
                key,
                kind: source_kind(&r),
                url: Some(r),
                title: None,
                note: None,
            });
        } else {
            quirks.push(quirk(
                line,
                Some("reference"),
                "lab-reference",
                r.clone(),
                "not a URL: kept as a `lab` source with this title",
            ));
            sources.push(Source {
                key,
                kind: SourceKind::Lab,
                url: None,
                title: Some(r),
                note: None,
            });
        }
    }
    sources
}

/// A value transcribed from the survey table.
fn survey_datum(value: Value, note: Option<String>) -> Datum {
    Datum {
        value,
        sources: vec![SURVEY_KEY.to_string()],
        note,
        ..Datum::default()
    }
}

/// The row's values: text and numeric columns, a battery description found in the
/// battery-mass column, and `has_torso` from the biped classes.
fn read_values(row: &Row, class: RobotClass, quirks: &mut Vec<Quirk>) -> BTreeMap<String, Datum> {
    let mut values: BTreeMap<String, Datum> = BTreeMap::new();
    let mut battery_text: Option<String> = None;
    for (column, field) in COLUMN_MAP {
        if field.is_empty() {
            continue;
        }
        let raw = row.get(column);
        let datum = if TEXT_FIELDS.contains(&field) {
            read_text(raw, row.line, column, quirks)
        } else {
            match read_number(raw, row.line, column, field, quirks) {
                Numeric::Datum(d) => Some(d),
                Numeric::Battery(t) => {
                    battery_text = Some(t);
                    None
                }
                Numeric::Skip => None,
            }
        };
        if let Some(d) = datum {
            values.insert(field.into(), d);
        }
    }
    if let Some(t) = battery_text {
        values.insert("battery".into(), survey_datum(Value::Text(t), None));
    }
    if matches!(class, RobotClass::LowerBiped | RobotClass::FullBiped) {
        values.insert(
            "has_torso".into(),
            survey_datum(
                Value::Bool(class == RobotClass::FullBiped),
                Some("from the survey's lower/full biped classification".into()),
            ),
        );
    }
    values
}

/// A text column: trimmed and repaired from Mac Roman mojibake; `None` when empty.
fn read_text(raw: &str, line: usize, column: &str, quirks: &mut Vec<Quirk>) -> Option<Datum> {
    let t = raw.trim();
    if t.is_empty() {
        return None;
    }
    let mut text = t.to_string();
    if t != raw {
        quirks.push(quirk(
            line,
            Some(column),
            "whitespace",
            raw,
            format!("trimmed to `{t}`"),
        ));
    }
    if let Some(fixed) = fix_mojibake(&text) {
        quirks.push(quirk(
            line,
            Some(column),
            "mojibake",
            text.clone(),
            format!("UTF-8 that had been decoded as Mac Roman, repaired to `{fixed}`"),
        ));
        text = fixed;
    }
    Some(survey_datum(Value::Text(text), None))
}

/// What a numeric column gives.
enum Numeric {
    Datum(Datum),
    /// A battery description found in the battery-mass column.
    Battery(String),
    Skip,
}

/// A numeric column: numbers, ranges, and text with numbers in it (read, the text kept
/// as the value's note).
fn read_number(
    raw: &str,
    line: usize,
    column: &str,
    field: &str,
    quirks: &mut Vec<Quirk>,
) -> Numeric {
    let value = match read_numeric(raw, line, column, quirks) {
        Cell::Empty => return Numeric::Skip,
        Cell::Number(x) if INTEGER_FIELDS.contains(&field) && x.fract() == 0.0 => {
            Value::Integer(x as i64)
        }
        Cell::Number(x) => Value::Number(x),
        Cell::Range(lo, hi) => Value::Range { min: lo, max: hi },
        Cell::Text(t) if field == "battery_mass_kg" => {
            quirks.push(quirk(
                line,
                Some(column),
                "text-in-numeric",
                t.clone(),
                "a battery description in the battery-mass column: moved to `battery`",
            ));
            return Numeric::Battery(fix_mojibake(&t).unwrap_or(t));
        }
        Cell::Text(t) => return read_number_in_text(t, line, column, quirks),
    };
    Numeric::Datum(survey_datum(value, None))
}

/// Text in a numeric column: one number is read as the value, two or more as a range,
/// none drops the cell (the text stays in the record note).
fn read_number_in_text(t: String, line: usize, column: &str, quirks: &mut Vec<Quirk>) -> Numeric {
    let nums = numbers_in(&t);
    let (value, how) = match nums.as_slice() {
        [x] => (
            Value::Number(*x),
            format!("read as {x}, text kept as the value's note"),
        ),
        [a, b, ..] => (
            Value::Range {
                min: Some(a.min(*b)),
                max: Some(a.max(*b)),
            },
            format!(
                "read as range {}..{}, text kept as the value's note",
                a.min(*b),
                a.max(*b)
            ),
        ),
        [] => {
            quirks.push(quirk(
                line,
                Some(column),
                "text-in-numeric",
                t,
                "no number in it: dropped from values, kept in the record note",
            ));
            return Numeric::Skip;
        }
    };
    quirks.push(quirk(line, Some(column), "text-in-numeric", t.clone(), how));
    Numeric::Datum(survey_datum(value, Some(format!("upstream text: {t}"))))
}

/// Fit status: the upstream note, hybrids (`hybrid_type` is the survey type), and rows
/// without the fitted values. Returns `fit` and the exclusion reason.
fn fit_status(
    line: usize,
    name: &str,
    values: &BTreeMap<String, Datum>,
    excluded_upstream: bool,
    hybrid_type: Option<&str>,
    quirks: &mut Vec<Quirk>,
) -> (bool, Option<String>) {
    let missing: Vec<&str> = ["leg_length_m", "body_length_m", "mass_kg"]
        .into_iter()
        .filter(|f| values.get(*f).and_then(|d| d.value.as_f64()).is_none())
        .collect();
    let mut reasons = Vec::new();
    if excluded_upstream {
        reasons.push("marked \"(excluded from power laws)\" in the survey table".to_string());
    }
    if let Some(raw_type) = hybrid_type {
        reasons.push(format!("not purely legged (survey type \"{raw_type}\")"));
    }
    if !missing.is_empty() {
        reasons.push(format!("no {} reported", missing.join(", no ")));
        if !excluded_upstream && hybrid_type.is_none() {
            quirks.push(quirk(
                line,
                None,
                "missing-leg-length",
                name,
                format!("not marked excluded upstream but has no {}: kept with fit = false (the paper's counts exclude it)", missing.join(", ")),
            ));
        }
    }
    let fit = reasons.is_empty();
    let exclusion = (!fit).then(|| {
        let mut r = reasons.join("; ");
        if let Some(first) = r.get_mut(0..1) {
            first.make_ascii_uppercase();
        }
        r
    });
    (fit, exclusion)
}

/// Two rows must not give the same record id.
fn check_unique_ids(robots: &[Robot], file: &str) -> Result<(), DatasetError> {
    let mut seen = BTreeMap::new();
    for r in robots {
        if let Some(prev) = seen.insert(r.id.clone(), r.name.clone()) {
            return Err(DatasetError::Invalid {
                file: file.to_string(),
                message: format!(
                    "rows `{prev}` and `{}` give the same record id `{}`",
                    r.name, r.id
                ),
            });
        }
    }
    Ok(())
}

/// Outcome of `import-upstream --check`.
#[derive(Debug, Clone, Serialize)]
pub struct ImportCheck {
    pub release: String,
    pub release_sha256: String,
    pub import_sha256: String,
    pub table_matches: bool,
    pub differing_rows: Vec<String>,
    pub ledger_matches: bool,
    pub rows_imported: usize,
    pub rows_skipped: usize,
}

impl ImportCheck {
    pub fn ok(&self) -> bool {
        self.table_matches && self.ledger_matches
    }
}

/// Checks an import against a frozen release (byte for byte) and the dataset's row ledger.
pub fn check(
    ds: &Dataset,
    imp: &UpstreamImport,
    against: &str,
) -> Result<ImportCheck, DatasetError> {
    let frozen = ds.table(Some(against))?;
    let robots: Vec<&Robot> = imp.robots.iter().collect();
    // In the release's own columns: the vocabulary has grown since (speed kinds, 1.5.0).
    let imported =
        super::release::compile_robots(&ds.vocab, &robots, against).in_columns(&frozen.columns);
    let mut differing = Vec::new();
    for r in &imported.rows {
        if frozen.rows.iter().find(|f| f.id == r.id) != Some(r) {
            differing.push(r.id.clone());
        }
    }
    for f in &frozen.rows {
        if !imported.rows.iter().any(|r| r.id == f.id) {
            differing.push(format!("{} (only in the release)", f.id));
        }
    }
    let ledger_matches = match ds.files.bytes(LEDGER_FILE) {
        Some(b) => b == imp.ledger().to_toml().as_bytes(),
        None => false,
    };
    Ok(ImportCheck {
        release: against.to_string(),
        release_sha256: frozen.sha256.clone(),
        import_sha256: imported.sha256.clone(),
        table_matches: imported.sha256 == frozen.sha256,
        differing_rows: differing,
        ledger_matches,
        rows_imported: imp.robots.len(),
        rows_skipped: imp.ledger.iter().filter(|l| l.skipped.is_some()).count(),
    })
}
