//! `sfmeval-runner report`: evaluates every finished run with the sfmeval core (the dataset's
//! ground truth prepared once, `auto` alignment with its cameras.json, optional crop), writes
//! one `sfmeval.report/1` per run and the comparison tables (Markdown, CSV, HTML).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use sfmeval::align::AlignRequest;
use sfmeval::dataset::{Dataset, DatasetPaths};
use sfmeval::evaluate::EvalOptions;
use sfmeval::pipeline::{self, EvalRequest};
use sfmeval::progress::NoProgress;
use sfmeval::report::Report;
use sfmeval_fs::{path_str, read_input_files, write_atomic};

use crate::adapters::BUILTIN;
use crate::run::{RunRecord, Status, list_runs, read_record};

/// One threshold's precision / recall / F.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Prf {
    /// Threshold in ground-truth units (metres for Blender datasets).
    pub tau: f64,
    /// The same threshold in percent of the ground-truth bounding-box diagonal.
    pub tau_percent_of_diagonal: f64,
    /// Precision.
    pub precision: f64,
    /// Recall.
    pub recall: f64,
    /// F-score.
    pub f_score: f64,
}

/// One run in the comparison.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Row {
    /// Dataset.
    pub dataset: String,
    /// Pipeline.
    pub pipeline: String,
    /// Tool and version.
    pub tool: String,
    /// Tool version.
    pub version: Option<String>,
    /// `ok`, `failed`, `timeout`, `not installed`, `evaluation failed`.
    pub status: String,
    /// Why not ok.
    pub reason: Option<String>,
    /// Images in the dataset.
    pub images_total: usize,
    /// Images registered.
    pub images_registered: usize,
    /// Points of the reconstruction.
    pub points: u64,
    /// Wall seconds.
    pub wall_seconds: f64,
    /// CPU seconds.
    pub cpu_seconds: f64,
    /// Peak memory, MB.
    pub peak_memory_mb: f64,
    /// Accuracy: mean distance reconstruction → GT (m).
    pub mean: Option<f64>,
    /// Median distance.
    pub median: Option<f64>,
    /// RMS distance.
    pub rms: Option<f64>,
    /// Mean completeness distance GT → reconstruction.
    pub completeness_mean: Option<f64>,
    /// P/R/F per threshold.
    pub thresholds: Vec<Prf>,
    /// Median rotation error (degrees).
    pub rotation_median_deg: Option<f64>,
    /// Median camera-centre error (m).
    pub center_median: Option<f64>,
    /// Median camera-centre error, % of the scene radius.
    pub center_median_percent: Option<f64>,
    /// Largest camera-centre error, % of the scene radius.
    pub center_max_percent: Option<f64>,
    /// Cumulative share of points within a distance: `(distance, share)`.
    pub cdf: Vec<(f64, f64)>,
    /// The report file, relative to the table folder.
    pub report: Option<String>,
}

/// Options of `report`.
#[derive(Debug, Clone)]
pub struct ReportArgs {
    /// Runs folders.
    pub runs: Vec<PathBuf>,
    /// Output folder.
    pub out: PathBuf,
    /// Dataset folders overriding the ones recorded in run.json (matched by name).
    pub datasets: Vec<PathBuf>,
    /// Measurement options.
    pub eval: EvalOptions,
    /// Alignment (`auto` by default).
    pub align: AlignRequest,
    /// Print progress.
    pub verbose: bool,
}

