//! Where a batch stands: which tasks left their result, from its files alone.

use crate::batch::plan::{Plan, Stage};

/// The part record `generate.py --views i/n` writes last.
fn part_record(plan: &Plan, dataset: &str, shard: usize) -> std::path::PathBuf {
    plan.dataset_dir(dataset)
        .join(".parts")
        .join(format!("views-{shard}-of-{}.json", plan.render_shards))
}

/// Whether a dataset is ready: finalized (its `dataset.json` is written last), or, given as an
/// existing folder (`run`, `table1 --scene`), with its `images/`.
pub fn dataset_done(plan: &Plan, dataset: &str) -> bool {
    let dir = plan.dataset_dir(dataset);
    if plan
        .datasets
        .iter()
        .any(|d| d.name == dataset && d.dir.is_some())
    {
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
