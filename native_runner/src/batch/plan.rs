//! The plan of a batch, one per command (`table1`, `sweep`, `run`: [`Plan::table1`],
//! [`Plan::sweep`], [`Plan::run`]): the command it was made from, its datasets (rendered by the
//! generator, or existing folders), its cells (dataset × pipeline), its stages and where every
//! task reads and writes. Either executor runs it: the local one stage by stage in this
//! process, the Slurm one as job arrays (written as `OUT/slurm/plan.json`). Task `k` of a stage
//! means the same work in every submission of a Slurm batch, so a resubmitted array index redoes
//! exactly one task.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Parser;
use serde::{Deserialize, Serialize};

use crate::args::{
    Cli, Command, EvalArgs, ExecArgs, RunArgs, SlurmArgs, SweepArgs, Table1Args, ToolArgs,
};
use crate::dataset::Dataset;
use crate::env::find_python;
use crate::generator::find_blender_scripts;
use crate::pipelines::{parse_customs, parse_list};
use crate::run::BatchOptions;
use crate::summary::Executor;
use crate::sweep::SweepPlan;
use crate::table1::{dataset_name, generator_args, presets};

/// `schema` of `plan.json`.
pub const PLAN_SCHEMA: &str = "sfmeval.slurm-plan/1";

/// A stage of the batch: one sbatch script, a job array (except `collect`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Stage {
    /// One task per dataset and render shard: `generate.py --views i/n` (none in a `run` batch).
    Render,
    /// One task per dataset: `generate.py --finalize` (none in a `run` batch).
    Finalize,
    /// One task per dataset × pipeline: the run into its own folder.
    Run,
    /// One task: merge the runs (a task without result becomes a failed run), evaluate,
    /// write the tables.
    Collect,
}

impl Stage {
    /// Every stage in submission order.
    pub const ALL: [Stage; 4] = [Stage::Render, Stage::Finalize, Stage::Run, Stage::Collect];

    /// Its name in scripts, logs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Render => "render",
            Stage::Finalize => "finalize",
            Stage::Run => "run",
            Stage::Collect => "collect",
        }
    }

    /// The stage named `s`.
    pub fn parse(s: &str) -> Result<Stage> {
        Stage::ALL
            .into_iter()
            .find(|st| st.name() == s)
            .with_context(|| format!("unknown stage '{s}': render, finalize, run or collect"))
    }
}

/// The command a batch runs, with its arguments.
pub enum Job {
    /// `table1`: the seed experiment.
    Table1(Box<Table1Args>),
    /// `sweep`: one condition varied.
    Sweep(Box<SweepArgs>),
    /// `run`: pipelines on existing datasets.
    Run(Box<RunArgs>),
}

impl Job {
    /// Where the tools are.
    pub fn tools(&self) -> &ToolArgs {
        match self {
            Job::Table1(a) => &a.tools,
            Job::Sweep(a) => &a.tools,
            Job::Run(a) => &a.batch.tools,
        }
    }

    /// How the runs execute.
    pub fn exec(&self) -> &ExecArgs {
        match self {
            Job::Table1(a) => &a.exec,
            Job::Sweep(a) => &a.exec,
            Job::Run(a) => &a.batch.exec,
        }
    }

    /// The `--pipelines` arguments.
    pub fn pipelines(&self) -> &[String] {
        match self {
            Job::Table1(a) => &a.pipelines,
            Job::Sweep(a) => &a.pipelines,
            Job::Run(a) => &a.batch.pipelines,
        }
    }

    /// Whether the tools' scratch files stay in the run folders (`run --keep-scratch`).
    pub fn keep_scratch(&self) -> bool {
        matches!(self, Job::Run(a) if a.batch.keep_scratch)
    }

