//! Grouped bar charts: one group of bars per x label (a dataset), one bar per series (a
//! pipeline) in each group; a run without a value because it failed is a red × where its bar
//! would stand.

use std::fmt::Write as _;

use crate::chart::palette::color;
use crate::chart::panel;
use crate::chart::scale::{nice_max, short_tick_label};
use crate::chart::value::Value;
use crate::html::esc;

/// A grouped bar chart.
#[derive(Debug, Clone)]
pub struct BarChart {
    /// Title.
    pub title: String,
    /// Group labels along the x axis (datasets).
    pub groups: Vec<String>,
    /// Series names (pipelines): one bar per group each, coloured by its index.
    pub series: Vec<String>,
    /// `values[group][series]`: a bar (`Ok`, finite), a × with the reason as tooltip
    /// (`Failed`), or nothing (`Missing`, or absent).
    pub values: Vec<Vec<Value>>,
}

/// The chart as inline SVG (no XML namespace), ending with a line break.
pub fn svg(c: &BarChart) -> String {
    let (left, top) = (60.0, panel::TOP);
    let plot_w = panel::WIDTH - left - 10.0;
    let plot_h = panel::HEIGHT - panel::BOTTOM - top;
    let max = c
        .values
        .iter()
        .flatten()
        .filter_map(|v| match v {
            Value::Ok(y) if y.is_finite() => Some(*y),
            _ => None,
        })
        .fold(0.0f64, f64::max);
    let ymax = nice_max(max);
    let mut s = panel::open("bar", &c.title, &c.title);
    for k in 0..=4 {
        let v = ymax * k as f64 / 4.0;
        let y = top + plot_h - plot_h * k as f64 / 4.0;
        let _ = write!(
            s,
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#eee\"/><text x=\"{}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"end\">{}</text>",
            left + plot_w,
            left - 4.0,
            y + 3.0,
            short_tick_label(v)
        );
    }
    let group = plot_w / c.groups.len().max(1) as f64;
    let bar = (group * 0.8 / c.series.len().max(1) as f64).max(1.0);
    for (gi, g) in c.groups.iter().enumerate() {
        let gx = left + group * gi as f64 + group * 0.1;
        for (si, name) in c.series.iter().enumerate() {
            let x = gx + bar * si as f64;
            match c.values.get(gi).and_then(|vs| vs.get(si)) {
                Some(Value::Ok(v)) if v.is_finite() => {
                    let bh = plot_h * (v / ymax).clamp(0.0, 1.0);
                    let _ = write!(
                        s,
                        "<rect x=\"{x:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bh:.1}\" fill=\"{}\"><title>{}: {} = {v}</title></rect>",
                        top + plot_h - bh,
                        (bar - 1.0).max(0.5),
                        color(si),
                        esc(g),
                        esc(name)
                    );
                }
                Some(Value::Failed(why)) => {
                    let _ = write!(
                        s,
                        "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" fill=\"#a00\" text-anchor=\"middle\">×<title>{}: {} {}</title></text>",
                        x + bar / 2.0,
                        top + plot_h - 3.0,
                        esc(g),
                        esc(name),
                        esc(why)
                    );
                }
                _ => {}
            }
        }
        let _ = write!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"middle\">{}</text>",
            gx + group * 0.4,
            top + plot_h + 16.0,
            esc(g)
        );
    }
    s.push_str("</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bars_and_failure_marks() {
        let c = BarChart {
            title: "mean <m>".into(),
            groups: vec!["d1".into(), "d2".into()],
            series: vec!["a".into(), "b".into()],
            values: vec![
                vec![Value::Ok(0.5), Value::Failed("timeout".into())],
                vec![Value::Ok(f64::NAN), Value::Missing(String::new())],
            ],
        };
        let s = svg(&c);
        assert_eq!(s.matches("<rect").count(), 1);
        assert!(s.contains("<title>d1: b timeout</title>"));
        assert!(s.contains("<title>mean &lt;m&gt;</title>"));
        assert!(!s.contains("NaN"));
    }
}
