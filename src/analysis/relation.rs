//! One relation y ∝ x^b fitted per class with its slope tests (`survey fit --y VAR`):
//! the exponents with intervals, each hypothesised exponent tested (smatr's `slope.test`),
//! and, for a speed, the Froude numbers v²/(gL) of the robots fitted. The fits are
//! [`crate::analysis::table2::fit_group`]'s; the tests are [`crate::regression`]'s.

use serde::Serialize;

use crate::analysis::laws::Law;
use crate::analysis::table2::{
    DatasetRef, Group, Numeric, PowerLawRow, Var, fit_group, isometric_exponent,
};
use crate::dataset::validate::G_MPS2;
use crate::dataset::{Dataset, DatasetError, SurveyTable};
use crate::regression::{self, Method, RegressionError, SlopeTest};

/// Fewest robots a class needs for a fit (a line with intercept has n − 2 residual
/// degrees of freedom).
pub const MIN_FIT_N: usize = 3;

/// A hypothesised exponent and where it comes from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Hypothesis {
    pub b: f64,
    /// "v ∝ L^0.5 (isometric, robotics)", "no trend".
    pub label: String,
    /// Why the exponent is expected (the laws' rationale), if known.
    pub rationale: Option<String>,
}

impl Hypothesis {
    /// b = 0: no relation between x and y.
    pub fn no_trend() -> Self {
        Hypothesis {
            b: 0.0,
            label: "no trend".into(),
            rationale: Some(
                "y does not change with x: the paper's 'no statistically significant trend'".into(),
            ),
        }
    }
}

/// The exponents a relation is tested against: those of the scaling laws of y against leg
/// length (`dataset/laws/table1.toml`: isometric, biology, robotics; one hypothesis per
/// distinct exponent), else the isometric exponent; and b = 0 (no trend) last.
pub fn hypotheses(laws: &[Law], x: Var, y: Var) -> Vec<Hypothesis> {
    let quantity = match y {
        Var::LegLength => None,
        Var::BodyLength => Some("body_length"),
        Var::Mass => Some("mass"),
        _ => Some("velocity"),
    };
    // (exponent, the first law's expression and rationale, every basis stating it)
    let mut by_exponent: Vec<(&Law, Vec<&str>)> = Vec::new();
    if x == Var::LegLength {
        for law in laws
            .iter()
            .filter(|l| Some(l.quantity.as_str()) == quantity && l.mass_law.is_none())
        {
            match by_exponent
                .iter_mut()
                .find(|(l, _)| l.exponent == law.exponent)
            {
                Some((_, bases)) => bases.push(&law.basis),
                None => by_exponent.push((law, vec![&law.basis])),
            }
        }
    }
    let mut out: Vec<Hypothesis> = by_exponent
        .into_iter()
        .map(|(law, bases)| Hypothesis {
            b: law.exponent,
            label: format!("{} ({})", law.expression, bases.join(", ")),
            rationale: Some(law.rationale.clone()),
        })
        .collect();
    if out.is_empty() {
        let b = isometric_exponent(x, y);
        out.push(Hypothesis {
            b,
            label: format!("{} ∝ {}^{b} (isometric)", y.symbol(), x.symbol()),
            rationale: Some("geometric and dynamic similarity".into()),
        });
    }
    if !out.iter().any(|h| h.b == 0.0) {
        out.push(Hypothesis::no_trend());
    }
    out
}

/// [`hypotheses`] with the laws of the dataset's `laws/table1.toml` (a dataset without
/// the file gets the isometric exponent and no trend; a broken file is an error).
pub fn default_hypotheses(ds: &Dataset, x: Var, y: Var) -> Result<Vec<Hypothesis>, DatasetError> {
    let laws = match ds.files.bytes(crate::analysis::laws::LAWS_FILE) {
        Some(_) => crate::analysis::laws::load_laws(ds)?.0,
        None => Vec::new(),
    };
    Ok(hypotheses(&laws, x, y))
}

/// One hypothesis tested on one class.
#[derive(Debug, Clone, Serialize)]
pub struct HypothesisTest {
    pub hypothesis: Hypothesis,
    pub test: SlopeTest,
    /// p < 1 − confidence.
    pub rejected: bool,
}

/// The Froude numbers v²/(gL) of the robots of one fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FroudeSummary {
    pub n: usize,
    pub median: f64,
    /// First and third quartiles (R's default quantile, type 7).
    pub quartiles: [f64; 2],
    pub min: f64,
    pub max: f64,
    /// Robots above Froude 1, the walk–run limit.
    pub above_1: usize,
}

impl FroudeSummary {
    /// The summary of Froude numbers of (leg length [m], speed [m/s]) pairs; None when
    /// there are none.
    pub fn of(legs: &[f64], speeds: &[f64]) -> Option<Self> {
        let fr: Vec<f64> = legs
            .iter()
            .zip(speeds)
            .map(|(l, v)| froude(*v, *l))
            .filter(|f| f.is_finite())
            .collect();
        if fr.is_empty() {
            return None;
        }
        let q = |p| regression::quantile(&fr, p);
        Some(FroudeSummary {
            n: fr.len(),
            median: q(0.5),
            quartiles: [q(0.25), q(0.75)],
            min: fr.iter().copied().fold(f64::INFINITY, f64::min),
            max: fr.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            above_1: fr.iter().filter(|f| **f > 1.0).count(),
        })
    }
}

