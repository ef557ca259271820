//! Designer queries (`survey predict`): what mass and body length should a walker of a
//! given leg length have, how sure is that, and how does that compare with scaling a
//! known robot isometrically (m ∝ L³) or by the survey's m ∝ L².
//!
//! Predictions use the OLS fit of log10 y on log10 L of one class: smatr and lmodel2 both
//! warn that MA/SMA lines describe the scatter and are not for predicting y from x.
//! The log-space prediction back-transforms to the *median* of y; the reported centre is
//! the bias-corrected *mean* by Duan's (1983) smearing estimate, the median is kept beside
//! it, and the intervals (median CI, prediction interval) are back-transformed limits.

use serde::Serialize;

use crate::analysis::relation::froude;
use crate::analysis::table2::{DatasetRef, Group, Var, log_points};
use crate::dataset::{SpeedKind, SurveyTable};
use crate::regression::{self, BiasCorrection, Method, PowerLawFit, RegressionError};

/// A reference robot or design to scale from.
#[derive(Debug, Clone, Serialize)]
pub struct Reference {
    /// Record id (`zippy`) or `design:NAME`.
    pub name: String,
    pub leg_length_m: f64,
    pub mass_kg: f64,
    pub body_length_m: Option<f64>,
    /// Where the reference values come from.
    pub source: String,
}

/// The law a prediction came from.
#[derive(Debug, Clone, Serialize)]
pub struct LawUsed {
    pub class: Group,
    pub x: Var,
    pub y: Var,
    pub method: Method,
    pub a: f64,
    pub b: f64,
    pub r2: f64,
    pub n: usize,
    /// Range of x covered by the class data.
    pub x_range: [f64; 2],
}

/// A predicted quantity at the target leg length.
#[derive(Debug, Clone, Serialize)]
pub struct QuantityPrediction {
    pub quantity: Var,
    pub unit: &'static str,
    pub law: LawUsed,
    /// Bias-corrected mean (Duan smearing): the reported centre.
    pub mean: f64,
    /// Median = 10^(log-space prediction), the uncorrected back-transform.
    pub median: f64,
    /// Duan's smearing factor mean(10^residual) applied to the median.
    pub smearing_factor: f64,
    /// Confidence interval of the median.
    pub median_ci: [f64; 2],
    /// Prediction interval for one new robot.
    pub prediction_interval: [f64; 2],
}

/// Leg length that the class fit gives for a mass budget (inverse prediction).
#[derive(Debug, Clone, Serialize)]
pub struct InversePrediction {
    pub mass_budget_kg: f64,
    pub law: LawUsed,
    /// Leg length at which the fitted median mass equals the budget.
    pub leg_length_m: f64,
    /// Fieller interval; None when the slope is not significantly non-zero.
    pub leg_length_ci: Option<[f64; 2]>,
    pub extrapolation: Option<String>,
}

/// Isometric scaling of a reference to the target leg length, beside the class fit.
#[derive(Debug, Clone, Serialize)]
pub struct ScaledReference {
    pub reference: Reference,
    pub scale_factor: f64,
    /// m_ref·(L/L_ref)²: the survey's robot mass law.
    pub mass_l2_kg: f64,
    /// m_ref·(L/L_ref)³: isometric (geometric similarity).
    pub mass_l3_kg: f64,
    /// L_B,ref·(L/L_ref): body length under geometric similarity.
    pub body_length_isometric_m: Option<f64>,
}

/// The Froude number v²/(gL) of the predicted speed at the target leg length.
#[derive(Debug, Clone, Serialize)]
pub struct FroudePrediction {
    /// Of the bias-corrected mean speed.
    pub mean: f64,
    /// Of the median speed.
    pub median: f64,
    /// Of the limits of the speed's prediction interval.
    pub prediction_interval: [f64; 2],
}

/// The answer to `survey predict`.
#[derive(Debug, Clone, Serialize)]
pub struct Prediction {
    pub dataset: DatasetRef,
    pub class: Group,
    pub confidence: f64,
    /// Which centre the `mean` fields are.
    pub centre: &'static str,
    pub leg_length_m: Option<f64>,
    pub quantities: Vec<QuantityPrediction>,
    pub inverse: Option<InversePrediction>,
    pub scaled_reference: Option<ScaledReference>,
    /// Set when the target lies outside the class data range.
    pub extrapolation: Option<String>,
    /// The kind of speed predicted (a speed is among `quantities` when the class has
    /// enough robots with a speed of this kind).
    pub speed_kind: SpeedKind,
    /// The Froude number of the predicted speed.
    pub froude: Option<FroudePrediction>,
    /// Why no speed is predicted (too few robots with a speed of the kind, no leg length).
    pub speed_unavailable: Option<String>,
}

