//! The local executor of a batch plan ([`crate::batch`]): its stages one after the other in
//! this process, through the same task code a Slurm job runs. Each dataset is rendered whole
//! (or reused when complete), the run stage runs every cell (`--jobs` at a time, finished runs
//! reused) and the collect writes the command's outputs.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{Context, Result, bail};

use crate::batch::collect::{DatasetOutcome, Outcome, results};
use crate::batch::plan::{Job, Plan};
use crate::batch::task::{render_whole, run_cells};
use crate::dataset::Dataset;
use crate::summary::{Executor, unix_now};
use crate::sweep::SweepPlan;
use crate::sweep::factor::parse_factor;

/// The checks of the local executor before a plan is made: options that go with Slurm only
/// are refused.
pub fn check(job: &Job) -> Result<()> {
    match job {
        Job::Table1(a) => {
            a.exec.check()?;
            a.slurm.check_local(a.resume)
        }
        Job::Sweep(a) => {
            parse_factor(&a.factor)?;
            a.exec.check()?;
            a.slurm.check_local(a.resume)
        }
        Job::Run(a) => {
            a.slurm.check_local(false)?;
            if !a.eval.is_default() {
                bail!(
                    "--crop, --samples, --tau, --tau-percent, --align and --eval-seed go with --executor \
                     slurm (a local run does not evaluate: give them to `report`)"
                );
            }
            Ok(())
        }
    }
}

/// Runs `plan` (the batch of `job`, begun at `started_unix`): render, run, collect. A sweep's
/// variant that fails to render is a failed variant and the others go on; any other dataset
/// that cannot be made stops the batch.
pub fn execute(plan: &Plan, job: &Job, sweep: Option<&SweepPlan>, started_unix: f64) -> Result<()> {
    let tolerant = matches!(job, Job::Sweep(_));
    if plan.datasets.iter().any(|d| d.dir.is_none()) {
        let root = plan.out.join("datasets");
        std::fs::create_dir_all(&root).with_context(|| format!("creating {}", root.display()))?;
    }
    let mut outcomes = BTreeMap::new();
    let mut ready: Vec<Dataset> = Vec::new();
    for ds in &plan.datasets {
        let mut outcome = match &ds.dir {
            Some(_) => DatasetOutcome::given(),
            None => match render_whole(plan, job, ds) {
                Ok(o) => o,
                Err(e) if tolerant => {
                    eprintln!("{}: {}: generation failed: {e:#}", job.name(), ds.name);
                    DatasetOutcome::failed(format!("{e:#}"))
                }
                Err(e) => return Err(e),
            },
        };
        if outcome.status != "failed" {
            match Dataset::open(&plan.dataset_dir(&ds.name)) {
                Ok(d) => ready.push(d),
                Err(e) if tolerant => outcome = DatasetOutcome::failed(format!("{e:#}")),
                Err(e) => return Err(e),
            }
        }
        outcomes.insert(ds.name.clone(), outcome);
    }
    let datasets_seconds = unix_now() - started_unix;
    let t_runs = Instant::now();
    let mut ran = BTreeMap::new();
    let mut reused = 0;
    if !ready.is_empty() {
        let opts = job.batch_options(&plan.runs_dir(job, Executor::Local), Executor::Local)?;
        let s = run_cells(plan, job, &ready, None, &opts)?;
        if tolerant {
            eprintln!(
                "sweep: runs: {} executed, {} reused",
                s.ran.values().sum::<usize>(),
                s.skipped
            );
        }
        ran = s.ran;
        reused = s.skipped;
    }
    let outcome = Outcome {
        executor: Executor::Local,
        datasets: outcomes,
        runs_executed: ran,
        runs_reused: reused,
        tasks_without_result: Vec::new(),
        datasets_seconds,
        runs_seconds: t_runs.elapsed().as_secs_f64(),
        started_unix,
    };
    results(plan, job, &outcome, sweep)
}
