//! SVG plot of a walk: attitude and hip angle over time, and the path seen from above.
//!
//! Lines are drawn with plotters; the text is added as plain SVG `<text>` elements
//! afterwards, so no font needs to be loaded or registered (works with any plotters font
//! feature set).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::ticks::{linear_label, linear_ticks};
use crate::sim::{SimError, TrajectorySample};

struct Label {
    x: i32,
    y: i32,
    text: String,
    anchor: &'static str,
    color: &'static str,
    rotate: bool,
}

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Grey grid lines with tick labels (`ticks` per axis) and a black frame over the
/// rectangle [x0, x1] × [y0, y1] of a chart.
fn grid_and_frame(
    c: &mut Chart<'_, '_>,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    ticks: usize,
    labels: &mut Vec<Label>,
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<_>| x.to_string();
    let grey = RGBColor(225, 225, 225);
    for tx in linear_ticks(x0, x1, ticks) {
        c.draw_series(LineSeries::new([(tx, y0), (tx, y1)], &grey))
            .map_err(e)?;
        let (px, py) = c.as_coord_spec().translate(&(tx, y0));
        labels.push(Label {
            x: px,
            y: py + 18,
            text: linear_label(tx),
            anchor: "middle",
            color: "black",
            rotate: false,
        });
    }
    for ty in linear_ticks(y0, y1, ticks) {
        c.draw_series(LineSeries::new([(x0, ty), (x1, ty)], &grey))
            .map_err(e)?;
        let (px, py) = c.as_coord_spec().translate(&(x0, ty));
        labels.push(Label {
            x: px - 6,
            y: py + 4,
            text: linear_label(ty),
            anchor: "end",
            color: "black",
            rotate: false,
        });
    }
    c.draw_series(LineSeries::new(
        [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)],
        &BLACK,
    ))
    .map_err(e)?;
    Ok(())
}
/// (legend, SVG colour, line colour, value) of one time series.
type Series = (
    &'static str,
    &'static str,
    RGBColor,
    fn(&TrajectorySample) -> f64,
);