impl Prediction {
    /// The masses a torque requirement is evaluated at (label, kg, prediction interval):
    /// the class fit's mean with its interval, and the scaled reference under m ∝ L² and
    /// m ∝ L³ when there is one.
    pub fn reference_masses(&self) -> Vec<(String, f64, Option<[f64; 2]>)> {
        let mut masses = Vec::new();
        if let Some(q) = self.quantities.iter().find(|q| q.quantity == Var::Mass) {
            masses.push((
                format!(
                    "{} fit (mean, {:.0} % prediction interval)",
                    self.class.as_str(),
                    100.0 * self.confidence
                ),
                q.mean,
                Some(q.prediction_interval),
            ));
        }
        if let Some(r) = &self.scaled_reference {
            masses.push((
                format!("{} scaled, m ∝ L²", r.reference.name),
                r.mass_l2_kg,
                None,
            ));
            masses.push((
                format!("{} scaled, m ∝ L³", r.reference.name),
                r.mass_l3_kg,
                None,
            ));
        }
        masses
    }
}

/// What the designer asks.
#[derive(Debug, Clone, Default)]
pub struct PredictRequest {
    pub leg_length_m: Option<f64>,
    pub mass_budget_kg: Option<f64>,
    pub reference: Option<Reference>,
    pub confidence: f64,
    /// The kind of speed predicted at the target leg length.
    pub speed_kind: SpeedKind,
}

/// Errors of a prediction request.
#[derive(Debug, thiserror::Error)]
pub enum PredictError {
    #[error("{0}")]
    Request(String),
    #[error("class {class}: {y} vs {x}: {source}")]
    Fit {
        class: &'static str,
        x: &'static str,
        y: &'static str,
        source: RegressionError,
    },
    #[error(transparent)]
    Dataset(#[from] crate::dataset::DatasetError),
    #[error(transparent)]
    Design(#[from] crate::sim::SimError),
}

pub const CENTRE: &str =
    "mean: median 10^(a + b·log10 L) × Duan (1983) smearing factor mean(10^residual)";

fn positive(name: &str, v: f64) -> Result<f64, PredictError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(PredictError::Request(format!(
            "{name} must be a positive number, got {v}"
        )))
    }
}

struct ClassFit {
    law: LawUsed,
    fit: PowerLawFit,
    smearing: BiasCorrection,
}

impl ClassFit {
    fn error(&self, source: RegressionError) -> PredictError {
        PredictError::Fit {
            class: self.law.class.as_str(),
            x: self.law.x.as_str(),
            y: self.law.y.as_str(),
            source,
        }
    }
}

fn class_fit(table: &SurveyTable, class: Group, x: Var, y: Var) -> Result<ClassFit, PredictError> {
    let err = |source| PredictError::Fit {
        class: class.as_str(),
        x: x.as_str(),
        y: y.as_str(),
        source,
    };
    let p = log_points(table, class, x, y).map_err(err)?;
    let fit = PowerLawFit::from_log_fit(
        regression::fit_line(&p.lx, &p.ly, Method::Ols, 0.95).map_err(err)?,
    );
    let residuals: Vec<f64> =
        p.lx.iter()
            .zip(&p.ly)
            .map(|(a, b)| b - fit.log_fit.fitted(*a))
            .collect();
    let smearing = BiasCorrection::duan(&residuals).map_err(err)?;
    let lo = p.x.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = p.x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Ok(ClassFit {
        law: LawUsed {
            class,
            x,
            y,
            method: Method::Ols,
            a: fit.a,
            b: fit.b,
            r2: fit.r2,
            n: fit.n,
            x_range: [lo, hi],
        },
        fit,
        smearing,
    })
}

