//! The pose protocols of a run (`sfmeval poses --protocol colmap|imc|co3d` through
//! `sfmeval_table::PoseReports`, the core's `evaluate_protocol`): computed for every run whose
//! dataset has ground-truth cameras and whose reconstruction has cameras, their reports written
//! beside the run's report, their numbers in its row.

use std::path::Path;

use anyhow::Result;
use sfmeval::pipeline;
use sfmeval_fs::write_atomic;
use sfmeval_table::PoseReports;

/// The pose protocols' reports of a run (`Ok(None)` when the dataset has no ground-truth
/// cameras or the reconstruction no cameras), or why they could not be computed.
pub type RunPoses = std::result::Result<Option<PoseReports>, String>;

/// The pose protocols of `recon`'s cameras against the dataset's `gt_cameras` (the core's
/// `sfmeval poses`, every protocol with its default options).
pub fn run_poses(
    gt_cameras: Option<&sfmeval::model::Reconstruction>,
    recon: &pipeline::ReconInput,
) -> RunPoses {
    match (gt_cameras, &recon.model) {
        (Some(gt), Some(est)) => PoseReports::evaluate(gt, est)
            .map(Some)
            .map_err(|e| format!("{}: pose protocols: {e}", recon.name)),
        _ => Ok(None),
    }
}

/// Writes a run's pose-protocol reports beside its report `rel` (under `out`), each what
/// `sfmeval poses --protocol P --json` prints, and returns the row's numbers; a run whose
/// poses could not be computed gets none and a line on stderr saying why.
pub fn write_poses(
    out: &Path,
    rel: &str,
    poses: RunPoses,
) -> Result<Option<sfmeval_table::RowPoses>> {
    match poses {
        Ok(Some(p)) => {
            for (file, text) in p.files(rel)? {
                write_atomic(&out.join(file), text.as_bytes())?;
            }
            Ok(p.row_poses())
        }
        Ok(None) => Ok(None),
        Err(why) => {
            eprintln!("{why}");
            Ok(None)
        }
    }
}
