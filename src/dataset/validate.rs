//! `survey validate`: every rule over every record, reporting all problems.
//!
//! Rules (their names are in [`Rule`]): parse errors, unknown/missing fields, types,
//! plausible ranges and unit slips, definitions (leg length ≤ body length, mass_min ≤
//! mass ≤ mass_max), the paper's class rules, duplicates, provenance of every value,
//! exclusion reasons, consistency, statistical outliers (warnings), integrity of frozen
//! releases and freshness of the metadata.

use std::collections::BTreeMap;

use serde::Serialize;

use super::Dataset;
use super::problem::{Problem, Rule, Severity};
use super::record::{Datum, Robot, RobotClass, SourceKind, Value};
use super::release::{self, SurveyTable, parse_semver};
use super::selection::{Group, TABLE2_PAIRS, log_points};
use super::vocabulary::{FieldSpec, FieldType};
use crate::regression::studentized_outliers;

/// Standard gravity [m/s²], for Froude numbers.
pub const G_MPS2: f64 = 9.80665;
/// Mass over leg length cubed [kg/m³] outside which a unit slip is suspected. The survey
/// spans about 9 (Ranger) to 3,400 (X2-VelociRoACH); a mass typed in grams lands near 10⁵+.
pub const MASS_PER_LEG_CUBED: (f64, f64) = (1.0, 20_000.0);
/// Froude number v²/(gL) above which walking is not possible (inverted-pendulum limit).
pub const WALK_FROUDE_LIMIT: f64 = 1.0;
/// |externally studentized residual| above which a fitted robot is reported as an outlier.
pub const OUTLIER_T: f64 = 3.0;
/// The first release whose speeds must all state their kind: from it on a speed of
/// unstated kind is an error in a release (it stays a warning in the live records).
pub const SPEED_KIND_REQUIRED_FROM: (u64, u64, u64) = (1, 5, 0);

/// The problems as a release must treat them: a speed of unstated kind, a warning in the
/// live records, is an error in a release (cutting one, or checking the rows of one from
/// [`SPEED_KIND_REQUIRED_FROM`] on).
pub fn as_release_problems(mut problems: Vec<Problem>) -> Vec<Problem> {
    for p in problems.iter_mut().filter(|p| p.rule == Rule::SpeedKind) {
        p.severity = Severity::Error;
    }
    problems
}

/// The outcome of validation.
#[derive(Debug, Clone, Serialize)]
pub struct ValidationReport {
    pub dataset: String,
    pub version: String,
    pub records: usize,
    pub problems: Vec<Problem>,
}

impl ValidationReport {
    pub fn errors(&self) -> usize {
        super::problem::count(&self.problems, Severity::Error)
    }
    pub fn warnings(&self) -> usize {
        super::problem::count(&self.problems, Severity::Warning)
    }
}

/// Validates the whole dataset.
pub fn validate(ds: &Dataset) -> ValidationReport {
    let mut problems = ds.parse_problems.clone();
    check_metadata(ds, &mut problems);
    for (rel, robot) in &ds.robots {
        let file = ds.files.display(rel);
        let text = ds
            .files
            .bytes(rel)
            .and_then(|b| std::str::from_utf8(b).ok());
        check_record(ds, rel, &file, robot, text, &mut problems);
    }
    check_duplicates(ds, &mut problems);
    check_outliers(ds, &mut problems);
    check_releases(ds, &mut problems);
    problems.sort_by(|a, b| {
        (a.severity, &a.file, a.line, &a.field, a.rule)
            .cmp(&(b.severity, &b.file, b.line, &b.field, b.rule))
    });
    ValidationReport {
        dataset: ds.files.origin.clone(),
        version: ds.meta.version.clone(),
        records: ds.robots.len()
            + ds.parse_problems
                .iter()
                .filter(|p| p.rule == Rule::Parse)
                .count(),
        problems,
    }
}

fn check_metadata(ds: &Dataset, problems: &mut Vec<Problem>) {
    let file = ds.files.display("dataset.toml");
    if parse_semver(&ds.meta.version).is_none() {
        problems.push(
            Problem::error(
                &file,
                Rule::Metadata,
                format!("version `{}` is not X.Y.Z", ds.meta.version),
            )
            .field("version"),
        );
    }
    let expected = super::datapackage::datapackage_json(ds);
    match ds.files.bytes(super::datapackage::FILE) {
        None => problems.push(Problem::error(
            &ds.files.display(super::datapackage::FILE),
            Rule::Metadata,
            "datapackage.json is missing (run `survey dataset package`)",
        )),
        Some(b) if b != expected.as_bytes() => problems.push(Problem::error(
            &ds.files.display(super::datapackage::FILE),
            Rule::Metadata,
            "datapackage.json is out of date with vocabulary.toml or dataset.toml (run `survey dataset package`)",
        )),
        Some(_) => {}
    }
}

