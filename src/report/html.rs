//! The interactive survey figure: one self-contained HTML page (inline SVG, inline CSS and
//! a small inline script; nothing fetched at view time) with the three log–log panels of
//! Table 2 and a fourth of top speed against leg length (with Froude 1, the walk–run limit,
//! dashed). Every robot with both values of a panel is one point, coloured by class;
//! robots excluded from the fits are grey and carry their exclusion reason. Each class's
//! fitted power law is drawn over its data range with the confidence band of the fitted
//! line (the OLS mean interval of [`crate::regression::predict_ols`], back-transformed).
//! The points, lines and bands are computed by [`crate::analysis::figure`]; this module
//! only writes them as HTML and SVG.
//!
//! Each point is an SVG `<circle class="pt">` whose `data-*` attributes hold the robot's
//! id, name, class, fit status, exclusion and its leg length, body length and mass as the
//! compiled table writes them, and its speeds by kind (`data-speeds-mps`, "top=1.6;…"); the
//! hover tooltip is built from those attributes (with each speed's Froude number).

use std::fmt::Write as _;

use super::ticks::{log_label, log_ticks_major_minor};
use crate::analysis::figure::{FigurePanel, FigurePoint, SurveyFigure};
use crate::analysis::table2::Var;
use crate::dataset::RobotClass;
use crate::regression::Method;

/// HTML-escapes text for element content and quoted attribute values.
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

fn hex(c: RobotClass) -> String {
    let rgb = super::plot::class_color(c);
    format!("#{:02x}{:02x}{:02x}", rgb.0, rgb.1, rgb.2)
}

/// Panel geometry (SVG user units).
const W: f64 = 440.0;
const H: f64 = 420.0;
const LEFT: f64 = 64.0;
const RIGHT: f64 = 14.0;
const TOP: f64 = 14.0;
const BOTTOM: f64 = 46.0;

/// A log10 axis: data range (log10 units) to pixels.
struct Axis {
    lo: f64,
    hi: f64,
    p0: f64,
    p1: f64,
}

impl Axis {
    fn new(values: impl Iterator<Item = f64>, p0: f64, p1: f64) -> Self {
        let (mut lo, mut hi) = values
            .filter(|v| v.is_finite() && *v > 0.0)
            .map(f64::log10)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if !(lo.is_finite() && hi.is_finite()) {
            (lo, hi) = (-2.0, 0.0);
        }
        let pad = ((hi - lo) * 0.06).max(0.1);
        Axis {
            lo: lo - pad,
            hi: hi + pad,
            p0,
            p1,
        }
    }
    fn px(&self, v: f64) -> f64 {
        self.p0 + (v.log10() - self.lo) / (self.hi - self.lo) * (self.p1 - self.p0)
    }
    fn ticks(&self) -> Vec<(f64, bool)> {
        log_ticks_major_minor(self.lo, self.hi)
    }
}

/// Axis title: "leg length L [m]", "top speed v [m/s]".
fn var_label(v: Var) -> String {
    format!("{} {} [{}]", v.label(), v.symbol(), v.unit())
}

/// Caption word: "Leg length", "Top speed".
fn title_case(v: Var) -> String {
    let label = v.label();
    let mut chars = label.chars();
    match chars.next() {
        Some(c) => c.to_uppercase().chain(chars).collect(),
        None => String::new(),
    }
}

fn panel_svg(out: &mut String, index: usize, p: &FigurePanel, confidence: f64) {
    let (xa, ya) = panel_axes(p);
    panel_open(out, index, p);
    grid_svg(out, &xa, &ya);
    frame_svg(out, p);
    lines_svg(out, index, p, &xa, &ya, confidence);
    references_svg(out, index, p, &xa, &ya);
    points_svg(out, p, &xa, &ya);
    fits_key(out, p);
    missing_list(out, p);
    out.push_str("</figure>\n");
}

/// The axes of a panel: over its points and lines (x) and its points and bands (y).
fn panel_axes(p: &FigurePanel) -> (Axis, Axis) {
    let xa = Axis::new(
        p.points
            .iter()
            .map(|q| q.x)
            .chain(p.lines.iter().flat_map(|l| [l.x_range.0, l.x_range.1])),
        LEFT,
        W - RIGHT,
    );
    let ya = Axis::new(
        p.points.iter().map(|q| q.y).chain(
            p.lines
                .iter()
                .flat_map(|l| l.band.iter().flat_map(|b| [b.1, b.2])),
        ),
        H - BOTTOM,
        TOP,
    );
    (xa, ya)
}

