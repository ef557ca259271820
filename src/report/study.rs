//! Table III (minimum torque and gait across scales) as Markdown, LaTeX, CSV and figures.

use plotters::chart::SeriesLabelPosition;
use plotters::style::RGBColor;

use super::plot::{Panel, Series};
use super::sig;
use crate::sim::{ContactScaling, MassLaw};
use crate::study::paper::PaperTable3;
use crate::study::scaling::StudyLaw;
use crate::study::{Table3, Table3Row};

fn law_name(m: MassLaw) -> &'static str {
    match m {
        MassLaw::L2 => "m ∝ L²",
        MassLaw::L3 => "m ∝ L³",
    }
}

fn contact_name(c: ContactScaling) -> &'static str {
    match c {
        ContactScaling::Similar => "similar",
        ContactScaling::FixedMaterial => "fixed-material",
    }
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map(|x| format!("{x:.digits$}"))
        .unwrap_or_else(|| "–".into())
}

fn exp_ci(b: Option<f64>, ci: Option<[f64; 2]>) -> String {
    match (b, ci) {
        (Some(b), Some([lo, hi])) => format!("{b:.3} [{lo:.3}, {hi:.3}]"),
        (Some(b), None) => format!("{b:.3}"),
        _ => "–".into(),
    }
}

fn pm(m: Option<f64>, sd: Option<f64>) -> String {
    match (m, sd) {
        (Some(m), Some(s)) => format!("{m:.2} ± {s:.2}"),
        _ => "–".into(),
    }
}

/// The summary table and, per row, where it stops walking; with the paper's values.
pub fn table3_md(t: &Table3, paper: Option<&PaperTable3>) -> String {
    let mut out = String::from(
        "| design | mass law | contact | v ∝ L^a: a [95 % CI] | R² | τ_min ∝ L^b: b [95 % CI] | R² | τ_min ∝ (mL)^c | τ_min/(mgL) | roll p-p [°] | pitch p-p [°] | yaw p-p [°] | sizes walking | walks simulated |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &t.rows {
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {}/{} | {} |\n",
            r.design,
            law_name(r.mass_law),
            contact_name(r.contact),
            exp_ci(r.velocity_exponent, r.velocity_exponent_ci),
            opt(r.velocity_r2, 3),
            exp_ci(r.torque_exponent, r.torque_exponent_ci),
            opt(r.torque_r2, 3),
            exp_ci(
                r.torque_vs_mass_length_exponent,
                r.torque_vs_mass_length_exponent_ci
            ),
            r.min_torque_over_mgl
                .map(|s| format!("{:.3} ± {:.3}", s.mean, s.sd))
                .unwrap_or_else(|| "–".into()),
            pm(r.roll_pp_deg, r.roll_pp_deg_sd),
            pm(r.pitch_pp_deg, r.pitch_pp_deg_sd),
            pm(r.yaw_pp_deg, r.yaw_pp_deg_sd),
            r.sizes_walking,
            r.sizes_total,
            r.walks_evaluated
        ));
    }
    if let Some(p) = paper {
        out.push_str(
            "\nThe paper (Oke et al. 2026, table tab:simresults; Drake, contact tuned per design):\n\n\
             | design | mass law | v ∝ L^a | R² | τ_min ∝ L^b | R² | roll p-p [°] | pitch p-p [°] | yaw p-p [°] |\n\
             |---|---|---|---|---|---|---|---|---|\n",
        );
        for r in &p.row {
            out.push_str(&format!(
                "| {} | {} | {:.2} | {:.3} | {:.2} | {:.3} | {:.2} ± {:.2} | {:.2} ± {:.2} | {:.2} ± {:.2} |\n",
                r.design,
                law_name(r.mass_law),
                r.velocity_exponent,
                r.velocity_r2,
                r.torque_exponent,
                r.torque_r2,
                r.roll_pp_deg[0],
                r.roll_pp_deg[1],
                r.pitch_pp_deg[0],
                r.pitch_pp_deg[1],
                r.yaw_pp_deg[0],
                r.yaw_pp_deg[1]
            ));
        }
    }
    let stops: Vec<&Table3Row> = t
        .rows
        .iter()
        .filter(|r| !r.sizes_not_walking_m.is_empty())
        .collect();
    out.push_str("\nSizes that do not walk consistently at any torque up to the cap:\n\n");
    if stops.is_empty() {
        out.push_str("- none: every design walks at every size.\n");
    }
    for r in stops {
        let ls: Vec<String> = r.sizes_not_walking_m.iter().map(|l| sig(*l)).collect();
        let why: Vec<String> = {
            let mut w: Vec<String> = r
                .points
                .iter()
                .filter(|p| !p.walks)
                .filter_map(|p| p.failure_below.clone())
                .collect();
            w.sort();
            w.dedup();
            w
        };
        out.push_str(&format!(
            "- {} {} {}: L = {} m ({})\n",
            r.design,
            law_name(r.mass_law),
            contact_name(r.contact),
            ls.join(", "),
            why.join(", ")
        ));
    }
    out.push_str(&format!("\nCriterion: {}.\n", t.criterion));
    out
}

