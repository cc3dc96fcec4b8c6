//! The page's Compare table: the catalogue's [`COMPARE`] columns of each compared
//! reconstruction (its row and, when evaluated, its report), each cell's number, its text as the
//! page shows it and whether it is the best of its column. The page draws this table as it is
//! (through the wasm bindings) and only sorts its rows.

use serde::{Deserialize, Serialize};
use serde_json::Value as Json;

use crate::catalogue::{Best, COMPARE, Metric, WIDE_POSES, metrics_of};
use crate::cells::for_columns;
use crate::number::compact;
use crate::row::Row;

/// One compared reconstruction: its row of the tables and its report (none when it was not
/// evaluated).
#[derive(Debug, Clone, Deserialize)]
pub struct Entry {
    /// Its row (`run_row` / `summary.json`).
    pub row: Row,
    /// Its `sfmeval.report/3` as JSON.
    #[serde(default)]
    pub report: Option<Json>,
}

/// A column of the Compare table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Column {
    /// The catalogue's id, with the threshold's index for a per-threshold metric (`f0`).
    pub id: String,
    /// The catalogue's key, the threshold's index in place of `[*]`.
    pub key: String,
    /// Header (`mean`, `F@0.5%`).
    pub header: String,
    /// Unit, if any.
    pub unit: Option<String>,
    /// Which end is best (none for text).
    pub best: Option<Best>,
    /// Whether the column holds text.
    pub text: bool,
}

/// A cell of the Compare table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cell {
    /// Its number (none for text or a missing value).
    pub value: Option<f64>,
    /// What the page shows.
    pub text: String,
    /// The best value of its column (of two values or more).
    pub best: bool,
}

/// The Compare table: columns, then each entry's cells in the columns' order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CompareTable {
    /// Columns.
    pub columns: Vec<Column>,
    /// Cells of each entry, in the entries' order.
    pub rows: Vec<Vec<Cell>>,
}

/// The Compare table of `entries`: per-threshold columns for the most thresholds an entry has,
/// named by the first report's thresholds; the pose protocols' columns ([`WIDE_POSES`], as in
/// the wide table) before the status when some entry's row has them.
pub fn compare_table(entries: &[Entry]) -> CompareTable {
    let n_tau = entries
        .iter()
        .map(|e| {
            e.report
                .as_ref()
                .and_then(|r| r.get("thresholds"))
                .and_then(Json::as_array)
                .map_or(0, Vec::len)
        })
        .max()
        .unwrap_or(0);
    let pcts: Vec<Option<f64>> = (0..n_tau)
        .map(|k| {
            entries
                .iter()
                .find_map(|e| e.report.as_ref())
                .and_then(|r| {
                    crate::catalogue::lookup(r, &format!("thresholds[{k}].tau_percent_of_diagonal"))
                })
                .map(|p| (p * 1e6).round() / 1e6)
        })
        .collect();
    let docs: Vec<Json> = entries
        .iter()
        .map(|e| serde_json::json!({ "report": e.report }))
        .collect();
    let mut columns = Vec::new();
    let mut cells: Vec<Vec<Cell>> = vec![Vec::new(); entries.len()];
    let mut keys = COMPARE.to_vec();
    if entries.iter().any(|e| e.row.poses.is_some()) {
        let at = keys.len().saturating_sub(1);
        keys.splice(at..at, WIDE_POSES.iter().copied());
    }
    for_columns(&metrics_of(&keys), n_tau, |m, k| {
        let kk = k.unwrap_or(0);
        columns.push(Column {
            id: m.id_at(kk),
            key: m.key_at(kk),
            header: m.header_at(k.and_then(|k| pcts[k])),
            unit: m.unit.map(String::from),
            best: m.best,
            text: m.is_text(),
        });
        let column: Vec<Cell> = entries
            .iter()
            .zip(&docs)
            .map(|(e, doc)| cell(m, &e.row, kk, doc))
            .collect();
        let best = best_of(m, &column);
        for (row, mut c) in cells.iter_mut().zip(column) {
            c.best = best.is_some_and(|b| c.value == Some(b));
            row.push(c);
        }
    });
    CompareTable {
        columns,
        rows: cells,
    }
}

fn cell(m: &Metric, row: &Row, k: usize, doc: &Json) -> Cell {
    if let crate::catalogue::Source::Text(f) = m.source {
        return Cell {
            value: None,
            text: f(row, false),
            best: false,
        };
    }
    let value = m.number(row, k, Some(doc));
    Cell {
        value,
        text: m.shown.map_or_else(|| compact(value), |f| f(row)),
        best: false,
    }
}

