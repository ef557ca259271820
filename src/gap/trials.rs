//! Trials: measurements of a walker, one CSV row per trial condition (format in
//! `dataset/trials/README.md`). Every cell is checked; an error names file, line and column.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::error::{GapError, read_text};
use crate::sim::{ContactScaling, MassLaw, WalkReport};

/// A measured gait metric (the simulator's [`WalkReport`] names).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    VelocityMps,
    StepFrequencyHz,
    RollPpDeg,
    PitchPpDeg,
    YawPpDeg,
    PeakTorqueNm,
    MinTorqueNm,
    Cot,
}

impl Metric {
    pub const ALL: [Metric; 8] = [
        Metric::VelocityMps,
        Metric::StepFrequencyHz,
        Metric::RollPpDeg,
        Metric::PitchPpDeg,
        Metric::YawPpDeg,
        Metric::PeakTorqueNm,
        Metric::MinTorqueNm,
        Metric::Cot,
    ];
    /// The metrics one walk gives (the minimum torque needs a bisection of walks).
    pub fn simulated() -> impl Iterator<Item = Metric> {
        Metric::ALL
            .into_iter()
            .filter(|m| *m != Metric::MinTorqueNm)
    }
    pub fn column(self) -> &'static str {
        match self {
            Metric::VelocityMps => "velocity_mps",
            Metric::StepFrequencyHz => "step_frequency_hz",
            Metric::RollPpDeg => "roll_pp_deg",
            Metric::PitchPpDeg => "pitch_pp_deg",
            Metric::YawPpDeg => "yaw_pp_deg",
            Metric::PeakTorqueNm => "peak_torque_nm",
            Metric::MinTorqueNm => "min_torque_nm",
            Metric::Cot => "cot",
        }
    }
    /// Words for summaries.
    pub fn words(self) -> &'static str {
        match self {
            Metric::VelocityMps => "velocity",
            Metric::StepFrequencyHz => "step frequency",
            Metric::RollPpDeg => "roll amplitude",
            Metric::PitchPpDeg => "pitch amplitude",
            Metric::YawPpDeg => "yaw amplitude",
            Metric::PeakTorqueNm => "peak hip torque",
            Metric::MinTorqueNm => "minimum walking torque",
            Metric::Cot => "cost of transport",
        }
    }
    pub fn index(self) -> usize {
        Metric::ALL.iter().position(|m| *m == self).unwrap_or(0)
    }
    /// The metric of a simulated walk (NaN where undefined).
    pub fn of_report(self, r: &WalkReport) -> f64 {
        match self {
            Metric::VelocityMps => r.velocity_mps,
            Metric::StepFrequencyHz => r.step_frequency_hz,
            Metric::RollPpDeg => r.roll_pp_deg,
            Metric::PitchPpDeg => r.pitch_pp_deg,
            Metric::YawPpDeg => r.yaw_pp_deg,
            Metric::PeakTorqueNm => r.peak_torque_nm,
            Metric::MinTorqueNm => f64::NAN,
            Metric::Cot => r.cot,
        }
    }
    /// Whether a measured value may be negative (a walker may drift backwards).
    fn signed(self) -> bool {
        self == Metric::VelocityMps
    }
}

/// A measured value and its standard deviation (None: not stated).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Measurement {
    pub value: f64,
    pub sd: Option<f64>,
}

impl Measurement {
    /// The stated sd, or `default_relative_sd` of the value where none is stated (never 0),
    /// and whether it was assumed.
    pub fn sd_or(&self, default_relative_sd: f64) -> (f64, bool) {
        match self.sd {
            Some(sd) => (sd, false),
            None => ((default_relative_sd * self.value.abs()).max(1e-12), true),
        }
    }
}