/// The summary table in LaTeX (booktabs).
pub fn table3_tex(t: &Table3) -> String {
    let mut out = String::from(
        "\\begin{tabular}{lllllllll}\n\\toprule\ndesign & mass law & contact & $v \\propto L^a$ & $R^2$ & $\\tau_{\\min} \\propto L^b$ & $R^2$ & $\\tau_{\\min} \\propto (mL)^c$ & walking \\\\\n\\midrule\n",
    );
    for r in &t.rows {
        let ml = match r.mass_law {
            MassLaw::L2 => "$m \\propto L^2$",
            MassLaw::L3 => "$m \\propto L^3$",
        };
        out.push_str(&format!(
            "{} & {} & {} & {} & {} & {} & {} & {} & {}/{} \\\\\n",
            r.design,
            ml,
            contact_name(r.contact),
            exp_ci(r.velocity_exponent, r.velocity_exponent_ci),
            opt(r.velocity_r2, 3),
            exp_ci(r.torque_exponent, r.torque_exponent_ci),
            opt(r.torque_r2, 3),
            exp_ci(
                r.torque_vs_mass_length_exponent,
                r.torque_vs_mass_length_exponent_ci
            ),
            r.sizes_walking,
            r.sizes_total
        ));
    }
    out.push_str("\\bottomrule\n\\end{tabular}\n");
    out.replace('[', "$[").replace(']', "]$")
}

/// Every point, one row per design × mass law × contact × size.
pub fn table3_csv(t: &Table3) -> Result<String, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in &t.rows {
        for p in &r.points {
            w.serialize(p)?;
        }
    }
    let bytes = w.into_inner().map_err(|e| e.into_error())?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

const COLORS: [RGBColor; 4] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0x94, 0x67, 0xbd),
];
const GREY: RGBColor = RGBColor(0x88, 0x88, 0x88);

fn designs(t: &Table3) -> Vec<String> {
    let mut d: Vec<String> = Vec::new();
    for r in &t.rows {
        if !d.contains(&r.design) {
            d.push(r.design.clone());
        }
    }
    d
}

fn series_key(r: &Table3Row, several_contacts: bool) -> String {
    if several_contacts {
        format!("{} {}", law_name(r.mass_law), contact_name(r.contact))
    } else {
        law_name(r.mass_law).to_string()
    }
}

/// One chain's points with its fitted law, labelled with the law's exponent.
fn chain_series(
    r: &Table3Row,
    several_contacts: bool,
    k: usize,
    (symbol, exponent): (&str, Option<f64>),
    law: Option<&StudyLaw>,
    points: Vec<(f64, f64)>,
) -> Series {
    Series {
        label: format!(
            "{} ({symbol} = {})",
            series_key(r, several_contacts),
            opt(exponent, 3)
        ),
        color: COLORS[k % COLORS.len()],
        points,
        line: law.map(|l| (l.a, l.b)),
        line_range: None,
        band: Vec::new(),
        ..Default::default()
    }
}

fn several_contacts(t: &Table3) -> bool {
    t.rows.iter().any(|r| r.contact != t.rows[0].contact)
}

