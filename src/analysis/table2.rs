//! The paper's Table 2 over a survey table (power laws per class) and the influence of
//! single robots on it (`--explain`). Numbers come from [`crate::regression`]; this module
//! only chooses the data (which robots, which variables) and names the results.

use serde::Serialize;

use crate::dataset::{RobotClass, SurveyTable};
use crate::regression::{self, Method};

// The variables, groups and points live with the compiled table (the validator selects
// the same data); re-exported here, where the analyses name them.
pub use crate::dataset::selection::{Group, LogPoints, TABLE2_PAIRS, Var, log_points, points};

/// Which dataset a result came from.
#[derive(Debug, Clone, Serialize)]
pub struct DatasetRef {
    pub version: String,
    pub sha256: String,
    /// True for a frozen release, false for the live records.
    pub frozen: bool,
}

impl DatasetRef {
    pub fn of(table: &SurveyTable) -> Self {
        DatasetRef {
            version: table.version.clone(),
            sha256: table.sha256.clone(),
            frozen: table.frozen,
        }
    }
}

/// One power law of Table 2: y = a·x^b.
#[derive(Debug, Clone, Serialize)]
pub struct PowerLawRow {
    pub class: Group,
    pub x: Var,
    pub y: Var,
    pub a: f64,
    pub b: f64,
    pub r2: f64,
    pub n: usize,
    pub method: Method,
    /// Standard error of b.
    pub se_b: f64,
    /// Confidence interval of b.
    pub b_ci: [f64; 2],
    /// Confidence interval of A (back-transformed from the interval of log10 A).
    pub a_ci: [f64; 2],
    /// p-value of b = 0 (no relation).
    pub p_b_equals_0: f64,
    /// p-value of isometry (b = 1 for length vs length, b = 3 for mass vs length).
    pub p_isometry: f64,
    pub confidence: f64,
    /// Seeded case-resampling percentile interval of b (only with `--bootstrap N`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b_ci_bootstrap: Option<[f64; 2]>,
    /// Bias-corrected and accelerated (BCa) bootstrap interval of b from the same
    /// resamples (only with `--bootstrap N`, and only where BCa is defined).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b_ci_bootstrap_bca: Option<[f64; 2]>,
}

/// Table 2 of the paper, for any dataset and fit method.
#[derive(Debug, Clone, Serialize)]
pub struct Table2 {
    pub dataset: DatasetRef,
    pub method: Method,
    pub fits: Vec<PowerLawRow>,
}

/// The isometric exponent of y against x under geometric and dynamic similarity: lengths
/// ∝ L, mass ∝ L³, speeds ∝ L^0.5 (equal Froude number v²/(gL)).
pub fn isometric_exponent(x: Var, y: Var) -> f64 {
    let dim = |v: Var| match v {
        Var::LegLength | Var::BodyLength => 1.0,
        Var::Mass => 3.0,
        _ => 0.5,
    };
    dim(y) / dim(x)
}

/// The survey variables of every row, parsed once (a table of a million robots is fitted
/// 15 times; parsing each cell once keeps that under a second).
pub struct Numeric {
    rows: Vec<(RobotClass, bool, [Option<f64>; Var::ALL.len()])>,
}

impl Numeric {
    pub fn of(table: &SurveyTable) -> Self {
        Numeric {
            rows: table
                .rows
                .iter()
                .map(|r| (r.class, r.fit, Var::ALL.map(|v| r.number(v.field()))))
                .collect(),
        }
    }

    /// (x, y) of the fitted robots of `group` that have both variables.
    pub fn select(&self, group: Group, x: Var, y: Var) -> (Vec<f64>, Vec<f64>) {
        let (ix, iy) = (x.index(), y.index());
        self.rows
            .iter()
            .filter(|(class, fit, _)| group.includes(*class, *fit))
            .filter_map(|(_, _, v)| Some((v[ix]?, v[iy]?)))
            .unzip()
    }
}

/// Fits one group's power law (and, with `bootstrap`, a seeded bootstrap interval of b
/// at the same confidence). The logarithms are taken once for the fit, the isometry test
/// and the bootstrap.
pub fn fit_group(
    data: &Numeric,
    group: Group,
    x: Var,
    y: Var,
    method: Method,
    confidence: f64,
    bootstrap: Option<regression::BootstrapConfig>,
) -> Result<PowerLawRow, regression::RegressionError> {
    let (xs, ys) = data.select(group, x, y);
    let lx = regression::log10_checked(&xs, x.as_str())?;
    let ly = regression::log10_checked(&ys, y.as_str())?;
    let fit =
        regression::PowerLawFit::from_log_fit(regression::fit_line(&lx, &ly, method, confidence)?);
    let p_iso = regression::slope_test(&lx, &ly, method, isometric_exponent(x, y))?.p_value;
    let (b_ci_bootstrap, b_ci_bootstrap_bca) = match bootstrap {
        Some(cfg) => {
            let cfg = regression::BootstrapConfig {
                level: confidence,
                ..cfg
            };
            let boot = regression::bootstrap_line(&lx, &ly, method, cfg)?;
            (
                Some([boot.b_ci.lower, boot.b_ci.upper]),
                boot.b_bca.map(|c| [c.interval.lower, c.interval.upper]),
            )
        }
        None => (None, None),
    };
    Ok(PowerLawRow {
        class: group,
        x,
        y,
        a: fit.a,
        b: fit.b,
        r2: fit.r2,
        n: fit.n,
        method,
        se_b: fit.se_b,
        b_ci: [fit.b_ci.lower, fit.b_ci.upper],
        a_ci: [fit.a_ci.lower, fit.a_ci.upper],
        p_b_equals_0: fit.p_b_equals_0,
        p_isometry: p_iso,
        confidence,
        b_ci_bootstrap,
        b_ci_bootstrap_bca,
    })
}