/// The panel's caption, the opening `<svg>` and its clip path.
fn panel_open(out: &mut String, index: usize, p: &FigurePanel) {
    let rel = format!("{} ∝ {}^b", p.y.symbol(), p.x.symbol());
    let _ = write!(
        out,
        "<figure class=\"panel\" id=\"panel-{index}\">\n<figcaption>{} vs {}: {}</figcaption>\n<svg class=\"plot\" viewBox=\"0 0 {W} {H}\" role=\"img\" aria-label=\"{} against {}, log–log\" data-x=\"{}\" data-y=\"{}\" data-relation=\"{}\">\n",
        title_case(p.y),
        p.x.as_str().replace('_', " "),
        esc(&rel),
        esc(&var_label(p.y)),
        esc(&var_label(p.x)),
        p.x.as_str(),
        p.y.as_str(),
        esc(&rel)
    );
    let _ = writeln!(
        out,
        "<defs><clipPath id=\"clip-{index}\"><rect x=\"{LEFT}\" y=\"{TOP}\" width=\"{}\" height=\"{}\"/></clipPath></defs>",
        W - LEFT - RIGHT,
        H - TOP - BOTTOM
    );
}

fn grid_svg(out: &mut String, xa: &Axis, ya: &Axis) {
    // Grid and ticks.
    out.push_str("<g class=\"grid\">\n");
    for (v, major) in xa.ticks() {
        let x = xa.px(v);
        let _ = writeln!(
            out,
            "<line x1=\"{x:.2}\" y1=\"{TOP}\" x2=\"{x:.2}\" y2=\"{:.2}\" class=\"{}\"/>",
            H - BOTTOM,
            if major { "major" } else { "minor" }
        );
        if major {
            let _ = writeln!(
                out,
                "<text x=\"{x:.2}\" y=\"{:.2}\" class=\"tick\" text-anchor=\"middle\">{}</text>",
                H - BOTTOM + 16.0,
                log_label(v)
            );
        }
    }
    for (v, major) in ya.ticks() {
        let y = ya.px(v);
        let _ = writeln!(
            out,
            "<line x1=\"{LEFT}\" y1=\"{y:.2}\" x2=\"{:.2}\" y2=\"{y:.2}\" class=\"{}\"/>",
            W - RIGHT,
            if major { "major" } else { "minor" }
        );
        if major {
            let _ = writeln!(
                out,
                "<text x=\"{:.2}\" y=\"{:.2}\" class=\"tick\" text-anchor=\"end\">{}</text>",
                LEFT - 6.0,
                y + 4.0,
                log_label(v)
            );
        }
    }
    out.push_str("</g>\n");
}

/// The frame and the axis titles.
fn frame_svg(out: &mut String, p: &FigurePanel) {
    let _ = writeln!(
        out,
        "<rect class=\"frame\" x=\"{LEFT}\" y=\"{TOP}\" width=\"{}\" height=\"{}\"/>",
        W - LEFT - RIGHT,
        H - TOP - BOTTOM
    );
    let _ = writeln!(
        out,
        "<text class=\"axis\" x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
        (LEFT + W - RIGHT) / 2.0,
        H - 8.0,
        esc(&var_label(p.x))
    );
    let _ = writeln!(
        out,
        "<text class=\"axis\" transform=\"translate(16 {:.1}) rotate(-90)\" text-anchor=\"middle\">{}</text>",
        (TOP + H - BOTTOM) / 2.0,
        esc(&var_label(p.y))
    );
}