/// Velocity against leg length, one panel per design, with the Froude line v ∝ √(gL)
/// through the geometric mean of the walking points.
pub fn table3_velocity_panels(t: &Table3) -> Vec<Panel> {
    let several = several_contacts(t);
    designs(t)
        .into_iter()
        .map(|d| {
            let mut series = Vec::new();
            let mut all: Vec<(f64, f64)> = Vec::new();
            for (k, r) in t.rows.iter().filter(|r| r.design == d).enumerate() {
                let pts: Vec<(f64, f64)> = r
                    .points
                    .iter()
                    .filter(|p| p.walks)
                    .filter_map(|p| p.velocity_mps.map(|v| (p.leg_length_m, v)))
                    .filter(|(_, v)| *v > 0.0)
                    .collect();
                all.extend(&pts);
                series.push(chain_series(
                    r,
                    several,
                    k,
                    ("a", r.velocity_exponent),
                    r.velocity_law.as_ref(),
                    pts,
                ));
            }
            if let Some(c) = froude_constant(&all) {
                series.push(reference_line(
                    "Froude: v ∝ √(gL)".into(),
                    c,
                    0.5,
                    &t.leg_lengths_m,
                ));
            }
            Panel {
                title: format!("{d}: walking speed"),
                x_label: "leg length L [m]".into(),
                y_label: "velocity v [m/s]".into(),
                series,
                legend: SeriesLabelPosition::UpperLeft,
            }
        })
        .collect()
}

/// c in v = c·L^0.5 through the geometric mean of the points.
fn froude_constant(pts: &[(f64, f64)]) -> Option<f64> {
    if pts.is_empty() {
        return None;
    }
    let mean = pts.iter().map(|(l, v)| (v / l.sqrt()).ln()).sum::<f64>() / pts.len() as f64;
    Some(mean.exp())
}

fn reference_line(label: String, a: f64, b: f64, ls: &[f64]) -> Series {
    let lo = ls.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = ls.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    Series {
        label,
        color: GREY,
        points: Vec::new(),
        line: Some((a, b)),
        line_range: Some((lo, hi)),
        band: Vec::new(),
        ..Default::default()
    }
}

/// Minimum torque against leg length, one panel per design, with the reference slopes of
/// τ ∝ m·L and τ ∝ m·L² (for each mass law present) through the smallest walking size.
pub fn table3_torque_panels(t: &Table3) -> Vec<Panel> {
    let several = several_contacts(t);
    designs(t)
        .into_iter()
        .map(|d| {
            let mut series = Vec::new();
            let mut refs = Vec::new();
            for (k, r) in t.rows.iter().filter(|r| r.design == d).enumerate() {
                let pts: Vec<(f64, f64)> = r
                    .points
                    .iter()
                    .filter_map(|p| p.min_torque_nm.map(|v| (p.leg_length_m, v)))
                    .collect();
                if let Some(&(l0, t0)) = pts.first()
                    && r.contact == t.rows[0].contact
                {
                    let e = r.mass_law.exponent();
                    refs.push(reference_line(
                        format!("m·L ∝ L^{} ({})", e + 1.0, law_name(r.mass_law)),
                        t0 / l0.powf(e + 1.0),
                        e + 1.0,
                        &t.leg_lengths_m,
                    ));
                    refs.push(reference_line(
                        format!("m·L² ∝ L^{}", e + 2.0),
                        t0 / l0.powf(e + 2.0),
                        e + 2.0,
                        &t.leg_lengths_m,
                    ));
                }
                series.push(chain_series(
                    r,
                    several,
                    k,
                    ("b", r.torque_exponent),
                    r.torque_law.as_ref(),
                    pts,
                ));
            }
            series.extend(refs);
            Panel {
                title: format!("{d}: minimum hip torque"),
                x_label: "leg length L [m]".into(),
                y_label: "τ_min [N·m]".into(),
                series,
                legend: SeriesLabelPosition::UpperLeft,
            }
        })
        .collect()
}

