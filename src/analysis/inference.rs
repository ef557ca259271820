//! Hypothesis tests over the survey (`survey test`): a slope against a given value
//! (isometry by default), a common slope among classes (Warton et al. 2006 likelihood
//! ratio for MA/SMA, ANCOVA F for OLS), and a shift in elevation given the common slope.
//! This module chooses the data; the statistics are [`crate::regression`]'s.

use serde::Serialize;

use crate::analysis::relation::{Hypothesis, HypothesisTest, test_hypotheses};
use crate::analysis::table2::{DatasetRef, Group, Var, log_points};
use crate::dataset::{RobotClass, SurveyTable};
use crate::regression::{self, CommonSlopeTest, ElevationComparison, Method, RegressionError};

/// `survey test slope`.
#[derive(Debug, Clone, Serialize)]
pub struct SlopeTestReport {
    pub dataset: DatasetRef,
    pub class: Group,
    pub x: Var,
    pub y: Var,
    pub confidence: f64,
    /// Fitted exponent with its interval.
    pub b_ci: [f64; 2],
    /// Each hypothesised exponent (given, or the scaling laws') and its test.
    pub tests: Vec<HypothesisTest>,
}

/// `survey test common-slope` and `survey test elevation`.
#[derive(Debug, Clone, Serialize)]
pub struct GroupComparisonReport {
    pub dataset: DatasetRef,
    pub classes: Vec<Group>,
    pub x: Var,
    pub y: Var,
    pub common_slope: CommonSlopeTest,
    /// Elevation shift among classes, given the common slope.
    pub elevation: Option<ElevationComparison>,
}

/// Tests each hypothesised exponent for one class (smatr's `slope.test`).
pub fn slope(
    table: &SurveyTable,
    class: Group,
    x: Var,
    y: Var,
    method: Method,
    hypotheses: &[Hypothesis],
    confidence: f64,
) -> Result<SlopeTestReport, RegressionError> {
    if hypotheses.is_empty() {
        return Err(RegressionError::InvalidArgument(
            "no exponent to test".into(),
        ));
    }
    let p = log_points(table, class, x, y)?;
    let (lx, ly) = (&p.lx, &p.ly);
    let fit = regression::fit_line(lx, ly, method, confidence)?;
    let tests = test_hypotheses(lx, ly, method, hypotheses, confidence)?;
    Ok(SlopeTestReport {
        dataset: DatasetRef::of(table),
        class,
        x,
        y,
        confidence,
        b_ci: [fit.b_ci.lower, fit.b_ci.upper],
        tests,
    })
}

/// Tests for a common slope among `classes` (default: the four classes), then for a
/// shift in elevation given that slope.
pub fn common_slope(
    table: &SurveyTable,
    classes: &[Group],
    x: Var,
    y: Var,
    method: Method,
    confidence: f64,
) -> Result<GroupComparisonReport, RegressionError> {
    let classes: Vec<Group> = if classes.is_empty() {
        RobotClass::FITTED
            .iter()
            .map(|c| Group::Class(*c))
            .collect()
    } else {
        classes.to_vec()
    };
    let data = classes
        .iter()
        .map(|g| log_points(table, *g, x, y))
        .collect::<Result<Vec<_>, _>>()?;
    let groups: Vec<regression::Group<'_>> = classes
        .iter()
        .zip(&data)
        .map(|(g, p)| regression::Group {
            label: g.as_str(),
            x: &p.lx,
            y: &p.ly,
        })
        .collect();
    let common = regression::slope_com(&groups, method, confidence)?;
    let elevation = regression::elev_com(&groups, method, confidence).ok();
    Ok(GroupComparisonReport {
        dataset: DatasetRef::of(table),
        classes,
        x,
        y,
        common_slope: common,
        elevation,
    })
}
