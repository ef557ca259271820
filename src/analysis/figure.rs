//! The data of the survey figure (`survey fit --out`: survey.svg, survey.png, survey.html):
//! for each Table 2 relation and for top speed against leg length, every robot with both
//! values, each class's fitted power law over its data range and the confidence band of that
//! line. `report/` draws it.

use crate::analysis::table2::{
    Group, LogPoints, Numeric, PowerLawRow, TABLE2_PAIRS, Table2, Var, fit_group, log_points,
};
use crate::dataset::validate::G_MPS2;
use crate::dataset::{RobotClass, SpeedKind, SurveyRow, SurveyTable};
use crate::regression::{self, Method};

/// The speed panel of the figure: top speed against leg length.
pub const SPEED_PANEL: (Var, Var) = (Var::LegLength, Var::SpeedTop);

/// One robot in one panel.
#[derive(Debug, Clone)]
pub struct FigurePoint {
    pub id: String,
    pub name: String,
    pub class: RobotClass,
    pub fit: bool,
    pub exclusion: Option<String>,
    /// Leg length, body length and mass cells of the compiled table (text as released).
    pub values: [Option<String>; 3],
    /// The robot's speeds of each kind it has (cells as released).
    pub speeds: Vec<(SpeedKind, String)>,
    pub x: f64,
    pub y: f64,
}

/// A class's fitted power law in one panel, with the confidence band of the line.
#[derive(Debug, Clone)]
pub struct FigureLine {
    pub class: RobotClass,
    pub fit: PowerLawRow,
    /// (x, lower, upper) of the band of the fitted median line (empty for MA and SMA).
    pub band: Vec<(f64, f64, f64)>,
    /// Data range of x the line is drawn over.
    pub x_range: (f64, f64),
}

/// One log–log panel: a Table 2 relation.
#[derive(Debug, Clone)]
pub struct FigurePanel {
    pub x: Var,
    pub y: Var,
    pub points: Vec<FigurePoint>,
    pub lines: Vec<FigureLine>,
    /// The fit over all classes (Table 2's last column), listed but not drawn.
    pub all: Option<PowerLawRow>,
    /// Robots without both values (or with a value a log axis cannot show): (id, name, why).
    pub missing: Vec<(String, String, String)>,
    /// Reference laws drawn dashed across the panel (the speed panel: Froude 1).
    pub references: Vec<ReferenceLine>,
}

/// A reference law y = a·x^b, not fitted.
#[derive(Debug, Clone)]
pub struct ReferenceLine {
    pub label: String,
    pub a: f64,
    pub b: f64,
}

/// The data of the figure, computed from the table and its Table 2 fits.
#[derive(Debug, Clone)]
pub struct SurveyFigure {
    pub version: String,
    pub sha256: String,
    pub frozen: bool,
    pub method: Method,
    pub confidence: f64,
    pub panels: Vec<FigurePanel>,
}

fn row_point(r: &SurveyRow, x: Var, y: Var) -> Result<FigurePoint, String> {
    let get = |v: Var| -> Result<f64, String> {
        match r.number(v.field()) {
            None => Err(format!("no {}", v.field())),
            Some(n) if n <= 0.0 => Err(format!("{} = {n} is not positive", v.field())),
            Some(n) => Ok(n),
        }
    };
    let (px, py) = (get(x), get(y));
    let (px, py) = match (px, py) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(a), Err(b)) => return Err(format!("{a}, {b}")),
        (Err(e), _) | (_, Err(e)) => return Err(e),
    };
    Ok(FigurePoint {
        id: r.id.clone(),
        name: r.name.clone(),
        class: r.class,
        fit: r.fit,
        exclusion: r.exclusion.clone(),
        values: Var::SIZES.map(|v| r.cells.get(v.field()).filter(|s| !s.is_empty()).cloned()),
        speeds: SpeedKind::ALL
            .into_iter()
            .filter_map(|k| Some((k, r.cells.get(k.field()).filter(|s| !s.is_empty())?.clone())))
            .collect(),
        x: px,
        y: py,
    })
}

