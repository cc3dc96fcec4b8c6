//! `sfmeval-runner`: runs SfM pipelines on sfmeval datasets, evaluates every run with the
//! sfmeval core and writes the comparison table (the seed paper's Table I and more).
//!
//! ```text
//! sfmeval-runner setup [--venv .venv]
//! sfmeval-runner run --datasets DIR... --pipelines LIST --out runs/ [--jobs N] [--resume] [--shard i/n]
//! sfmeval-runner merge runs-0/ runs-1/ ... --out runs/
//! sfmeval-runner report runs/ --out table/
//! sfmeval-runner table1 [--quick] [--out table1/]
//! sfmeval-runner sweep --factor views=12,24,36 --dataset-preset statue --pipelines LIST --out sweep/
//! ```

mod adapters;
mod chart;
mod dataset;
mod exec;
mod files;
mod html;
mod pipelines;
mod report;
mod run;
mod setup;
mod sweep;
mod table1;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};

use crate::adapters::{Env, Intrinsics};
use crate::dataset::Dataset;
use crate::run::BatchOptions;

#[derive(Parser)]
#[command(
    name = "sfmeval-runner",
    version,
    about = "Run SfM pipelines on sfmeval datasets, evaluate them with the sfmeval core and write the comparison table."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Create the Python venv with the pinned SfM tools (requirements/runner.txt).
    Setup(SetupArgs),
    /// Run pipelines on datasets: writes `OUT/<dataset>/<pipeline>/` (sparse.ply, cameras.json, run.json, log.txt, model/).
    Run(RunArgs),
    /// Join the run folders of several shards into one.
    Merge(MergeArgs),
    /// Evaluate every run and write the comparison tables (Markdown, CSV, HTML).
    Report(ReportCmd),
    /// The whole seed experiment: render the five built-in datasets, run every pipeline, write the table.
    Table1(Table1Args),
    /// Vary one dataset condition (views, baseline, focal, texture, lighting, noise, blur):
    /// render a variant per value, run the pipelines, plot every metric against it.
    Sweep(sweep::SweepArgs),
    /// List the pipelines and whether each is installed here.
    Pipelines(ToolArgs),
}

#[derive(Args, Clone)]
struct ToolArgs {
    /// Python interpreter of the venv with pycolmap, pytheia, openmvg-rs (default:
    /// $SFMEVAL_PYTHON, ./.venv/bin/python, the repository's .venv, python3).
    #[arg(long)]
    python: Option<PathBuf>,
    /// COLMAP executable.
    #[arg(long, default_value = "colmap")]
    colmap: String,
    /// VisualSfM executable.
    #[arg(long, default_value = "VisualSFM")]
    visualsfm: String,
    /// A custom pipeline: NAME='COMMAND with {images} and {out}' (repeatable; see README).
    #[arg(long = "custom", value_name = "NAME=COMMAND")]
    customs: Vec<String>,
}

/// How the runs of a batch execute: shared by `run`, `table1` and `sweep`.
#[derive(Args, Clone)]
struct ExecArgs {
    /// Timeout per run, seconds (a pipeline's `timeout=` option overrides it).
    #[arg(long, default_value_t = 3600.0)]
    timeout: f64,
    /// Runs at once.
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// Intrinsics given to the tools: `exif` (the images' EXIF, default) or `known`
    /// (the dataset's cameras.json).
    #[arg(long, default_value = "exif", value_parser = ["exif", "known"])]
    intrinsics: String,
    /// Seed passed to the tools that take one.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

impl ExecArgs {
    /// Fails on a timeout that is not positive. Commands that render first call it before
    /// rendering, so a bad flag does not cost the renders.
    fn check(&self) -> Result<()> {
        if !(self.timeout > 0.0) {
            anyhow::bail!("--timeout must be > 0");
        }
        Ok(())
    }

