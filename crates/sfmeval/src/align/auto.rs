//! Chaining the stages: `auto` = `cameras` (when camera pairs are given; `points` when point
//! pairs are given; `global` otherwise), then `icp`. A stage that fails falls back to the next
//! possibility and the fallback stage's note names the failure, so the report never hides it.

use super::global::align_global;
use super::{
    AlignMode, AlignStage, Alignment, CameraPair, CamerasOptions, GlobalOptions, IcpOptions,
    PointPair, align_cameras, align_points, refine_icp,
};
use crate::error::{Error, Result};
use crate::geometry::Point3;
use crate::note::{Code, Note};
use crate::prepared::PreparedGroundTruth;
use crate::transform::Similarity;

/// Most runs of `icp` alone while it looks for its fixed point (`IcpOptions::max_restarts`).
pub(crate) const ICP_ALONE_RUNS: usize = 8;

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

/// The note of a stage of `auto` that failed.
fn stage_failed(stage: &str, error: &Error) -> Note {
    let what = match stage {
        "cameras" => "the camera-based alignment",
        _ => "the point-pair alignment",
    };
    Note::new(Code::StageFailed, format!("{what} failed: {error}"))
        .with("stage", stage)
        .with("error", error.to_string())
}

/// The note of `auto` falling back to `to`.
pub(crate) fn fell_back(to: &str) -> Note {
    let what = match to {
        "global" => "the global shape search (no correspondences)",
        "points" => "the user's point pairs",
        other => other,
    };
    Note::new(Code::FellBack, format!("the alignment fell back to {what}")).with("to", to)
}

/// Runs the chosen alignment (ICP after the first stage when `opts.refine`).
///
/// Errors when an explicitly chosen stage cannot run (for instance `cameras` with fewer than 3
/// usable cameras); `auto` instead falls back and names the failure in the next stage's note.
pub fn align(
    gt: &PreparedGroundTruth,
    input: &AlignInput<'_>,
    method: AlignMethod,
    opts: &AlignOptions,
) -> Result<Alignment> {
    let mut stages: Vec<AlignStage> = Vec::new();
    let mut pending: Vec<Note> = Vec::new();
    let coarse: Option<(Similarity, AlignStage)> = match method {
        AlignMethod::Cameras => Some(align_cameras(input.cameras, &opts.cameras)?),
        AlignMethod::Points => Some(align_points(input.point_pairs)?),
        AlignMethod::Global => Some(align_global(gt, input.recon, &opts.global)?),
        AlignMethod::Icp => None,
        AlignMethod::Auto => {
            let mut found = None;
            if !input.cameras.is_empty() {
                match align_cameras(input.cameras, &opts.cameras) {
                    Ok(r) => found = Some(r),
                    Err(e) => pending.push(stage_failed("cameras", &e)),
                }
            }
            if found.is_none() && !input.point_pairs.is_empty() {
                match align_points(input.point_pairs) {
                    Ok(mut r) => {
                        if !pending.is_empty() {
                            pending.push(fell_back("points"));
                        }
                        r.1.prepend_notes(std::mem::take(&mut pending));
                        found = Some(r);
                    }
                    Err(e) => pending.push(stage_failed("points", &e)),
                }
            }
            if found.is_none() {
                let mut r = align_global(gt, input.recon, &opts.global)?;
                if !pending.is_empty() {
                    pending.push(fell_back("global"));
                }
                r.1.prepend_notes(std::mem::take(&mut pending));
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
                pending.push(
                    Note::new(
                        Code::IcpFromIdentity,
                        "ICP started from the identity (no start transform was given): it converges only when the reconstruction is already close to the ground truth",
                    )
                    .with("stage", "icp"),
                );
            }
            input.start.unwrap_or(Similarity::IDENTITY)
        }
    };
    let run_icp = matches!(method, AlignMethod::Auto | AlignMethod::Icp) || opts.refine;
    if run_icp {
        // ICP alone refines a placement given by hand or by another tool: it runs to its fixed
        // point, so that refining its own answer again leaves it where it is.
        let icp = match method {
            AlignMethod::Icp => IcpOptions {
                max_restarts: opts.icp.max_restarts.max(ICP_ALONE_RUNS),
                ..opts.icp.clone()
            },
            _ => opts.icp.clone(),
        };
        let (t2, mut stage) = refine_icp(gt, input.recon, &t, &icp)?;
        stage.prepend_notes(std::mem::take(&mut pending));
        t = t2;
        stages.push(stage);
    }
    Ok(Alignment {
        gt_from_recon: t,
        stages,
        requested: AlignMode::of_stages(method, opts.refine),
    })
}
