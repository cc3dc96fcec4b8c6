//! What a sweep plots: metrics as JSON paths into `{"report": <sfmeval.report/3>, "run": <the
//! run's row>}`, the defaults (the catalogue's `SWEEP` lists, named there), `[*]` expansion,
//! lookup, and chart file names. A new report field is one more line in the catalogue
//! (`sfmeval_table::catalogue`) and its `SWEEP` list (or `--metric PATH`).

use serde_json::Value as Json;
pub use sfmeval_table::catalogue::lookup;
use sfmeval_table::catalogue::{SWEEP, SWEEP_VISIBILITY, metrics_of};

use crate::sweep::cells::Cell;

/// `(path, label)` of the catalogue's metrics of `keys`.
fn catalogue_specs(keys: &[&str]) -> Vec<(String, String)> {
    metrics_of(keys)
        .iter()
        .map(|m| (m.key.to_string(), m.name.to_string()))
        .collect()
}

/// A metric to plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Metric {
    /// JSON path (CSV column), `[*]` expanded.
    pub path: String,
    /// Chart title.
    pub label: String,
}

/// Expands `[*]` (first occurrence) against the documents: one metric per index seen, the
/// label suffixed with the element's τ when it has one.
pub fn expand_metric(path: &str, label: &str, docs: &[&Json]) -> Vec<Metric> {
    let Some(i) = path.find("[*]") else {
        return vec![Metric {
            path: path.into(),
            label: label.into(),
        }];
    };
    let (prefix, suffix) = (&path[..i], &path[i + 3..]);
    let pointer = format!("/{}", prefix.replace('.', "/"));
    let mut n = 0;
    let mut first: Option<&Json> = None;
    for d in docs {
        if let Some(a) = d.pointer(&pointer).and_then(Json::as_array)
            && a.len() > n
        {
            n = a.len();
            first = Some(*d);
        }
    }
    (0..n)
        .map(|k| {
            let el = first.and_then(|d| d.pointer(&format!("{pointer}/{k}")));
            let tau = el.and_then(|e| e.get("tau")).and_then(Json::as_f64);
            let percent = el
                .and_then(|e| e.get("tau_percent_of_diagonal"))
                .and_then(Json::as_f64);
            let suffix_label = match (tau, percent) {
                (Some(t), Some(p)) if p > 0.0 => {
                    format!(" at τ = {} m ({} % of the diagonal)", sig(t), sig(p))
                }
                (Some(t), _) => format!(" at τ = {} m", sig(t)),
                _ => format!(" [{k}]"),
            };
            Metric {
                path: format!("{prefix}[{k}]{suffix}"),
                label: format!("{label}{suffix_label}"),
            }
        })
        .collect()
}

