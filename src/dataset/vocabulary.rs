//! The field vocabulary of robot records (`dataset/vocabulary.toml`): names, units,
//! types and plausible ranges, in canonical order. Data, not code, so contributors can
//! extend the schema by pull request (as AusTraits keeps its trait definitions).

use serde::Deserialize;

use super::DatasetError;

/// Value type of a field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FieldType {
    Number,
    Integer,
    Text,
    Bool,
}

/// What kind of speed a `speed_*_mps` field holds, so that speeds fitted together are
/// comparable: the top (maximum) speed, a typical (nominal or average) one, a walking or
/// running speed reported without saying which, or — the survey's speeds — unstated.
#[derive(
    Debug,
    Clone,
    Copy,
    Default,
    PartialEq,
    Eq,
    PartialOrd,
    Ord,
    Hash,
    Deserialize,
    serde::Serialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum SpeedKind {
    /// The highest speed reported for each robot (its maximum), in any gait: the most
    /// reported and most comparable kind, the default of fits and predictions.
    #[default]
    Top,
    /// A nominal, cruising or average speed.
    Typical,
    /// A walking speed reported without saying whether top or typical.
    Walking,
    /// A running speed reported without saying whether top or typical.
    Running,
    /// Speeds of unstated kind: the survey's speeds as the paper used them (releases up to
    /// 1.4.0).
    Unstated,
}

impl SpeedKind {
    pub const ALL: [SpeedKind; 5] = [
        SpeedKind::Top,
        SpeedKind::Typical,
        SpeedKind::Walking,
        SpeedKind::Running,
        SpeedKind::Unstated,
    ];
    /// The kinds a speed is stated as (every kind but `unstated`).
    pub const STATED: [SpeedKind; 4] = [
        SpeedKind::Top,
        SpeedKind::Typical,
        SpeedKind::Walking,
        SpeedKind::Running,
    ];
    pub fn as_str(self) -> &'static str {
        match self {
            SpeedKind::Top => "top",
            SpeedKind::Typical => "typical",
            SpeedKind::Walking => "walking",
            SpeedKind::Running => "running",
            SpeedKind::Unstated => "unstated",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.as_str() == s)
    }
    /// The compiled column (and record field) of this kind.
    pub fn field(self) -> &'static str {
        match self {
            SpeedKind::Top => "speed_top_mps",
            SpeedKind::Typical => "speed_typical_mps",
            SpeedKind::Walking => "speed_walking_mps",
            SpeedKind::Running => "speed_running_mps",
            SpeedKind::Unstated => "speed_normal_mps",
        }
    }
}

impl std::fmt::Display for SpeedKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A gait a speed value may name (`gait = "trot"`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaitSpec {
    pub name: String,
    /// No aerial phase: bounded by the walk–run limit, Froude v²/(gL) ≤ 1.
    pub walking: bool,
    pub description: String,
}

/// One field of the `[values]` table of a record.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSpec {
    pub name: String,
    #[serde(rename = "type")]
    pub field_type: FieldType,
    pub unit: String,
    pub min: Option<f64>,
    pub max: Option<f64>,
    #[serde(default)]
    pub compiled: bool,
    /// Used as x or y of the survey power laws: must have a source when the robot is fitted.
    #[serde(default)]
    pub fit_variable: bool,
    #[serde(default)]
    pub allowed: Vec<String>,
    /// For a speed field: which kind of speed it holds (its values may name a `gait`).
    #[serde(default)]
    pub speed_kind: Option<SpeedKind>,
    pub description: String,
}

/// The whole vocabulary, in canonical field order.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vocabulary {
    #[serde(rename = "field")]
    pub fields: Vec<FieldSpec>,
    /// Gaits a speed value may name (none in vocabularies before 1.5.0).
    #[serde(default, rename = "gait")]
    pub gaits: Vec<GaitSpec>,
}

impl Vocabulary {
    /// Parses `vocabulary.toml` text; `origin` names the file in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self, DatasetError> {
        let vocab: Vocabulary =
            toml::from_str(text).map_err(|e| DatasetError::toml(origin, text, &e))?;
        let mut seen = std::collections::BTreeSet::new();
        for f in &vocab.fields {
            if !seen.insert(f.name.as_str()) {
                return Err(DatasetError::Invalid {
                    file: origin.to_string(),
                    message: format!("field `{}` is defined twice", f.name),
                });
            }
        }
        // The analyses select a kind's column by name (SpeedKind::field): a vocabulary
        // that names it otherwise would silently fit nothing.
        for f in &vocab.fields {
            if let Some(k) = f.speed_kind
                && f.name != k.field()
            {
                return Err(DatasetError::Invalid {
                    file: origin.to_string(),
                    message: format!(
                        "field `{}` declares speed_kind `{k}`, whose field is `{}`",
                        f.name,
                        k.field()
                    ),
                });
            }
        }
        let mut gaits = std::collections::BTreeSet::new();
        for g in &vocab.gaits {
            if !gaits.insert(g.name.as_str()) {
                return Err(DatasetError::Invalid {
                    file: origin.to_string(),
                    message: format!("gait `{}` is defined twice", g.name),
                });
            }
        }
        Ok(vocab)
    }

    pub fn get(&self, name: &str) -> Option<&FieldSpec> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// Position of a field in canonical order (unknown fields sort last).
    pub fn order(&self, name: &str) -> usize {
        self.fields
            .iter()
            .position(|f| f.name == name)
            .unwrap_or(usize::MAX)
    }

    pub fn compiled_fields(&self) -> impl Iterator<Item = &FieldSpec> {
        self.fields.iter().filter(|f| f.compiled)
    }

    pub fn gait(&self, name: &str) -> Option<&GaitSpec> {
        self.gaits.iter().find(|g| g.name == name)
    }
}

/// 1-based line number of a byte offset.
pub fn line_of_offset(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}
