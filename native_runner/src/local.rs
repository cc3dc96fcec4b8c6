//! The local executor of a batch plan ([`crate::batch`]): its stages one after the other in
//! this process, through the same task code a Slurm job runs. Each dataset is made by its
//! render tasks and its finalize task (`--render-shards`, 1 by default: one generator call),
//! or reused when complete; the run stage runs every cell (`--jobs` at a time, finished runs
//! reused) and the collect writes the command's outputs.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use sfmeval_fs::write_atomic;

use crate::batch::collect::{DatasetOutcome, Outcome, results};
use crate::batch::plan::{Job, Plan, Stage};
use crate::batch::state::task_done;
use crate::batch::task::{finalize, render, run_cells};
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

/// Makes the `d`-th dataset of the plan through its render tasks and its finalize task (a
/// task whose result is there is skipped, as on Slurm; one shard leaves no finalize to do),
/// the generator's output in `OUT/datasets/<name>.log`; or reuses it when it is complete
/// (unless `--fresh`). A sweep's variant is reused only when the same generator arguments made
/// it (`OUT/datasets/<name>.args.json`); any other dataset folder is rendered again from
/// scratch.
fn make_dataset(plan: &Plan, job: &Job, d: usize) -> Result<DatasetOutcome> {
    let ds = plan
        .datasets
        .get(d)
        .with_context(|| format!("dataset {d}: the plan has {}", plan.datasets.len()))?;
    let dest = plan.dataset_dir(&ds.name);
    let root = plan.out.join("datasets");
    let stamped = matches!(job, Job::Sweep(_));
    let stamp = root.join(format!("{}.args.json", ds.name));
    let stamp_json = serde_json::to_string_pretty(&ds.generator_args)? + "\n";
    let complete = dest.join("dataset.json").is_file()
        && dest.join("cameras.json").is_file()
        && (!stamped
            || std::fs::read_to_string(&stamp).ok().as_deref() == Some(stamp_json.as_str()));
    if complete && !job.fresh() {
        eprintln!("{}: reusing {}", job.name(), dest.display());
        return Ok(DatasetOutcome::reused());
    }
    if stamp.exists() {
        std::fs::remove_file(&stamp).with_context(|| format!("removing {}", stamp.display()))?;
    }
    if dest.exists() {
        std::fs::remove_dir_all(&dest)
            .with_context(|| format!("removing the old {}", dest.display()))?;
    }
    let log = root.join(format!("{}.log", ds.name));
    eprintln!(
        "{}: rendering {} in {} shard(s) → {} (log {})",
        job.name(),
        ds.name,
        plan.render_shards,
        dest.display(),
        log.display()
    );
    let tasks = plan
        .render_tasks_of(d)
        .map(|k| (Stage::Render, k))
        .chain([(Stage::Finalize, d)]);
    let mut seconds = 0.0;
    for (stage, k) in tasks {
        if task_done(plan, stage, k) {
            continue;
        }
        seconds += match stage {
            Stage::Render => render(plan, k, &log)?,
            _ => finalize(plan, k, &log)?,
        };
    }
    if stamped {
        write_atomic(&stamp, stamp_json.as_bytes())?;
    }
    Ok(DatasetOutcome::rendered(Some(seconds)))
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
    for (d, ds) in plan.datasets.iter().enumerate() {
        let mut outcome = match &ds.dir {
            Some(_) => DatasetOutcome::given(),
            None => match make_dataset(plan, job, d) {
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
