//! Figures with plotters: log–log scatter plots with fitted power laws, as SVG and PNG.
//! The font is bundled (assets/fonts) so PNG output is identical on every machine.

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::ticks::{log_label, log_ticks};
use crate::analysis::table2::{Group, Table2, Var, points};
use crate::dataset::{RobotClass, SurveyTable};

static FONT: Once = Once::new();
const FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

pub(crate) fn register_font() {
    FONT.call_once(|| {
        // The bytes are a known-good TTF compiled in; failure would be a build defect.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_BYTES);
    });
}

/// Error drawing a figure.
#[derive(Debug, thiserror::Error)]
#[error("drawing {path}: {message}")]
pub struct PlotError {
    pub path: String,
    pub message: String,
}

/// Colour of a class in every figure.
pub fn class_color(c: RobotClass) -> RGBColor {
    match c {
        RobotClass::LowerBiped => RGBColor(0xd6, 0x27, 0x28),
        RobotClass::FullBiped => RGBColor(0x1f, 0x77, 0xb4),
        RobotClass::Quadruped => RGBColor(0x2c, 0xa0, 0x2c),
        RobotClass::Hexapod => RGBColor(0x94, 0x67, 0xbd),
        RobotClass::Hybrid => RGBColor(0x7f, 0x7f, 0x7f),
    }
}

/// How a series' points are drawn.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Marker {
    #[default]
    Circle,
    Square,
    Triangle,
    Cross,
}

/// One series of a log–log panel: points and, optionally, a fitted line y = a·x^b and a band.
pub struct Series {
    pub label: String,
    pub color: RGBColor,
    pub points: Vec<(f64, f64)>,
    pub line: Option<(f64, f64)>,
    /// x range of `line` when it is a reference drawn without points (None: the points').
    pub line_range: Option<(f64, f64)>,
    /// (x, low, high) of a band to shade (e.g. a prediction interval).
    pub band: Vec<(f64, f64, f64)>,
    pub marker: Marker,
    /// Draw `line` dashed (a reference rather than a fit).
    pub dashed: bool,
    /// Leave the series out of the legend.
    pub unlabelled: bool,
}

impl Default for Series {
    fn default() -> Self {
        Series {
            label: String::new(),
            color: BLACK,
            points: Vec::new(),
            line: None,
            line_range: None,
            band: Vec::new(),
            marker: Marker::Circle,
            dashed: false,
            unlabelled: false,
        }
    }
}

/// A log–log panel.
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Where the legend goes (a corner the data leave free).
    pub legend: SeriesLabelPosition,
}

fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo.is_finite() && hi.is_finite() {
        (lo / 1.6, hi * 1.6)
    } else {
        (0.01, 1.0)
    }
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> Result<(), String> {
    let xr = bounds(panel.series.iter().flat_map(|s| {
        s.points
            .iter()
            .map(|p| p.0)
            .chain(s.band.iter().map(|b| b.0))
            .chain(s.line_range.iter().flat_map(|r| [r.0, r.1]))
    }));
    let yr = bounds(panel.series.iter().flat_map(|s| {
        let reference_ends = match (s.line, s.line_range) {
            (Some((a, b)), Some((lo, hi))) => vec![a * lo.powf(b), a * hi.powf(b)],
            _ => Vec::new(),
        };
        s.points
            .iter()
            .map(|p| p.1)
            .chain(s.band.iter().flat_map(|b| [b.1, b.2]))
            .chain(reference_ends)
    }));
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            {
                let (bold, light) = log_ticks(xr.0, xr.1);
                (xr.0..xr.1)
                    .log_scale()
                    .with_key_points(bold)
                    .with_light_points(light)
            },
            {
                let (bold, light) = log_ticks(yr.0, yr.1);
                (yr.0..yr.1)
                    .log_scale()
                    .with_key_points(bold)
                    .with_light_points(light)
            },
        )
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(&panel.x_label)
        .y_desc(&panel.y_label)
        .x_label_formatter(&|v: &f64| log_label(*v))
        .y_label_formatter(&|v: &f64| log_label(*v))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| e.to_string())?;
    for s in &panel.series {
        draw_band(&mut chart, s)?;
        draw_markers(&mut chart, s)?;
        draw_line(&mut chart, s)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .position(panel.legend.clone())
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// Draws a series' shaded band.
fn draw_band<'a, DB: DrawingBackend + 'a, CT: CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'a, DB, CT>,
    s: &Series,
) -> Result<(), String> {
    let color = s.color;
    if !s.band.is_empty() {
        let mut poly: Vec<(f64, f64)> = s.band.iter().map(|b| (b.0, b.2)).collect();
        poly.extend(s.band.iter().rev().map(|b| (b.0, b.1)));
        chart
            .draw_series(std::iter::once(Polygon::new(
                poly,
                color.mix(0.15).filled(),
            )))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Draws a series' markers, with their legend entry.
fn draw_markers<'a, DB: DrawingBackend + 'a, CT: CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'a, DB, CT>,
    s: &Series,
) -> Result<(), String> {
    let color = s.color;
    if !s.points.is_empty() {
        // Each marker is its own element type, in data and in legend coordinates: the
        // macro writes the element once for both.
        macro_rules! marked {
            (|$p:ident, $r:ident| $e:expr) => {{
                let anno = chart
                    .draw_series(s.points.iter().map(|&$p| {
                        let $r: i32 = 4;
                        $e
                    }))
                    .map_err(|e| e.to_string())?;
                if !s.unlabelled {
                    anno.label(&s.label).legend(move |(x, y)| {
                        let ($p, $r): ((i32, i32), i32) = ((x + 8, y), 4);
                        $e
                    });
                }
            }};
        }
        match s.marker {
            Marker::Circle => marked!(|p, r| Circle::new(p, r, color.filled())),
            Marker::Square => {
                marked!(
                    |p, r| EmptyElement::at(p) + Rectangle::new([(-r, -r), (r, r)], color.filled())
                )
            }
            Marker::Triangle => marked!(|p, r| TriangleMarker::new(p, r + 1, color.filled())),
            Marker::Cross => marked!(|p, r| Cross::new(p, r, color.stroke_width(2))),
        }
    }
    Ok(())
}

/// Draws a series' fitted line, with its legend entry when it has no markers.
fn draw_line<'a, DB: DrawingBackend + 'a, CT: CoordTranslate<From = (f64, f64)>>(
    chart: &mut ChartContext<'a, DB, CT>,
    s: &Series,
) -> Result<(), String> {
    let color = s.color;
    if let Some((a, b)) = s.line {
        let (lo, hi) = s.line_range.unwrap_or_else(|| {
            s.points
                .iter()
                .map(|p| p.0)
                .chain(s.band.iter().map(|p| p.0))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                    (l.min(v), h.max(v))
                })
        });
        if lo.is_finite() && hi > lo {
            let steps = 50;
            let line = (0..=steps).map(|i| {
                let x = lo * (hi / lo).powf(i as f64 / steps as f64);
                (x, a * x.powf(b))
            });
            let line: Vec<(f64, f64)> = line.collect();
            let drawn = if s.dashed {
                chart
                    .draw_series(DashedLineSeries::new(line, 8, 5, color.stroke_width(2)))
                    .map_err(|e| e.to_string())?
            } else {
                chart
                    .draw_series(LineSeries::new(line, color.stroke_width(2)))
                    .map_err(|e| e.to_string())?
            };
            if s.points.is_empty() && !s.unlabelled {
                drawn.label(&s.label).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
                });
            }
        }
    }
    Ok(())
}

/// Draws panels side by side into an SVG or PNG file (by extension).
pub fn draw_panels(path: &Path, panels: &[Panel], size: (u32, u32)) -> Result<(), PlotError> {
    register_font();
    let err = |message: String| PlotError {
        path: path.display().to_string(),
        message,
    };
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let n = panels.len().max(1);
    macro_rules! render {
        ($backend:expr) => {{
            let root = $backend.into_drawing_area();
            root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
            let areas = root.split_evenly((1, n));
            for (area, panel) in areas.iter().zip(panels) {
                draw_panel(area, panel).map_err(err)?;
            }
            root.present().map_err(|e| err(e.to_string()))?;
        }};
    }
    match ext.as_str() {
        "svg" => render!(SVGBackend::new(path, size)),
        "png" => render!(BitMapBackend::new(path, size)),
        other => {
            return Err(err(format!(
                "unsupported figure format `.{other}` (use .svg or .png)"
            )));
        }
    }
    Ok(())
}

