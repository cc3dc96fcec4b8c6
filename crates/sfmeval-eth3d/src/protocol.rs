//! One evaluation as the tool's `main` runs it: the tolerances sorted, completeness, accuracy,
//! and F1 per tolerance, all in `float`.

use sfmeval::{Error, Result};

use crate::accuracy::{Beam, SphericalGrid, classify_points};
use crate::scene::Eth3dScene;
use crate::{completeness, voxel};

/// The tool's default voxel size (m).
pub const VOXEL_SIZE: f32 = 0.01;
/// The tool's default beam radius at the scanner (m).
pub const BEAM_START_RADIUS: f32 = 0.5 * 0.00225;
/// The tool's default beam divergence half-angle (degrees).
pub const BEAM_DIVERGENCE_HALFANGLE_DEG: f32 = 0.011;
/// The tolerances the ETH3D benchmark reports (m): the tool has no default, its README's example
/// and the benchmark's tables use these.
pub const DEFAULT_TOLERANCES: [f32; 6] = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5];

/// The tool's parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Eth3dOptions {
    /// Evaluation tolerances (m), in any order (the tool sorts them; duplicates are kept).
    pub tolerances: Vec<f32>,
    /// Voxel size of the normalisation (m).
    pub voxel_size: f32,
    /// Beam radius at the scanner (m).
    pub beam_start_radius: f32,
    /// Beam divergence half-angle (degrees).
    pub beam_divergence_halfangle_deg: f32,
}

impl Default for Eth3dOptions {
    fn default() -> Self {
        Eth3dOptions {
            tolerances: DEFAULT_TOLERANCES.to_vec(),
            voxel_size: VOXEL_SIZE,
            beam_start_radius: BEAM_START_RADIUS,
            beam_divergence_halfangle_deg: BEAM_DIVERGENCE_HALFANGLE_DEG,
        }
    }
}

impl Eth3dOptions {
    fn validate(&self) -> Result<()> {
        if self.tolerances.is_empty() {
            return Err(Error::InvalidOption(
                "at least one tolerance is needed".into(),
            ));
        }
        if let Some(t) = self
            .tolerances
            .iter()
            .find(|t| !(t.is_finite() && **t >= 0.0))
        {
            return Err(Error::InvalidOption(format!(
                "tolerance {t} is not a finite non-negative length"
            )));
        }
        if !(self.voxel_size.is_finite() && self.voxel_size > 0.0) {
            return Err(Error::InvalidOption(format!(
                "the voxel size must be positive, not {}",
                self.voxel_size
            )));
        }
        for (name, v) in [
            ("beam start radius", self.beam_start_radius),
            (
                "beam divergence half-angle",
                self.beam_divergence_halfangle_deg,
            ),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidOption(format!(
                    "the {name} must be finite and non-negative, not {v}"
                )));
            }
        }
        Ok(())
    }
}

/// Everything one evaluation computed.
#[derive(Debug, Clone)]
pub struct Eth3dEvaluation {
    /// The options, tolerances as given.
    pub options: Eth3dOptions,
    /// The tolerances sorted (the order of every per-tolerance vector below).
    pub tolerances: Vec<f32>,
    /// Accuracy per tolerance (the tool's, in `float`).
    pub accuracy: Vec<f32>,
    /// Completeness per tolerance.
    pub completeness: Vec<f32>,
    /// F1 per tolerance.
    pub f1: Vec<f32>,
    /// Per reconstruction point, the first tolerance index at which it is accurate
    /// (`tolerances.len()` for none).
    pub first_accurate: Vec<u32>,
    /// Per reconstruction point, whether it is inaccurate below that index (else unobserved).
    pub inaccurate: Vec<bool>,
    /// The scan points in the global frame, scans in the project's order.
    pub scan_points: Vec<[f32; 3]>,
    /// Per scan point, the first tolerance index at which it is complete.
    pub first_complete: Vec<u32>,
    /// Per tolerance, the voxel cells (of both grids) with an accurate or inaccurate point.
    pub accuracy_cells: Vec<usize>,
    /// The voxel cells (of both grids) holding scan points.
    pub completeness_cells: usize,
}

/// The tool's F1 of one tolerance: `2pr / (p + r)` in `float`, 0 when both are 0.
pub fn f1_score(precision: f32, recall: f32) -> f32 {
    if precision <= 0.0 && recall <= 0.0 {
        0.0
    } else {
        2.0 * (precision * recall) / (precision + recall)
    }
}

/// Evaluates `reconstruction` (global frame, `float` as the tool reads it) on `scene`.
pub fn evaluate(
    scene: &Eth3dScene,
    reconstruction: &[[f32; 3]],
    options: &Eth3dOptions,
) -> Result<Eth3dEvaluation> {
    options.validate()?;
    let mut tolerances = options.tolerances.clone();
    tolerances.sort_by(f32::total_cmp);
    let tolerances2: Vec<f32> = tolerances.iter().map(|t| t * t).collect();
    let n = tolerances.len();
    let inv = voxel::voxel_size_inv(options.voxel_size);

    let scan_points = scene.global_points();
    let first_complete = completeness::first_complete(&scan_points, reconstruction, &tolerances2)?;
    let (completeness, completeness_cells) =
        voxel::completeness(&scan_points, &first_complete, n, inv);
    let completeness = if reconstruction.is_empty() {
        // The tool's special case: no k-d tree, every completeness 0.
        vec![0.0; n]
    } else {
        completeness
    };

    let deg_to_rad = (std::f64::consts::PI / 180.0) as f32;
    let beam = Beam {
        start_radius: options.beam_start_radius,
        tan_divergence: libm::tanf(deg_to_rad * options.beam_divergence_halfangle_deg),
    };
    // (the scans at once: each grid's counting sort is serial)
    let grids: Vec<SphericalGrid> = sfmeval::parallel::map_range(scene.scans.len(), |s| {
        SphericalGrid::new(&scene.scans[s].points)
    });
    let classes = classify_points(scene, &grids, reconstruction, &tolerances2, &beam);
    drop(grids);
    let first_accurate: Vec<u32> = classes.iter().map(|c| c.first_accurate).collect();
    let inaccurate: Vec<bool> = classes.iter().map(|c| c.inaccurate).collect();
    let (accuracy, accuracy_cells) =
        voxel::accuracy(reconstruction, &first_accurate, &inaccurate, n, inv);
    let f1 = accuracy
        .iter()
        .zip(&completeness)
        .map(|(&p, &r)| f1_score(p, r))
        .collect();
    Ok(Eth3dEvaluation {
        options: options.clone(),
        tolerances,
        accuracy,
        completeness,
        f1,
        first_accurate,
        inaccurate,
        scan_points,
        first_complete,
        accuracy_cells,
        completeness_cells,
    })
}
