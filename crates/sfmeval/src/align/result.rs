//! What an alignment found, as its own types (as Open3D's registration returns a
//! `RegistrationResult`): the transform, and per stage what it did and what it noted. The
//! report's `alignment` section is built from these once, by [`Alignment::report`].

use super::AlignMode;
use crate::note::Note;
use crate::report::{AlignmentReport, AlignmentStage};
use crate::transform::Similarity;

/// The kind of an alignment stage (the report's `alignment.stages[].method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageKind {
    /// A transform given by the user.
    Given,
    /// Matched camera centres (LO-RANSAC).
    Cameras,
    /// User point pairs.
    Points,
    /// The shape-only multi-start search.
    Global,
    /// Trimmed, scaled ICP against the ground-truth surface.
    Icp,
}

impl StageKind {
    /// The name in the report.
    pub fn name(self) -> &'static str {
        match self {
            StageKind::Given => "given",
            StageKind::Cameras => "cameras",
            StageKind::Points => "points",
            StageKind::Global => "global",
            StageKind::Icp => "icp",
        }
    }
}

/// One stage's result.
#[derive(Debug, Clone, PartialEq)]
pub struct AlignStage {
    /// Which stage.
    pub kind: StageKind,
    /// The transform after this stage.
    pub gt_from_recon: Similarity,
    /// Root mean square residual of the stage's correspondences.
    pub rmse: Option<f64>,
    /// Share of correspondences kept as inliers.
    pub inlier_ratio: Option<f64>,
    /// Iterations run.
    pub iterations: u64,
    /// Whether the stage met its stopping criterion.
    pub converged: bool,
    /// Why the stage was rejected or what it fell back to, if anything (the report lists them
    /// in its `notes`).
    pub notes: Vec<Note>,
}

impl AlignStage {
    /// The stage's entry in the report.
    fn report(&self) -> AlignmentStage {
        AlignmentStage {
            method: self.kind.name().into(),
            gt_from_recon: self.gt_from_recon.matrix,
            scale: self.gt_from_recon.scale(),
            rmse: self.rmse,
            inlier_ratio: self.inlier_ratio,
            iterations: self.iterations,
            converged: self.converged,
        }
    }

    /// Puts `notes` (what happened before the stage ran) before the stage's own notes.
    pub(crate) fn prepend_notes(&mut self, mut notes: Vec<Note>) {
        if !notes.is_empty() {
            notes.append(&mut self.notes);
            self.notes = notes;
        }
    }
}

/// An alignment: the transform and the stages that found it.
#[derive(Debug, Clone, PartialEq)]
pub struct Alignment {
    /// Maps the reconstruction into the ground-truth frame.
    pub gt_from_recon: Similarity,
    /// The stages in the order they ran (none for `none`).
    pub stages: Vec<AlignStage>,
    /// The mode that was asked for (the report's `options.align`).
    pub requested: AlignMode,
}

impl Alignment {
    /// No alignment: the reconstruction is already in the ground-truth frame.
    pub fn none() -> Self {
        Alignment {
            gt_from_recon: Similarity::IDENTITY,
            stages: Vec::new(),
            requested: AlignMode::None,
        }
    }

    /// A transform given by the user.
    pub fn given(t: Similarity) -> Self {
        Alignment {
            gt_from_recon: t,
            stages: vec![AlignStage {
                kind: StageKind::Given,
                gt_from_recon: t,
                rmse: None,
                inlier_ratio: None,
                iterations: 0,
                converged: true,
                notes: Vec::new(),
            }],
            requested: AlignMode::Given,
        }
    }

    /// The stage of this kind, if one ran.
    pub fn stage(&self, kind: StageKind) -> Option<&AlignStage> {
        self.stages.iter().find(|s| s.kind == kind)
    }

    /// `none`, or the stages' names joined by `+` (`cameras+icp`).
    pub fn method(&self) -> String {
        if self.stages.is_empty() {
            return "none".into();
        }
        let names: Vec<&str> = self.stages.iter().map(|s| s.kind.name()).collect();
        names.join("+")
    }

    /// The notes of every stage, in stage order.
    pub fn notes(&self) -> impl Iterator<Item = &Note> {
        self.stages.iter().flat_map(|s| &s.notes)
    }

    /// The report's `alignment` section.
    pub fn report(&self) -> AlignmentReport {
        let last = self.stages.last();
        AlignmentReport {
            method: self.method(),
            gt_from_recon: self.gt_from_recon.matrix,
            scale: self.gt_from_recon.scale(),
            rmse: last.and_then(|s| s.rmse),
            inlier_ratio: last.and_then(|s| s.inlier_ratio),
            iterations: self.stages.iter().map(|s| s.iterations).sum(),
            converged: self.stages.iter().all(|s| s.converged),
            stages: self.stages.iter().map(AlignStage::report).collect(),
        }
    }
}