fn problem(
    file: &str,
    robot: &Robot,
    field: &str,
    sev: Severity,
    rule: Rule,
    msg: String,
    text: Option<&str>,
) -> Problem {
    let key = field.rsplit('.').next().unwrap_or(field);
    Problem::new(file, sev, rule, msg)
        .robot(robot.id.clone())
        .field(field)
        .line(text.and_then(|t| super::record::line_of_key(t, key)))
}

/// Where a record's problems go, with its file, the record and its text (for the line of
/// each field).
struct RecordCheck<'a> {
    file: &'a str,
    r: &'a Robot,
    text: Option<&'a str>,
    problems: &'a mut Vec<Problem>,
}

impl RecordCheck<'_> {
    fn push(&mut self, field: &str, sev: Severity, rule: Rule, msg: String) {
        self.problems
            .push(problem(self.file, self.r, field, sev, rule, msg, self.text));
    }
}

fn check_record(
    ds: &Dataset,
    rel: &str,
    file: &str,
    r: &Robot,
    text: Option<&str>,
    problems: &mut Vec<Problem>,
) {
    let mut c = RecordCheck {
        file,
        r,
        text,
        problems,
    };
    check_id(&mut c, rel);
    for (name, d) in &r.values {
        let Some(spec) = ds.vocab.get(name) else {
            continue;
        };
        check_value(&mut c, name, d, spec);
        check_value_provenance(&mut c, name, d, spec);
        check_speed_kind(&mut c, &ds.vocab, name, d, spec);
    }
    check_sources(&mut c);
    check_fit_status(&mut c, ds);
    check_definitions(&mut c);
    check_unit_slips(&mut c);
    check_class(&mut c);
    check_froude(&mut c, &ds.vocab);
}

/// A speed states its kind (by its field) and names a known gait, if any.
fn check_speed_kind(
    c: &mut RecordCheck,
    vocab: &super::Vocabulary,
    name: &str,
    d: &Datum,
    spec: &FieldSpec,
) {
    use Severity::{Error, Warning};
    let field = format!("values.{name}");
    if let Some(g) = &d.gait
        && spec.speed_kind.is_some()
        && vocab.gait(g).is_none()
    {
        c.push(
            &field,
            Error,
            Rule::Range,
            format!(
                "unknown gait `{g}` (one of: {})",
                vocab
                    .gaits
                    .iter()
                    .map(|g| g.name.as_str())
                    .collect::<Vec<_>>()
                    .join(" | ")
            ),
        );
    }
    if spec.speed_kind == Some(super::SpeedKind::Unstated) {
        let kinds: Vec<&str> = super::SpeedKind::STATED.iter().map(|k| k.field()).collect();
        c.push(
            &field,
            Warning,
            Rule::SpeedKind,
            format!(
                "`{name}` does not say what kind of speed it is: move it to the field of its kind ({}), with `gait` where the source says; an error in a release from 1.5.0",
                kinds.join(", ")
            ),
        );
    }
}

/// File name and id.
fn check_id(c: &mut RecordCheck, rel: &str) {
    use Severity::Error;
    let r = c.r;
    let stem = rel.trim_start_matches("robots/").trim_end_matches(".toml");
    if stem != r.id {
        c.push(
            "id",
            Error,
            Rule::FileName,
            format!("id `{}` does not match the file name `{stem}.toml`", r.id),
        );
    }
    if r.id.is_empty()
        || !r
            .id
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
    {
        c.push(
            "id",
            Error,
            Rule::Type,
            format!("id `{}` must be lowercase letters, digits and `-`", r.id),
        );
    }
}

