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
    pub description: String,
}

/// The whole vocabulary, in canonical field order.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vocabulary {
    #[serde(rename = "field")]
    pub fields: Vec<FieldSpec>,
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
