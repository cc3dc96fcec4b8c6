//! The command line: every subcommand's arguments (clap), and their translation into the
//! options of the batch ([`BatchOptions`]) and of the evaluation ([`EvalOptions`]).

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result};
use clap::builder::PossibleValuesParser;
use clap::{Args, Parser, Subcommand};
use sfmeval::align::{AlignMode, AlignRequest};
use sfmeval::evaluate::EvalOptions;

use crate::adapters::Intrinsics;
use crate::report::ReportArgs;
use crate::run::{BatchOptions, parse_shard};

/// The whole command line.
#[derive(Parser)]
#[command(
    name = "sfmeval-runner",
    version,
    about = "Run SfM pipelines on sfmeval datasets, evaluate them with the sfmeval core and write the comparison table."
)]
pub struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand)]
pub enum Command {
    /// Create the Python venv with the pinned SfM tools (requirements/runner.txt).
    Setup(SetupArgs),
    /// Run pipelines on datasets: writes `OUT/<dataset>/<pipeline>/` (sparse.ply, cameras.json, run.json, log.txt, model/);
    /// with `--executor slurm`, `OUT/runs/<dataset>/<pipeline>/` and the tables in `OUT/table/`.
    Run(RunArgs),
    /// Join the run folders of several shards into one.
    Merge(MergeArgs),
    /// Evaluate every run and write the comparison tables (Markdown, CSV, HTML).
    Report(ReportCmd),
    /// The whole seed experiment: render the five built-in datasets, run every pipeline, write the table.
    Table1(Table1Args),
    /// Vary one dataset condition (views, baseline, focal, texture, lighting, noise, blur):
    /// render a variant per value, run the pipelines, plot every metric against it.
    Sweep(SweepArgs),
    /// List the pipelines and whether each is installed here.
    Pipelines(PipelinesArgs),
    /// One task of a Slurm batch (what the sbatch scripts of `--executor slurm` run).
    #[command(hide = true)]
    SlurmTask(SlurmTaskArgs),
}

/// Where the tools are, and the custom pipelines.
#[derive(Args, Clone)]
pub struct ToolArgs {
    /// Python interpreter of the venv with pycolmap, pytheia, openmvg-rs (default:
    /// $SFMEVAL_PYTHON, ./.venv/bin/python, the repository's .venv, python3).
    #[arg(long)]
    pub python: Option<PathBuf>,
    /// COLMAP executable.
    #[arg(long, default_value = "colmap")]
    pub colmap: String,
    /// VisualSfM executable.
    #[arg(long, default_value = "VisualSFM")]
    pub visualsfm: String,
    /// A custom pipeline: NAME='COMMAND with {images} and {out}' (repeatable; see README).
    #[arg(long = "custom", value_name = "NAME=COMMAND")]
    pub customs: Vec<String>,
}

/// Arguments of `pipelines`.
#[derive(Args)]
pub struct PipelinesArgs {
    /// Print a JSON array `[{"name", "installed", "detail"}]` (detail: the version when
    /// installed, else why not) instead of the text table.
    #[arg(long)]
    pub json: bool,
    /// Where the tools are.
    #[command(flatten)]
    pub tools: ToolArgs,
}

/// How the runs of a batch execute: shared by `run`, `table1` and `sweep`.
#[derive(Args, Clone)]
pub struct ExecArgs {
    /// Timeout per run, seconds (a pipeline's `timeout=` option overrides it).
    #[arg(long, default_value_t = 3600.0)]
    pub timeout: f64,
    /// Runs at once.
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
    /// Intrinsics given to the tools: `exif` (the images' EXIF, default) or `known`
    /// (the dataset's cameras.json).
    #[arg(long, default_value = "exif", value_parser = ["exif", "known"])]
    pub intrinsics: String,
    /// Seed passed to the tools that take one.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

impl ExecArgs {
    /// Fails on a timeout that is not positive. Commands that render first call it before
    /// rendering, so a bad flag does not cost the renders.
    pub fn check(&self) -> Result<()> {
        if !(self.timeout > 0.0) {
            anyhow::bail!("--timeout must be > 0");
        }
        Ok(())
    }