fn lines_svg(
    out: &mut String,
    index: usize,
    p: &FigurePanel,
    xa: &Axis,
    ya: &Axis,
    confidence: f64,
) {
    // Bands and lines, clipped to the plot area.
    let _ = writeln!(out, "<g clip-path=\"url(#clip-{index})\">");
    for l in &p.lines {
        let color = hex(l.class);
        if !l.band.is_empty() {
            let mut d = String::new();
            for (i, (x, _, hi)) in l.band.iter().enumerate() {
                let _ = write!(
                    d,
                    "{}{:.2},{:.2}",
                    if i == 0 { "M" } else { " L" },
                    xa.px(*x),
                    ya.px(*hi)
                );
            }
            for (x, lo, _) in l.band.iter().rev() {
                let _ = write!(d, " L{:.2},{:.2}", xa.px(*x), ya.px(*lo));
            }
            d.push_str(" Z");
            let _ = writeln!(
                out,
                "<path class=\"band\" data-class=\"{}\" d=\"{d}\" fill=\"{color}\"><title>{} {:.0}% confidence band of the fitted line</title></path>",
                l.class.as_str(),
                esc(l.class.label()),
                confidence * 100.0
            );
        }
        let (x0, x1) = l.x_range;
        let _ = writeln!(
            out,
            "<line class=\"fit\" data-class=\"{}\" data-a=\"{}\" data-b=\"{}\" x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"{color}\"><title>{}: {} = {:.4}·{}^{:.3}, R² = {:.3}, n = {}</title></line>",
            l.class.as_str(),
            l.fit.a,
            l.fit.b,
            xa.px(x0),
            ya.px(l.fit.a * x0.powf(l.fit.b)),
            xa.px(x1),
            ya.px(l.fit.a * x1.powf(l.fit.b)),
            esc(l.class.label()),
            p.y.symbol(),
            l.fit.a,
            p.x.symbol(),
            l.fit.b,
            l.fit.r2,
            l.fit.n
        );
    }
    out.push_str("</g>\n");
}

/// Reference laws (not fitted), dashed across the panel and clipped to it.
fn references_svg(out: &mut String, index: usize, p: &FigurePanel, xa: &Axis, ya: &Axis) {
    if p.references.is_empty() {
        return;
    }
    let _ = writeln!(out, "<g clip-path=\"url(#clip-{index})\">");
    let (x0, x1) = (10f64.powf(xa.lo), 10f64.powf(xa.hi));
    for r in &p.references {
        let _ = writeln!(
            out,
            "<line class=\"reference\" data-a=\"{}\" data-b=\"{}\" x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\"><title>{}</title></line>",
            r.a,
            r.b,
            xa.px(x0),
            ya.px(r.a * x0.powf(r.b)),
            xa.px(x1),
            ya.px(r.a * x1.powf(r.b)),
            esc(&r.label)
        );
    }
    out.push_str("</g>\n");
}

/// The robots (closing the `<svg>`).
fn points_svg(out: &mut String, p: &FigurePanel, xa: &Axis, ya: &Axis) {
    // Points: excluded (grey) first, fitted on top.
    let mut order: Vec<&FigurePoint> = p.points.iter().collect();
    order.sort_by_key(|q| q.fit);
    out.push_str("<g class=\"points\">\n");
    for q in order {
        let fill = if q.fit {
            hex(q.class)
        } else {
            "#b4b4b4".to_string()
        };
        let v = |i: usize| q.values[i].as_deref().unwrap_or("");
        let speeds = q
            .speeds
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(";");
        let _ = writeln!(
            out,
            "<circle class=\"pt{}\" tabindex=\"0\" cx=\"{:.2}\" cy=\"{:.2}\" r=\"{}\" fill=\"{fill}\" data-id=\"{}\" data-name=\"{}\" data-class=\"{}\" data-class-label=\"{}\" data-fit=\"{}\" data-exclusion=\"{}\" data-leg-length-m=\"{}\" data-body-length-m=\"{}\" data-mass-kg=\"{}\" data-speeds-mps=\"{}\"/>",
            if q.fit { "" } else { " excluded" },
            xa.px(q.x),
            ya.px(q.y),
            if q.fit { 4.5 } else { 4.0 },
            esc(&q.id),
            esc(&q.name),
            q.class.as_str(),
            esc(q.class.label()),
            q.fit,
            esc(q.exclusion.as_deref().unwrap_or("")),
            esc(v(0)),
            esc(v(1)),
            esc(v(2)),
            esc(&speeds),
        );
    }
    out.push_str("</g>\n</svg>\n");
}

