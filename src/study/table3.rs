//! The paper's Table III (its Table IV in the arXiv numbering): each design scaled over
//! leg lengths 0.02–1.2 m under m ∝ L² and m ∝ L³, and under a contact rule; at every size
//! the minimum hip torque for consistent walking and the gait; over the sizes, the power
//! laws v ∝ L^a, τ_min ∝ L^b and τ_min ∝ (m·L)^c fitted with the regression engine, and
//! the attitude amplitudes as mean ± sd.
//!
//! A *chain* is one design × mass law × contact rule over all sizes. Sizes within a chain
//! run in order of leg length, each warm-started from its smaller neighbour's bracket
//! rescaled by m·g·L (under similar contact that bracket holds exactly, so a point costs
//! a handful of walks); chains run in parallel and are the unit of sharding, so a
//! shard's points are exactly those of one run. Every finished point can be appended to a
//! points file ([`super::sweep`]): a re-run resumes, shards merge.
//!
//! Duration: the simulated time of every walk is `duration_at_design_size_s` × √(L/L₀)
//! (L₀ the design's own leg length), the same number of drive cycles and time steps at
//! every size, so under similar contact every size is the same dimensionless simulation.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Mutex;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::StudyError;
use super::min_torque::{MinTorqueOptions, min_torque};
use super::scaling::{StudyLaw, law};
use super::sweep::{PointLog, Shard, SweepPoint, append_to, finish_points, open_log, spec_line};
use crate::sim::{
    ContactScaling, Design, GRAVITY_MPS2, MassLaw, WalkOptions, WalkReport, simulate_walk,
};

/// Kind name of Table III points files.
pub const TABLE3_KIND: &str = "table3";

/// Leg lengths of the paper's protocol: `n` log-spaced from 0.02 to 1.2 m, rounded to 3
/// significant digits, with the nearest to 0.025, 0.15 and 1.0 m replaced by those sizes
/// (the hardware sizes of Zippy and Mugatu and the 1 m design point).
pub fn table3_leg_lengths(n: usize) -> Vec<f64> {
    let n = n.max(4);
    let (lo, hi) = (0.02f64, 1.2f64);
    let mut ls: Vec<f64> = (0..n)
        .map(|k| {
            let v = lo * (hi / lo).powf(k as f64 / (n - 1) as f64);
            let mag = 10f64.powf(v.log10().floor() - 2.0);
            (v / mag).round() * mag
        })
        .map(|v| (v * 1e9).round() / 1e9)
        .collect();
    for anchor in [0.025, 0.15, 1.0] {
        if let Some(i) = (0..n).min_by(|&a, &b| {
            let da = (ls[a] / anchor).ln().abs();
            let db = (ls[b] / anchor).ln().abs();
            da.total_cmp(&db)
        }) {
            ls[i] = anchor;
        }
    }
    ls
}

/// What to run.
#[derive(Clone, Debug)]
pub struct Table3Spec {
    pub designs: Vec<Design>,
    pub mass_laws: Vec<MassLaw>,
    pub contacts: Vec<ContactScaling>,
    pub leg_lengths_m: Vec<f64>,
    /// Simulated time at the design's own size [s]; ∝ √L at other sizes.
    pub duration_at_design_size_s: f64,
    /// Perturbed starts that must walk too (see [`MinTorqueOptions::seeds`]).
    pub seeds: u64,
    pub rel_tol: f64,
    pub cap_over_mgl: f64,
}

impl Table3Spec {
    /// The paper's protocol for `designs`: 36 sizes, both mass laws, 25 s at 1×.
    pub fn paper(designs: Vec<Design>, contacts: Vec<ContactScaling>) -> Self {
        Table3Spec {
            designs,
            mass_laws: vec![MassLaw::L2, MassLaw::L3],
            contacts,
            leg_lengths_m: table3_leg_lengths(36),
            duration_at_design_size_s: 25.0,
            seeds: 2,
            rel_tol: 0.02,
            cap_over_mgl: 2.0,
        }
    }