    /// The batch options writing into `out`; `resume`/`retry_failed` say which finished runs
    /// are reused. Fails as [`Self::check`] does.
    pub fn batch_options(
        &self,
        out: &Path,
        resume: bool,
        retry_failed: bool,
    ) -> Result<BatchOptions> {
        self.check()?;
        Ok(BatchOptions {
            out: out.to_path_buf(),
            timeout: Duration::from_secs_f64(self.timeout),
            jobs: self.jobs.max(1),
            resume,
            retry_failed,
            shard: None,
            intrinsics: if self.intrinsics == "known" {
                Intrinsics::Known
            } else {
                Intrinsics::Exif
            },
            seed: self.seed,
            keep_scratch: false,
            verbose: true,
        })
    }
}

/// The pipelines of a batch and how it runs (`run`).
#[derive(Args, Clone)]
pub struct BatchArgs {
    /// Pipelines: names or specs KIND[:key=value,...] separated by commas or `;`, or `all`.
    #[arg(long, num_args = 1.., required = true)]
    pub pipelines: Vec<String>,
    /// How the runs execute.
    #[command(flatten)]
    pub exec: ExecArgs,
    /// Skip runs already finished in the output folder (with --executor slurm: complete the
    /// batch planned in OUT, submitting only the tasks without result, then collect again).
    #[arg(long)]
    pub resume: bool,
    /// With --resume, redo runs that failed or timed out.
    #[arg(long)]
    pub retry_failed: bool,
    /// Only the grid cells k with k % n == i (0 <= i < n), for cluster job arrays.
    #[arg(long, value_name = "i/n")]
    pub shard: Option<String>,
    /// Keep the tools' scratch files (databases, features) in the run folders.
    #[arg(long)]
    pub keep_scratch: bool,
    /// Where the tools are.
    #[command(flatten)]
    pub tools: ToolArgs,
}

impl BatchArgs {
    /// The batch options writing into `out`, with the shard and `--keep-scratch`.
    pub fn batch_options(&self, out: &Path) -> Result<BatchOptions> {
        Ok(BatchOptions {
            shard: self.shard.as_deref().map(parse_shard).transpose()?,
            keep_scratch: self.keep_scratch,
            ..self
                .exec
                .batch_options(out, self.resume, self.retry_failed)?
        })
    }
}

/// Arguments of `setup`.
#[derive(Args)]
pub struct SetupArgs {
    /// The venv to create or update.
    #[arg(long, default_value = ".venv")]
    pub venv: PathBuf,
    /// The Python used to create it (bpy 5.0 needs CPython 3.11).
    #[arg(long, default_value = "python3.11")]
    pub python: String,
}

/// Arguments of `run`.
#[derive(Args)]
pub struct RunArgs {
    /// Dataset folders (sfmeval.dataset/1).
    #[arg(long, num_args = 1.., required = true)]
    pub datasets: Vec<PathBuf>,
    /// Output folder.
    #[arg(long, default_value = "runs")]
    pub out: PathBuf,
    /// The pipelines and how they run.
    #[command(flatten)]
    pub batch: BatchArgs,
    /// With --executor slurm: how the collect stage measures every run into OUT/table/ (a
    /// local run does not evaluate: `report` does).
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Where the runs go (this machine, or a Slurm cluster: OUT/slurm/, OUT/runs/, OUT/table/).
    #[command(flatten)]
    pub slurm: SlurmArgs,
}

/// Arguments of `merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// Shard output folders.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Merged output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// When a run differs between shards, keep the last instead of failing.
    #[arg(long)]
    pub force: bool,
}

/// How every run is measured: shared by `report`, `table1` and `sweep`.
#[derive(Args, Clone)]
pub struct EvalArgs {
    /// Crop file (sfmeval.crop/1) applied in the ground-truth frame.
    #[arg(long)]
    pub crop: Option<PathBuf>,
    /// Completeness samples on the ground-truth mesh.
    #[arg(long, default_value_t = sfmeval::evaluate::DEFAULT_SAMPLES)]
    pub samples: usize,
    /// Thresholds in ground-truth units (metres for Blender datasets), comma-separated.
    #[arg(long, value_delimiter = ',')]
    pub tau: Vec<f64>,
    /// Thresholds in percent of the ground-truth bounding-box diagonal (default 0.5,1,2).
    #[arg(long, value_delimiter = ',', alias = "tau-relative")]
    pub tau_percent: Vec<f64>,
    /// Alignment: auto (cameras, else global; then ICP), cameras, global, cameras+icp,
    /// global+icp, icp or none (given and points need inputs a batch does not have).
    #[arg(long, default_value = "auto", value_parser = PossibleValuesParser::new(AlignMode::names()))]
    pub align: String,
    /// Seed of the surface sampler.
    #[arg(long = "eval-seed", default_value_t = 0)]
    pub eval_seed: u64,
}