    /// The command's name (`table1`, `sweep`, `run`), which begins its progress lines.
    pub fn name(&self) -> &'static str {
        match self {
            Job::Table1(_) => "table1",
            Job::Sweep(_) => "sweep",
            Job::Run(_) => "run",
        }
    }

    /// The Slurm options (`--executor` and the rest).
    pub fn slurm(&self) -> &SlurmArgs {
        match self {
            Job::Table1(a) => &a.slurm,
            Job::Sweep(a) => &a.slurm,
            Job::Run(a) => &a.slurm,
        }
    }

    /// The evaluation options.
    pub fn eval(&self) -> &EvalArgs {
        match self {
            Job::Table1(a) => &a.eval,
            Job::Sweep(a) => &a.eval,
            Job::Run(a) => &a.eval,
        }
    }

    /// Which executor runs the batch (`--executor`).
    pub fn executor(&self) -> Executor {
        if self.slurm().is_slurm() {
            Executor::Slurm
        } else {
            Executor::Local
        }
    }

    /// `--resume`.
    pub fn resume(&self) -> bool {
        match self {
            Job::Table1(a) => a.resume,
            Job::Sweep(a) => a.resume,
            Job::Run(a) => a.batch.resume,
        }
    }

    /// `--fresh`: render the datasets and run the pipelines again (`run` has none).
    pub fn fresh(&self) -> bool {
        match self {
            Job::Table1(a) => a.generator.fresh,
            Job::Sweep(a) => a.generator.fresh,
            Job::Run(_) => false,
        }
    }

    /// The options of the runs written into `runs`. Locally the finished runs there are
    /// reused unless `--fresh` (`run`: with `--resume`, also `--retry-failed`, `--shard` and
    /// `--keep-scratch`; `sweep`: `--retry-failed`); a Slurm run task writes into a folder of
    /// its own, where a finished run is its result.
    pub fn batch_options(&self, runs: &Path, executor: Executor) -> Result<BatchOptions> {
        match (self, executor) {
            (Job::Run(a), Executor::Local) => a.batch.batch_options(runs),
            (Job::Table1(a), Executor::Local) => a.exec.batch_options(runs, !self.fresh(), false),
            (Job::Sweep(a), Executor::Local) => {
                a.exec.batch_options(runs, !self.fresh(), a.retry_failed)
            }
            (_, Executor::Slurm) => Ok(BatchOptions {
                keep_scratch: self.keep_scratch(),
                ..self.exec().batch_options(runs, true, false)?
            }),
        }
    }
}

/// One dataset of the batch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DatasetPlan {
    /// What it stands for: the generator preset (`table1`), the factor value (`sweep`) or
    /// the folder name (`run`).
    pub preset: String,
    /// Folder name under `OUT/datasets/` (`run`: the existing folder's name).
    pub name: String,
    /// The generator's arguments (without `--views`, `--finalize`, `--out`).
    pub generator_args: Vec<String>,
    /// An existing dataset folder (`run`): not rendered, read where it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dir: Option<PathBuf>,
}

/// One cell of the table: a pipeline on a dataset (run task `k` is `cells[k]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellPlan {
    /// Dataset name.
    pub dataset: String,
    /// Pipeline name.
    pub pipeline: String,
}

/// `OUT/slurm/plan.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Plan {
    /// Always [`PLAN_SCHEMA`].
    pub schema: String,
    /// The `sfmeval-runner table1|sweep|run ...` command line; every task reads its options
    /// from it.
    pub argv: Vec<String>,
    /// The folder it was given in: the tasks start there.
    pub cwd: PathBuf,
    /// The `sfmeval-runner` binary the tasks run (on the shared filesystem).
    pub runner: PathBuf,
    /// The venv's Python (bpy and the SfM tools).
    pub python: PathBuf,
    /// The generator's folder (`blender_scripts`; none in a `run` batch).
    pub blender_scripts: Option<PathBuf>,
    /// The batch's output folder (absolute).
    pub out: PathBuf,
    /// Render tasks per dataset; 0 in a `run` batch, whose datasets exist (no render or
    /// finalize task).
    pub render_shards: usize,
    /// The datasets, in preset order.
    pub datasets: Vec<DatasetPlan>,
    /// The pipeline names, in table order.
    pub pipelines: Vec<String>,
    /// The cells: datasets by name, then pipelines in the given order (as `run`'s grid).
    pub cells: Vec<CellPlan>,
}

impl Plan {
    /// The plan of a command's batch: [`Plan::table1`], [`Plan::sweep`] (with the sweep's own
    /// plan of its values) or [`Plan::run`].
    pub fn of(job: &Job) -> Result<(Plan, Option<SweepPlan>)> {
        match job {
            Job::Table1(a) => Ok((Plan::table1(a)?, None)),
            Job::Sweep(a) => Plan::sweep(a).map(|(p, s)| (p, Some(s))),
            Job::Run(a) => Ok((Plan::run(a)?, None)),
        }
    }

    /// `table1`: one dataset per preset, rendered, then the `--scene` folders (Tanks and
    /// Temples scenes, DTU scans, ETH3D scenes) as they are.
    pub fn table1(a: &Table1Args) -> Result<Plan> {
        a.exec.check()?;
        let mut datasets: Vec<DatasetPlan> = Vec::new();
        for p in presets(a) {
            datasets.push(DatasetPlan {
                generator_args: generator_args(&p, a.quick, &a.generator.sets),
                name: dataset_name(&p, a.quick),
                preset: p,
                dir: None,
            });
        }
        for scene in &a.scenes {
            let ds = Dataset::open(scene)?;
            if !crate::tnt::is_scene(&ds.dir, &ds.name)
                && crate::dtu::scan_number(&ds.dir).is_none()
                && !crate::eth3d::is_scene(&ds.dir)
            {
                bail!(
                    "--scene {}: neither a Tanks and Temples scene (no {name}_trans.txt and {name}_COLMAP_SfM.log in it, folder named after the scene), a DTU scan (no Points/stl/stlNNN_total.ply with ObsMask/ObsMaskN_10.mat and ObsMask/PlaneN.mat) nor an ETH3D scene (no {mlp})",
                    scene.display(),
                    name = ds.name,
                    mlp = crate::eth3d::MLP
                );
            }
            datasets.push(DatasetPlan {
                preset: ds.name.clone(),
                name: ds.name,
                generator_args: Vec::new(),
                dir: Some(ds.dir),
            });
        }
        let scripts = std::path::absolute(find_blender_scripts(
            a.generator.blender_scripts.as_deref(),
        )?)?;
        make_plan(
            std::env::args().collect(),
            &a.out,
            &a.tools,
            Some(scripts),
            &a.pipelines,
            datasets,
            a.slurm.render_shards(),
        )
    }

