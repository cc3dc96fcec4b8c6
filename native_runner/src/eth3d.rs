//! Runs on an ETH3D scene (a folder with `images/`, the ground-truth cameras in the scene's
//! frame and in metres — `cameras.json`, else the benchmark's COLMAP model
//! `dslr_calibration_undistorted/` — and the laser scans as the benchmark ships them:
//! `dslr_scan_eval/scan_alignment.mlp` with its scan PLYs), evaluated with ETH3D's multi-view
//! protocol (`sfmeval_eth3d`) instead of the synthetic datasets' evaluation: each run's model is
//! brought into the scene's frame by its cameras (the core's camera alignment, as `sfmeval
//! cameras` aligns them), its points are written there as a PLY, and `sfmeval eth3d` on that
//! PLY gives the run's report.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use sfmeval::dataset::CAMERAS_FILE;
use sfmeval::model;
use sfmeval::pose::PoseOptions;
use sfmeval_eth3d::{Eth3dOptions, Eth3dScene};
use sfmeval_fs::{
    Eth3dRun, eth3d_on_scene, path_str, read_eth3d_scene, read_input_files, write_atomic,
};
use sfmeval_table::Row;
use sfmeval_table::row::{Eth3dNumbers, Eth3dTolerance};
use sfmeval_table::run::{eth3d_row, report_path};

use crate::run::RunRecord;

/// The scene's MeshLab project, relative to its folder.
pub const MLP: &str = "dslr_scan_eval/scan_alignment.mlp";
/// The benchmark's ground-truth cameras (a COLMAP text model), used without a `cameras.json`.
pub const CALIBRATION_DIR: &str = "dslr_calibration_undistorted";
/// The reconstruction's points in the scene's frame, in the run's files folder.
pub const RECON_PLY: &str = "recon_in_scene_frame.ply";
/// The camera alignment that brought them there.
pub const ALIGNMENT_JSON: &str = "alignment.json";

/// Whether `dir` is an ETH3D scene (its [`MLP`] is there).
pub fn is_scene(dir: &Path) -> bool {
    dir.join(MLP).is_file()
}

/// An ETH3D scene read for the report: its project's path (its name in the reports), the scans
/// and the ground-truth cameras.
pub struct SceneInputs {
    /// `DIR/dslr_scan_eval/scan_alignment.mlp`.
    pub mlp: PathBuf,
    /// The scans.
    pub scene: Eth3dScene,
    /// The ground-truth cameras, in the scene's frame (m).
    pub gt_cameras: model::Reconstruction,
}

/// Reads the scene in `dir` and its ground-truth cameras.
pub fn read_scene(dir: &Path) -> Result<SceneInputs> {
    let cameras = [dir.join(CAMERAS_FILE), dir.join(CALIBRATION_DIR)]
        .into_iter()
        .find(|p| p.exists())
        .with_context(|| {
            format!(
                "ETH3D scene {}: no {CAMERAS_FILE} or {CALIBRATION_DIR}/ (the ground-truth cameras in the scene's frame, in metres, which align each run)",
                dir.display()
            )
        })?;
    let gt_cameras = model::read_model_files(&read_input_files(&cameras)?)
        .with_context(|| format!("ground-truth cameras '{}'", cameras.display()))?;
    let mlp = dir.join(MLP);
    let scene = read_eth3d_scene(&mlp)?;
    Ok(SceneInputs {
        mlp,
        scene,
        gt_cameras,
    })
}

/// The report's numbers, each `float` as the report writes it (its shortest decimal).
fn numbers(report: &sfmeval_eth3d::Eth3dReport) -> Eth3dNumbers {
    let f = |v: f32| format!("{v}").parse::<f64>().unwrap_or(f64::from(v));
    Eth3dNumbers {
        tolerances: report
            .tolerances
            .iter()
            .map(|t| Eth3dTolerance {
                tolerance: f(t.tolerance),
                accuracy: f(t.accuracy),
                completeness: f(t.completeness),
                f1: f(t.f1),
            })
            .collect(),
    }
}

/// Evaluates one finished run on the scene: aligns its model's cameras to the ground truth's,
/// writes in `reports/<ds>/<pipeline>/` its points in the scene's frame ([`RECON_PLY`]), the
/// alignment ([`ALIGNMENT_JSON`]) and the tool's coloured clouds, the protocol's report as
/// `reports/<ds>/<pipeline>.json` with the CLI's default options (`sfmeval eth3d --gt MLP
/// --recon RECON_PLY --json` prints the same bytes), and the pose protocols' reports beside it.
pub fn evaluate_run(s: &SceneInputs, run_dir: &Path, rec: &RunRecord, out: &Path) -> Result<Row> {
    let files =
        sfmeval_table::layout::read_run_reconstruction(&sfmeval_fs::Disk, path_str(run_dir)?)?;
    let name = format!("{}/{}", rec.dataset, rec.pipeline);
    let recon = sfmeval::pipeline::read_reconstruction(&name, &files)
        .with_context(|| format!("run {}", run_dir.display()))?;
    let Some(est) = &recon.model else {
        bail!(
            "run {}: no cameras to align to the scene's",
            run_dir.display()
        );
    };
    let (gt_from_recon, alignment, _) =
        sfmeval::pipeline::cameras_only(&s.gt_cameras, est, None, 0, &PoseOptions::default())
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
    // float x y z, as ETH3D's tool reads PLYs (PCL reads a PLY of doubles as zeros)
    let ply_path = dir.join(RECON_PLY);
    write_atomic(&ply_path, &sfmeval::export::points_ply(&points, None))?;
    let mut alignment_json = serde_json::to_string_pretty(&alignment)?;
    alignment_json.push('\n');
    write_atomic(&dir.join(ALIGNMENT_JSON), alignment_json.as_bytes())?;
    let options = Eth3dOptions::default();
    let outputs = eth3d_on_scene(
        &s.scene,
        &Eth3dRun {
            gt: &s.mlp,
            recon: &ply_path,
            options: &options,
        },
    )
    .with_context(|| format!("run {}", run_dir.display()))?;
    write_atomic(&out.join(&rel), outputs.json.as_bytes())?;
    outputs.write_vis_files(|file, bytes| write_atomic(&dir.join(file), bytes))?;
    let mut row = eth3d_row(
        &rec.facts(),
        numbers(&outputs.report),
        outputs.report.reconstruction_points as u64,
        "cameras",
    );
    let poses = crate::poses::run_poses(Some(&s.gt_cameras), &recon);
    row.poses = crate::poses::write_poses(out, &rel, poses)?;
    Ok(row)
}
