//! What the table cells say: Table I's `mean (points)` or the failure, and the wide table's
//! columns and values (shared by Markdown, CSV and HTML).

use crate::catalogue::{Metric, Source, WIDE, WIDE_DTU, WIDE_ETH3D, WIDE_POSES, metrics_of, short};
use crate::order::find;
use crate::row::Row;

/// Table I cell text: `mean m (points)` or the failure.
pub fn table1_cell(r: Option<&Row>) -> String {
    match r {
        None => "—".into(),
        Some(r) => match (
            r.mean,
            r.dtu.as_ref().and_then(|d| d.overall),
            eth3d_headline(r),
        ) {
            (Some(m), _, _) => format!("{m:.6} ({})", r.points),
            (None, Some(overall), _) => format!("{overall:.3} mm DTU overall ({})", r.points),
            (None, None, Some((tolerance, f1))) => {
                format!("{f1:.3} ETH3D F1 at {tolerance} m ({})", r.points)
            }
            (None, None, None) => {
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

/// The tolerance of Table I's ETH3D cell: the benchmark's headline 2 cm (its leaderboard's
/// default), else the row's first.
pub const ETH3D_TABLE1_TOLERANCE: f64 = 0.02;

/// The `(tolerance, F1)` Table I shows for an ETH3D row.
pub fn eth3d_headline(r: &Row) -> Option<(f64, f64)> {
    let t = &r.eth3d.as_ref()?.tolerances;
    let pick = t
        .iter()
        .find(|t| t.tolerance == ETH3D_TABLE1_TOLERANCE)
        .or(t.first())?;
    Some((pick.tolerance, pick.f1))
}

/// A number with `digits` decimals, empty for none.
fn opt(v: Option<f64>, digits: usize) -> String {
    v.map(|x| format!("{x:.digits$}")).unwrap_or_default()
}

/// A number as CSV text (shortest round-trip form), empty for none.
pub fn csv_num(v: Option<f64>) -> String {
    v.map(|x| format!("{x}")).unwrap_or_default()
}

/// What the wide table's columns depend on: the number of thresholds (the most any row has)
/// and whether some row has DTU numbers or pose-protocol numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WideShape {
    /// Thresholds of the per-threshold columns.
    pub n_tau: usize,
    /// Whether the DTU columns ([`WIDE_DTU`]) are shown.
    pub dtu: bool,
    /// Whether the pose protocols' columns ([`WIDE_POSES`]) are shown.
    pub poses: bool,
    /// Whether ETH3D's columns ([`WIDE_ETH3D`]) are shown.
    pub eth3d: bool,
}

/// The wide table's shape for `rows`.
pub fn wide_shape(rows: &[Row]) -> WideShape {
    WideShape {
        n_tau: n_tau(rows),
        dtu: rows.iter().any(|r| r.dtu.is_some()),
        poses: rows.iter().any(|r| r.poses.is_some()),
        eth3d: rows.iter().any(|r| r.eth3d.is_some()),
    }
}

/// The wide table's metrics ([`WIDE`] of the catalogue, with [`WIDE_POSES`] after the camera
/// columns, [`WIDE_DTU`] after the per-threshold ones and [`WIDE_ETH3D`] after those when the
/// shape has them).
pub(crate) fn wide_metrics(shape: WideShape) -> Vec<&'static Metric> {
    let mut keys: Vec<&str> = WIDE.to_vec();
    if shape.poses {
        let after = keys
            .iter()
            .rposition(|k| k.starts_with("report.cameras."))
            .map_or(keys.len(), |i| i + 1);
        keys.splice(after..after, WIDE_POSES.iter().copied());
    }
    if shape.dtu {
        let after = keys
            .iter()
            .rposition(|k| k.contains("[*]"))
            .map_or(keys.len(), |i| i + 1);
        keys.splice(after..after, WIDE_DTU.iter().copied());
    }
    if shape.eth3d {
        let after = keys
            .iter()
            .rposition(|k| k.contains("[*]") || WIDE_DTU.contains(k))
            .map_or(keys.len(), |i| i + 1);
        keys.splice(after..after, WIDE_ETH3D.iter().copied());
    }
    metrics_of(&keys)
}

/// The thresholds in percent of the diagonal that name per-threshold columns: the first row's
/// with thresholds (rounded to 6 decimals).
fn threshold_percents(rows: &[Row]) -> Vec<f64> {
    rows.iter()
        .find(|r| !r.thresholds.is_empty())
        .map(|r| {
            r.thresholds
                .iter()
                .map(|t| (t.tau_percent_of_diagonal * 1e6).round() / 1e6)
                .collect()
        })
        .unwrap_or_default()
}

/// Column headers of the wide table (shared by Markdown, CSV and HTML): the catalogue's
/// headers with their units, per-threshold metrics grouped by threshold.
pub fn wide_columns(rows: &[Row]) -> Vec<String> {
    let pcts = threshold_percents(rows);
    let mut cols = Vec::new();
    for_columns(&wide_metrics(wide_shape(rows)), pcts.len(), |m, k| {
        cols.push(m.header_with_unit(k.map(|k| pcts[k])));
    });
    cols
}

/// Calls `f` with each column of `metrics`: a per-threshold run (consecutive per-threshold
/// metrics) repeated for each of `n_tau` thresholds, with the threshold's index.
pub(crate) fn for_columns(
    metrics: &[&'static Metric],
    n_tau: usize,
    mut f: impl FnMut(&'static Metric, Option<usize>),
) {
    let mut i = 0;
    while i < metrics.len() {
        if metrics[i].per_threshold() {
            let start = i;
            while i < metrics.len() && metrics[i].per_threshold() {
                i += 1;
            }
            for k in 0..n_tau {
                for m in &metrics[start..i] {
                    f(m, Some(k));
                }
            }
        } else {
            f(metrics[i], None);
            i += 1;
        }
    }
}

/// One row's values in the wide table: numbers rounded for Markdown and HTML (the catalogue's
/// decimals), in full for CSV (`csv`), in the table's `shape`.
pub fn wide_values(r: &Row, shape: WideShape, csv: bool) -> Vec<String> {
    let mut v = Vec::new();
    for_columns(&wide_metrics(shape), shape.n_tau, |m, k| {
        v.push(cell_text(m, r, k.unwrap_or(0), csv));
    });
    v
}

/// A wide-table cell: the metric's text, or its number with the catalogue's decimals (in full
/// for CSV), empty for none.
fn cell_text(m: &Metric, r: &Row, k: usize, csv: bool) -> String {
    if let Source::Text(f) = m.source {
        return f(r, csv);
    }
    if let Some(shown) = m.shown {
        return shown(r);
    }
    let v = m.number(r, k, None);
    if csv {
        csv_num(v)
    } else {
        opt(v, m.digits.unwrap_or(0))
    }
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
    let shape = wide_shape(rows);
    let mut out = Vec::new();
    for d in datasets {
        for p in pipes {
            if let Some(r) = find(rows, d, p) {
                out.push((r.status.clone(), wide_values(r, shape, false)));
            }
        }
    }
    (wide_columns(rows), out)
}
