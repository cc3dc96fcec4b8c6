//! The order of the tables: datasets by name, pipelines built-ins first.

use std::collections::BTreeSet;

use crate::row::Row;

/// The runner's built-in pipelines, in table order (the runner's adapters have these names).
pub const BUILTIN_PIPELINES: [&str; 8] = [
    "colmap",
    "pycolmap",
    "pycolmap-global",
    "theia",
    "theia-incremental",
    "openmvg",
    "openmvg-global",
    "visualsfm",
];

/// Pipelines in table order: built-ins first (their fixed order), then others by name.
pub fn pipeline_order(rows: &[Row]) -> Vec<String> {
    let names: BTreeSet<&str> = rows.iter().map(|r| r.pipeline.as_str()).collect();
    let mut out: Vec<String> = BUILTIN_PIPELINES
        .iter()
        .filter(|b| names.contains(*b))
        .map(|s| s.to_string())
        .collect();
    out.extend(
        names
            .iter()
            .filter(|n| !BUILTIN_PIPELINES.contains(*n))
            .map(|s| s.to_string()),
    );
    out
}

/// Datasets in table order (by name).
pub fn dataset_order(rows: &[Row]) -> Vec<String> {
    let s: BTreeSet<&str> = rows.iter().map(|r| r.dataset.as_str()).collect();
    s.into_iter().map(String::from).collect()
}

/// The row of dataset `d` and pipeline `p`.
pub fn find<'a>(rows: &'a [Row], d: &str, p: &str) -> Option<&'a Row> {
    rows.iter().find(|r| r.dataset == d && r.pipeline == p)
}