    fn check(&self) -> Result<(), StudyError> {
        let bad = |option: &str, reason: String| {
            Err(StudyError::InvalidOption {
                option: option.into(),
                reason,
            })
        };
        if self.designs.is_empty() || self.mass_laws.is_empty() || self.contacts.is_empty() {
            return bad(
                "designs",
                "need at least one design, mass law and contact rule".into(),
            );
        }
        if self.leg_lengths_m.len() < 3 {
            return bad("leg_lengths", "need at least 3 sizes for the fits".into());
        }
        if let Some(l) = self
            .leg_lengths_m
            .iter()
            .find(|l| !(l.is_finite() && **l > 0.0))
        {
            return bad(
                "leg_lengths",
                format!("{l} is not a positive length in metres"),
            );
        }
        if !(self.duration_at_design_size_s > 0.0 && self.duration_at_design_size_s.is_finite()) {
            return bad(
                "duration",
                format!("must be > 0 s, got {}", self.duration_at_design_size_s),
            );
        }
        Ok(())
    }

    /// The chains in canonical order (contact, design, mass law): the unit of sharding.
    pub fn chains(&self) -> Vec<(usize, MassLaw, ContactScaling)> {
        let mut out = Vec::new();
        for &c in &self.contacts {
            for d in 0..self.designs.len() {
                for &m in &self.mass_laws {
                    out.push((d, m, c));
                }
            }
        }
        out
    }

    /// The first line of this study's points files: everything that determines a point
    /// (the designs through a SHA-256 of their full parameter sets).
    pub fn header(&self) -> String {
        #[derive(Serialize)]
        struct Fingerprint<'a> {
            version: &'a str,
            designs: Vec<(String, String)>,
            mass_laws: &'a [MassLaw],
            contacts: &'a [ContactScaling],
            leg_lengths_m: &'a [f64],
            duration_at_design_size_s: f64,
            seeds: u64,
            rel_tol: f64,
            cap_over_mgl: f64,
        }
        let designs = self
            .designs
            .iter()
            .map(|d| (d.name.clone(), design_hash(d)))
            .collect();
        let fp = Fingerprint {
            version: env!("CARGO_PKG_VERSION"),
            designs,
            mass_laws: &self.mass_laws,
            contacts: &self.contacts,
            leg_lengths_m: &self.leg_lengths_m,
            duration_at_design_size_s: self.duration_at_design_size_s,
            seeds: self.seeds,
            rel_tol: self.rel_tol,
            cap_over_mgl: self.cap_over_mgl,
        };
        spec_line(TABLE3_KIND, &serde_json::to_string(&fp).unwrap_or_default())
    }

    pub fn points_total(&self) -> usize {
        self.chains().len() * self.leg_lengths_m.len()
    }
}

/// The first 16 hex digits of the SHA-256 of a design's full parameter set (JSON): a
/// points file names the exact designs it was made with.
pub fn design_hash(d: &Design) -> String {
    // The uncertain-parameter declarations and the audit's are not physics: the same walks
    // with or without.
    let physics = Design {
        uncertain: Vec::new(),
        audit: None,
        ..d.clone()
    };
    let json = serde_json::to_string(&physics).unwrap_or_default();
    let hash = Sha256::digest(json.as_bytes());
    hash.iter().take(8).map(|b| format!("{b:02x}")).collect()
}

/// One size of one chain.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Table3Point {
    pub design: String,
    pub mass_law: MassLaw,
    pub contact: ContactScaling,
    pub leg_length_m: f64,
    pub mass_kg: f64,
    /// m·g·L [N·m].
    pub mgl_nm: f64,
    pub duration_s: f64,
    /// Walks consistently at some torque up to the cap.
    pub walks: bool,
    /// The unperturbed walk at the design's own torque (scaled ∝ m·g·L) walks.
    pub walks_at_design_torque: bool,
    pub min_torque_nm: Option<f64>,
    pub min_torque_over_mgl: Option<f64>,
    pub bracket_lo_nm: Option<f64>,
    pub bracket_hi_nm: Option<f64>,
    pub walks_evaluated: usize,
    /// What fails just below the minimum (or at the cap): a fall reason or "no_progress".
    pub failure_below: Option<String>,
    /// Which walk the gait columns come from: `design_torque` (the design's own torque,
    /// when it walks there) or `min_torque`.
    pub gait_at: Option<String>,
    pub gait_torque_nm: Option<f64>,
    pub velocity_mps: Option<f64>,
    pub froude: Option<f64>,
    pub step_frequency_hz: Option<f64>,
    pub roll_pp_deg: Option<f64>,
    pub pitch_pp_deg: Option<f64>,
    pub yaw_pp_deg: Option<f64>,
    pub peak_torque_nm: Option<f64>,
}

