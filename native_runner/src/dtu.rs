//! Runs on a DTU scan (a folder with `images/`, the ground-truth cameras `cameras.json` in the
//! scan's frame and in mm, and the benchmark's files `Points/stl/stlNNN_total.ply`,
//! `ObsMask/ObsMaskN_10.mat`, `ObsMask/PlaneN.mat`), evaluated with the DTU protocol
//! (`sfmeval_dtu`) instead of the synthetic datasets' evaluation: each run's model is brought
//! into the scan's frame by its cameras (the core's camera alignment, as `sfmeval cameras`
//! aligns them), its points are written there as a PLY, and `sfmeval dtu` on that PLY gives the
//! run's report.

use std::path::Path;

use anyhow::{Context, Result, bail};
use sfmeval::dataset::CAMERAS_FILE;
use sfmeval::model;
use sfmeval::pose::PoseOptions;
use sfmeval::progress::NoProgress;
use sfmeval_dtu::{self as dtu, DtuInput, DtuOptions, DtuReport, DtuScan};
use sfmeval_fs::{path_str, read_dtu_scan, read_input_files, write_atomic};
use sfmeval_table::Row;
use sfmeval_table::row::DtuNumbers;
use sfmeval_table::run::{dtu_row, report_path};

use crate::run::RunRecord;

/// The reconstruction's points in the scan's frame, in the run's files folder.
pub const RECON_PLY: &str = "recon_in_scan_frame.ply";
/// The camera alignment that brought them there (the report's alignment section).
pub const ALIGNMENT_JSON: &str = "alignment.json";

/// The scan number of the DTU scan in `dir`: its one `Points/stl/stlNNN_total.ply` whose
/// observation mask and plane are there too; none for a folder in another layout.
pub fn scan_number(dir: &Path) -> Option<u32> {
    let stl_dir = dir.join("Points").join("stl");
    let mut scans = std::fs::read_dir(stl_dir).ok()?.filter_map(|e| {
        let name = e.ok()?.file_name().into_string().ok()?;
        let n: u32 = name
            .strip_prefix("stl")?
            .strip_suffix("_total.ply")?
            .parse()
            .ok()?;
        (dir.join(dtu::scan::obs_mask_path(n)).is_file()
            && dir.join(dtu::scan::plane_path(n)).is_file())
        .then_some(n)
    });
    let first = scans.next()?;
    scans.next().is_none().then_some(first)
}

/// Reads the scan `scan` in `dir` and its ground-truth cameras.
pub fn read_scan(dir: &Path, scan: u32) -> Result<(DtuScan, model::Reconstruction)> {
    let cameras = dir.join(CAMERAS_FILE);
    if !cameras.is_file() {
        bail!(
            "DTU scan {}: no {CAMERAS_FILE} (the ground-truth cameras in the scan's frame, in mm, which align each run)",
            dir.display()
        );
    }
    let gt = model::read_model_files(&read_input_files(&cameras)?)
        .with_context(|| format!("ground-truth cameras '{}'", cameras.display()))?;
    Ok((read_dtu_scan(dir, scan)?, gt))
}

/// Evaluates one finished run on the scan: aligns its model's cameras to the ground truth's,
/// writes in `reports/<ds>/<pipeline>/` its points in the scan's frame ([`RECON_PLY`]), the
/// alignment ([`ALIGNMENT_JSON`]) and the evaluator's error clouds, and the protocol's report
/// as `reports/<ds>/<pipeline>.json`, with the CLI's default options (`sfmeval dtu --recon
/// RECON_PLY` gives the same report but for its name), and the pose protocols' reports beside it.
pub fn evaluate_run(
    scan_no: u32,
    scan: &DtuScan,
    gt_cameras: &model::Reconstruction,
    run_dir: &Path,
    rec: &RunRecord,
    out: &Path,
) -> Result<Row> {
    let files =
        sfmeval_table::layout::read_run_reconstruction(&sfmeval_fs::Disk, path_str(run_dir)?)?;
    let name = format!("{}/{}", rec.dataset, rec.pipeline);
    let recon = sfmeval::pipeline::read_reconstruction(&name, &files)
        .with_context(|| format!("run {}", run_dir.display()))?;
    let Some(est) = &recon.model else {
        bail!(
            "run {}: no cameras to align to the scan's",
            run_dir.display()
        );
    };
    let (gt_from_recon, alignment, _) =
        sfmeval::pipeline::cameras_only(gt_cameras, est, None, 0, &PoseOptions::default())
            .with_context(|| format!("run {}: camera alignment", run_dir.display()))?;
    let points: Vec<[f64; 3]> = recon
        .cloud
        .points
        .as_f64()
        .iter()
        .map(|p| gt_from_recon.apply(*p))
        .collect();
    let rel = report_path(&rec.dataset, &rec.pipeline);
    let dir = out.join(rel.trim_end_matches(".json"));
    let ply = sfmeval::export::points_ply_f64(&points, None);
    let ply_path = dir.join(RECON_PLY);
    write_atomic(&ply_path, &ply)?;
    let mut alignment_json = serde_json::to_string_pretty(&alignment)?;
    alignment_json.push('\n');
    write_atomic(&dir.join(ALIGNMENT_JSON), alignment_json.as_bytes())?;
    // Evaluated from the written file's numbers, as `sfmeval dtu` reads them.
    let written = sfmeval::io::ply::read_ply(&ply)?.vertices.into_f64();
    let evaluation = dtu::evaluate(
        scan,
        DtuInput::Cloud(written),
        &DtuOptions::default(),
        &NoProgress,
    )
    .with_context(|| format!("run {}", run_dir.display()))?;
    let report = DtuReport::new(&evaluation, scan_no, &ply_path.display().to_string(), false);
    write_atomic(&out.join(&rel), report.to_json().as_bytes())?;
    for (file, bytes) in dtu::vis::output_files(&evaluation, scan_no, &scan.stl) {
        write_atomic(&dir.join(file), &bytes)?;
    }
    let mut row = dtu_row(
        &rec.facts(),
        DtuNumbers {
            scan: scan_no,
            mean_accuracy: report.mean_accuracy,
            mean_completeness: report.mean_completeness,
            overall: report.overall,
        },
        report.counts.points as u64,
        "cameras",
    );
    let poses = crate::poses::run_poses(Some(gt_cameras), &recon);
    row.poses = crate::poses::write_poses(out, &rel, poses)?;
    Ok(row)
}
