//! The toolbox's precision/recall plot (`plot.py`'s `plot_graph`): the two cumulative curves in
//! percent over the distance in the scene's unit, τ as a dashed line, the axes `[0, τ·stretch]`
//! by `[0, 100]`, the title `Precision and Recall: <scene>, <F·100> f-score`, written as an SVG
//! document (and, with the `png` feature, rasterised from it). Named as the toolbox names it:
//! `PR_<scene>_@d_th_0_<τ·10000 as %04d>`.

use std::fmt::Write as _;

use crate::report::TntReport;

/// Width and height of the plot in CSS pixels (the PNG's size in pixels).
pub const PLOT_SIZE: (u32, u32) = (720, 480);

const LEFT: f64 = 70.0;
const RIGHT: f64 = 150.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 55.0;

/// The toolbox's file stem for the plot: `PR_<scene>_@d_th_0_<%04d of τ·10000>` (Python's
/// `"%04d" % x` truncates toward zero).
pub fn plot_stem(scene: &str, tau: f64) -> String {
    let code = (tau * 10000.0).trunc();
    let code = if code.is_finite() && code >= 0.0 {
        code as u64
    } else {
        0
    };
    format!("PR_{scene}_@d_th_0_{code:04}")
}

/// The precision/recall plot of a report as an SVG document.
pub fn pr_svg(report: &TntReport) -> String {
    let (width, height) = (f64::from(PLOT_SIZE.0), f64::from(PLOT_SIZE.1));
    let tau = report.protocol.tau;
    let x_max = tau * report.protocol.evaluation.plot_stretch;
    let (plot_w, plot_h) = (width - LEFT - RIGHT, height - TOP - BOTTOM);
    let px = |x: f64| LEFT + if x_max > 0.0 { x / x_max } else { 0.0 } * plot_w;
    let py = |percent: f64| TOP + (1.0 - percent / 100.0) * plot_h;
    let mut s = String::with_capacity(16 * 1024);
    let _ = write!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif">
<rect width="{w}" height="{h}" fill="#ffffff"/>
<text x="{tx}" y="24" font-size="15" text-anchor="middle">{title}</text>
<defs><clipPath id="axes"><rect x="{LEFT}" y="{TOP}" width="{plot_w}" height="{plot_h}"/></clipPath></defs>
"##,
        w = PLOT_SIZE.0,
        h = PLOT_SIZE.1,
        tx = LEFT + plot_w / 2.0,
        title = esc(&format!(
            "Precision and Recall: {}, {:.2} f-score",
            report.protocol.scene,
            report.f_score * 100.0
        )),
    );
    // Grid and ticks.
    for x in ticks(x_max) {
        let _ = writeln!(
            s,
            r##"<line x1="{p:.2}" y1="{TOP}" x2="{p:.2}" y2="{b}" stroke="#b0b0b0" stroke-width="0.8"/><text x="{p:.2}" y="{ty}" font-size="11" text-anchor="middle">{label}</text>"##,
            p = px(x),
            b = TOP + plot_h,
            ty = TOP + plot_h + 16.0,
            label = tick_label(x),
        );
    }
    for y in [0.0, 20.0, 40.0, 60.0, 80.0, 100.0] {
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{p:.2}" x2="{r}" y2="{p:.2}" stroke="#b0b0b0" stroke-width="0.8"/><text x="{tx}" y="{ty:.2}" font-size="11" text-anchor="end">{y}</text>"##,
            p = py(y),
            r = LEFT + plot_w,
            tx = LEFT - 6.0,
            ty = py(y) + 4.0,
        );
    }
    // The curves: the toolbox plots cum[k] at edges[k + 1].
    let edges = &report.curves.edges;
    for (curve, colour) in [
        (&report.curves.precision, "#ff0000"),
        (&report.curves.recall, "#0000ff"),
    ] {
        let mut d = String::new();
        for (k, (x, c)) in edges.iter().skip(1).zip(curve.iter()).enumerate() {
            let _ = write!(
                d,
                "{}{:.2},{:.2}",
                if k == 0 { "M" } else { " L" },
                px(*x),
                py(c * 100.0)
            );
        }
        if !d.is_empty() {
            let _ = writeln!(
                s,
                r##"<path d="{d}" fill="none" stroke="{colour}" stroke-width="2" clip-path="url(#axes)"/>"##
            );
        }
    }
    let _ = writeln!(
        s,
        r##"<line x1="{p:.2}" y1="{TOP}" x2="{p:.2}" y2="{b}" stroke="#000000" stroke-width="2" stroke-dasharray="7,3" clip-path="url(#axes)"/>"##,
        p = px(tau),
        b = TOP + plot_h,
    );
    let legend_x = LEFT + plot_w + 14.0;
    let legend_y = TOP + plot_h / 2.0 - 22.0;
    let _ = write!(
        s,
        r##"<rect x="{LEFT}" y="{TOP}" width="{plot_w}" height="{plot_h}" fill="none" stroke="#000000" stroke-width="1"/>
<text x="{xl}" y="{yl}" font-size="14" text-anchor="middle">Meters</text>
<text x="18" y="{ym}" font-size="14" text-anchor="middle" transform="rotate(-90 18 {ym})"># of points (%)</text>
<rect x="{legend_x}" y="{legend_y}" width="118" height="48" fill="#ffffff" stroke="#cccccc"/>
<line x1="{l1}" y1="{r1}" x2="{l2}" y2="{r1}" stroke="#ff0000" stroke-width="2"/><text x="{lt}" y="{t1}" font-size="12">precision</text>
<line x1="{l1}" y1="{r2}" x2="{l2}" y2="{r2}" stroke="#0000ff" stroke-width="2"/><text x="{lt}" y="{t2}" font-size="12">recall</text>
</svg>
"##,
        xl = LEFT + plot_w / 2.0,
        yl = height - 14.0,
        ym = TOP + plot_h / 2.0,
        l1 = legend_x + 8.0,
        l2 = legend_x + 34.0,
        lt = legend_x + 42.0,
        r1 = legend_y + 16.0,
        t1 = legend_y + 20.0,
        r2 = legend_y + 34.0,
        t2 = legend_y + 38.0,
    );
    s
}