impl Table3Point {
    /// One line of a sweep's progress: which chain and size finished (and whether it came
    /// from the points file of an earlier run).
    pub fn progress_label(&self, resumed: bool) -> String {
        format!(
            "{} {:?} {:?} L = {} m{}",
            self.design,
            self.mass_law,
            self.contact,
            self.leg_length_m,
            if resumed {
                " (from the points file)"
            } else {
                ""
            }
        )
    }
}

impl SweepPoint for Table3Point {
    fn key(&self) -> String {
        point_key(&self.design, self.mass_law, self.contact, self.leg_length_m)
    }
}

fn point_key(design: &str, m: MassLaw, c: ContactScaling, l: f64) -> String {
    format!("{design}/{m:?}/{c:?}/{l}")
}

/// Mean ± sd of a column over the walking sizes.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MeanSd {
    pub mean: f64,
    pub sd: f64,
}

fn mean_sd(v: &[f64]) -> Option<MeanSd> {
    let (mean, sd) = crate::sim::walk::mean_sd(v);
    (!v.is_empty()).then_some(MeanSd { mean, sd })
}

/// One row of Table III: a design under a mass law and a contact rule.
#[derive(Clone, Debug, Serialize)]
pub struct Table3Row {
    pub design: String,
    pub mass_law: MassLaw,
    pub contact: ContactScaling,
    pub velocity_exponent: Option<f64>,
    pub velocity_exponent_ci: Option<[f64; 2]>,
    pub velocity_r2: Option<f64>,
    pub torque_exponent: Option<f64>,
    pub torque_exponent_ci: Option<[f64; 2]>,
    pub torque_r2: Option<f64>,
    pub torque_vs_mass_length_exponent: Option<f64>,
    pub torque_vs_mass_length_exponent_ci: Option<[f64; 2]>,
    pub roll_pp_deg: Option<f64>,
    pub roll_pp_deg_sd: Option<f64>,
    pub pitch_pp_deg: Option<f64>,
    pub pitch_pp_deg_sd: Option<f64>,
    pub yaw_pp_deg: Option<f64>,
    pub yaw_pp_deg_sd: Option<f64>,
    /// τ_min/(m·g·L) over the walking sizes.
    pub min_torque_over_mgl: Option<MeanSd>,
    pub sizes_walking: usize,
    pub sizes_total: usize,
    /// Leg lengths at which no torque up to the cap walks consistently.
    pub sizes_not_walking_m: Vec<f64>,
    pub walks_evaluated: usize,
    pub velocity_law: Option<StudyLaw>,
    pub torque_law: Option<StudyLaw>,
    pub torque_vs_mass_length: Option<StudyLaw>,
    pub points: Vec<Table3Point>,
}

/// The whole table.
#[derive(Clone, Debug, Serialize)]
pub struct Table3 {
    pub leg_lengths_m: Vec<f64>,
    pub duration_at_design_size_s: f64,
    pub seeds: u64,
    pub rel_tol: f64,
    pub cap_over_mgl: f64,
    pub criterion: String,
    pub rows: Vec<Table3Row>,
}

/// Progress of a run (for a progress bar).
pub trait Observer: Sync {
    fn point_done(&self, _p: &Table3Point, _resumed: bool) {}
}

impl Observer for () {}

/// What a (possibly sharded, possibly resumed) run produced.
pub struct Table3Run {
    /// Points of the chains this shard ran, in canonical order.
    pub points: Vec<Table3Point>,
    /// Points newly simulated (the rest came from the points file).
    pub simulated: usize,
    /// The table, when the run covered every chain (no shard, or a merged file).
    pub table: Option<Table3>,
}