impl EvalArgs {
    /// The core's evaluation options: thresholds, samples, seed and the crop file's volume
    /// (read here: a missing or malformed crop file is an error naming it).
    pub fn eval_options(&self) -> Result<EvalOptions> {
        let crop = match &self.crop {
            Some(p) => {
                let bytes = std::fs::read(p).with_context(|| format!("reading {}", p.display()))?;
                sfmeval::crop::Crop::parse(&bytes)
                    .with_context(|| format!("crop file {}", p.display()))?
            }
            None => sfmeval::crop::Crop::default(),
        };
        Ok(EvalOptions {
            tau: self.tau.clone(),
            tau_percent_of_diagonal: self.tau_percent.clone(),
            samples: self.samples,
            seed: self.eval_seed,
            crop,
            ..EvalOptions::default()
        })
    }
}

impl EvalArgs {
    /// Whether every option has its default (a local `run`, which does not evaluate, takes
    /// none).
    pub fn is_default(&self) -> bool {
        self.crop.is_none()
            && self.samples == sfmeval::evaluate::DEFAULT_SAMPLES
            && self.tau.is_empty()
            && self.tau_percent.is_empty()
            && self.align == "auto"
            && self.eval_seed == 0
    }

    /// The report of a batch: its runs folder into its table folder, measured as these
    /// options say (a local `table1` and a Slurm batch's collect make the same tables).
    pub fn report_args(&self, runs: &Path, table: &Path) -> Result<ReportArgs> {
        Ok(ReportArgs {
            runs: vec![runs.to_path_buf()],
            out: table.to_path_buf(),
            datasets: Vec::new(),
            eval: self.eval_options()?,
            align: self.align_request()?,
            verbose: false,
        })
    }

    /// The alignment request of `--align` (validated: modes that need a transform or point
    /// pairs are refused, a batch has neither).
    pub fn align_request(&self) -> Result<AlignRequest> {
        let mode = AlignMode::parse(&self.align)?;
        AlignRequest::new(Some(mode), None, Vec::new()).map_err(|e| match e {
            sfmeval::Error::AlignInput { mode, problem } => anyhow::anyhow!(
                "--align {mode} {problem}, which a batch of runs does not have: use one of \
                 auto, cameras, global, icp or their +icp forms"
            ),
            e => e.into(),
        })
    }
}

/// Arguments of `report`.
#[derive(Args)]
pub struct ReportCmd {
    /// Runs folders.
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    /// Table folder.
    #[arg(long, default_value = "table")]
    pub out: PathBuf,
    /// Dataset folders, when they moved since the runs (matched by folder name).
    #[arg(long, num_args = 1..)]
    pub datasets: Vec<PathBuf>,
    /// How every run is measured.
    #[command(flatten)]
    pub eval: EvalArgs,
}

/// The dataset generator's flags, shared by `table1` and `sweep`.
#[derive(Args)]
pub struct GeneratorArgs {
    /// Extra generator overrides `section.key=value` for every dataset (repeatable).
    #[arg(long = "set")]
    pub sets: Vec<String>,
    /// The blender_scripts folder (default: found from the binary or the working directory).
    #[arg(long)]
    pub blender_scripts: Option<PathBuf>,
    /// Redo everything (default: reuse rendered datasets and finished runs).
    #[arg(long)]
    pub fresh: bool,
}

