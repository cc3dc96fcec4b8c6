//! The last stage of a batch, whichever executor ran it: the runs in the plan's runs folder
//! are evaluated and the command's outputs written from what the executor says happened (an
//! [`Outcome`]): `table/` and `table1.json` for `table1`; `table/`, `sweep.csv`, `charts/`,
//! `sweep.html` and `sweep.json` for `sweep`; `batch.json` (and, on Slurm, `report`'s
//! `table/`) for `run`.

use std::collections::BTreeMap;

use anyhow::Result;
use serde_json::json;

use crate::batch::plan::{Job, Plan};
use crate::report::{ReportArgs, report};
use crate::summary::{
    BatchSummary, BatchTiming, Executor, Table1Summary, Table1Timing, TaskWithoutResult,
    render_times, unix_now, write_summary,
};
use crate::sweep::variants::Variant;
use crate::sweep::{Execution, SweepPlan, write_results};

/// How a dataset of the batch came to be.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetOutcome {
    /// `rendered`, `reused`, `given` (an existing folder) or `failed`.
    pub status: &'static str,
    /// Why it failed.
    pub reason: Option<String>,
    /// Its render seconds, when this batch rendered it and they are known.
    pub seconds: Option<f64>,
}

impl DatasetOutcome {
    /// Rendered by this batch in `seconds`.
    pub fn rendered(seconds: Option<f64>) -> DatasetOutcome {
        DatasetOutcome {
            status: "rendered",
            reason: None,
            seconds,
        }
    }

    /// Complete from an earlier call.
    pub fn reused() -> DatasetOutcome {
        DatasetOutcome {
            status: "reused",
            reason: None,
            seconds: None,
        }
    }

    /// An existing folder the batch was given.
    pub fn given() -> DatasetOutcome {
        DatasetOutcome {
            status: "given",
            reason: None,
            seconds: None,
        }
    }

    /// Not made, and why.
    pub fn failed(reason: String) -> DatasetOutcome {
        DatasetOutcome {
            status: "failed",
            reason: Some(reason),
            seconds: None,
        }
    }
}

/// What an executor did with a plan, for its summary documents.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Which executor.
    pub executor: Executor,
    /// Each dataset by name.
    pub datasets: BTreeMap<String, DatasetOutcome>,
    /// Runs executed by this batch, by status (a Slurm task with its result counts here).
    pub runs_executed: BTreeMap<String, usize>,
    /// Finished runs of an earlier call reused (locally).
    pub runs_reused: usize,
    /// Slurm tasks that left no result (none locally).
    pub tasks_without_result: Vec<TaskWithoutResult>,
    /// Getting the datasets (locally their wall time; on Slurm the sum of the render times).
    pub datasets_seconds: f64,
    /// The runs (locally their wall time; on Slurm the sum of the runs' wall times).
    pub runs_seconds: f64,
    /// When the batch began (Unix seconds; on Slurm its first submission).
    pub started_unix: f64,
}