fn fits_key(out: &mut String, p: &FigurePanel) {
    // The fits of the panel, as a compact key.
    out.push_str("<ul class=\"fits\">\n");
    for l in &p.lines {
        let _ = writeln!(
            out,
            "<li><span class=\"swatch\" style=\"background:{}\"></span>{}: b = {:.2} [{:.2}, {:.2}], R² = {:.3}, n = {}</li>",
            hex(l.class),
            esc(l.class.label()),
            l.fit.b,
            l.fit.b_ci[0],
            l.fit.b_ci[1],
            l.fit.r2,
            l.fit.n
        );
    }
    if let Some(f) = &p.all {
        let _ = writeln!(
            out,
            "<li><span class=\"swatch\"></span>All classes (not drawn): b = {:.2} [{:.2}, {:.2}], R² = {:.3}, n = {}</li>",
            f.b, f.b_ci[0], f.b_ci[1], f.r2, f.n
        );
    }
    for r in &p.references {
        let _ = writeln!(
            out,
            "<li><span class=\"swatch dashed\"></span>{}</li>",
            esc(&r.label)
        );
    }
    out.push_str("</ul>\n");
}

fn missing_list(out: &mut String, p: &FigurePanel) {
    if !p.missing.is_empty() {
        let _ = writeln!(
            out,
            "<details class=\"missing\"><summary>{} robot(s) not in this panel (missing value)</summary><ul>",
            p.missing.len()
        );
        for (id, name, why) in &p.missing {
            let _ = writeln!(
                out,
                "<li data-id=\"{}\">{} <span class=\"why\">({})</span></li>",
                esc(id),
                esc(name),
                esc(why)
            );
        }
        out.push_str("</ul></details>\n");
    }
}

