//! The motor catalogue: published motor-torque scaling laws, actuator datasheet values and
//! the anchor actuators that pin the laws' unknown coefficients (`dataset/motors/`).
//!
//! ```text
//! laws.toml       [[law]]       tau ∝ size^k (motor length or motor mass), theory or empirical
//! actuators.toml  [[actuator]]  mass, gear ratio, stall torque / no-load speed per voltage
//! anchors.toml    [[anchor]]    design → its hip actuator at a voltage, with its leg length
//! ```
//! [`MotorCatalogue::load`] reads a folder, [`MotorCatalogue::bundled`] the copy compiled
//! into the binary; both reject unknown keys. [`MotorCatalogue::validate`] reports content
//! problems (ranges, duplicates, provenance, unit slips) as [`MotorProblem`]s, each naming
//! its file, entry id and field. The schema and the meaning of the laws are documented in
//! `dataset/motors/README.md`.

pub mod validate;

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::dataset::DatasetFiles;
use crate::regression::{Method, PowerLawFit, RegressionError, fit_power_law};

pub use validate::MotorProblem;

/// The three files of a catalogue, relative to its folder.
pub const LAWS_FILE: &str = "laws.toml";
pub const ACTUATORS_FILE: &str = "actuators.toml";
pub const ANCHORS_FILE: &str = "anchors.toml";

/// Tolerance [V] when matching a requested voltage to a datasheet rating.
pub const VOLTAGE_TOLERANCE_V: f64 = 1e-6;

/// Confidence level of [`MotorCatalogue::stall_torque_vs_mass`].
pub const FIT_LEVEL: f64 = 0.95;

/// Errors that stop a catalogue from being read (content problems are [`MotorProblem`]s).
#[derive(Debug, thiserror::Error)]
pub enum MotorError {
    #[error("{file}: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}: missing (a motor catalogue needs laws.toml, actuators.toml and anchors.toml)")]
    Missing { file: String },
    #[error("{file}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        file: String,
        line: Option<usize>,
        message: String,
    },
    #[error("the motor catalogue is not bundled into this binary")]
    NotBundled,
    #[error("stall torque vs mass over {points} actuator(s): {source}")]
    Fit {
        points: usize,
        #[source]
        source: RegressionError,
    },
}

impl MotorError {
    /// The error as a validation finding (rule `parse`), naming its file and line.
    pub fn to_problem(&self) -> crate::dataset::Problem {
        use crate::dataset::{Problem, Rule};
        match self {
            MotorError::Io { file, source } => {
                Problem::error(file, Rule::Parse, source.to_string())
            }
            MotorError::Missing { file } => Problem::error(
                file,
                Rule::MissingField,
                "missing (a motor catalogue needs laws.toml, actuators.toml and anchors.toml)",
            ),
            MotorError::Parse {
                file,
                line,
                message,
            } => Problem::error(file, Rule::Parse, message.clone()).line(*line),
            e => Problem::error("motors", Rule::Parse, e.to_string()),
        }
    }
}

/// What a law's size is: the motor's characteristic length L_m (S1: "torque relative to
/// motor diameter") or its mass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SizeVariable {
    MotorLength,
    MotorMass,
}

/// What a law predicts: a torque, or a force (which needs a lever arm to become a torque).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    Torque,
    Force,
}

/// Whether a law comes from a physical model or a fit over real motors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Basis {
    Theory,
    Empirical,
}

/// What kind of actuator an entry is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ActuatorKind {
    /// A smart servo: motor, gearbox and controller (e.g. DYNAMIXEL).
    Servo,
    /// A brushed DC motor with a gearbox.
    Gearmotor,
    /// A robot's joint module (motor, transmission, driver), often known only from a model.
    ActuatorModule,
}

/// Where an actuator's numbers come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceKind {
    /// The manufacturer's datasheet or specification page (a URL is required).
    Datasheet,
    /// A manufacturer's web page that is not a datasheet (e.g. a product page).
    Web,
    /// A simulation model's parameters (e.g. a MuJoCo actuator limit).
    Model,
    /// A secondary source (slides, news, a blog).
    Secondary,
}

/// What an actuator's stall torque is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StallTorqueBasis {
    /// The datasheet's stall torque (maximum instantaneous static torque).
    Datasheet,
    /// The maker's extrapolation of the torque–speed line to zero speed (not measured).
    Extrapolated,
    /// A simulation model's torque limit, not a motor property.
    ModelLimit,
    /// A figure from a secondary source.
    Secondary,
}

/// A cited work: `{ citation, url?, at? }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    pub citation: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub url: Option<String>,
    /// Where in the work (section, table, figure, line).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<String>,
}

