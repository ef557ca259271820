//! Content rules of the motor catalogue, reported as [`MotorProblem`]s.
//!
//! Errors: non-finite or non-positive numbers; mass outside 1 g–20 kg; stall torque
//! outside 1e-4–1000 N·m; no-load speed outside 1–20,000 rpm; voltage outside 1–100 V;
//! duplicate or non-kebab-case ids; two ratings at one voltage; a recommended voltage with
//! no rating; an actuator without ratings; a non-datasheet stall torque without a note; a
//! `datasheet` source without a URL, or a URL that is not http(s); a law without sources,
//! or with an exponent outside 0.5–6; an anchor whose actuator is unknown or has no rating
//! at its voltage. Warnings: a mass-specific stall torque outside 1–200 N·m/kg (a likely
//! unit slip, e.g. grams typed as kilograms or kg·cm as N·m); a continuous torque above
//! the stall torque.

use std::collections::BTreeMap;

use serde::Serialize;

use super::{Actuator, Anchor, MotorCatalogue, MotorFile, MotorLaw, SourceKind, StallTorqueBasis};
use crate::dataset::{Problem, Rule, Severity};

/// Mass range [kg] of an actuator.
pub const MASS_KG: (f64, f64) = (1e-3, 20.0);
/// Stall-torque range [N·m].
pub const STALL_TORQUE_NM: (f64, f64) = (1e-4, 1000.0);
/// No-load speed range [rpm].
pub const NO_LOAD_SPEED_RPM: (f64, f64) = (1.0, 20_000.0);
/// Supply-voltage range [V].
pub const VOLTAGE_V: (f64, f64) = (1.0, 100.0);
/// Law exponent range.
pub const EXPONENT: (f64, f64) = (0.5, 6.0);
/// Mass-specific stall torque [N·m/kg] outside which a unit slip is suspected (warning).
/// walkers.md §5.3 finds 12–64 N·m/kg across the DYNAMIXEL servos.
pub const SPECIFIC_STALL_TORQUE: (f64, f64) = (1.0, 200.0);

/// One finding: `file:line:field: severity: message [rule]`, for entry `id`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MotorProblem {
    pub file: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    /// The entry's id (law id, actuator id, anchor design).
    pub id: Option<String>,
    /// The field, e.g. `mass_kg`, `ratings[1].stall_torque_nm`, `source.url`.
    pub field: Option<String>,
    pub severity: Severity,
    pub rule: Rule,
    pub message: String,
}

impl MotorProblem {
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// The same finding as a dataset [`Problem`] (the id as its `robot`), for the shared
    /// text and JSON reports.
    pub fn to_problem(&self) -> Problem {
        let mut p = Problem::new(&self.file, self.severity, self.rule, self.message.clone())
            .line(self.line);
        if let Some(id) = &self.id {
            p = p.robot(id.clone());
        }
        if let Some(f) = &self.field {
            p = p.field(f.clone());
        }
        p
    }

    /// `file:line:field: severity: message [rule]`, as `survey validate` prints it.
    pub fn to_line(&self) -> String {
        self.to_problem().to_line()
    }
}