/// The plot rasterised at [`PLOT_SIZE`] and encoded as PNG, with the system's fonts for its
/// labels; `None` when the system has no font (the SVG is then the plot) or the SVG does not
/// render.
#[cfg(feature = "png")]
pub fn svg_to_png(svg: &str) -> Option<Vec<u8>> {
    use resvg::{tiny_skia, usvg};
    let mut options = usvg::Options::default();
    options.fontdb_mut().load_system_fonts();
    if options.fontdb.is_empty() {
        return None;
    }
    let tree = usvg::Tree::from_str(svg, &options).ok()?;
    let mut pixmap = tiny_skia::Pixmap::new(PLOT_SIZE.0, PLOT_SIZE.1)?;
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    pixmap.encode_png().ok()
}

/// Tick positions over `[0, max]`: multiples of 1, 2 or 5 × 10^k, about five of them.
fn ticks(max: f64) -> Vec<f64> {
    if !(max.is_finite() && max > 0.0) {
        return vec![0.0];
    }
    let raw = max / 5.0;
    let magnitude = libm::pow(10.0, libm::floor(libm::log10(raw)));
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * magnitude);
    let count = libm::floor(max / step * (1.0 + 1e-9)) as usize;
    (0..=count).map(|i| i as f64 * step).collect()
}

/// A tick's label: the shortest decimal that reads back as the tick (ticks are multiples of
/// a round step, so this is short).
fn tick_label(x: f64) -> String {
    let rounded = libm::round(x * 1e9) / 1e9;
    format!("{rounded}")
}

fn esc(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stem_is_the_toolboxs() {
        // The toolbox: "PR_{0}_@d_th_0_{1}".format(scene, "%04d" % (tau * 10000))
        assert_eq!(plot_stem("Barn", 0.01), "PR_Barn_@d_th_0_0100");
        assert_eq!(plot_stem("Ignatius", 0.003), "PR_Ignatius_@d_th_0_0030");
        assert_eq!(
            plot_stem("Meetingroom", 0.01),
            "PR_Meetingroom_@d_th_0_0100"
        );
        assert_eq!(plot_stem("x", 0.00005), "PR_x_@d_th_0_0000");
        assert_eq!(plot_stem("x", 1.5), "PR_x_@d_th_0_15000");
    }

    #[test]
    fn ticks_are_round_and_cover_the_axis() {
        assert_eq!(ticks(0.05), vec![0.0, 0.01, 0.02, 0.03, 0.04, 0.05]);
        let t = ticks(0.015);
        assert_eq!(t.first(), Some(&0.0));
        assert!(
            *t.last().unwrap_or(&0.0) <= 0.015 + 1e-12 && t.len() >= 4,
            "{t:?}"
        );
        assert_eq!(ticks(f64::NAN), vec![0.0]);
        assert_eq!(tick_label(0.1 + 0.2), "0.3");
    }
}