    /// The batch options writing into `out`; `resume`/`retry_failed` say which finished runs
    /// are reused. Fails as [`Self::check`] does.
    fn batch_options(&self, out: &Path, resume: bool, retry_failed: bool) -> Result<BatchOptions> {
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

#[derive(Args, Clone)]
struct BatchArgs {
    /// Pipelines: names or specs KIND[:key=value,...] separated by commas or `;`, or `all`.
    #[arg(long, num_args = 1.., required = true)]
    pipelines: Vec<String>,
    #[command(flatten)]
    exec: ExecArgs,
    /// Skip runs already finished in the output folder.
    #[arg(long)]
    resume: bool,
    /// With --resume, redo runs that failed or timed out.
    #[arg(long)]
    retry_failed: bool,
    /// Only the grid cells k with k % n == i (0 <= i < n), for cluster job arrays.
    #[arg(long, value_name = "i/n")]
    shard: Option<String>,
    /// Keep the tools' scratch files (databases, features) in the run folders.
    #[arg(long)]
    keep_scratch: bool,
    #[command(flatten)]
    tools: ToolArgs,
}

#[derive(Args)]
struct SetupArgs {
    /// The venv to create or update.
    #[arg(long, default_value = ".venv")]
    venv: PathBuf,
    /// The Python used to create it (bpy 5.0 needs CPython 3.11).
    #[arg(long, default_value = "python3.11")]
    python: String,
}

#[derive(Args)]
struct RunArgs {
    /// Dataset folders (sfmeval.dataset/1).
    #[arg(long, num_args = 1.., required = true)]
    datasets: Vec<PathBuf>,
    /// Output folder.
    #[arg(long, default_value = "runs")]
    out: PathBuf,
    #[command(flatten)]
    batch: BatchArgs,
}

#[derive(Args)]
struct MergeArgs {
    /// Shard output folders.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Merged output folder.
    #[arg(long)]
    out: PathBuf,
    /// When a run differs between shards, keep the last instead of failing.
    #[arg(long)]
    force: bool,
}

#[derive(Args, Clone)]
struct EvalArgs {
    /// Crop file (sfmeval.crop/1) applied in the ground-truth frame.
    #[arg(long)]
    crop: Option<PathBuf>,
    /// Completeness samples on the ground-truth mesh.
    #[arg(long, default_value_t = sfmeval::evaluate::DEFAULT_SAMPLES)]
    samples: usize,
    /// Thresholds in ground-truth units (metres for Blender datasets), comma-separated.
    #[arg(long, value_delimiter = ',')]
    tau: Vec<f64>,
    /// Thresholds in percent of the ground-truth bounding-box diagonal (default 0.5,1,2).
    #[arg(long, value_delimiter = ',', alias = "tau-relative")]
    tau_percent: Vec<f64>,
    /// Alignment: auto (cameras, else global; then ICP), cameras, global, cameras+icp,
    /// global+icp, icp or none (given and points need inputs a batch does not have).
    #[arg(long, default_value = "auto", value_parser = clap::builder::PossibleValuesParser::new(sfmeval::align::AlignMode::names()))]
    align: String,
    /// Seed of the surface sampler.
    #[arg(long = "eval-seed", default_value_t = 0)]
    eval_seed: u64,
}

impl EvalArgs {
    /// The alignment request of `--align` (validated: modes that need a transform or point
    /// pairs are refused, a batch has neither).
    fn align_request(&self) -> Result<sfmeval::align::AlignRequest> {
        let mode = sfmeval::align::AlignMode::parse(&self.align)?;
        Ok(sfmeval::align::AlignRequest::new(
            Some(mode),
            None,
            Vec::new(),
        )?)
    }
}

#[derive(Args)]
struct ReportCmd {
    /// Runs folders.
    #[arg(required = true)]
    runs: Vec<PathBuf>,
    /// Table folder.
    #[arg(long, default_value = "table")]
    out: PathBuf,
    /// Dataset folders, when they moved since the runs (matched by folder name).
    #[arg(long, num_args = 1..)]
    datasets: Vec<PathBuf>,
    #[command(flatten)]
    eval: EvalArgs,
}

#[derive(Args)]
struct Table1Args {
    /// The small preset (36 views, 640×360, 16 spp) instead of the seed's full datasets.
    #[arg(long)]
    quick: bool,
    /// Output folder (datasets/, runs/, table/).
    #[arg(long, default_value = "table1")]
    out: PathBuf,
    /// Pipelines (default: all built-in ones; those not installed are recorded as such).
    #[arg(long, num_args = 1.., default_value = "all")]
    pipelines: Vec<String>,
    /// Only these presets (default: statue vase bicycle hydrant vehicle).
    #[arg(long, num_args = 1..)]
    presets: Vec<String>,
    /// Extra generator overrides `section.key=value` for every dataset (repeatable).
    #[arg(long = "set")]
    sets: Vec<String>,
    /// The blender_scripts folder (default: found from the binary or the working directory).
    #[arg(long)]
    blender_scripts: Option<PathBuf>,
    /// Redo everything (default: reuse rendered datasets and finished runs).
    #[arg(long)]
    fresh: bool,
    #[command(flatten)]
    exec: ExecArgs,
    #[command(flatten)]
    tools: ToolArgs,
    #[command(flatten)]
    eval: EvalArgs,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Setup(a) => setup::setup(&a.venv, &a.python),
        Command::Run(a) => cmd_run(&a),
        Command::Merge(a) => run::merge(&a.shards, &a.out, a.force).map(|n| {
            eprintln!("merged {n} run(s) into {}", a.out.display());
        }),
        Command::Report(a) => cmd_report(&a),
        Command::Table1(a) => table1::table1(&a),
        Command::Sweep(a) => sweep::sweep(&a),
        Command::Pipelines(a) => cmd_pipelines(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sfmeval-runner: {e:#}");
            ExitCode::from(1)
        }
    }
}

/// The venv interpreter: flag, $SFMEVAL_PYTHON, ./.venv, a .venv beside an ancestor of the
/// binary (the repository's), then `python3`. The commands run in other folders (the run
/// folders, the generator's datasets folder), so a relative path with a folder part
/// (`.venv/bin/python`) is made absolute here; a bare name is searched on PATH as it is.
fn find_python(given: Option<&Path>) -> Result<PathBuf> {
    let python = candidate_python(given);
    if python.is_relative() && python.components().count() > 1 {
        return std::path::absolute(&python)
            .with_context(|| format!("resolving the Python path {}", python.display()));
    }
    Ok(python)
}

fn candidate_python(given: Option<&Path>) -> PathBuf {
    if let Some(p) = given {
        return p.to_path_buf();
    }
    if let Some(p) = std::env::var_os("SFMEVAL_PYTHON") {
        return PathBuf::from(p);
    }
    let local = PathBuf::from(".venv/bin/python");
    if local.exists() {
        return local;
    }
    if let Ok(exe) = std::env::current_exe() {
        for dir in exe.ancestors().skip(1) {
            let p = dir.join(".venv/bin/python");
            if p.exists() {
                return p;
            }
        }
    }
    PathBuf::from("python3")
}

fn make_env(tools: &ToolArgs, out: &Path) -> Result<Env> {
    let scripts = run::install_scripts(out)?;
    let python = find_python(tools.python.as_deref())?;
    Ok(Env::new(
        python,
        scripts,
        tools.colmap.clone(),
        tools.visualsfm.clone(),
    ))
}

fn batch_options(b: &BatchArgs, out: &Path) -> Result<BatchOptions> {
    Ok(BatchOptions {
        shard: b.shard.as_deref().map(run::parse_shard).transpose()?,
        keep_scratch: b.keep_scratch,
        ..b.exec.batch_options(out, b.resume, b.retry_failed)?
    })
}

fn cmd_run(a: &RunArgs) -> Result<()> {
    let customs = pipelines::parse_customs(&a.batch.tools.customs)?;
    let specs = pipelines::parse_list(&a.batch.pipelines, &customs)?;
    let datasets: Vec<Dataset> = a
        .datasets
        .iter()
        .map(|d| Dataset::open(d))
        .collect::<Result<_>>()?;
    let opts = batch_options(&a.batch, &a.out)?;
    let env = make_env(&a.batch.tools, &a.out)?;
    let t = std::time::Instant::now();
    let s = run::run_batch(&datasets, &specs, &customs, &env, &opts)?;
    eprintln!(
        "run: {} in {:.1} s; skipped {} finished run(s); output {}",
        if s.ran.is_empty() {
            "nothing to do".to_string()
        } else {
            s.ran
                .iter()
                .map(|(k, v)| format!("{v} {k}"))
                .collect::<Vec<_>>()
                .join(", ")
        },
        t.elapsed().as_secs_f64(),
        s.skipped,
        a.out.display()
    );
    Ok(())
}

fn eval_options(e: &EvalArgs) -> Result<sfmeval::evaluate::EvalOptions> {
    let crop = match &e.crop {
        Some(p) => {
            let bytes = std::fs::read(p).with_context(|| format!("reading {}", p.display()))?;
            sfmeval::crop::Crop::parse(&bytes)
                .with_context(|| format!("crop file {}", p.display()))?
        }
        None => sfmeval::crop::Crop::default(),
    };
    Ok(sfmeval::evaluate::EvalOptions {
        tau: e.tau.clone(),
        tau_percent_of_diagonal: e.tau_percent.clone(),
        samples: e.samples,
        seed: e.eval_seed,
        crop,
        ..sfmeval::evaluate::EvalOptions::default()
    })
}

fn cmd_report(a: &ReportCmd) -> Result<()> {
    let args = report::ReportArgs {
        runs: a.runs.clone(),
        out: a.out.clone(),
        datasets: a.datasets.clone(),
        eval: eval_options(&a.eval)?,
        align: a.eval.align_request()?,
        verbose: true,
    };
    let rows = report::report(&args)?;
    eprintln!(
        "report: {} run(s) → {}/{{table1.md,table1.csv,table.md,runs.csv,index.html,summary.json,reports/}}",
        rows.len(),
        a.out.display()
    );
    Ok(())
}

fn cmd_pipelines(a: &ToolArgs) -> Result<()> {
    let customs = pipelines::parse_customs(&a.customs)?;
    let tmp = std::env::temp_dir().join(format!("sfmeval-runner-{}", std::process::id()));
    let env = make_env(a, &tmp)?;
    for name in adapters::BUILTIN
        .iter()
        .map(|s| s.to_string())
        .chain(customs.keys().cloned())
    {
        let ad = adapters::adapter(&name, &name, &customs)?;
        match ad.availability(&env) {
            adapters::Availability::Installed(v) => println!("{name:18} installed  {v}"),
            adapters::Availability::Missing(r) => println!("{name:18} missing    {r}"),
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
    Ok(())
}
