//! Line charts: one line per series over a numeric x axis. A point that has no value is
//! drawn, not dropped: a red × (the run failed or was not run) or a grey ○ (the run succeeded
//! but this metric has no finite value) in a band below the axis, one row per series, with a
//! `<title>` tooltip saying why.

use std::fmt::Write as _;

use crate::chart::palette::{FAIL_COLOR, color};
use crate::chart::scale::{tick_label, y_scale};
use crate::chart::value::Value;
use crate::html::esc;

/// One line.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend name.
    pub name: String,
    /// `(x, value)` in x order.
    pub points: Vec<(f64, Value)>,
}

/// A chart.
#[derive(Debug, Clone)]
pub struct Chart {
    /// Title (the metric's label).
    pub title: String,
    /// Secondary line under the title (the metric path).
    pub subtitle: String,
    /// X axis label (the factor).
    pub x_label: String,
    /// X tick positions and labels (the sweep's values).
    pub x_ticks: Vec<(f64, String)>,
    /// Lines.
    pub series: Vec<Series>,
}

const W: f64 = 520.0;
const ML: f64 = 70.0;
const MR: f64 = 16.0;
const MT: f64 = 44.0;
const PH: f64 = 200.0;
const ROW: f64 = 13.0;

/// The chart as SVG. `standalone` adds the XML namespace (an `.svg` file); inline in HTML it
/// is not needed.
pub fn svg(c: &Chart) -> String {
    let mut c = c.clone();
    for se in &mut c.series {
        for (_, v) in &mut se.points {
            if let Value::Ok(y) = v
                && !y.is_finite()
            {
                *v = Value::Missing(format!("not finite: {y}"));
            }
        }
    }
    let c = &c;
    let ys: Vec<f64> = c
        .series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter_map(|(_, v)| match v {
            Value::Ok(y) => Some(*y),
            _ => None,
        })
        .collect();
    let (ticks, log) = y_scale(&ys);
    let (y0, y1) = (ticks[0], ticks[ticks.len() - 1]);
    let tf = |y: f64| if log { y.log10() } else { y };
    let (t0, t1) = (tf(y0), tf(y1));
    let pw = W - ML - MR;
    let py = |y: f64| MT + PH - (tf(y) - t0) / (t1 - t0) * PH;
    let xs: Vec<f64> = c.x_ticks.iter().map(|(x, _)| *x).collect();
    let xlo = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let xhi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let px = |x: f64| {
        if !(xhi > xlo) {
            ML + pw / 2.0
        } else {
            ML + 12.0 + (x - xlo) / (xhi - xlo) * (pw - 24.0)
        }
    };
    let band_top = MT + PH + 36.0;
    let n = c.series.len();
    let legend_top = band_top + ROW * n as f64 + 14.0;
    let legend_rows = n.div_ceil(3) + 1;
    let h = legend_top + 16.0 * legend_rows as f64 + 4.0;
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"sweep-chart\" width=\"{W}\" height=\"{h:.0}\" viewBox=\"0 0 {W} {h:.0}\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n"
    );
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"16\" font-size=\"13\" font-weight=\"bold\" text-anchor=\"middle\">{}</text>\n<text x=\"{}\" y=\"31\" fill=\"#666\" text-anchor=\"middle\">{}{}</text>",
        W / 2.0,
        esc(&c.title),
        W / 2.0,
        esc(&c.subtitle),
        if log { " (log scale)" } else { "" }
    );
    // y grid and labels
    for t in &ticks {
        let y = py(*t);
        let _ = writeln!(
            s,
            "<line x1=\"{ML}\" x2=\"{:.1}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#e5e5e5\"/><text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\" class=\"ytick\">{}</text>",
            W - MR,
            ML - 5.0,
            y + 4.0,
            tick_label(*t)
        );
    }
    // axes and x ticks
    let _ = writeln!(
        s,
        "<line x1=\"{ML}\" x2=\"{ML}\" y1=\"{MT}\" y2=\"{:.1}\" stroke=\"#333\"/><line x1=\"{ML}\" x2=\"{:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"#333\"/>",
        MT + PH,
        W - MR,
        MT + PH,
        MT + PH
    );
    for (x, label) in &c.x_ticks {
        let x = px(*x);
        let _ = writeln!(
            s,
            "<line x1=\"{x:.1}\" x2=\"{x:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"#333\"/><text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\" class=\"xtick\">{}</text>",
            MT + PH,
            MT + PH + 4.0,
            MT + PH + 16.0,
            esc(label)
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
        ML + pw / 2.0,
        MT + PH + 30.0,
        esc(&c.x_label)
    );
    let any_marker = c
        .series
        .iter()
        .any(|se| se.points.iter().any(|(_, v)| !matches!(v, Value::Ok(_))));
    if any_marker {
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\" fill=\"{FAIL_COLOR}\" font-size=\"10\">no value</text>",
            ML - 5.0,
            band_top + 4.0
        );
    }
    for (i, se) in c.series.iter().enumerate() {
        let col = color(i);
        let name = esc(&se.name);
        let _ = writeln!(s, "<g class=\"series\" data-series=\"{name}\">");
        // line segments through consecutive measured points
        let mut seg: Vec<(f64, f64)> = Vec::new();
        let flush = |seg: &mut Vec<(f64, f64)>, s: &mut String| {
            if seg.len() > 1 {
                let pts: Vec<String> = seg.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
                let _ = writeln!(
                    s,
                    "<polyline fill=\"none\" stroke=\"{col}\" stroke-width=\"2\" points=\"{}\"/>",
                    pts.join(" ")
                );
            }
            seg.clear();
        };
        for (x, v) in &se.points {
            match v {
                Value::Ok(y) => seg.push((px(*x), py(*y))),
                _ => flush(&mut seg, &mut s),
            }
        }
        flush(&mut seg, &mut s);
        let row_y = band_top + ROW * i as f64;
        for (x, v) in &se.points {
            let label = c
                .x_ticks
                .iter()
                .find(|(t, _)| t == x)
                .map(|(_, l)| l.clone())
                .unwrap_or_else(|| tick_label(*x));
            let at = format!("{} = {}", c.x_label, label);
            match v {
                Value::Ok(y) => {
                    let _ = writeln!(
                        s,
                        "<circle class=\"pt\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"3.5\" fill=\"{col}\"><title>{name}, {}: {}</title></circle>",
                        px(*x),
                        py(*y),
                        esc(&at),
                        y
                    );
                }
                Value::Failed(why) => {
                    let (cx, cy) = (px(*x), row_y);
                    let _ = writeln!(
                        s,
                        "<g class=\"fail\" data-series=\"{name}\"><title>{name}, {}: {}</title><path d=\"M{:.1},{:.1}l8,8m0,-8l-8,8\" stroke=\"{FAIL_COLOR}\" stroke-width=\"2.2\"/></g>",
                        esc(&at),
                        esc(why),
                        cx - 4.0,
                        cy - 4.0
                    );
                }
                Value::Missing(why) => {
                    let _ = writeln!(
                        s,
                        "<g class=\"missing\" data-series=\"{name}\"><title>{name}, {}: no value ({})</title><circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3.5\" fill=\"none\" stroke=\"#888\" stroke-width=\"1.5\"/></g>",
                        esc(&at),
                        esc(why),
                        px(*x),
                        row_y
                    );
                }
            }
        }
        if any_marker {
            let _ = writeln!(
                s,
                "<line x1=\"{:.1}\" x2=\"{:.1}\" y1=\"{row_y:.1}\" y2=\"{row_y:.1}\" stroke=\"{col}\" stroke-width=\"3\"/>",
                ML - 2.0,
                ML + 6.0
            );
        }
        s.push_str("</g>\n");
    }
    // legend: the series, then the markers
    for (i, se) in c.series.iter().enumerate() {
        let col = color(i);
        let lx = 10.0 + (i % 3) as f64 * ((W - 20.0) / 3.0);
        let ly = legend_top + 16.0 * (i / 3) as f64;
        let _ = writeln!(
            s,
            "<g class=\"legend\"><line x1=\"{lx:.1}\" x2=\"{:.1}\" y1=\"{ly:.1}\" y2=\"{ly:.1}\" stroke=\"{col}\" stroke-width=\"3\"/><text x=\"{:.1}\" y=\"{:.1}\">{}</text></g>",
            lx + 18.0,
            lx + 22.0,
            ly + 4.0,
            esc(&se.name)
        );
    }
    let ly = legend_top + 16.0 * (legend_rows - 1) as f64;
    let _ = writeln!(
        s,
        "<path d=\"M14,{:.1}l8,8m0,-8l-8,8\" stroke=\"{FAIL_COLOR}\" stroke-width=\"2.2\"/><text x=\"28\" y=\"{:.1}\">failed / not run (row of its pipeline; hover for the reason)</text><circle cx=\"{:.1}\" cy=\"{ly:.1}\" r=\"3.5\" fill=\"none\" stroke=\"#888\" stroke-width=\"1.5\"/><text x=\"{:.1}\" y=\"{:.1}\">ok, no value</text>",
        ly - 4.0,
        ly + 4.0,
        W - 110.0,
        W - 102.0,
        ly + 4.0
    );
    s.push_str("</svg>\n");
    s
}

