//! One task of a batch, as an sbatch script runs it (`sfmeval-runner slurm-task --plan P
//! --stage S --index K`). Every task is idempotent: one whose result is there (a rendered part,
//! a finalized dataset, a finished run) returns at once, so a resubmitted task only redoes what
//! is missing.

use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::args::{SlurmTaskArgs, ToolArgs};
use crate::dataset::Dataset;
use crate::env::make_env;
use crate::pipelines::{parse_customs, parse_list};
use crate::run::{BatchOptions, run_batch};
use crate::slurm::collect::collect;
use crate::slurm::plan::{DatasetPlan, Plan, Stage};
use crate::slurm::state::{dataset_done, task_done};

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
    if task_done(&plan, stage, k) {
        eprintln!("{} task {k}: its result is there already", stage.name());
        return Ok(());
    }
    match stage {
        Stage::Render => {
            let (ds, shard) = plan.render_task(k)?;
            let views = format!("{shard}/{}", plan.render_shards);
            generator(&plan, ds, &["--views", &views])
        }
        Stage::Finalize => {
            let ds = plan.finalize_task(k)?;
            generator(&plan, ds, &["--finalize"])
        }
        Stage::Run => run_cell(&plan, k),
        Stage::Collect => collect(&plan),
    }
}

/// `generate.py ARGS EXTRA --out OUT/datasets/<name>`, its output into the task's log.
fn generator(plan: &Plan, ds: &DatasetPlan, extra: &[&str]) -> Result<()> {
    let dir = plan.dataset_dir(&ds.name);
    let script = plan.blender_scripts()?.join("generate.py");
    eprintln!(
        "{}: {} {} {} {} --out {}",
        ds.name,
        plan.python.display(),
        script.display(),
        ds.generator_args.join(" "),
        extra.join(" "),
        dir.display()
    );
    // from the datasets folder, as a local table1 runs it (relative model paths in --set)
    let status = Command::new(&plan.python)
        .current_dir(plan.out.join("datasets"))
        .arg(&script)
        .args(&ds.generator_args)
        .args(extra)
        .arg("--out")
        .arg(&dir)
        .status()
        .with_context(|| format!("starting {}", plan.python.display()))?;
    if !status.success() {
        bail!("the generator failed ({status}) on {}", dir.display());
    }
    Ok(())
}

/// Run task `k`: its pipeline on its dataset, into the task's own runs folder.
fn run_cell(plan: &Plan, k: usize) -> Result<()> {
    let cell = plan.run_task(k)?;
    let job = plan.job()?;
    if !dataset_done(plan, &cell.dataset) {
        bail!("dataset {} is not finalized", cell.dataset);
    }
    let dataset = Dataset::open(&plan.dataset_dir(&cell.dataset))?;
    let customs = parse_customs(&job.tools().customs)?;
    let specs = parse_list(job.pipelines(), &customs)?;
    let spec = specs
        .into_iter()
        .find(|s| s.name == cell.pipeline)
        .with_context(|| format!("pipeline {} is not in the plan's command", cell.pipeline))?;
    let out = plan.task_runs(k);
    let tools = ToolArgs {
        python: Some(plan.python.clone()),
        ..job.tools().clone()
    };
    let env = make_env(&tools, &out)?;
    let opts = BatchOptions {
        keep_scratch: job.keep_scratch(),
        ..job.exec().batch_options(&out, true, false)?
    };
    let summary = run_batch(&[dataset], &[spec], &customs, &env, &opts)?;
    eprintln!(
        "run task {k}: {}/{}: {:?}",
        cell.dataset, cell.pipeline, summary.ran
    );
    Ok(())
}