/// Types, ranges, allowed values of one value.
fn check_value(c: &mut RecordCheck, name: &str, d: &Datum, spec: &FieldSpec) {
    use Severity::Error;
    let r = c.r;
    let field = format!("values.{name}");
    let nums: Vec<f64> = match &d.value {
        Value::Number(x) => vec![*x],
        Value::Integer(i) => vec![*i as f64],
        Value::Range { min, max } => min.iter().chain(max.iter()).copied().collect(),
        _ => vec![],
    };
    for x in nums {
        if !x.is_finite() {
            c.push(
                &field,
                Error,
                Rule::Type,
                format!("`{name}` is not a finite number"),
            );
            continue;
        }
        let below = spec.min.is_some_and(|m| x < m);
        let above = spec.max.is_some_and(|m| x > m);
        if below || above {
            c.push(
                &field,
                Error,
                Rule::Range,
                format!(
                    "`{name}` = {x} {} is outside the plausible range [{}, {}] {}; check the unit ({})",
                    spec.unit,
                    spec.min.map(|m| m.to_string()).unwrap_or("-inf".into()),
                    spec.max.map(|m| m.to_string()).unwrap_or("inf".into()),
                    spec.unit,
                    spec.description
                ),
            );
        }
    }
    if let Value::Range {
        min: Some(lo),
        max: Some(hi),
    } = d.value
        && lo > hi
    {
        c.push(
            &field,
            Error,
            Rule::Definition,
            format!("range min {lo} > max {hi}"),
        );
    }
    if let Value::Range { .. } = d.value
        && spec.fit_variable
        && r.fit
    {
        c.push(
            &field,
            Error,
            Rule::Exclusion,
            format!("`{name}` is used in fits and needs a point `value`, not a range"),
        );
    }
    if spec.field_type == FieldType::Text
        && !spec.allowed.is_empty()
        && let Value::Text(s) = &d.value
        && !spec.allowed.iter().any(|a| a == s)
    {
        c.push(
            &field,
            Error,
            Rule::Range,
            format!("`{s}` is not one of: {}", spec.allowed.join(" | ")),
        );
    }
}

/// Provenance of one value.
fn check_value_provenance(c: &mut RecordCheck, name: &str, d: &Datum, spec: &FieldSpec) {
    use Severity::{Error, Warning};
    let r = c.r;
    let field = format!("values.{name}");
    if d.sources.is_empty() {
        let fitted = spec.fit_variable && r.fit;
        c.push(
            &field,
            if fitted { Error } else { Warning },
            Rule::Provenance,
            if fitted {
                format!("`{name}` is used in a fit but names no source")
            } else {
                format!("`{name}` names no source")
            },
        );
    }
    if d.derived && d.derivation.as_deref().is_none_or(|x| x.trim().is_empty()) {
        c.push(
            &field,
            Error,
            Rule::Provenance,
            format!(
                "`{name}` is marked derived but has no `derivation` note saying how it was derived from its source"
            ),
        );
    }
    if !d.derived && d.derivation.is_some() {
        c.push(
            &field,
            Warning,
            Rule::Provenance,
            format!("`{name}` has a `derivation` note but is not marked `derived = true`"),
        );
    }
    for key in d
        .sources
        .iter()
        .chain(d.history.iter().flat_map(|h| h.sources.iter()))
    {
        if !r.sources.iter().any(|s| &s.key == key) {
            c.push(
                &field,
                Error,
                Rule::Provenance,
                format!("source `{key}` is not among the record's [[sources]]"),
            );
        }
    }
}

/// Sources themselves.
fn check_sources(c: &mut RecordCheck) {
    use Severity::Error;
    let r = c.r;
    let mut keys = BTreeMap::new();
    for (i, s) in r.sources.iter().enumerate() {
        let field = format!("sources[{i}]");
        if keys.insert(s.key.clone(), i).is_some() {
            c.push(
                &field,
                Error,
                Rule::Provenance,
                format!("source key `{}` is used twice", s.key),
            );
        }
        match (&s.url, s.kind) {
            (Some(u), _)
                if !(u.starts_with("https://") || u.starts_with("http://"))
                    || u.contains(char::is_whitespace) =>
            {
                c.push(
                    &format!("{field}.url"),
                    Error,
                    Rule::Provenance,
                    format!("`{u}` is not an http(s) URL"),
                );
            }
            (None, SourceKind::Lab) if s.title.is_some() => {}
            (None, _) => c.push(
                &field,
                Error,
                Rule::Provenance,
                format!(
                    "source `{}` needs a `url` (or, for kind lab, a `title`)",
                    s.key
                ),
            ),
            _ => {}
        }
    }
}

