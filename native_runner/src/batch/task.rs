//! The work of a batch's tasks, the same whichever executor runs them: rendering a dataset
//! (whole, or one part of its views and then the finalize) and running the pipelines of its
//! cells into a runs folder. The local executor calls these in this process, stage by stage; a
//! Slurm job calls them through `sfmeval-runner slurm-task`.

use std::process::Command;

use anyhow::{Context, Result, bail};
use sfmeval_fs::write_atomic;

use crate::args::ToolArgs;
use crate::batch::collect::DatasetOutcome;
use crate::batch::plan::{DatasetPlan, Job, Plan};
use crate::dataset::Dataset;
use crate::env::make_env;
use crate::generator::render_dataset;
use crate::pipelines::{parse_customs, parse_list};
use crate::run::{BatchOptions, BatchSummary, run_batch};

/// `generate.py ARGS EXTRA --out OUT/datasets/<name>` (a part of the views, `--views i/n`, or
/// the finalize, `--finalize`), its output into the caller's stderr.
pub fn generator(plan: &Plan, ds: &DatasetPlan, extra: &[&str]) -> Result<()> {
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
    // from the datasets folder, as the whole render runs it (relative model paths in --set)
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

/// Renders a dataset of the plan whole, in one generator call (through a temporary folder),
/// or reuses it when it is complete (unless `--fresh`). A sweep's variant is reused only when
/// the same generator arguments made it (`OUT/datasets/<name>.args.json`).
pub fn render_whole(plan: &Plan, job: &Job, ds: &DatasetPlan) -> Result<DatasetOutcome> {
    let dest = plan.dataset_dir(&ds.name);
    let stamped = matches!(job, Job::Sweep(_));
    let stamp = plan
        .out
        .join("datasets")
        .join(format!("{}.args.json", ds.name));
    let stamp_json = serde_json::to_string_pretty(&ds.generator_args)? + "\n";
    let complete = dest.join("dataset.json").is_file()
        && dest.join("cameras.json").is_file()
        && (!stamped
            || std::fs::read_to_string(&stamp).ok().as_deref() == Some(stamp_json.as_str()));
    if complete && !job.fresh() {
        eprintln!("{}: reusing {}", job.name(), dest.display());
        return Ok(DatasetOutcome::reused());
    }
    let rendered = render_dataset(
        job.name(),
        &plan.python,
        plan.blender_scripts()?,
        &ds.generator_args,
        &dest,
    );
    match rendered {
        Ok(seconds) => {
            if stamped {
                write_atomic(&stamp, stamp_json.as_bytes())?;
            }
            Ok(DatasetOutcome::rendered(Some(seconds)))
        }
        Err(e) => {
            if stamped {
                let _ = std::fs::remove_file(&stamp);
            }
            Err(e)
        }
    }
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
