//! The diagnosis: where the nominal simulation misses the trials, which candidate effect
//! explains the miss, its parameters with intervals, and how far the gap shrinks on
//! held-out conditions.
//!
//! Method. Every observation (trial × metric) gives a standardised residual
//! z = (simulated − measured)/sd, sd the trial's, or [`DiagnoseOptions::default_relative_sd`]
//! of the value where none is stated. The gap is the RMS of z (the weighted RMS of the
//! residuals, weights 1/sd²); χ² = Σz².
//!
//! Each candidate effect is simulated on every condition at [`DiagnoseOptions::grid_points`]
//! log-spaced magnitudes over its plausible range; per condition and metric the magnitude
//! dependence is a monotone cubic (PCHIP) in ln(magnitude) through those walks, so fitting,
//! leave-one-condition-out refits and profiles cost no further walks. The nominal model (the
//! effect off) is one more candidate value. The best candidates are refined with walks at
//! the optimum and either side of it, which become nodes of the interpolant.
//!
//! Ranking: held-out χ² per observation (each condition predicted by the fit to the others)
//! plus a BIC penalty ln(n)/n per fitted parameter. Significance: the likelihood-ratio
//! statistic χ²_nominal − χ²_fit against χ²₁ at α/K (K candidates, Bonferroni), and a
//! held-out gap below the nominal's. Interval: the profile Δχ² ≤ χ²₁(0.95)·max(1, χ²/dof).

use std::collections::HashMap;
use std::sync::Mutex;
use std::time::Instant;

use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

use super::error::GapError;
use super::library::{EffectDef, EffectLibrary, EffectSetting};
use super::simulate::{Condition, SimMetrics, resolve};
use super::trials::{Metric, TrialSet};
use crate::regression::{Method, fit_line};

/// z² charged to an observation whose simulated walk fell (a 10-sd miss).
pub const FELL_Z2: f64 = 100.0;
/// Points of the fine grid the interpolated χ² is minimised on.
const FINE_POINTS: usize = 1601;

#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// Candidate effects (empty: the whole library).
    pub effects: Vec<String>,
    /// Magnitudes simulated per candidate over its plausible range.
    pub grid_points: usize,
    /// Relative sd assumed for a measurement that states none.
    pub default_relative_sd: f64,
    /// Family-wise false-alarm rate of the effect tests.
    pub alpha: f64,
    /// Candidates refined with extra walks (the best by the coarse score, and the next ones
    /// within 2.5 times its score).
    pub refine_top: usize,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            effects: Vec::new(),
            grid_points: 8,
            default_relative_sd: 0.10,
            alpha: 0.001,
            refine_top: 3,
        }
    }
}

/// Walks shared between diagnoses of trials over the same conditions (the benchmark): key =
/// (condition, effect and its nondimensional values).
#[derive(Default)]
pub struct SimCache {
    map: Mutex<HashMap<(usize, String), SimMetrics>>,
    pub walks: std::sync::atomic::AtomicUsize,
}

fn key(e: Option<&EffectSetting>) -> String {
    match e {
        None => "nominal".into(),
        Some(s) => {
            let mut k = s.effect.clone();
            for v in &s.nondimensional {
                k.push_str(&format!(":{:016x}", v.to_bits()));
            }
            k
        }
    }
}

impl SimCache {
    /// Metrics of `effect` on every condition, walking only what the cache lacks.
    pub fn get(
        &self,
        conditions: &[Condition],
        lib: &EffectLibrary,
        effect: Option<&EffectSetting>,
        progress: &(dyn Fn() + Sync),
    ) -> Result<Vec<SimMetrics>, GapError> {
        self.get_many(conditions, lib, &[effect.cloned()], progress)
            .map(|mut v| v.remove(0))
    }

    /// Metrics of several effect settings on every condition, in parallel.
    pub fn get_many(
        &self,
        conditions: &[Condition],
        lib: &EffectLibrary,
        effects: &[Option<EffectSetting>],
        progress: &(dyn Fn() + Sync),
    ) -> Result<Vec<Vec<SimMetrics>>, GapError> {
        let keys: Vec<String> = effects.iter().map(|e| key(e.as_ref())).collect();
        let mut jobs = Vec::new();
        {
            let map = self
                .map
                .lock()
                .map_err(|_| GapError::Invalid("cache poisoned".into()))?;
            for (k, e) in keys.iter().zip(effects) {
                for i in 0..conditions.len() {
                    if !map.contains_key(&(i, k.clone())) {
                        jobs.push((i, e.clone()));
                    }
                }
            }
        }
        let done = super::simulate::simulate_jobs(&jobs, conditions, lib, progress)?;
        self.walks
            .fetch_add(jobs.len(), std::sync::atomic::Ordering::Relaxed);
        let mut map = self
            .map
            .lock()
            .map_err(|_| GapError::Invalid("cache poisoned".into()))?;
        for ((i, e), m) in jobs.iter().zip(done) {
            map.insert((*i, key(e.as_ref())), m);
        }
        let mut out = Vec::new();
        for k in &keys {
            let mut v = Vec::with_capacity(conditions.len());
            for i in 0..conditions.len() {
                v.push(
                    *map.get(&(i, k.clone()))
                        .ok_or_else(|| GapError::Invalid("cache miss after simulation".into()))?,
                );
            }
            out.push(v);
        }
        Ok(out)
    }
}

/// One observation: a measured metric of a trial with its sd.
#[derive(Clone, Copy, Debug)]
pub struct Observation {
    pub trial: usize,
    pub metric: Metric,
    pub value: f64,
    pub sd: f64,
    pub sd_assumed: bool,
}

impl Observation {
    fn z2(&self, simulated: f64) -> f64 {
        if simulated.is_finite() {
            let z = (simulated - self.value) / self.sd;
            z * z
        } else {
            FELL_Z2
        }
    }
}