/// Fit status.
fn check_fit_status(c: &mut RecordCheck, ds: &Dataset) {
    use Severity::{Error, Warning};
    let r = c.r;
    if !r.fit && r.exclusion.as_deref().is_none_or(|e| e.trim().is_empty()) {
        c.push(
            "exclusion",
            Error,
            Rule::Exclusion,
            "a robot kept but not fitted needs an `exclusion` reason".into(),
        );
    }
    if r.fit {
        if r.class == RobotClass::Hybrid {
            c.push(
                "fit",
                Error,
                Rule::Class,
                "hybrid robots (not purely legged) are not fitted with the legged classes".into(),
            );
        }
        for f in ds.vocab.fields.iter().filter(|f| f.fit_variable) {
            if r.number(&f.name).is_none()
                && !matches!(
                    r.values.get(&f.name).map(|d| &d.value),
                    Some(Value::Range { .. })
                )
            {
                c.push(
                    &format!("values.{}", f.name),
                    Error,
                    Rule::Exclusion,
                    format!(
                        "fitted robot has no `{}`: add it or set fit = false with a reason",
                        f.name
                    ),
                );
            }
        }
        if r.exclusion.is_some() {
            c.push(
                "exclusion",
                Warning,
                Rule::Exclusion,
                "an exclusion reason on a fitted robot (fit = true)".into(),
            );
        }
    }
}

/// Definitions.
fn check_definitions(c: &mut RecordCheck) {
    use Severity::{Error, Warning};
    let r = c.r;
    let leg = r.number("leg_length_m");
    let body = r.number("body_length_m");
    let mass = r.number("mass_kg");
    if let (Some(l), Some(b)) = (leg, body)
        && l > b
    {
        c.push(
            "values.leg_length_m",
            Error,
            Rule::Definition,
            format!(
                "leg length {l} m exceeds body length {b} m: leg length is the standing hip height and body length the longest dimension, so L ≤ L_B"
            ),
        );
    }
    if let Some(m) = mass {
        if let Some(lo) = r.number("mass_min_kg")
            && lo > m
        {
            c.push(
                "values.mass_min_kg",
                Error,
                Rule::Definition,
                format!("mass_min {lo} kg exceeds mass {m} kg"),
            );
        }
        if let Some(hi) = r.number("mass_max_kg")
            && hi < m
        {
            c.push(
                "values.mass_max_kg",
                Error,
                Rule::Definition,
                format!("mass_max {hi} kg is below mass {m} kg"),
            );
        }
    }
    // An average needs both ends: "min 20, average 30, no max" is not an average of
    // anything reported (the survey's average column filled from one bound and a guess).
    if let Some(m) = mass {
        let (lo, hi) = (r.number("mass_min_kg"), r.number("mass_max_kg"));
        let one = match (lo, hi) {
            (Some(b), None) => Some(("mass_min_kg", "mass_max_kg", b)),
            (None, Some(b)) => Some(("mass_max_kg", "mass_min_kg", b)),
            _ => None,
        };
        if let Some((given, absent, b)) = one
            && (m - b).abs() > 1e-9 * m.abs().max(b.abs())
        {
            c.push(
                "values.mass_kg",
                Warning,
                Rule::Definition,
                format!(
                    "mass {m} kg is given as an average but only `{given}` ({b} kg) is reported, no `{absent}`: an average of one bound is not defined; give the reported mass, or both bounds"
                ),
            );
        }
    }
    if let (Some(lo), Some(hi)) = (r.number("mass_min_kg"), r.number("mass_max_kg"))
        && lo > hi
    {
        c.push(
            "values.mass_min_kg",
            Error,
            Rule::Definition,
            format!("mass_min {lo} kg exceeds mass_max {hi} kg"),
        );
    }
}

