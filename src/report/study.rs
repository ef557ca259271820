//! Table III (minimum torque and gait across scales) as Markdown, LaTeX, CSV and figures.

use plotters::style::RGBColor;

use super::plot::{Panel, Series};
use super::sig;
use crate::sim::{ContactScaling, MassLaw};
use crate::study::paper::PaperTable3;
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
                series.push(Series {
                    label: format!(
                        "{} (a = {})",
                        series_key(r, several),
                        opt(r.velocity_exponent, 3)
                    ),
                    color: COLORS[k % COLORS.len()],
                    points: pts,
                    line: r.velocity_law.as_ref().map(|l| (l.a, l.b)),
                    line_range: None,
                    band: Vec::new(),
                });
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
                series.push(Series {
                    label: format!(
                        "{} (b = {})",
                        series_key(r, several),
                        opt(r.torque_exponent, 3)
                    ),
                    color: COLORS[k % COLORS.len()],
                    points: pts,
                    line: r.torque_law.as_ref().map(|l| (l.a, l.b)),
                    line_range: None,
                    band: Vec::new(),
                });
            }
            series.extend(refs);
            Panel {
                title: format!("{d}: minimum hip torque"),
                x_label: "leg length L [m]".into(),
                y_label: "τ_min [N·m]".into(),
                series,
            }
        })
        .collect()
}