/// The same chart for inlining in HTML (no XML namespace declaration needed).
pub fn svg_inline(c: &Chart) -> String {
    svg(c).replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::float_cmp)]
mod tests {
    use super::*;

    fn chart() -> Chart {
        Chart {
            title: "recall".into(),
            subtitle: "report.thresholds[0].recall".into(),
            x_label: "views".into(),
            x_ticks: vec![(8.0, "8".into()), (16.0, "16".into()), (24.0, "24".into())],
            series: vec![
                Series {
                    name: "pycolmap".into(),
                    points: vec![
                        (8.0, Value::Ok(0.1)),
                        (16.0, Value::Ok(0.5)),
                        (24.0, Value::Missing("no cameras".into())),
                    ],
                },
                Series {
                    name: "broken<x>".into(),
                    points: vec![
                        (8.0, Value::Failed("failed: exit 1".into())),
                        (16.0, Value::Failed("failed".into())),
                        (24.0, Value::Ok(f64::NAN)),
                    ],
                },
            ],
        }
    }

    #[test]
    fn svg_draws_every_point_and_marks_failures() {
        let s = svg(&chart());
        assert!(s.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
        assert_eq!(s.matches("<g class=\"series\"").count(), 2);
        assert_eq!(s.matches("class=\"fail\"").count(), 2);
        assert_eq!(s.matches("class=\"missing\"").count(), 2);
        assert!(s.contains("data-series=\"broken&lt;x&gt;\""));
        assert!(s.contains("failed: exit 1"));
        assert_eq!(s.matches("<polyline").count(), 1);
        assert!(
            !s.contains("=\"NaN") && !s.contains(",NaN"),
            "a NaN must never reach the coordinates"
        );
        assert!(!svg_inline(&chart()).contains("xmlns"));
    }
}
