//! The self-contained HTML page of the comparison: both tables, a grouped bar chart per metric
//! and cumulative error curves per dataset, all inline SVG (no scripts, no network).

use std::fmt::Write as _;

use crate::report::{Row, table1_cell, wide_for_html};

const COLORS: [&str; 10] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf",
];

/// HTML-escapes text.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn color(i: usize) -> &'static str {
    COLORS[i % COLORS.len()]
}

fn find<'a>(rows: &'a [Row], d: &str, p: &str) -> Option<&'a Row> {
    rows.iter().find(|r| r.dataset == d && r.pipeline == p)
}

/// The whole page.
pub fn page(rows: &[Row], datasets: &[String], pipes: &[String]) -> String {
    let mut h = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>sfmeval-runner comparison</title>\n<style>\nbody{font-family:system-ui,sans-serif;margin:1.5em;color:#222}table{border-collapse:collapse;margin:1em 0;font-size:13px}\nth,td{border:1px solid #ccc;padding:3px 7px;text-align:right}th{background:#f3f3f3}td.l,th.l{text-align:left}\ntr.failed td,td.failed{color:#a00;background:#fff3f3}.charts{display:flex;flex-wrap:wrap;gap:1em}\nsvg{background:#fff;border:1px solid #ddd}.legend span{display:inline-block;margin-right:1em}.sw{display:inline-block;width:12px;height:12px;margin-right:4px;vertical-align:middle}\n</style></head><body>\n<h1>SfM pipelines compared with sfmeval</h1>\n",
    );
    let _ = writeln!(
        h,
        "<p>{} datasets × {} pipelines. Distances in metres, after <code>auto</code> alignment to the ground truth; one <code>sfmeval.report/1</code> per run under <code>reports/</code>.</p>",
        datasets.len(),
        pipes.len()
    );
    h.push_str("<div class=\"legend\">");
    for (i, p) in pipes.iter().enumerate() {
        let _ = write!(
            h,
            "<span><i class=\"sw\" style=\"background:{}\"></i>{}</span>",
            color(i),
            esc(p)
        );
    }
    h.push_str("</div>\n<h2 id=\"table1\">Table I: mean distance (m) and number of points</h2>\n<table id=\"table1-table\"><tr><th class=\"l\">dataset</th>");
    for p in pipes {
        let _ = write!(h, "<th>{}</th>", esc(p));
    }
    h.push_str("</tr>\n");
    for d in datasets {
        let _ = write!(h, "<tr><td class=\"l\">{}</td>", esc(d));
        for p in pipes {
            let r = find(rows, d, p);
            let failed = r.is_some_and(|r| r.mean.is_none());
            let _ = write!(
                h,
                "<td{}>{}</td>",
                if failed { " class=\"failed\"" } else { "" },
                esc(&table1_cell(r))
            );
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n<h2>Charts</h2>\n<div class=\"charts\">\n");
    type Metric = (&'static str, fn(&Row) -> Option<f64>);
    let metrics: [Metric; 8] = [
        ("mean distance (m)", |r| r.mean),
        ("median distance (m)", |r| r.median),
        ("points", |r| r.mean.map(|_| r.points as f64)),
        ("F-score at the middle threshold", |r| {
            r.thresholds.get(r.thresholds.len() / 2).map(|t| t.f_score)
        }),
        ("registered images (%)", |r| {
            (r.status == "ok" && r.images_total > 0)
                .then(|| 100.0 * r.images_registered as f64 / r.images_total as f64)
        }),
        ("camera-centre median error (% radius)", |r| {
            r.center_median_percent
        }),
        ("wall time (s)", |r| {
            (r.status != "not installed").then_some(r.wall_seconds)
        }),
        ("peak memory (MB)", |r| {
            (r.status != "not installed").then_some(r.peak_memory_mb)
        }),
    ];
    for (title, f) in metrics {
        h.push_str(&bar_chart(title, rows, datasets, pipes, f));
    }
    for d in datasets {
        h.push_str(&cdf_chart(d, rows, pipes));
    }
    h.push_str("</div>\n<h2 id=\"runs\">All runs</h2>\n<table id=\"runs-table\"><tr>");
    let (cols, values) = wide_for_html(rows, datasets, pipes);
    for (i, c) in cols.iter().enumerate() {
        let _ = write!(
            h,
            "<th{}>{}</th>",
            if i < 3 || i + 2 >= cols.len() {
                " class=\"l\""
            } else {
                ""
            },
            esc(c)
        );
    }
    h.push_str("</tr>\n");
    for (status, vals) in &values {
        let _ = write!(
            h,
            "<tr{}>",
            if status == "ok" {
                ""
            } else {
                " class=\"failed\""
            }
        );
        for (i, v) in vals.iter().enumerate() {
            let _ = write!(
                h,
                "<td{}>{}</td>",
                if i < 3 || i + 2 >= vals.len() {
                    " class=\"l\""
                } else {
                    ""
                },
                esc(v)
            );
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n<p>Written by sfmeval-runner.</p>\n</body></html>\n");
    h
}

fn nice_max(v: f64) -> f64 {
    if !(v > 0.0) {
        return 1.0;
    }
    let e = 10f64.powf(v.log10().floor());
    for m in [1.0, 2.0, 2.5, 5.0, 10.0] {
        if v <= m * e {
            return m * e;
        }
    }
    10.0 * e
}

fn fmt_tick(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2e}")
    }
}

fn bar_chart(
    title: &str,
    rows: &[Row],
    datasets: &[String],
    pipes: &[String],
    f: fn(&Row) -> Option<f64>,
) -> String {
    let (w, hgt, left, bottom, top) = (460.0, 260.0, 60.0, 40.0, 28.0);
    let plot_w = w - left - 10.0;
    let plot_h = hgt - bottom - top;
    let max = rows
        .iter()
        .filter_map(f)
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let ymax = nice_max(max);
    let mut s = format!(
        "<svg class=\"bar\" width=\"{w}\" height=\"{hgt}\" viewBox=\"0 0 {w} {hgt}\" role=\"img\"><title>{t}</title><text x=\"{x}\" y=\"18\" font-size=\"13\" text-anchor=\"middle\">{t}</text>",
        t = esc(title),
        x = w / 2.0
    );
    for k in 0..=4 {
        let v = ymax * k as f64 / 4.0;
        let y = top + plot_h - plot_h * k as f64 / 4.0;
        let _ = write!(
            s,
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#eee\"/><text x=\"{}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"end\">{}</text>",
            left + plot_w,
            left - 4.0,
            y + 3.0,
            fmt_tick(v)
        );
    }
    let group = plot_w / datasets.len().max(1) as f64;
    let bar = (group * 0.8 / pipes.len().max(1) as f64).max(1.0);
    for (di, d) in datasets.iter().enumerate() {
        let gx = left + group * di as f64 + group * 0.1;
        for (pi, p) in pipes.iter().enumerate() {
            let x = gx + bar * pi as f64;
            let Some(r) = find(rows, d, p) else { continue };
            match f(r).filter(|v| v.is_finite()) {
                Some(v) => {
                    let bh = plot_h * (v / ymax).clamp(0.0, 1.0);
                    let _ = write!(
                        s,
                        "<rect x=\"{x:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bh:.1}\" fill=\"{}\"><title>{}: {} = {v}</title></rect>",
                        top + plot_h - bh,
                        (bar - 1.0).max(0.5),
                        color(pi),
                        esc(d),
                        esc(p)
                    );
                }
                None if r.status != "ok" => {
                    let _ = write!(
                        s,
                        "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" fill=\"#a00\" text-anchor=\"middle\">×<title>{}: {} {}</title></text>",
                        x + bar / 2.0,
                        top + plot_h - 3.0,
                        esc(d),
                        esc(p),
                        esc(&r.status)
                    );
                }
                None => {}
            }
        }
        let _ = write!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"middle\">{}</text>",
            gx + group * 0.4,
            top + plot_h + 16.0,
            esc(d)
        );
    }
    s.push_str("</svg>\n");
    s
}

fn cdf_chart(dataset: &str, rows: &[Row], pipes: &[String]) -> String {
    let (w, hgt, left, bottom, top) = (460.0, 260.0, 50.0, 40.0, 28.0);
    let plot_w = w - left - 30.0;
    let plot_h = hgt - bottom - top;
    let series: Vec<(usize, &Row)> = pipes
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            find(rows, dataset, p)
                .filter(|r| !r.cdf.is_empty())
                .map(|r| (i, r))
        })
        .collect();
    // The x range covers the 95th percentile of the worst run, so the curves are readable.
    let xmax = series
        .iter()
        .filter_map(|(_, r)| r.cdf.iter().find(|(_, y)| *y >= 0.95).map(|(x, _)| *x))
        .fold(0.0f64, f64::max);
    let xmax = nice_max(xmax);
    let mut s = format!(
        "<svg class=\"cdf\" width=\"{w}\" height=\"{hgt}\" viewBox=\"0 0 {w} {hgt}\" role=\"img\"><title>cumulative error {d}</title><text x=\"{x}\" y=\"18\" font-size=\"13\" text-anchor=\"middle\">{d}: share of points within distance (m)</text>",
        d = esc(dataset),
        x = w / 2.0
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
            fmt_tick(xmax * k as f64 / 4.0)
        );
    }
    for (i, r) in series {
        let pts: Vec<String> = r
            .cdf
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
            color(i),
            pts.join(" "),
            esc(&r.pipeline)
        );
    }
    s.push_str("</svg>\n");
    s
}