/// Arguments of `table1`.
#[derive(Args)]
pub struct Table1Args {
    /// The small preset (36 views, 640×360, 16 spp) instead of the seed's full datasets.
    #[arg(long)]
    pub quick: bool,
    /// Output folder (datasets/, runs/, table/).
    #[arg(long, default_value = "table1")]
    pub out: PathBuf,
    /// Pipelines (default: all built-in ones; those not installed are recorded as such).
    #[arg(long, num_args = 1.., default_value = "all")]
    pub pipelines: Vec<String>,
    /// Only these presets (default: statue vase bicycle hydrant vehicle).
    #[arg(long, num_args = 1..)]
    pub presets: Vec<String>,
    /// Real scenes besides the generated datasets: folders in the Tanks and Temples layout
    /// (images/ plus SCENE.ply, SCENE.json, SCENE_trans.txt, SCENE_COLMAP_SfM.log, the
    /// folder named after the scene), evaluated with the benchmark's protocol at the scene's
    /// τ, or DTU scans (images/, cameras.json in the scan's frame in mm, Points/stl/ and
    /// ObsMask/ as the benchmark ships them), evaluated with the DTU protocol after the camera
    /// alignment, or ETH3D scenes (images/, cameras.json or dslr_calibration_undistorted/ in
    /// the scene's frame in metres, dslr_scan_eval/scan_alignment.mlp with its scans),
    /// evaluated with ETH3D's protocol after the camera alignment; run like the others.
    #[arg(long = "scene", value_name = "DIR")]
    pub scenes: Vec<PathBuf>,
    /// The dataset generator.
    #[command(flatten)]
    pub generator: GeneratorArgs,
    /// How the runs execute.
    #[command(flatten)]
    pub exec: ExecArgs,
    /// Where the tools are.
    #[command(flatten)]
    pub tools: ToolArgs,
    /// How every run is measured.
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Slurm: complete the batch already planned in OUT (after a node failure, a cancelled or
    /// timed-out task): submit only the tasks whose results are missing, then collect again.
    #[arg(long)]
    pub resume: bool,
    /// Where the stages run (this machine, or a Slurm cluster).
    #[command(flatten)]
    pub slurm: SlurmArgs,
}

/// Where `table1`, `sweep` and `run` run: here, or as Slurm job arrays (`--executor slurm`).
/// Their `--resume` (a Slurm batch: submit only what is missing) is each command's own.
#[derive(Args, Clone)]
pub struct SlurmArgs {
    /// `local` (everything in this process) or `slurm`: write sbatch scripts for the stages
    /// (render shards, finalize, one task per dataset × pipeline, collect; `run` only the last
    /// two) into OUT/slurm/ and submit them as job arrays chained by dependencies.
    #[arg(long, default_value = "local", value_parser = ["local", "slurm"])]
    pub executor: String,
    /// Render tasks per dataset, with either executor (task i renders the views k with
    /// k % n == i, then a finalize writes the ground truth; one task renders the dataset in
    /// one generator call). Default: 1 locally, 4 on Slurm.
    #[arg(long, value_name = "N")]
    pub render_shards: Option<usize>,
    /// Slurm: partition of every stage (a `--stage` partition overrides it).
    #[arg(long)]
    pub partition: Option<String>,
    /// Slurm: account of every stage (a `--stage` account overrides it).
    #[arg(long)]
    pub account: Option<String>,
    /// Slurm: resources of one stage, STAGE:KEY=VALUE,... with STAGE render, finalize, run or
    /// collect and KEY cpus, mem, time, partition or account (repeatable), e.g.
    /// `--stage run:cpus=8,mem=32G,time=08:00:00`.
    #[arg(long = "stage", value_name = "STAGE:KEY=VALUE,...")]
    pub stages: Vec<String>,
    /// Slurm: only write the scripts (OUT/slurm/*.sbatch and submit.sh), submit nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// Slurm: the sbatch executable.
    #[arg(long, default_value = "sbatch")]
    pub sbatch: String,
}

impl SlurmArgs {
    /// Whether the batch goes to Slurm.
    pub fn is_slurm(&self) -> bool {
        self.executor == "slurm"
    }

    /// Render tasks per dataset: `--render-shards`, else 1 locally and 4 on Slurm.
    pub fn render_shards(&self) -> usize {
        self.render_shards
            .unwrap_or(if self.is_slurm() { 4 } else { 1 })
    }

