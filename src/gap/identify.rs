//! How strong an effect must be for these trials to see it (detection) and to tell it from
//! every other knob (identification), from the knobs' curves: no walks beyond the grids.
//!
//! Detection: the likelihood-ratio test at level p_crit finds the effect with 90 % power
//! when its predictions sit λ = (z_{1−p/2} + z₀.₉)² (in χ² units) from the nominal's.
//! Identification: beyond that, its closest mimic (any other knob — an effect, or with
//! calibration an uncertain parameter — at its best value) misses its predictions by at least
//! (2·z₀.₉)², the distance at which the two are told apart with 90 % probability; and, with
//! calibration, the best recalibration of every uncertain parameter at once misses them by the
//! detection distance, so that the effect's test against the recalibration has 90 % power.

use serde::Serialize;

use super::error::GapError;
use super::fit::FitContext;
use super::knob::{KnobKind, Knobs};
use super::problem::{FELL_Z2, Observation};
use super::simulate::SimMetrics;
use super::surrogate::Surrogate;
use super::trials::Metric;
use crate::regression::dist::normal_quantile;

/// From which metrics an effect shows, and the smallest magnitude these trials detect.
#[derive(Clone, Debug, Serialize)]
pub struct Identifiability {
    pub effect: String,
    pub parameter: String,
    pub unit: String,
    /// Magnitude (SI, first design at 1×) at which the likelihood-ratio test detects the
    /// effect with 90 % power given these trials' sds; None: not within the range.
    pub detection_threshold: Option<f64>,
    /// Magnitude beyond which the effect is also told from every other knob with 90 %
    /// probability; None: not within the range.
    pub identification_threshold: Option<f64>,
    /// The closest mimic at the identification threshold (or at the range's end).
    pub closest_mimic: Option<String>,
    /// Metrics carrying ≥ 10 % of the detection statistic at the threshold (or at the
    /// range's end).
    pub identifiable_from: Vec<Metric>,
}

/// Distance² between two prediction functions over the observations (sd units); a fall on
/// one side only counts [`FELL_Z2`].
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

/// Thresholds of every effect knob of the context.
pub fn identifiability(
    ctx: &FitContext<'_>,
    p_crit: f64,
    magnitude_name: &dyn Fn(&str) -> (String, String),
) -> Result<Vec<Identifiability>, GapError> {
    (0..ctx.knobs.len())
        .filter(|k| ctx.knobs.list[*k].kind == KnobKind::Effect)
        .map(|k| one(k, ctx, p_crit, magnitude_name))
        .collect()
}

/// How closely the recalibrated nominal (every uncertain parameter free) reproduces the
/// walks of effect knob `ci` at coordinate `u` (noiseless, with the trials' sds): the χ² of
/// its best fit, confirmed and refined with walks as a diagnosis would.
fn recalibration_distance(
    ctx: &FitContext<'_>,
    ci: usize,
    params: &[usize],
    u: f64,
) -> Result<f64, GapError> {
    let mut point = ctx.knobs.nominal_point();
    point[ci] = Some(u);
    let own = ctx.walks(&point)?;
    let obs: Vec<Observation> = ctx
        .obs
        .iter()
        .filter_map(|o| {
            let v = own[o.trial].get(o.metric);
            v.is_finite().then_some(Observation { value: v, ..*o })
        })
        .collect();
    let sub = FitContext { obs: &obs, ..*ctx };
    let nominal = sub.nominal()?;
    let starts = vec![(nominal.point.clone(), nominal.correction.clone())];
    Ok(sub.fit_walked(params, &starts, None, Some(&nominal))?.chi2)
}