/// Runs the chains of `shard`, appending each new point to `points_file` when given and
/// taking the points already there. Chains run in parallel; results are independent of
/// thread count and interruption.
pub fn run_table3(
    spec: &Table3Spec,
    shard: Shard,
    points_file: Option<&Path>,
    observer: &dyn Observer,
) -> Result<Table3Run, StudyError> {
    spec.check()?;
    let (log, done) = open_log::<Table3Point>(points_file, &spec.header())?;
    let chains: Vec<_> = spec
        .chains()
        .into_iter()
        .enumerate()
        .filter(|(k, _)| shard.takes(*k))
        .map(|(_, c)| c)
        .collect();
    let simulated = std::sync::atomic::AtomicUsize::new(0);
    let per_chain: Vec<Vec<Table3Point>> = chains
        .par_iter()
        .map(|&(d, m, c)| {
            run_chain(
                spec,
                &spec.designs[d],
                m,
                c,
                &done,
                log.as_ref(),
                &|p, resumed| {
                    if !resumed {
                        simulated.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    }
                    observer.point_done(p, resumed)
                },
            )
        })
        .collect::<Result<_, _>>()?;
    let points: Vec<Table3Point> = per_chain.into_iter().flatten().collect();
    let table = if shard == Shard::WHOLE {
        Some(assemble(spec, &points)?)
    } else {
        None
    };
    if let (Some(path), true) = (points_file, shard == Shard::WHOLE) {
        finish_points(path, &spec.header(), &points)?;
    }
    Ok(Table3Run {
        points,
        simulated: simulated.into_inner(),
        table,
    })
}

fn run_chain(
    spec: &Table3Spec,
    design: &Design,
    mass_law: MassLaw,
    contact: ContactScaling,
    done: &HashMap<String, Table3Point>,
    log: Option<&Mutex<PointLog>>,
    on_point: &(dyn Fn(&Table3Point, bool) + Sync),
) -> Result<Vec<Table3Point>, StudyError> {
    let mut ls = spec.leg_lengths_m.clone();
    ls.sort_by(f64::total_cmp);
    let mut warm: Option<[f64; 2]> = None;
    let mut out = Vec::with_capacity(ls.len());
    for l in ls {
        let key = point_key(&design.name, mass_law, contact, l);
        let (p, resumed) = match done.get(&key) {
            Some(p) => (p.clone(), true),
            None => {
                let p = table3_point(spec, design, mass_law, contact, l, warm)?;
                append_to(log, &p)?;
                (p, false)
            }
        };
        on_point(&p, resumed);
        if let (true, Some(lo), Some(hi)) = (p.walks, p.bracket_lo_nm, p.bracket_hi_nm)
            && lo > 0.0
        {
            warm = Some([lo / p.mgl_nm, hi / p.mgl_nm]);
        }
        out.push(p);
    }
    Ok(out)
}