/// A residual of the nominal (and, once a best effect is found, the corrected) simulation.
#[derive(Clone, Debug, Serialize)]
pub struct Residual {
    pub trial: usize,
    pub label: String,
    pub design: String,
    pub leg_length_m: f64,
    pub frequency_hz: f64,
    pub metric: Metric,
    pub measured: f64,
    pub sd: f64,
    pub sd_assumed: bool,
    pub simulated: Option<f64>,
    pub z: Option<f64>,
    /// (simulated − measured)/|measured|.
    pub relative: Option<f64>,
    pub simulated_after: Option<f64>,
    pub z_after: Option<f64>,
}

/// A linear trend of the relative residual against ln(x).
#[derive(Clone, Debug, Serialize)]
pub struct Trend {
    /// Change of the relative residual per e-fold of x.
    pub slope: f64,
    pub se: f64,
    pub p_value: f64,
}

/// How one metric carries the gap.
#[derive(Clone, Debug, Serialize)]
pub struct MetricGap {
    pub metric: Metric,
    pub n: usize,
    pub rms_z: f64,
    pub mean_relative_pct: f64,
    pub chi2: f64,
    pub p_value: f64,
    /// χ² beyond noise at level α.
    pub significant: bool,
    pub leg_lengths_m: [f64; 2],
    pub trend_with_leg_length: Option<Trend>,
    pub trend_with_frequency: Option<Trend>,
    pub rms_z_after: Option<f64>,
    /// The gap per design and size.
    pub regimes: Vec<RegimeGap>,
    pub statement: String,
}

/// One metric's gap on the trials of one design at one size.
#[derive(Clone, Debug, Serialize)]
pub struct RegimeGap {
    pub design: String,
    pub leg_length_m: f64,
    pub n: usize,
    pub rms_z: f64,
    pub mean_relative_pct: f64,
    pub p_value: f64,
    pub significant: bool,
}

/// A candidate's fit.
#[derive(Clone, Debug, Serialize)]
pub struct RankedEffect {
    pub effect: String,
    /// Fitted parameters in SI at the first trial's design at 1× (others at defaults).
    pub params: std::collections::BTreeMap<String, f64>,
    /// The magnitude in its natural unit (see `survey gap effects`), None: the fit prefers
    /// the nominal model.
    pub magnitude_nondimensional: Option<f64>,
    /// Held-out gap (RMS z, each condition predicted from the fit to the others).
    pub gap_after: f64,
    pub shrink_pct: f64,
    /// Held-out χ²/n plus the parameter penalty; lower is better.
    pub score: f64,
    pub gap_after_in_sample: f64,
    /// χ²_nominal − χ²_fit, and its p-value against χ²₁.
    pub lr: f64,
    pub p_value: f64,
    pub significant: bool,
    pub refined: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct BestEffect {
    pub effect: String,
    pub params: std::collections::BTreeMap<String, f64>,
    /// 95 % profile interval of the magnitude parameter, in SI.
    pub params_ci: std::collections::BTreeMap<String, [f64; 2]>,
    pub magnitude_nondimensional: f64,
    pub magnitude_ci_nondimensional: [f64; 2],
    pub gap_after: f64,
    pub shrink_pct: f64,
    pub gap_after_in_sample: f64,
    /// The interval reaches an end of the plausible range (open there).
    pub ci_at_range_edge: bool,
}

/// From which metrics an effect shows, and the smallest magnitude these trials detect.
#[derive(Clone, Debug, Serialize)]
pub struct Identifiability {
    pub effect: String,
    pub parameter: String,
    pub unit: String,
    /// Magnitude (SI, first design at 1×) at which the likelihood-ratio test detects the
    /// effect with 90 % power given these trials' sds; None: not within the range.
    pub detection_threshold: Option<f64>,
    /// Magnitude beyond which the effect is also told from every other candidate with
    /// 90 % probability (its best mimic's χ² excess ≥ (2·z₀.₉)²).
    pub identification_threshold: Option<f64>,
    /// The closest mimic at the identification threshold.
    pub closest_mimic: Option<String>,
    /// Metrics carrying ≥ 10 % of the detection statistic at the threshold (or at the
    /// range's end).
    pub identifiable_from: Vec<Metric>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub trials: String,
    pub n_trials: usize,
    pub n_observations: usize,
    pub gap_before: f64,
    pub chi2_before: f64,
    pub p_value_before: f64,
    /// The nominal model's misfit is consistent with measurement noise.
    pub within_noise: bool,
    pub summary: String,
    #[serde(rename = "where")]
    pub where_: Vec<MetricGap>,
    pub ranking: Vec<RankedEffect>,
    pub best: Option<BestEffect>,
    pub verdict: String,
    pub identifiability: Vec<Identifiability>,
    pub notes: Vec<String>,
    pub residuals: Vec<Residual>,
    pub walks_evaluated: usize,
}

/// Wall-clock breakdown (not part of the deterministic result).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timing {
    pub nominal_s: f64,
    pub grid_s: f64,
    pub refine_s: f64,
    pub fit_s: f64,
    pub walks: usize,
}

