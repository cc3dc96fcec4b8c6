//! Progress reporting hooks. The core never prints; front ends implement [`Progress`] to show
//! bars (CLI) or post messages (the browser worker).

/// The long steps of an evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Building the BVH or k-d tree of the ground truth.
    IndexGroundTruth,
    /// Reconstruction → ground-truth distances.
    Accuracy,
    /// Sampling the ground-truth surface.
    Sampling,
    /// Building the k-d tree of the reconstruction.
    IndexReconstruction,
    /// Ground-truth samples → reconstruction distances.
    Completeness,
    /// Aligning the reconstruction.
    Alignment,
    /// Counting the ground-truth images that see each surface sample.
    Visibility,
    /// Back-projecting the tracks of the reconstructed points.
    TrackError,
}

impl Stage {
    /// A short human name.
    pub fn label(self) -> &'static str {
        match self {
            Stage::IndexGroundTruth => "indexing ground truth",
            Stage::Accuracy => "accuracy (recon → GT)",
            Stage::Sampling => "sampling GT surface",
            Stage::IndexReconstruction => "indexing reconstruction",
            Stage::Completeness => "completeness (GT → recon)",
            Stage::Alignment => "aligning",
            Stage::Visibility => "visibility (depth maps)",
            Stage::TrackError => "track error (depth maps)",
        }
    }
}

/// Receives progress; must be shareable across worker threads.
pub trait Progress: Sync {
    /// A stage starts with `total` units of work.
    fn start(&self, stage: Stage, total: u64);
    /// `n` more units are done.
    fn advance(&self, n: u64);
    /// The current stage is finished.
    fn finish(&self);
}

/// Ignores all progress.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _: Stage, _: u64) {}
    fn advance(&self, _: u64) {}
    fn finish(&self) {}
}