/// One trial condition and what was measured there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Trial {
    /// Line in the file (1 = header).
    pub line: u64,
    pub label: String,
    /// A bundled design name, or a design TOML path relative to the trials file.
    pub design: String,
    pub leg_length_m: f64,
    pub mass_kg: Option<f64>,
    pub mass_law: Option<MassLaw>,
    pub contact: Option<ContactScaling>,
    pub frequency_hz: Option<f64>,
    pub amplitude_deg: Option<f64>,
    pub torque_limit_nm: Option<f64>,
    pub torque_nm: Option<f64>,
    pub slope_deg: Option<f64>,
    /// Indexed by [`Metric::index`].
    pub measured: [Option<Measurement>; 8],
    /// A trajectory CSV (the `sim walk --trajectory` format), relative to the trials file.
    pub trajectory: Option<String>,
    pub source: String,
}

impl Trial {
    /// A condition without measurements.
    pub fn condition(design: &str, leg_length_m: f64) -> Trial {
        Trial {
            line: 0,
            label: String::new(),
            design: design.to_string(),
            leg_length_m,
            mass_kg: None,
            mass_law: None,
            contact: None,
            frequency_hz: None,
            amplitude_deg: None,
            torque_limit_nm: None,
            torque_nm: None,
            slope_deg: None,
            measured: [None; 8],
            trajectory: None,
            source: String::new(),
        }
    }
    pub fn measured(&self, m: Metric) -> Option<Measurement> {
        self.measured[m.index()]
    }

    /// How reports name the trial: its label, or its line in the file.
    pub fn name(&self) -> String {
        if self.label.is_empty() {
            format!("line {}", self.line)
        } else {
            self.label.clone()
        }
    }
}

/// The trials of one file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrialSet {
    /// The file (for messages), and the folder design and trajectory paths are relative to.
    pub origin: String,
    #[serde(skip)]
    pub base_dir: PathBuf,
    pub trials: Vec<Trial>,
}

const CONDITION_COLUMNS: [&str; 13] = [
    "label",
    "design",
    "leg_length_m",
    "mass_kg",
    "mass_law",
    "contact",
    "frequency_hz",
    "amplitude_deg",
    "torque_limit_nm",
    "torque_nm",
    "slope_deg",
    "trajectory",
    "source",
];

/// Every column the format knows, in the order files are written.
pub fn columns() -> Vec<String> {
    let mut c: Vec<String> = CONDITION_COLUMNS[..11]
        .iter()
        .map(|s| s.to_string())
        .collect();
    for m in Metric::ALL {
        c.push(m.column().to_string());
        c.push(format!("{}_sd", m.column()));
    }
    c.push("trajectory".into());
    c.push("source".into());
    c
}

impl TrialSet {
    pub fn read(path: &Path) -> Result<TrialSet, GapError> {
        let text = read_text(path)?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        TrialSet::parse(&text, &path.display().to_string(), &base)
    }

    /// Parses and validates a trials CSV; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str, base_dir: &Path) -> Result<TrialSet, GapError> {
        let mut rdr = csv::ReaderBuilder::new()
            .flexible(false)
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let col = read_columns(&mut rdr, origin)?;
        let mut trials = Vec::new();
        for rec in rdr.records() {
            let rec = rec.map_err(|e| {
                let line = e.position().map(|p| p.line()).unwrap_or(0);
                GapError::at(origin, line, 1, format!("malformed row: {e}"))
            })?;
            let row = TrialRow {
                origin,
                col: &col,
                line: rec.position().map(|p| p.line()).unwrap_or(0),
                rec: &rec,
            };
            trials.push(row.trial()?);
        }
        if trials.is_empty() {
            return Err(GapError::at(
                origin,
                1,
                1,
                "no trials: the file has a header but no rows".into(),
            ));
        }
        Ok(TrialSet {
            origin: origin.to_string(),
            base_dir: base_dir.to_path_buf(),
            trials,
        })
    }

    /// The trials as CSV, in the format [`TrialSet::parse`] reads. Writing to memory fails
    /// only on a row of another length than the header (a bug, not bad input): an error
    /// rather than a file cut short.
    pub fn to_csv(&self) -> Result<String, GapError> {
        let failed = |e: &dyn std::fmt::Display| {
            GapError::Invalid(format!("cannot write the trials as CSV: {e}"))
        };
        let mut w = csv::WriterBuilder::new().from_writer(Vec::new());
        w.write_record(columns()).map_err(|e| failed(&e))?;
        for t in &self.trials {
            w.write_record(trial_row(t)).map_err(|e| failed(&e))?;
        }
        let bytes = w.into_inner().map_err(|e| failed(&e))?;
        String::from_utf8(bytes).map_err(|e| failed(&e))
    }
}