/// The Froude number v²/(gL) of a speed v [m/s] on a leg of length L [m].
pub fn froude(v: f64, leg_length_m: f64) -> f64 {
    v * v / (G_MPS2 * leg_length_m)
}

/// One class of a relation: its fit and tests, or why it has none.
#[derive(Debug, Clone, Serialize)]
pub struct GroupRelation {
    pub class: Group,
    /// Fitted robots of the class with both values.
    pub n: usize,
    pub fit: Option<PowerLawRow>,
    pub tests: Vec<HypothesisTest>,
    /// Why the class is not fitted (too few robots, values a log cannot take).
    pub not_fitted: Option<String>,
    /// For a speed: the Froude numbers of the class's robots with a leg length.
    pub froude: Option<FroudeSummary>,
}

impl GroupRelation {
    /// The test of the hypothesis with exponent `b`, if the class was fitted.
    pub fn test_of(&self, b: f64) -> Option<&HypothesisTest> {
        self.tests.iter().find(|t| t.hypothesis.b == b)
    }
}

/// `survey fit --y VAR`: y ∝ x^b for each class and all.
#[derive(Debug, Clone, Serialize)]
pub struct RelationFits {
    pub dataset: DatasetRef,
    pub x: Var,
    pub y: Var,
    pub method: Method,
    pub confidence: f64,
    pub hypotheses: Vec<Hypothesis>,
    pub groups: Vec<GroupRelation>,
}

impl RelationFits {
    pub fn group(&self, g: Group) -> Option<&GroupRelation> {
        self.groups.iter().find(|r| r.class == g)
    }
}

/// What to fit: y ∝ x^b by `method`, intervals at `confidence`, each hypothesis tested,
/// optionally a seeded bootstrap interval of b.
#[derive(Debug, Clone)]
pub struct RelationSpec {
    pub x: Var,
    pub y: Var,
    pub method: Method,
    pub confidence: f64,
    pub hypotheses: Vec<Hypothesis>,
    pub bootstrap: Option<regression::BootstrapConfig>,
}

/// Fits y ∝ x^b for every class (and all) of the table, tests each hypothesis, and — for
/// a speed — summarises the Froude numbers. A class with fewer than [`MIN_FIT_N`] robots
/// is reported as not fitted, not as an error.
pub fn relation_fits(
    table: &SurveyTable,
    spec: &RelationSpec,
) -> Result<RelationFits, RegressionError> {
    let (x, y) = (spec.x, spec.y);
    if !(spec.confidence > 0.0 && spec.confidence < 1.0) {
        return Err(RegressionError::InvalidLevel(spec.confidence));
    }
    let data = Numeric::of(table);
    let mut groups = Vec::new();
    for g in Group::TABLE2 {
        let n = data.select(g, x, y).0.len();
        let froude = y.speed_kind().and_then(|_| {
            let (legs, speeds) = data.select(g, Var::LegLength, y);
            FroudeSummary::of(&legs, &speeds)
        });
        let mut row = GroupRelation {
            class: g,
            n,
            fit: None,
            tests: Vec::new(),
            not_fitted: None,
            froude,
        };
        if n < MIN_FIT_N {
            row.not_fitted = Some(format!(
                "{n} robot(s) with {} and {} (a fit needs {MIN_FIT_N})",
                x.label(),
                y.label()
            ));
            groups.push(row);
            continue;
        }
        match fit_with_tests(&data, g, spec) {
            Ok((fit, tests)) => {
                row.fit = Some(fit);
                row.tests = tests;
            }
            Err(e) => row.not_fitted = Some(e.to_string()),
        }
        groups.push(row);
    }
    Ok(RelationFits {
        dataset: DatasetRef::of(table),
        x,
        y,
        method: spec.method,
        confidence: spec.confidence,
        hypotheses: spec.hypotheses.clone(),
        groups,
    })
}

/// One class's fit and its slope tests.
fn fit_with_tests(
    data: &Numeric,
    g: Group,
    spec: &RelationSpec,
) -> Result<(PowerLawRow, Vec<HypothesisTest>), RegressionError> {
    let (x, y, method) = (spec.x, spec.y, spec.method);
    let fit = fit_group(data, g, x, y, method, spec.confidence, spec.bootstrap)?;
    let (xs, ys) = data.select(g, x, y);
    let lx = regression::log10_checked(&xs, x.as_str())?;
    let ly = regression::log10_checked(&ys, y.as_str())?;
    let tests = test_hypotheses(&lx, &ly, method, &spec.hypotheses, spec.confidence)?;
    Ok((fit, tests))
}

/// smatr's slope test of each hypothesis on log10 data, rejected below 1 − confidence.
pub fn test_hypotheses(
    lx: &[f64],
    ly: &[f64],
    method: Method,
    hypotheses: &[Hypothesis],
    confidence: f64,
) -> Result<Vec<HypothesisTest>, RegressionError> {
    hypotheses
        .iter()
        .map(|h| {
            let test = regression::slope_test(lx, ly, method, h.b)?;
            Ok(HypothesisTest {
                hypothesis: h.clone(),
                rejected: test.p_value < 1.0 - confidence,
                test,
            })
        })
        .collect()
}
