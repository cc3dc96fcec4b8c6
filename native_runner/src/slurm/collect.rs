//! The last stage of a batch: every run task's result is merged into `OUT/runs/`; a task that
//! left none (cancelled, timed out, its node failed, its dataset never rendered) becomes a run
//! with status `failed` or `timeout` and the reason from its Slurm output file, so the table
//! is written with that cell marked; then every run is evaluated and the tables written, as a
//! local `table1`, `sweep` or `run` + `report` does.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::json;
use sfmeval_fs::write_atomic;

use crate::args::{RunArgs, SweepArgs, Table1Args};
use crate::dataset::Dataset;
use crate::files::{copy_dir, partial_name, replace_dir};
use crate::pipelines::{parse_customs, parse_list};
use crate::report::{ReportArgs, report};
use crate::run::{RunRecord, Status, read_record};
use crate::slurm::plan::{CellPlan, Job, Plan, Stage};
use crate::slurm::state::{dataset_done, end_reason, slurm_end, task_done};
use crate::slurm::submit::{SubmissionRecord, job_of_task, read_records};
use crate::summary::{
    BatchSummary, BatchTiming, Executor, Table1Summary, Table1Timing, TaskWithoutResult,
    render_times, write_summary,
};
use crate::sweep::variants::Variant;
use crate::sweep::{Execution, SweepPlan, write_results};

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
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
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

/// Render times as the generator's parts measured them: (total, mean per view) per dataset.
fn plan_render_times(plan: &Plan) -> (BTreeMap<String, f64>, BTreeMap<String, f64>) {
    render_times(
        plan.datasets
            .iter()
            .map(|d| (d.name.as_str(), plan.dataset_dir(&d.name))),
    )
}

/// Seconds from the batch's first submission until now (the collect's own time when no
/// submission is recorded).
fn batch_seconds(plan: &Plan, t0: Instant) -> f64 {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
    read_records(plan)
        .ok()
        .and_then(|r| r.first().map(|r| now - r.submitted_unix))
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or_else(|| t0.elapsed().as_secs_f64())
}

/// Merges the runs, marks the missing ones, evaluates and writes what the local command
/// writes: `table/` and `table1.json` for `table1`; `table/`, `sweep.csv`, `charts/`,
/// `sweep.html` and `sweep.json` for `sweep`; `report`'s `table/` and `batch.json` for `run`.
pub fn collect(plan: &Plan) -> Result<()> {
    let t0 = Instant::now();
    let job = plan.job()?;
    let merged = merge_runs(plan, &job)?;
    match &job {
        Job::Table1(a) => table1_results(plan, a, &merged, t0),
        Job::Sweep(a) => sweep_results(plan, a, &merged, t0),
        Job::Run(a) => run_results(plan, a, &merged, t0),
    }
}

/// The sweep's outputs: a variant whose dataset was not finalized is a failed variant.
fn sweep_results(plan: &Plan, a: &SweepArgs, merged: &Merged, t0: Instant) -> Result<()> {
    let sweep_plan = SweepPlan::new(a, &plan.python, plan.blender_scripts()?)?;
    let (frame_seconds, _) = plan_render_times(plan);
    let variants: Vec<Variant> = sweep_plan
        .planned
        .iter()
        .map(|pl| {
            let done = dataset_done(plan, &pl.dataset);
            Variant {
                value: pl.text.clone(),
                dataset: pl.dataset.clone(),
                overrides: pl.overrides.clone(),
                status: if done { "rendered" } else { "failed" }.into(),
                reason: (!done)
                    .then(|| "not rendered by its Slurm tasks (see OUT/slurm/logs/)".into()),
                seconds: frame_seconds.get(&pl.dataset).copied(),
            }
        })
        .collect();
    write_results(
        a,
        &sweep_plan,
        &variants,
        &plan.pipelines,
        &plan.out,
        t0,
        Execution {
            executor: Executor::Slurm,
            tasks_without_result: merged.without_result.clone(),
            timing: json!({"datasets_seconds": frame_seconds.values().sum::<f64>(),
                           "runs_seconds": merged.runs_seconds}),
        },
    )
}

/// Evaluates `OUT/runs/` into `OUT/table/` as `report` does, prints `table1.md` and a summary
/// line; returns the seconds it took.
fn write_tables(plan: &Plan, args: &ReportArgs, merged: &Merged) -> Result<f64> {
    let t = Instant::now();
    let rows = report(args)?;
    let seconds = t.elapsed().as_secs_f64();
    let t1 = std::fs::read_to_string(args.out.join("table1.md")).unwrap_or_default();
    println!("{t1}");
    eprintln!(
        "collect: {} run(s), {} without result; tables in {}",
        rows.len(),
        merged.without_result.len(),
        plan.out.join("table").display()
    );
    Ok(seconds)
}

/// `table/` and `table1.json`.
fn table1_results(plan: &Plan, a: &Table1Args, merged: &Merged, t0: Instant) -> Result<()> {
    let args = a
        .eval
        .report_args(&plan.out.join("runs"), &plan.out.join("table"))?;
    let report_seconds = write_tables(plan, &args, merged)?;
    let (render_seconds, per_view) = plan_render_times(plan);
    let doc = Table1Summary {
        quick: a.quick,
        presets: plan.datasets.iter().map(|d| d.preset.clone()).collect(),
        pipelines: plan.pipelines.clone(),
        executor: Executor::Slurm,
        runs_executed: merged.executed.clone(),
        runs_reused: 0,
        tasks_without_result: merged.without_result.clone(),
        timing: Table1Timing {
            datasets_seconds: render_seconds.values().sum(),
            render_seconds,
            render_seconds_per_view: per_view,
            runs_seconds: merged.runs_seconds,
            report_seconds,
            total_seconds: batch_seconds(plan, t0),
        },
    };
    write_summary(&plan.out.join("table1.json"), &doc)
}

/// `run`'s batch: `report`'s `table/` and `batch.json` (the datasets, pipelines, tasks without
/// result and times).
fn run_results(plan: &Plan, a: &RunArgs, merged: &Merged, t0: Instant) -> Result<()> {
    let args = a
        .eval
        .report_args(&plan.out.join("runs"), &plan.out.join("table"))?;
    let report_seconds = write_tables(plan, &args, merged)?;
    let doc = BatchSummary {
        executor: Executor::Slurm,
        datasets: plan
            .datasets
            .iter()
            .map(|d| plan.dataset_dir(&d.name))
            .collect(),
        pipelines: plan.pipelines.clone(),
        runs_executed: merged.executed.clone(),
        tasks_without_result: merged.without_result.clone(),
        timing: BatchTiming {
            runs_seconds: merged.runs_seconds,
            report_seconds,
            total_seconds: batch_seconds(plan, t0),
        },
    };
    write_summary(&plan.out.join("batch.json"), &doc)
}