/// One point: the minimum torque (warm-started from `warm`, a bracket in units of m·g·L)
/// and the gait.
pub fn table3_point(
    spec: &Table3Spec,
    design: &Design,
    mass_law: MassLaw,
    contact: ContactScaling,
    leg_length_m: f64,
    warm: Option<[f64; 2]>,
) -> Result<Table3Point, StudyError> {
    let scaled = design.scaled(leg_length_m, mass_law, contact)?;
    let mgl = scaled.mass.total_mass_kg * GRAVITY_MPS2 * scaled.geometry.leg_length_m;
    let duration_s =
        spec.duration_at_design_size_s * (leg_length_m / design.geometry.leg_length_m).sqrt();
    let walk = WalkOptions {
        leg_length_m: Some(leg_length_m),
        mass_law,
        contact_scaling: contact,
        duration_s,
        record_trajectory: false,
        ..WalkOptions::default()
    };
    let r = min_torque(
        design,
        &MinTorqueOptions {
            walk: walk.clone(),
            seeds: spec.seeds,
            rel_tol: spec.rel_tol,
            cap_over_mgl: spec.cap_over_mgl,
            start_nm: None,
            start_bracket_nm: warm.map(|[a, b]| [a * mgl, b * mgl]),
        },
    )?;
    let at_design = simulate_walk(design, &walk)?.report;
    let gait: Option<(&WalkReport, &str)> = match (&r.gait, r.walks) {
        (_, true) if at_design.walks => Some((&at_design, "design_torque")),
        (Some(g), true) => Some((g, "min_torque")),
        _ => None,
    };
    let f = |get: fn(&WalkReport) -> f64| gait.map(|(g, _)| get(g));
    Ok(Table3Point {
        design: design.name.clone(),
        mass_law,
        contact,
        leg_length_m,
        mass_kg: r.mass_kg,
        mgl_nm: r.mgl_nm,
        duration_s,
        walks: r.walks,
        walks_at_design_torque: at_design.walks,
        min_torque_nm: r.min_torque_nm,
        min_torque_over_mgl: r.min_torque_over_mgl,
        bracket_lo_nm: r.bracket_nm.map(|b| b[0]),
        bracket_hi_nm: r.bracket_nm.map(|b| b[1]),
        walks_evaluated: r.walks_evaluated + 1,
        failure_below: r.failure_below.clone(),
        gait_at: gait.map(|(_, at)| at.to_string()),
        gait_torque_nm: f(|g| g.torque_limit_nm),
        velocity_mps: f(|g| g.velocity_mps),
        froude: f(|g| g.froude),
        step_frequency_hz: f(|g| g.step_frequency_hz),
        roll_pp_deg: f(|g| g.roll_pp_deg),
        pitch_pp_deg: f(|g| g.pitch_pp_deg),
        yaw_pp_deg: f(|g| g.yaw_pp_deg),
        peak_torque_nm: f(|g| g.peak_torque_nm),
    })
}

/// Fits and summaries over a complete set of points.
pub fn assemble(spec: &Table3Spec, points: &[Table3Point]) -> Result<Table3, StudyError> {
    let mut rows = Vec::new();
    for (d, m, c) in spec.chains() {
        let name = &spec.designs[d].name;
        let mut pts: Vec<Table3Point> = points
            .iter()
            .filter(|p| &p.design == name && p.mass_law == m && p.contact == c)
            .cloned()
            .collect();
        pts.sort_by(|a, b| a.leg_length_m.total_cmp(&b.leg_length_m));
        if pts.len() != spec.leg_lengths_m.len() {
            return Err(StudyError::InvalidOption {
                option: "points".into(),
                reason: format!(
                    "{name} {m:?} {c:?}: {} of {} sizes present; run the missing shards first",
                    pts.len(),
                    spec.leg_lengths_m.len()
                ),
            });
        }
        rows.push(row(name, m, c, pts));
    }
    Ok(Table3 {
        leg_lengths_m: spec.leg_lengths_m.clone(),
        duration_at_design_size_s: spec.duration_at_design_size_s,
        seeds: spec.seeds,
        rel_tol: spec.rel_tol,
        cap_over_mgl: spec.cap_over_mgl,
        criterion: format!(
            "walks consistently: no fall and steady forward speed above the design's threshold \
             from the unperturbed start and {} seeded perturbations; minimum torque by \
             bracketing and bisection to {:.1} % relative; cap {} m·g·L; {} s at the design's \
             own size, ∝ √L elsewhere",
            spec.seeds,
            100.0 * spec.rel_tol,
            spec.cap_over_mgl,
            spec.duration_at_design_size_s
        ),
        rows,
    })
}

/// Table III rows from a set of points alone (e.g. a points file), one per design × mass
/// law × contact rule in order of first appearance.
pub fn rows_from_points(points: &[Table3Point]) -> Vec<Table3Row> {
    let mut keys: Vec<(String, MassLaw, ContactScaling)> = Vec::new();
    for p in points {
        let k = (p.design.clone(), p.mass_law, p.contact);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|(d, m, c)| {
            let mut pts: Vec<Table3Point> = points
                .iter()
                .filter(|p| p.design == d && p.mass_law == m && p.contact == c)
                .cloned()
                .collect();
            pts.sort_by(|a, b| a.leg_length_m.total_cmp(&b.leg_length_m));
            row(&d, m, c, pts)
        })
        .collect()
}

