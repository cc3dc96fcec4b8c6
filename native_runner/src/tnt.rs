//! Runs on a Tanks and Temples scene (a folder with `images/` and the benchmark's files:
//! `<scene>.ply`, `<scene>.json`, `<scene>_trans.txt`, `<scene>_COLMAP_SfM.log`), evaluated
//! with the benchmark's protocol (`sfmeval_tnt`) instead of the synthetic datasets'
//! evaluation: each run's cameras become its `.log` trajectory (one frame per image of
//! `images/`, sorted by name), and its sparse cloud is measured after the protocol's registration.

use std::path::Path;

use anyhow::{Context, Result};
use sfmeval::geometry::Aabb;
use sfmeval::progress::NoProgress;
use sfmeval_fs::{Disk, image_names, path_str, read_input_files, write_atomic};
use sfmeval_table::Row;
use sfmeval_table::run::{report_path, tnt_row};
use sfmeval_tnt::{
    self as tnt, IcpCriteria, Registration, Scene, TntRequest, TrajectoryAlignmentOptions,
};

use crate::run::RunRecord;

/// Whether `dir` holds a Tanks and Temples scene named `name` (its trans and reference
/// trajectory files).
pub fn is_scene(dir: &Path, name: &str) -> bool {
    dir.join(format!("{name}_trans.txt")).is_file()
        && dir.join(format!("{name}_COLMAP_SfM.log")).is_file()
}

/// Reads the scene and its ground truth's diagonal.
pub fn read_scene(dir: &Path, name: &str) -> Result<(Scene, f64)> {
    let scene = Scene::read(&Disk, path_str(dir)?, Some(name))?;
    let diagonal = Aabb::of(&scene.ground_truth).map_or(1.0, |b| b.diagonal());
    Ok((scene, diagonal))
}

/// Evaluates one finished run on the scene: writes `reports/<ds>/<pipeline>.json` (the
/// protocol's report) and, in `reports/<ds>/<pipeline>/`, the run's `trajectory.log`, the
/// coloured `<scene>.precision.ply` / `.recall.ply` and the toolbox's text files. `tau` overrides
/// the benchmark's τ of the scene.
pub fn evaluate_run(
    scene: &Scene,
    gt_diagonal: f64,
    run_dir: &Path,
    rec: &RunRecord,
    out: &Path,
    tau: Option<f64>,
) -> Result<Row> {
    let model_dir = run_dir.join(sfmeval_table::layout::MODEL_DIR);
    let name = format!("{}/{}", rec.dataset, rec.pipeline);
    let recon = sfmeval::pipeline::read_reconstruction(&name, &read_input_files(&model_dir)?)
        .with_context(|| format!("model {}", model_dir.display()))?;
    let Some(model) = &recon.model else {
        anyhow::bail!("model {} has no cameras", model_dir.display());
    };
    let images = Path::new(&rec.dataset_dir).join("images");
    let names = image_names(&images)?;
    let (frames, _) = tnt::log_from_model(model, &names);
    let rel = report_path(&rec.dataset, &rec.pipeline);
    let files = out.join(rel.trim_end_matches(".json"));
    let log = tnt::write_log(&frames);
    write_atomic(&files.join("trajectory.log"), log.as_bytes())?;
    // Evaluated from the written file's numbers (12 decimals), so that `sfmeval tnt` on the
    // run's files reproduces the report exactly.
    let frames = tnt::read_log(log.as_bytes())?;
    let request = TntRequest {
        tau,
        registration: Registration::Protocol {
            trajectory: frames,
            trajectory_name: "trajectory.log".into(),
            options: TrajectoryAlignmentOptions::default(),
        },
        icp: IcpCriteria::TOOLBOX,
    };
    let evaluation = tnt::evaluate(
        scene,
        &name,
        &recon.cloud.points.as_f64(),
        &request,
        &NoProgress,
    )?;
    write_atomic(&out.join(&rel), evaluation.report_json().as_bytes())?;
    for (file, bytes) in evaluation.output_files() {
        write_atomic(&files.join(file), &bytes)?;
    }
    Ok(tnt_row(
        &rec.facts(),
        &evaluation.report,
        &evaluation.precision_distances,
        gt_diagonal,
    ))
}
