//! The paper's simulated scaling study (Sec. V): one walker design scaled across leg
//! lengths under a mass law, each size simulated, and the gait's power laws fitted —
//! velocity against L (dynamic similarity predicts L^0.5) and peak hip torque against L
//! and against m·L (the paper finds τ ∝ m·L).
//!
//! Sizes run in parallel (rayon); each walk is deterministic, and results are collected
//! in input order, so the study is bit-for-bit reproducible whatever the thread count.

use rayon::prelude::*;
use serde::Serialize;

use crate::progress::Observer;
use crate::regression::{self, Method};
use crate::sim::{Design, SimError, WalkOptions, WalkReport, simulate_walk};

/// A fitted power law y = a·x^b of the study.
#[derive(Debug, Clone, Serialize)]
pub struct StudyLaw {
    pub x: &'static str,
    pub y: &'static str,
    pub a: f64,
    pub b: f64,
    pub b_ci: [f64; 2],
    pub r2: f64,
    pub n: usize,
}

/// The result of a scaling study.
#[derive(Debug, Clone, Serialize)]
pub struct ScalingStudy {
    pub design: String,
    /// Walks in the order of the requested leg lengths.
    pub walks: Vec<WalkReport>,
    /// v ∝ L^b over the sizes that walk (needs 3).
    pub velocity_law: Option<StudyLaw>,
    /// Peak hip torque ∝ L^b over the sizes that walk.
    pub torque_law: Option<StudyLaw>,
    /// Peak hip torque ∝ (m·L)^b over the sizes that walk (b = 1: τ ∝ m·L).
    pub torque_vs_mass_length: Option<StudyLaw>,
}

pub(crate) fn law(x: &'static str, y: &'static str, xs: &[f64], ys: &[f64]) -> Option<StudyLaw> {
    if xs.len() < 3 {
        return None;
    }
    let f = regression::fit_power_law(xs, ys, Method::Ols, 0.95).ok()?;
    Some(StudyLaw {
        x,
        y,
        a: f.a,
        b: f.b,
        b_ci: [f.b_ci.lower, f.b_ci.upper],
        r2: f.r2,
        n: f.n,
    })
}

/// Simulates `design` at every leg length in `leg_lengths_m` with `base` options (its
/// `leg_length_m` is replaced), ticking `progress` after each walk.
pub fn scaling_study(
    design: &Design,
    leg_lengths_m: &[f64],
    base: &WalkOptions,
    progress: &dyn Observer,
) -> Result<ScalingStudy, SimError> {
    let walks: Vec<WalkReport> = leg_lengths_m
        .par_iter()
        .map(|&l| {
            let opts = WalkOptions {
                leg_length_m: Some(l),
                record_trajectory: false,
                ..base.clone()
            };
            let r = simulate_walk(design, &opts).map(|w| w.report);
            progress.tick();
            r
        })
        .collect::<Result<_, _>>()?;
    let ok: Vec<&WalkReport> = walks.iter().filter(|w| w.walks).collect();
    let l: Vec<f64> = ok.iter().map(|w| w.leg_length_m).collect();
    let v: Vec<f64> = ok.iter().map(|w| w.velocity_mps).collect();
    let tau: Vec<f64> = ok.iter().map(|w| w.peak_torque_nm).collect();
    let ml: Vec<f64> = ok.iter().map(|w| w.mass_kg * w.leg_length_m).collect();
    Ok(ScalingStudy {
        design: walks.first().map(|w| w.design.clone()).unwrap_or_default(),
        velocity_law: law("leg_length_m", "velocity_mps", &l, &v),
        torque_law: law("leg_length_m", "peak_torque_nm", &l, &tau),
        torque_vs_mass_length: law("mass_times_leg_length_kg_m", "peak_torque_nm", &ml, &tau),
        walks,
    })
}
