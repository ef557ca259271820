//! Problems found in a dataset: what `survey validate` reports.

use serde::Serialize;

/// How serious a problem is: errors fail validation (exit 1), warnings do not.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
}

/// How many of `problems` have this severity.
pub fn count<'a>(problems: impl IntoIterator<Item = &'a Problem>, severity: Severity) -> usize {
    problems
        .into_iter()
        .filter(|p| p.severity == severity)
        .count()
}

/// The rule a problem breaks. Its kebab-case name is stable: tests, JSON consumers and
/// CONTRIBUTING.md refer to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rule {
    /// The file is not valid TOML or not UTF-8.
    Parse,
    /// A key that the schema does not know.
    UnknownField,
    /// A required key is absent.
    MissingField,
    /// A value of the wrong type.
    Type,
    /// A value outside its plausible range, or not in its allowed list.
    Range,
    /// Values whose combination betrays a unit slip (e.g. a mass typed in grams).
    UnitPlausibility,
    /// A definition is broken (leg length > body length, mass_min > mass > mass_max).
    Definition,
    /// The class contradicts the paper's class rules.
    Class,
    /// Two records describe the same robot.
    Duplicate,
    /// A value lacks a source, or a source is malformed or unknown.
    Provenance,
    /// A fitted robot lies far from its class fit (leave-one-out studentized residual).
    Outlier,
    /// Values that contradict each other or physics (e.g. walking above the walk–run limit).
    Consistency,
    /// A speed that does not say what kind of speed it is (top, typical, walking, running):
    /// a warning in the live records, an error in a release from 1.5.0.
    SpeedKind,
    /// A record is excluded from fits without a reason, or fitted without the fitted values.
    Exclusion,
    /// The file name does not match the record id.
    FileName,
    /// A frozen release's bytes changed, or the manifest is broken.
    ReleaseIntegrity,
    /// dataset.toml, the manifest or the data package description is broken or stale.
    Metadata,
}

impl Rule {
    pub fn name(self) -> String {
        serde_json::to_value(self)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default()
    }
}

/// One finding: `file:line: field: message`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Problem {
    pub file: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    pub robot: Option<String>,
    pub field: Option<String>,
    pub severity: Severity,
    pub rule: Rule,
    pub message: String,
}

impl Problem {
    pub fn new(file: &str, severity: Severity, rule: Rule, message: impl Into<String>) -> Self {
        Problem {
            file: file.to_string(),
            line: None,
            robot: None,
            field: None,
            severity,
            rule,
            message: message.into(),
        }
    }
    pub fn error(file: &str, rule: Rule, message: impl Into<String>) -> Self {
        Self::new(file, Severity::Error, rule, message)
    }
    pub fn warning(file: &str, rule: Rule, message: impl Into<String>) -> Self {
        Self::new(file, Severity::Warning, rule, message)
    }
    pub fn field(mut self, field: impl Into<String>) -> Self {
        self.field = Some(field.into());
        self
    }
    pub fn robot(mut self, robot: impl Into<String>) -> Self {
        self.robot = Some(robot.into());
        self
    }
    pub fn line(mut self, line: Option<usize>) -> Self {
        self.line = line;
        self
    }

    /// `file:line: field: message [rule]` — the text form, one problem per line.
    pub fn to_line(&self) -> String {
        let mut s = self.file.clone();
        if let Some(l) = self.line {
            s.push_str(&format!(":{l}"));
        }
        if let Some(f) = &self.field {
            s.push_str(&format!(":{f}"));
        }
        let sev = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        format!("{s}: {sev}: {} [{}]", self.message, self.rule.name())
    }
}