/// Table III points from a points file (`survey sim table3 --points FILE`), or the bundled
/// copy when `path` is None (what `survey predict`, `survey torque-check` and the Python
/// package read).
pub fn points(path: Option<&std::path::Path>) -> Result<Vec<Table3Point>, StudyError> {
    match path {
        Some(p) => Ok(crate::checkpoint::read_points::<Table3Point>(p)?.1),
        None => bundled_points(),
    }
}

/// The project's Table III points (`reports/table3.points.csv`, made by
/// `survey sim table3 --out reports/`), compiled in for `survey predict` and
/// `survey torque-check`.
pub fn bundled_points() -> Result<Vec<Table3Point>, StudyError> {
    const TEXT: &str = include_str!("../../reports/table3.points.csv");
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(TEXT.as_bytes());
    reader
        .deserialize()
        .enumerate()
        .map(|(i, r)| {
            r.map_err(|e| StudyError::Data {
                origin: format!("reports/table3.points.csv (bundled), row {}", i + 1),
                message: e.to_string(),
            })
        })
        .collect()
}

fn row(name: &str, m: MassLaw, c: ContactScaling, pts: Vec<Table3Point>) -> Table3Row {
    let walking: Vec<&Table3Point> = pts.iter().filter(|p| p.walks).collect();
    let col = |get: fn(&Table3Point) -> Option<f64>| -> (Vec<f64>, Vec<f64>) {
        walking
            .iter()
            .filter_map(|p| get(p).map(|y| (p.leg_length_m, y)))
            .unzip()
    };
    let (lv, v) = col(|p| p.velocity_mps.filter(|v| *v > 0.0));
    let (lt, t) = col(|p| p.min_torque_nm);
    let ml: Vec<f64> = walking
        .iter()
        .filter(|p| p.min_torque_nm.is_some())
        .map(|p| p.mass_kg * p.leg_length_m)
        .collect();
    let velocity_law = law("leg_length_m", "velocity_mps", &lv, &v);
    let torque_law = law("leg_length_m", "min_torque_nm", &lt, &t);
    let torque_vs_mass_length = law("mass_length_kg_m", "min_torque_nm", &ml, &t);
    let att = |get: fn(&Table3Point) -> Option<f64>| {
        mean_sd(&walking.iter().filter_map(|p| get(p)).collect::<Vec<_>>())
    };
    let roll = att(|p| p.roll_pp_deg);
    let pitch = att(|p| p.pitch_pp_deg);
    let yaw = att(|p| p.yaw_pp_deg);
    Table3Row {
        design: name.to_string(),
        mass_law: m,
        contact: c,
        velocity_exponent: velocity_law.as_ref().map(|l| l.b),
        velocity_exponent_ci: velocity_law.as_ref().map(|l| l.b_ci),
        velocity_r2: velocity_law.as_ref().map(|l| l.r2),
        torque_exponent: torque_law.as_ref().map(|l| l.b),
        torque_exponent_ci: torque_law.as_ref().map(|l| l.b_ci),
        torque_r2: torque_law.as_ref().map(|l| l.r2),
        torque_vs_mass_length_exponent: torque_vs_mass_length.as_ref().map(|l| l.b),
        torque_vs_mass_length_exponent_ci: torque_vs_mass_length.as_ref().map(|l| l.b_ci),
        roll_pp_deg: roll.map(|s| s.mean),
        roll_pp_deg_sd: roll.map(|s| s.sd),
        pitch_pp_deg: pitch.map(|s| s.mean),
        pitch_pp_deg_sd: pitch.map(|s| s.sd),
        yaw_pp_deg: yaw.map(|s| s.mean),
        yaw_pp_deg_sd: yaw.map(|s| s.sd),
        min_torque_over_mgl: att(|p| p.min_torque_over_mgl),
        sizes_walking: walking.len(),
        sizes_total: pts.len(),
        sizes_not_walking_m: pts
            .iter()
            .filter(|p| !p.walks)
            .map(|p| p.leg_length_m)
            .collect(),
        walks_evaluated: pts.iter().map(|p| p.walks_evaluated).sum(),
        velocity_law,
        torque_law,
        torque_vs_mass_length,
        points: pts,
    }
}