/// Fritsch–Carlson monotone cubic through (x, y), NaN-aware: NaN where a bracketing node is
/// NaN. Hand-written: the interpolation crates do not keep monotonicity or handle the NaN
/// of a fallen walk, and this is twenty lines.
fn pchip(x: &[f64], y: &[f64], t: f64) -> f64 {
    let n = x.len();
    if n == 1 {
        return y[0];
    }
    let k = x.partition_point(|v| *v <= t).clamp(1, n - 1) - 1;
    let (y0, y1) = (y[k], y[k + 1]);
    if !(y0.is_finite() && y1.is_finite()) {
        return f64::NAN;
    }
    let h = x[k + 1] - x[k];
    let d = |i: usize| -> f64 { (y[i + 1] - y[i]) / (x[i + 1] - x[i]) };
    let slope = |i: usize| -> f64 {
        let left = if i > 0 { d(i - 1) } else { f64::NAN };
        let right = if i + 1 < n { d(i) } else { f64::NAN };
        match (left.is_finite(), right.is_finite()) {
            (true, true) => {
                if left * right <= 0.0 {
                    0.0
                } else {
                    let (h0, h1) = (x[i] - x[i - 1], x[i + 1] - x[i]);
                    let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
                    (w1 + w2) / (w1 / left + w2 / right)
                }
            }
            (true, false) => left,
            (false, true) => right,
            _ => 0.0,
        }
    };
    let (m0, m1) = (slope(k), slope(k + 1));
    let s = ((t - x[k]) / h).clamp(0.0, 1.0);
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * y0
        + (s3 - 2.0 * s2 + s) * h * m0
        + (-2.0 * s3 + 3.0 * s2) * y1
        + (s3 - s2) * h * m1
}

/// A candidate's walks: the metrics at each simulated magnitude (u = ln magnitude), sorted.
struct Curve {
    u: Vec<f64>,
    /// The walks' metric values, [condition][metric index][node], kept beside `u` so that
    /// evaluating the interpolant (millions of times in profiles and thresholds) allocates
    /// nothing.
    series: Vec<Vec<Vec<f64>>>,
}

impl Curve {
    /// `sims` is [node][condition].
    fn new(u: Vec<f64>, sims: Vec<Vec<SimMetrics>>) -> Curve {
        let n_cond = sims.first().map(Vec::len).unwrap_or(0);
        let series = (0..n_cond)
            .map(|c| {
                Metric::ALL
                    .iter()
                    .map(|m| sims.iter().map(|s| s[c].get(*m)).collect())
                    .collect()
            })
            .collect();
        Curve { u, series }
    }
    fn insert(&mut self, u: f64, sims: Vec<SimMetrics>) {
        if self.u.iter().any(|x| (x - u).abs() < 1e-12) {
            return;
        }
        let k = self.u.partition_point(|x| *x < u);
        self.u.insert(k, u);
        for (per_metric, s) in self.series.iter_mut().zip(&sims) {
            for m in Metric::ALL {
                per_metric[m.index()].insert(k, s.get(m));
            }
        }
    }
    fn value(&self, cond: usize, metric: Metric, u: f64) -> f64 {
        pchip(&self.u, &self.series[cond][metric.index()], u)
    }
}

/// The per-condition χ² of a candidate on a fine grid of u, plus the nominal (off) column.
struct Profile {
    u: Vec<f64>,
    /// [condition][grid point]; the last column is the nominal.
    chi2: Vec<Vec<f64>>,
}

impl Profile {
    fn total(&self, j: usize) -> f64 {
        self.chi2.iter().map(|c| c[j]).sum()
    }
    fn off(&self) -> usize {
        self.u.len()
    }
    /// In-sample optimum over the grid and the nominal.
    fn best(&self) -> (usize, f64) {
        let mut best = (self.off(), self.total(self.off()));
        for j in 0..self.u.len() {
            let t = self.total(j);
            if t < best.1 {
                best = (j, t);
            }
        }
        best
    }
    /// Leave-one-condition-out χ²: each condition at the optimum of the others.
    fn held_out(&self) -> f64 {
        let npts = self.u.len() + 1;
        let totals: Vec<f64> = (0..npts).map(|j| self.total(j)).collect();
        let mut cv = 0.0;
        for c in &self.chi2 {
            let mut bj = self.off();
            let mut bv = totals[bj] - c[bj];
            for j in 0..self.u.len() {
                let v = totals[j] - c[j];
                if v < bv {
                    bv = v;
                    bj = j;
                }
            }
            cv += c[bj];
        }
        cv
    }
}

fn build_profile(
    curve: &Curve,
    obs: &[Observation],
    nominal: &[SimMetrics],
    n_cond: usize,
    u_range: (f64, f64),
) -> Profile {
    let u: Vec<f64> = (0..FINE_POINTS)
        .map(|j| u_range.0 + (u_range.1 - u_range.0) * j as f64 / (FINE_POINTS - 1) as f64)
        .collect();
    let mut chi2 = vec![vec![0.0; u.len() + 1]; n_cond];
    for o in obs {
        let row = &mut chi2[o.trial];
        for (j, uj) in u.iter().enumerate() {
            row[j] += o.z2(curve.value(o.trial, o.metric, *uj));
        }
        row[u.len()] += o.z2(nominal[o.trial].get(o.metric));
    }
    Profile { u, chi2 }
}

/// Trials whose `trajectory` file is given get the metrics they lack measured from it, by
/// the code that measures the simulator's walks (`sim::report_from_trajectory`).
fn fill_from_trajectories(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
) -> Result<TrialSet, GapError> {
    let mut out = set.clone();
    for (t, c) in out.trials.iter_mut().zip(conditions) {
        let Some(rel) = &t.trajectory else { continue };
        let path = set.base_dir.join(rel);
        let at = |message: String| GapError::Trials {
            path: set.origin.clone(),
            line: t.line,
            column: 0,
            message,
        };
        let samples = crate::sim::read_trajectory_csv(&path)
            .map_err(|e| at(format!("trajectory {}: {e}", path.display())))?;
        let d = c.design_with(lib, None)?;
        let report =
            crate::sim::report_from_trajectory(&d, &crate::sim::WalkOptions::default(), &samples)
                .map_err(|e| at(format!("trajectory {}: {e}", path.display())))?;
        for m in Metric::SIMULATED {
            let v = m.of_report(&report);
            if t.measured(m).is_none() && v.is_finite() {
                t.measured[m.index()] = Some(super::trials::Measurement { value: v, sd: None });
            }
        }
    }
    Ok(out)
}

