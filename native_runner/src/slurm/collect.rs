//! The collect task of a Slurm batch: every run task's result is merged into `OUT/runs/`; a
//! task that left none (cancelled, timed out, its node failed, its dataset never rendered)
//! becomes a run with status `failed` or `timeout` and the reason from its Slurm output file,
//! so the table is written with that cell marked; then the batch's outputs are written by the
//! one collect both executors use ([`crate::batch::collect::results`]).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use sfmeval_fs::write_atomic;

use crate::batch::collect::{DatasetOutcome, Outcome, results};
use crate::batch::plan::{CellPlan, Job, Plan, Stage};
use crate::batch::state::{dataset_done, task_done};
use crate::dataset::Dataset;
use crate::files::{copy_dir, partial_name, replace_dir};
use crate::pipelines::{parse_customs, parse_list};
use crate::run::{RunRecord, Status, read_record};
use crate::slurm::state::{end_reason, slurm_end};
use crate::slurm::submit::{SubmissionRecord, job_of_task, read_records};
use crate::summary::{Executor, TaskWithoutResult, render_times, unix_now};

/// Why run task `k` has no result: its dataset's missing render or finalize task, or itself.
fn why_missing(
    plan: &Plan,
    records: &[SubmissionRecord],
    k: usize,
    cell: &CellPlan,
) -> (Status, String) {
    // how Slurm recorded the task's job, while it keeps the record
    let ended = |stage: Stage, k: usize| {
        let slurm = job_of_task(records, stage, k).and_then(|j| slurm_end(&j));
        end_reason(&plan.log(stage, k), slurm.as_ref())
    };
    if dataset_done(plan, &cell.dataset) {
        let (st, why) = ended(Stage::Run, k);
        return (st, format!("Slurm run task {k}: {why}"));
    }
    let n = plan.render_shards;
    if n == 0 {
        return (
            Status::Failed,
            format!(
                "dataset {} is gone: no images/ in {}",
                cell.dataset,
                plan.dataset_dir(&cell.dataset).display()
            ),
        );
    }
    let d = plan
        .datasets
        .iter()
        .position(|d| d.name == cell.dataset)
        .unwrap_or(0);
    for r in d * n..(d + 1) * n {
        if !task_done(plan, Stage::Render, r) {
            let (st, why) = ended(Stage::Render, r);
            return (
                st,
                format!(
                    "dataset {} not rendered: Slurm render task {r}: {why}",
                    cell.dataset
                ),
            );
        }
    }
    let (st, why) = ended(Stage::Finalize, d);
    (
        st,
        format!(
            "dataset {} not finalized: Slurm finalize task {d}: {why}",
            cell.dataset
        ),
    )
}

