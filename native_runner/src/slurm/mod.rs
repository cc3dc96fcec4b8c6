//! `sfmeval-runner table1 --executor slurm`: the seed experiment as Slurm job arrays on a
//! cluster whose nodes share the output folder, the runner binary, `blender_scripts` and the
//! venv. Four stages, one sbatch script each under `OUT/slurm/`:
//!
//! 1. `render`: one task per dataset and render shard (`generate.py --views i/n`);
//! 2. `finalize` (`afterok` on render): one task per dataset (`generate.py --finalize`);
//! 3. `run` (`afterok` on finalize): one task per dataset × pipeline, each into its own folder;
//! 4. `collect` (`afterany` on all): merge the runs into `OUT/runs/` (a task that left no
//!    result becomes a failed or timed-out cell with Slurm's reason), evaluate and write the
//!    tables, as a local `table1` does.
//!
//! The modules: [`plan`] (what task k of a stage does, where it writes), [`resources`] (the
//! per-stage `--cpus-per-task`, `--mem`, `--time`, partition, account), [`script`] (the sbatch
//! scripts and `submit.sh`), [`submit`] (`sbatch` and `jobs.json`), [`state`] (which tasks left
//! their result, why one did not), [`task`] (running one task) and [`collect`].

pub mod collect;
pub mod plan;
pub mod resources;
pub mod script;
pub mod state;
pub mod submit;
pub mod task;

use std::collections::BTreeSet;

use anyhow::{Context, Result, bail};
use sfmeval_fs::write_atomic;

use crate::args::Table1Args;
use crate::env::find_python;
use crate::generator::find_blender_scripts;
use crate::pipelines::{parse_customs, parse_list};
use crate::slurm::plan::{CellPlan, DatasetPlan, PLAN_SCHEMA, Plan, Stage};
use crate::slurm::resources::resources;
use crate::slurm::script::{Dependency, Submission, sbatch_script, submit_sh};
use crate::slurm::state::missing_tasks;
use crate::table1::{dataset_name, generator_args, presets};

/// The plan of a `table1` command line (`argv`, as given).
fn make_plan(a: &Table1Args, argv: Vec<String>) -> Result<Plan> {
    if a.slurm.render_shards == 0 {
        bail!("--render-shards must be at least 1");
    }
    let out = std::path::absolute(&a.out)
        .with_context(|| format!("resolving --out {}", a.out.display()))?;
    let python = std::path::absolute(find_python(a.tools.python.as_deref())?)?;
    let blender_scripts = std::path::absolute(find_blender_scripts(
        a.generator.blender_scripts.as_deref(),
    )?)?;
    let runner = std::env::current_exe().context("locating the sfmeval-runner binary")?;
    let customs = parse_customs(&a.tools.customs)?;
    let specs = parse_list(&a.pipelines, &customs)?;
    let mut datasets: Vec<DatasetPlan> = Vec::new();
    let mut names = BTreeSet::new();
    for p in presets(a) {
        let name = dataset_name(&p, a.quick);
        if !names.insert(name.clone()) {
            bail!("preset {p} is given twice");
        }
        datasets.push(DatasetPlan {
            generator_args: generator_args(&p, a.quick, &a.generator.sets),
            preset: p,
            name,
        });
    }
    // The cells in `run`'s grid order: datasets by name, pipelines as given.
    let mut cells = Vec::new();
    for name in &names {
        for s in &specs {
            cells.push(CellPlan {
                dataset: name.clone(),
                pipeline: s.name.clone(),
            });
        }
    }
    Ok(Plan {
        schema: PLAN_SCHEMA.into(),
        argv,
        cwd: std::env::current_dir().context("the working directory")?,
        runner,
        python,
        blender_scripts,
        out,
        render_shards: a.slurm.render_shards,
        datasets,
        pipelines: specs.iter().map(|s| s.name.clone()).collect(),
        cells,
    })
}

/// What to submit: each stage's tasks without result (all of them in a new batch), each
/// waiting on the last stage submitted before it; the collect stage always.
fn submissions(plan: &Plan) -> Vec<Submission> {
    let mut subs: Vec<Submission> = Vec::new();
    for stage in [Stage::Render, Stage::Finalize, Stage::Run] {
        let tasks = missing_tasks(plan, stage);
        if tasks.is_empty() {
            continue;
        }
        let dependency = match subs.last() {
            Some(prev) => Dependency::AfterOk(prev.stage),
            None => Dependency::None,
        };
        subs.push(Submission {
            stage,
            tasks,
            dependency,
        });
    }
    let before: Vec<Stage> = subs.iter().map(|s| s.stage).collect();
    subs.push(Submission {
        stage: Stage::Collect,
        tasks: vec![0],
        dependency: if before.is_empty() {
            Dependency::None
        } else {
            Dependency::AfterAny(before)
        },
    });
    subs
}

/// Plans the batch (or checks a resumed one against its plan), writes the scripts and, unless
/// `--dry-run`, submits them.
pub fn submit_table1(a: &Table1Args) -> Result<()> {
    a.exec.check()?;
    if a.generator.fresh {
        bail!("--fresh does not go with --executor slurm: choose a new --out");
    }
    let res = resources(&a.slurm)?;
    let argv: Vec<String> = std::env::args().collect();
    let plan = make_plan(a, argv)?;
    let plan_path = Plan::path(&plan.out);
    if plan_path.is_file() {
        let old = Plan::read(&plan_path)?;
        if !a.slurm.resume {
            bail!(
                "{} holds a Slurm batch already: add --resume to submit what is missing, or \
                 choose another --out",
                plan.out.display()
            );
        }
        if !old.same_work(&plan) {
            bail!(
                "--resume: {} was planned with other presets, pipelines or --render-shards; \
                 give the same ones, or choose another --out",
                plan.out.display()
            );
        }
    } else if a.slurm.resume {
        bail!(
            "--resume: {} holds no Slurm batch (no {})",
            plan.out.display(),
            plan_path.display()
        );
    }
    for dir in [plan.slurm_dir().join("logs"), plan.out.join("datasets")] {
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let subs = submissions(&plan);
    for sub in &subs {
        let r = res
            .get(&sub.stage)
            .with_context(|| format!("no resources for stage {}", sub.stage.name()))?;
        write_atomic(
            &plan.script(sub.stage),
            sbatch_script(&plan, sub, r)?.as_bytes(),
        )?;
    }
    let submit_path = plan.slurm_dir().join("submit.sh");
    write_atomic(
        &submit_path,
        submit_sh(&plan, &subs, &a.slurm.sbatch).as_bytes(),
    )?;
    let mut text = serde_json::to_string_pretty(&plan)?;
    text.push('\n');
    write_atomic(&plan_path, text.as_bytes())?;
    let summary: Vec<String> = subs
        .iter()
        .map(|s| {
            format!(
                "{} {}/{}",
                s.stage.name(),
                s.tasks.len(),
                plan.task_count(s.stage)
            )
        })
        .collect();
    if a.slurm.dry_run {
        eprintln!(
            "slurm: --dry-run: scripts in {} ({}); submit them with bash {}",
            plan.slurm_dir().display(),
            summary.join(", "),
            submit_path.display()
        );
        return Ok(());
    }
    let jobs = submit::submit(&plan, &subs, &a.slurm.sbatch)?;
    submit::record(&plan, &subs, &jobs)?;
    eprintln!(
        "slurm: submitted {} (tasks to run / in the stage); the table will be in {} (logs in {})",
        summary.join(", "),
        plan.out.join("table").display(),
        plan.slurm_dir().join("logs").display()
    );
    Ok(())
}