/// Line of the entry whose `key = "value"` line identifies it, and of `field` inside it.
fn line_in_entry(text: &str, key: &str, value: &str, field: Option<&str>) -> Option<usize> {
    let lines: Vec<&str> = text.lines().collect();
    let quoted = format!("\"{value}\"");
    let start = lines.iter().position(|l| {
        let t = l.trim_start();
        t.strip_prefix(key)
            .is_some_and(|rest| rest.trim_start().starts_with('=') && rest.contains(&quoted))
    })?;
    let Some(field) = field else {
        return Some(start + 1);
    };
    // `ratings[1].stall_torque_nm` → `ratings`; `source.url` → `source`.
    let top = field.split(['[', '.']).next().unwrap_or(field);
    let found = lines[start..]
        .iter()
        .enumerate()
        .take_while(|(i, l)| *i == 0 || !l.trim_start().starts_with("[["))
        .find(|(_, l)| {
            let t = l.trim_start();
            t.strip_prefix(top)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
        .map(|(i, _)| start + i + 1);
    found.or(Some(start + 1))
}

struct Sink<'a> {
    file: &'a MotorFile,
    key: &'static str,
    out: Vec<MotorProblem>,
}

impl Sink<'_> {
    fn push(&mut self, sev: Severity, rule: Rule, id: &str, field: &str, msg: String) {
        let field = (!field.is_empty()).then(|| field.to_string());
        self.out.push(MotorProblem {
            file: self.file.name.clone(),
            line: line_in_entry(&self.file.text, self.key, id, field.as_deref()),
            id: (!id.is_empty()).then(|| id.to_string()),
            field,
            severity: sev,
            rule,
            message: msg,
        });
    }
    fn error(&mut self, rule: Rule, id: &str, field: &str, msg: String) {
        self.push(Severity::Error, rule, id, field, msg);
    }
    fn warning(&mut self, rule: Rule, id: &str, field: &str, msg: String) {
        self.push(Severity::Warning, rule, id, field, msg);
    }
    /// A positive finite number within `range` (inclusive), else an error.
    fn number(&mut self, id: &str, field: &str, v: f64, range: (f64, f64), unit: &str) {
        if !v.is_finite() || v <= 0.0 {
            self.error(
                Rule::Range,
                id,
                field,
                format!("{v} is not a positive finite number"),
            );
        } else if v < range.0 || v > range.1 {
            self.error(
                Rule::Range,
                id,
                field,
                format!("{v} {unit} is outside {}–{} {unit}", range.0, range.1),
            );
        }
    }
    fn positive(&mut self, id: &str, field: &str, v: f64) {
        if !v.is_finite() || v <= 0.0 {
            self.error(
                Rule::Range,
                id,
                field,
                format!("{v} is not a positive finite number"),
            );
        }
    }
    fn id(&mut self, id: &str, seen: &mut BTreeMap<String, usize>, what: &str) {
        let kebab = !id.is_empty()
            && id
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
            && !id.starts_with('-')
            && !id.ends_with('-');
        if !kebab {
            self.error(
                Rule::Definition,
                id,
                self.key,
                format!("{what} `{id}` is not kebab-case (a-z, 0-9, -)"),
            );
        }
        let n = seen.entry(id.to_string()).or_default();
        *n += 1;
        if *n == 2 {
            self.error(
                Rule::Duplicate,
                id,
                self.key,
                format!("duplicate {what} `{id}`"),
            );
        }
    }
    fn url(&mut self, id: &str, field: &str, url: &str) {
        if !(url.starts_with("https://") || url.starts_with("http://")) || url.contains(' ') {
            self.error(
                Rule::Provenance,
                id,
                field,
                format!("`{url}` is not an http(s) URL"),
            );
        }
    }
}

/// Every problem of the catalogue, errors first, then by file and line.
pub fn validate(cat: &MotorCatalogue) -> Vec<MotorProblem> {
    let mut out = Vec::new();
    out.extend(check_laws(&cat.files.laws, &cat.laws));
    out.extend(check_actuators(&cat.files.actuators, &cat.actuators));
    out.extend(check_anchors(&cat.files.anchors, cat));
    out.sort_by(|a, b| {
        (a.severity, &a.file, a.line, &a.id, &a.field)
            .cmp(&(b.severity, &b.file, b.line, &b.id, &b.field))
    });
    out
}

