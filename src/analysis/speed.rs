//! Speed in the survey (`survey fit --y speed --out DIR`, `reports/speed.md`): how many
//! robots of each class carry a speed of each kind (and how many cite a primary source for
//! it), v ∝ L^b per class for every kind with the slope tests of dynamic similarity
//! (b = 0.5), of the biological trend below the speed hump (b = 0.25) and of no trend
//! (b = 0), the Froude numbers v²/(gL), and the paper's own speeds (release 1.0.0, kind
//! unstated) fitted the same way.

use std::collections::BTreeSet;

use serde::Serialize;

use crate::analysis::relation::{RelationFits, RelationSpec, froude, relation_fits};
use crate::analysis::table2::{DatasetRef, Group, Var};
use crate::dataset::validate::has_primary_source;
use crate::dataset::{Dataset, DatasetError, RobotClass, SpeedKind, SurveyTable};
use crate::regression::{Method, RegressionError};

/// The release whose speeds are the paper's (its survey table, speeds of unstated kind).
pub const PAPER_RELEASE: &str = "1.0.0";

/// Why the speed report could not be made.
#[derive(Debug, thiserror::Error)]
pub enum SpeedError {
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    #[error("{what}: {source}")]
    Fit {
        what: String,
        source: RegressionError,
    },
}

/// Fitted robots of one class with a speed of one kind.
#[derive(Debug, Clone, Serialize)]
pub struct KindCount {
    pub class: Group,
    pub kind: SpeedKind,
    pub n: usize,
    /// Of those, speeds citing a primary source (None for a frozen release, which keeps no
    /// per-value sources).
    pub primary: Option<usize>,
}

/// One speed of one robot (a robot with several kinds has several).
#[derive(Debug, Clone, Serialize)]
pub struct SpeedPoint {
    pub id: String,
    pub name: String,
    pub class: RobotClass,
    pub fit: bool,
    pub kind: SpeedKind,
    pub leg_length_m: f64,
    pub speed_mps: f64,
    pub froude: f64,
    /// Whether the speed cites a primary source (None for a frozen release).
    pub primary: Option<bool>,
}

/// `reports/speed.md`.
#[derive(Debug, Clone, Serialize)]
pub struct SpeedReport {
    pub dataset: DatasetRef,
    pub method: Method,
    pub confidence: f64,
    /// Every class (and all) × every kind, stated kinds first.
    pub counts: Vec<KindCount>,
    /// Fitted robots with a speed of at least one stated kind.
    pub robots_with_stated_speed: usize,
    /// Of those, robots with at least one primary-sourced speed of stated kind.
    pub robots_with_primary_speed: Option<usize>,
    /// v ∝ L^b for each stated kind.
    pub fits: Vec<RelationFits>,
    /// Top speeds citing a primary source only (live records).
    pub primary_top: Option<RelationFits>,
    /// The paper's speeds: release 1.0.0's speeds of unstated kind.
    pub paper: Option<RelationFits>,
    pub points: Vec<SpeedPoint>,
}

impl SpeedReport {
    pub fn fits_of(&self, kind: SpeedKind) -> Option<&RelationFits> {
        self.fits.iter().find(|f| f.y.speed_kind() == Some(kind))
    }
    pub fn count(&self, class: Group, kind: SpeedKind) -> Option<&KindCount> {
        self.counts
            .iter()
            .find(|c| c.class == class && c.kind == kind)
    }
}

/// The speeds of the live records that cite a primary source, as (robot id, kind).
pub fn primary_speeds(ds: &Dataset) -> BTreeSet<(String, SpeedKind)> {
    let mut out = BTreeSet::new();
    for (_, r) in &ds.robots {
        for kind in SpeedKind::ALL {
            if let Some(d) = r.values.get(kind.field())
                && has_primary_source(r, d)
            {
                out.insert((r.id.clone(), kind));
            }
        }
    }
    out
}

/// The table with only the speeds that cite a primary source (the other speed cells
/// emptied); sizes untouched.
pub fn primary_speeds_only(
    table: &SurveyTable,
    primary: &BTreeSet<(String, SpeedKind)>,
) -> SurveyTable {
    let mut t = table.clone();
    for row in &mut t.rows {
        for kind in SpeedKind::ALL {
            if !primary.contains(&(row.id.clone(), kind)) {
                row.cells.remove(kind.field());
            }
        }
    }
    t
}