/// Evaluates every run and writes the tables. Returns the rows.
pub fn report(args: &ReportArgs) -> Result<Vec<Row>> {
    args.eval.validate()?;
    let mut runs: BTreeMap<(String, String), PathBuf> = BTreeMap::new();
    for root in &args.runs {
        for (ds, pipe, dir) in list_runs(root)? {
            runs.insert((ds, pipe), dir);
        }
    }
    if runs.is_empty() {
        bail!(
            "no finished runs under {}",
            args.runs
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let overrides: BTreeMap<String, PathBuf> = args
        .datasets
        .iter()
        .filter_map(|d| Some((d.file_name()?.to_string_lossy().to_string(), d.clone())))
        .collect();
    let mut rows = Vec::new();
    let datasets: BTreeSet<String> = runs.keys().map(|k| k.0.clone()).collect();
    for ds in datasets {
        let these: Vec<(&String, &PathBuf)> = runs
            .iter()
            .filter(|(k, _)| k.0 == ds)
            .map(|(k, v)| (&k.1, v))
            .collect();
        let records: Vec<(RunRecord, &PathBuf)> = these
            .iter()
            .map(|(_, dir)| Ok((read_record(dir)?, *dir)))
            .collect::<Result<_>>()?;
        let ds_dir = match overrides.get(&ds) {
            Some(d) => d.clone(),
            None => records
                .first()
                .map(|(r, _)| PathBuf::from(&r.dataset_dir))
                .unwrap_or_default(),
        };
        let any_ok = records.iter().any(|(r, _)| r.status == Status::Ok);
        let mut gt = if any_ok {
            match load_gt(&ds_dir) {
                Ok(g) => Some(g),
                Err(e) => {
                    eprintln!("{ds}: ground truth: {e:#}");
                    None
                }
            }
        } else {
            None
        };
        for (rec, dir) in &records {
            let mut row = base_row(rec);
            if rec.status == Status::Ok {
                match &mut gt {
                    None => {
                        row.status = "evaluation failed".into();
                        row.reason = Some(format!(
                            "no ground truth at {} (pass --datasets)",
                            ds_dir.display()
                        ));
                    }
                    Some(g) => match evaluate_run(g, dir, rec, args) {
                        Ok((report, cdf)) => {
                            let rel = format!("reports/{}/{}.json", rec.dataset, rec.pipeline);
                            write_atomic(&args.out.join(&rel), report.to_json().as_bytes())?;
                            fill_row(&mut row, &report);
                            row.cdf = cdf;
                            row.report = Some(rel);
                        }
                        Err(e) => {
                            row.status = "evaluation failed".into();
                            row.reason = Some(format!("{e:#}"));
                        }
                    },
                }
            }
            if args.verbose {
                eprintln!(
                    "{}/{}: {}{}",
                    row.dataset,
                    row.pipeline,
                    row.status,
                    row.mean
                        .map(|m| format!(", mean {m:.6} m, {} points", row.points))
                        .unwrap_or_default()
                );
            }
            rows.push(row);
        }
    }
    write_tables(&args.out, &rows)?;
    Ok(rows)
}

/// The dataset's ground truth with its cameras.json and depth maps when present.
fn load_gt(dir: &Path) -> Result<Dataset> {
    sfmeval_fs::read_dataset(&DatasetPaths::folder(path_str(dir)?))
}

/// Points of the cumulative distribution of `distances`: 201 quantiles `(distance, share)`.
fn cdf_points(distances: &[f64]) -> Vec<(f64, f64)> {
    let mut d: Vec<f64> = distances
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    if d.is_empty() {
        return Vec::new();
    }
    d.sort_by(f64::total_cmp);
    let n = d.len();
    (0..=200)
        .map(|k| {
            let i = ((k as f64 / 200.0) * (n - 1) as f64).round() as usize;
            (d[i.min(n - 1)], (i + 1) as f64 / n as f64)
        })
        .collect()
}

fn evaluate_run(
    gt: &mut Dataset,
    dir: &Path,
    rec: &RunRecord,
    args: &ReportArgs,
) -> Result<(Report, Vec<(f64, f64)>)> {
    let model = dir.join("model");
    let mut files = if model.is_dir() {
        read_input_files(&model)?
    } else {
        BTreeMap::new()
    };
    if files.is_empty() {
        let ply = std::fs::read(dir.join("sparse.ply")).context("reading sparse.ply")?;
        files.insert("sparse.ply".into(), ply);
    }
    let name = format!("{}/{}", rec.dataset, rec.pipeline);
    let recon = pipeline::read_reconstruction(&name, &files)?;
    let request = EvalRequest {
        eval: args.eval.clone(),
        align: args.align.clone(),
        ..EvalRequest::default()
    };
    let evaluation = pipeline::run(gt, &recon, &request, &NoProgress)?;
    let kept: Vec<f64> = evaluation
        .distances
        .iter()
        .zip(&evaluation.status)
        .filter(|(_, s)| matches!(s, sfmeval::evaluate::PointStatus::Kept))
        .map(|(d, _)| *d)
        .collect();
    let cdf = cdf_points(&kept);
    Ok((evaluation.report, cdf))
}

fn base_row(rec: &RunRecord) -> Row {
    Row {
        dataset: rec.dataset.clone(),
        pipeline: rec.pipeline.clone(),
        tool: rec.tool.clone(),
        version: rec.version.clone(),
        status: rec.status.label().to_string(),
        reason: rec.reason.clone(),
        images_total: rec.images_total,
        images_registered: rec.images_registered,
        points: rec.points as u64,
        wall_seconds: rec.wall_seconds,
        cpu_seconds: rec.cpu_seconds,
        peak_memory_mb: rec.peak_memory_bytes as f64 / 1e6,
        mean: None,
        median: None,
        rms: None,
        completeness_mean: None,
        thresholds: Vec::new(),
        rotation_median_deg: None,
        center_median: None,
        center_median_percent: None,
        center_max_percent: None,
        cdf: Vec::new(),
        report: None,
    }
}

fn fill_row(row: &mut Row, r: &Report) {
    let a = &r.accuracy.stats;
    row.points = r.inputs.reconstruction.points;
    row.mean = Some(a.mean);
    row.median = Some(a.median);
    row.rms = Some(a.rms);
    row.completeness_mean = Some(r.completeness.stats.mean);
    row.thresholds = r
        .thresholds
        .iter()
        .map(|t| Prf {
            tau: t.tau,
            tau_percent_of_diagonal: t.tau_percent_of_diagonal,
            precision: t.precision,
            recall: t.recall,
            f_score: t.f_score,
        })
        .collect();
    if let Some(c) = &r.cameras {
        let c = &c.errors;
        row.rotation_median_deg = Some(c.rotation_error_deg.median);
        row.center_median = Some(c.center_error.median);
        row.center_median_percent = Some(c.center_error_percent.median);
        row.center_max_percent = Some(c.center_error_percent.max);
        row.images_registered = c.registered;
    }
}

/// Pipelines in table order: built-ins first (their fixed order), then others by name.
pub fn pipeline_order(rows: &[Row]) -> Vec<String> {
    let names: BTreeSet<&str> = rows.iter().map(|r| r.pipeline.as_str()).collect();
    let mut out: Vec<String> = BUILTIN
        .iter()
        .filter(|b| names.contains(*b))
        .map(|s| s.to_string())
        .collect();
    out.extend(
        names
            .iter()
            .filter(|n| !BUILTIN.contains(*n))
            .map(|s| s.to_string()),
    );
    out
}

/// Datasets in table order (by name).
pub fn dataset_order(rows: &[Row]) -> Vec<String> {
    let s: BTreeSet<&str> = rows.iter().map(|r| r.dataset.as_str()).collect();
    s.into_iter().map(String::from).collect()
}

fn find<'a>(rows: &'a [Row], d: &str, p: &str) -> Option<&'a Row> {
    rows.iter().find(|r| r.dataset == d && r.pipeline == p)
}