/// The foot study: feasible multipliers per size and axis, the feasible-length laws beside
/// the paper's, and the fastest foot per size against the Froude prediction.
pub fn feet_md(f: &crate::study::feet::FeetStudy) -> String {
    let mut out = String::from(
        "Feasible feet: multipliers of one semi-axis (others 1×) that walk with the design's own control.\n\n\
         | design | contact | L [m] | axis | walking multipliers | shortest–longest semi-axis [m] |\n|---|---|---|---|---|---|\n",
    );
    for r in &f.ranges {
        out.push_str(&format!(
            "| {} | {} | {} | R_{} | {} | {} |\n",
            r.design,
            contact_name(r.contact),
            sig(r.leg_length_m),
            r.axis.to_uppercase(),
            factor_runs(&r.walking_factors),
            match (r.min_m, r.max_m) {
                (Some(a), Some(b)) => format!("{}–{}", sig(a), sig(b)),
                _ => "none".into(),
            }
        ));
    }
    out.push_str(
        "\nFeasible semi-axis length against leg length, R = a·L^b over every walking foot:\n\n\
         | design | contact | axis | a | b [95 % CI] | R² | n | paper a·L^b (R²) |\n|---|---|---|---|---|---|---|---|\n",
    );
    for l in &f.laws {
        let paper = l
            .paper
            .map(|[a, b, r2]| format!("{a}·L^{b} ({r2})"))
            .unwrap_or_else(|| "–".into());
        match &l.law {
            Some(law) => out.push_str(&format!(
                "| {} | {} | R_{} | {:.3} | {:.3} [{:.3}, {:.3}] | {:.3} | {} | {} |\n",
                l.design,
                contact_name(l.contact),
                l.axis.to_uppercase(),
                law.a,
                law.b,
                law.b_ci[0],
                law.b_ci[1],
                law.r2,
                law.n,
                paper
            )),
            None => out.push_str(&format!(
                "| {} | {} | R_{} | – | – | – | – | {} |\n",
                l.design,
                contact_name(l.contact),
                l.axis.to_uppercase(),
                paper
            )),
        }
    }
    out.push_str(
        "\nFastest foot per size, against the Froude prediction from the 1× foot at the reference size (v ∝ √L):\n\n\
         | design | contact | L [m] | foot | v [m/s] | 1× foot v [m/s] | Froude prediction [m/s] | excess | paper fastest [m/s] |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for b in &f.fastest {
        out.push_str(&format!(
            "| {} | {} | {} | R_{} × {} | {:.3} | {} | {} | {} | {} |\n",
            b.design,
            contact_name(b.contact),
            sig(b.leg_length_m),
            b.axis.to_uppercase(),
            b.factor,
            b.velocity_mps,
            opt(b.velocity_1x_mps, 3),
            b.froude_prediction_mps
                .map(|v| format!("{v:.3} (from L = {})", sig(b.reference_leg_length_m)))
                .unwrap_or_else(|| "–".into()),
            b.excess_over_froude
                .map(|e| format!("{:+.0} %", 100.0 * e))
                .unwrap_or_else(|| "–".into()),
            opt(b.paper_velocity_mps, 3)
        ));
    }
    out
}