fn range_warning(what: &str, v: f64, unit: &str, range: [f64; 2], class: Group) -> Option<String> {
    (v < range[0] || v > range[1]).then(|| {
        format!(
            "extrapolation: {what} {v:.3} {unit} lies outside the {} data ({:.3}–{:.3} {unit}); the power law is untested there",
            class.as_str(),
            range[0],
            range[1]
        )
    })
}

/// Predicts one quantity y at leg length `l` from the class OLS fit.
fn predict_quantity(
    cf: &ClassFit,
    l: f64,
    confidence: f64,
) -> Result<QuantityPrediction, PredictError> {
    let (_, back) = regression::predict_power_law(&cf.fit, l, confidence, cf.smearing)
        .map_err(|e| cf.error(e))?;
    let y = cf.law.y;
    Ok(QuantityPrediction {
        quantity: y,
        unit: y.unit(),
        law: cf.law.clone(),
        mean: back.centre,
        median: back.median,
        smearing_factor: cf.smearing.factor(),
        median_ci: [back.median_ci.lower, back.median_ci.upper],
        prediction_interval: [
            back.prediction_interval.lower,
            back.prediction_interval.upper,
        ],
    })
}

/// `survey predict`: class-fit predictions, the inverse for a mass budget, and the
/// isometric scaling of a reference robot.
pub fn predict(
    table: &SurveyTable,
    class: Group,
    req: &PredictRequest,
) -> Result<Prediction, PredictError> {
    if req.leg_length_m.is_none() && req.mass_budget_kg.is_none() {
        return Err(PredictError::Request(
            "give a target leg length (--leg-length M) or a mass budget (--mass-budget KG)".into(),
        ));
    }
    if !(req.confidence > 0.0 && req.confidence < 1.0) {
        return Err(PredictError::Request(format!(
            "confidence must be in (0, 1), got {}",
            req.confidence
        )));
    }
    // Both queries need the mass law: fit it once.
    let mass_fit = class_fit(table, class, Var::LegLength, Var::Mass)?;
    let mut quantities = Vec::new();
    let mut extrapolation = None;
    let (mut froude_at, mut speed_unavailable) = (None, None);
    if let Some(l) = req.leg_length_m {
        let l = positive("leg length", l)?;
        let body_fit = class_fit(table, class, Var::LegLength, Var::BodyLength)?;
        for cf in [&mass_fit, &body_fit] {
            let q = predict_quantity(cf, l, req.confidence)?;
            if extrapolation.is_none() {
                extrapolation = range_warning("leg length", l, "m", q.law.x_range, class);
            }
            quantities.push(q);
        }
        match predict_speed(table, class, l, req) {
            Ok(q) => {
                froude_at = Some(FroudePrediction {
                    mean: froude(q.mean, l),
                    median: froude(q.median, l),
                    prediction_interval: q.prediction_interval.map(|v| froude(v, l)),
                });
                quantities.push(q);
            }
            Err(why) => speed_unavailable = Some(why),
        }
    } else {
        speed_unavailable = Some("a speed is predicted for a target leg length".into());
    }
    let inverse = match req.mass_budget_kg {
        None => None,
        Some(m) => Some(inverse_prediction(&mass_fit, m, req.confidence, class)?),
    };
    let scaled_reference = scaled_reference(req)?;
    Ok(Prediction {
        dataset: DatasetRef::of(table),
        class,
        confidence: req.confidence,
        centre: CENTRE,
        leg_length_m: req.leg_length_m,
        quantities,
        inverse,
        scaled_reference,
        extrapolation,
        speed_kind: req.speed_kind,
        froude: froude_at,
        speed_unavailable,
    })
}

/// The inverse query: the leg length at which the class's mass law gives the mass budget
/// `m` (its median), with its confidence interval.
fn inverse_prediction(
    cf: &ClassFit,
    m: f64,
    confidence: f64,
    class: Group,
) -> Result<InversePrediction, PredictError> {
    let m = positive("mass budget", m)?;
    let inv = regression::inverse_predict_ols(&cf.fit.log_fit, m.log10(), confidence)
        .map_err(|e| cf.error(e))?;
    let l = 10f64.powf(inv.x0);
    let extrapolation = range_warning("leg length", l, "m", cf.law.x_range, class);
    Ok(InversePrediction {
        mass_budget_kg: m,
        leg_length_m: l,
        leg_length_ci: inv
            .x0_ci
            .map(|c| [10f64.powf(c.lower), 10f64.powf(c.upper)]),
        law: cf.law.clone(),
        extrapolation,
    })
}

