//! Camera poses of files on disk: a ground-truth model and a reconstruction's cameras, measured as
//! `sfmeval cameras` (the aligned camera errors) and `sfmeval poses` (a benchmark's pose protocol)
//! do, so that the CLI and the Python package give the same reports byte for byte.

use std::path::Path;

use anyhow::{Context as _, Result, anyhow};
use sfmeval::model::{self, Reconstruction};
use sfmeval::pipeline;
use sfmeval::pose::{CamerasReport, PoseOptions, PosesReport, Protocol, ProtocolOptions};
use sfmeval::report::AlignmentReport;
use sfmeval::transform::Similarity;

use crate::disk::{name_of, read_input_files};

/// The ground-truth cameras at `gt_cameras` and the cameras of the reconstruction at `recon`
/// (a model file or folder); errors name the file, and a bare point cloud is refused.
pub fn read_camera_models(
    gt_cameras: &Path,
    recon: &Path,
) -> Result<(Reconstruction, Reconstruction)> {
    let gt = model::read_model_files(&read_input_files(gt_cameras)?)
        .with_context(|| format!("ground-truth cameras '{}'", gt_cameras.display()))?;
    let est = pipeline::read_reconstruction(&name_of(recon), &read_input_files(recon)?)
        .with_context(|| format!("reconstruction '{}'", recon.display()))?;
    let est = est.model.ok_or_else(|| {
        anyhow!(
            "reconstruction '{}' has no cameras (a bare point cloud)",
            recon.display()
        )
    })?;
    Ok((gt, est))
}

/// What `sfmeval cameras` measures: the alignment (by the camera centres, or `given`) and each
/// camera's errors.
#[derive(Debug)]
pub struct CamerasOutputs {
    /// How the reconstruction was brought into the ground truth's frame.
    pub alignment: AlignmentReport,
    /// The per-camera errors and their statistics.
    pub cameras: CamerasReport,
}

impl CamerasOutputs {
    /// The JSON `sfmeval cameras --report` writes (`{"alignment", "cameras"}`, a final newline).
    pub fn to_json(&self) -> Result<String> {
        let value = serde_json::json!({"alignment": self.alignment, "cameras": self.cameras});
        let mut s = serde_json::to_string_pretty(&value)?;
        s.push('\n');
        Ok(s)
    }
}

/// `sfmeval cameras` on files: the reconstruction's cameras at `recon` against `gt_cameras`.
pub fn cameras_on_files(
    gt_cameras: &Path,
    recon: &Path,
    given: Option<Similarity>,
) -> Result<CamerasOutputs> {
    let (gt, est) = read_camera_models(gt_cameras, recon)?;
    let (_, alignment, cameras) =
        pipeline::cameras_only(&gt, &est, given, 0, &PoseOptions::default())
            .with_context(|| format!("cameras of '{}'", recon.display()))?;
    Ok(CamerasOutputs { alignment, cameras })
}

/// `sfmeval poses` on files: the protocol's report on the reconstruction's cameras at `recon`
/// against `gt_cameras`, with the ground-truth model (its image names label the pairs' CSV).
pub fn poses_on_files(
    gt_cameras: &Path,
    recon: &Path,
    protocol: Protocol,
    options: &ProtocolOptions,
) -> Result<(Reconstruction, PosesReport)> {
    let (gt, est) = read_camera_models(gt_cameras, recon)?;
    let poses =
        sfmeval::pose::evaluate_protocol(&gt, &est, protocol, options).with_context(|| {
            format!(
                "poses of '{}' against '{}'",
                recon.display(),
                gt_cameras.display()
            )
        })?;
    Ok((gt, poses))
}
