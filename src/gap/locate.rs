//! Where the gap lies: per metric, its χ², mean relative miss, trends against leg length
//! and drive frequency (the regression engine's OLS), and the designs and sizes that carry
//! it; the one-line statements of the diagnosis' summary.

use serde::Serialize;

use super::likelihood::FELL_Z2;
use super::trials::Metric;
use crate::regression::dist::chi2_upper_p;
use crate::regression::{Method, fit_line};

fn chi2_sf(x: f64, df: f64) -> f64 {
    chi2_upper_p(x, df).unwrap_or(1.0)
}

/// A residual's z², a fall's [`FELL_Z2`].
fn z2(r: &Residual) -> f64 {
    r.z.map_or(FELL_Z2, |z| z * z)
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

pub fn trend(x: &[f64], y: &[f64]) -> Option<Trend> {
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

pub fn metric_gaps(res: &[Residual], alpha: f64) -> Vec<MetricGap> {
    let mut out = Vec::new();
    for m in Metric::ALL {
        let rs: Vec<&Residual> = res.iter().filter(|r| r.metric == m).collect();
        if rs.is_empty() {
            continue;
        }
        let chi2: f64 = rs.iter().map(|r| z2(r)).sum();
        let nn = rs.len() as f64;
        let p_value = chi2_sf(chi2, nn);
        let rel: Vec<f64> = rs.iter().filter_map(|r| r.relative).collect();
        let mean_rel = if rel.is_empty() {
            f64::NAN
        } else {
            rel.iter().sum::<f64>() / rel.len() as f64
        };
        let (lmin, lmax) = rs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
                (a.min(r.leg_length_m), b.max(r.leg_length_m))
            });
        let with_rel: Vec<&&Residual> = rs.iter().filter(|r| r.relative.is_some()).collect();
        let y: Vec<f64> = with_rel.iter().filter_map(|r| r.relative).collect();
        let xl: Vec<f64> = with_rel.iter().map(|r| r.leg_length_m.ln()).collect();
        let xf: Vec<f64> = with_rel.iter().map(|r| r.frequency_hz.ln()).collect();
        let after: Vec<f64> = rs.iter().filter_map(|r| r.z_after).collect();
        let rms_after = (after.len() == rs.len() && !after.is_empty())
            .then(|| (after.iter().map(|z| z * z).sum::<f64>() / nn).sqrt());
        let significant = p_value < alpha;
        let regimes = regimes_of(&rs, alpha);
        let statement = statement_of(m, &regimes, significant, mean_rel, [lmin, lmax]);
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

/// One metric's gap per design and size.
fn regimes_of(rs: &[&Residual], alpha: f64) -> Vec<RegimeGap> {
    let mut keys: Vec<(String, String)> = rs
        .iter()
        .map(|r| (r.design.clone(), sig3(r.leg_length_m)))
        .collect();
    keys.sort();
    keys.dedup();
    keys.iter()
        .map(|(dn, lk)| {
            let g: Vec<&&Residual> = rs
                .iter()
                .filter(|r| &r.design == dn && &sig3(r.leg_length_m) == lk)
                .collect();
            let c2: f64 = g.iter().map(|r| z2(r)).sum();
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
        .collect()
}

/// A metric's gap in words: where it lies when some regimes carry it, else its mean miss.
fn statement_of(
    m: Metric,
    regimes: &[RegimeGap],
    significant: bool,
    mean_rel: f64,
    [lmin, lmax]: [f64; 2],
) -> String {
    let place = if (lmax / lmin - 1.0).abs() < 0.05 {
        format!("at L ≈ {} m", sig3(lmin))
    } else {
        format!("over L = {}–{} m", sig3(lmin), sig3(lmax))
    };
    let hot: Vec<&RegimeGap> = regimes.iter().filter(|g| g.significant).collect();
    let same_sign = (hot.iter().all(|g| g.mean_relative_pct < 0.0)
        || hot.iter().all(|g| g.mean_relative_pct >= 0.0))
        && regimes.iter().all(|g| g.design == regimes[0].design);
    let side = |pct: f64| if pct < 0.0 { "under" } else { "over" };
    if significant
        && regimes.len() > 1
        && !hot.is_empty()
        && !(hot.len() == regimes.len() && same_sign)
    {
        let parts: Vec<String> = hot
            .iter()
            .map(|g| {
                format!(
                    "{}-predicted by {:.0} % at L ≈ {} m ({})",
                    side(g.mean_relative_pct),
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
            side(mean_rel),
            mean_rel.abs() * 100.0,
            place
        )
    } else if significant {
        format!("{} missed {} (the simulation falls)", m.words(), place)
    } else {
        format!("{} within noise", m.words())
    }
}

/// Three significant digits, no trailing zeros.
pub fn sig3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    let trimmed = s.trim_end_matches('0').trim_end_matches('.');
    if s.contains('.') { trimmed } else { &s }.to_string()
}

pub fn summarize(gaps: &[MetricGap], within_noise: bool) -> String {
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