/// The request's reference robot scaled isometrically to the target leg length (mass under
/// m ∝ L² and m ∝ L³); an error when a reference is given without a target leg length.
fn scaled_reference(req: &PredictRequest) -> Result<Option<ScaledReference>, PredictError> {
    match (&req.reference, req.leg_length_m) {
        (Some(r), Some(l)) => {
            positive("reference leg length", r.leg_length_m)?;
            positive("reference mass", r.mass_kg)?;
            let s = l / r.leg_length_m;
            Ok(Some(ScaledReference {
                reference: r.clone(),
                scale_factor: s,
                mass_l2_kg: r.mass_kg * s * s,
                mass_l3_kg: r.mass_kg * s * s * s,
                body_length_isometric_m: r.body_length_m.map(|b| b * s),
            }))
        }
        (Some(_), None) => Err(PredictError::Request(
            "--from scales a reference to a target leg length: give --leg-length too".into(),
        )),
        _ => Ok(None),
    }
}

/// The speed of the requested kind at leg length `l`, or why the class cannot predict it
/// (fewer robots with such a speed than a fit needs).
fn predict_speed(
    table: &SurveyTable,
    class: Group,
    l: f64,
    req: &PredictRequest,
) -> Result<QuantityPrediction, String> {
    let y = Var::speed(req.speed_kind);
    let n = crate::analysis::table2::points(table, class, Var::LegLength, y).len();
    if n < crate::analysis::relation::MIN_FIT_N {
        return Err(format!(
            "{n} {} robot(s) of dataset {} have a {} (a fit needs {})",
            class.as_str(),
            table.version,
            y.label(),
            crate::analysis::relation::MIN_FIT_N
        ));
    }
    let cf = class_fit(table, class, Var::LegLength, y).map_err(|e| e.to_string())?;
    predict_quantity(&cf, l, req.confidence).map_err(|e| e.to_string())
}

/// A reference from a record of the table (its leg length, mass and body length).
pub fn reference_from_record(table: &SurveyTable, id: &str) -> Option<Reference> {
    let row = table.rows.iter().find(|r| r.id == id)?;
    Some(Reference {
        name: id.to_string(),
        leg_length_m: row.number(Var::LegLength.field())?,
        mass_kg: row.number(Var::Mass.field())?,
        body_length_m: row.number(Var::BodyLength.field()),
        source: format!("dataset {} record `{id}`", table.version),
    })
}

/// (L, low, high) of a prediction band [m, kg, kg].
pub type BandPoint = (f64, f64, f64);

/// One class's prediction band for the figure: (L, low, high) of the prediction interval
/// of mass over the class range (and a little beyond), plus the fitted line.
pub fn mass_band(
    table: &SurveyTable,
    class: Group,
    confidence: f64,
    span: [f64; 2],
) -> Result<(LawUsed, Vec<BandPoint>), PredictError> {
    let cf = class_fit(table, class, Var::LegLength, Var::Mass)?;
    let (lo, hi) = (span[0].ln(), span[1].ln());
    let steps = 60;
    let mut band = Vec::with_capacity(steps + 1);
    for i in 0..=steps {
        let l = (lo + (hi - lo) * i as f64 / steps as f64).exp();
        if let Ok((_, back)) = regression::predict_power_law(&cf.fit, l, confidence, cf.smearing) {
            band.push((
                l,
                back.prediction_interval.lower,
                back.prediction_interval.upper,
            ));
        }
    }
    Ok((cf.law, band))
}

/// A reference from a walker design of the dataset (`dataset/walkers/NAME.toml`), read by
/// the simulator's own design parser, so a design the simulator refuses is refused here.
pub fn reference_from_design(
    files: &crate::dataset::DatasetFiles,
    name: &str,
) -> Result<Reference, PredictError> {
    let rel = format!("walkers/{name}.toml");
    let file = files.display(&rel);
    let design = crate::sim::Design::from_toml_str(files.text(&rel)?, &file)?;
    Ok(Reference {
        name: format!("design:{name}"),
        leg_length_m: design.geometry.leg_length_m,
        mass_kg: design.mass.total_mass_kg,
        body_length_m: Some(design.geometry.body_length_m),
        source: format!("walker design {file}"),
    })
}
