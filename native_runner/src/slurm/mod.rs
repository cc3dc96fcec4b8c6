//! The Slurm executor of a batch plan ([`crate::batch`]), `sfmeval-runner table1|sweep|run
//! --executor slurm`: the seed experiment, a sweep or a batch of runs as Slurm job arrays on a cluster whose nodes share the output folder, the runner binary,
//! `blender_scripts` and the venv. Four stages, one sbatch script each under `OUT/slurm/` (a
//! `run` batch, on datasets that exist, has only the last two):
//!
//! 1. `render`: one task per dataset and render shard (`generate.py --views i/n`);
//! 2. `finalize` (`afterok` on render): one task per dataset (`generate.py --finalize`);
//! 3. `run` (`afterok` on finalize): one task per dataset × pipeline, each into its own folder;
//! 4. `collect` (`afterany` on all): merge the runs into `OUT/runs/` (a task that left no
//!    result becomes a failed or timed-out cell with Slurm's reason), evaluate and write the
//!    outputs with the same collect as the local executor.
//!
//! The plan (what task k of a stage does, where it writes) and the tasks' work are the
//! batch's, shared with the local executor. The modules here: [`resources`](mod@resources) (the
//! per-stage `--cpus-per-task`, `--mem`, `--time`, partition, account, checked against
//! `sinfo`), [`script`] (the sbatch scripts and `submit.sh`), [`submit`] (`sbatch` and
//! `jobs.json`, each job recorded as soon as it is queued), [`state`] (why a task left no
//! result), [`task`] (one task as a job runs it) and [`collect`] (the merge of the tasks'
//! runs).

pub mod collect;
pub mod resources;
pub mod script;
pub mod state;
pub mod submit;
pub mod task;

use anyhow::{Context, Result, bail};
use sfmeval_fs::write_atomic;

use crate::batch::plan::{Job, Plan, Stage};
use crate::batch::state::missing_tasks;
use crate::slurm::resources::resources;
use crate::slurm::script::{Dependency, Submission, sbatch_script, submit_sh};

/// What to submit: per dataset, its render tasks without result, then its finalize task, then
/// its run tasks, each `afterok` on the one before it that is submitted (a `run` batch has
/// only run tasks, which wait for nothing); last the collect, `afterany` on everything
/// submitted (always: the tables are rewritten on every submission).
fn submissions(plan: &Plan) -> Vec<Submission> {
    let missing: Vec<Vec<usize>> = [Stage::Render, Stage::Finalize, Stage::Run]
        .into_iter()
        .map(|st| missing_tasks(plan, st))
        .collect();
    let n = plan.render_shards.max(1);
    let mut subs: Vec<Submission> = Vec::new();
    for (d, ds) in plan.datasets.iter().enumerate() {
        let mut previous: Option<usize> = None;
        for (stage, tasks) in [Stage::Render, Stage::Finalize, Stage::Run]
            .into_iter()
            .zip(&missing)
        {
            let mine: Vec<usize> = tasks
                .iter()
                .copied()
                .filter(|&k| match stage {
                    Stage::Render => k / n == d,
                    Stage::Finalize => k == d,
                    _ => plan.cells.get(k).is_some_and(|c| c.dataset == ds.name),
                })
                .collect();
            if mine.is_empty() {
                continue;
            }
            subs.push(Submission {
                stage,
                label: format!("{}_{d}", stage.name()),
                tasks: mine,
                dependency: previous.map_or(Dependency::None, Dependency::AfterOk),
            });
            previous = Some(subs.len() - 1);
        }
    }
    let before: Vec<usize> = (0..subs.len()).collect();
    subs.push(Submission {
        stage: Stage::Collect,
        label: "collect".into(),
        tasks: vec![0],
        dependency: if before.is_empty() {
            Dependency::None
        } else {
            Dependency::AfterAny(before)
        },
    });
    subs
}

/// The checks of the Slurm executor before a plan is made: options that go with the local
/// executor only are refused.
pub fn check(job: &Job) -> Result<()> {
    job.eval().eval_options()?;
    job.eval().align_request()?;
    match job {
        Job::Table1(a) if !a.scenes.is_empty() => bail!(
            "--scene (a Tanks and Temples scene) runs with the local executor only: run it with `table1 --scene DIR` or `run` + `report`"
        ),
        Job::Run(a) if a.batch.shard.is_some() => {
            bail!("--shard goes with the local executor: a Slurm batch runs one task per cell")
        }
        Job::Run(a) if a.batch.retry_failed => bail!(
            "--retry-failed goes with the local executor: a Slurm batch's --resume redoes the \
             tasks without result"
        ),
        _ => Ok(()),
    }
}

