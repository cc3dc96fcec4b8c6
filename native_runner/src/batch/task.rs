//! The work of a batch's tasks, the same whichever executor runs them: a render task (a
//! dataset whole, or one shard of its views), a finalize task, and the pipelines of cells run
//! into a runs folder. The local executor calls these in this process, stage by stage; a
//! Slurm job calls them through `sfmeval-runner slurm-task`.

use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::args::ToolArgs;
use crate::batch::plan::{DatasetPlan, Job, Plan};
use crate::dataset::Dataset;
use crate::env::make_env;
use crate::files::{partial_name, replace_dir};
use crate::generator::run_generator;
use crate::pipelines::{parse_customs, parse_list};
use crate::run::{BatchOptions, BatchSummary, run_batch};

/// Render task `k` of the plan, the generator's output appended to `log`; returns its wall
/// seconds. With one shard it renders its dataset whole in one generator call, through a
/// temporary folder moved into place once complete (no finalize is left to do); with `n`
/// shards it renders the views of its shard (`generate.py --views i/n`) into the dataset's
/// folder, which the finalize task completes.
pub fn render(plan: &Plan, k: usize, log: &Path) -> Result<f64> {
    let (ds, shard) = plan.render_task(k)?;
    let dest = plan.dataset_dir(&ds.name);
    if plan.render_shards <= 1 {
        let tmp = partial_name(&dest);
        if tmp.exists() {
            std::fs::remove_dir_all(&tmp).with_context(|| format!("removing {}", tmp.display()))?;
        }
        let made = generator(plan, ds, &[], &tmp, log);
        if made.is_err() {
            let _ = std::fs::remove_dir_all(&tmp);
        }
        let seconds = made?;
        replace_dir(&tmp, &dest)?;
        return Ok(seconds);
    }
    let views = format!("{shard}/{}", plan.render_shards);
    generator(plan, ds, &["--views".into(), views], &dest, log)
}

/// Finalize task `k` of the plan (`generate.py --finalize`: the ground truth, `cameras.json`
/// and `dataset.json` once its shards are rendered), the generator's output appended to
/// `log`; returns its wall seconds.
pub fn finalize(plan: &Plan, k: usize, log: &Path) -> Result<f64> {
    let ds = plan.finalize_task(k)?;
    generator(
        plan,
        ds,
        &["--finalize".into()],
        &plan.dataset_dir(&ds.name),
        log,
    )
}

/// `generate.py ARGS EXTRA --out OUT` for dataset `ds`, from `OUT/datasets` (the relative
/// model paths in `--set` are read from there).
fn generator(
    plan: &Plan,
    ds: &DatasetPlan,
    extra: &[String],
    out: &Path,
    log: &Path,
) -> Result<f64> {
    let label = format!("generate {} {}", ds.name, extra.join(" "));
    let what = if extra.is_empty() {
        "the whole dataset".to_string()
    } else {
        extra.join(" ")
    };
    eprintln!(
        "{}: generator {what} → {} (log {})",
        ds.name,
        out.display(),
        log.display()
    );
    let args: Vec<String> = ds.generator_args.iter().chain(extra).cloned().collect();
    run_generator(
        label.trim_end(),
        &plan.python,
        plan.blender_scripts()?,
        &args,
        out,
        &plan.out.join("datasets"),
        log,
    )
}

/// Runs the plan's pipelines (only `pipeline`, when given) on `datasets` into `opts.out`, as
/// `run`'s grid: the local executor's run stage (every cell at once, `--jobs` at a time) and
/// a Slurm run task (one cell) alike.
pub fn run_cells(
    plan: &Plan,
    job: &Job,
    datasets: &[Dataset],
    pipeline: Option<&str>,
    opts: &BatchOptions,
) -> Result<BatchSummary> {
    let customs = parse_customs(&job.tools().customs)?;
    let mut specs = parse_list(job.pipelines(), &customs)?;
    if let Some(p) = pipeline {
        specs.retain(|s| s.name == p);
        if specs.is_empty() {
            bail!("pipeline {p} is not in the plan's command");
        }
    }
    let tools = ToolArgs {
        python: Some(plan.python.clone()),
        ..job.tools().clone()
    };
    let env = make_env(&tools, &opts.out)?;
    run_batch(datasets, &specs, &customs, &env, opts)
}