const STYLE: &str = r#"
body { font-family: "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; margin: 18px 24px; color: #222; }
h1 { font-size: 20px; margin: 0 0 4px; }
p.meta { font-size: 13px; color: #555; margin: 0 0 10px; }
.legend { font-size: 13px; margin: 0 0 8px; display: flex; flex-wrap: wrap; gap: 14px; align-items: center; }
.legend span { display: inline-flex; align-items: center; gap: 5px; }
.dot { width: 10px; height: 10px; border-radius: 50%; display: inline-block; }
.panels { display: grid; grid-template-columns: repeat(2, minmax(0, 1fr)); gap: 12px; max-width: 1100px; }
@media (max-width: 900px) { .panels { grid-template-columns: minmax(0, 1fr); max-width: 560px; } }
figure.panel { margin: 0; min-width: 0; }
figcaption { font-weight: bold; font-size: 15px; text-align: center; margin-bottom: 2px; }
svg.plot { width: 100%; height: auto; display: block; }
.grid line.major { stroke: #d0d0d0; stroke-width: 1; }
.grid line.minor { stroke: #ededed; stroke-width: 1; }
text.tick { font-size: 11px; fill: #444; }
text.axis { font-size: 13px; fill: #222; }
rect.frame { fill: none; stroke: #666; stroke-width: 1; }
path.band { fill-opacity: 0.16; stroke: none; }
line.fit { stroke-width: 2; }
line.reference { stroke: #555; stroke-width: 1.2; stroke-dasharray: 6 4; }
.swatch.dashed { border-top: 2px dashed #555; height: 0; }
circle.pt { stroke: #fff; stroke-width: 0.8; cursor: pointer; }
circle.pt.excluded { stroke: #777; stroke-width: 0.8; fill-opacity: 0.75; }
circle.pt:hover, circle.pt:focus, circle.pt.hi { stroke: #000; stroke-width: 2; outline: none; }
ul.fits { list-style: none; padding: 0; margin: 4px 0 0 12px; font-size: 12px; }
ul.fits li { margin: 1px 0; }
.swatch { display: inline-block; width: 14px; height: 3px; margin-right: 6px; vertical-align: middle; }
details.missing { font-size: 12px; color: #555; margin: 4px 0 0 12px; }
details.missing ul { margin: 2px 0; padding-left: 18px; }
#tip { position: fixed; pointer-events: none; background: #fff; border: 1px solid #888; border-radius: 4px;
  box-shadow: 0 2px 6px rgba(0,0,0,.2); padding: 6px 8px; font-size: 12px; line-height: 1.45; max-width: 340px; display: none; z-index: 10; }
#tip b { font-size: 13px; }
#tip .ex { color: #8a4b00; }
"#;

/// Tooltip: built with textContent from the point's data attributes (no HTML injection).
/// Hovering or focusing a point also highlights the same robot in the other panels.
const SCRIPT: &str = r#"
(function () {
  var tip = document.getElementById('tip');
  function line(label, value, unit) {
    var d = document.createElement('div');
    d.textContent = label + ': ' + (value ? value + ' ' + unit : '–');
    return d;
  }
  function show(pt, x, y) {
    var s = pt.dataset;
    tip.textContent = '';
    var b = document.createElement('b');
    b.textContent = s.name;
    tip.appendChild(b);
    var c = document.createElement('div');
    c.textContent = s.classLabel + ' (' + s.id + ')';
    tip.appendChild(c);
    tip.appendChild(line('leg length L', s.legLengthM, 'm'));
    tip.appendChild(line('body length L_B', s.bodyLengthM, 'm'));
    tip.appendChild(line('mass m', s.massKg, 'kg'));
    var legM = parseFloat(s.legLengthM);
    (s.speedsMps || '').split(';').filter(Boolean).forEach(function (kv) {
      var parts = kv.split('='), v = parseFloat(parts[1]);
      var d = document.createElement('div');
      var fr = legM > 0 ? ', Froude ' + (v * v / (9.80665 * legM)).toPrecision(2) : '';
      d.textContent = parts[0] + ' speed v: ' + parts[1] + ' m/s' + fr;
      tip.appendChild(d);
    });
    if (s.fit !== 'true') {
      var e = document.createElement('div');
      e.className = 'ex';
      e.textContent = 'excluded from the fits: ' + (s.exclusion || 'no reason given');
      tip.appendChild(e);
    }
    tip.style.display = 'block';
    var w = tip.offsetWidth, h = tip.offsetHeight;
    var left = x + 14, top = y + 14;
    if (left + w > window.innerWidth - 4) left = x - w - 14;
    if (top + h > window.innerHeight - 4) top = y - h - 14;
    tip.style.left = Math.max(4, left) + 'px';
    tip.style.top = Math.max(4, top) + 'px';
    document.querySelectorAll('circle.pt').forEach(function (o) {
      o.classList.toggle('hi', o.dataset.id === s.id);
    });
  }
  function hide() {
    tip.style.display = 'none';
    document.querySelectorAll('circle.pt.hi').forEach(function (o) { o.classList.remove('hi'); });
  }
  document.querySelectorAll('circle.pt').forEach(function (pt) {
    pt.addEventListener('mousemove', function (ev) { show(pt, ev.clientX, ev.clientY); });
    pt.addEventListener('mouseleave', hide);
    pt.addEventListener('focus', function () {
      var r = pt.getBoundingClientRect();
      show(pt, r.right, r.bottom);
    });
    pt.addEventListener('blur', hide);
  });
})();
"#;

/// The figure as one self-contained HTML page.
pub fn survey_html(fig: &SurveyFigure) -> String {
    let pct = fig.confidence * 100.0;
    let mut out = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n",
    );
    let _ = writeln!(
        out,
        "<title>Legged-robot survey, dataset {}: Table 2 power laws and top speed</title>",
        esc(&fig.version)
    );
    let _ = writeln!(out, "<style>{STYLE}</style>\n</head>\n<body>");
    let _ = writeln!(
        out,
        "<h1>Allometry of legged robots: the power laws of Table 2 and top speed</h1>\n<p class=\"meta\">Dataset {} ({}), sha256 <code>{}</code>. {} fit of log<sub>10</sub> y on log<sub>10</sub> x per class{}; the speed panel shows each robot's top speed (the highest it is reported to reach), with Froude 1 dashed. Generated by <code>survey fit --out</code>. Hover or focus a point for its values.</p>",
        esc(&fig.version),
        if fig.frozen {
            "frozen release"
        } else {
            "live records"
        },
        esc(&fig.sha256),
        fig.method.label(),
        if fig.method == Method::Ols {
            format!("; shaded: {pct:.0}% confidence band of the fitted line")
        } else {
            String::new()
        }
    );
    out.push_str("<div class=\"legend\">");
    for c in RobotClass::FITTED {
        let _ = write!(
            out,
            "<span><i class=\"dot\" style=\"background:{}\"></i>{}</span>",
            hex(c),
            esc(c.label())
        );
    }
    out.push_str("<span><i class=\"dot\" style=\"background:#b4b4b4;border:1px solid #777\"></i>excluded from the fits (any class)</span></div>\n<div class=\"panels\">\n");
    for (i, p) in fig.panels.iter().enumerate() {
        panel_svg(&mut out, i, p, fig.confidence);
    }
    out.push_str("</div>\n<div id=\"tip\" role=\"tooltip\"></div>\n");
    let _ = writeln!(out, "<script>{SCRIPT}</script>\n</body>\n</html>");
    out
}
