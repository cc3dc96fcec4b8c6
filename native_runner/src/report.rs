//! `sfmeval-runner report`: evaluates every finished run with the sfmeval core (the dataset's
//! ground truth prepared once, `auto` alignment with its cameras.json, optional crop), writes
//! one `sfmeval.report/3` per run and the comparison tables (Markdown, CSV, HTML). A Tanks and
//! Temples scene's runs get the benchmark's protocol (`tnt.rs`), a DTU scan's the DTU protocol
//! (`dtu.rs`), an ETH3D scene's ETH3D's multi-view protocol (`eth3d.rs`). A run whose dataset
//! has ground-truth cameras also gets the pose protocols (`poses.rs`: `sfmeval poses` for COLMAP,
//! IMC and CO3D), their reports beside its report.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use sfmeval::align::AlignRequest;
use sfmeval::dataset::{Dataset, DatasetPaths};
use sfmeval::evaluate::EvalOptions;
use sfmeval::pipeline::{self, EvalRequest};
use sfmeval::progress::NoProgress;
use sfmeval::report::Report;
use sfmeval_fs::{path_str, write_atomic};

use crate::run::{RunRecord, Status, list_runs, read_record};
use crate::table::write_tables;
use sfmeval_table::Row;
use sfmeval_table::run::{base_row, evaluated_row, report_path};

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
        if crate::tnt::is_scene(&ds_dir, &ds) {
            rows.extend(report_tnt_dataset(&ds, &ds_dir, &records, args)?);
            continue;
        }
        if let Some(scan) = crate::dtu::scan_number(&ds_dir) {
            rows.extend(report_dtu_dataset(scan, &ds_dir, &records, args)?);
            continue;
        }
        if crate::eth3d::is_scene(&ds_dir) {
            rows.extend(report_eth3d_dataset(&ds_dir, &records, args)?);
            continue;
        }
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
        rows.extend(dataset_rows(&records, args, |rec, dir| match &mut gt {
            None => Ok(Err(anyhow::anyhow!(
                "no ground truth at {} (pass --datasets)",
                ds_dir.display()
            ))),
            Some(g) => match evaluate_run(g, dir, rec, args) {
                Ok((report, kept, poses)) => {
                    let rel = report_path(&rec.dataset, &rec.pipeline);
                    write_atomic(&args.out.join(&rel), report.to_json().as_bytes())?;
                    let mut row = evaluated_row(&rec.facts(), &report, &kept);
                    row.poses = crate::poses::write_poses(&args.out, &rel, poses)?;
                    Ok(Ok(row))
                }
                Err(e) => Ok(Err(e)),
            },
        })?);
    }
    write_tables(&args.out, &rows)?;
    Ok(rows)
}

/// `--verbose`'s line for a row: its status, then its mean distance and points, and its F-score
/// at the first τ, when evaluated.
fn progress_line(row: &Row) -> String {
    let mut line = format!("{}/{}: {}", row.dataset, row.pipeline, row.status);
    if let Some(m) = row.mean {
        line += &format!(", mean {m:.6} m, {} points", row.points);
    }
    if let Some(t) = row.thresholds.first() {
        line += &format!(", F {:.4} at τ {}", t.f_score, t.tau);
    }
    line
}

/// The rows of a Tanks and Temples scene's runs, evaluated with the benchmark's protocol (τ: the
/// benchmark's for its scenes, else the first `--tau`).
fn report_tnt_dataset(
    ds: &str,
    ds_dir: &Path,
    records: &[(RunRecord, &PathBuf)],
    args: &ReportArgs,
) -> Result<Vec<Row>> {
    let any_ok = records.iter().any(|(r, _)| r.status == Status::Ok);
    // Read only when some run needs it; unused otherwise.
    let scene = if any_ok {
        crate::tnt::read_scene(ds_dir, ds).map_err(|e| format!("{e:#}"))
    } else {
        Err(String::new())
    };
    dataset_rows(records, args, |rec, dir| {
        Ok(match &scene {
            Ok((scene, diagonal)) => crate::tnt::evaluate_run(
                scene,
                *diagonal,
                dir,
                rec,
                &args.out,
                sfmeval_tnt::scene_tau(ds).or(args.eval.tau.first().copied()),
            ),
            Err(e) => Err(anyhow::anyhow!(
                "Tanks and Temples scene {}: {e}",
                ds_dir.display()
            )),
        })
    })
}

