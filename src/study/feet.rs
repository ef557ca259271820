//! The foot study (the paper's Sec. V, "Feasible Foot Curvatures"): at a few sizes, each
//! semi-axis of the foot ellipsoid (R_X fore-aft, R_Y lateral, R_Z vertical) is scaled
//! alone from 0.5× to 2.0× (the others at 1×) and the walker is simulated with its own
//! (scaled) control. Which feet walk, the feasible semi-axis lengths against L fitted as
//! power laws (the paper: R_X ≈ 1.8·L^1.01 for Zippy, 1.2·L^1.00 for Mugatu), and the
//! fastest foot at each size against the Froude prediction from the 1× foot.
//!
//! Points are independent (no warm start), so every point is a unit of `--shard` and of
//! the resumable points file.

use std::path::Path;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::StudyError;
use super::scaling::{StudyLaw, law};
use super::sweep::{Shard, SweepPoint, append_to, finish_points, open_log, spec_line};
use crate::sim::{ContactScaling, Design, MassLaw, WalkOptions, simulate_walk};

pub const FEET_KIND: &str = "feet";

const AXES: [&str; 3] = ["x", "y", "z"];

#[derive(Clone, Debug)]
pub struct FeetSpec {
    pub designs: Vec<Design>,
    pub leg_lengths_m: Vec<f64>,
    /// Multipliers of one semi-axis (the paper: 0.5 to 2.0 in steps of 0.1).
    pub factors: Vec<f64>,
    pub contacts: Vec<ContactScaling>,
    pub mass_law: MassLaw,
    /// Simulated time at the design's own size [s]; ∝ √L elsewhere (the paper: 25 s).
    pub duration_at_design_size_s: f64,
}

impl FeetSpec {
    pub fn paper(designs: Vec<Design>, contacts: Vec<ContactScaling>) -> Self {
        FeetSpec {
            designs,
            leg_lengths_m: vec![0.025, 0.15, 1.0],
            factors: (5..=20).map(|k| k as f64 / 10.0).collect(),
            contacts,
            mass_law: MassLaw::L2,
            duration_at_design_size_s: 25.0,
        }
    }

    /// Every point in canonical order: contact, design, size, axis, factor.
    pub fn units(&self) -> Vec<(ContactScaling, usize, f64, usize, f64)> {
        let mut out = Vec::new();
        for &c in &self.contacts {
            for d in 0..self.designs.len() {
                for &l in &self.leg_lengths_m {
                    for axis in 0..3 {
                        for &f in &self.factors {
                            out.push((c, d, l, axis, f));
                        }
                    }
                }
            }
        }
        out
    }

    pub fn header(&self) -> String {
        #[derive(Serialize)]
        struct Fingerprint<'a> {
            version: &'a str,
            designs: Vec<(String, String)>,
            leg_lengths_m: &'a [f64],
            factors: &'a [f64],
            contacts: &'a [ContactScaling],
            mass_law: MassLaw,
            duration_at_design_size_s: f64,
        }
        let fp = Fingerprint {
            version: env!("CARGO_PKG_VERSION"),
            designs: self
                .designs
                .iter()
                .map(|d| (d.name.clone(), super::table3::design_hash(d)))
                .collect(),
            leg_lengths_m: &self.leg_lengths_m,
            factors: &self.factors,
            contacts: &self.contacts,
            mass_law: self.mass_law,
            duration_at_design_size_s: self.duration_at_design_size_s,
        };
        spec_line(FEET_KIND, &serde_json::to_string(&fp).unwrap_or_default())
    }

    fn check(&self) -> Result<(), StudyError> {
        let bad = |option: &str, reason: String| {
            Err(StudyError::InvalidOption {
                option: option.into(),
                reason,
            })
        };
        if self.designs.is_empty() || self.contacts.is_empty() {
            return bad(
                "designs",
                "need at least one design and contact rule".into(),
            );
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
        if let Some(f) = self.factors.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
            return bad("factors", format!("{f} is not a positive multiplier"));
        }
        if self.factors.is_empty() || self.leg_lengths_m.is_empty() {
            return bad(
                "factors",
                "need at least one size and one multiplier".into(),
            );
        }
        Ok(())
    }
}

