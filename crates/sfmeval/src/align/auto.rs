//! Chaining the stages: `auto` = `cameras` (when camera pairs are given; `points` when point
//! pairs are given; `global` otherwise), then `icp`. A stage that fails falls back to the next
//! possibility and the fallback stage's note names the failure, so the report never hides it.

use super::global::align_global;
use super::{
    CameraPair, CamerasOptions, GlobalOptions, IcpOptions, PointPair, align_cameras, align_points,
    refine_icp,
};
use crate::error::{Error, Result};
use crate::geometry::Point3;
use crate::prepared::PreparedGroundTruth;
use crate::report::{AlignmentReport, AlignmentStage};
use crate::transform::Similarity;

/// Which alignment to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlignMethod {
    /// `cameras` if camera pairs are given, else `points` if point pairs are given, else
    /// `global`; then `icp`.
    Auto,
    /// Camera centres (and orientations when needed); then `icp` if `refine`.
    Cameras,
    /// User point pairs; then `icp` if `refine`.
    Points,
    /// Shape-only search; then `icp` if `refine`.
    Global,
    /// ICP alone from the given start (the identity when none).
    Icp,
}

impl AlignMethod {
    /// Parses `auto`, `cameras`, `points`, `global`, `icp`.
    pub fn parse(s: &str) -> Result<Self> {
        Ok(match s {
            "auto" => AlignMethod::Auto,
            "cameras" => AlignMethod::Cameras,
            "points" => AlignMethod::Points,
            "global" => AlignMethod::Global,
            "icp" => AlignMethod::Icp,
            other => {
                return Err(Error::InvalidOption(format!(
                    "unknown alignment '{other}' (expected auto, cameras, points, global or icp)"
                )));
            }
        })
    }

    /// The name as parsed.
    pub fn name(self) -> &'static str {
        match self {
            AlignMethod::Auto => "auto",
            AlignMethod::Cameras => "cameras",
            AlignMethod::Points => "points",
            AlignMethod::Global => "global",
            AlignMethod::Icp => "icp",
        }
    }
}

/// What the alignment works from.
#[derive(Debug, Clone, Copy, Default)]
pub struct AlignInput<'a> {
    /// The reconstruction's points, in its own frame.
    pub recon: &'a [Point3],
    /// Matched cameras (may be empty).
    pub cameras: &'a [CameraPair],
    /// User point pairs (may be empty).
    pub point_pairs: &'a [PointPair],
    /// Start for `icp` alone (identity when `None`).
    pub start: Option<Similarity>,
}

/// Options of every stage.
#[derive(Debug, Clone, PartialEq)]
pub struct AlignOptions {
    /// `cameras` stage.
    pub cameras: CamerasOptions,
    /// `global` stage.
    pub global: GlobalOptions,
    /// `icp` stage.
    pub icp: IcpOptions,
    /// Run `icp` after `cameras`, `points` or `global` (always on for `auto`).
    pub refine: bool,
}

impl Default for AlignOptions {
    fn default() -> Self {
        AlignOptions {
            cameras: CamerasOptions::default(),
            global: GlobalOptions::default(),
            icp: IcpOptions::default(),
            refine: true,
        }
    }
}

impl AlignOptions {
    /// The same seed for every stage.
    pub(crate) fn with_seed(mut self, seed: u64) -> Self {
        self.cameras.seed = seed;
        self.global.seed = seed;
        self.icp.seed = seed;
        self
    }
}

fn add_note(stage: &mut AlignmentStage, note: Option<String>) {
    if let Some(n) = note {
        stage.note = Some(match stage.note.take() {
            Some(old) => format!("{n}; {old}"),
            None => n,
        });
    }
}

/// Runs the chosen alignment; returns `gt_from_recon` and the report's `alignment` section.
///
/// Errors when an explicitly chosen stage cannot run (for instance `cameras` with fewer than 3
/// usable cameras); `auto` instead falls back and names the failure in the next stage's note.
pub fn align(
    gt: &PreparedGroundTruth,
    input: &AlignInput<'_>,
    method: AlignMethod,
    opts: &AlignOptions,
) -> Result<(Similarity, AlignmentReport)> {
    let mut stages: Vec<AlignmentStage> = Vec::new();
    let mut pending: Option<String> = None;
    let coarse: Option<(Similarity, AlignmentStage)> = match method {
        AlignMethod::Cameras => Some(align_cameras(input.cameras, &opts.cameras)?),
        AlignMethod::Points => Some(align_points(input.point_pairs)?),
        AlignMethod::Global => Some(align_global(gt, input.recon, &opts.global)?),
        AlignMethod::Icp => None,
        AlignMethod::Auto => {
            let mut found = None;
            if !input.cameras.is_empty() {
                match align_cameras(input.cameras, &opts.cameras) {
                    Ok(r) => found = Some(r),
                    Err(e) => pending = Some(format!("cameras stage failed ({e})")),
                }
            }
            if found.is_none() && !input.point_pairs.is_empty() {
                match align_points(input.point_pairs) {
                    Ok(mut r) => {
                        add_note(
                            &mut r.1,
                            pending.take().map(|p| format!("{p}; fell back to points")),
                        );
                        found = Some(r);
                    }
                    Err(e) => {
                        let p = pending.take().map_or(String::new(), |p| format!("{p}; "));
                        pending = Some(format!("{p}points stage failed ({e})"));
                    }
                }
            }
            if found.is_none() {
                let mut r = align_global(gt, input.recon, &opts.global)?;
                add_note(
                    &mut r.1,
                    pending.take().map(|p| format!("{p}; fell back to global")),
                );
                found = Some(r);
            }
            found
        }
    };
    let mut t = match coarse {
        Some((t, stage)) => {
            stages.push(stage);
            t
        }
        None => {
            if input.start.is_none() {
                pending = Some("ICP started from the identity (no start transform given)".into());
            }
            input.start.unwrap_or(Similarity::IDENTITY)
        }
    };
    let run_icp = matches!(method, AlignMethod::Auto | AlignMethod::Icp) || opts.refine;
    if run_icp {
        let (t2, mut stage) = refine_icp(gt, input.recon, &t, &opts.icp)?;
        add_note(&mut stage, pending.take());
        t = t2;
        stages.push(stage);
    }
    let last = stages.last();
    let report = AlignmentReport {
        method: stages
            .iter()
            .map(|s| s.method.as_str())
            .collect::<Vec<_>>()
            .join("+"),
        gt_from_recon: t.matrix,
        scale: t.scale(),
        rmse: last.and_then(|s| s.rmse),
        inlier_ratio: last.and_then(|s| s.inlier_ratio),
        iterations: stages.iter().map(|s| s.iterations).sum(),
        converged: stages.iter().all(|s| s.converged),
        stages,
    };
    Ok((t, report))
}

/// The stage notes of an alignment report as warning lines (`"alignment (icp): ..."`), for the
/// report's `warnings`.
pub(crate) fn stage_notes(report: &AlignmentReport) -> Vec<String> {
    report
        .stages
        .iter()
        .filter_map(|s| {
            s.note
                .as_ref()
                .map(|n| format!("alignment ({}): {n}", s.method))
        })
        .collect()
}
