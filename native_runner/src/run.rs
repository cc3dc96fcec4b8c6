//! `sfmeval-runner run`: every (dataset, pipeline) pair of the grid, each in its own run folder
//! `OUT/<dataset>/<pipeline>/` written under a temporary name and renamed when complete, so a
//! folder with that name is always a finished run (ok, failed, timed out or not installed).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use sfmeval_fs::write_atomic;

use crate::adapters::{Adapter, Availability, Env, Intrinsics, Job, SCRIPTS};
use crate::dataset::Dataset;
use crate::exec::{StepResult, run_step};
use crate::files::{partial_name, replace_dir};
use crate::pipelines::PipelineSpec;

pub use sfmeval_table::Status;
pub use sfmeval_table::run::RUN_SCHEMA;

/// `run.json`: everything about how one run went.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunRecord {
    /// Always [`RUN_SCHEMA`].
    pub schema: String,
    /// Dataset name (first folder level).
    pub dataset: String,
    /// Dataset folder as given to the tool.
    pub dataset_dir: String,
    /// Pipeline name (second folder level).
    pub pipeline: String,
    /// Adapter kind.
    pub kind: String,
    /// Tool name.
    pub tool: String,
    /// Tool version (as the tool reports it).
    pub version: Option<String>,
    /// Outcome.
    pub status: Status,
    /// Why it did not succeed.
    pub reason: Option<String>,
    /// Every command run, shell-quoted, in order.
    pub command: Vec<String>,
    /// Pipeline options, intrinsics source, timeout, seed.
    pub options: BTreeMap<String, String>,
    /// Wall-clock seconds of the tool's commands.
    pub wall_seconds: f64,
    /// User + system CPU seconds of the tool's commands (with waited-for descendants).
    pub cpu_seconds: f64,
    /// Peak resident memory of the largest process, bytes.
    pub peak_memory_bytes: u64,
    /// Exit status of the last command run (null when killed or not run).
    pub exit_status: Option<i32>,
    /// Images in the dataset.
    pub images_total: usize,
    /// Images with a pose in the model.
    pub images_registered: usize,
    /// 3D points of the model.
    pub points: usize,
    /// Separate models the tool produced (the largest is kept).
    pub models: usize,
    /// Unix time the run started.
    pub started_unix: f64,
    /// Unix time it ended.
    pub finished_unix: f64,
    /// The tool's log file in the run folder.
    pub log: String,
    /// Per command.
    pub steps: Vec<StepResult>,
    /// Notes from reading the model.
    pub warnings: Vec<String>,
    /// Extra facts the adapter reported (tool.json).
    #[serde(default)]
    pub tool_report: serde_json::Value,
}

impl RunRecord {
    /// A run of `pipeline` (`kind`, `tool`, `options`) on a dataset that has done nothing yet:
    /// status `failed` without reason, no command, no time, nothing registered. `run_one` fills
    /// it in as the tool runs; the Slurm collect writes it for a task that left no result.
    pub fn not_run(
        dataset: &str,
        dataset_dir: &Path,
        images_total: usize,
        pipeline: &str,
        kind: &str,
        tool: &str,
        options: BTreeMap<String, String>,
    ) -> RunRecord {
        RunRecord {
            schema: RUN_SCHEMA.into(),
            dataset: dataset.into(),
            dataset_dir: dataset_dir.to_string_lossy().to_string(),
            pipeline: pipeline.into(),
            kind: kind.into(),
            tool: tool.into(),
            version: None,
            status: Status::Failed,
            reason: None,
            command: Vec::new(),
            options,
            wall_seconds: 0.0,
            cpu_seconds: 0.0,
            peak_memory_bytes: 0,
            exit_status: None,
            images_total,
            images_registered: 0,
            points: 0,
            models: 0,
            started_unix: 0.0,
            finished_unix: 0.0,
            log: "log.txt".into(),
            steps: Vec::new(),
            warnings: Vec::new(),
            tool_report: serde_json::Value::Null,
        }
    }

    /// The fields the tables use.
    pub fn facts(&self) -> sfmeval_table::RunFacts {
        sfmeval_table::RunFacts {
            dataset: self.dataset.clone(),
            pipeline: self.pipeline.clone(),
            tool: self.tool.clone(),
            version: self.version.clone(),
            status: self.status,
            reason: self.reason.clone(),
            wall_seconds: self.wall_seconds,
            cpu_seconds: self.cpu_seconds,
            peak_memory_bytes: self.peak_memory_bytes,
            images_total: self.images_total,
            images_registered: self.images_registered,
            points: self.points,
        }
    }
}

