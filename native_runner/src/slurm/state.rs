//! Where a batch stands, from its files alone (no scheduler accounting needed): which tasks
//! left their result, and why a task that left none ended (the last Slurm message in its
//! output file: cancelled, time limit, node failure, out of memory).

use std::path::Path;

use crate::run::Status;
use crate::slurm::plan::{Plan, Stage};

/// The part record `generate.py --views i/n` writes last.
fn part_record(plan: &Plan, dataset: &str, shard: usize) -> std::path::PathBuf {
    plan.dataset_dir(dataset)
        .join(".parts")
        .join(format!("views-{shard}-of-{}.json", plan.render_shards))
}

/// Whether a dataset is ready: finalized (its `dataset.json` is written last), or, in a `run`
/// batch, an existing folder with its `images/`.
pub fn dataset_done(plan: &Plan, dataset: &str) -> bool {
    let dir = plan.dataset_dir(dataset);
    if plan.render_shards == 0 {
        return dir.join("images").is_dir();
    }
    dir.join("dataset.json").is_file()
}

/// Whether task `k` of `stage` left its result (a task whose result is there has nothing to do).
pub fn task_done(plan: &Plan, stage: Stage, k: usize) -> bool {
    match stage {
        Stage::Render => plan.render_task(k).is_ok_and(|(ds, shard)| {
            dataset_done(plan, &ds.name) || part_record(plan, &ds.name, shard).is_file()
        }),
        Stage::Finalize => plan
            .finalize_task(k)
            .is_ok_and(|ds| dataset_done(plan, &ds.name)),
        Stage::Run => plan.run_task(k).is_ok_and(|c| {
            plan.task_runs(k)
                .join(&c.dataset)
                .join(&c.pipeline)
                .join("run.json")
                .is_file()
        }),
        // The tables are rewritten by every submission.
        Stage::Collect => false,
    }
}

/// The tasks of `stage` without their result.
pub fn missing_tasks(plan: &Plan, stage: Stage) -> Vec<usize> {
    (0..plan.task_count(stage))
        .filter(|&k| !task_done(plan, stage, k))
        .collect()
}

/// Why a task ended without a result, from its Slurm output file: the status its cell gets
/// (`timeout` for Slurm's time limit, else `failed`) and a reason naming the file.
pub fn end_reason(log: &Path) -> (Status, String) {
    let Ok(text) = std::fs::read_to_string(log) else {
        return (
            Status::Failed,
            format!("never started (no output file {})", log.display()),
        );
    };
    // The last submission's lines only: each begins with the `# sfmeval <stage> task` line.
    let last = text
        .rfind("# sfmeval ")
        .map_or(text.as_str(), |i| &text[i..]);
    let line = |pat: &str| {
        last.lines()
            .rev()
            .find(|l| l.contains(pat))
            .map(|l| l.trim().to_string())
    };
    let (status, what) = if let Some(l) = line("DUE TO TIME LIMIT") {
        (Status::Timeout, format!("Slurm time limit ({l})"))
    } else if let Some(l) = line("DUE TO NODE FAIL") {
        (Status::Failed, format!("node failure ({l})"))
    } else if let Some(l) = line("DUE TO PREEMPTION") {
        (Status::Failed, format!("preempted ({l})"))
    } else if let Some(l) = line("CANCELLED") {
        (Status::Failed, format!("cancelled ({l})"))
    } else if let Some(l) = line("oom-kill").or_else(|| line("Exceeded job memory limit")) {
        (Status::Failed, format!("out of memory ({l})"))
    } else if let Some(l) = last
        .lines()
        .rev()
        .find(|l| l.to_ascii_lowercase().contains("error"))
    {
        (Status::Failed, format!("failed: {}", l.trim()))
    } else {
        (Status::Failed, "ended without a result".to_string())
    };
    (status, format!("{what}; see {}", log.display()))
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn the_last_submission_of_a_log_says_why() {
        let dir = std::env::temp_dir().join(format!("sfmeval-state-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let log = dir.join("run-3.out");
        std::fs::write(
            &log,
            "# sfmeval run task 3 (job 7)\nslurmstepd: error: *** JOB 8 ON vm CANCELLED AT 2026-12-02T12:00:00 DUE TO TIME LIMIT ***\n\
             # sfmeval run task 3 (job 9)\nslurmstepd: error: *** JOB 10 ON vm CANCELLED AT 2026-12-02T13:00:00 ***\n",
        )
        .unwrap();
        let (st, why) = end_reason(&log);
        assert_eq!(st, Status::Failed);
        assert!(
            why.starts_with("cancelled (slurmstepd: error: *** JOB 10"),
            "{why}"
        );
        std::fs::write(
            &log,
            "# sfmeval run task 3\n*** JOB 8 ON vm CANCELLED AT x DUE TO TIME LIMIT ***\n",
        )
        .unwrap();
        assert_eq!(end_reason(&log).0, Status::Timeout);
        let (st, why) = end_reason(&dir.join("absent.out"));
        assert!(
            st == Status::Failed && why.starts_with("never started"),
            "{why}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