/// The rows of a DTU scan's runs, evaluated with the DTU protocol after the camera alignment.
fn report_dtu_dataset(
    scan: u32,
    ds_dir: &Path,
    records: &[(RunRecord, &PathBuf)],
    args: &ReportArgs,
) -> Result<Vec<Row>> {
    let any_ok = records.iter().any(|(r, _)| r.status == Status::Ok);
    // Read only when some run needs it; unused otherwise.
    let read = if any_ok {
        crate::dtu::read_scan(ds_dir, scan).map_err(|e| format!("{e:#}"))
    } else {
        Err(String::new())
    };
    dataset_rows(records, args, |rec, dir| {
        Ok(match &read {
            Ok((dtu_scan, gt_cameras)) => {
                crate::dtu::evaluate_run(scan, dtu_scan, gt_cameras, dir, rec, &args.out)
            }
            Err(e) => Err(anyhow::anyhow!("DTU scan {}: {e}", ds_dir.display())),
        })
    })
}

/// The rows of an ETH3D scene's runs, evaluated with ETH3D's protocol after the camera
/// alignment.
fn report_eth3d_dataset(
    ds_dir: &Path,
    records: &[(RunRecord, &PathBuf)],
    args: &ReportArgs,
) -> Result<Vec<Row>> {
    let any_ok = records.iter().any(|(r, _)| r.status == Status::Ok);
    // Read only when some run needs it; unused otherwise.
    let read = if any_ok {
        crate::eth3d::read_scene(ds_dir).map_err(|e| format!("{e:#}"))
    } else {
        Err(String::new())
    };
    dataset_rows(records, args, |rec, dir| {
        Ok(match &read {
            Ok(scene) => crate::eth3d::evaluate_run(scene, dir, rec, &args.out),
            Err(e) => Err(anyhow::anyhow!("ETH3D scene {}: {e}", ds_dir.display())),
        })
    })
}

/// A dataset's rows: each run's row from its run.json, replaced by `evaluate`'s for runs that
/// ended ok. `evaluate` returns `Err` for what stops the report (an output that cannot be
/// written) and `Ok(Err)` for a run that cannot be evaluated, whose row then says
/// "evaluation failed" and why.
fn dataset_rows(
    records: &[(RunRecord, &PathBuf)],
    args: &ReportArgs,
    mut evaluate: impl FnMut(&RunRecord, &Path) -> Result<Result<Row>>,
) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    for (rec, dir) in records {
        let mut row = base_row(&rec.facts());
        if rec.status == Status::Ok {
            match evaluate(rec, dir)? {
                Ok(evaluated) => row = evaluated,
                Err(e) => {
                    row.status = "evaluation failed".into();
                    row.reason = Some(format!("{e:#}"));
                }
            }
        }
        if args.verbose {
            eprintln!("{}", progress_line(&row));
        }
        rows.push(row);
    }
    Ok(rows)
}

/// The dataset's ground truth with its cameras.json and depth maps when present.
fn load_gt(dir: &Path) -> Result<Dataset> {
    sfmeval_fs::read_dataset(
        &DatasetPaths::folder(path_str(dir)?),
        &sfmeval::io::ReadLimits::default(),
    )
}

fn evaluate_run(
    gt: &mut Dataset,
    dir: &Path,
    rec: &RunRecord,
    args: &ReportArgs,
) -> Result<(Report, Vec<f64>, crate::poses::RunPoses)> {
    // the run folder's layout (model/, else sparse.ply) is sfmeval-table's
    let files = sfmeval_table::layout::read_run_reconstruction(&sfmeval_fs::Disk, path_str(dir)?)?;
    let name = format!("{}/{}", rec.dataset, rec.pipeline);
    let recon = pipeline::read_reconstruction(&name, &files)?;
    let request = EvalRequest {
        eval: args.eval.clone(),
        align: args.align.clone(),
        ..EvalRequest::default()
    };
    let evaluation = pipeline::run(gt, &recon, &request, &NoProgress)?;
    let poses = crate::poses::run_poses(gt.cameras(), &recon);
    let kept: Vec<f64> = evaluation
        .distances
        .iter()
        .zip(&evaluation.status)
        .filter(|(_, s)| matches!(s, sfmeval::evaluate::PointStatus::Kept))
        .map(|(d, _)| *d)
        .collect();
    Ok((evaluation.report, kept, poses))
}