/// Options of a batch.
#[derive(Debug, Clone)]
pub struct BatchOptions {
    /// Output root.
    pub out: PathBuf,
    /// Default timeout per run.
    pub timeout: Duration,
    /// Runs at once.
    pub jobs: usize,
    /// Skip finished runs.
    pub resume: bool,
    /// With `resume`, redo runs that failed or timed out.
    pub retry_failed: bool,
    /// `(i, n)`: only grid cells `k` with `k % n == i`.
    pub shard: Option<(usize, usize)>,
    /// Default intrinsics source.
    pub intrinsics: Intrinsics,
    /// Seed passed to the tools.
    pub seed: u64,
    /// Keep the tools' scratch (databases, features) in the run folder.
    pub keep_scratch: bool,
    /// Print progress lines.
    pub verbose: bool,
}

/// One cell of the grid.
#[derive(Debug, Clone)]
pub struct Cell {
    /// Dataset index.
    pub dataset: usize,
    /// Pipeline index.
    pub pipeline: usize,
}

/// The grid in its deterministic order (datasets sorted by name, pipelines in the given
/// order), restricted to a shard.
pub fn grid(
    datasets: &[Dataset],
    pipelines: &[PipelineSpec],
    shard: Option<(usize, usize)>,
) -> Vec<Cell> {
    let mut order: Vec<usize> = (0..datasets.len()).collect();
    order.sort_by(|&a, &b| datasets[a].name.cmp(&datasets[b].name));
    let mut cells = Vec::new();
    for d in order {
        for p in 0..pipelines.len() {
            cells.push(Cell {
                dataset: d,
                pipeline: p,
            });
        }
    }
    match shard {
        Some((i, n)) => cells
            .into_iter()
            .enumerate()
            .filter(|(k, _)| k % n == i)
            .map(|(_, c)| c)
            .collect(),
        None => cells,
    }
}

/// Parses `i/n` (0 ≤ i < n).
pub fn parse_shard(s: &str) -> Result<(usize, usize)> {
    let (i, n) = s
        .split_once('/')
        .with_context(|| format!("--shard wants i/n, got '{s}'"))?;
    let (i, n): (usize, usize) = (
        i.trim()
            .parse()
            .with_context(|| format!("--shard index '{i}'"))?,
        n.trim()
            .parse()
            .with_context(|| format!("--shard count '{n}'"))?,
    );
    if n == 0 || i >= n {
        bail!("--shard i/n needs 0 <= i < n, got {i}/{n}");
    }
    Ok((i, n))
}

/// Reads `run.json` of a run folder.
pub fn read_record(dir: &Path) -> Result<RunRecord> {
    let p = dir.join("run.json");
    let bytes = std::fs::read(&p).with_context(|| format!("reading {}", p.display()))?;
    serde_json::from_slice(&bytes).with_context(|| format!("parsing {}", p.display()))
}

/// Writes the adapter scripts to `OUT/.sfmeval-runner/adapters/` and returns that folder.
pub fn install_scripts(out: &Path) -> Result<PathBuf> {
    let dir = out.join(".sfmeval-runner").join("adapters");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    for (name, text) in SCRIPTS {
        let p = dir.join(name);
        if std::fs::read(&p).ok().as_deref() != Some(text.as_bytes()) {
            write_atomic(&p, text.as_bytes())?;
        }
    }
    Ok(dir)
}

/// What a batch did.
#[derive(Debug, Default)]
pub struct BatchSummary {
    /// Runs executed now, by status.
    pub ran: BTreeMap<String, usize>,
    /// Finished runs skipped by `--resume`.
    pub skipped: usize,
}