/// One foot at one size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FootPoint {
    pub design: String,
    pub contact: ContactScaling,
    pub mass_law: MassLaw,
    pub leg_length_m: f64,
    /// The semi-axis scaled: x (fore-aft), y (lateral) or z (vertical).
    pub axis: String,
    pub factor: f64,
    pub r_x_m: f64,
    pub r_y_m: f64,
    pub r_z_m: f64,
    pub walks: bool,
    pub fall_reason: Option<String>,
    pub velocity_mps: f64,
    pub froude: f64,
    pub roll_pp_deg: f64,
    pub pitch_pp_deg: f64,
    pub yaw_pp_deg: f64,
}

impl SweepPoint for FootPoint {
    fn key(&self) -> String {
        foot_key(
            &self.design,
            self.contact,
            self.leg_length_m,
            &self.axis,
            self.factor,
        )
    }
}

fn foot_key(design: &str, c: ContactScaling, l: f64, axis: &str, factor: f64) -> String {
    format!("{design}/{c:?}/{l}/{axis}/{factor}")
}

/// Feasible multipliers of one semi-axis at one size.
#[derive(Clone, Debug, Serialize)]
pub struct FeasibleRange {
    pub design: String,
    pub contact: ContactScaling,
    pub leg_length_m: f64,
    pub axis: String,
    /// Multipliers that walk, ascending.
    pub walking_factors: Vec<f64>,
    /// Shortest and longest walking semi-axis [m].
    pub min_m: Option<f64>,
    pub max_m: Option<f64>,
}

/// Feasible semi-axis length against leg length: every walking foot's scaled semi-axis,
/// R = a·L^b (OLS, log–log), beside the paper's fit.
#[derive(Clone, Debug, Serialize)]
pub struct FeasibleLaw {
    pub design: String,
    pub contact: ContactScaling,
    pub axis: String,
    pub law: Option<StudyLaw>,
    /// The paper's (a, b, R²), when it reports this design and axis.
    pub paper: Option<[f64; 3]>,
}