/// A law's published prefactor: `output = value · size^exponent`, with its units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Coefficient {
    pub value: f64,
    /// Unit of the law's output (e.g. `N`, `N·m`).
    pub output_unit: String,
    /// Unit the size must be expressed in (e.g. `kg`, `m`).
    pub size_unit: String,
}

/// One scaling law `quantity ∝ size^exponent`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorLaw {
    pub id: String,
    /// k in quantity ∝ size^k.
    pub exponent: f64,
    pub size_variable: SizeVariable,
    pub quantity: Quantity,
    pub basis: Basis,
    /// Where the allometric paper (S1) cites the law, when it does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cited_by: Option<Reference>,
    /// The works that support the law.
    pub sources: Vec<Reference>,
    /// The published prefactor; absent when unknown (then a torque check pins it to an
    /// anchor actuator).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coefficient: Option<Coefficient>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl MotorLaw {
    /// The law pinned to pass through `(size0, output0)`: output at `size`.
    /// Used with an anchor: `pinned(tau_anchor, L_anchor, L)`.
    pub fn pinned(&self, output0: f64, size0: f64, size: f64) -> f64 {
        output0 * (size / size0).powf(self.exponent)
    }

    /// The law's own prediction at `size` (in [`Coefficient::size_unit`]), when it has a
    /// published coefficient.
    pub fn predict(&self, size: f64) -> Option<f64> {
        self.coefficient
            .as_ref()
            .map(|c| c.value * size.powf(self.exponent))
    }
}

/// A datasheet line: the stall torque (and more) at one supply voltage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rating {
    /// Supply voltage [V]; absent when the source gives none (e.g. a model's limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub voltage_v: Option<f64>,
    /// Stall torque [N·m] at the output shaft.
    pub stall_torque_nm: f64,
    /// No-load speed [rpm] at the output shaft.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_load_speed_rpm: Option<f64>,
    /// Stall current [A].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stall_current_a: Option<f64>,
}

/// Where an actuator's numbers come from: `{ kind, url?, title?, at }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSource {
    pub kind: SourceKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub url: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub title: Option<String>,
    /// Where in the source the numbers are.
    pub at: String,
}

/// One actuator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Actuator {
    /// Kebab-case id, e.g. `dynamixel-xl330-m288-t`.
    pub id: String,
    pub name: String,
    pub maker: String,
    pub kind: ActuatorKind,
    /// Mass [kg]; absent when not published.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Gear reduction (output turns per motor turn, inverted: 288.4 means 288.4:1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gear_ratio: Option<f64>,
    /// One rating per voltage the source lists.
    pub ratings: Vec<Rating>,
    /// The maker's recommended (nominal, rated) voltage [V].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recommended_voltage_v: Option<f64>,
    /// Continuous (rated) torque [N·m].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub continuous_torque_nm: Option<f64>,
    pub stall_torque_basis: StallTorqueBasis,
    pub source: ActuatorSource,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl Actuator {
    /// The rating at `voltage_v` (within [`VOLTAGE_TOLERANCE_V`]); with `None`, the rating
    /// at the recommended voltage, or the only rating when no voltage is recommended and
    /// there is just one.
    pub fn rating(&self, voltage_v: Option<f64>) -> Option<&Rating> {
        let at = |v: f64| {
            self.ratings.iter().find(|r| {
                r.voltage_v
                    .is_some_and(|rv| (rv - v).abs() <= VOLTAGE_TOLERANCE_V)
            })
        };
        match (voltage_v, self.recommended_voltage_v) {
            (Some(v), _) => at(v),
            (None, Some(rec)) => at(rec),
            (None, None) if self.ratings.len() == 1 => self.ratings.first(),
            (None, None) => None,
        }
    }

    /// Stall torque [N·m] at `voltage_v`; `None` voltage: the recommended rating (see
    /// [`Actuator::rating`]).
    pub fn stall_torque_at(&self, voltage_v: Option<f64>) -> Option<f64> {
        self.rating(voltage_v).map(|r| r.stall_torque_nm)
    }

    /// No-load speed [rad/s] at `voltage_v` (same voltage rule as [`Actuator::rating`]).
    pub fn no_load_speed_rad_s(&self, voltage_v: Option<f64>) -> Option<f64> {
        self.rating(voltage_v)
            .and_then(|r| r.no_load_speed_rpm)
            .map(|rpm| rpm * std::f64::consts::TAU / 60.0)
    }

    /// Peak mechanical power [W] of the linear torque–speed line, τ_stall·ω₀/4.
    pub fn peak_power_w(&self, voltage_v: Option<f64>) -> Option<f64> {
        Some(self.stall_torque_at(voltage_v)? * self.no_load_speed_rad_s(voltage_v)? / 4.0)
    }

    /// Mass-specific stall torque [N·m/kg] at `voltage_v`.
    pub fn specific_stall_torque(&self, voltage_v: Option<f64>) -> Option<f64> {
        Some(self.stall_torque_at(voltage_v)? / self.mass_kg?)
    }
}

