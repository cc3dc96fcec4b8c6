//! The sweep's grid: one cell per (factor value, pipeline), with the run's status and the
//! document its metrics are read from.

use std::path::Path;

use serde_json::Value as Json;

use crate::sweep::variants::{Planned, Variant};
use sfmeval_table::Row;

/// One (value, pipeline) cell of the sweep.
#[derive(Debug, Clone)]
pub struct Cell {
    /// Factor value text and number.
    pub value: (String, f64),
    /// Dataset name.
    pub dataset: String,
    /// Pipeline name.
    pub pipeline: String,
    /// `ok`, `failed`, `timeout`, `not installed`, `evaluation failed`, `generation failed`, `not run`.
    pub status: String,
    /// Why not ok.
    pub reason: Option<String>,
    /// `{"report": ..., "run": ...}`.
    pub doc: Json,
}

/// The run's row as JSON, plus `registered_fraction`.
fn run_doc(row: &Row) -> Json {
    let mut v = serde_json::to_value(row).unwrap_or(Json::Null);
    if let Json::Object(o) = &mut v {
        o.remove("cdf");
        if row.images_total > 0 {
            o.insert(
                "registered_fraction".into(),
                Json::from(row.images_registered as f64 / row.images_total as f64),
            );
        }
    }
    v
}

/// Every (value, pipeline) cell, values in `planned` order and pipelines in `pipes` order: a
/// variant that failed to render is `generation failed`, a run the report has no row for `not
/// run`, any other the row's status with `{"report": <its report under table/>, "run": <the
/// row>}`.
pub fn collect(
    planned: &[Planned],
    variants: &[Variant],
    pipes: &[String],
    rows: &[Row],
    table: &Path,
) -> Vec<Cell> {
    let mut cells: Vec<Cell> = Vec::new();
    for (pl, v) in planned.iter().zip(variants) {
        let (text, x, name) = (&pl.text, &pl.x, &pl.dataset);
        for p in pipes {
            let row = rows.iter().find(|r| &r.dataset == name && &r.pipeline == p);
            let (status, reason, doc) = match (v.status.as_str(), row) {
                ("failed", _) => (
                    "generation failed".to_string(),
                    v.reason.clone(),
                    Json::Null,
                ),
                (_, None) => ("not run".to_string(), None, Json::Null),
                (_, Some(r)) => {
                    let report = r
                        .report
                        .as_ref()
                        .and_then(|rel| std::fs::read(table.join(rel)).ok())
                        .and_then(|b| serde_json::from_slice::<Json>(&b).ok())
                        .unwrap_or(Json::Null);
                    (
                        r.status.clone(),
                        r.reason.clone(),
                        serde_json::json!({"report": report, "run": run_doc(r)}),
                    )
                }
            };
            cells.push(Cell {
                value: (text.clone(), *x),
                dataset: name.clone(),
                pipeline: p.clone(),
                status,
                reason,
                doc,
            });
        }
    }
    cells
}
