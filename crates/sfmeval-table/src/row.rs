//! One run's row of the comparison tables: its record, its evaluation's numbers (built by
//! `run::evaluated_row`, read by the tables, the runner's page and sweep, and the web page).

use serde::{Deserialize, Serialize};

pub use crate::poses::RowPoses;

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

/// The DTU protocol's numbers of a run on a DTU scan (`sfmeval.dtu/1`, in mm).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct DtuNumbers {
    /// The scan number.
    pub scan: u32,
    /// Mean accuracy (reconstruction → STL points, observed points, capped), mm.
    pub mean_accuracy: Option<f64>,
    /// Mean completeness (STL points above the plane → reconstruction, capped), mm.
    pub mean_completeness: Option<f64>,
    /// The mean of the two, mm.
    pub overall: Option<f64>,
}

/// One tolerance's numbers of ETH3D's evaluation (`sfmeval.eth3d/1`'s `tolerances[k]`, each
/// `float` as the report writes it).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Eth3dTolerance {
    /// The tolerance, m.
    pub tolerance: f64,
    /// Accuracy (share of the reconstruction's cells within the tolerance), 0..1.
    pub accuracy: f64,
    /// Completeness (share of the scans' cells within the tolerance), 0..1.
    pub completeness: f64,
    /// F1 of the two.
    pub f1: f64,
}

/// ETH3D's numbers of a run on an ETH3D scene, tolerances ascending.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Eth3dNumbers {
    /// Per tolerance.
    pub tolerances: Vec<Eth3dTolerance>,
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
    /// How the reconstruction was aligned before it was measured: the requested mode of its
    /// report (`auto`, `given`, ...) or `tanksandtemples` (the protocol's registration); none
    /// for a run that was not evaluated. Table I's caption names it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alignment: Option<String>,
    /// The DTU protocol's numbers, for a run on a DTU scan (its other distance fields are then
    /// none: the protocol's report has no per-point distances in metres).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dtu: Option<DtuNumbers>,
    /// The pose protocols' numbers (`sfmeval poses`), for a run whose dataset has ground-truth
    /// cameras and whose reconstruction has cameras.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poses: Option<RowPoses>,
    /// ETH3D's numbers, for a run on an ETH3D scene (its other distance fields are then none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eth3d: Option<Eth3dNumbers>,
}
