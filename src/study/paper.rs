//! The paper's simulation results as reference data (`dataset/laws/table3-paper.toml`),
//! for printing beside this project's Table III and foot study.

use serde::{Deserialize, Serialize};

use super::StudyError;
use crate::sim::MassLaw;

const BUNDLED: &str = include_str!("../../dataset/laws/table3-paper.toml");

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PaperSource {
    pub kind: String,
    pub url: String,
    pub at: String,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PaperRow {
    pub design: String,
    pub mass_law: MassLaw,
    pub velocity_exponent: f64,
    pub velocity_r2: f64,
    pub torque_exponent: f64,
    pub torque_r2: f64,
    /// [mean, sd]
    pub roll_pp_deg: [f64; 2],
    pub pitch_pp_deg: [f64; 2],
    pub yaw_pp_deg: [f64; 2],
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PaperFootLaw {
    pub design: String,
    pub axis: String,
    pub a: f64,
    pub b: f64,
    pub r2: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PaperFastestFoot {
    pub design: String,
    pub leg_length_m: f64,
    pub velocity_mps: f64,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PaperTable3 {
    pub source: PaperSource,
    pub row: Vec<PaperRow>,
    pub feet: Vec<PaperFootLaw>,
    pub fastest_foot: Vec<PaperFastestFoot>,
}

impl PaperTable3 {
    /// The bundled reference (dataset/laws/table3-paper.toml).
    pub fn bundled() -> Result<Self, StudyError> {
        toml::from_str(BUNDLED).map_err(|e| StudyError::Data {
            origin: "dataset/laws/table3-paper.toml".into(),
            message: e.to_string(),
        })
    }

    pub fn row(&self, design: &str, mass_law: MassLaw) -> Option<&PaperRow> {
        self.row
            .iter()
            .find(|r| r.design == design && r.mass_law == mass_law)
    }
}
