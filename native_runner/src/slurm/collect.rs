//! The last stage of a batch: every run task's result is merged into `OUT/runs/`; a task that
//! left none (cancelled, timed out, its node failed, its dataset never rendered) becomes a run
//! with status `failed` or `timeout` and the reason from its Slurm output file, so the table
//! is written with that cell marked; then every run is evaluated and the tables written, as a
//! local `table1` does.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::json;
use sfmeval_fs::write_atomic;

use crate::dataset::Dataset;
use crate::files::{copy_dir, partial_name, replace_dir};
use crate::pipelines::{parse_customs, parse_list};
use crate::report::{ReportArgs, report};
use crate::run::{RUN_SCHEMA, RunRecord, Status, read_record};
use crate::slurm::plan::{CellPlan, Plan, Stage};
use crate::slurm::state::{dataset_done, end_reason, task_done};

/// Why run task `k` has no result: its dataset's missing render or finalize task, or itself.
fn why_missing(plan: &Plan, k: usize, cell: &CellPlan) -> (Status, String) {
    if dataset_done(plan, &cell.dataset) {
        let (st, why) = end_reason(&plan.log(Stage::Run, k));
        return (st, format!("Slurm run task {k}: {why}"));
    }
    let n = plan.render_shards;
    let d = plan
        .datasets
        .iter()
        .position(|d| d.name == cell.dataset)
        .unwrap_or(0);
    for r in d * n..(d + 1) * n {
        if !task_done(plan, Stage::Render, r) {
            let (st, why) = end_reason(&plan.log(Stage::Render, r));
            return (
                st,
                format!(
                    "dataset {} not rendered: Slurm render task {r}: {why}",
                    cell.dataset
                ),
            );
        }
    }
    let (st, why) = end_reason(&plan.log(Stage::Finalize, d));
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
        schema: RUN_SCHEMA.into(),
        dataset: cell.dataset.clone(),
        dataset_dir: dataset_dir.to_string_lossy().to_string(),
        pipeline: cell.pipeline.clone(),
        kind: kind_tool.0,
        tool: kind_tool.1,
        version: None,
        status,
        reason: Some(reason.clone()),
        command: Vec::new(),
        options,
        wall_seconds: 0.0,
        cpu_seconds: 0.0,
        peak_memory_bytes: 0,
        exit_status: None,
        images_total: Dataset::open(&dataset_dir).map_or(0, |d| d.image_count),
        images_registered: 0,
        points: 0,
        models: 0,
        started_unix: 0.0,
        finished_unix: now,
        log: "log.txt".into(),
        steps: Vec::new(),
        warnings: vec![
            "no result from its Slurm task: `sfmeval-runner table1 --executor slurm --resume` redoes it"
                .into(),
        ],
        tool_report: serde_json::Value::Null,
    };
    let tmp = partial_name(dest);
    std::fs::create_dir_all(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
    write_atomic(
        &tmp.join("log.txt"),
        format!("# {}: {reason}\n", status.label()).as_bytes(),
    )?;
    let mut text = serde_json::to_string_pretty(&rec)?;
    text.push('\n');
    write_atomic(&tmp.join("run.json"), text.as_bytes())?;
    replace_dir(&tmp, dest)
}

/// Merges the runs, marks the missing ones, evaluates, writes `OUT/table/` and
/// `OUT/table1.json`.
pub fn collect(plan: &Plan) -> Result<()> {
    let t0 = Instant::now();
    let a = plan.table1_args()?;
    let customs = parse_customs(&a.tools.customs)?;
    let specs = parse_list(&a.pipelines, &customs)?;
    let runs = plan.out.join("runs");
    let mut executed: BTreeMap<String, usize> = BTreeMap::new();
    let mut without_result = Vec::new();
    let mut runs_seconds = 0.0;
    for (k, cell) in plan.cells.iter().enumerate() {
        let dest = runs.join(&cell.dataset).join(&cell.pipeline);
        let src = plan.task_runs(k).join(&cell.dataset).join(&cell.pipeline);
        if let Some(p) = dest.parent() {
            std::fs::create_dir_all(p).with_context(|| format!("creating {}", p.display()))?;
        }
        if src.join("run.json").is_file() {
            let rec = read_record(&src)?;
            *executed.entry(rec.status.label().to_string()).or_default() += 1;
            runs_seconds += rec.wall_seconds;
            let same = std::fs::read(dest.join("run.json")).ok()
                == std::fs::read(src.join("run.json")).ok();
            if !same {
                let tmp = partial_name(&dest);
                copy_dir(&src, &tmp)?;
                replace_dir(&tmp, &dest)?;
            }
            continue;
        }
        let why = why_missing(plan, k, cell);
        eprintln!(
            "{}/{}: {}: {}",
            cell.dataset,
            cell.pipeline,
            why.0.label(),
            why.1
        );
        without_result.push(
            json!({"task": k, "dataset": cell.dataset, "pipeline": cell.pipeline,
                                   "status": why.0.label(), "reason": why.1}),
        );
        let spec = specs.iter().find(|s| s.name == cell.pipeline);
        let kind_tool = match spec.map(|s| (s, s.adapter(&customs))) {
            Some((s, Ok(ad))) => (s.kind.clone(), ad.tool().to_string()),
            _ => (cell.pipeline.clone(), cell.pipeline.clone()),
        };
        let options = spec.map(|s| s.options.clone()).unwrap_or_default();
        write_missing_run(plan, cell, kind_tool, options, why, &dest)?;
    }
    let table = plan.out.join("table");
    let t_rep = Instant::now();
    let rows = report(&ReportArgs {
        runs: vec![runs],
        out: table.clone(),
        datasets: Vec::new(),
        eval: a.eval.eval_options()?,
        align: a.eval.align_request()?,
        verbose: false,
    })?;
    let report_seconds = t_rep.elapsed().as_secs_f64();
    // Render times as the generator measured them (timing.json), per dataset.
    let mut frame_seconds = serde_json::Map::new();
    let mut per_view = serde_json::Map::new();
    for d in &plan.datasets {
        let p = plan.dataset_dir(&d.name).join("timing.json");
        if let Some(t) = std::fs::read(&p)
            .ok()
            .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
        {
            frame_seconds.insert(d.name.clone(), t["render_seconds_total"].clone());
            per_view.insert(d.name.clone(), t["render_seconds_mean"].clone());
        }
    }
    let doc = json!({
        "quick": a.quick,
        "presets": plan.datasets.iter().map(|d| d.preset.clone()).collect::<Vec<_>>(),
        "pipelines": plan.pipelines,
        "executor": "slurm",
        "runs_executed": executed,
        "runs_reused": 0,
        "tasks_without_result": without_result,
        "timing": {
            "render_frame_seconds": frame_seconds,
            "render_seconds_per_view": per_view,
            "runs_seconds": runs_seconds,
            "report_seconds": report_seconds,
            "collect_seconds": t0.elapsed().as_secs_f64(),
        },
    });
    let mut text = serde_json::to_string_pretty(&doc)?;
    text.push('\n');
    write_atomic(&plan.out.join("table1.json"), text.as_bytes())?;
    let t1 = std::fs::read_to_string(table.join("table1.md")).unwrap_or_default();
    println!("{t1}");
    eprintln!(
        "collect: {} run(s), {} without result; tables in {}",
        rows.len(),
        without_result.len(),
        table.display()
    );
    Ok(())
}