fn one(
    ci: usize,
    ctx: &FitContext<'_>,
    p_crit: f64,
    magnitude_name: &dyn Fn(&str) -> (String, String),
) -> Result<Identifiability, GapError> {
    let knobs = ctx.knobs;
    let obs = ctx.obs;
    let guard = ctx.sur();
    let surrogate: &Surrogate = &guard;
    let nq = |p: f64| normal_quantile(p).unwrap_or(f64::NAN);
    let z = nq(1.0 - p_crit / 2.0) + nq(0.9);
    let lambda_detect = z * z;
    let z_id = 2.0 * nq(0.9);
    let lambda_id = z_id * z_id;
    let knob = &knobs.list[ci];
    let path = knob.strengthening_path(200);
    let nominal: Vec<SimMetrics> = surrogate.nominal.clone();
    let nominal_of = |i: usize, m: Metric| nominal[i].get(m);
    let mut detection = None;
    let mut identification = None;
    let mut mimic = None;
    let mut shares = [0.0; 8];
    for &u in &path {
        let own = |i: usize, m: Metric| surrogate.curves[ci].value(i, m, u);
        let mut pm = [0.0; 8];
        let lam = distance2(obs, &own, &nominal_of, Some(&mut pm));
        if detection.is_none() && lam >= lambda_detect {
            detection = Some(u);
            shares = pm;
        }
        if detection.is_some() && identification.is_none() {
            let (d, m) = closest_mimic(ci, knobs, surrogate, obs, &own);
            mimic = m;
            if d >= lambda_id {
                identification = Some(u);
            }
        }
    }
    // With uncertain parameters: the test against the recalibration must also have power
    // (checked with walks: the recalibration's reach is what the surrogate misses most).
    let params: Vec<usize> = (0..knobs.len())
        .filter(|k| knobs.list[*k].kind == KnobKind::Parameter)
        .collect();
    drop(guard);
    if !params.is_empty()
        && let Some(u_id) = identification
    {
        let k0 = path.iter().position(|u| *u == u_id).unwrap_or(0);
        let (mut lo, mut hi) = (k0, path.len() - 1);
        let far = |k: usize| -> Result<bool, GapError> {
            Ok(recalibration_distance(ctx, ci, &params, path[k])? >= lambda_detect)
        };
        if far(lo)? {
            // Already far enough at the identification threshold.
        } else if !far(hi)? {
            identification = None;
            mimic = Some("the recalibrated nominal (every uncertain parameter)".into());
        } else {
            while hi - lo > 6 {
                let mid = (lo + hi) / 2;
                if far(mid)? {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            identification = Some(path[hi]);
            mimic = Some("the recalibrated nominal (every uncertain parameter)".into());
        }
    }
    let guard = ctx.sur();
    let surrogate: &Surrogate = &guard;
    if detection.is_none() {
        let u = *path.last().unwrap_or(&knob.hi);
        let own = |i: usize, m: Metric| surrogate.curves[ci].value(i, m, u);
        distance2(obs, &own, &nominal_of, Some(&mut shares));
    }
    let total: f64 = shares.iter().sum();
    let identifiable_from = Metric::ALL
        .iter()
        .filter(|m| total > 0.0 && shares[m.index()] >= 0.1 * total)
        .copied()
        .collect();
    let (parameter, unit) = magnitude_name(&knob.name);
    Ok(Identifiability {
        effect: knob.name.clone(),
        parameter,
        unit,
        detection_threshold: detection.map(|u| knob.si(u)),
        identification_threshold: identification.map(|u| knob.si(u)),
        closest_mimic: mimic,
        identifiable_from,
    })
}

/// The other knob closest to predictions `own` (distance², label): each knob's best value
/// on a 61-point grid of its range, polished by golden section between the neighbours.
fn closest_mimic(
    ci: usize,
    knobs: &Knobs,
    surrogate: &Surrogate,
    obs: &[Observation],
    own: &dyn Fn(usize, Metric) -> f64,
) -> (f64, Option<String>) {
    let mut closest = (f64::INFINITY, None);
    for (cj, other) in surrogate.curves.iter().enumerate() {
        if cj == ci {
            continue;
        }
        let o = &knobs.list[cj];
        let d_at = |uo: f64| {
            let theirs = |i: usize, m: Metric| other.value(i, m, uo);
            distance2(obs, own, &theirs, None)
        };
        let n = 60;
        let h = (o.hi - o.lo) / n as f64;
        let (mut best_u, mut best_d) = (o.lo, f64::INFINITY);
        for k in 0..=n {
            let uo = o.lo + h * k as f64;
            let d = d_at(uo);
            if d < best_d {
                (best_u, best_d) = (uo, d);
            }
        }
        let (mut a, mut b) = ((best_u - h).max(o.lo), (best_u + h).min(o.hi));
        let g = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..25 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            if d_at(c) < d_at(d) {
                b = d;
            } else {
                a = c;
            }
        }
        best_d = best_d.min(d_at(0.5 * (a + b)));
        if best_d < closest.0 {
            closest = (best_d, Some(o.label()));
        }
    }
    closest
}