/// Table 2: every class (and all) × every variable pair.
pub fn table2(
    table: &SurveyTable,
    method: Method,
    confidence: f64,
) -> Result<Table2, regression::RegressionError> {
    table2_with_bootstrap(table, method, confidence, None)
}

/// Table 2 with, optionally, a seeded bootstrap interval of every exponent (same seed,
/// same intervals, bit for bit).
pub fn table2_with_bootstrap(
    table: &SurveyTable,
    method: Method,
    confidence: f64,
    bootstrap: Option<regression::BootstrapConfig>,
) -> Result<Table2, regression::RegressionError> {
    let data = Numeric::of(table);
    let mut fits = Vec::new();
    for (x, y) in TABLE2_PAIRS {
        for g in Group::TABLE2 {
            fits.push(fit_group(&data, g, x, y, method, confidence, bootstrap)?);
        }
    }
    Ok(Table2 {
        dataset: DatasetRef::of(table),
        method,
        fits,
    })
}

/// How much one robot moves one power law of its class.
#[derive(Debug, Clone, Serialize)]
pub struct RobotInfluence {
    pub id: String,
    /// Exponent without this robot.
    pub b_without: f64,
    /// b_without − b: positive when the robot pulls the exponent down.
    pub delta_b: f64,
    /// R² without this robot (OLS only; how much it degrades the fit).
    pub r2_without: Option<f64>,
    /// Externally studentized residual of the OLS log–log fit.
    pub studentized_residual: f64,
    /// Leverage (hat value) of the OLS fit.
    pub leverage: f64,
    /// Cook's distance of the OLS fit.
    pub cooks_distance: f64,
}

/// One relation of a class with its robots sorted by |Δb|, largest first.
#[derive(Debug, Clone, Serialize)]
pub struct RelationInfluence {
    pub x: Var,
    pub y: Var,
    pub n: usize,
    pub b: f64,
    pub r2: f64,
    pub robots: Vec<RobotInfluence>,
}

/// `survey fit --explain CLASS`: leave-one-out influence on every Table 2 exponent.
#[derive(Debug, Clone, Serialize)]
pub struct Explanation {
    pub dataset: DatasetRef,
    pub class: Group,
    pub method: Method,
    pub relations: Vec<RelationInfluence>,
}

/// Refits each Table 2 relation of `group` without each robot in turn.
pub fn explain(
    table: &SurveyTable,
    group: Group,
    method: Method,
) -> Result<Explanation, regression::RegressionError> {
    explain_relations(table, group, method, &TABLE2_PAIRS)
}

/// Refits each (x, y) relation of `group` without each robot in turn.
pub fn explain_relations(
    table: &SurveyTable,
    group: Group,
    method: Method,
    pairs: &[(Var, Var)],
) -> Result<Explanation, regression::RegressionError> {
    let mut relations = Vec::new();
    for &(x, y) in pairs {
        let p = log_points(table, group, x, y)?;
        let full = regression::fit_line(&p.lx, &p.ly, method, 0.95)?;
        let loo = regression::leave_one_out(&p.lx, &p.ly, method)?;
        let diag = regression::ols_diagnostics(&p.lx, &p.ly)?;
        let mut robots: Vec<RobotInfluence> = loo
            .iter()
            .filter_map(|l| {
                let i = l.index;
                Some(RobotInfluence {
                    id: p.ids[i].clone(),
                    b_without: l.b_without?,
                    delta_b: l.delta_b?,
                    // The leave-one-out refit already has it; reported for OLS, the fit
                    // whose R² the paper quotes.
                    r2_without: l.r2_without.filter(|_| method == Method::Ols),
                    studentized_residual: diag.studentized_external[i],
                    leverage: diag.leverage[i],
                    cooks_distance: diag.cooks_distance[i],
                })
            })
            .collect();
        robots.sort_by(|a, b| {
            b.delta_b
                .abs()
                .total_cmp(&a.delta_b.abs())
                .then(a.id.cmp(&b.id))
        });
        relations.push(RelationInfluence {
            x,
            y,
            n: full.n,
            b: full.b,
            r2: full.r2,
            robots,
        });
    }
    Ok(Explanation {
        dataset: DatasetRef::of(table),
        class: group,
        method,
        relations,
    })
}