    /// Fails when a Slurm-only option is given without `--executor slurm` (`slurm_resume`:
    /// `--resume` of `table1` and `sweep`, which only Slurm batches have).
    pub fn check_local(&self, slurm_resume: bool) -> Result<()> {
        if self.dry_run
            || slurm_resume
            || !self.stages.is_empty()
            || self.partition.is_some()
            || self.account.is_some()
        {
            anyhow::bail!(
                "--dry-run, --resume, --stage, --partition and --account go with --executor slurm"
            );
        }
        Ok(())
    }
}

/// Arguments of the hidden `slurm-task`: one task of a planned batch.
#[derive(Args)]
pub struct SlurmTaskArgs {
    /// The batch's plan (OUT/slurm/plan.json).
    #[arg(long)]
    pub plan: PathBuf,
    /// The stage: render, finalize, run or collect.
    #[arg(long)]
    pub stage: String,
    /// The task's index in its stage (the array task id; 0 for collect).
    #[arg(long, default_value_t = 0)]
    pub index: usize,
    /// The script's cleanup after the task's runner ended with this status (128 + N: killed
    /// by signal N): ends what is left of its tools' process groups and says so in the log.
    #[arg(long, value_name = "STATUS")]
    pub ended: Option<i32>,
}

/// Arguments of `sweep`.
#[derive(Args)]
pub struct SweepArgs {
    /// The condition and its values, NAME=V1,V2,...: views, baseline, focal, texture,
    /// lighting, noise, blur (see the README for what each changes).
    #[arg(long, value_name = "NAME=V1,V2,...")]
    pub factor: String,
    /// Generator preset of the base dataset (default `small` when no --dataset-config).
    #[arg(long)]
    pub dataset_preset: Option<String>,
    /// Generator config file (TOML/JSON) of the base dataset.
    #[arg(long)]
    pub dataset_config: Option<PathBuf>,
    /// Pipelines: names or specs KIND[:key=value,...] separated by commas or `;`, or `all`.
    #[arg(long, num_args = 1.., required = true)]
    pub pipelines: Vec<String>,
    /// Output folder (datasets/, runs/, table/, charts/, sweep.csv, sweep.html, sweep.json).
    #[arg(long, default_value = "sweep")]
    pub out: PathBuf,
    /// Also render depth maps, so every report gains completeness over the visible surface and
    /// the track-based error, and plot them (rendering takes longer).
    #[arg(long)]
    pub visibility: bool,
    /// Extra metric to plot: a JSON path such as `report.completeness.p90` or
    /// `report.thresholds[*].recall`, optionally `=LABEL` (repeatable).
    #[arg(long = "metric", value_name = "PATH[=LABEL]")]
    pub metrics: Vec<String>,
    /// The dataset generator.
    #[command(flatten)]
    pub generator: GeneratorArgs,
    /// Redo runs that failed or timed out (finished ones are reused).
    #[arg(long)]
    pub retry_failed: bool,
    /// How the runs execute.
    #[command(flatten)]
    pub exec: ExecArgs,
    /// Where the tools are.
    #[command(flatten)]
    pub tools: ToolArgs,
    /// How every run is measured.
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Slurm: complete the batch already planned in OUT (after a node failure, a cancelled or
    /// timed-out task): submit only the tasks whose results are missing, then collect again.
    #[arg(long)]
    pub resume: bool,
    /// Where the stages run (this machine, or a Slurm cluster).
    #[command(flatten)]
    pub slurm: SlurmArgs,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `EvalArgs` alone on a command line.
    #[derive(Parser)]
    struct Eval {
        #[command(flatten)]
        eval: EvalArgs,
    }

    fn request(align: &str) -> Result<AlignRequest> {
        Eval::try_parse_from(["test", "--align", align])?
            .eval
            .align_request()
    }

    #[test]
    fn a_batch_refuses_modes_that_need_a_transform_or_pairs() {
        assert_eq!(request("cameras+icp").unwrap().mode, AlignMode::CamerasIcp);
        let e = request("given").unwrap_err().to_string();
        assert!(
            e.starts_with("--align given needs a transform, which a batch"),
            "{e}"
        );
        let e = request("points").unwrap_err().to_string();
        assert!(e.starts_with("--align points needs point pairs"), "{e}");
        assert!(request("nonsense").is_err());
    }

    /// `SlurmArgs` alone on a command line.
    #[derive(Parser)]
    struct Where {
        #[command(flatten)]
        slurm: SlurmArgs,
    }

    fn shards(args: &[&str]) -> usize {
        Where::try_parse_from(std::iter::once("test").chain(args.iter().copied()))
            .unwrap()
            .slurm
            .render_shards()
    }

    #[test]
    fn render_shards_default_to_one_locally_and_four_on_slurm() {
        assert_eq!(shards(&[]), 1);
        assert_eq!(shards(&["--executor", "slurm"]), 4);
        assert_eq!(shards(&["--render-shards", "3"]), 3);
        assert_eq!(shards(&["--executor", "slurm", "--render-shards", "2"]), 2);
    }
}