/// Builds the figure: every row of the table in every panel it has values for, and each
/// class's line with its band (OLS only: the band is the mean interval of the OLS
/// prediction at each x): Table 2's three relations, then top speed against leg length
/// (fitted here the same way, for classes with enough robots with a top speed).
pub fn survey_figure(table: &SurveyTable, t2: &Table2) -> SurveyFigure {
    let confidence = t2.fits.first().map(|f| f.confidence).unwrap_or(0.95);
    let mut panels: Vec<FigurePanel> = TABLE2_PAIRS
        .into_iter()
        .map(|(x, y)| figure_panel(table, &t2.fits, x, y, confidence))
        .collect();
    let (x, y) = SPEED_PANEL;
    let data = Numeric::of(table);
    let speed_fits: Vec<PowerLawRow> = Group::TABLE2
        .into_iter()
        .filter_map(|g| fit_group(&data, g, x, y, t2.method, confidence, None).ok())
        .collect();
    let mut speed = figure_panel(table, &speed_fits, x, y, confidence);
    speed.references.push(ReferenceLine {
        label: "Froude 1 (walk–run limit): v = √(gL)".into(),
        a: G_MPS2.sqrt(),
        b: 0.5,
    });
    panels.push(speed);
    SurveyFigure {
        version: table.version.clone(),
        sha256: table.sha256.clone(),
        frozen: table.frozen,
        method: t2.method,
        confidence,
        panels,
    }
}

/// One relation: its points (and the robots it cannot show), the class lines and the
/// all-classes fit, from `fits`.
fn figure_panel(
    table: &SurveyTable,
    fits: &[PowerLawRow],
    x: Var,
    y: Var,
    confidence: f64,
) -> FigurePanel {
    let mut points = Vec::new();
    let mut missing = Vec::new();
    for r in &table.rows {
        match row_point(r, x, y) {
            Ok(p) => points.push(p),
            Err(why) => missing.push((r.id.clone(), r.name.clone(), why)),
        }
    }
    let lines = RobotClass::FITTED
        .into_iter()
        .filter_map(|c| class_line(table, fits, c, x, y, confidence))
        .collect();
    FigurePanel {
        x,
        y,
        all: fits
            .iter()
            .find(|f| f.class == Group::All && f.x == x && f.y == y)
            .cloned(),
        points,
        lines,
        missing,
        references: Vec::new(),
    }
}

/// A class's Table 2 line over its data range, with its band (None without a fit or
/// without a range to draw).
fn class_line(
    table: &SurveyTable,
    fits: &[PowerLawRow],
    c: RobotClass,
    x: Var,
    y: Var,
    confidence: f64,
) -> Option<FigureLine> {
    let g = Group::Class(c);
    let fit = fits
        .iter()
        .find(|f| f.class == g && f.x == x && f.y == y)?
        .clone();
    let pts = log_points(table, g, x, y).ok()?;
    let lo = pts.x.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = pts.x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return None;
    }
    let band = match fit.method {
        Method::Ols => ols_band(&pts, lo, hi, confidence),
        _ => Vec::new(),
    };
    Some(FigureLine {
        class: c,
        fit,
        band,
        x_range: (lo, hi),
    })
}

/// The confidence band of the OLS line of `pts` at 49 points evenly spaced in log x over
/// [lo, hi], back-transformed: (x, lower, upper). Empty when the line cannot be fitted.
fn ols_band(pts: &LogPoints, lo: f64, hi: f64, confidence: f64) -> Vec<(f64, f64, f64)> {
    let Ok(line) = regression::fit_line(&pts.lx, &pts.ly, Method::Ols, confidence) else {
        return Vec::new();
    };
    let steps = 48;
    (0..=steps)
        .filter_map(|i| {
            let lx = lo.log10() + (hi.log10() - lo.log10()) * i as f64 / steps as f64;
            let p = regression::predict_ols(&line, lx, confidence).ok()?;
            let ci = p.mean_ci.map(|v| 10f64.powf(v));
            Some((10f64.powf(lx), ci.lower, ci.upper))
        })
        .collect()
}
