//! The summary documents of a batch — `table1.json` and, for a `run` batch, `batch.json` — one
//! type each, written by both executors (local and Slurm) with the same keys; only the measured
//! times and `executor` differ between them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::{Deserialize, Serialize};
use sfmeval_fs::write_atomic;

/// Where the batch ran.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Executor {
    /// In this process.
    Local,
    /// As Slurm job arrays (the summary is written by the collect stage).
    Slurm,
}

/// A task of a Slurm batch that left no result (its cell is a failed or timed-out run).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskWithoutResult {
    /// Its index in the run stage.
    pub task: usize,
    /// Dataset name.
    pub dataset: String,
    /// Pipeline name.
    pub pipeline: String,
    /// The status its run got (`failed`, `timeout`).
    pub status: String,
    /// Why, naming its Slurm output file.
    pub reason: String,
}

/// The times of a `table1` (seconds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Table1Timing {
    /// Per dataset rendered by this batch: locally the wall time of its generator calls, on
    /// Slurm the render time its parts measured (`timing.json`'s `render_seconds_total`).
    pub render_seconds: BTreeMap<String, f64>,
    /// Per dataset rendered by this batch: mean render seconds of a view (`timing.json`).
    pub render_seconds_per_view: BTreeMap<String, f64>,
    /// Getting the datasets (locally: rendering or reusing them; on Slurm: the sum of
    /// `render_seconds`).
    pub datasets_seconds: f64,
    /// The runs (locally their wall time; on Slurm the sum of the runs' wall times).
    pub runs_seconds: f64,
    /// Evaluating the runs and writing the tables.
    pub report_seconds: f64,
    /// The whole batch (on Slurm: from its first submission to the end of the collect).
    pub total_seconds: f64,
}

/// `OUT/table1.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Table1Summary {
    /// `--quick`.
    pub quick: bool,
    /// The presets, in table order.
    pub presets: Vec<String>,
    /// The pipeline names, in table order.
    pub pipelines: Vec<String>,
    /// Where it ran.
    pub executor: Executor,
    /// Runs executed by this batch, by status.
    pub runs_executed: BTreeMap<String, usize>,
    /// Finished runs reused (locally: from an earlier call; a Slurm task with its result is
    /// not run again and counts as executed).
    pub runs_reused: usize,
    /// Slurm tasks that left no result (always empty locally).
    pub tasks_without_result: Vec<TaskWithoutResult>,
    /// The times.
    pub timing: Table1Timing,
}

/// The times of a `run` batch (seconds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BatchTiming {
    /// The runs (locally their wall time; on Slurm the sum of the runs' wall times).
    pub runs_seconds: f64,
    /// Evaluating the runs and writing the tables (null for a local `run`, which does not
    /// evaluate: `report` does).
    pub report_seconds: Option<f64>,
    /// The whole batch (on Slurm: from its first submission to the end of the collect).
    pub total_seconds: f64,
}

/// `OUT/batch.json` of `run`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BatchSummary {
    /// Where it ran.
    pub executor: Executor,
    /// The dataset folders.
    pub datasets: Vec<PathBuf>,
    /// The pipeline names, in table order.
    pub pipelines: Vec<String>,
    /// Runs executed by this batch, by status.
    pub runs_executed: BTreeMap<String, usize>,
    /// Finished runs reused (locally: `--resume`; a Slurm task with its result is not run again
    /// and counts as executed).
    pub runs_reused: usize,
    /// Slurm tasks that left no result (always empty locally).
    pub tasks_without_result: Vec<TaskWithoutResult>,
    /// The times.
    pub timing: BatchTiming,
}

/// Render times as the generator measured them (`<dataset>/timing.json`): (total, mean per
/// view) of each dataset folder that has one.
pub fn render_times<'a>(
    datasets: impl IntoIterator<Item = (&'a str, PathBuf)>,
) -> (BTreeMap<String, f64>, BTreeMap<String, f64>) {
    let mut total = BTreeMap::new();
    let mut per_view = BTreeMap::new();
    for (name, dir) in datasets {
        let Some(t) = std::fs::read(dir.join("timing.json"))
            .ok()
            .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        else {
            continue;
        };
        if let Some(s) = t["render_seconds_total"].as_f64() {
            total.insert(name.to_string(), s);
        }
        if let Some(s) = t["render_seconds_mean"].as_f64() {
            per_view.insert(name.to_string(), s);
        }
    }
    (total, per_view)
}

/// Writes a summary as pretty JSON with a final newline.
pub fn write_summary<T: Serialize>(path: &Path, doc: &T) -> Result<()> {
    let mut text = serde_json::to_string_pretty(doc)?;
    text.push('\n');
    write_atomic(path, text.as_bytes())
}

/// Now, in seconds since the Unix epoch.
pub fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}