/// The survey figure: mass and body length against leg length per class, log–log, with
/// each class's fitted power law.
pub fn survey_panels(table: &SurveyTable, t2: &Table2) -> Vec<Panel> {
    let panel = |y: Var, title: &str, y_label: &str| Panel {
        title: title.to_string(),
        x_label: "leg length L [m]".into(),
        y_label: y_label.to_string(),
        series: RobotClass::FITTED
            .into_iter()
            .map(|c| {
                let g = Group::Class(c);
                let fit = t2
                    .fits
                    .iter()
                    .find(|f| f.class == g && f.x == Var::LegLength && f.y == y);
                Series {
                    label: match fit {
                        Some(f) => format!("{} (b = {:.2}, R² = {:.2})", c.label(), f.b, f.r2),
                        None => c.label().to_string(),
                    },
                    color: class_color(c),
                    points: points(table, g, Var::LegLength, y)
                        .into_iter()
                        .map(|p| (p.1, p.2))
                        .collect(),
                    line: fit.map(|f| (f.a, f.b)),
                    line_range: None,
                    band: Vec::new(),
                    ..Default::default()
                }
            })
            .collect(),
        legend: SeriesLabelPosition::UpperLeft,
    };
    vec![
        panel(Var::Mass, "Mass vs leg length", "mass m [kg]"),
        panel(
            Var::BodyLength,
            "Body length vs leg length",
            "body length L_B [m]",
        ),
    ]
}

/// `survey predict --plot`: mass vs leg length with each class's prediction band, the
/// target's prediction and the L² / L³ scaling of the reference.
pub fn prediction_panel(
    table: &SurveyTable,
    pred: &crate::analysis::prediction::Prediction,
) -> Result<Panel, crate::analysis::prediction::PredictError> {
    let all = points(table, Group::All, Var::LegLength, Var::Mass);
    let mut lo = all.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let mut hi = all.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    if let Some(l) = pred.leg_length_m {
        lo = lo.min(l);
        hi = hi.max(l);
    }
    let mut series = Vec::new();
    for c in RobotClass::FITTED {
        let g = Group::Class(c);
        let (law, band) =
            crate::analysis::prediction::mass_band(table, g, pred.confidence, [lo, hi])?;
        series.push(Series {
            label: format!("{} m = {:.3}·L^{:.2}", c.label(), law.a, law.b),
            color: class_color(c),
            points: points(table, g, Var::LegLength, Var::Mass)
                .into_iter()
                .map(|p| (p.1, p.2))
                .collect(),
            line: Some((law.a, law.b)),
            line_range: None,
            band,
            ..Default::default()
        });
    }
    if let (Some(l), Some(q)) = (
        pred.leg_length_m,
        pred.quantities.iter().find(|q| q.quantity == Var::Mass),
    ) {
        series.push(Series {
            label: format!(
                "target L = {l} m: {} fit {} kg",
                pred.class.as_str(),
                super::sig(q.mean)
            ),
            color: BLACK,
            points: vec![(l, q.mean)],
            line: None,
            line_range: None,
            band: Vec::new(),
            ..Default::default()
        });
    }
    if let Some(s) = &pred.scaled_reference {
        let r = &s.reference;
        for (exp, mass, color) in [
            (2.0, s.mass_l2_kg, RGBColor(0xff, 0x7f, 0x0e)),
            (3.0, s.mass_l3_kg, RGBColor(0x8c, 0x56, 0x4b)),
        ] {
            series.push(Series {
                label: format!("{} scaled m ∝ L^{exp:.0}: {} kg", r.name, super::sig(mass)),
                color,
                points: vec![
                    (r.leg_length_m, r.mass_kg),
                    (r.leg_length_m * s.scale_factor, mass),
                ],
                line: Some((r.mass_kg / r.leg_length_m.powf(exp), exp)),
                line_range: None,
                band: Vec::new(),
                ..Default::default()
            });
        }
    }
    Ok(Panel {
        title: format!(
            "Mass vs leg length, {:.0}% prediction bands",
            pred.confidence * 100.0
        ),
        x_label: "leg length L [m]".into(),
        y_label: "mass m [kg]".into(),
        series,
        legend: SeriesLabelPosition::UpperLeft,
    })
}