/// Runs the grid. Failures of single runs are recorded in their folders; only problems with
/// the output folder itself are errors.
pub fn run_batch(
    datasets: &[Dataset],
    pipelines: &[PipelineSpec],
    customs: &BTreeMap<String, String>,
    env: &Env,
    opts: &BatchOptions,
) -> Result<BatchSummary> {
    let mut names = std::collections::BTreeSet::new();
    for d in datasets {
        if !names.insert(&d.name) {
            bail!(
                "two datasets are named '{}': run folders would collide",
                d.name
            );
        }
    }
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating {}", opts.out.display()))?;
    let adapters: Vec<Box<dyn Adapter>> = pipelines
        .iter()
        .map(|p| p.adapter(customs))
        .collect::<Result<_>>()?;
    let cells = grid(datasets, pipelines, opts.shard);
    let mut todo = Vec::new();
    let mut summary = BatchSummary::default();
    for c in cells {
        let dest = opts
            .out
            .join(&datasets[c.dataset].name)
            .join(&pipelines[c.pipeline].name);
        if opts.resume
            && let Ok(r) = read_record(&dest)
            && !(opts.retry_failed && matches!(r.status, Status::Failed | Status::Timeout))
        {
            summary.skipped += 1;
            continue;
        }
        todo.push(c);
    }
    // Leftovers of an interrupted batch are never mistaken for runs (their names start with
    // a dot); remove those of dead processes.
    for d in datasets {
        clean_partials(&opts.out.join(&d.name));
    }
    let total = todo.len();
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let ran: Mutex<BTreeMap<String, usize>> = Mutex::new(BTreeMap::new());
    let first_error: Mutex<Option<anyhow::Error>> = Mutex::new(None);
    std::thread::scope(|s| {
        for _ in 0..opts.jobs.max(1) {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    let Some(c) = todo.get(k) else { break };
                    let ds = &datasets[c.dataset];
                    let spec = &pipelines[c.pipeline];
                    match run_one(ds, spec, adapters[c.pipeline].as_ref(), env, opts) {
                        Ok(r) => {
                            let n = done.fetch_add(1, Ordering::SeqCst) + 1;
                            if opts.verbose {
                                eprintln!(
                                    "[{n}/{total}] {}/{}: {} in {:.1} s ({}/{} images, {} points){}",
                                    ds.name,
                                    spec.name,
                                    r.status.label(),
                                    r.wall_seconds,
                                    r.images_registered,
                                    r.images_total,
                                    r.points,
                                    r.reason.as_deref().map(|x| format!(": {x}")).unwrap_or_default()
                                );
                            }
                            if let Ok(mut m) = ran.lock() {
                                *m.entry(r.status.label().to_string()).or_default() += 1;
                            }
                        }
                        Err(e) => {
                            eprintln!("{}/{}: {e:#}", ds.name, spec.name);
                            if let Ok(mut f) = first_error.lock() {
                                f.get_or_insert(e);
                            }
                        }
                    }
                }
            });
        }
    });
    if let Some(e) = first_error.into_inner().ok().flatten() {
        return Err(e);
    }
    summary.ran = ran.into_inner().unwrap_or_default();
    Ok(summary)
}