/// A trial's cells, in the order of [`columns`].
fn trial_row(t: &Trial) -> Vec<String> {
    let f = |x: Option<f64>| x.map(fmt_number).unwrap_or_default();
    let mut row = vec![
        t.label.clone(),
        t.design.clone(),
        fmt_number(t.leg_length_m),
        f(t.mass_kg),
        t.mass_law
            .map(|m| match m {
                MassLaw::L2 => "l2".to_string(),
                MassLaw::L3 => "l3".to_string(),
            })
            .unwrap_or_default(),
        t.contact
            .map(|c| match c {
                ContactScaling::Similar => "similar".to_string(),
                ContactScaling::FixedMaterial => "fixed-material".to_string(),
            })
            .unwrap_or_default(),
        f(t.frequency_hz),
        f(t.amplitude_deg),
        f(t.torque_limit_nm),
        f(t.torque_nm),
        f(t.slope_deg),
    ];
    for m in Metric::ALL {
        let meas = t.measured(m);
        row.push(f(meas.map(|x| x.value)));
        row.push(f(meas.and_then(|x| x.sd)));
    }
    row.push(t.trajectory.clone().unwrap_or_default());
    row.push(t.source.clone());
    row
}

/// The header: every column known, none twice, the required ones there. Returns each
/// column's index.
fn read_columns(
    rdr: &mut csv::Reader<&[u8]>,
    origin: &str,
) -> Result<std::collections::HashMap<String, usize>, GapError> {
    let err =
        |line: u64, column: usize, message: String| GapError::at(origin, line, column, message);
    let headers = rdr
        .headers()
        .map_err(|e| err(1, 1, format!("cannot read the header: {e}")))?
        .clone();
    let known = columns();
    let mut col = std::collections::HashMap::new();
    for (i, h) in headers.iter().enumerate() {
        if !known.iter().any(|k| k == h) {
            return Err(err(
                1,
                i + 1,
                format!(
                    "unknown column {h:?}; the format's columns are {}",
                    known.join(", ")
                ),
            ));
        }
        if col.insert(h.to_string(), i).is_some() {
            return Err(err(1, i + 1, format!("column {h:?} appears twice")));
        }
    }
    for required in ["design", "leg_length_m", "source"] {
        if !col.contains_key(required) {
            return Err(err(
                1,
                headers.len() + 1,
                format!("missing required column {required:?}"),
            ));
        }
    }
    Ok(col)
}

/// One data row of a trials file.
struct TrialRow<'a> {
    origin: &'a str,
    col: &'a std::collections::HashMap<String, usize>,
    rec: &'a csv::StringRecord,
    line: u64,
}