/// `survey sim scale --plot`: velocity and peak hip torque against leg length, log–log,
/// with the fitted power laws.
pub fn scaling_panels(s: &crate::study::scaling::ScalingStudy) -> Vec<Panel> {
    let walking: Vec<&crate::sim::WalkReport> = s.walks.iter().filter(|w| w.walks).collect();
    let panel = |title: &str,
                 y_label: &str,
                 y: fn(&crate::sim::WalkReport) -> f64,
                 law: &Option<crate::study::scaling::StudyLaw>| Panel {
        title: title.to_string(),
        x_label: "leg length L [m]".into(),
        y_label: y_label.to_string(),
        series: vec![Series {
            label: match law {
                Some(l) => format!("{} (b = {:.3}, R² = {:.3})", s.design, l.b, l.r2),
                None => s.design.clone(),
            },
            color: RGBColor(0x1f, 0x77, 0xb4),
            points: walking.iter().map(|w| (w.leg_length_m, y(w))).collect(),
            line: law.as_ref().map(|l| (l.a, l.b)),
            line_range: None,
            band: Vec::new(),
            ..Default::default()
        }],
        legend: SeriesLabelPosition::UpperLeft,
    };
    vec![
        panel(
            "Walking speed",
            "velocity v [m/s]",
            |w| w.velocity_mps,
            &s.velocity_law,
        ),
        panel(
            "Peak hip torque",
            "peak torque τ [N·m]",
            |w| w.peak_torque_nm,
            &s.torque_law,
        ),
    ]
}

/// The marker of a kind of speed in the Froude figure.
pub fn kind_marker(kind: crate::dataset::SpeedKind) -> Marker {
    use crate::dataset::SpeedKind;
    match kind {
        SpeedKind::Top => Marker::Circle,
        SpeedKind::Typical => Marker::Square,
        SpeedKind::Walking => Marker::Triangle,
        SpeedKind::Running | SpeedKind::Unstated => Marker::Cross,
    }
}

/// The speed report's figure: the Froude number v²/(gL) of every fitted robot's speed
/// against its leg length, log–log, coloured by class, one marker per kind; Froude 1 (the
/// walk–run limit) dashed; each class's top-speed fit v = A·L^b drawn as
/// Fr = (A²/g)·L^(2b − 1), level under dynamic similarity (b = 0.5).
pub fn froude_panel(r: &crate::analysis::speed::SpeedReport) -> Panel {
    use crate::dataset::SpeedKind;
    use crate::dataset::validate::G_MPS2;
    let fitted: Vec<_> = r.points.iter().filter(|p| p.fit).collect();
    let (lo, hi) = fitted
        .iter()
        .map(|p| p.leg_length_m)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), l| {
            (a.min(l), b.max(l))
        });
    let mut series = Vec::new();
    for c in RobotClass::FITTED {
        let color = class_color(c);
        let top = r
            .fits_of(SpeedKind::Top)
            .and_then(|f| f.group(Group::Class(c)))
            .and_then(|g| g.fit.as_ref());
        let mut labelled = top.is_some();
        for kind in SpeedKind::ALL {
            let points: Vec<(f64, f64)> = fitted
                .iter()
                .filter(|p| p.class == c && p.kind == kind)
                .map(|p| (p.leg_length_m, p.froude))
                .collect();
            if points.is_empty() {
                continue;
            }
            series.push(Series {
                label: c.label().to_string(),
                color,
                points,
                marker: kind_marker(kind),
                unlabelled: std::mem::replace(&mut labelled, true),
                ..Default::default()
            });
        }
        if let Some(f) = top {
            let range = fitted
                .iter()
                .filter(|p| p.class == c && p.kind == SpeedKind::Top)
                .map(|p| p.leg_length_m)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), l| {
                    (a.min(l), b.max(l))
                });
            series.push(Series {
                label: format!("{}: top v ∝ L^{:.2}", c.label(), f.b),
                color,
                line: Some((f.a * f.a / G_MPS2, 2.0 * f.b - 1.0)),
                line_range: Some(range),
                ..Default::default()
            });
        }
    }
    if lo.is_finite() && hi > lo {
        series.push(Series {
            label: "Froude 1 (walk–run limit)".into(),
            line: Some((1.0, 0.0)),
            line_range: Some((lo, hi)),
            dashed: true,
            ..Default::default()
        });
    }
    Panel {
        title: format!(
            "Froude number vs leg length, dataset {} (● top, ■ typical, ▲ walking, ✕ running or unstated)",
            r.dataset.version
        ),
        x_label: "leg length L [m]".into(),
        y_label: "Froude number v²/(gL)".into(),
        series,
        legend: SeriesLabelPosition::LowerLeft,
    }
}