/// Unit slips: mass against leg³, body against leg.
fn check_unit_slips(c: &mut RecordCheck) {
    use Severity::Error;
    let r = c.r;
    let leg = r.number("leg_length_m");
    let body = r.number("body_length_m");
    let mass = r.number("mass_kg");
    if let (Some(l), Some(m)) = (leg, mass) {
        let rho = m / l.powi(3);
        let (lo, hi) = MASS_PER_LEG_CUBED;
        if !(lo..=hi).contains(&rho) {
            let hint = if rho > hi {
                "a mass typed in grams, or a leg length in the wrong unit?"
            } else {
                "a leg length typed in mm or cm, or a mass in tonnes?"
            };
            c.push(
                "values.mass_kg",
                Error,
                Rule::UnitPlausibility,
                format!(
                    "mass / leg length³ = {rho:.3e} kg/m³ is outside [{lo}, {hi}] seen across legged robots: {hint}"
                ),
            );
        }
    }
    if let (Some(l), Some(b)) = (leg, body)
        && b / l > 20.0
    {
        c.push(
            "values.body_length_m",
            Error,
            Rule::UnitPlausibility,
            format!("body length is {:.0}× the leg length: a unit slip?", b / l),
        );
    }
    if let (Some(p), Some(m)) = (r.number("battery_mass_kg"), mass)
        && p >= m
    {
        c.push(
            "values.battery_mass_kg",
            Error,
            Rule::Consistency,
            format!("battery mass {p} kg is not less than the robot mass {m} kg"),
        );
    }
    if let (Some(a), Some(n), Some(m)) = (
        r.number("actuator_mass_kg"),
        r.integer("actuator_count"),
        mass,
    ) && a * n as f64 > m
    {
        c.push(
            "values.actuator_mass_kg",
            Error,
            Rule::Consistency,
            format!("{n} actuators of {a} kg weigh more than the robot ({m} kg)"),
        );
    }
}

/// Class rules (paper, Sec. II): a biped without upper torso or with < 4 DOF is a
/// lower biped, any other biped a full biped.
fn check_class(c: &mut RecordCheck) {
    use Severity::{Error, Warning};
    let r = c.r;
    if matches!(r.class, RobotClass::LowerBiped | RobotClass::FullBiped) {
        match r.bool("has_torso") {
            None => c.push(
                "values.has_torso",
                Error,
                Rule::Class,
                "a biped needs `has_torso` to check its class".into(),
            ),
            Some(torso) => {
                let dof = r.integer("dof");
                let lower = !torso || dof.is_some_and(|d| d < 4);
                if r.class == RobotClass::FullBiped && lower {
                    c.push(
                        "class",
                        Error,
                        Rule::Class,
                        format!(
                            "a biped with{} torso and {} DOF is a lower-biped by the paper's rule",
                            if torso { "" } else { "out" },
                            dof.map(|d| d.to_string()).unwrap_or("unknown".into())
                        ),
                    );
                }
                if r.class == RobotClass::LowerBiped && !lower {
                    c.push(
                        "class",
                        Error,
                        Rule::Class,
                        format!(
                            "a biped with an upper torso and {} DOF is a full-biped by the paper's rule (lower: no torso or < 4 DOF)",
                            dof.map(|d| d.to_string()).unwrap_or("unknown".into())
                        ),
                    );
                }
            }
        }
    } else if r.values.contains_key("has_torso") && r.class != RobotClass::Hybrid {
        c.push(
            "values.has_torso",
            Warning,
            Rule::Class,
            "`has_torso` only decides between biped classes".into(),
        );
    }
}

/// Consistency with locomotion physics: walking above Froude 1 is impossible. A speed is
/// taken as walking when its gait is a walking gait (the vocabulary's `walking = true`),
/// when it is a walking speed with no gait stated, or — a speed of unstated kind — when
/// a biped reports it and no faster running speed.
fn check_froude(c: &mut RecordCheck, vocab: &super::Vocabulary) {
    use super::SpeedKind;
    use Severity::Warning;
    let r = c.r;
    let Some(l) = r.number("leg_length_m") else {
        return;
    };
    let biped = matches!(r.class, RobotClass::LowerBiped | RobotClass::FullBiped);
    for (name, d) in &r.values {
        let Some(kind) = vocab.get(name).and_then(|f| f.speed_kind) else {
            continue;
        };
        let Some(v) = d.value.as_f64() else {
            continue;
        };
        let gait = d.gait.as_deref().and_then(|g| vocab.gait(g));
        let walking = match (gait, kind) {
            (Some(g), _) => g.walking,
            (None, SpeedKind::Walking) => true,
            (None, SpeedKind::Unstated) => {
                // A biped's "normal" speed is a walking speed; quadrupeds and hexapods
                // normally trot, bound or run (Froude ≫ 1 for RHex-like runners is real).
                biped && !r.number("speed_running_mps").is_some_and(|vr| vr >= v)
            }
            (None, _) => false,
        };
        let fr = v * v / (G_MPS2 * l);
        if walking && fr > WALK_FROUDE_LIMIT {
            let what = match (gait, kind) {
                (Some(g), _) => format!("in gait `{}`", g.name),
                (None, SpeedKind::Unstated) => "(a speed of unstated kind)".to_string(),
                (None, _) => format!("as a {kind} speed"),
            };
            c.push(
                &format!("values.{name}"),
                Warning,
                Rule::Consistency,
                format!(
                    "{v} m/s {what} on a {l} m leg is Froude number v²/(gL) = {fr:.2} > 1, beyond the walk–run limit: is it a running or top speed in another gait, or a unit slip?"
                ),
            );
        }
    }
}

