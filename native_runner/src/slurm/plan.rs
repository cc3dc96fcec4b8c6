//! The plan of a Slurm batch, `OUT/slurm/plan.json`: the `table1`, `sweep` or `run` command it
//! was made from, its datasets (each rendered in `render_shards` parts, or existing folders for
//! `run`) and its cells (dataset × pipeline), and where every task reads and writes. Task `k` of a stage means the same work in every
//! submission of the batch, so a resubmitted array index redoes exactly one task.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Parser;
use serde::{Deserialize, Serialize};

use crate::args::{Cli, Command, ExecArgs, RunArgs, SweepArgs, Table1Args, ToolArgs};

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

/// The command a batch runs.
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
