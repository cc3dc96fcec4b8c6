//! `sweep.csv`: every cell's status and metric values.

use crate::sweep::cells::Cell;
use crate::sweep::factor::Factor;
use crate::sweep::metrics::{Metric, lookup};
use sfmeval_table::csv::CsvWriter;

/// `sweep.csv`: one row per (value, pipeline): factor, value, dataset, pipeline, status,
/// reason, then every metric (empty where there is none).
pub fn csv(factor: Factor, cells: &[Cell], metrics: &[Metric]) -> String {
    let mut w = CsvWriter::new();
    let mut header: Vec<String> = ["factor", "value", "dataset", "pipeline", "status", "reason"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    header.extend(metrics.iter().map(|m| m.path.clone()));
    w.record(&header);
    for c in cells {
        let mut record = vec![
            factor.name().to_string(),
            c.value.0.clone(),
            c.dataset.clone(),
            c.pipeline.clone(),
            c.status.clone(),
            c.reason.clone().unwrap_or_default().replace('\n', " "),
        ];
        record.extend(metrics.iter().map(|m| {
            lookup(&c.doc, &m.path)
                .map(|x| format!("{x}"))
                .unwrap_or_default()
        }));
        w.record(&record);
    }
    w.finish()
}