    /// `run`: the pipelines on existing datasets (nothing rendered).
    pub fn run(a: &RunArgs) -> Result<Plan> {
        a.batch.exec.check()?;
        let datasets = a
            .datasets
            .iter()
            .map(|d| {
                let ds = Dataset::open(d)?;
                Ok(DatasetPlan {
                    preset: ds.name.clone(),
                    name: ds.name,
                    generator_args: Vec::new(),
                    dir: Some(ds.dir),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        make_plan(
            std::env::args().collect(),
            &a.out,
            &a.batch.tools,
            None,
            &a.batch.pipelines,
            datasets,
            0,
        )
    }

    /// `sweep`: one dataset per factor value, made by the base dataset's generator arguments,
    /// the value's overrides and its name; with the sweep's plan of its values.
    pub fn sweep(a: &SweepArgs) -> Result<(Plan, SweepPlan)> {
        a.exec.check()?;
        a.eval.eval_options()?;
        let python = find_python(a.tools.python.as_deref())?;
        let scripts = std::path::absolute(find_blender_scripts(
            a.generator.blender_scripts.as_deref(),
        )?)?;
        let sweep_plan = SweepPlan::new(a, &python, &scripts)?;
        let datasets = sweep_plan
            .planned
            .iter()
            .map(|pl| {
                let mut args = sweep_plan.base_args.clone();
                for o in pl
                    .overrides
                    .iter()
                    .cloned()
                    .chain([format!("dataset.name=\"{}\"", pl.dataset)])
                {
                    args.extend(["--set".to_string(), o]);
                }
                DatasetPlan {
                    preset: pl.text.clone(),
                    name: pl.dataset.clone(),
                    generator_args: args,
                    dir: None,
                }
            })
            .collect();
        let plan = make_plan(
            std::env::args().collect(),
            &a.out,
            &a.tools,
            Some(scripts),
            &a.pipelines,
            datasets,
            a.slurm.render_shards(),
        )?;
        Ok((plan, sweep_plan))
    }

    /// The runs folder the collect evaluates: `OUT/runs/` (a local `run` writes into `OUT`
    /// itself, which `report` and `merge` read as a runs folder).
    pub fn runs_dir(&self, job: &Job, executor: Executor) -> PathBuf {
        match (job, executor) {
            (Job::Run(_), Executor::Local) => self.out.clone(),
            _ => self.out.join("runs"),
        }
    }
    /// `OUT/slurm/plan.json`.
    pub fn path(out: &Path) -> PathBuf {
        out.join("slurm").join("plan.json")
    }

    /// Reads a plan.
    pub fn read(path: &Path) -> Result<Plan> {
        let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        let plan: Plan = serde_json::from_slice(&bytes)
            .with_context(|| format!("parsing {}", path.display()))?;
        if plan.schema != PLAN_SCHEMA {
            bail!("{} is not a {PLAN_SCHEMA} plan", path.display());
        }
        Ok(plan)
    }

    /// The command of the batch (`table1`, `sweep` or `run`), parsed again from
    /// [`Plan::argv`].
    pub fn job(&self) -> Result<Job> {
        let cli = Cli::try_parse_from(&self.argv).context("the plan's command line")?;
        match cli.command {
            Command::Table1(a) => Ok(Job::Table1(Box::new(a))),
            Command::Sweep(a) => Ok(Job::Sweep(Box::new(a))),
            Command::Run(a) => Ok(Job::Run(Box::new(a))),
            _ => bail!("the plan's command line is not table1, sweep or run"),
        }
    }

    /// The generator's folder (a batch that renders has one).
    pub fn blender_scripts(&self) -> Result<&Path> {
        self.blender_scripts
            .as_deref()
            .context("the plan names no blender_scripts folder (a run batch renders nothing)")
    }

    /// Whether `other` does the same work (datasets, shards, cells): a batch may only be
    /// resumed with the plan it was started with.
    pub fn same_work(&self, other: &Plan) -> bool {
        self.datasets == other.datasets
            && self.render_shards == other.render_shards
            && self.cells == other.cells
    }

    /// Tasks in a stage.
    pub fn task_count(&self, stage: Stage) -> usize {
        match stage {
            Stage::Render => self.datasets.len() * self.render_shards,
            Stage::Finalize if self.render_shards == 0 => 0,
            Stage::Finalize => self.datasets.len(),
            Stage::Run => self.cells.len(),
            Stage::Collect => 1,
        }
    }

    /// Render task `k`: its dataset and shard.
    pub fn render_task(&self, k: usize) -> Result<(&DatasetPlan, usize)> {
        let n = self.render_shards.max(1);
        let ds = self.datasets.get(k / n).with_context(|| {
            format!(
                "render task {k}: the plan has {} tasks",
                self.datasets.len() * n
            )
        })?;
        Ok((ds, k % n))
    }

    /// The render tasks of the `d`-th dataset (its shards, in order).
    pub fn render_tasks_of(&self, d: usize) -> std::ops::Range<usize> {
        d * self.render_shards..(d + 1) * self.render_shards
    }

    /// Finalize task `k`: its dataset.
    pub fn finalize_task(&self, k: usize) -> Result<&DatasetPlan> {
        self.datasets.get(k).with_context(|| {
            format!(
                "finalize task {k}: the plan has {} datasets",
                self.datasets.len()
            )
        })
    }

    /// Run task `k`: its cell.
    pub fn run_task(&self, k: usize) -> Result<&CellPlan> {
        self.cells
            .get(k)
            .with_context(|| format!("run task {k}: the plan has {} cells", self.cells.len()))
    }

    /// The folder of dataset `name`: its existing folder (`run`), else `OUT/datasets/<name>`.
    pub fn dataset_dir(&self, name: &str) -> PathBuf {
        self.datasets
            .iter()
            .find(|d| d.name == name)
            .and_then(|d| d.dir.clone())
            .unwrap_or_else(|| self.out.join("datasets").join(name))
    }

    /// `OUT/slurm/`: plan, scripts, logs, the run tasks' folders.
    pub fn slurm_dir(&self) -> PathBuf {
        self.out.join("slurm")
    }

    /// The runs folder of run task `k` (each task its own: tasks on other nodes never share one).
    pub fn task_runs(&self, k: usize) -> PathBuf {
        self.slurm_dir().join("runs").join(format!("task-{k}"))
    }

    /// The Slurm output file of a task (appended to by every submission).
    pub fn log(&self, stage: Stage, k: usize) -> PathBuf {
        let logs = self.slurm_dir().join("logs");
        match stage {
            Stage::Collect => logs.join("collect.out"),
            _ => logs.join(format!("{}-{k}.out", stage.name())),
        }
    }

    /// Where a task's runner records its tools' process groups (`$SFMEVAL_PROCESS_GROUPS`),
    /// so that the task's script can end them when the runner was killed.
    pub fn process_groups(&self, stage: Stage, k: usize) -> PathBuf {
        let logs = self.slurm_dir().join("logs");
        match stage {
            Stage::Collect => logs.join("collect.pgids"),
            _ => logs.join(format!("{}-{k}.pgids", stage.name())),
        }
    }

    /// The sbatch script of a stage.
    pub fn script(&self, stage: Stage) -> PathBuf {
        self.slurm_dir().join(format!("{}.sbatch", stage.name()))
    }
}

/// The plan of a batch: its command line `argv`, output folder, tools, generator (absolute;
/// none for `run`), pipelines and datasets (rendered in `render_shards` parts each,
/// or, with `dir`, existing folders); the cells are the datasets by name × the pipelines (as
/// `run`'s grid).
fn make_plan(
    argv: Vec<String>,
    out: &Path,
    tools: &ToolArgs,
    blender_scripts: Option<PathBuf>,
    pipelines: &[String],
    datasets: Vec<DatasetPlan>,
    render_shards: usize,
) -> Result<Plan> {
    if render_shards == 0 && datasets.iter().any(|d| d.dir.is_none()) {
        bail!("--render-shards must be at least 1");
    }
    let out =
        std::path::absolute(out).with_context(|| format!("resolving --out {}", out.display()))?;
    // absolute when given as a path; a bare name is looked up on each node's PATH
    let python = find_python(tools.python.as_deref())?;
    let runner = std::env::current_exe().context("locating the sfmeval-runner binary")?;
    let customs = parse_customs(&tools.customs)?;
    let specs = parse_list(pipelines, &customs)?;
    let mut names = BTreeSet::new();
    for d in &datasets {
        if !names.insert(d.name.clone()) {
            bail!("two datasets are named {}", d.name);
        }
    }
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
        render_shards,
        datasets,
        pipelines: specs.iter().map(|s| s.name.clone()).collect(),
        cells,
    })
}