/// A design whose hip actuator pins the motor-length laws.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Anchor {
    /// Walker design name (as in `dataset/walkers/<design>.toml`).
    pub design: String,
    /// Actuator id (actuators.toml).
    pub actuator: String,
    /// The rating's voltage [V].
    pub voltage_v: f64,
    /// The design's leg length [m].
    pub leg_length_m: f64,
    pub source: Reference,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// One file of a catalogue as read: its display name (for messages) and text (for lines).
#[derive(Debug, Clone, Default)]
pub struct MotorFile {
    pub name: String,
    pub text: String,
}

/// The files a catalogue was read from.
#[derive(Debug, Clone, Default)]
pub struct MotorFiles {
    pub laws: MotorFile,
    pub actuators: MotorFile,
    pub anchors: MotorFile,
}

/// A point of the stall-torque–mass fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MassTorquePoint {
    pub id: String,
    pub mass_kg: f64,
    /// The rating's voltage (the recommended one; `None` for a single unrated rating).
    pub voltage_v: Option<f64>,
    pub stall_torque_nm: f64,
}

/// The motor catalogue.
#[derive(Debug, Clone, Default)]
pub struct MotorCatalogue {
    pub laws: Vec<MotorLaw>,
    pub actuators: Vec<Actuator>,
    pub anchors: Vec<Anchor>,
    /// Where it was read from (empty for a catalogue built in code).
    pub files: MotorFiles,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LawsToml {
    #[serde(default)]
    law: Vec<MotorLaw>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ActuatorsToml {
    #[serde(default)]
    actuator: Vec<Actuator>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AnchorsToml {
    #[serde(default)]
    anchor: Vec<Anchor>,
}

fn parse<T: serde::de::DeserializeOwned>(file: &MotorFile) -> Result<T, MotorError> {
    toml::from_str(&file.text).map_err(|e| MotorError::Parse {
        file: file.name.clone(),
        line: e
            .span()
            .map(|s| crate::dataset::vocabulary::line_of_offset(&file.text, s.start)),
        message: e.message().to_string(),
    })
}

impl MotorCatalogue {
    /// Reads `dir/laws.toml`, `dir/actuators.toml` and `dir/anchors.toml`.
    pub fn load(dir: &Path) -> Result<Self, MotorError> {
        let read = |name: &str| -> Result<MotorFile, MotorError> {
            let path = dir.join(name);
            let display = path.display().to_string();
            match std::fs::read_to_string(&path) {
                Ok(text) => Ok(MotorFile {
                    name: display,
                    text,
                }),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    Err(MotorError::Missing { file: display })
                }
                Err(source) => Err(MotorError::Io {
                    file: display,
                    source,
                }),
            }
        };
        Self::from_files(MotorFiles {
            laws: read(LAWS_FILE)?,
            actuators: read(ACTUATORS_FILE)?,
            anchors: read(ANCHORS_FILE)?,
        })
    }

    /// The catalogue a command uses: `dir` when given; else `./dataset/motors` when the
    /// working directory is a checkout (a contributor's edits count at once); else the
    /// bundled one.
    pub fn locate(dir: Option<&Path>) -> Result<Self, MotorError> {
        match dir {
            Some(d) => Self::load(d),
            None if Path::new("dataset/motors").is_dir() => Self::load(Path::new("dataset/motors")),
            None => Self::bundled(),
        }
    }

    /// The catalogue compiled into the binary (`dataset/motors/`).
    pub fn bundled() -> Result<Self, MotorError> {
        let dir = crate::dataset::bundled_dir("motors").ok_or(MotorError::NotBundled)?;
        let read = |name: &str| -> Result<MotorFile, MotorError> {
            let display = format!("dataset/motors/{name} (bundled)");
            let file =
                dir.get_file(format!("motors/{name}"))
                    .ok_or_else(|| MotorError::Missing {
                        file: display.clone(),
                    })?;
            let text = file.contents_utf8().ok_or_else(|| MotorError::Parse {
                file: display.clone(),
                line: None,
                message: "not UTF-8".into(),
            })?;
            Ok(MotorFile {
                name: display,
                text: text.to_string(),
            })
        };
        Self::from_files(MotorFiles {
            laws: read(LAWS_FILE)?,
            actuators: read(ACTUATORS_FILE)?,
            anchors: read(ANCHORS_FILE)?,
        })
    }

    /// The `motors/` folder of a dataset read into memory (a directory or the bundled
    /// copy); `None` when the dataset has no `motors/` files.
    pub fn from_dataset_files(files: &DatasetFiles) -> Option<Result<Self, MotorError>> {
        if !files.files.keys().any(|k| k.starts_with("motors/")) {
            return None;
        }
        let read = |name: &str| -> Result<MotorFile, MotorError> {
            let rel = format!("motors/{name}");
            let display = files.display(&rel);
            let bytes = files.bytes(&rel).ok_or_else(|| MotorError::Missing {
                file: display.clone(),
            })?;
            let text = std::str::from_utf8(bytes).map_err(|_| MotorError::Parse {
                file: display.clone(),
                line: None,
                message: "not UTF-8".into(),
            })?;
            Ok(MotorFile {
                name: display,
                text: text.to_string(),
            })
        };
        Some((|| {
            Self::from_files(MotorFiles {
                laws: read(LAWS_FILE)?,
                actuators: read(ACTUATORS_FILE)?,
                anchors: read(ANCHORS_FILE)?,
            })
        })())
    }

    /// Parses the three files' texts.
    pub fn from_files(files: MotorFiles) -> Result<Self, MotorError> {
        let laws: LawsToml = parse(&files.laws)?;
        let actuators: ActuatorsToml = parse(&files.actuators)?;
        let anchors: AnchorsToml = parse(&files.anchors)?;
        Ok(MotorCatalogue {
            laws: laws.law,
            actuators: actuators.actuator,
            anchors: anchors.anchor,
            files,
        })
    }

    /// Every problem of the catalogue's content (see [`validate`]).
    pub fn validate(&self) -> Vec<MotorProblem> {
        validate::validate(self)
    }

    pub fn actuator(&self, id: &str) -> Option<&Actuator> {
        self.actuators.iter().find(|a| a.id == id)
    }

    pub fn law(&self, id: &str) -> Option<&MotorLaw> {
        self.laws.iter().find(|l| l.id == id)
    }

    pub fn anchor(&self, design: &str) -> Option<&Anchor> {
        self.anchors.iter().find(|a| a.design == design)
    }

    /// The anchor's actuator and its stall torque [N·m] at the anchor's voltage.
    pub fn anchor_stall_torque(&self, design: &str) -> Option<(&Anchor, &Actuator, f64)> {
        let anchor = self.anchor(design)?;
        let actuator = self.actuator(&anchor.actuator)?;
        let tau = actuator.stall_torque_at(Some(anchor.voltage_v))?;
        Some((anchor, actuator, tau))
    }

    /// The points of [`MotorCatalogue::stall_torque_vs_mass`]. Rule: every actuator whose
    /// source kind is in `source_kinds`, that has a mass, whose `stall_torque_basis` is
    /// `datasheet` (no extrapolations, model limits or secondary figures), and that has a
    /// rating at its recommended voltage ([`Actuator::rating`] with `None`); the point is
    /// (mass, stall torque at that voltage). In catalogue order.
    pub fn stall_torque_mass_points(&self, source_kinds: &[SourceKind]) -> Vec<MassTorquePoint> {
        self.actuators
            .iter()
            .filter(|a| source_kinds.contains(&a.source.kind))
            .filter(|a| a.stall_torque_basis == StallTorqueBasis::Datasheet)
            .filter_map(|a| {
                let mass_kg = a.mass_kg?;
                let r = a.rating(None)?;
                Some(MassTorquePoint {
                    id: a.id.clone(),
                    mass_kg,
                    voltage_v: r.voltage_v,
                    stall_torque_nm: r.stall_torque_nm,
                })
            })
            .collect()
    }

    /// τ_stall = A·m^b (τ in N·m, m in kg) fitted by OLS on log–log axes
    /// ([`fit_power_law`], 95 % intervals) over [`MotorCatalogue::stall_torque_mass_points`].
    pub fn stall_torque_vs_mass(
        &self,
        source_kinds: &[SourceKind],
    ) -> Result<PowerLawFit, MotorError> {
        let points = self.stall_torque_mass_points(source_kinds);
        let m: Vec<f64> = points.iter().map(|p| p.mass_kg).collect();
        let tau: Vec<f64> = points.iter().map(|p| p.stall_torque_nm).collect();
        fit_power_law(&m, &tau, Method::Ols, FIT_LEVEL).map_err(|source| MotorError::Fit {
            points: points.len(),
            source,
        })
    }

    /// `motors: N actuator(s), M law(s), K anchor(s): E error(s), W warning(s)`.
    pub fn summary_line(&self, problems: &[MotorProblem]) -> String {
        let errors = problems.iter().filter(|p| p.is_error()).count();
        format!(
            "motors: {} actuator(s), {} law(s), {} anchor(s): {} error(s), {} warning(s)",
            self.actuators.len(),
            self.laws.len(),
            self.anchors.len(),
            errors,
            problems.len() - errors
        )
    }
}
