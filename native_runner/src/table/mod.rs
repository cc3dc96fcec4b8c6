//! The comparison tables of `report`, from its rows: Table I and the wide table of every run
//! as Markdown and CSV, the HTML page with both and their charts, and `summary.json`.

pub mod cells;
pub mod order;
pub mod page;

use std::path::Path;

use anyhow::Result;

use sfmeval_fs::write_atomic;

use crate::csv::CsvWriter;
use crate::row::Row;
use crate::table::cells::{csv_num, n_tau, table1_cell, wide_columns, wide_values};
use crate::table::order::{dataset_order, find, pipeline_order};

/// Writes `table1.md`, `table1.csv`, `runs.csv`, `table.md` (both tables), `index.html` and
/// `summary.json` into `out`.
pub fn write_tables(out: &Path, rows: &[Row]) -> Result<()> {
    let datasets = dataset_order(rows);
    let pipes = pipeline_order(rows);
    // Table I.
    let mut t1 = String::from("| dataset |");
    for p in &pipes {
        t1.push_str(&format!(" {p} |"));
    }
    t1.push_str("\n|---|");
    t1.push_str(&"---:|".repeat(pipes.len()));
    t1.push('\n');
    for d in &datasets {
        t1.push_str(&format!("| {d} |"));
        for p in &pipes {
            t1.push_str(&format!(" {} |", table1_cell(find(rows, d, p))));
        }
        t1.push('\n');
    }
    let t1_md = format!(
        "# Table I: mean distance to the ground truth (m) and number of points\n\nEach cell: mean reconstruction → ground-truth distance in metres (after `auto` alignment), and in parentheses the number of points; failed runs show why.\n\n{t1}"
    );
    write_atomic(&out.join("table1.md"), t1_md.as_bytes())?;
    let mut csv = CsvWriter::new();
    let mut header = vec!["dataset".to_string()];
    for p in &pipes {
        header.extend([
            format!("{p}.mean_m"),
            format!("{p}.points"),
            format!("{p}.status"),
        ]);
    }
    csv.record(&header);
    for d in &datasets {
        let mut record = vec![d.clone()];
        for p in &pipes {
            match find(rows, d, p) {
                Some(r) => record.extend([
                    csv_num(r.mean),
                    if r.mean.is_some() {
                        r.points.to_string()
                    } else {
                        String::new()
                    },
                    r.status.clone(),
                ]),
                None => record.extend([String::new(), String::new(), String::new()]),
            }
        }
        csv.record(&record);
    }
    write_atomic(&out.join("table1.csv"), csv.finish().as_bytes())?;
    // Wide table.
    let cols = wide_columns(rows);
    let nt = n_tau(rows);
    let mut ordered: Vec<&Row> = Vec::new();
    for d in &datasets {
        for p in &pipes {
            if let Some(r) = find(rows, d, p) {
                ordered.push(r);
            }
        }
    }
    let mut wide = format!("| {} |\n|{}\n", cols.join(" | "), "---|".repeat(cols.len()));
    for r in &ordered {
        wide.push_str(&format!("| {} |\n", wide_values(r, nt, false).join(" | ")));
    }
    let mut wcsv = CsvWriter::new();
    wcsv.record(&cols);
    for r in &ordered {
        wcsv.record(wide_values(r, nt, true));
    }
    write_atomic(&out.join("runs.csv"), wcsv.finish().as_bytes())?;
    let md = format!(
        "{t1_md}\n# All runs\n\nP/R/F at thresholds in % of the ground-truth bounding-box diagonal; camera errors after the same alignment, centre errors also in % of the scene radius (mean distance of the ground-truth cameras from their centroid).\n\n{wide}"
    );
    write_atomic(&out.join("table.md"), md.as_bytes())?;
    write_atomic(
        &out.join("index.html"),
        page::page(rows, &datasets, &pipes).as_bytes(),
    )?;
    let mut json = serde_json::to_string_pretty(&serde_json::json!({
        "schema": "sfmeval.runner-table/1",
        "datasets": datasets,
        "pipelines": pipes,
        "rows": rows,
    }))?;
    json.push('\n');
    write_atomic(&out.join("summary.json"), json.as_bytes())?;
    Ok(())
}
