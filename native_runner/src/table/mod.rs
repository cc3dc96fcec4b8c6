//! The comparison tables of `report`, from its rows: the text of Table I and the wide table
//! (Markdown and CSV, built by `sfmeval_table`), the HTML page with both and their charts, and
//! `summary.json`, written into the table folder.

pub mod page;

use std::path::Path;

use anyhow::Result;

use sfmeval_fs::write_atomic;
use sfmeval_table::order::{dataset_order, pipeline_order};
use sfmeval_table::{Row, summary_json, tables};

/// Writes `table1.md`, `table1.csv`, `runs.csv`, `table.md` (both tables), `index.html` and
/// `summary.json` into `out`.
pub fn write_tables(out: &Path, rows: &[Row]) -> Result<()> {
    let t = tables(rows);
    write_atomic(&out.join("table1.md"), t.table1_md.as_bytes())?;
    write_atomic(&out.join("table1.csv"), t.table1_csv.as_bytes())?;
    write_atomic(&out.join("runs.csv"), t.runs_csv.as_bytes())?;
    write_atomic(&out.join("table.md"), t.table_md.as_bytes())?;
    let datasets = dataset_order(rows);
    let pipes = pipeline_order(rows);
    write_atomic(
        &out.join("index.html"),
        page::page(rows, &datasets, &pipes).as_bytes(),
    )?;
    write_atomic(&out.join("summary.json"), summary_json(rows)?.as_bytes())?;
    Ok(())
}