fn norm_name(s: &str) -> String {
    s.chars()
        .filter(|c| c.is_alphanumeric())
        .flat_map(char::to_lowercase)
        .collect()
}

fn check_duplicates(ds: &Dataset, problems: &mut Vec<Problem>) {
    let robots: Vec<_> = ds.robots.iter().collect();
    for (i, (fa, a)) in robots.iter().enumerate() {
        for (fb, b) in robots.iter().skip(i + 1) {
            let file = ds.files.display(fb);
            if a.id == b.id || norm_name(&a.name) == norm_name(&b.name) {
                problems.push(
                    Problem::error(
                        &file,
                        Rule::Duplicate,
                        format!("same robot as {} (`{}`)", ds.files.display(fa), a.name),
                    )
                    .robot(b.id.clone())
                    .field("name"),
                );
                continue;
            }
            let close = |f: &str| match (a.number(f), b.number(f)) {
                (Some(x), Some(y)) => (x - y).abs() <= 0.005 * x.abs().max(y.abs()),
                _ => false,
            };
            if close("leg_length_m") && close("body_length_m") && close("mass_kg") {
                problems.push(
                    Problem::warning(
                        &file,
                        Rule::Duplicate,
                        format!("leg length, body length and mass are within 0.5% of `{}` ({}): the same robot twice?", a.name, ds.files.display(fa)),
                    )
                    .robot(b.id.clone()),
                );
            }
        }
    }
}

fn check_outliers(ds: &Dataset, problems: &mut Vec<Problem>) {
    let table = release::compile(ds);
    let locate = |id: &str| {
        let (rel, _) = ds.robots.iter().find(|(_, r)| r.id == id)?;
        Some((ds.files.display(rel), None))
    };
    push_outliers(
        &table,
        locate,
        "; check the values and their sources",
        problems,
    );
}

/// A fitted robot far from its class line in one Table 2 relation.
struct Outlier {
    id: String,
    class: Group,
    x: &'static str,
    y: &'static str,
    y_field: &'static str,
    /// Externally studentized (leave-one-out) residual of the OLS log–log fit.
    t: f64,
}

/// Fitted robots whose leave-one-out studentized residual exceeds [`OUTLIER_T`] in any
/// Table 2 relation of their class (classes with fewer than 5 robots are skipped).
fn outliers(table: &SurveyTable) -> Vec<Outlier> {
    let mut out = Vec::new();
    for class in RobotClass::FITTED {
        let g = Group::Class(class);
        for (x, y) in TABLE2_PAIRS {
            // Unusable values (non-positive, …) are the other rules' business.
            let Ok(p) = log_points(table, g, x, y) else {
                continue;
            };
            for (i, t) in studentized_outliers(&p.lx, &p.ly, OUTLIER_T) {
                out.push(Outlier {
                    id: p.ids[i].clone(),
                    class: g,
                    x: x.as_str(),
                    y: y.as_str(),
                    y_field: y.field(),
                    t,
                });
            }
        }
    }
    out
}

/// One warning per outlier of `table`, at the file (and line) `locate` gives its robot
/// (none: not reported); `advice` ends the message.
fn push_outliers(
    table: &SurveyTable,
    locate: impl Fn(&str) -> Option<(String, Option<usize>)>,
    advice: &str,
    problems: &mut Vec<Problem>,
) {
    for o in outliers(table) {
        let Some((file, line)) = locate(&o.id) else {
            continue;
        };
        problems.push(
            Problem::warning(
                &file,
                Rule::Outlier,
                format!(
                    "{} vs {}: leave-one-out studentized residual {:+.2} against the {} fit (|t| > {OUTLIER_T}){advice}",
                    o.y, o.x, o.t, o.class
                ),
            )
            .robot(o.id.clone())
            .field(format!("values.{}", o.y_field))
            .line(line),
        );
    }
}

