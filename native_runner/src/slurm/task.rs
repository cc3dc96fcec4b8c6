//! One task of a batch, as an sbatch script runs it (`sfmeval-runner slurm-task --plan P
//! --stage S --index K`), through the batch's task code. Every task is idempotent: one whose result is there (a rendered part,
//! a finalized dataset, a finished run) returns at once, so a resubmitted task only redoes what
//! is missing.

use anyhow::{Result, bail};
use nix::sys::signal::{Signal, killpg};
use nix::unistd::Pid;

use crate::args::SlurmTaskArgs;
use crate::batch::plan::{Plan, Stage};
use crate::batch::state::{dataset_done, task_done};
use crate::batch::task::{finalize, render, run_cells};
use crate::dataset::Dataset;
use crate::slurm::collect::collect;
use crate::summary::Executor;

/// Runs the task named on the command line.
pub fn slurm_task(a: &SlurmTaskArgs) -> Result<()> {
    let plan = Plan::read(&a.plan)?;
    let stage = Stage::parse(&a.stage)?;
    let k = a.index;
    if k >= plan.task_count(stage) {
        bail!(
            "{} task {k}: the plan has {} task(s) in that stage",
            stage.name(),
            plan.task_count(stage)
        );
    }
    if let Some(status) = a.ended {
        return task_ended(&plan, stage, k, status);
    }
    // this run's tools only: the groups of an earlier run of the task are long gone
    let _ = std::fs::remove_file(plan.process_groups(stage, k));
    if task_done(&plan, stage, k) {
        eprintln!("{} task {k}: its result is there already", stage.name());
        return Ok(());
    }
    match stage {
        // the generator's output into the task's Slurm log (opened in append mode)
        Stage::Render => render(&plan, k, &plan.log(stage, k)).map(drop),
        Stage::Finalize => finalize(&plan, k, &plan.log(stage, k)).map(drop),
        Stage::Run => run_cell(&plan, k),
        Stage::Collect => collect(&plan),
    }
}

/// Run task `k`: its pipeline on its dataset, into the task's own runs folder.
fn run_cell(plan: &Plan, k: usize) -> Result<()> {
    let cell = plan.run_task(k)?;
    let job = plan.job()?;
    if !dataset_done(plan, &cell.dataset) {
        bail!("dataset {} is not finalized", cell.dataset);
    }
    let dataset = Dataset::open(&plan.dataset_dir(&cell.dataset))?;
    let opts = job.batch_options(&plan.task_runs(k), Executor::Slurm)?;
    let summary = run_cells(plan, &job, &[dataset], Some(&cell.pipeline), &opts)?;
    eprintln!(
        "run task {k}: {}/{}: {:?}",
        cell.dataset, cell.pipeline, summary.ran
    );
    Ok(())
}

/// The processes in process group `pgid` (from `/proc`), with their environment's
/// `SLURM_JOB_ID` (`None` when it cannot be read).
fn group_members(pgid: i32) -> Vec<(i32, Option<String>)> {
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in dir.filter_map(|e| e.ok()) {
        let Some(pid) = e.file_name().to_str().and_then(|n| n.parse::<i32>().ok()) else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
            continue;
        };
        // `pid (comm) state ppid pgrp ...`: comm may hold spaces and parentheses
        let pgrp = stat
            .rsplit_once(')')
            .and_then(|(_, rest)| rest.split_whitespace().nth(2))
            .and_then(|g| g.parse::<i32>().ok());
        if pgrp != Some(pgid) {
            continue;
        }
        let job = std::fs::read(e.path().join("environ"))
            .ok()
            .and_then(|env| {
                env.split(|&b| b == 0)
                    .find_map(|kv| kv.strip_prefix(b"SLURM_JOB_ID="))
                    .map(|v| String::from_utf8_lossy(v).to_string())
            });
        out.push((pid, job));
    }
    out
}

/// The script's cleanup after the task's runner ended with `status` without success: ends
/// the process groups its tools were started in (those of this Slurm job only) and writes one
/// `# sfmeval-runner:` line into the task's log saying how the runner ended (read by the
/// collect).
fn task_ended(plan: &Plan, stage: Stage, k: usize, status: i32) -> Result<()> {
    let how = if status > 128 {
        let sig = status - 128;
        let name = Signal::try_from(sig).map_or(String::new(), |s| format!(" ({})", s.as_str()));
        format!("was killed by signal {sig}{name}")
    } else {
        format!("ended with exit status {status}")
    };
    let path = plan.process_groups(stage, k);
    let ours = std::env::var("SLURM_JOB_ID").ok();
    let mut ended = Vec::new();
    if let Ok(text) = std::fs::read_to_string(&path) {
        let mut groups: Vec<i32> = text.lines().filter_map(|l| l.trim().parse().ok()).collect();
        groups.sort_unstable();
        groups.dedup();
        for g in groups.into_iter().filter(|&g| g > 1) {
            let members = group_members(g);
            // a group id reused by another job's (or no job's) processes is not ours
            let mine = !members.is_empty()
                && members
                    .iter()
                    .all(|(_, job)| ours.is_none() || job.as_deref() == ours.as_deref());
            if mine && killpg(Pid::from_raw(g), Signal::SIGKILL).is_ok() {
                ended.push(format!("{g} ({} process(es))", members.len()));
            }
        }
    }
    let _ = std::fs::remove_file(&path);
    eprintln!(
        "# sfmeval-runner: {} task {k}: its runner {how}; {}",
        stage.name(),
        if ended.is_empty() {
            "no tool process was left".to_string()
        } else {
            format!("ended its tools' process group(s) {}", ended.join(", "))
        }
    );
    Ok(())
}