/// The Slurm executor: checks a resumed batch (`--resume`) against its plan (or refuses to
/// overwrite one), writes the plan and the scripts and, unless `--dry-run`, submits them.
pub fn submit_plan(plan: &Plan, job: &Job) -> Result<()> {
    let (slurm, resume) = (job.slurm(), job.resume());
    if job.fresh() {
        bail!("--fresh does not go with --executor slurm: choose a new --out");
    }
    let res = resources(slurm)?;
    let plan_path = Plan::path(&plan.out);
    let planned = plan_path.is_file();
    if planned {
        let old = Plan::read(&plan_path)?;
        let records = submit::read_records(plan)?;
        // A batch is started once one submission queued every job it meant to; before that
        // (a dry run, a first submission that failed) the same command tries again.
        let started = records.iter().any(|r| r.complete);
        let queued_any = records.iter().any(|r| !r.stages.is_empty());
        if started && !resume {
            bail!(
                "{} holds a Slurm batch already: add --resume to submit what is missing, or \
                 choose another --out",
                plan.out.display()
            );
        }
        if !old.same_work(plan) && (resume || queued_any) {
            bail!(
                "{}{} was planned with other presets, datasets, pipelines or \
                 --render-shards; give the same ones, or choose another --out",
                if resume { "--resume: " } else { "" },
                plan.out.display()
            );
        }
    } else if resume {
        bail!(
            "--resume: {} holds no Slurm batch (no {})",
            plan.out.display(),
            plan_path.display()
        );
    }
    if planned && !slurm.dry_run {
        let queued = submit::still_queued(plan, &slurm.sbatch)?;
        if !queued.is_empty() {
            bail!(
                "jobs {} of this batch in {} are still in the queue: wait for them (or \
                 scancel them), then run the command again",
                queued.join(" "),
                plan.out.display()
            );
        }
    }
    if !slurm.dry_run {
        let stages: Vec<Stage> = Stage::ALL
            .into_iter()
            .filter(|&st| plan.task_count(st) > 0)
            .collect();
        resources::check_partitions(&res, &stages, &slurm.sbatch)?;
    }
    let mut dirs = vec![plan.slurm_dir().join("logs")];
    if plan.render_shards > 0 {
        dirs.push(plan.out.join("datasets"));
    }
    for dir in dirs {
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let subs = submissions(plan);
    // the stages the batch has (a `run` batch renders nothing)
    for stage in Stage::ALL.into_iter().filter(|&st| plan.task_count(st) > 0) {
        let r = res
            .get(&stage)
            .with_context(|| format!("no resources for stage {}", stage.name()))?;
        write_atomic(
            &plan.script(stage),
            sbatch_script(plan, stage, r)?.as_bytes(),
        )?;
    }
    let submit_path = plan.slurm_dir().join("submit.sh");
    write_atomic(
        &submit_path,
        submit_sh(plan, &subs, &slurm.sbatch).as_bytes(),
    )?;
    let mut text = serde_json::to_string_pretty(plan)?;
    text.push('\n');
    write_atomic(&plan_path, text.as_bytes())?;
    let summary: Vec<String> = Stage::ALL
        .into_iter()
        .filter_map(|st| {
            let k: usize = subs
                .iter()
                .filter(|s| s.stage == st)
                .map(|s| s.tasks.len())
                .sum();
            (k > 0).then(|| format!("{} {k}/{}", st.name(), plan.task_count(st)))
        })
        .collect();
    if slurm.dry_run {
        eprintln!(
            "slurm: --dry-run: scripts in {} ({}); submit them with bash {}",
            plan.slurm_dir().display(),
            summary.join(", "),
            submit_path.display()
        );
        return Ok(());
    }
    submit::submit(plan, &subs, &slurm.sbatch)?;
    eprintln!(
        "slurm: submitted {} (tasks to run / in the stage); the table will be in {} (logs in {})",
        summary.join(", "),
        plan.out.join("table").display(),
        plan.slurm_dir().join("logs").display()
    );
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::batch::plan::{CellPlan, DatasetPlan, PLAN_SCHEMA};
    use crate::batch::state;

    fn plan(out: &std::path::Path) -> Plan {
        let ds = |n: &str| DatasetPlan {
            preset: n.into(),
            name: n.into(),
            generator_args: Vec::new(),
            dir: None,
        };
        let cell = |d: &str, p: &str| CellPlan {
            dataset: d.into(),
            pipeline: p.into(),
        };
        Plan {
            schema: PLAN_SCHEMA.into(),
            argv: Vec::new(),
            cwd: out.into(),
            runner: out.join("sfmeval-runner"),
            python: out.join("python"),
            blender_scripts: Some(out.into()),
            out: out.into(),
            render_shards: 2,
            datasets: vec![ds("b"), ds("a")],
            pipelines: vec!["p".into(), "q".into()],
            cells: vec![
                cell("a", "p"),
                cell("a", "q"),
                cell("b", "p"),
                cell("b", "q"),
            ],
        }
    }

    /// Each submission as (label, tasks, dependency).
    fn shape(p: &Plan) -> Vec<(String, Vec<usize>, Dependency)> {
        submissions(p)
            .iter()
            .map(|s| (s.label.clone(), s.tasks.clone(), s.dependency.clone()))
            .collect()
    }

    #[test]
    fn each_dataset_is_chained_alone_and_resume_submits_what_is_missing() {
        let out = std::env::temp_dir().join(format!("sfmeval-slurm-plan-{}", std::process::id()));
        let p = plan(&out);
        assert_eq!(
            shape(&p),
            vec![
                ("render_0".into(), vec![0, 1], Dependency::None),
                ("finalize_0".into(), vec![0], Dependency::AfterOk(0)),
                ("run_0".into(), vec![2, 3], Dependency::AfterOk(1)),
                ("render_1".into(), vec![2, 3], Dependency::None),
                ("finalize_1".into(), vec![1], Dependency::AfterOk(3)),
                ("run_1".into(), vec![0, 1], Dependency::AfterOk(4)),
                (
                    "collect".into(),
                    vec![0],
                    Dependency::AfterAny(vec![0, 1, 2, 3, 4, 5])
                ),
            ]
        );
        // Dataset b finalized, one shard of a rendered, a's run of q finished.
        std::fs::create_dir_all(p.dataset_dir("b")).unwrap();
        std::fs::write(p.dataset_dir("b").join("dataset.json"), "{}").unwrap();
        let parts = p.dataset_dir("a").join(".parts");
        std::fs::create_dir_all(&parts).unwrap();
        std::fs::write(parts.join("views-1-of-2.json"), "{}").unwrap();
        let run = p.task_runs(1).join("a").join("q");
        std::fs::create_dir_all(&run).unwrap();
        std::fs::write(run.join("run.json"), "{}").unwrap();
        assert_eq!(
            shape(&p),
            vec![
                ("run_0".into(), vec![2, 3], Dependency::None),
                ("render_1".into(), vec![2], Dependency::None),
                ("finalize_1".into(), vec![1], Dependency::AfterOk(1)),
                ("run_1".into(), vec![0], Dependency::AfterOk(2)),
                (
                    "collect".into(),
                    vec![0],
                    Dependency::AfterAny(vec![0, 1, 2, 3])
                ),
            ]
        );
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn a_run_batch_has_only_run_tasks_on_the_datasets_where_they_are() {
        let out = std::env::temp_dir().join(format!("sfmeval-slurm-run-{}", std::process::id()));
        let mut p = plan(&out);
        p.render_shards = 0;
        p.blender_scripts = None;
        for d in &mut p.datasets {
            d.dir = Some(out.join("given").join(&d.name));
        }
        assert_eq!(p.task_count(Stage::Render), 0);
        assert_eq!(p.task_count(Stage::Finalize), 0);
        assert_eq!(p.task_count(Stage::Run), 4);
        assert_eq!(p.dataset_dir("a"), out.join("given").join("a"));
        assert!(p.blender_scripts().is_err());
        assert_eq!(
            shape(&p),
            vec![
                ("run_0".into(), vec![2, 3], Dependency::None),
                ("run_1".into(), vec![0, 1], Dependency::None),
                ("collect".into(), vec![0], Dependency::AfterAny(vec![0, 1])),
            ]
        );
        // Task 2 (b/p) finished: a resume submits the other three, then collects.
        let run = p.task_runs(2).join("b").join("p");
        std::fs::create_dir_all(&run).unwrap();
        std::fs::write(run.join("run.json"), "{}").unwrap();
        assert_eq!(
            shape(&p),
            vec![
                ("run_0".into(), vec![3], Dependency::None),
                ("run_1".into(), vec![0, 1], Dependency::None),
                ("collect".into(), vec![0], Dependency::AfterAny(vec![0, 1])),
            ]
        );
        // A dataset folder is ready when it has its images (no dataset.json needed).
        assert!(!state::dataset_done(&p, "a"));
        std::fs::create_dir_all(out.join("given").join("a").join("images")).unwrap();
        assert!(state::dataset_done(&p, "a"));
        let _ = std::fs::remove_dir_all(&out);
    }
}
