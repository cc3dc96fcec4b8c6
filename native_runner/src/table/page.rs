//! The tables' self-contained HTML page (`index.html`): both tables, a grouped bar chart per
//! metric and cumulative error curves per dataset, all inline SVG (no scripts, no network).

use std::fmt::Write as _;

use crate::chart::bar::{self, BarChart};
use crate::chart::cdf::{self, Curve};
use crate::chart::palette::color;
use crate::chart::value::Value;
use crate::html::{self, esc};
use sfmeval_table::Row;
use sfmeval_table::cells::{table1_cell, wide_for_html};
use sfmeval_table::order::find;

/// The page's own style, after the shell's.
const STYLE: &str = "th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}th{background:#f3f3f3}td.l,th.l{text-align:left}\ntr.failed td,td.failed{color:#a00;background:#fff3f3}.charts{display:flex;flex-wrap:wrap;gap:1em}\nsvg{background:#fff;border:1px solid #ddd}.legend span{display:inline-block;margin-right:1em}.sw{display:inline-block;width:12px;height:12px;margin-right:4px;vertical-align:middle}";

/// The whole page (`index.html`).
pub fn page(rows: &[Row], datasets: &[String], pipes: &[String]) -> String {
    let mut h = String::from("<h1>SfM pipelines compared with sfmeval</h1>\n");
    let _ = writeln!(
        h,
        "<p>{} datasets × {} pipelines. Distances in metres, after <code>auto</code> alignment to the ground truth; one <code>sfmeval.report/3</code> per run under <code>reports/</code>.</p>",
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
        h.push_str(&bar::svg(&bar_chart(title, rows, datasets, pipes, f)));
    }
    for d in datasets {
        h.push_str(&cdf_chart(d, rows, pipes));
    }
    h.push_str("</div>\n<h2 id=\"runs\">All runs</h2>\n<table id=\"runs-table\"><tr>");
    let (cols, values) = wide_for_html(rows, datasets, pipes);
    for (i, c) in cols.iter().enumerate() {
        let _ = write!(h, "<th{}>{}</th>", align(i, cols.len()), esc(c));
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
            let _ = write!(h, "<td{}>{}</td>", align(i, vals.len()), esc(v));
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n<p>Written by sfmeval-runner.</p>\n");
    html::page("sfmeval-runner comparison", STYLE, &h)
}

/// The class of column `i` of `n` in the wide table: the first three (dataset, pipeline,
/// status) and the last two (tool, reason) are text, aligned left; numbers are aligned right.
fn align(i: usize, n: usize) -> &'static str {
    if i < 3 || i + 2 >= n {
        " class=\"l\""
    } else {
        ""
    }
}

/// The bar chart of one metric: a group per dataset, a bar per pipeline; a run without the
/// value that did not succeed is marked with its status.
fn bar_chart(
    title: &str,
    rows: &[Row],
    datasets: &[String],
    pipes: &[String],
    f: fn(&Row) -> Option<f64>,
) -> BarChart {
    let values = datasets
        .iter()
        .map(|d| {
            pipes
                .iter()
                .map(|p| match find(rows, d, p) {
                    None => Value::Missing("no run".into()),
                    Some(r) => match f(r).filter(|v| v.is_finite()) {
                        Some(v) => Value::Ok(v),
                        None if r.status != "ok" => Value::Failed(r.status.clone()),
                        None => Value::Missing("no value".into()),
                    },
                })
                .collect()
        })
        .collect();
    BarChart {
        title: title.to_string(),
        groups: datasets.to_vec(),
        series: pipes.to_vec(),
        values,
    }
}

/// The cumulative error curves of one dataset, a curve per pipeline with an evaluation.
fn cdf_chart(dataset: &str, rows: &[Row], pipes: &[String]) -> String {
    let curves: Vec<Curve> = pipes
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            find(rows, dataset, p).map(|r| Curve {
                name: &r.pipeline,
                color: i,
                points: &r.cdf,
            })
        })
        .collect();
    cdf::svg(dataset, &curves)
}