impl TrialRow<'_> {
    fn err(&self, column: usize, message: String) -> GapError {
        GapError::at(self.origin, self.line, column, message)
    }

    /// A non-empty cell with its 1-based column.
    fn cell(&self, name: &str) -> Option<(usize, &str)> {
        self.col
            .get(name)
            .and_then(|&i| self.rec.get(i).map(|v| (i + 1, v)))
            .filter(|(_, v)| !v.is_empty())
    }

    /// A numeric cell, checked by `ok` (`why` says what it must be).
    fn number(
        &self,
        name: &str,
        ok: &dyn Fn(f64) -> bool,
        why: &str,
    ) -> Result<Option<f64>, GapError> {
        match self.cell(name) {
            None => Ok(None),
            Some((c, v)) => {
                let x: f64 = v
                    .parse()
                    .map_err(|_| self.err(c, format!("{name}: {v:?} is not a number")))?;
                if !x.is_finite() || !ok(x) {
                    return Err(self.err(c, format!("{name}: {v} {why}")));
                }
                Ok(Some(x))
            }
        }
    }

    /// A cell's text (None: empty).
    fn text(&self, name: &str) -> Option<String> {
        self.cell(name).map(|(_, v)| v.to_string())
    }

    /// The error of a required cell (its column is there, `read_columns` checked) that is
    /// empty; `why` says why it is needed.
    fn empty(&self, name: &str, why: &str) -> GapError {
        self.err(self.col[name] + 1, format!("{name}: empty; {why}"))
    }

    fn trial(&self) -> Result<Trial, GapError> {
        let design = self
            .text("design")
            .ok_or_else(|| self.empty("design", "name a bundled design or a design TOML path"))?;
        let leg = |x: f64| (1e-3..=100.0).contains(&x);
        let leg_length_m = self
            .number(
                "leg_length_m",
                &leg,
                "must be a leg length in [0.001, 100] m",
            )?
            .ok_or_else(|| self.empty("leg_length_m", "every trial needs its leg length"))?;
        let (mass_law, contact) = self.laws()?;
        let positive = |x: f64| x > 0.0;
        let mass_kg = self.number("mass_kg", &positive, "must be > 0 kg")?;
        let frequency_hz = self.number("frequency_hz", &positive, "must be > 0 Hz")?;
        let amplitude_deg = self.number(
            "amplitude_deg",
            &|x| x > 0.0 && x < 90.0,
            "must be in (0, 90) deg",
        )?;
        let torque_limit_nm = self.number("torque_limit_nm", &positive, "must be > 0 N·m")?;
        let torque_nm = self.number("torque_nm", &positive, "must be > 0 N·m")?;
        let slope_deg = self.number("slope_deg", &|x| x.abs() <= 45.0, "must be within ±45 deg")?;
        let measured = self.measurements()?;
        let source = self.text("source").ok_or_else(|| {
            self.empty("source", "every trial must say where its numbers come from")
        })?;
        Ok(Trial {
            line: self.line,
            label: self.text("label").unwrap_or_default(),
            design,
            leg_length_m,
            mass_kg,
            mass_law,
            contact,
            frequency_hz,
            amplitude_deg,
            torque_limit_nm,
            torque_nm,
            slope_deg,
            measured,
            trajectory: self.text("trajectory"),
            source,
        })
    }

    /// The mass law and contact scaling of a resized trial.
    fn laws(&self) -> Result<(Option<MassLaw>, Option<ContactScaling>), GapError> {
        let mass_law = match self.cell("mass_law") {
            None => None,
            Some((c, v)) => Some(match v {
                "l2" => MassLaw::L2,
                "l3" => MassLaw::L3,
                _ => return Err(self.err(c, format!("mass_law: {v:?}; expected l2 or l3"))),
            }),
        };
        let contact = match self.cell("contact") {
            None => None,
            Some((c, v)) => Some(match v {
                "similar" => ContactScaling::Similar,
                "fixed-material" => ContactScaling::FixedMaterial,
                _ => {
                    return Err(self.err(
                        c,
                        format!("contact: {v:?}; expected similar or fixed-material"),
                    ));
                }
            }),
        };
        Ok((mass_law, contact))
    }

    /// The measured metrics and their standard deviations (an sd needs its value).
    fn measurements(&self) -> Result<[Option<Measurement>; 8], GapError> {
        let positive = |x: f64| x > 0.0;
        let mut measured = [None; 8];
        for m in Metric::ALL {
            let name = m.column();
            let ok = |x: f64| m.signed() || x >= 0.0;
            let value = self.number(name, &ok, "must be ≥ 0")?;
            let sd_name = format!("{name}_sd");
            let sd = self.number(&sd_name, &positive, "must be > 0 (a standard deviation)")?;
            match (value, sd) {
                (Some(v), sd) => measured[m.index()] = Some(Measurement { value: v, sd }),
                (None, Some(_)) => {
                    let c = self.col[&sd_name] + 1;
                    return Err(self.err(c, format!("{sd_name} given without {name}")));
                }
                (None, None) => {}
            }
        }
        Ok(measured)
    }
}

/// Shortest text that reads back to the same f64 (Rust's `{}` round-trips).
fn fmt_number(x: f64) -> String {
    format!("{x}")
}