/// The fastest walking foot at one size.
#[derive(Clone, Debug, Serialize)]
pub struct FastestFoot {
    pub design: String,
    pub contact: ContactScaling,
    pub leg_length_m: f64,
    pub axis: String,
    pub factor: f64,
    pub velocity_mps: f64,
    /// The 1× foot at this size.
    pub velocity_1x_mps: Option<f64>,
    /// The reference size: the study's size nearest the design's own leg length.
    pub reference_leg_length_m: f64,
    /// The 1× foot's velocity at the reference size × √(L/L_ref).
    pub froude_prediction_mps: Option<f64>,
    /// velocity / Froude prediction − 1.
    pub excess_over_froude: Option<f64>,
    /// The paper's fastest-foot velocity at this design and size, when reported.
    pub paper_velocity_mps: Option<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct FeetStudy {
    pub leg_lengths_m: Vec<f64>,
    pub factors: Vec<f64>,
    pub mass_law: MassLaw,
    pub duration_at_design_size_s: f64,
    pub ranges: Vec<FeasibleRange>,
    pub laws: Vec<FeasibleLaw>,
    pub fastest: Vec<FastestFoot>,
    pub points: Vec<FootPoint>,
}

pub struct FeetRun {
    pub points: Vec<FootPoint>,
    pub simulated: usize,
    pub study: Option<FeetStudy>,
}

/// Simulates one foot.
pub fn foot_point(
    spec: &FeetSpec,
    design: &Design,
    contact: ContactScaling,
    leg_length_m: f64,
    axis: usize,
    factor: f64,
) -> Result<FootPoint, StudyError> {
    let mut d = design.clone();
    d.geometry.foot_semi_axes_m[axis] *= factor;
    let duration_s =
        spec.duration_at_design_size_s * (leg_length_m / design.geometry.leg_length_m).sqrt();
    let w = simulate_walk(
        &d,
        &WalkOptions {
            leg_length_m: Some(leg_length_m),
            mass_law: spec.mass_law,
            contact_scaling: contact,
            duration_s,
            record_trajectory: false,
            ..WalkOptions::default()
        },
    )?
    .report;
    let s = leg_length_m / design.geometry.leg_length_m;
    let r = d.geometry.foot_semi_axes_m.map(|a| a * s);
    Ok(FootPoint {
        design: design.name.clone(),
        contact,
        mass_law: spec.mass_law,
        leg_length_m,
        axis: AXES[axis].into(),
        factor,
        r_x_m: r[0],
        r_y_m: r[1],
        r_z_m: r[2],
        walks: w.walks,
        fall_reason: w.fall_reason,
        velocity_mps: w.velocity_mps,
        froude: w.froude,
        roll_pp_deg: w.roll_pp_deg,
        pitch_pp_deg: w.pitch_pp_deg,
        yaw_pp_deg: w.yaw_pp_deg,
    })
}

/// Runs the points of `shard` (in parallel), appending each to `points_file` when given
/// and skipping those already there.
pub fn run_feet(
    spec: &FeetSpec,
    shard: Shard,
    points_file: Option<&Path>,
    on_point: &(dyn Fn(&FootPoint, bool) + Sync),
) -> Result<FeetRun, StudyError> {
    spec.check()?;
    let (log, done) = open_log::<FootPoint>(points_file, &spec.header())?;
    let units: Vec<_> = spec
        .units()
        .into_iter()
        .enumerate()
        .filter(|(k, _)| shard.takes(*k))
        .map(|(_, u)| u)
        .collect();
    let simulated = std::sync::atomic::AtomicUsize::new(0);
    let points: Vec<FootPoint> = units
        .par_iter()
        .map(|&(c, d, l, axis, f)| {
            let design = &spec.designs[d];
            let key = foot_key(&design.name, c, l, AXES[axis], f);
            if let Some(p) = done.get(&key) {
                on_point(p, true);
                return Ok(p.clone());
            }
            let p = foot_point(spec, design, c, l, axis, f)?;
            append_to(log.as_ref(), &p)?;
            simulated.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            on_point(&p, false);
            Ok(p)
        })
        .collect::<Result<_, StudyError>>()?;
    let study = (shard == Shard::WHOLE).then(|| assemble_feet(spec, &points));
    if let (Some(path), true) = (points_file, shard == Shard::WHOLE) {
        finish_points(path, &spec.header(), &points)?;
    }
    Ok(FeetRun {
        points,
        simulated: simulated.into_inner(),
        study,
    })
}

/// Ranges, fits and fastest feet over a complete set of points.
pub fn assemble_feet(spec: &FeetSpec, points: &[FootPoint]) -> FeetStudy {
    let paper = super::paper::PaperTable3::bundled().ok();
    let mut ranges = Vec::new();
    let mut laws = Vec::new();
    let mut fastest = Vec::new();
    for &c in &spec.contacts {
        for design in &spec.designs {
            let of = |p: &&FootPoint| p.design == design.name && p.contact == c;
            for (ai, axis) in AXES.iter().enumerate() {
                let (mut xs, mut ys) = (Vec::new(), Vec::new());
                for &l in &spec.leg_lengths_m {
                    let mut walking: Vec<&FootPoint> = points
                        .iter()
                        .filter(of)
                        .filter(|p| p.leg_length_m == l && p.axis == *axis && p.walks)
                        .collect();
                    walking.sort_by(|a, b| a.factor.total_cmp(&b.factor));
                    let r = |p: &FootPoint| [p.r_x_m, p.r_y_m, p.r_z_m][ai];
                    for p in &walking {
                        xs.push(l);
                        ys.push(r(p));
                    }
                    ranges.push(FeasibleRange {
                        design: design.name.clone(),
                        contact: c,
                        leg_length_m: l,
                        axis: axis.to_string(),
                        walking_factors: walking.iter().map(|p| p.factor).collect(),
                        min_m: walking.first().map(|p| r(p)),
                        max_m: walking.last().map(|p| r(p)),
                    });
                }
                let distinct_sizes = {
                    let mut s = xs.clone();
                    s.dedup();
                    s.len()
                };
                laws.push(FeasibleLaw {
                    design: design.name.clone(),
                    contact: c,
                    axis: axis.to_string(),
                    law: if distinct_sizes >= 2 {
                        law("leg_length_m", "semi_axis_m", &xs, &ys)
                    } else {
                        None
                    },
                    paper: paper.as_ref().and_then(|p| {
                        p.feet
                            .iter()
                            .find(|f| f.design == design.name && f.axis == *axis)
                            .map(|f| [f.a, f.b, f.r2])
                    }),
                });
            }
            fastest.extend(fastest_feet(spec, points, design, c, paper.as_ref()));
        }
    }
    let mut pts = points.to_vec();
    pts.sort_by_key(|p| p.key());
    FeetStudy {
        leg_lengths_m: spec.leg_lengths_m.clone(),
        factors: spec.factors.clone(),
        mass_law: spec.mass_law,
        duration_at_design_size_s: spec.duration_at_design_size_s,
        ranges,
        laws,
        fastest,
        points: pts,
    }
}

/// The fastest walking foot of `design` at each size, beside the speed dynamic similarity
/// predicts from its 1× foot at the size nearest the design's own (and the paper's).
fn fastest_feet(
    spec: &FeetSpec,
    points: &[FootPoint],
    design: &Design,
    c: ContactScaling,
    paper: Option<&super::paper::PaperTable3>,
) -> Vec<FastestFoot> {
    let mut fastest = Vec::new();
    // Reference: the size nearest the design's own, with its 1× foot.
    let l0 = design.geometry.leg_length_m;
    let of = |p: &&FootPoint| p.design == design.name && p.contact == c;
    let Some(&l_ref) = spec
        .leg_lengths_m
        .iter()
        .min_by(|a, b| (*a / l0).ln().abs().total_cmp(&(*b / l0).ln().abs()))
    else {
        return Vec::new();
    };
    let v1x = |l: f64| {
        points
            .iter()
            .filter(of)
            .find(|p| p.leg_length_m == l && p.factor == 1.0 && p.walks)
            .map(|p| p.velocity_mps)
    };
    for &l in &spec.leg_lengths_m {
        let best = points
            .iter()
            .filter(of)
            .filter(|p| p.leg_length_m == l && p.walks)
            .max_by(|a, b| a.velocity_mps.total_cmp(&b.velocity_mps));
        if let Some(b) = best {
            let pred = v1x(l_ref).map(|v| v * (l / l_ref).sqrt());
            fastest.push(FastestFoot {
                design: design.name.clone(),
                contact: c,
                leg_length_m: l,
                axis: b.axis.clone(),
                factor: b.factor,
                velocity_mps: b.velocity_mps,
                velocity_1x_mps: v1x(l),
                reference_leg_length_m: l_ref,
                froude_prediction_mps: pred,
                excess_over_froude: pred.map(|p| b.velocity_mps / p - 1.0),
                paper_velocity_mps: paper.and_then(|p| {
                    p.fastest_foot
                        .iter()
                        .find(|f| f.design == design.name && (f.leg_length_m - l).abs() < 1e-9)
                        .map(|f| f.velocity_mps)
                }),
            });
        }
    }
    fastest
}