fn sig(x: f64) -> String {
    let s = format!("{x:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The metrics to plot: defaults then `--metric` ones, `[*]` expanded over the cells.
pub fn metrics(extra: &[String], cells: &[Cell]) -> Vec<Metric> {
    let docs: Vec<&Json> = cells.iter().map(|c| &c.doc).collect();
    let mut specs = catalogue_specs(SWEEP);
    specs.extend(
        catalogue_specs(SWEEP_VISIBILITY)
            .into_iter()
            .filter(|(p, _)| {
                // only when a report has the section (runs with depth maps)
                let section = p.split('.').take(2).collect::<Vec<_>>().join("/");
                docs.iter()
                    .any(|d| d.pointer(&format!("/{section}")).is_some())
            }),
    );
    for e in extra {
        let (p, l) = e.split_once('=').unwrap_or((e, e));
        specs.push((p.trim().to_string(), l.trim().to_string()));
    }
    let mut out: Vec<Metric> = Vec::new();
    for (p, l) in specs {
        for m in expand_metric(&p, &l, &docs) {
            if !out.iter().any(|o| o.path == m.path) {
                out.push(m);
            }
        }
    }
    out
}

/// A file-name-safe stem for a metric path.
pub fn metric_file(path: &str) -> String {
    let s: String = path
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    let mut out = String::new();
    for c in s.chars() {
        if !(c == '_' && out.ends_with('_')) {
            out.push(c);
        }
    }
    out.trim_matches('_').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn metric_paths() {
        let doc = json!({"report": {"accuracy": {"mean": 0.5},
            "thresholds": [{"tau": 0.006, "tau_percent_of_diagonal": 0.5, "recall": 0.1},
                           {"tau": 0.012, "tau_percent_of_diagonal": 1.0, "recall": 0.3}]},
            "run": {"wall_seconds": 3.0}});
        assert_eq!(lookup(&doc, "report.accuracy.mean"), Some(0.5));
        assert_eq!(lookup(&doc, "report.thresholds[1].recall"), Some(0.3));
        assert_eq!(lookup(&doc, "report.thresholds[2].recall"), None);
        assert_eq!(lookup(&doc, "report.cameras.ate_rmse"), None);
        assert_eq!(lookup(&Json::Null, "run.wall_seconds"), None);
        let m = expand_metric(
            "report.thresholds[*].recall",
            "recall",
            &[&Json::Null, &doc],
        );
        assert_eq!(m.len(), 2);
        assert_eq!(m[1].path, "report.thresholds[1].recall");
        assert_eq!(m[0].label, "recall at τ = 0.006 m (0.5 % of the diagonal)");
        assert!(expand_metric("report.thresholds[*].recall", "r", &[&Json::Null]).is_empty());
        assert_eq!(
            metric_file("report.thresholds[1].f_score"),
            "report_thresholds_1_f_score"
        );
    }

    #[test]
    fn default_metrics_are_the_catalogue_ones_with_the_titles_sweeps_had() {
        // the sweep's own list before the catalogue took it over: same paths (CSV columns,
        // chart files) and titles
        let before = [
            ("report.thresholds[*].recall", "completeness (recall)"),
            ("report.thresholds[*].precision", "precision"),
            ("report.thresholds[*].f_score", "F-score"),
            ("report.accuracy.mean", "accuracy: mean distance (m)"),
            ("report.accuracy.median", "accuracy: median distance (m)"),
            (
                "report.completeness.median",
                "completeness: median distance GT → reconstruction (m)",
            ),
            ("run.registered_fraction", "registered images (fraction)"),
            (
                "report.cameras.rotation_error_deg.median",
                "median rotation error (°)",
            ),
            ("report.cameras.ate_rmse", "ATE RMSE (m)"),
            ("run.points", "points"),
            ("run.wall_seconds", "run time (s, wall)"),
            (
                "report.completeness_visible.thresholds[*].recall_visible",
                "completeness of the visible surface (recall)",
            ),
            (
                "report.completeness_visible.visible_fraction",
                "visible share of the surface (≥ k images)",
            ),
            (
                "report.track_error.median",
                "track-based true error: median (m)",
            ),
            (
                "report.track_error.thresholds[*].sliding_fraction",
                "sliding points (true error − surface distance > τ)",
            ),
        ];
        let mut now = catalogue_specs(SWEEP);
        now.extend(catalogue_specs(SWEEP_VISIBILITY));
        let before: Vec<(String, String)> = before
            .iter()
            .map(|(p, l)| (p.to_string(), l.to_string()))
            .collect();
        assert_eq!(now, before);
    }

    #[test]
    fn visibility_metrics_only_when_a_report_has_them() {
        let cell = |doc: Json| Cell {
            value: ("1".into(), 1.0),
            dataset: "d".into(),
            pipeline: "p".into(),
            status: "ok".into(),
            reason: None,
            doc,
        };
        let plain = json!({"report": {"thresholds": [{"tau": 0.01, "recall": 0.3}]}});
        let without = metrics(&[], &[cell(plain.clone())]);
        assert!(
            !without
                .iter()
                .any(|m| m.path.contains("visible") || m.path.contains("track"))
        );
        let with = json!({"report": {
            "thresholds": [{"tau": 0.01, "recall": 0.3}],
            "completeness_visible": {"visible_fraction": 0.8,
                "thresholds": [{"tau": 0.01, "recall_visible": 0.4}]},
            "track_error": {"median": 0.001, "thresholds": [{"tau": 0.01, "sliding_fraction": 0.02}]}}});
        let m = metrics(&[], &[cell(plain), cell(with.clone())]);
        let paths: Vec<&str> = m.iter().map(|m| m.path.as_str()).collect();
        for p in [
            "report.completeness_visible.thresholds[0].recall_visible",
            "report.completeness_visible.visible_fraction",
            "report.track_error.median",
            "report.track_error.thresholds[0].sliding_fraction",
        ] {
            assert!(paths.contains(&p), "{p} missing from {paths:?}");
            assert!(lookup(&with, p).is_some(), "{p}");
        }
    }
}
