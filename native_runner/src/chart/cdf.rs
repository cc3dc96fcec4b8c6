//! Cumulative distribution charts: per curve, the share of points (y, 0–100 %) within each
//! distance (x); the x axis ends at a round value above the worst curve's 95th percentile, so
//! the curves stay readable.

use std::fmt::Write as _;

use crate::chart::palette::color;
use crate::chart::panel;
use crate::chart::scale::{nice_max, short_tick_label};
use crate::html::esc;

/// One curve.
#[derive(Debug, Clone)]
pub struct Curve<'a> {
    /// Its name (tooltip).
    pub name: &'a str,
    /// Its colour: the series index.
    pub color: usize,
    /// `(distance, share)` points, shares in [0, 1], distances increasing.
    pub points: &'a [(f64, f64)],
}

/// The chart of `name`'s curves as inline SVG (no XML namespace), ending with a line break.
/// Curves without points are left out.
pub fn svg(name: &str, curves: &[Curve]) -> String {
    let (left, top) = (50.0, panel::TOP);
    let plot_w = panel::WIDTH - left - 30.0;
    let plot_h = panel::HEIGHT - panel::BOTTOM - top;
    let curves: Vec<&Curve> = curves.iter().filter(|c| !c.points.is_empty()).collect();
    // The x range covers the 95th percentile of the worst run, so the curves are readable.
    let xmax = curves
        .iter()
        .filter_map(|c| c.points.iter().find(|(_, y)| *y >= 0.95).map(|(x, _)| *x))
        .fold(0.0f64, f64::max);
    let xmax = nice_max(xmax);
    let mut s = panel::open(
        "cdf",
        &format!("cumulative error {name}"),
        &format!("{name}: share of points within distance (m)"),
    );
    for k in 0..=4 {
        let y = top + plot_h - plot_h * k as f64 / 4.0;
        let xv = left + plot_w * k as f64 / 4.0;
        let _ = write!(
            s,
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#eee\"/><text x=\"{}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"end\">{}%</text><text x=\"{xv:.1}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"middle\">{}</text>",
            left + plot_w,
            left - 4.0,
            y + 3.0,
            25 * k,
            top + plot_h + 14.0,
            short_tick_label(xmax * k as f64 / 4.0)
        );
    }
    for c in curves {
        let pts: Vec<String> = c
            .points
            .iter()
            .map(|(x, y)| {
                format!(
                    "{:.1},{:.1}",
                    left + plot_w * (x / xmax).clamp(0.0, 1.0),
                    top + plot_h - plot_h * y.clamp(0.0, 1.0)
                )
            })
            .collect();
        let _ = write!(
            s,
            "<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"1.6\" points=\"{}\"><title>{}</title></polyline>",
            color(c.color),
            pts.join(" "),
            esc(c.name)
        );
    }
    s.push_str("</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_polyline_per_curve_with_points() {
        let pts = [(0.001, 0.5), (0.004, 0.96), (0.01, 1.0)];
        let s = svg(
            "d",
            &[
                Curve {
                    name: "a",
                    color: 0,
                    points: &pts,
                },
                Curve {
                    name: "empty",
                    color: 1,
                    points: &[],
                },
            ],
        );
        assert_eq!(s.matches("<polyline").count(), 1);
        assert!(s.contains("stroke=\"#1f77b4\""));
        assert!(s.contains(">5.00e-3</text>"), "x axis ends at 0.005: {s}");
    }
}