fn check_laws(file: &MotorFile, laws: &[MotorLaw]) -> Vec<MotorProblem> {
    let mut s = Sink {
        file,
        key: "id",
        out: Vec::new(),
    };
    let mut seen = BTreeMap::new();
    for law in laws {
        let id = law.id.as_str();
        s.id(id, &mut seen, "law id");
        s.number(id, "exponent", law.exponent, EXPONENT, "");
        if law.sources.is_empty() {
            s.error(
                Rule::Provenance,
                id,
                "sources",
                "a law needs at least one source".into(),
            );
        }
        for (i, r) in law.sources.iter().enumerate() {
            if r.citation.trim().is_empty() {
                s.error(
                    Rule::Provenance,
                    id,
                    &format!("sources[{i}].citation"),
                    "empty citation".into(),
                );
            }
            if let Some(u) = &r.url {
                s.url(id, &format!("sources[{i}].url"), u);
            }
        }
        if let Some(r) = &law.cited_by
            && let Some(u) = &r.url
        {
            s.url(id, "cited_by.url", u);
        }
        if let Some(c) = &law.coefficient {
            s.positive(id, "coefficient.value", c.value);
            if c.output_unit.trim().is_empty() || c.size_unit.trim().is_empty() {
                s.error(
                    Rule::MissingField,
                    id,
                    "coefficient",
                    "a coefficient needs its output_unit and size_unit".into(),
                );
            }
        }
    }
    s.out
}

fn check_actuators(file: &MotorFile, actuators: &[Actuator]) -> Vec<MotorProblem> {
    let mut s = Sink {
        file,
        key: "id",
        out: Vec::new(),
    };
    let mut seen = BTreeMap::new();
    for a in actuators {
        let id = a.id.as_str();
        s.id(id, &mut seen, "actuator id");
        check_actuator_numbers(&mut s, id, a);
        if a.ratings.is_empty() {
            s.error(
                Rule::MissingField,
                id,
                "ratings",
                "an actuator needs at least one rating".into(),
            );
        }
        check_ratings(&mut s, id, a);
        check_actuator_provenance(&mut s, id, a);
    }
    s.out
}

/// The actuator-wide numbers: mass, gear ratio, the recommended voltage (which must have a
/// rating) and the continuous torque (which should not exceed every stall torque).
fn check_actuator_numbers(s: &mut Sink<'_>, id: &str, a: &Actuator) {
    if let Some(m) = a.mass_kg {
        s.number(id, "mass_kg", m, MASS_KG, "kg");
    }
    if let Some(g) = a.gear_ratio {
        s.positive(id, "gear_ratio", g);
    }
    if let Some(v) = a.recommended_voltage_v {
        s.number(id, "recommended_voltage_v", v, VOLTAGE_V, "V");
        if v.is_finite() && a.rating(Some(v)).is_none() {
            s.error(
                Rule::Consistency,
                id,
                "recommended_voltage_v",
                format!("no rating at the recommended voltage {v} V"),
            );
        }
    }
    if let Some(t) = a.continuous_torque_nm {
        s.number(id, "continuous_torque_nm", t, STALL_TORQUE_NM, "N·m");
        let max_stall = a
            .ratings
            .iter()
            .map(|r| r.stall_torque_nm)
            .fold(f64::NAN, f64::max);
        if t > max_stall {
            s.warning(
                Rule::Consistency,
                id,
                "continuous_torque_nm",
                format!(
                    "continuous torque {t} N·m exceeds every stall torque (max {max_stall} N·m)"
                ),
            );
        }
    }
}