/// The best finite value of a column with two or more of them.
fn best_of(m: &Metric, column: &[Cell]) -> Option<f64> {
    let vals: Vec<f64> = column
        .iter()
        .filter_map(|c| c.value)
        .filter(|v| v.is_finite())
        .collect();
    if vals.len() < 2 {
        return None;
    }
    match m.best? {
        Best::Lower => vals.into_iter().reduce(f64::min),
        Best::Higher => vals.into_iter().reduce(f64::max),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::run::{RunFacts, Status, base_row};
    use serde_json::json;

    fn entry(p: &str, mean: Option<f64>, registered: usize) -> Entry {
        let mut row = base_row(&RunFacts {
            dataset: "d".into(),
            pipeline: p.into(),
            tool: "t".into(),
            version: None,
            status: if mean.is_some() {
                Status::Ok
            } else {
                Status::Failed
            },
            reason: None,
            wall_seconds: 1.0,
            cpu_seconds: 1.0,
            peak_memory_bytes: 0,
            images_total: 36,
            images_registered: registered,
            points: 100,
        });
        row.mean = mean;
        let report = mean.map(|m| {
            json!({"accuracy": {"mean": m, "min": m / 2.0, "std": 0.25},
                "thresholds": [{"tau_percent_of_diagonal": 0.5, "f_score": m}],
                "cameras": {"ate_rmse": 0.001}})
        });
        if let Some(m) = mean {
            row.thresholds = vec![crate::row::Prf {
                tau: 0.01,
                tau_percent_of_diagonal: 0.5,
                precision: 0.0,
                recall: 0.0,
                f_score: m,
            }];
        }
        Entry { row, report }
    }

    #[test]
    fn columns_cells_and_best_ends_come_from_the_catalogue() {
        let t = compare_table(&[
            entry("a", Some(0.25), 30),
            entry("b", Some(0.125), 36),
            entry("c", None, 0),
        ]);
        let ids: Vec<&str> = t.columns.iter().map(|c| c.id.as_str()).collect();
        assert_eq!(
            ids,
            [
                "pipeline",
                "registered",
                "points",
                "min",
                "max",
                "mean",
                "median",
                "std",
                "completeness",
                "f0",
                "ate",
                "status"
            ]
        );
        let col = |id: &str| t.columns.iter().position(|c| c.id == id).unwrap();
        assert_eq!(t.columns[col("f0")].header, "F@0.5%");
        assert_eq!(t.columns[col("mean")].best, Some(Best::Lower));
        // lowest mean, highest F (the same run), most registered
        assert!(t.rows[1][col("mean")].best && !t.rows[0][col("mean")].best);
        assert!(t.rows[0][col("f0")].best && !t.rows[1][col("f0")].best);
        assert!(t.rows[1][col("registered")].best);
        assert_eq!(t.rows[1][col("registered")].text, "36/36");
        assert_eq!(t.rows[0][col("min")].text, "0.1250");
        assert_eq!(t.rows[0][col("points")].text, "100");
        // the run that was not evaluated: no numbers, its status in words
        assert_eq!(t.rows[2][col("mean")].value, None);
        assert_eq!(t.rows[2][col("mean")].text, "—");
        assert_eq!(t.rows[2][col("points")].value, None);
        assert_eq!(t.rows[2][col("status")].text, "failed");
        // equal values are both best; a column without two values has none
        assert!(t.rows[0][col("ate")].best && t.rows[1][col("ate")].best);
        assert!(!t.rows.iter().any(|r| r[col("median")].best));
    }

    #[test]
    fn pose_columns_join_before_the_status_when_a_row_has_them() {
        let plain = compare_table(&[entry("a", Some(0.25), 30)]);
        assert!(
            !plain
                .columns
                .iter()
                .any(|c| c.key.starts_with("run.poses."))
        );
        let mut with = entry("b", Some(0.125), 36);
        with.row.poses = Some(
            serde_json::from_value(json!({
                "colmap": {"thresholds_deg": [0.5, 1.0, 5.0, 10.0],
                    "auc_percent": [10.0, 20.0, 30.0, 40.0], "recall_percent": [1.0, 2.0, 3.0, 4.0],
                    "position_accuracy": 0.0, "pairs": 2, "pairs_unregistered": 0,
                    "pairs_outside_gt": 0, "median_error_deg": 0.5},
                "imc": {"thresholds_deg": [1.0], "accuracy": [0.5], "maa_5": 0.25, "maa_10": 0.75,
                    "pairs": 1, "pairs_unregistered": 0, "model_valid": true},
                "co3d": {"thresholds_deg": [5.0, 15.0, 30.0], "rra_percent": [50.0, 60.0, 70.0],
                    "rta_percent": [5.0, 6.0, 7.0], "auc_max_deg": 30.0, "auc_percent": 42.5,
                    "pairs": 1, "pairs_unregistered": 0}
            }))
            .unwrap(),
        );
        let t = compare_table(&[entry("a", Some(0.25), 30), with]);
        let col = |id: &str| t.columns.iter().position(|c| c.id == id).unwrap();
        assert_eq!(col("colmap_auc0"), col("ate") + 1);
        assert_eq!(col("co3d_auc") + 1, col("status"));
        assert_eq!(t.columns[col("colmap_auc3")].header, "COLMAP AUC@10°");
        assert_eq!(t.columns[col("colmap_auc3")].unit.as_deref(), Some("%"));
        assert_eq!(t.rows[1][col("colmap_auc3")].value, Some(40.0));
        assert_eq!(t.rows[1][col("imc_maa")].value, Some(0.75));
        assert_eq!(t.rows[1][col("co3d_rta2")].value, Some(7.0));
        assert_eq!(t.rows[1][col("co3d_auc")].value, Some(42.5));
        assert_eq!(t.rows[0][col("co3d_auc")].value, None);
    }
}