fn check_releases(ds: &Dataset, problems: &mut Vec<Problem>) {
    let file = ds.files.display(release::MANIFEST);
    let manifest = match ds.manifest() {
        Ok(m) => m,
        Err(e) => {
            problems.push(Problem::error(&file, Rule::ReleaseIntegrity, e.to_string()));
            return;
        }
    };
    let mut seen = BTreeMap::new();
    for r in &manifest.releases {
        if parse_semver(&r.version).is_none() {
            problems.push(Problem::error(
                &file,
                Rule::ReleaseIntegrity,
                format!("release `{}` is not X.Y.Z", r.version),
            ));
        }
        if seen.insert(r.version.clone(), ()).is_some() {
            problems.push(Problem::error(
                &file,
                Rule::ReleaseIntegrity,
                format!("release {} is listed twice", r.version),
            ));
        }
        for (rel, msg) in release::verify_release(ds, r) {
            problems.push(Problem::error(
                &ds.files.display(&rel),
                Rule::ReleaseIntegrity,
                msg,
            ));
        }
    }
    // A file under releases/X/ that the manifest does not list is not frozen: flag it.
    for rel in ds
        .files
        .files
        .keys()
        .filter(|k| k.starts_with("releases/") && k.as_str() != release::MANIFEST)
    {
        let listed = manifest.releases.iter().any(|r| {
            r.files
                .iter()
                .any(|f| format!("releases/{}", f.path) == *rel)
        });
        if !listed {
            problems.push(Problem::error(
                &ds.files.display(rel),
                Rule::ReleaseIntegrity,
                "file in releases/ that the manifest does not list".to_string(),
            ));
        }
    }
    let newest = manifest
        .releases
        .iter()
        .filter_map(|r| parse_semver(&r.version))
        .max();
    if let (Some(n), Some(live)) = (newest, parse_semver(&ds.meta.version))
        && live < n
    {
        problems.push(
            Problem::error(
                &ds.files.display("dataset.toml"),
                Rule::Metadata,
                format!(
                    "live version {} is older than the latest release {}.{}.{}",
                    ds.meta.version, n.0, n.1, n.2
                ),
            )
            .field("version"),
        );
    }
}

/// The fields whose values are fitted (leg length, body length, mass), in report order.
pub const FITTED_FIELDS: [&str; 3] = ["leg_length_m", "body_length_m", "mass_kg"];

/// How many fitted values cite a primary source, for one field and class (or all).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Count {
    /// Fitted values (robots with fit = true that give the field).
    pub values: usize,
    /// Of those, values citing at least one primary source (not a `dataset` or `secondary`).
    pub primary: usize,
    /// Of those primary values, the ones marked `derived`.
    pub derived: usize,
}

impl Count {
    pub fn share(&self) -> f64 {
        if self.values == 0 {
            0.0
        } else {
            self.primary as f64 / self.values as f64
        }
    }
    fn add(&mut self, o: Count) {
        self.values += o.values;
        self.primary += o.primary;
        self.derived += o.derived;
    }
}

/// Provenance coverage of the fitted values: per field and class, per field, and overall.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Coverage {
    /// (field, class) → count, classes in Table 2 order.
    pub cells: Vec<(String, RobotClass, Count)>,
    pub per_field: Vec<(String, Count)>,
    pub per_class: Vec<(RobotClass, Count)>,
    pub total: Count,
}

/// Whether a value cites a primary source of its record.
pub fn has_primary_source(r: &Robot, d: &super::record::Datum) -> bool {
    d.sources
        .iter()
        .any(|k| r.sources.iter().any(|s| &s.key == k && s.kind.is_primary()))
}

/// Provenance coverage of the fitted values of the live records.
pub fn coverage(ds: &Dataset) -> Coverage {
    let mut cov = Coverage::default();
    let mut per_class: BTreeMap<RobotClass, Count> = BTreeMap::new();
    for field in FITTED_FIELDS {
        let mut field_total = Count::default();
        for class in RobotClass::FITTED {
            let mut c = Count::default();
            for (_, r) in ds.robots.iter().filter(|(_, r)| r.fit && r.class == class) {
                let Some(d) = r.values.get(field) else {
                    continue;
                };
                c.values += 1;
                if has_primary_source(r, d) {
                    c.primary += 1;
                    if d.derived {
                        c.derived += 1;
                    }
                }
            }
            cov.cells.push((field.to_string(), class, c));
            field_total.add(c);
            per_class.entry(class).or_default().add(c);
        }
        cov.per_field.push((field.to_string(), field_total));
        cov.total.add(field_total);
    }
    cov.per_class = per_class.into_iter().collect();
    cov
}