/// The speed report of `table`. `spec` gives the method, level and hypotheses (its x and
/// y are set here: leg length and each kind's speed). With `live` the table is the live
/// records of `ds`, whose per-value sources give the primary-sourced counts and fit; the
/// paper's speeds come from release [`PAPER_RELEASE`] when `ds` has it.
pub fn speed_report(
    ds: &Dataset,
    table: &SurveyTable,
    live: bool,
    spec: &RelationSpec,
) -> Result<SpeedReport, SpeedError> {
    let primary = live.then(|| primary_speeds(ds));
    let fit = |t: &SurveyTable, kind: SpeedKind, what: &str| {
        let spec = RelationSpec {
            x: Var::LegLength,
            y: Var::speed(kind),
            ..spec.clone()
        };
        relation_fits(t, &spec).map_err(|source| SpeedError::Fit {
            what: format!("{what}: {} vs leg length", kind.field()),
            source,
        })
    };
    let fits = SpeedKind::STATED
        .into_iter()
        .map(|k| fit(table, k, &format!("dataset {}", table.version)))
        .collect::<Result<Vec<_>, _>>()?;
    let primary_top = match &primary {
        Some(p) => Some(fit(
            &primary_speeds_only(table, p),
            SpeedKind::Top,
            "primary-sourced speeds",
        )?),
        None => None,
    };
    let has_paper = ds.manifest()?.get(PAPER_RELEASE).is_some();
    let paper = match has_paper {
        true => Some(fit(
            &ds.table(Some(PAPER_RELEASE))?,
            SpeedKind::Unstated,
            &format!("release {PAPER_RELEASE}"),
        )?),
        false => None,
    };
    let points = speed_points(table, primary.as_ref());
    Ok(SpeedReport {
        dataset: DatasetRef::of(table),
        method: spec.method,
        confidence: spec.confidence,
        counts: counts(&points, primary.is_some()),
        robots_with_stated_speed: robots_with(&points, |_| true),
        robots_with_primary_speed: primary
            .is_some()
            .then(|| robots_with(&points, |p| p.primary == Some(true))),
        fits,
        primary_top,
        paper,
        points,
    })
}

/// Every speed of every robot with a leg length.
fn speed_points(
    table: &SurveyTable,
    primary: Option<&BTreeSet<(String, SpeedKind)>>,
) -> Vec<SpeedPoint> {
    let mut points = Vec::new();
    for r in &table.rows {
        let Some(l) = r.number(Var::LegLength.field()).filter(|l| *l > 0.0) else {
            continue;
        };
        for kind in SpeedKind::ALL {
            let Some(v) = r.number(kind.field()).filter(|v| *v > 0.0) else {
                continue;
            };
            points.push(SpeedPoint {
                id: r.id.clone(),
                name: r.name.clone(),
                class: r.class,
                fit: r.fit,
                kind,
                leg_length_m: l,
                speed_mps: v,
                froude: froude(v, l),
                primary: primary.map(|p| p.contains(&(r.id.clone(), kind))),
            });
        }
    }
    points
}

/// Fitted robots per class and kind (every kind, the four classes and all).
fn counts(points: &[SpeedPoint], with_primary: bool) -> Vec<KindCount> {
    let mut out = Vec::new();
    for g in Group::TABLE2 {
        for kind in SpeedKind::ALL {
            let of: Vec<&SpeedPoint> = points
                .iter()
                .filter(|p| p.kind == kind && g.includes(p.class, p.fit))
                .collect();
            out.push(KindCount {
                class: g,
                kind,
                n: of.len(),
                primary: with_primary
                    .then(|| of.iter().filter(|p| p.primary == Some(true)).count()),
            });
        }
    }
    out
}

/// Fitted robots of the four classes with a speed of stated kind that `keep` accepts.
fn robots_with(points: &[SpeedPoint], keep: impl Fn(&SpeedPoint) -> bool) -> usize {
    points
        .iter()
        .filter(|p| p.kind != SpeedKind::Unstated && Group::All.includes(p.class, p.fit))
        .filter(|p| keep(p))
        .map(|p| p.id.as_str())
        .collect::<BTreeSet<_>>()
        .len()
}