/// Evaluates the runs and writes the command's outputs (see the module). `sweep`: the sweep's
/// plan when the caller has it (else made again from the command).
pub fn results(plan: &Plan, job: &Job, outcome: &Outcome, sweep: Option<&SweepPlan>) -> Result<()> {
    match job {
        Job::Table1(a) => {
            let args = a
                .eval
                .report_args(&plan.out.join("runs"), &plan.out.join("table"))?;
            let report_seconds = write_tables(plan, job, &args, outcome)?;
            let rendered: Vec<&str> = plan
                .datasets
                .iter()
                .filter(|d| d.dir.is_none())
                .filter(|d| {
                    outcome
                        .datasets
                        .get(&d.name)
                        .is_some_and(|o| o.seconds.is_some())
                })
                .map(|d| d.name.as_str())
                .collect();
            let render_seconds = rendered
                .iter()
                .filter_map(|n| Some((n.to_string(), outcome.datasets.get(*n)?.seconds?)))
                .collect();
            // per view: what the generator measured (timing.json)
            let (_, per_view) = render_times(rendered.iter().map(|n| (*n, plan.dataset_dir(n))));
            let doc = Table1Summary {
                quick: a.quick,
                presets: plan
                    .datasets
                    .iter()
                    .filter(|d| d.dir.is_none())
                    .map(|d| d.preset.clone())
                    .collect(),
                pipelines: plan.pipelines.clone(),
                executor: outcome.executor,
                runs_executed: outcome.runs_executed.clone(),
                runs_reused: outcome.runs_reused,
                tasks_without_result: outcome.tasks_without_result.clone(),
                timing: Table1Timing {
                    render_seconds,
                    render_seconds_per_view: per_view,
                    datasets_seconds: outcome.datasets_seconds,
                    runs_seconds: outcome.runs_seconds,
                    report_seconds,
                    total_seconds: unix_now() - outcome.started_unix,
                },
            };
            write_summary(&plan.out.join("table1.json"), &doc)
        }
        Job::Sweep(a) => {
            let owned;
            let sweep_plan = match sweep {
                Some(s) => s,
                None => {
                    owned = SweepPlan::new(a, &plan.python, plan.blender_scripts()?)?;
                    &owned
                }
            };
            let variants: Vec<Variant> = sweep_plan
                .planned
                .iter()
                .map(|pl| {
                    let o = outcome
                        .datasets
                        .get(&pl.dataset)
                        .cloned()
                        .unwrap_or_else(|| DatasetOutcome::failed("not in the plan".into()));
                    Variant {
                        value: pl.text.clone(),
                        dataset: pl.dataset.clone(),
                        overrides: pl.overrides.clone(),
                        status: o.status.into(),
                        reason: o.reason,
                        seconds: o.seconds,
                    }
                })
                .collect();
            write_results(
                a,
                sweep_plan,
                &variants,
                &plan.pipelines,
                &plan.out,
                outcome.started_unix,
                Execution {
                    executor: outcome.executor,
                    tasks_without_result: outcome.tasks_without_result.clone(),
                    timing: json!({"datasets_seconds": outcome.datasets_seconds,
                                   "runs_seconds": outcome.runs_seconds}),
                },
            )
        }
        Job::Run(a) => {
            // A local `run` does not evaluate (`report` does); the Slurm batch ends with it.
            let report_seconds = match outcome.executor {
                Executor::Local => {
                    let ran = &outcome.runs_executed;
                    eprintln!(
                        "run: {} in {:.1} s; skipped {} finished run(s); output {}",
                        if ran.is_empty() {
                            "nothing to do".to_string()
                        } else {
                            ran.iter()
                                .map(|(k, v)| format!("{v} {k}"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        },
                        outcome.runs_seconds,
                        outcome.runs_reused,
                        plan.out.display()
                    );
                    None
                }
                Executor::Slurm => {
                    let args = a
                        .eval
                        .report_args(&plan.out.join("runs"), &plan.out.join("table"))?;
                    Some(write_tables(plan, job, &args, outcome)?)
                }
            };
            let doc = BatchSummary {
                executor: outcome.executor,
                datasets: plan
                    .datasets
                    .iter()
                    .map(|d| plan.dataset_dir(&d.name))
                    .collect(),
                pipelines: plan.pipelines.clone(),
                runs_executed: outcome.runs_executed.clone(),
                runs_reused: outcome.runs_reused,
                tasks_without_result: outcome.tasks_without_result.clone(),
                timing: BatchTiming {
                    runs_seconds: outcome.runs_seconds,
                    report_seconds,
                    total_seconds: unix_now() - outcome.started_unix,
                },
            };
            write_summary(&plan.out.join("batch.json"), &doc)
        }
    }
}

/// Evaluates the runs into `args.out` as `report` does, prints `table1.md` and a summary
/// line; returns the seconds the report took.
fn write_tables(plan: &Plan, job: &Job, args: &ReportArgs, outcome: &Outcome) -> Result<f64> {
    let t = std::time::Instant::now();
    let rows = report(args)?;
    let seconds = t.elapsed().as_secs_f64();
    let t1 = std::fs::read_to_string(args.out.join("table1.md")).unwrap_or_default();
    println!("{t1}");
    eprintln!(
        "{}: {} run(s), {} without result; datasets {:.0} s, runs {:.0} s, report {seconds:.0} s, total {:.0} s; tables in {}",
        job.name(),
        rows.len(),
        outcome.tasks_without_result.len(),
        outcome.datasets_seconds,
        outcome.runs_seconds,
        unix_now() - outcome.started_unix,
        plan.out.join("table").display()
    );
    Ok(seconds)
}