/// The coverage as the table `survey validate` prints after the problems.
pub fn coverage_text(cov: &Coverage) -> String {
    let pct = |c: &Count| {
        if c.values == 0 {
            "    -".to_string()
        } else {
            format!(
                "{:>4.0}% {:>2}/{:<2}",
                100.0 * c.share(),
                c.primary,
                c.values
            )
        }
    };
    let mut out = String::from(
        "provenance coverage: fitted values citing a primary source (paper, datasheet, web, lab, model; not the survey table)
",
    );
    out.push_str(&format!("  {:<14}", "field"));
    for class in RobotClass::FITTED {
        out.push_str(&format!(" {:>12}", class.as_str()));
    }
    out.push_str(&format!(" {:>12}\n", "all"));
    for (field, total) in &cov.per_field {
        out.push_str(&format!("  {field:<14}"));
        for class in RobotClass::FITTED {
            let c = cov
                .cells
                .iter()
                .find(|(f, k, _)| f == field && *k == class)
                .map(|(_, _, c)| *c)
                .unwrap_or_default();
            out.push_str(&format!(" {:>12}", pct(&c)));
        }
        out.push_str(&format!(" {:>12}\n", pct(total)));
    }
    out.push_str(&format!("  {:<14}", "all fields"));
    for class in RobotClass::FITTED {
        let c = cov
            .per_class
            .iter()
            .find(|(k, _)| *k == class)
            .map(|(_, c)| *c)
            .unwrap_or_default();
        out.push_str(&format!(" {:>12}", pct(&c)));
    }
    out.push_str(&format!(" {:>12}\n", pct(&cov.total)));
    out.push_str(&format!(
        "  {} of {} fitted values ({:.1}%) cite a primary source, {} of them derived (see each value's `derivation`)\n",
        cov.total.primary,
        cov.total.values,
        100.0 * cov.total.share(),
        cov.total.derived
    ));
    out
}

/// Checks the rows of a frozen release against the record rules (the rules that a
/// compiled row can break: ranges, definitions, unit slips, classes, exclusions,
/// consistency) and its class fits for outliers: the known problems a release was frozen
/// with (1.0.0 keeps the survey's three impossible leg lengths). Each problem names the
/// release's CSV file and the row's line in it.
pub fn validate_release_rows(
    ds: &Dataset,
    version: &str,
) -> Result<Vec<Problem>, super::DatasetError> {
    use super::record::Source;
    let table = release::load_release(ds, version)?;
    let rel = format!("releases/{version}/{}", release::TABLE_CSV);
    let file = ds.files.display(&rel);
    let mut problems = Vec::new();
    for (i, row) in table.rows.iter().enumerate() {
        let mut values = BTreeMap::new();
        for f in ds.vocab.compiled_fields() {
            let Some(cell) = row.cells.get(&f.name).filter(|c| !c.is_empty()) else {
                continue;
            };
            let Some(value) = Value::from_cell(f.field_type, cell) else {
                problems.push(
                    Problem::error(
                        &file,
                        Rule::Type,
                        format!("`{}` cell `{cell}` does not parse", f.name),
                    )
                    .robot(row.id.clone())
                    .field(format!("values.{}", f.name))
                    .line(Some(i + 2)),
                );
                continue;
            };
            values.insert(
                f.name.clone(),
                Datum::new(value, vec!["release".into()], None),
            );
        }
        let robot = row.robot(
            vec![Source {
                key: "release".into(),
                kind: SourceKind::Dataset,
                url: Some(format!(
                    "https://github.com/robomechanics/robot-dataset#release-{version}"
                )),
                title: None,
                note: None,
            }],
            values,
        );
        let mut found = Vec::new();
        check_record(
            ds,
            &format!("robots/{}.toml", row.id),
            &file,
            &robot,
            None,
            &mut found,
        );
        for mut p in found.into_iter().filter(|p| p.rule != Rule::FileName) {
            p.line = Some(i + 2);
            problems.push(p);
        }
    }
    let locate = |id: &str| {
        let line = table.rows.iter().position(|r| r.id == id).map(|i| i + 2);
        Some((file.clone(), line))
    };
    push_outliers(&table, locate, "", &mut problems);
    if parse_semver(version).is_some_and(|v| v >= SPEED_KIND_REQUIRED_FROM) {
        problems = as_release_problems(problems);
    }
    problems.sort_by(|a, b| {
        (a.severity, a.line, &a.field, a.rule).cmp(&(b.severity, b.line, &b.field, b.rule))
    });
    Ok(problems)
}