/// Each rating's numbers, one rating per voltage, and its mass-specific stall torque (a
/// value far outside the servos' range is most likely a unit slip).
fn check_ratings(s: &mut Sink<'_>, id: &str, a: &Actuator) {
    let mut voltages: Vec<f64> = Vec::new();
    for (i, r) in a.ratings.iter().enumerate() {
        let f = |k: &str| format!("ratings[{i}].{k}");
        if let Some(v) = r.voltage_v {
            s.number(id, &f("voltage_v"), v, VOLTAGE_V, "V");
            if voltages
                .iter()
                .any(|w| (w - v).abs() <= super::VOLTAGE_TOLERANCE_V)
            {
                s.error(
                    Rule::Duplicate,
                    id,
                    &f("voltage_v"),
                    format!("two ratings at {v} V"),
                );
            }
            voltages.push(v);
        }
        s.number(
            id,
            &f("stall_torque_nm"),
            r.stall_torque_nm,
            STALL_TORQUE_NM,
            "N·m",
        );
        if let Some(w) = r.no_load_speed_rpm {
            s.number(id, &f("no_load_speed_rpm"), w, NO_LOAD_SPEED_RPM, "rpm");
        }
        if let Some(c) = r.stall_current_a {
            s.positive(id, &f("stall_current_a"), c);
        }
        if let Some(m) = a.mass_kg
            && m.is_finite()
            && m > 0.0
            && r.stall_torque_nm.is_finite()
        {
            let specific = r.stall_torque_nm / m;
            if specific < SPECIFIC_STALL_TORQUE.0 || specific > SPECIFIC_STALL_TORQUE.1 {
                s.warning(
                    Rule::UnitPlausibility,
                    id,
                    &f("stall_torque_nm"),
                    format!(
                        "mass-specific stall torque {specific:.3} N·m/kg ({} N·m / {m} kg) is outside {}–{} N·m/kg: a unit slip?",
                        r.stall_torque_nm, SPECIFIC_STALL_TORQUE.0, SPECIFIC_STALL_TORQUE.1
                    ),
                );
            }
        }
    }
}

/// Where the numbers come from: a note for a stall torque that is not the datasheet's, a
/// URL for a datasheet source (any URL must be http(s)), and where in the source to look.
fn check_actuator_provenance(s: &mut Sink<'_>, id: &str, a: &Actuator) {
    if a.stall_torque_basis != StallTorqueBasis::Datasheet
        && a.note.as_deref().is_none_or(|n| n.trim().is_empty())
    {
        s.error(
            Rule::Provenance,
            id,
            "note",
            format!(
                "stall_torque_basis `{}` needs a note saying what the torque is",
                basis_name(a.stall_torque_basis)
            ),
        );
    }
    match &a.source.url {
        Some(u) => s.url(id, "source.url", u),
        None if a.source.kind == SourceKind::Datasheet => s.error(
            Rule::Provenance,
            id,
            "source.url",
            "a datasheet source needs a URL".into(),
        ),
        None => {}
    }
    if a.source.at.trim().is_empty() {
        s.error(
            Rule::Provenance,
            id,
            "source.at",
            "say where in the source the numbers are".into(),
        );
    }
}

fn basis_name(b: StallTorqueBasis) -> &'static str {
    match b {
        StallTorqueBasis::Datasheet => "datasheet",
        StallTorqueBasis::Extrapolated => "extrapolated",
        StallTorqueBasis::ModelLimit => "model_limit",
        StallTorqueBasis::Secondary => "secondary",
    }
}

fn check_anchors(file: &MotorFile, cat: &MotorCatalogue) -> Vec<MotorProblem> {
    let mut s = Sink {
        file,
        key: "design",
        out: Vec::new(),
    };
    let mut seen = BTreeMap::new();
    for an in &cat.anchors {
        let Anchor {
            design,
            actuator,
            voltage_v,
            leg_length_m,
            source,
            ..
        } = an;
        let id = design.as_str();
        s.id(id, &mut seen, "anchor design");
        s.number(id, "voltage_v", *voltage_v, VOLTAGE_V, "V");
        s.positive(id, "leg_length_m", *leg_length_m);
        match cat.actuator(actuator) {
            None => s.error(
                Rule::Consistency,
                id,
                "actuator",
                format!("unknown actuator `{actuator}` (not in actuators.toml)"),
            ),
            Some(a) if a.rating(Some(*voltage_v)).is_none() => s.error(
                Rule::Consistency,
                id,
                "voltage_v",
                format!("actuator `{actuator}` has no rating at {voltage_v} V"),
            ),
            Some(_) => {}
        }
        if source.citation.trim().is_empty() {
            s.error(
                Rule::Provenance,
                id,
                "source.citation",
                "empty citation".into(),
            );
        }
        if let Some(u) = &source.url {
            s.url(id, "source.url", u);
        }
    }
    s.out
}