/// Observations of the trials: every measured metric a walk simulates.
pub fn observations(set: &TrialSet, default_relative_sd: f64) -> (Vec<Observation>, Vec<String>) {
    let mut obs = Vec::new();
    let mut notes = Vec::new();
    let mut min_torque = 0;
    for (i, t) in set.trials.iter().enumerate() {
        for m in Metric::ALL {
            let Some(meas) = t.measured(m) else { continue };
            if m == Metric::MinTorqueNm {
                min_torque += 1;
                continue;
            }
            let (sd, assumed) = match meas.sd {
                Some(sd) => (sd, false),
                None => ((default_relative_sd * meas.value.abs()).max(1e-12), true),
            };
            obs.push(Observation {
                trial: i,
                metric: m,
                value: meas.value,
                sd,
                sd_assumed: assumed,
            });
        }
    }
    if min_torque > 0 {
        notes.push(format!(
            "{min_torque} min_torque_nm measurement(s) not used: the minimum walking torque needs \
             a bisection of walks per candidate magnitude (compare them with `survey sim min-torque`)"
        ));
    }
    (obs, notes)
}

fn chi2_sf(x: f64, df: f64) -> f64 {
    match ChiSquared::new(df) {
        Ok(d) if x > 0.0 => d.sf(x),
        _ => 1.0,
    }
}

fn normal_quantile(p: f64) -> f64 {
    Normal::new(0.0, 1.0)
        .map(|n| n.inverse_cdf(p))
        .unwrap_or(f64::NAN)
}

/// The nondimensional magnitude range and off value of an effect for the first design.
fn magnitude_domain(def: &EffectDef, cond: &Condition) -> (f64, f64, f64) {
    let p = def.magnitude();
    let off = p.off_nondimensional(&cond.design, &def.name);
    (p.range[0].ln(), p.range[1].ln(), off)
}

/// Grid of simulated magnitudes (u = ln nondimensional magnitude).
fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
        .collect()
}