/// Table I cell text: `mean m (points)` or the failure.
pub fn table1_cell(r: Option<&Row>) -> String {
    match r {
        None => "—".into(),
        Some(r) => match r.mean {
            Some(m) => format!("{m:.6} ({})", r.points),
            None => {
                let reason = short(r.reason.as_deref().unwrap_or(""));
                if reason.starts_with(&r.status) {
                    reason
                } else {
                    format!("{}: {reason}", r.status)
                }
            }
        },
    }
}

fn short(s: &str) -> String {
    let one = s.replace(['\n', '|'], " ");
    if one.chars().count() > 120 {
        format!("{}…", one.chars().take(120).collect::<String>())
    } else {
        one
    }
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map(|x| format!("{x:.digits$}")).unwrap_or_default()
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn csv_num(v: Option<f64>) -> String {
    v.map(|x| format!("{x}")).unwrap_or_default()
}

/// Column headers and per-row values of the wide table (shared by Markdown, CSV and HTML).
fn wide_columns(rows: &[Row]) -> Vec<String> {
    let mut cols: Vec<String> = [
        "dataset",
        "pipeline",
        "status",
        "points",
        "registered",
        "mean (m)",
        "median (m)",
        "RMS (m)",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    if let Some(r) = rows.iter().find(|r| !r.thresholds.is_empty()) {
        for t in &r.thresholds {
            let pct = (t.tau_percent_of_diagonal * 1e6).round() / 1e6;
            cols.push(format!("P@{pct}%"));
            cols.push(format!("R@{pct}%"));
            cols.push(format!("F@{pct}%"));
        }
    }
    cols.extend(
        [
            "rot. median (°)",
            "centre median (m)",
            "centre median (% radius)",
            "centre max (% radius)",
            "wall (s)",
            "CPU (s)",
            "peak mem (MB)",
            "tool",
            "reason",
        ]
        .iter()
        .map(|s| s.to_string()),
    );
    cols
}

fn wide_values(r: &Row, n_tau: usize, csv: bool) -> Vec<String> {
    let num = |v: Option<f64>, d: usize| if csv { csv_num(v) } else { opt(v, d) };
    let mut v = vec![
        r.dataset.clone(),
        r.pipeline.clone(),
        r.status.clone(),
        if r.status == "ok" {
            r.points.to_string()
        } else {
            String::new()
        },
        format!("{}/{}", r.images_registered, r.images_total),
        num(r.mean, 6),
        num(r.median, 6),
        num(r.rms, 6),
    ];
    for k in 0..n_tau {
        let t = r.thresholds.get(k);
        v.push(num(t.map(|t| t.precision), 3));
        v.push(num(t.map(|t| t.recall), 3));
        v.push(num(t.map(|t| t.f_score), 3));
    }
    v.extend([
        num(r.rotation_median_deg, 3),
        num(r.center_median, 5),
        num(r.center_median_percent, 3),
        num(r.center_max_percent, 3),
        num(Some(r.wall_seconds), 1),
        num(Some(r.cpu_seconds), 1),
        num(Some(r.peak_memory_mb), 0),
        format!("{} {}", r.tool, r.version.as_deref().unwrap_or(""))
            .trim()
            .to_string(),
        if csv {
            r.reason.clone().unwrap_or_default()
        } else {
            short(r.reason.as_deref().unwrap_or(""))
        },
    ]);
    v
}

fn n_tau(rows: &[Row]) -> usize {
    rows.iter().map(|r| r.thresholds.len()).max().unwrap_or(0)
}

/// Writes `table1.md`, `table1.csv`, `runs.csv`, `table.md` (both tables), `index.html` and
/// `summary.json` into `out`.
pub fn write_tables(out: &Path, rows: &[Row]) -> Result<()> {
    let datasets = dataset_order(rows);
    let pipes = pipeline_order(rows);
    // Table I.
    let mut t1 = String::from("| dataset |");
    for p in &pipes {
        t1.push_str(&format!(" {p} |"));
    }
    t1.push_str("\n|---|");
    t1.push_str(&"---:|".repeat(pipes.len()));
    t1.push('\n');
    for d in &datasets {
        t1.push_str(&format!("| {d} |"));
        for p in &pipes {
            t1.push_str(&format!(" {} |", table1_cell(find(rows, d, p))));
        }
        t1.push('\n');
    }
    let t1_md = format!(
        "# Table I: mean distance to the ground truth (m) and number of points\n\nEach cell: mean reconstruction → ground-truth distance in metres (after `auto` alignment), and in parentheses the number of points; failed runs show why.\n\n{t1}"
    );
    write_atomic(&out.join("table1.md"), t1_md.as_bytes())?;
    let mut csv = String::from("dataset");
    for p in &pipes {
        csv.push_str(&format!(",{p}.mean_m,{p}.points,{p}.status"));
    }
    csv.push('\n');
    for d in &datasets {
        csv.push_str(&csv_field(d));
        for p in &pipes {
            match find(rows, d, p) {
                Some(r) => csv.push_str(&format!(
                    ",{},{},{}",
                    csv_num(r.mean),
                    if r.mean.is_some() {
                        r.points.to_string()
                    } else {
                        String::new()
                    },
                    csv_field(&r.status)
                )),
                None => csv.push_str(",,,"),
            }
        }
        csv.push('\n');
    }
    write_atomic(&out.join("table1.csv"), csv.as_bytes())?;
    // Wide table.
    let cols = wide_columns(rows);
    let nt = n_tau(rows);
    let mut ordered: Vec<&Row> = Vec::new();
    for d in &datasets {
        for p in &pipes {
            if let Some(r) = find(rows, d, p) {
                ordered.push(r);
            }
        }
    }
    let mut wide = format!("| {} |\n|{}\n", cols.join(" | "), "---|".repeat(cols.len()));
    for r in &ordered {
        wide.push_str(&format!("| {} |\n", wide_values(r, nt, false).join(" | ")));
    }
    let mut wcsv = cols
        .iter()
        .map(|c| csv_field(c))
        .collect::<Vec<_>>()
        .join(",");
    wcsv.push('\n');
    for r in &ordered {
        wcsv.push_str(
            &wide_values(r, nt, true)
                .iter()
                .map(|v| csv_field(v))
                .collect::<Vec<_>>()
                .join(","),
        );
        wcsv.push('\n');
    }
    write_atomic(&out.join("runs.csv"), wcsv.as_bytes())?;
    let md = format!(
        "{t1_md}\n# All runs\n\nP/R/F at thresholds in % of the ground-truth bounding-box diagonal; camera errors after the same alignment, centre errors also in % of the scene radius (mean distance of the ground-truth cameras from their centroid).\n\n{wide}"
    );
    write_atomic(&out.join("table.md"), md.as_bytes())?;
    write_atomic(
        &out.join("index.html"),
        crate::html::page(rows, &datasets, &pipes).as_bytes(),
    )?;
    let mut json = serde_json::to_string_pretty(&serde_json::json!({
        "schema": "sfmeval.runner-table/1",
        "datasets": datasets,
        "pipelines": pipes,
        "rows": rows,
    }))?;
    json.push('\n');
    write_atomic(&out.join("summary.json"), json.as_bytes())?;
    Ok(())
}

/// Wide-table columns and values for the HTML page.
pub fn wide_for_html(
    rows: &[Row],
    datasets: &[String],
    pipes: &[String],
) -> (Vec<String>, Vec<(String, Vec<String>)>) {
    let nt = n_tau(rows);
    let mut out = Vec::new();
    for d in datasets {
        for p in pipes {
            if let Some(r) = find(rows, d, p) {
                out.push((r.status.clone(), wide_values(r, nt, false)));
            }
        }
    }
    (wide_columns(rows), out)
}
