//! The scaling-law comparison of the paper's Table 1: isometric vs biology vs robotics
//! exponents against leg length L. The isometric and biological laws are data
//! (`dataset/laws/table1.toml`, with literature sources); the robotics mass and body-length
//! exponents are recomputed from the survey with confidence intervals.

use serde::{Deserialize, Serialize};

use crate::analysis::table2::{DatasetRef, Group, Numeric, Var, fit_group};
use crate::dataset::{Dataset, DatasetError, SurveyTable};
use crate::regression::Method;

/// File of the laws, relative to the dataset root.
pub const LAWS_FILE: &str = "laws/table1.toml";

/// A literature source of a law.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LawSource {
    pub key: String,
    pub kind: String,
    #[serde(default)]
    pub url: Option<String>,
    pub title: String,
}

/// Which survey relation a robotics law is computed from.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FromData {
    pub x: String,
    pub y: String,
}

/// One law of Table 1.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Law {
    /// body_length, mass, velocity, torque.
    pub quantity: String,
    /// isometric, biology, robotics.
    pub basis: String,
    pub expression: String,
    /// Power of L (for torque: under `mass_law`).
    pub exponent: f64,
    #[serde(default)]
    pub exponent_range: Option<[f64; 2]>,
    #[serde(default)]
    pub mass_law: Option<String>,
    pub rationale: String,
    pub sources: Vec<String>,
    #[serde(default)]
    pub from_data: Option<FromData>,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct LawsFile {
    source: Vec<LawSource>,
    law: Vec<Law>,
}

/// An exponent recomputed from the survey for one group.
#[derive(Debug, Clone, Serialize)]
pub struct DataExponent {
    pub class: Group,
    pub b: f64,
    pub b_ci: [f64; 2],
    pub r2: f64,
    pub n: usize,
    /// p-value of the isometric exponent (b = 1 for lengths, 3 for mass).
    pub p_isometry: f64,
    /// Whether the law's stated exponent lies inside the interval.
    pub law_in_ci: bool,
}

/// A law with, for the robotics laws, its exponents from the data.
#[derive(Debug, Clone, Serialize)]
pub struct LawRow {
    #[serde(flatten)]
    pub law: Law,
    pub from_data: Vec<DataExponent>,
}

/// `survey laws`.
#[derive(Debug, Clone, Serialize)]
pub struct LawTable {
    pub dataset: DatasetRef,
    pub confidence: f64,
    pub laws: Vec<LawRow>,
    pub sources: Vec<LawSource>,
}

/// Reads and checks the laws file of a dataset: every cited source key must exist.
pub fn load_laws(ds: &Dataset) -> Result<(Vec<Law>, Vec<LawSource>), DatasetError> {
    let file = ds.files.display(LAWS_FILE);
    let text = ds.files.text(LAWS_FILE)?;
    let parsed: LawsFile =
        toml::from_str(text).map_err(|e| DatasetError::toml(file.as_str(), text, &e))?;
    for law in &parsed.law {
        for key in &law.sources {
            if !parsed.source.iter().any(|s| &s.key == key) {
                return Err(DatasetError::Invalid {
                    file: file.clone(),
                    message: format!("law `{}` cites unknown source `{key}`", law.expression),
                });
            }
        }
        if let Some(fd) = &law.from_data
            && (Var::parse(&fd.x).is_none() || Var::parse(&fd.y).is_none())
        {
            return Err(DatasetError::Invalid {
                file: file.clone(),
                message: format!(
                    "law `{}`: from_data names unknown variables {} / {}",
                    law.expression, fd.x, fd.y
                ),
            });
        }
    }
    Ok((parsed.law, parsed.source))
}

/// Table 1 with the robotics exponents recomputed (OLS, as in the paper) per class.
pub fn law_table(
    ds: &Dataset,
    table: &SurveyTable,
    confidence: f64,
) -> Result<LawTable, DatasetError> {
    let (laws, sources) = load_laws(ds)?;
    let data = Numeric::of(table);
    let mut rows = Vec::new();
    for law in laws {
        let mut from_data = Vec::new();
        if let Some(fd) = &law.from_data {
            // load_laws checked the names.
            let (Some(x), Some(y)) = (Var::parse(&fd.x), Var::parse(&fd.y)) else {
                continue;
            };
            for g in Group::TABLE2 {
                let f = fit_group(&data, g, x, y, Method::Ols, confidence, None).map_err(|e| {
                    DatasetError::Other(format!("{} {}: {e}", g.as_str(), law.expression))
                })?;
                from_data.push(DataExponent {
                    class: g,
                    b: f.b,
                    b_ci: f.b_ci,
                    r2: f.r2,
                    n: f.n,
                    p_isometry: f.p_isometry,
                    law_in_ci: f.b_ci[0] <= law.exponent && law.exponent <= f.b_ci[1],
                });
            }
        }
        rows.push(LawRow { law, from_data });
    }
    Ok(LawTable {
        dataset: DatasetRef::of(table),
        confidence,
        laws: rows,
        sources,
    })
}