/// "0.5–1.3, 1.5" from sorted multipliers on a 0.1 grid.
fn factor_runs(fs: &[f64]) -> String {
    if fs.is_empty() {
        return "none".into();
    }
    let mut runs: Vec<(f64, f64)> = Vec::new();
    for &f in fs {
        match runs.last_mut() {
            Some((_, hi)) if (f - *hi - 0.1).abs() < 1e-6 => *hi = f,
            _ => runs.push((f, f)),
        }
    }
    runs.iter()
        .map(|(a, b)| {
            if a == b {
                format!("{a}")
            } else {
                format!("{a}–{b}")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Feasible region: every walking foot's scaled semi-axis against L, per design and axis
/// (each axis offset slightly in L so the columns do not overlap), with the fitted laws.
pub fn feet_panels(f: &crate::study::feet::FeetStudy) -> Vec<Panel> {
    let mut keys: Vec<(String, ContactScaling)> = Vec::new();
    for p in &f.points {
        if !keys.contains(&(p.design.clone(), p.contact)) {
            keys.push((p.design.clone(), p.contact));
        }
    }
    keys.into_iter()
        .map(|(d, c)| {
            let series = ["x", "y", "z"]
                .iter()
                .enumerate()
                .map(|(k, axis)| {
                    let offset = [0.93, 1.0, 1.075][k];
                    let pts: Vec<(f64, f64)> = f
                        .points
                        .iter()
                        .filter(|p| p.design == d && p.contact == c && p.axis == *axis && p.walks)
                        .map(|p| (p.leg_length_m * offset, [p.r_x_m, p.r_y_m, p.r_z_m][k]))
                        .collect();
                    let law = f
                        .laws
                        .iter()
                        .find(|l| l.design == d && l.contact == c && l.axis == *axis)
                        .and_then(|l| l.law.as_ref());
                    Series {
                        label: match law {
                            Some(l) => {
                                format!("R_{} = {:.2}·L^{:.2}", axis.to_uppercase(), l.a, l.b)
                            }
                            None => format!("R_{}", axis.to_uppercase()),
                        },
                        color: COLORS[k],
                        points: pts,
                        line: law.map(|l| (l.a, l.b)),
                        line_range: None,
                        band: Vec::new(),
                        ..Default::default()
                    }
                })
                .collect();
            Panel {
                title: format!("{d} ({}): walking feet", contact_name(c)),
                x_label: "leg length L [m]".into(),
                y_label: "semi-axis [m]".into(),
                series,
                legend: SeriesLabelPosition::UpperLeft,
            }
        })
        .collect()
}

/// `survey torque-check` as text.
pub fn torque_check_text(c: &crate::study::torque_check::TorqueCheck) -> String {
    let a = &c.anchor;
    let mut out = format!(
        "{} ({}, {} contact): minimum hip torque (Table III) against motor-torque laws\n\
         anchor: {} ({}) stall {} N·m{} at L = {} m (robot {} kg{}); required there {} N·m\n\
         required τ_min ∝ L^{} over {} walking sizes ({}–{} m)\n",
        c.design,
        law_name(c.mass_law),
        contact_name(c.contact),
        a.actuator_name,
        a.actuator,
        sig(a.stall_torque_nm),
        a.voltage_v
            .map(|v| format!(" at {v} V"))
            .unwrap_or_default(),
        a.leg_length_m,
        sig(a.robot_mass_kg),
        a.actuator_mass_kg
            .map(|m| format!(", actuator {} kg", sig(m)))
            .unwrap_or_default(),
        a.required_nm.map(sig).unwrap_or_else(|| "–".into()),
        opt(c.required_exponent, 2),
        c.leg_lengths_m.len(),
        c.leg_lengths_m.first().map(|l| sig(*l)).unwrap_or_default(),
        c.leg_lengths_m.last().map(|l| sig(*l)).unwrap_or_default(),
    );
    if let (Some(b), Some([lo, hi]), Some(r2)) = (
        c.actuator_fit_exponent,
        c.actuator_fit_exponent_ci,
        c.actuator_fit_r2,
    ) {
        out.push_str(&format!(
            "catalogue: τ_stall ∝ M^{b:.2} [{lo:.2}, {hi:.2}], R² {r2:.3}, n = {} datasheet actuators\n",
            c.actuator_fit_n
        ));
    }
    for b in &c.bridges {
        out.push_str(&format!("\n{}\n", b.description));
        if let (Some(Some(f0)), Some(Some(f1))) = (
            b.actuator_mass_fraction.first(),
            b.actuator_mass_fraction.last(),
        ) {
            out.push_str(&format!(
                "  actuator mass / robot mass: {:.3} at the smallest size, {:.3} at the largest{}\n",
                f0,
                f1,
                if *f1 > 1.0 || *f0 > 1.0 {
                    " (above 1: the bridge is impossible there)"
                } else {
                    ""
                }
            ));
        }
        out.push_str(&format!(
            "  {:<22} {:>9} {:>8} {:>10} {:>10}  {}\n",
            "law", "basis", "τ ∝ L^p", "margin min", "margin max", "verdict"
        ));
        for l in &b.laws {
            let (mn, mx) = l
                .margin
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), m| {
                    (a.min(*m), b.max(*m))
                });
            out.push_str(&format!(
                "  {:<22} {:>9} {:>8.2} {:>10} {:>10}  {}\n",
                l.law,
                l.basis,
                l.exponent_vs_leg_length,
                sig(mn),
                sig(mx),
                l.verdict
            ));
        }
    }
    out
}

/// One panel per bridge: the required minimum torque and every law's available torque.
pub fn torque_check_panels(c: &crate::study::torque_check::TorqueCheck) -> Vec<Panel> {
    let palette = [
        RGBColor(0x1f, 0x77, 0xb4),
        RGBColor(0x2c, 0xa0, 0x2c),
        RGBColor(0x94, 0x67, 0xbd),
        RGBColor(0xff, 0x7f, 0x0e),
        RGBColor(0x8c, 0x56, 0x4b),
        RGBColor(0xe3, 0x77, 0xc2),
        RGBColor(0x17, 0xbe, 0xcf),
        RGBColor(0xbc, 0xbd, 0x22),
        RGBColor(0x7f, 0x7f, 0x7f),
        RGBColor(0x00, 0x00, 0x00),
    ];
    let (lo, hi) = match (c.leg_lengths_m.first(), c.leg_lengths_m.last()) {
        (Some(a), Some(b)) => (*a, *b),
        _ => (0.02, 1.2),
    };
    c.bridges
        .iter()
        .map(|b| {
            let mut series = vec![Series {
                label: format!("required τ_min ({})", law_name(c.mass_law)),
                color: RGBColor(0xd6, 0x27, 0x28),
                points: c
                    .leg_lengths_m
                    .iter()
                    .zip(&c.required_nm)
                    .map(|(l, t)| (*l, *t))
                    .collect(),
                line: None,
                line_range: None,
                band: Vec::new(),
                ..Default::default()
            }];
            for (k, l) in b.laws.iter().enumerate() {
                let p = l.exponent_vs_leg_length;
                series.push(Series {
                    label: format!("{} (L^{p:.2})", l.law),
                    color: palette[k % palette.len()],
                    points: Vec::new(),
                    line: Some((c.anchor.stall_torque_nm / c.anchor.leg_length_m.powf(p), p)),
                    line_range: Some((lo, hi)),
                    band: Vec::new(),
                    ..Default::default()
                });
            }
            Panel {
                title: match b.bridge {
                    crate::study::torque_check::Bridge::IsometricActuator => {
                        format!("{}: isometric actuator", c.design)
                    }
                    crate::study::torque_check::Bridge::FixedMassFraction => {
                        format!("{}: fixed actuator mass fraction", c.design)
                    }
                },
                x_label: "leg length L [m]".into(),
                y_label: "hip torque [N·m]".into(),
                series,
                legend: SeriesLabelPosition::UpperLeft,
            }
        })
        .collect()
}

/// The required hip torque of `survey predict --from design:NAME`.
pub fn torque_need_text(t: &crate::study::torque_need::TorqueNeed) -> String {
    let mut out = format!(
        "\nrequired minimum hip torque of {} at L = {} m (Table III, {}, {} contact: τ_min = {:.3} m·g·L, bracket [{:.3}, {:.3}], walking sizes {}–{} m)\n",
        t.design,
        t.leg_length_m,
        law_name(t.mass_law),
        contact_name(t.contact),
        t.min_torque_over_mgl,
        t.bracket_over_mgl[0],
        t.bracket_over_mgl[1],
        sig(t.walking_range_m[0]),
        sig(t.walking_range_m[1])
    );
    for q in &t.torques {
        out.push_str(&format!(
            "  mass {:>9} kg ({}){}: τ_min {} N·m [{}, {}]\n",
            sig(q.mass_kg),
            q.mass_from,
            q.mass_interval_kg
                .map(|[a, b]| format!(" [{}, {}] kg", sig(a), sig(b)))
                .unwrap_or_default(),
            sig(q.required_nm),
            sig(q.required_interval_nm[0]),
            sig(q.required_interval_nm[1])
        ));
    }
    out.push_str(&format!(
        "actuators with stall torque ≥ {}× the first requirement (lightest first):\n",
        t.torque_margin
    ));
    if t.actuators.iter().all(|a| !a.meets_margin) {
        out.push_str(
            "  none in the catalogue (dataset/motors/actuators.toml); the strongest catalogued:\n",
        );
    }
    for a in t.actuators.iter().take(8) {
        out.push_str(&format!(
            "  {:<34} {:>8} {:>9} N·m stall{} margin {:.1}×\n",
            a.name,
            a.mass_kg
                .map(|m| format!("{} kg", sig(m)))
                .unwrap_or_else(|| "mass ?".into()),
            sig(a.stall_torque_nm),
            a.voltage_v
                .map(|v| format!(" at {v} V,"))
                .unwrap_or(",".into()),
            a.margin
        ));
    }
    out
}
