//! What the table cells say: Table I's `mean (points)` or the failure, and the wide table's
//! columns and values (shared by Markdown, CSV and HTML).

use crate::order::find;
use crate::row::Row;
use crate::text::one_line;

/// Table I cell text: `mean m (points)` or the failure.
pub fn table1_cell(r: Option<&Row>) -> String {
    match r {
        None => "—".into(),
        Some(r) => match r.mean {
            Some(m) => format!("{m:.6} ({})", r.points),
            None => {
                let reason = short(r.reason.as_deref().unwrap_or(""));
                if reason.starts_with(&r.status) {
                    reason
                } else {
                    format!("{}: {reason}", r.status)
                }
            }
        },
    }
}

/// A reason on one line for a Markdown cell: no line breaks or `|`, at most 120 characters.
fn short(s: &str) -> String {
    one_line(&s.replace('|', " "), 120)
}

/// A number with `digits` decimals, empty for none.
fn opt(v: Option<f64>, digits: usize) -> String {
    v.map(|x| format!("{x:.digits$}")).unwrap_or_default()
}

/// A number as CSV text (shortest round-trip form), empty for none.
pub fn csv_num(v: Option<f64>) -> String {
    v.map(|x| format!("{x}")).unwrap_or_default()
}

/// Column headers of the wide table (shared by Markdown, CSV and HTML).
pub fn wide_columns(rows: &[Row]) -> Vec<String> {
    let mut cols: Vec<String> = [
        "dataset",
        "pipeline",
        "status",
        "points",
        "registered",
        "mean (m)",
        "median (m)",
        "RMS (m)",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    if let Some(r) = rows.iter().find(|r| !r.thresholds.is_empty()) {
        for t in &r.thresholds {
            let pct = (t.tau_percent_of_diagonal * 1e6).round() / 1e6;
            cols.push(format!("P@{pct}%"));
            cols.push(format!("R@{pct}%"));
            cols.push(format!("F@{pct}%"));
        }
    }
    cols.extend(
        [
            "rot. median (°)",
            "centre median (m)",
            "centre median (% radius)",
            "centre max (% radius)",
            "wall (s)",
            "CPU (s)",
            "peak mem (MB)",
            "tool",
            "reason",
        ]
        .iter()
        .map(|s| s.to_string()),
    );
    cols
}

/// One row's values in the wide table: numbers rounded for Markdown and HTML, in full for CSV
/// (`csv`), with `n_tau` thresholds.
pub fn wide_values(r: &Row, n_tau: usize, csv: bool) -> Vec<String> {
    let num = |v: Option<f64>, d: usize| if csv { csv_num(v) } else { opt(v, d) };
    let mut v = vec![
        r.dataset.clone(),
        r.pipeline.clone(),
        r.status.clone(),
        if r.status == "ok" {
            r.points.to_string()
        } else {
            String::new()
        },
        format!("{}/{}", r.images_registered, r.images_total),
        num(r.mean, 6),
        num(r.median, 6),
        num(r.rms, 6),
    ];
    for k in 0..n_tau {
        let t = r.thresholds.get(k);
        v.push(num(t.map(|t| t.precision), 3));
        v.push(num(t.map(|t| t.recall), 3));
        v.push(num(t.map(|t| t.f_score), 3));
    }
    v.extend([
        num(r.rotation_median_deg, 3),
        num(r.center_median, 5),
        num(r.center_median_percent, 3),
        num(r.center_max_percent, 3),
        num(Some(r.wall_seconds), 1),
        num(Some(r.cpu_seconds), 1),
        num(Some(r.peak_memory_mb), 0),
        format!("{} {}", r.tool, r.version.as_deref().unwrap_or(""))
            .trim()
            .to_string(),
        if csv {
            r.reason.clone().unwrap_or_default()
        } else {
            short(r.reason.as_deref().unwrap_or(""))
        },
    ]);
    v
}

/// The number of thresholds of the wide table (the most any row has).
pub fn n_tau(rows: &[Row]) -> usize {
    rows.iter().map(|r| r.thresholds.len()).max().unwrap_or(0)
}

/// Wide-table columns and values for the HTML page.
pub fn wide_for_html(
    rows: &[Row],
    datasets: &[String],
    pipes: &[String],
) -> (Vec<String>, Vec<(String, Vec<String>)>) {
    let nt = n_tau(rows);
    let mut out = Vec::new();
    for d in datasets {
        for p in pipes {
            if let Some(r) = find(rows, d, p) {
                out.push((r.status.clone(), wide_values(r, nt, false)));
            }
        }
    }
    (wide_columns(rows), out)
}
