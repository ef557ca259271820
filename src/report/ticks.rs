//! Axis ticks and their labels, for every figure: linear ticks (a walk's plot), log ticks
//! for the plotters figures (labelled 1, 2, (3), 5 × 10^k) and for the hand-written SVG of
//! survey.html (majors at decades, and 2, 5 below three decades). The two log rules differ,
//! each suiting its layout: one rule for both would move ticks in the committed figures.

/// About `n` ticks at 1, 2 or 5 × 10^k steps over [lo, hi].
pub(super) fn linear_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + 1e-9 * span {
        out.push(t);
        t += step;
    }
    out
}

/// A linear tick's label: no decimals for whole numbers, else one or three.
pub(super) fn linear_label(v: f64) -> String {
    if v.abs() >= 100.0 || v == v.round() {
        format!("{v:.0}")
    } else if (v * 10.0).round() == v * 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.3}")
    }
}

/// A tick label with at most 3 significant digits (log axes otherwise print float noise
/// such as 0.30000000000000004).
pub(super) fn log_label(v: f64) -> String {
    let s = super::sig(v);
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Tick positions of a log axis over [lo, hi]: labelled (bold) at 1, 2, 5 × 10^k (with 3
/// added when the axis spans less than 1.5 decades), light grid lines at the other
/// integers × 10^k. plotters' own log key points label every integer of the top decade,
/// which runs the labels together ("0.70.80.91"), and draw a light line per key point,
/// which packs into a grey band near a decade's end.
pub(super) fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut bold, mut light) = (Vec::new(), Vec::new());
    if !(lo > 0.0 && hi > lo && lo.is_finite() && hi.is_finite()) {
        return (bold, light);
    }
    let labelled: &[f64] = if (hi / lo).log10() < 1.5 {
        &[1.0, 2.0, 3.0, 5.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    for k in k0..=k1 {
        let decade = 10f64.powi(k);
        for m in 1..=9 {
            // Rounded to 12 significant digits so labels print as 0.3, not 0.30000000000000004.
            let v = (m as f64 * decade * 1e12).round() / 1e12;
            if v < lo || v > hi {
                continue;
            }
            if labelled.contains(&(m as f64)) {
                bold.push(v);
            } else {
                light.push(v);
            }
        }
    }
    (bold, light)
}

/// (value, major) ticks of a log axis whose ends are `lo`, `hi` in log10 units (the page
/// survey.html): every decade, with 2 and 5 labelled when the axis spans
/// fewer than three decades; minor ticks at the other multiples.
pub(super) fn log_ticks_major_minor(lo: f64, hi: f64) -> Vec<(f64, bool)> {
    let span = hi - lo;
    let mut out = Vec::new();
    for e in (lo.floor() as i32)..=(hi.ceil() as i32) {
        for m in 1..10 {
            let v = f64::from(m) * 10f64.powi(e);
            let lv = v.log10();
            if lv < lo || lv > hi {
                continue;
            }
            let major = m == 1 || (span < 3.0 && (m == 2 || m == 5));
            out.push((v, major));
        }
    }
    out
}