fn clean_partials(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.filter_map(|e| e.ok()) {
        let name = e.file_name().to_string_lossy().to_string();
        let Some(rest) = name.split_once(".partial-").map(|x| x.1) else {
            continue;
        };
        let pid: Option<i32> = rest.split('-').next().and_then(|p| p.parse().ok());
        let alive = pid.is_some_and(|p| {
            p == std::process::id() as i32 || Path::new(&format!("/proc/{p}")).exists()
        });
        if !alive {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

fn unix_now() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// Runs one pipeline on one dataset and moves the finished folder into place.
pub fn run_one(
    ds: &Dataset,
    spec: &PipelineSpec,
    adapter: &dyn Adapter,
    env: &Env,
    opts: &BatchOptions,
) -> Result<RunRecord> {
    let dest = opts.out.join(&ds.name).join(&spec.name);
    let parent = opts.out.join(&ds.name);
    std::fs::create_dir_all(&parent).with_context(|| format!("creating {}", parent.display()))?;
    let work = partial_name(&dest);
    if work.exists() {
        std::fs::remove_dir_all(&work).with_context(|| format!("removing {}", work.display()))?;
    }
    let output = work.join("output");
    let scratch = work.join("scratch");
    for d in [&work, &output, &scratch] {
        std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
    }
    let intrinsics = match spec.options.get("intrinsics").map(String::as_str) {
        Some("known") => Intrinsics::Known,
        Some("exif") => Intrinsics::Exif,
        _ => opts.intrinsics,
    };
    let timeout = spec
        .options
        .get("timeout")
        .and_then(|t| t.parse::<f64>().ok())
        .map_or(opts.timeout, Duration::from_secs_f64);
    let mut options = spec.options.clone();
    options.insert("intrinsics".into(), intrinsics.name().into());
    options.insert("timeout".into(), format!("{}", timeout.as_secs_f64()));
    options.insert("seed".into(), opts.seed.to_string());
    let mut rec = RunRecord {
        started_unix: unix_now(),
        ..RunRecord::not_run(
            &ds.name,
            &ds.dir,
            ds.image_count,
            &spec.name,
            &spec.kind,
            adapter.tool(),
            options,
        )
    };
    let log = work.join(&rec.log);
    let header = format!(
        "# sfmeval-runner {}: dataset {} ({}), pipeline {} ({})\n",
        env!("CARGO_PKG_VERSION"),
        ds.name,
        ds.dir.display(),
        adapter.name(),
        adapter.tool()
    );
    write_atomic(&log, header.as_bytes())?;
    match adapter.availability(env) {
        Availability::Missing(reason) => {
            rec.status = Status::NotInstalled;
            rec.reason = Some(reason.clone());
            append(&log, &format!("# not installed: {reason}\n"));
        }
        Availability::Installed(version) => {
            rec.version = Some(version);
            let job = Job {
                dataset: ds,
                work: work.clone(),
                output: output.clone(),
                scratch: scratch.clone(),
                output_rel: "output".into(),
                scratch_rel: "scratch".into(),
                intrinsics,
                options: &spec.options,
                seed: opts.seed,
            };
            execute(adapter, env, &job, &log, timeout, &mut rec);
        }
    }
    rec.finished_unix = unix_now();
    if rec.status == Status::Ok
        && let Err(e) = collect(&work, &output, &mut rec)
    {
        rec.status = Status::Failed;
        rec.reason = Some(format!("reading the tool's output: {e:#}"));
    }
    if let Some(r) = &rec.reason {
        append(&log, &format!("# {}: {r}\n", rec.status.label()));
    }
    let tool_json = work.join("tool.json");
    if let Ok(bytes) = std::fs::read(&tool_json)
        && let Ok(v) = serde_json::from_slice::<serde_json::Value>(&bytes)
    {
        if let Some(version) = v.get("version").and_then(|x| x.as_str()) {
            rec.version = Some(version.to_string());
        }
        rec.tool_report = v;
    }
    if !opts.keep_scratch {
        let _ = std::fs::remove_dir_all(&scratch);
    }
    if output.exists() {
        let _ = std::fs::remove_dir_all(&output);
    }
    let mut json = serde_json::to_string_pretty(&rec)?;
    json.push('\n');
    write_atomic(&work.join("run.json"), json.as_bytes())?;
    replace_dir(&work, &dest)?;
    Ok(rec)
}

fn append(log: &Path, text: &str) {
    use std::io::Write;
    if let Ok(mut f) = std::fs::File::options().append(true).open(log) {
        let _ = f.write_all(text.as_bytes());
    }
}

fn execute(
    adapter: &dyn Adapter,
    env: &Env,
    job: &Job,
    log: &Path,
    timeout: Duration,
    rec: &mut RunRecord,
) {
    let deadline = Instant::now() + timeout;
    let steps = match adapter.steps(env, job) {
        Ok(s) => s,
        Err(e) => {
            rec.reason = Some(format!("{e:#}"));
            return;
        }
    };
    if !run_steps(&steps, log, deadline, rec) {
        return;
    }
    match adapter.after(env, job) {
        Ok(more) => {
            if !run_steps(&more, log, deadline, rec) {
                return;
            }
        }
        Err(e) => {
            rec.reason = Some(format!("{e:#}"));
            return;
        }
    }
    rec.status = Status::Ok;
}

fn run_steps(
    steps: &[crate::exec::Step],
    log: &Path,
    deadline: Instant,
    rec: &mut RunRecord,
) -> bool {
    for step in steps {
        rec.command.push(step.command_line());
        let r = run_step(step, log, deadline);
        rec.wall_seconds += r.wall_seconds;
        rec.cpu_seconds += r.user_seconds + r.system_seconds;
        rec.peak_memory_bytes = rec.peak_memory_bytes.max(r.peak_memory_bytes);
        rec.exit_status = r.exit_code;
        let ok = r.success();
        if !ok {
            rec.status = if r.timed_out {
                Status::Timeout
            } else {
                Status::Failed
            };
            let mut reason = r.failure_reason();
            if let Some(last) = last_error_line(log) {
                reason.push_str(&format!(" — {last}"));
            }
            rec.reason = Some(reason);
        }
        rec.steps.push(r);
        if !ok {
            return false;
        }
    }
    true
}

/// The last line of the log that looks like an error message (for the table's reason).
fn last_error_line(log: &Path) -> Option<String> {
    let text = std::fs::read_to_string(log).ok()?;
    text.lines()
        .rev()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .take(40)
        .find(|l| {
            let x = l.to_ascii_lowercase();
            x.contains("error")
                || x.contains("not found")
                || x.contains("failed")
                || x.contains("no such")
        })
        .map(|l| l.trim().chars().take(200).collect())
}

/// Turns the tool's output into the run files: `model/` (COLMAP text), `sparse.ply`,
/// `cameras.json`.
fn collect(work: &Path, output: &Path, rec: &mut RunRecord) -> Result<()> {
    let files = sfmeval_fs::read_input_files(output)?;
    if files.is_empty() {
        bail!("the tool wrote no model or cloud into its output folder");
    }
    let input = sfmeval::pipeline::read_reconstruction(&rec.pipeline, &files)?;
    rec.warnings
        .extend(input.notes.iter().map(|n| n.message.clone()));
    let model_dir = work.join("model");
    std::fs::create_dir_all(&model_dir)?;
    if let Some(model) = &input.model {
        rec.images_registered = model.images.len();
        rec.points = model.points.len();
        rec.models = model.num_models();
        let text_model = ["cameras.txt", "images.txt", "points3D.txt"]
            .iter()
            .all(|f| files.contains_key(*f));
        if text_model && model.sub_models.is_empty() {
            for f in ["cameras.txt", "images.txt", "points3D.txt"] {
                std::fs::copy(output.join(f), model_dir.join(f))
                    .with_context(|| format!("copying {f}"))?;
            }
        } else {
            let mut odd: Vec<&str> = model
                .cameras
                .iter()
                .filter(|c| !sfmeval::model::colmap_write::is_colmap_camera(c))
                .map(|c| c.model.as_str())
                .collect();
            odd.dedup();
            if !odd.is_empty() {
                rec.warnings.push(format!(
                    "model/: camera model {} is not a COLMAP model: written as PINHOLE without its distortion",
                    odd.join(", ")
                ));
            }
            for (name, text) in sfmeval::model::colmap_write::write_colmap_text(model) {
                write_atomic(&model_dir.join(name), text.as_bytes())?;
            }
        }
        let cams = sfmeval::model::cameras_json::write_cameras_json(model, "reconstruction");
        write_atomic(&work.join("cameras.json"), cams.as_bytes())?;
        if model.images.is_empty() {
            bail!("the model has no registered image");
        }
    } else {
        // A bare cloud: keep the tool's PLY as is.
        rec.points = input.cloud.points.len();
        rec.models = 1;
        for (name, bytes) in &files {
            if name.to_ascii_lowercase().ends_with(".ply") {
                write_atomic(&model_dir.join(name.replace('/', "_")), bytes)?;
            }
        }
    }
    let ply =
        sfmeval::export::points_ply(&input.cloud.points.as_f64(), input.cloud.colors.as_deref());
    write_atomic(&work.join("sparse.ply"), &ply)?;
    Ok(())
}

/// `sfmeval-runner merge`: copies every finished run of each shard folder into `out`.
/// A run present in several shards must be identical (same run.json) unless `force`, which
/// keeps the last one given.
pub fn merge(shards: &[PathBuf], out: &Path, force: bool) -> Result<usize> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut copied = 0;
    for shard in shards {
        for (ds, pipe, dir) in list_runs(shard)? {
            let dest = out.join(&ds).join(&pipe);
            if let Ok(existing) = std::fs::read(dest.join("run.json")) {
                let mine = std::fs::read(dir.join("run.json"))?;
                if existing == mine {
                    continue;
                }
                if !force {
                    bail!(
                        "{ds}/{pipe} is in two shards with different results ({} and {}); use --force to keep the last",
                        dest.display(),
                        dir.display()
                    );
                }
            }
            let tmp = partial_name(&dest);
            if let Some(p) = dest.parent() {
                std::fs::create_dir_all(p)?;
            }
            crate::files::copy_dir(&dir, &tmp)?;
            replace_dir(&tmp, &dest)?;
            copied += 1;
        }
    }
    Ok(copied)
}

/// Every finished run under a runs folder: `(dataset, pipeline, folder)`, sorted.
pub fn list_runs(root: &Path) -> Result<Vec<(String, String, PathBuf)>> {
    let mut out = Vec::new();
    let entries = std::fs::read_dir(root).with_context(|| format!("reading {}", root.display()))?;
    for d in entries.filter_map(|e| e.ok()) {
        let ds = d.file_name().to_string_lossy().to_string();
        if ds.starts_with('.') || !d.path().is_dir() {
            continue;
        }
        let Ok(inner) = std::fs::read_dir(d.path()) else {
            continue;
        };
        for p in inner.filter_map(|e| e.ok()) {
            let pipe = p.file_name().to_string_lossy().to_string();
            if pipe.starts_with('.') || !p.path().join("run.json").is_file() {
                continue;
            }
            out.push((ds.clone(), pipe, p.path()));
        }
    }
    out.sort();
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_grid() {
        assert_eq!(parse_shard("1/3").unwrap(), (1, 3));
        assert!(
            parse_shard("3/3").is_err() && parse_shard("x").is_err() && parse_shard("0/0").is_err()
        );
    }
}