/// Draws the two panels into `svg` and returns their text, which [`render_svg`] adds as
/// plain SVG elements afterwards.
fn draw(svg: &mut String, samples: &[TrajectorySample], title: &str) -> Result<Vec<Label>, String> {
    let e = |x: DrawingAreaErrorKind<_>| x.to_string();
    let mut labels = Vec::new();
    let root: Area = SVGBackend::with_string(svg, (1150, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let (left, right) = root.split_horizontally(720);
    labels.push(Label {
        x: 20,
        y: 22,
        text: title.to_string(),
        anchor: "start",
        color: "black",
        rotate: false,
    });
    draw_angles(&left, samples, &mut labels)?;
    draw_path(&right, samples, &mut labels)?;
    root.present().map_err(e)?;
    Ok(labels)
}

/// Value range of the series over the samples, padded by 5 % either side ([-1, 1] before
/// padding when nothing finite or no spread), so every curve sits inside the frame.
fn angle_range(samples: &[TrajectorySample], series: &[Series]) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for s in samples {
        for (_, _, _, f) in series {
            let v = f(s);
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
    }
    if !(lo.is_finite() && hi.is_finite()) || hi - lo < 1e-6 {
        lo = -1.0;
        hi = 1.0;
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Left panel: roll, pitch, yaw and hip angle over time, with their legend and axis titles.
fn draw_angles(
    area: &Area<'_>,
    samples: &[TrajectorySample],
    labels: &mut Vec<Label>,
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<_>| x.to_string();
    let t0 = samples.first().map(|s| s.t_s).unwrap_or(0.0);
    let t1 = samples.last().map(|s| s.t_s).unwrap_or(1.0).max(t0 + 1e-6);
    let series: [Series; 4] = [
        ("roll", "#d62728", RGBColor(214, 39, 40), |s| s.roll_deg),
        ("pitch", "#1f77b4", RGBColor(31, 119, 180), |s| s.pitch_deg),
        ("yaw", "#2ca02c", RGBColor(44, 160, 44), |s| s.yaw_deg),
        ("hip angle", "#7f7f7f", RGBColor(127, 127, 127), |s| {
            s.hip_angle_deg
        }),
    ];
    let (lo, hi) = angle_range(samples, &series);
    let mut c = ChartBuilder::on(area)
        .margin_left(70)
        .margin_right(20)
        .margin_top(60)
        .margin_bottom(50)
        .build_cartesian_2d(t0..t1, lo..hi)
        .map_err(e)?;
    grid_and_frame(&mut c, (t0, t1), (lo, hi), 8, labels)?;
    for (i, (name, hex, col, f)) in series.iter().enumerate() {
        c.draw_series(LineSeries::new(samples.iter().map(|s| (s.t_s, f(s))), col))
            .map_err(e)?;
        labels.push(Label {
            x: 90 + 130 * i as i32,
            y: 48,
            text: format!("— {name}"),
            anchor: "start",
            color: hex,
            rotate: false,
        });
    }
    let (px, py) = c.as_coord_spec().translate(&(0.5 * (t0 + t1), lo));
    labels.push(Label {
        x: px,
        y: py + 38,
        text: "time [s]".into(),
        anchor: "middle",
        color: "black",
        rotate: false,
    });
    let (_, py) = c.as_coord_spec().translate(&(t0, 0.5 * (lo + hi)));
    labels.push(Label {
        x: 22,
        y: py,
        text: "angle [deg] (hip frame)".into(),
        anchor: "middle",
        color: "black",
        rotate: true,
    });
    Ok(())
}

/// Square window (x0, x1, y0, y1) around the path, 10 % wider than its larger extent, so
/// the top view keeps equal axes.
fn path_window(xs: &[f64], ys: &[f64]) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let (mut y0, mut y1) = ys
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !(x0.is_finite() && y0.is_finite()) {
        (x0, x1, y0, y1) = (-1.0, 1.0, -1.0, 1.0);
    }
    let span = (x1 - x0).max(y1 - y0).max(1e-3) * 1.1;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    (
        cx - 0.5 * span,
        cx + 0.5 * span,
        cy - 0.5 * span,
        cy + 0.5 * span,
    )
}

/// Right panel: the hip point's path seen from above, on equal axes, with axis titles.
fn draw_path(
    area: &Area<'_>,
    samples: &[TrajectorySample],
    labels: &mut Vec<Label>,
) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<_>| x.to_string();
    let xs: Vec<f64> = samples.iter().map(|s| s.x_m).collect();
    let ys: Vec<f64> = samples.iter().map(|s| s.y_m).collect();
    let (x0, x1, y0, y1) = path_window(&xs, &ys);
    let mut p = ChartBuilder::on(area)
        .margin_left(70)
        .margin_right(20)
        .margin_top(60)
        .margin_bottom(50)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    grid_and_frame(&mut p, (x0, x1), (y0, y1), 5, labels)?;
    p.draw_series(LineSeries::new(
        xs.iter().copied().zip(ys.iter().copied()),
        &RGBColor(148, 103, 189),
    ))
    .map_err(e)?;
    let (px, py) = p.as_coord_spec().translate(&(0.5 * (x0 + x1), y0));
    labels.push(Label {
        x: px,
        y: py + 38,
        text: "x [m] (hip point, seen from above)".into(),
        anchor: "middle",
        color: "black",
        rotate: false,
    });
    let (px0, py) = p.as_coord_spec().translate(&(x0, 0.5 * (y0 + y1)));
    labels.push(Label {
        x: px0 - 55,
        y: py,
        text: "y [m]".into(),
        anchor: "middle",
        color: "black",
        rotate: true,
    });
    Ok(())
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Renders the plot to an SVG string.
pub fn render_svg(samples: &[TrajectorySample], title: &str) -> Result<String, String> {
    let mut svg = String::new();
    let labels = draw(&mut svg, samples, title)?;
    let mut text = String::new();
    for l in labels {
        let rot = if l.rotate {
            format!(" transform=\"rotate(-90 {} {})\"", l.x, l.y)
        } else {
            String::new()
        };
        text.push_str(&format!(
            "<text x=\"{}\" y=\"{}\" font-family=\"sans-serif\" font-size=\"13\" fill=\"{}\" text-anchor=\"{}\"{}>{}</text>\n",
            l.x,
            l.y,
            l.color,
            l.anchor,
            rot,
            escape(&l.text)
        ));
    }
    match svg.rfind("</svg>") {
        Some(i) => svg.insert_str(i, &text),
        None => return Err("plotters produced no </svg> tag".into()),
    }
    Ok(svg)
}

/// Writes the plot to `path`.
pub fn write_plot_svg(
    samples: &[TrajectorySample],
    title: &str,
    path: &Path,
) -> Result<(), SimError> {
    let out = |message: String| SimError::Output {
        path: path.to_path_buf(),
        message,
    };
    let svg = render_svg(samples, title).map_err(out)?;
    std::fs::write(path, svg).map_err(|e| out(e.to_string()))
}