/// Diagnoses `set` against the simulator.
pub fn diagnose(
    set: &TrialSet,
    lib: &EffectLibrary,
    opts: &DiagnoseOptions,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<(Diagnosis, Timing), GapError> {
    let conditions = resolve(set)?;
    let cache = SimCache::default();
    diagnose_conditions(set, &conditions, lib, opts, &cache, progress)
}

/// [`diagnose`] on resolved conditions, sharing walks through `cache`.
pub fn diagnose_conditions(
    set: &TrialSet,
    conditions: &[Condition],
    lib: &EffectLibrary,
    opts: &DiagnoseOptions,
    cache: &SimCache,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<(Diagnosis, Timing), GapError> {
    if !(opts.default_relative_sd > 0.0 && opts.default_relative_sd.is_finite()) {
        return Err(GapError::Invalid(
            "the default relative sd must be finite and > 0".into(),
        ));
    }
    if !(opts.alpha > 0.0 && opts.alpha < 1.0) {
        return Err(GapError::Invalid("alpha must be in (0, 1)".into()));
    }
    if !(2..=64).contains(&opts.grid_points) {
        return Err(GapError::Invalid("grid points must be in [2, 64]".into()));
    }
    let candidates = lib.subset(&opts.effects)?;
    let filled = fill_from_trajectories(set, conditions, lib)?;
    let set = &filled;
    let (obs, mut notes) = observations(set, opts.default_relative_sd);
    if obs.is_empty() {
        return Err(GapError::File {
            path: set.origin.clone(),
            message: "no trial has a measured metric the simulator computes (velocity_mps, \
                      step_frequency_hz, roll/pitch/yaw_pp_deg, peak_torque_nm, cot)"
                .into(),
        });
    }
    let walks0 = cache.walks.load(std::sync::atomic::Ordering::Relaxed);
    let mut timing = Timing::default();
    let n = obs.len() as f64;
    let nc = conditions.len();
    let first = &conditions[0];

    // Nominal.
    let t0 = Instant::now();
    progress("nominal model");
    let nominal = cache.get(conditions, lib, None, &|| progress(""))?;
    timing.nominal_s = t0.elapsed().as_secs_f64();
    let chi2_before: f64 = obs
        .iter()
        .map(|o| o.z2(nominal[o.trial].get(o.metric)))
        .sum();
    let gap_before = (chi2_before / n).sqrt();
    let p_value_before = chi2_sf(chi2_before, n);
    let within_noise = p_value_before >= opts.alpha;

    // Candidate grids, all walks in one parallel batch.
    let t1 = Instant::now();
    progress("candidate grids");
    let mut settings = Vec::new();
    let mut domains = Vec::new();
    for def in &candidates {
        let (lo, hi, off) = magnitude_domain(def, first);
        domains.push((lo, hi, off));
        for u in grid(lo, hi, opts.grid_points) {
            settings.push(Some(def.setting(u.exp())));
        }
    }
    let grid_sims = cache.get_many(conditions, lib, &settings, &|| progress(""))?;
    let mut curves: Vec<Curve> = Vec::new();
    let mut it = grid_sims.into_iter();
    for (lo, hi, off) in &domains {
        let u = grid(*lo, *hi, opts.grid_points);
        let sims: Vec<Vec<SimMetrics>> = (0..u.len()).filter_map(|_| it.next()).collect();
        let mut curve = Curve::new(u, sims);
        // An off value inside the range (the design's own μ) is a walk already made: the
        // nominal one, a node of the curve.
        if *off > 0.0 && off.is_finite() && (*lo..=*hi).contains(&off.ln()) {
            curve.insert(off.ln(), nominal.clone());
        }
        curves.push(curve);
    }
    timing.grid_s = t1.elapsed().as_secs_f64();

    // Coarse fits.
    let t2 = Instant::now();
    let k = candidates.len() as f64;
    let lr_critical_p = opts.alpha / k;
    let mut profiles: Vec<Profile> = curves
        .iter()
        .zip(&domains)
        .map(|(c, d)| build_profile(c, &obs, &nominal, nc, (d.0, d.1)))
        .collect();
    let penalty = n.ln() / n;
    let score_of = |p: &Profile| p.held_out() / n + penalty;
    timing.fit_s += t2.elapsed().as_secs_f64();

    // Refine the best few: walks at the optimum and at its interval's ends.
    let t3 = Instant::now();
    let mut order: Vec<usize> = (0..candidates.len()).collect();
    let coarse: Vec<f64> = profiles.iter().map(score_of).collect();
    order.sort_by(|a, b| coarse[*a].total_cmp(&coarse[*b]));
    let mut refined = vec![false; candidates.len()];
    for (rank, &ci) in order.iter().enumerate() {
        if rank >= opts.refine_top.max(1) {
            break;
        }
        if rank > 0 && coarse[ci] > coarse[order[0]] * 2.5 {
            break;
        }
        // Surrogate refinement: walk at the interpolant's optimum and halfway to the nodes
        // either side, until the optimum sits on a walked node (the interpolant is exact
        // there) or the rounds run out. The best candidate gets more rounds.
        let rounds = if rank == 0 { 5 } else { 3 };
        for _round in 0..rounds {
            let prof = &profiles[ci];
            let (j, _) = prof.best();
            if j == prof.off() {
                break;
            }
            let u_hat = prof.u[j];
            let nodes = &curves[ci].u;
            let tol = 2.0 * (domains[ci].1 - domains[ci].0) / (FINE_POINTS - 1) as f64;
            if nodes.iter().any(|x| (x - u_hat).abs() <= tol) && refined[ci] {
                break;
            }
            let k = nodes.partition_point(|x| *x < u_hat);
            let mut pts = vec![u_hat];
            if k > 0 {
                pts.push(0.5 * (u_hat + nodes[k - 1]));
            }
            if k < nodes.len() {
                pts.push(0.5 * (u_hat + nodes[k]));
            }
            let new: Vec<f64> = pts
                .into_iter()
                .map(|u| u.clamp(domains[ci].0, domains[ci].1))
                .filter(|u| !curves[ci].u.iter().any(|x| (x - u).abs() < tol))
                .collect();
            if new.is_empty() {
                break;
            }
            progress(&format!("refining {}", candidates[ci].name));
            let sets: Vec<Option<EffectSetting>> = new
                .iter()
                .map(|u| Some(candidates[ci].setting(u.exp())))
                .collect();
            let sims = cache.get_many(conditions, lib, &sets, &|| progress(""))?;
            for (u, s) in new.into_iter().zip(sims) {
                curves[ci].insert(u, s);
            }
            profiles[ci] = build_profile(
                &curves[ci],
                &obs,
                &nominal,
                nc,
                (domains[ci].0, domains[ci].1),
            );
            refined[ci] = true;
        }
    }
    timing.refine_s = t3.elapsed().as_secs_f64();

    // Ranking.
    let t4 = Instant::now();
    let mut ranking = Vec::new();
    for (ci, def) in candidates.iter().enumerate() {
        let prof = &profiles[ci];
        let (j, chi_in) = prof.best();
        let cv = prof.held_out();
        let lr = (chi2_before - chi_in).max(0.0);
        let p_value = chi2_sf(lr, 1.0);
        let gap_after = (cv / n).sqrt();
        let mag = (j != prof.off()).then(|| prof.u[j].exp());
        let setting = def.setting(mag.unwrap_or(def.magnitude().default));
        let mut params = def.si_values(&first.design, &setting.nondimensional);
        if mag.is_none()
            && let Some(p) = def.parameters.first()
        {
            params.insert(
                p.name.clone(),
                p.off_nondimensional(&first.design, &def.name) * p.scale.value(&first.design),
            );
        }
        ranking.push(RankedEffect {
            effect: def.name.clone(),
            params,
            magnitude_nondimensional: mag,
            gap_after,
            shrink_pct: 100.0 * (1.0 - gap_after / gap_before),
            score: cv / n + penalty,
            gap_after_in_sample: (chi_in / n).sqrt(),
            lr,
            p_value,
            significant: p_value < lr_critical_p && cv < chi2_before && mag.is_some(),
            refined: refined[ci],
        });
    }
    ranking.sort_by(|a, b| a.score.total_cmp(&b.score));

    // A call must also be material: the corrected model fits within noise, or the gap at
    // least halves. A significant but small improvement (a real gap that stays real) is
    // reported in the ranking and the verdict, not called.
    let material = |r: &RankedEffect| {
        let chi_in = r.gap_after_in_sample.powi(2) * n;
        chi2_sf(chi_in, (n - 1.0).max(1.0)) >= opts.alpha || r.shrink_pct >= 50.0
    };
    let best_idx = ranking.iter().position(|r| r.significant && material(r));
    let partial = ranking
        .iter()
        .find(|r| r.significant && !material(r))
        .map(|r| (r.effect.clone(), r.shrink_pct, r.gap_after));
    let mut best = None;
    let mut after: Option<(usize, f64)> = None;
    if let Some(bi) = best_idx {
        let r = &ranking[bi];
        let ci = candidates
            .iter()
            .position(|d| d.name == r.effect)
            .unwrap_or(0);
        let prof = &profiles[ci];
        let (j, chi_min) = prof.best();
        let def = candidates[ci];
        let (lo_u, hi_u) = profile_interval(prof, j, chi_min, n).unwrap_or((prof.u[j], prof.u[j]));
        let scale = def.magnitude().scale.value(&first.design);
        let mag = prof.u[j].exp();
        let mut params_ci = std::collections::BTreeMap::new();
        params_ci.insert(
            def.magnitude().name.clone(),
            [lo_u.exp() * scale, hi_u.exp() * scale],
        );
        let edge = (lo_u - domains[ci].0).abs() < 1e-9 || (hi_u - domains[ci].1).abs() < 1e-9;
        best = Some(BestEffect {
            effect: r.effect.clone(),
            params: r.params.clone(),
            params_ci,
            magnitude_nondimensional: mag,
            magnitude_ci_nondimensional: [lo_u.exp(), hi_u.exp()],
            gap_after: r.gap_after,
            shrink_pct: r.shrink_pct,
            gap_after_in_sample: r.gap_after_in_sample,
            ci_at_range_edge: edge,
        });
        after = Some((ci, prof.u[j]));
    }

    // Residuals before/after.
    let mut residuals = Vec::new();
    for o in &obs {
        let c = &conditions[o.trial];
        let t = &set.trials[o.trial];
        let sim = nominal[o.trial].get(o.metric);
        let (sa, za) = match after {
            Some((ci, u)) => {
                let v = curves[ci].value(o.trial, o.metric, u);
                (
                    v.is_finite().then_some(v),
                    v.is_finite().then(|| (v - o.value) / o.sd),
                )
            }
            None => (None, None),
        };
        residuals.push(Residual {
            trial: o.trial,
            label: if t.label.is_empty() {
                format!("line {}", t.line)
            } else {
                t.label.clone()
            },
            design: t.design.clone(),
            leg_length_m: c.leg_length_m,
            frequency_hz: c.drive_frequency_hz()?,
            metric: o.metric,
            measured: o.value,
            sd: o.sd,
            sd_assumed: o.sd_assumed,
            simulated: sim.is_finite().then_some(sim),
            z: sim.is_finite().then(|| (sim - o.value) / o.sd),
            relative: (sim.is_finite() && o.value != 0.0).then(|| (sim - o.value) / o.value.abs()),
            simulated_after: sa,
            z_after: za,
        });
    }
    let where_ = metric_gaps(&residuals, opts.alpha);
    let summary = summarize(&where_, within_noise);
    let identifiability = candidates
        .iter()
        .enumerate()
        .map(|(ci, def)| {
            identifiability(
                ci,
                def,
                &candidates,
                &curves,
                &domains,
                &obs,
                &nominal,
                first,
                lr_critical_p,
            )
        })
        .collect();
    let mut verdict = verdict(within_noise, &best, &ranking, gap_before, lr_critical_p);
    if best.is_none()
        && let Some((e, shrink, after)) = partial
    {
        verdict = format!(
            "the gap (RMS z = {gap_before:.2}) is real and no candidate explains it: the best, \
             {e}, lowers it significantly but only by {shrink:.0} % (held-out RMS z {after:.2}, \
             still beyond noise) — a model error or an effect outside the library carries the rest"
        );
    }
    if obs.iter().any(|o| o.sd_assumed) {
        notes.push(format!(
            "{} of {} measurements state no sd: {} % of the value assumed",
            obs.iter().filter(|o| o.sd_assumed).count(),
            obs.len(),
            opts.default_relative_sd * 100.0
        ));
    }
    timing.fit_s += t4.elapsed().as_secs_f64();
    let walks = cache.walks.load(std::sync::atomic::Ordering::Relaxed) - walks0;
    timing.walks = walks;
    Ok((
        Diagnosis {
            trials: set.origin.clone(),
            n_trials: set.trials.len(),
            n_observations: obs.len(),
            gap_before,
            chi2_before,
            p_value_before,
            within_noise,
            summary,
            where_,
            ranking,
            best,
            verdict,
            identifiability,
            notes,
            residuals,
            walks_evaluated: walks,
        },
        timing,
    ))
}

/// The 95 % profile interval [u_lo, u_hi] around grid point `j`: Δχ² ≤ χ²₁(0.95)·s²,
/// s² = max(1, χ²_min/(n − 1)) (an overdispersed fit widens its interval).
fn profile_interval(p: &Profile, j: usize, chi_min: f64, n: f64) -> Option<(f64, f64)> {
    if j >= p.u.len() {
        return None;
    }
    let s2 = (chi_min / (n - 1.0).max(1.0)).max(1.0);
    let limit = chi_min + 3.841_458_820_694_124 * s2;
    let mut lo = j;
    while lo > 0 && p.total(lo - 1) <= limit {
        lo -= 1;
    }
    let mut hi = j;
    while hi + 1 < p.u.len() && p.total(hi + 1) <= limit {
        hi += 1;
    }
    Some((p.u[lo], p.u[hi]))
}

fn trend(x: &[f64], y: &[f64]) -> Option<Trend> {
    let distinct = {
        let mut v: Vec<f64> = x.to_vec();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        v.len()
    };
    if x.len() < 4 || distinct < 2 {
        return None;
    }
    let f = fit_line(x, y, Method::Ols, 0.95).ok()?;
    f.b.is_finite().then_some(Trend {
        slope: f.b,
        se: f.se_b,
        p_value: f.p_b_equals_0,
    })
}

fn metric_gaps(res: &[Residual], alpha: f64) -> Vec<MetricGap> {
    let mut out = Vec::new();
    for m in Metric::ALL {
        let rs: Vec<&Residual> = res.iter().filter(|r| r.metric == m).collect();
        if rs.is_empty() {
            continue;
        }
        let z2: Vec<f64> = rs
            .iter()
            .map(|r| r.z.map(|z| z * z).unwrap_or(FELL_Z2))
            .collect();
        let chi2: f64 = z2.iter().sum();
        let nn = rs.len() as f64;
        let p_value = chi2_sf(chi2, nn);
        let rel: Vec<f64> = rs.iter().filter_map(|r| r.relative).collect();
        let mean_rel = if rel.is_empty() {
            f64::NAN
        } else {
            rel.iter().sum::<f64>() / rel.len() as f64
        };
        let ls: Vec<f64> = rs.iter().map(|r| r.leg_length_m).collect();
        let (lmin, lmax) = ls
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        let with_rel: Vec<&&Residual> = rs.iter().filter(|r| r.relative.is_some()).collect();
        let y: Vec<f64> = with_rel.iter().filter_map(|r| r.relative).collect();
        let xl: Vec<f64> = with_rel.iter().map(|r| r.leg_length_m.ln()).collect();
        let xf: Vec<f64> = with_rel.iter().map(|r| r.frequency_hz.ln()).collect();
        let after: Vec<f64> = rs.iter().filter_map(|r| r.z_after).collect();
        let rms_after = (after.len() == rs.len() && !after.is_empty())
            .then(|| (after.iter().map(|z| z * z).sum::<f64>() / nn).sqrt());
        let significant = p_value < alpha;
        let mut keys: Vec<(String, String)> = rs
            .iter()
            .map(|r| (r.design.clone(), sig3(r.leg_length_m)))
            .collect();
        keys.sort();
        keys.dedup();
        let regimes: Vec<RegimeGap> = keys
            .iter()
            .map(|(dn, lk)| {
                let g: Vec<&&Residual> = rs
                    .iter()
                    .filter(|r| &r.design == dn && &sig3(r.leg_length_m) == lk)
                    .collect();
                let c2: f64 = g
                    .iter()
                    .map(|r| r.z.map(|z| z * z).unwrap_or(FELL_Z2))
                    .sum();
                let rel: Vec<f64> = g.iter().filter_map(|r| r.relative).collect();
                let p = chi2_sf(c2, g.len() as f64);
                RegimeGap {
                    design: dn.clone(),
                    leg_length_m: g[0].leg_length_m,
                    n: g.len(),
                    rms_z: (c2 / g.len() as f64).sqrt(),
                    mean_relative_pct: 100.0 * rel.iter().sum::<f64>() / rel.len().max(1) as f64,
                    p_value: p,
                    significant: p < alpha,
                }
            })
            .collect();
        let place = if (lmax / lmin - 1.0).abs() < 0.05 {
            format!("at L ≈ {} m", sig3(lmin))
        } else {
            format!("over L = {}–{} m", sig3(lmin), sig3(lmax))
        };
        let hot: Vec<&RegimeGap> = regimes.iter().filter(|g| g.significant).collect();
        let same_sign = (hot.iter().all(|g| g.mean_relative_pct < 0.0)
            || hot.iter().all(|g| g.mean_relative_pct >= 0.0))
            && regimes.iter().all(|g| g.design == regimes[0].design);
        let statement = if significant
            && regimes.len() > 1
            && !hot.is_empty()
            && !(hot.len() == regimes.len() && same_sign)
        {
            // Say where: the regimes that carry it.
            let parts: Vec<String> = hot
                .iter()
                .map(|g| {
                    format!(
                        "{}-predicted by {:.0} % at L ≈ {} m ({})",
                        if g.mean_relative_pct < 0.0 {
                            "under"
                        } else {
                            "over"
                        },
                        g.mean_relative_pct.abs(),
                        sig3(g.leg_length_m),
                        g.design
                    )
                })
                .collect();
            let rest = if hot.len() < regimes.len() {
                ", within noise elsewhere"
            } else {
                ""
            };
            format!("{} {}{rest}", m.words(), parts.join(" and "))
        } else if significant && mean_rel.is_finite() {
            format!(
                "{} {}-predicted by {:.0} % {}",
                m.words(),
                if mean_rel < 0.0 { "under" } else { "over" },
                mean_rel.abs() * 100.0,
                place
            )
        } else if significant {
            format!("{} missed {} (the simulation falls)", m.words(), place)
        } else {
            format!("{} within noise", m.words())
        };
        out.push(MetricGap {
            metric: m,
            n: rs.len(),
            rms_z: (chi2 / nn).sqrt(),
            mean_relative_pct: mean_rel * 100.0,
            chi2,
            p_value,
            significant,
            leg_lengths_m: [lmin, lmax],
            trend_with_leg_length: trend(&xl, &y),
            trend_with_frequency: trend(&xf, &y),
            rms_z_after: rms_after,
            regimes,
            statement,
        });
    }
    out
}

/// Three significant digits, no trailing zeros.
fn sig3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn summarize(gaps: &[MetricGap], within_noise: bool) -> String {
    let mut parts: Vec<String> = gaps
        .iter()
        .filter(|g| g.significant)
        .map(|g| {
            let mut s = g.statement.clone();
            for (t, what) in [
                (&g.trend_with_leg_length, "leg length"),
                (&g.trend_with_frequency, "drive frequency"),
            ] {
                if let Some(t) = t
                    && t.p_value < 0.01
                {
                    s.push_str(&format!(
                        " (the relative miss changes by {:+.0} points per doubling of {what})",
                        t.slope * std::f64::consts::LN_2 * 100.0
                    ));
                }
            }
            s
        })
        .collect();
    let quiet: Vec<&str> = gaps
        .iter()
        .filter(|g| !g.significant)
        .map(|g| g.metric.words())
        .collect();
    if !quiet.is_empty() {
        parts.push(format!("{} within noise", quiet.join(", ")));
    }
    if within_noise && gaps.iter().all(|g| !g.significant) {
        return format!("no significant gap: {}", parts.join("; "));
    }
    parts.join("; ")
}

fn verdict(
    within_noise: bool,
    best: &Option<BestEffect>,
    ranking: &[RankedEffect],
    gap_before: f64,
    p_crit: f64,
) -> String {
    match best {
        Some(b) => format!(
            "{} explains the gap: held-out gap {:.2} → {:.2} ({:.0} % smaller)",
            b.effect, gap_before, b.gap_after, b.shrink_pct
        ),
        None if within_noise && ranking.iter().all(|r| !r.significant) => format!(
            "no significant gap (RMS z = {gap_before:.2}, consistent with the stated noise); \
             no effect is called"
        ),
        None => {
            let top = ranking.first();
            format!(
                "the gap (RMS z = {gap_before:.2}) is real but no candidate explains it \
                 significantly (best: {}, held-out gap {:.2}, p = {:.2e} vs {:.1e} needed): \
                 a model error or an effect outside the library",
                top.map(|t| t.effect.as_str()).unwrap_or("none"),
                top.map(|t| t.gap_after).unwrap_or(f64::NAN),
                top.map(|t| t.p_value).unwrap_or(1.0),
                p_crit
            )
        }
    }
}

/// Noncentrality of a magnitude: how far its predictions sit from a reference, in sd units.
fn distance2(
    obs: &[Observation],
    a: &dyn Fn(usize, Metric) -> f64,
    b: &dyn Fn(usize, Metric) -> f64,
    per_metric: Option<&mut [f64; 8]>,
) -> f64 {
    let mut total = 0.0;
    let mut pm = [0.0; 8];
    for o in obs {
        let (x, y) = (a(o.trial, o.metric), b(o.trial, o.metric));
        let d2 = if x.is_finite() && y.is_finite() {
            ((x - y) / o.sd).powi(2)
        } else if x.is_finite() != y.is_finite() {
            FELL_Z2
        } else {
            0.0
        };
        total += d2;
        pm[o.metric.index()] += d2;
    }
    if let Some(p) = per_metric {
        *p = pm;
    }
    total
}

#[allow(clippy::too_many_arguments)]
fn identifiability(
    ci: usize,
    def: &EffectDef,
    candidates: &[&EffectDef],
    curves: &[Curve],
    domains: &[(f64, f64, f64)],
    obs: &[Observation],
    nominal: &[SimMetrics],
    first: &Condition,
    p_crit: f64,
) -> Identifiability {
    // Detection with 90 % power by the one-sided LR test at level p_crit.
    let z = normal_quantile(1.0 - p_crit / 2.0) + normal_quantile(0.9);
    let lambda_detect = z * z;
    let z_id = 2.0 * normal_quantile(0.9);
    let lambda_id = z_id * z_id;
    let (lo, hi, off) = domains[ci];
    // Walk outward from the nominal: for off = 0 upward in u, for off = inf downward, for
    // an off inside the range (μ) toward the lower end ("slip").
    let steps = 200;
    let path: Vec<f64> = if off == 0.0 || (off.is_finite() && off.ln() > hi) {
        (0..=steps)
            .map(|k| lo + (hi - lo) * k as f64 / steps as f64)
            .collect()
    } else if off.is_infinite() || off.ln() >= lo {
        let start = if off.is_finite() {
            off.ln().min(hi)
        } else {
            hi
        };
        (0..=steps)
            .map(|k| start - (start - lo) * k as f64 / steps as f64)
            .collect()
    } else {
        (0..=steps)
            .map(|k| hi - (hi - lo) * k as f64 / steps as f64)
            .collect()
    };
    let nominal_of = |i: usize, m: Metric| nominal[i].get(m);
    let scale = def.magnitude().scale.value(&first.design);
    let mut detection = None;
    let mut identification = None;
    let mut mimic = None;
    let mut shares = [0.0; 8];
    for &u in &path {
        let own = |i: usize, m: Metric| curves[ci].value(i, m, u);
        let mut pm = [0.0; 8];
        let lam = distance2(obs, &own, &nominal_of, Some(&mut pm));
        if detection.is_none() && lam >= lambda_detect {
            detection = Some(u);
            shares = pm;
        }
        if detection.is_some() && identification.is_none() {
            // The best mimic: the other candidate's magnitude closest to these predictions.
            let mut closest = (f64::INFINITY, None);
            for (cj, other) in curves.iter().enumerate() {
                if cj == ci {
                    continue;
                }
                let (olo, ohi, _) = domains[cj];
                for k in 0..=60 {
                    let uo = olo + (ohi - olo) * k as f64 / 60.0;
                    let theirs = |i: usize, m: Metric| other.value(i, m, uo);
                    let d = distance2(obs, &own, &theirs, None);
                    if d < closest.0 {
                        closest = (d, Some(candidates[cj].name.clone()));
                    }
                }
            }
            if closest.0 >= lambda_id {
                identification = Some(u);
                mimic = closest.1;
            }
        }
    }
    if detection.is_none() {
        let u = *path.last().unwrap_or(&hi);
        let own = |i: usize, m: Metric| curves[ci].value(i, m, u);
        distance2(obs, &own, &nominal_of, Some(&mut shares));
    }
    let total: f64 = shares.iter().sum();
    let identifiable_from = Metric::ALL
        .iter()
        .filter(|m| total > 0.0 && shares[m.index()] >= 0.1 * total)
        .copied()
        .collect();
    Identifiability {
        effect: def.name.clone(),
        parameter: def.magnitude().name.clone(),
        unit: def.magnitude().unit.clone(),
        detection_threshold: detection.map(|u| u.exp() * scale),
        identification_threshold: identification.map(|u| u.exp() * scale),
        closest_mimic: mimic,
        identifiable_from,
    }
}
