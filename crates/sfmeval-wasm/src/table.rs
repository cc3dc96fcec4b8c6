//! The comparison tables of `sfmeval-runner report` for the page: a run's row from its
//! `run.json` (and its evaluation), and the tables' text from the rows, through the same
//! `sfmeval_table` code the runner uses.

use sfmeval::evaluate::PointStatus;
use sfmeval_table::{Row, RunFacts};
use wasm_bindgen::prelude::*;

use crate::{Evaluation, js_err};

fn facts(run_json: &str) -> Result<RunFacts, JsError> {
    RunFacts::parse(run_json).map_err(|e| js_err("run.json", e))
}

fn row_json(row: &Row) -> Result<String, JsError> {
    serde_json::to_string(row).map_err(|e| js_err("row", e))
}

/// The row of a run that was not evaluated (not `ok`), from its `run.json` text, as JSON.
#[wasm_bindgen(js_name = runRow)]
pub fn run_row(run_json: &str) -> Result<String, JsError> {
    row_json(&sfmeval_table::run::base_row(&facts(run_json)?))
}

#[wasm_bindgen]
impl Evaluation {
    /// This evaluation's row of the comparison tables, for the run whose `run.json` text is
    /// given (as JSON): what `sfmeval-runner report` puts in `summary.json`, with the pose
    /// protocols' numbers when both sides have cameras.
    #[wasm_bindgen(js_name = runRow)]
    pub fn run_row(&self, run_json: &str) -> Result<String, JsError> {
        let kept: Vec<f64> = self
            .inner
            .distances
            .iter()
            .zip(&self.inner.status)
            .filter(|(_, s)| matches!(s, PointStatus::Kept))
            .map(|(d, _)| *d)
            .collect();
        let mut row =
            sfmeval_table::run::evaluated_row(&facts(run_json)?, &self.inner.report, &kept);
        row.poses.clone_from(&self.poses);
        row_json(&row)
    }
}

/// The tables of `rows_json` (a JSON array of rows): `{table1_md, table1_csv, runs_csv,
/// table_md, summary_json}`, each the text of the runner's file of that name.
#[wasm_bindgen(js_name = comparisonTables)]
pub fn comparison_tables(rows_json: &str) -> Result<JsValue, JsError> {
    let rows: Vec<Row> = serde_json::from_str(rows_json).map_err(|e| js_err("rows", e))?;
    let t = sfmeval_table::tables(&rows);
    let summary = sfmeval_table::summary_json(&rows).map_err(|e| js_err("rows", e))?;
    let out = serde_json::json!({
        "table1_md": t.table1_md,
        "table1_csv": t.table1_csv,
        "runs_csv": t.runs_csv,
        "table_md": t.table_md,
        "summary_json": summary,
    });
    serde::Serialize::serialize(&out, &serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| js_err("tables", e.to_string()))
}

pub(crate) fn to_js<T: serde::Serialize>(what: &str, v: &T) -> Result<JsValue, JsError> {
    v.serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| js_err(what, e.to_string()))
}

/// The page's Compare table of `entries_json` (a JSON array of `{row, report}`, `report` the
/// evaluation's `sfmeval.report/3` or null): `{columns: [{id, key, header, unit, best, text}],
/// rows: [[{value, text, best}]]}`, columns from `sfmeval_table`'s catalogue, texts and best
/// marks decided there.
#[wasm_bindgen(js_name = compareTable)]
pub fn compare_table(entries_json: &str) -> Result<JsValue, JsError> {
    let entries: Vec<sfmeval_table::Entry> =
        serde_json::from_str(entries_json).map_err(|e| js_err("compare entries", e))?;
    to_js("compare table", &sfmeval_table::compare_table(&entries))
}

/// The comparison's metrics (`sfmeval_table`'s catalogue): `[{key, id, header, unit, name, best,
/// digits}]`.
#[wasm_bindgen(js_name = metricCatalogue)]
pub fn metric_catalogue() -> Result<JsValue, JsError> {
    to_js("catalogue", &sfmeval_table::CATALOGUE)
}

/// Which of a run folder's files form its reconstruction (`sfmeval_table::layout`), given the
/// paths relative to the folder as a JSON array: `[[path, name]]`, `name` as the
/// reconstruction's readers key it (the runner's `report` reads the same).
#[wasm_bindgen(js_name = runReconstructionFiles)]
pub fn run_reconstruction_files(paths_json: &str) -> Result<JsValue, JsError> {
    let paths: Vec<String> =
        serde_json::from_str(paths_json).map_err(|e| js_err("run folder paths", e))?;
    to_js(
        "run folder",
        &sfmeval_table::layout::reconstruction_files(&paths),
    )
}