/// The run folder of a cell without result: `run.json` (status, reason) and `log.txt`.
fn write_missing_run(
    plan: &Plan,
    cell: &CellPlan,
    kind_tool: (String, String),
    options: BTreeMap<String, String>,
    (status, reason): (Status, String),
    dest: &Path,
) -> Result<()> {
    let dataset_dir = plan.dataset_dir(&cell.dataset);
    let now = unix_now();
    let rec = RunRecord {
        status,
        reason: Some(reason.clone()),
        finished_unix: now,
        warnings: vec![
            "no result from its Slurm task: the batch's command with --resume redoes it".into(),
        ],
        ..RunRecord::not_run(
            &cell.dataset,
            &dataset_dir,
            Dataset::open(&dataset_dir).map_or(0, |d| d.image_count),
            &cell.pipeline,
            &kind_tool.0,
            &kind_tool.1,
            options,
        )
    };
    let tmp = partial_name(dest);
    std::fs::create_dir_all(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
    write_atomic(
        &tmp.join(&rec.log),
        format!("# {}: {reason}\n", status.label()).as_bytes(),
    )?;
    let mut text = serde_json::to_string_pretty(&rec)?;
    text.push('\n');
    write_atomic(&tmp.join("run.json"), text.as_bytes())?;
    replace_dir(&tmp, dest)
}

/// What the merge found.
struct Merged {
    /// Runs with a result, by status.
    executed: BTreeMap<String, usize>,
    /// The tasks without result (task, dataset, pipeline, status, reason).
    without_result: Vec<TaskWithoutResult>,
    /// Wall seconds of the runs with a result.
    runs_seconds: f64,
}

/// Merges every run task's result into `OUT/runs/`; a task without result becomes a failed
/// run there.
fn merge_runs(plan: &Plan, job: &Job) -> Result<Merged> {
    let customs = parse_customs(&job.tools().customs)?;
    let specs = parse_list(job.pipelines(), &customs)?;
    let runs = plan.out.join("runs");
    let records = read_records(plan)?;
    let mut m = Merged {
        executed: BTreeMap::new(),
        without_result: Vec::new(),
        runs_seconds: 0.0,
    };
    for (k, cell) in plan.cells.iter().enumerate() {
        let dest = runs.join(&cell.dataset).join(&cell.pipeline);
        let src = plan.task_runs(k).join(&cell.dataset).join(&cell.pipeline);
        if let Some(p) = dest.parent() {
            std::fs::create_dir_all(p).with_context(|| format!("creating {}", p.display()))?;
        }
        if src.join("run.json").is_file() {
            let rec = read_record(&src)?;
            *m.executed
                .entry(rec.status.label().to_string())
                .or_default() += 1;
            m.runs_seconds += rec.wall_seconds;
            let same = std::fs::read(dest.join("run.json")).ok()
                == std::fs::read(src.join("run.json")).ok();
            if !same {
                let tmp = partial_name(&dest);
                copy_dir(&src, &tmp)?;
                replace_dir(&tmp, &dest)?;
            }
            continue;
        }
        let why = why_missing(plan, &records, k, cell);
        eprintln!(
            "{}/{}: {}: {}",
            cell.dataset,
            cell.pipeline,
            why.0.label(),
            why.1
        );
        m.without_result.push(TaskWithoutResult {
            task: k,
            dataset: cell.dataset.clone(),
            pipeline: cell.pipeline.clone(),
            status: why.0.label().to_string(),
            reason: why.1.clone(),
        });
        let spec = specs.iter().find(|s| s.name == cell.pipeline);
        let kind_tool = match spec.map(|s| (s, s.adapter(&customs))) {
            Some((s, Ok(ad))) => (s.kind.clone(), ad.tool().to_string()),
            _ => (cell.pipeline.clone(), cell.pipeline.clone()),
        };
        let options = spec.map(|s| s.options.clone()).unwrap_or_default();
        write_missing_run(plan, cell, kind_tool, options, why, &dest)?;
    }
    Ok(m)
}

/// Merges the runs, marks the missing ones and writes the batch's outputs (the datasets'
/// render times as the generator's parts measured them; the total from the batch's first
/// submission).
pub fn collect(plan: &Plan) -> Result<()> {
    let now = unix_now();
    let job = plan.job()?;
    let merged = merge_runs(plan, &job)?;
    let (render_seconds, _) = render_times(
        plan.datasets
            .iter()
            .map(|d| (d.name.as_str(), plan.dataset_dir(&d.name))),
    );
    let datasets = plan
        .datasets
        .iter()
        .map(|d| {
            let o = if d.dir.is_some() {
                DatasetOutcome::given()
            } else if dataset_done(plan, &d.name) {
                DatasetOutcome::rendered(render_seconds.get(&d.name).copied())
            } else {
                DatasetOutcome::failed(
                    "not rendered by its Slurm tasks (see OUT/slurm/logs/)".into(),
                )
            };
            (d.name.clone(), o)
        })
        .collect();
    let started_unix = read_records(plan)
        .ok()
        .and_then(|r| r.first().map(|r| r.submitted_unix))
        .filter(|t| t.is_finite() && *t < now)
        .unwrap_or(now);
    let outcome = Outcome {
        executor: Executor::Slurm,
        datasets,
        runs_executed: merged.executed,
        runs_reused: 0,
        tasks_without_result: merged.without_result,
        datasets_seconds: render_seconds.values().sum(),
        runs_seconds: merged.runs_seconds,
        started_unix,
    };
    results(plan, &job, &outcome, None)
}
