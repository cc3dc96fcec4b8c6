//! The evaluation pipeline: transform → distances to the ground truth → crop → statistics,
//! completeness from seeded surface samples, precision/recall/F per threshold, the report.

use serde::{Deserialize, Serialize};

use crate::align::Alignment;
use crate::crop::Crop;
use crate::distance::slot_tree::{SlotTree, kd_order};
use crate::error::{Error, Result};
use crate::geometry::{Point3, Positions, permute_in_place};
use crate::metrics::{Thresholds, f_score, share_below};
use crate::note::{Code, Note};
use crate::parallel;
use crate::prepared::PreparedGroundTruth;
use crate::progress::{Progress, Stage};
use crate::report::*;
use crate::stats::{DEFAULT_BINS, Statistics};
use crate::transform::Similarity;

/// Default number of completeness samples on a ground-truth mesh. The recall at any tau is a
/// binomial share, so its sampling standard error is at most 0.5/√n: 1M samples keep it below
/// 0.05 percentage points, and the mean completeness distance varies by well under 0.1 % between
/// seeds, while sampling and querying 1M points stays well under a second natively.
pub const DEFAULT_SAMPLES: usize = 1_000_000;

/// Options of an evaluation. Every field changes numbers and is echoed in the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EvalOptions {
    /// Thresholds in ground-truth units.
    pub tau: Vec<f64>,
    /// Thresholds in percent of the ground-truth bounding-box diagonal.
    pub tau_percent_of_diagonal: Vec<f64>,
    /// Completeness samples on a mesh ground truth.
    pub samples: usize,
    /// Seed of the surface sampler.
    pub seed: u64,
    /// Also compute distances signed by the closest triangle's normal.
    pub signed: bool,
    /// Histogram bins.
    pub histogram_bins: usize,
    /// The crop, applied in the ground-truth frame after the transform.
    pub crop: Crop,
    /// Images a surface sample must be seen in to count as visible (used with depth maps).
    pub min_views: u32,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions {
            tau: Vec::new(),
            tau_percent_of_diagonal: Vec::new(),
            samples: DEFAULT_SAMPLES,
            seed: 0,
            signed: false,
            histogram_bins: DEFAULT_BINS,
            crop: Crop::default(),
            min_views: crate::visibility::DEFAULT_MIN_VIEWS,
        }
    }
}

impl EvalOptions {
    /// The thresholds in ground-truth units for a ground truth of this diagonal.
    pub fn thresholds(&self, diagonal: f64) -> Thresholds {
        Thresholds::resolve(&self.tau, &self.tau_percent_of_diagonal, diagonal)
    }

    /// Checks ranges.
    pub fn validate(&self) -> Result<()> {
        self.crop.validate()?;
        if let Some(t) = self
            .tau
            .iter()
            .chain(&self.tau_percent_of_diagonal)
            .find(|t| !(t.is_finite() && **t > 0.0))
        {
            return Err(Error::InvalidOption(format!(
                "thresholds must be > 0, got {t}"
            )));
        }
        if self.samples == 0 {
            return Err(Error::InvalidOption("samples must be ≥ 1".into()));
        }
        if self.samples > 100_000_000 {
            return Err(Error::InvalidOption("samples must be ≤ 100000000".into()));
        }
        if self.min_views == 0 {
            return Err(Error::InvalidOption("min views must be ≥ 1".into()));
        }
        if self.histogram_bins == 0 || self.histogram_bins > 100_000 {
            return Err(Error::InvalidOption(
                "histogram bins must be in 1..=100000".into(),
            ));
        }
        Ok(())
    }
}

/// Names and formats of the inputs, for the report.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InputInfo {
    /// Reconstruction file name.
    pub recon_name: String,
    /// Reconstruction format (`ply`, `colmap`, ...).
    pub recon_format: String,
    /// Registered images of the reconstruction.
    pub recon_images: u64,
    /// Ground-truth file name.
    pub gt_name: String,
    /// Ground-truth format.
    pub gt_format: String,
    /// Notes from reading and aligning.
    pub notes: Vec<Note>,
}

/// Why a reconstructed point was discarded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[repr(u8)]
pub enum PointStatus {
    /// Kept and measured.
    Kept = 0,
    /// Outside the crop volume.
    OutsideVolume = 1,
    /// Farther than the crop's max distance.
    TooFar = 2,
}

/// An evaluation: the report plus per-point data for exports and the viewer.
///
/// The reconstructed points are kept once, as read (`f32` where the file stored `f32`), in the
/// storage order of the k-d tree the completeness queries used; [`Evaluation::points_in_gt`]
/// maps them into the ground-truth frame on demand. Per-point arrays are in input order.
pub struct Evaluation {
    /// The report.
    pub report: Report,
    /// The reconstruction's points in its own frame, slot `k` holding input point
    /// `slot_input[k]`.
    recon: Positions,
    slot_input: Vec<u32>,
    /// The transform the points were measured in.
    pub gt_from_recon: Similarity,
    /// Unsigned distance of every point to the ground truth.
    pub distances: Vec<f64>,
    /// Signed distances, when asked for.
    pub signed_distances: Option<Vec<f64>>,
    /// Kept or why discarded, per point.
    pub status: Vec<PointStatus>,
    /// Completeness samples used (inside the volume), in the ground-truth frame.
    pub completeness_points: Vec<Point3>,
    /// Their distances to the reconstruction.
    pub completeness_distances: Vec<f64>,
    /// The thresholds the report's P/R/F were computed at, resolved once.
    pub thresholds: Thresholds,
    /// Per completeness sample, the ground-truth images that see it (with depth maps only).
    pub sample_views: Option<Vec<u32>>,
    /// Per completeness sample, covered / missed / unseen at the report's `labels_tau` (with
    /// depth maps only).
    pub sample_labels: Option<Vec<crate::visibility::SampleLabel>>,
    /// Per reconstructed point (input order), its track-based true error; `None` when not
    /// measured (with depth maps and tracks only).
    pub track_errors: Option<Vec<Option<f64>>>,
}

impl Evaluation {
    /// Number of reconstructed points.
    pub fn point_count(&self) -> usize {
        self.recon.len()
    }

    /// Every reconstructed point in the ground-truth frame, in input order (a new vector of
    /// 24 bytes a point; exports use `Evaluation::for_each_point_in_gt`).
    pub fn points_in_gt(&self) -> Vec<Point3> {
        let t = self.gt_from_recon;
        let slot_of = self.slot_of_input();
        parallel::map_range(slot_of.len(), |i| {
            t.apply(self.recon.get(slot_of[i] as usize))
        })
    }

    /// The kept points' distances, ascending (NaN last): what curves of precision against τ
    /// read (the page sorts them here, in the core's threads, not on its UI thread).
    pub fn sorted_kept_distances(&self) -> Vec<f64> {
        let mut kept: Vec<f64> = self
            .distances
            .iter()
            .zip(&self.status)
            .filter(|(_, s)| **s == PointStatus::Kept)
            .map(|(&d, _)| d)
            .collect();
        parallel::sort_floats(&mut kept);
        kept
    }

    /// The completeness distances, ascending (NaN last, for a sample the search found no
    /// point for).
    pub fn sorted_completeness_distances(&self) -> Vec<f64> {
        let mut d = self.completeness_distances.clone();
        parallel::sort_floats(&mut d);
        d
    }

    /// The inverse of `slot_input`: the slot of every input point.
    fn slot_of_input(&self) -> Vec<u32> {
        let mut slot_of = vec![0u32; self.slot_input.len()];
        for (k, &i) in self.slot_input.iter().enumerate() {
            slot_of[i as usize] = k as u32;
        }
        slot_of
    }

    /// Calls `f(index, point in the ground-truth frame)` for every reconstructed point in input
    /// order (4 bytes a point of extra memory).
    pub(crate) fn for_each_point_in_gt(&self, mut f: impl FnMut(usize, Point3)) {
        let t = self.gt_from_recon;
        let slot_of = self.slot_of_input();
        for (i, &k) in slot_of.iter().enumerate() {
            f(i, t.apply(self.recon.get(k as usize)));
        }
    }
}

/// Reorders the points so that new slot `k` holds old point `order[k]` (`order` is a
/// permutation of `0..len`). `f32` points are gathered into new storage in parallel: their 12
/// bytes a point stay below the 16 a point `kd_order` held just before, so the peak does not
/// move. `f64` points are reordered in place (one bit a point of extra memory), as their copy
/// would raise it.
fn into_tree_order(points: &mut Positions, order: &[u32]) {
    match points {
        Positions::F64(v) => permute_in_place(v, order),
        Positions::F32(v) => *v = parallel::map_range(order.len(), |k| v[order[k] as usize]),
    }
}

/// The distance from each of `samples` to the nearest live point of `tree`, `point(k)` giving
/// slot `k` in the samples' frame; NaN where the search finds none (a sample not finite).
fn nearest_kept(
    tree: &SlotTree,
    samples: &[Point3],
    point: impl Fn(usize) -> Point3 + Sync,
    live: impl Fn(usize) -> bool + Sync,
    progress: &dyn Progress,
) -> Vec<f64> {
    parallel::map_points(samples, progress, |&p| {
        tree.nearest(p, &point, &live)
            .map_or(f64::NAN, |(d2, _)| d2.sqrt())
    })
}

/// Slots per block of accuracy queries: results are scattered into input order a block at a
/// time, so the queries hold no per-point buffer beyond the outputs.
const BLOCK: usize = 1 << 20;

/// Runs the evaluation of the reconstruction's points `recon` (its own frame; kept, reordered,
/// in the [`Evaluation`]) against a prepared ground truth, and builds its report.
///
/// Memory, `n` points: the points as read (12 bytes a point in `f32`, 24 in `f64`), their input
/// indices in tree order (4), the distances (8; 8 more signed), the status (1), the live mask
/// (1/8) and the tree boxes (about 2), plus 16 bytes a point while the tree order is computed
/// (the statistics select their percentiles without a copy).
pub fn evaluate(
    gt: &PreparedGroundTruth,
    recon: Positions,
    alignment: &Alignment,
    options: &EvalOptions,
    info: &InputInfo,
    progress: &dyn Progress,
) -> Result<Evaluation> {
    let measured = measure(gt, recon, alignment.gt_from_recon, options, progress)?;
    Ok(measured.into_evaluation(gt, options, info, alignment, Extras::default()))
}

/// What [`measure`] found: the per-point data and the report sections they give, before the
/// report is built.
pub(crate) struct Measured {
    recon: Positions,
    slot_input: Vec<u32>,
    gt_from_recon: Similarity,
    pub(crate) distances: Vec<f64>,
    signed_distances: Option<Vec<f64>>,
    pub(crate) status: Vec<PointStatus>,
    pub(crate) completeness_points: Vec<Point3>,
    pub(crate) completeness_distances: Vec<f64>,
    /// The thresholds, resolved once: every score of the report is taken at these.
    pub(crate) thresholds: Thresholds,
    /// Precision, recall and F-score at each of `thresholds`.
    pub(crate) scores: Vec<ThresholdReport>,
    crop: CropReport,
    accuracy: AccuracyReport,
    completeness: CompletenessReport,
    notes: Vec<Note>,
}

/// What the pipeline measured beyond the points' distances (cameras, visibility, track error),
/// with the notes in the order they were found.
#[derive(Default)]
pub(crate) struct Extras {
    pub(crate) cameras: Option<CamerasSection>,
    pub(crate) completeness_visible: Option<VisibleCompletenessReport>,
    pub(crate) min_views: Option<u64>,
    pub(crate) track_error: Option<TrackErrorReport>,
    pub(crate) notes: Vec<Note>,
    pub(crate) sample_views: Option<Vec<u32>>,
    pub(crate) sample_labels: Option<Vec<crate::visibility::SampleLabel>>,
    pub(crate) track_errors: Option<Vec<Option<f64>>>,
}

/// Distances, crop, completeness and scores of the reconstruction's points `recon` (its own
/// frame) mapped by `t` into the ground-truth frame.
pub(crate) fn measure(
    gt: &PreparedGroundTruth,
    mut recon: Positions,
    t: Similarity,
    options: &EvalOptions,
    progress: &dyn Progress,
) -> Result<Measured> {
    options.validate()?;
    if options.samples != gt.requested_samples && gt.is_mesh() {
        return Err(Error::InvalidOption(format!(
            "the ground truth was prepared with {} samples but the options ask for {}",
            gt.requested_samples, options.samples
        )));
    }
    if recon.is_empty() {
        return Err(Error::Empty {
            what: "reconstruction (no points)".into(),
        });
    }
    let n = recon.len();
    let mut notes = Vec::new();
    crate::geometry::check_finite_with("aligned reconstruction", "point", n, |i| {
        t.apply(recon.get(i))
    })?;

    // The storage in k-d tree order: the completeness index, and the visiting order of the
    // accuracy queries (neighbours in space one after the other keep the BVH in cache).
    let slot_input = kd_order(n, |i| t.apply(recon.get(i)));
    into_tree_order(&mut recon, &slot_input);
    // The identity (no alignment, or a given one that is) leaves every coordinate as it is
    // (1·x plus zeros is x, up to the sign of a zero, which no distance sees): skipped, as the
    // completeness searches read each point many times.
    let identity = t == Similarity::IDENTITY;
    let in_gt = |k: usize| {
        if identity {
            recon.get(k)
        } else {
            t.apply(recon.get(k))
        }
    };

    let (distances, signed_distances) =
        accuracy_distances(gt, &slot_input, options.signed, &in_gt, progress);
    if options.signed && !gt.is_mesh() {
        notes.push(Note::new(
            Code::SignedNeedsMesh,
            "signed distances need a mesh ground truth; reported unsigned only",
        ));
    }

    let crop = &options.crop;
    let (status, live) = crop_status(crop, &distances, &slot_input, &in_gt);
    let is_live = |k: usize| live[k / 64] >> (k % 64) & 1 == 1;
    let count = |s: PointStatus| status.iter().filter(|&&x| x == s).count() as u64;
    let (kept_n, outside, too_far) = (
        count(PointStatus::Kept),
        count(PointStatus::OutsideVolume),
        count(PointStatus::TooFar),
    );
    if kept_n == 0 {
        notes.push(Note::new(
            Code::CropDiscardedEverything,
            "the crop discarded every reconstructed point",
        ));
    }

    // The ground truth's own samples while the searches run (no copy without a crop volume:
    // 24 bytes a sample at the phase of an evaluation's peak memory); the evaluation keeps a
    // copy afterwards, once the searches' buffers are gone.
    let completeness_points: std::borrow::Cow<'_, [Point3]> = if crop.volume.is_none() {
        std::borrow::Cow::Borrowed(gt.samples())
    } else {
        gt.samples()
            .iter()
            .copied()
            .filter(|&p| crop.in_volume(p))
            .collect()
    };
    let completeness_distances: Vec<f64> = if kept_n == 0 {
        vec![f64::INFINITY; completeness_points.len()]
    } else {
        progress.start(Stage::IndexReconstruction, 1);
        let tree = SlotTree::new(n, in_gt, is_live);
        progress.finish();
        progress.start(Stage::Completeness, completeness_points.len() as u64);
        // A plain read of the storage where no transform applies: the leaf scans inline it
        // (0.8-0.9x the time of the searches through `in_gt`, one thread, 1M samples).
        let samples = &completeness_points;
        let d = match (&recon, identity) {
            (Positions::F32(v), true) => {
                nearest_kept(&tree, samples, |k| v[k].map(f64::from), is_live, progress)
            }
            (Positions::F64(v), true) => nearest_kept(&tree, samples, |k| v[k], is_live, progress),
            _ => nearest_kept(&tree, samples, in_gt, is_live, progress),
        };
        progress.finish();
        d
    };
    if completeness_points.is_empty() {
        notes.push(Note::new(
            Code::NoGroundTruthInCrop,
            "no ground-truth sample lies inside the crop volume",
        ));
    }

    let thresholds = options.thresholds(gt.aabb.diagonal());
    let is_kept = |i: usize| status[i] == PointStatus::Kept;
    let scores = thresholds
        .taus
        .iter()
        .map(|&tau| {
            // share_below over the kept distances, without a copy of them.
            let precision = if kept_n == 0 {
                0.0
            } else {
                let below = (0..n).filter(|&i| is_kept(i) && distances[i] < tau).count();
                below as f64 / kept_n as f64
            };
            let recall = share_below(&completeness_distances, tau);
            ThresholdReport {
                tau,
                tau_percent_of_diagonal: thresholds.percent_of_diagonal(tau),
                precision,
                recall,
                f_score: f_score(precision, recall),
            }
        })
        .collect();

    let bins = options.histogram_bins;
    let accuracy = AccuracyReport {
        direction: "reconstruction_to_ground_truth".into(),
        metric: if gt.is_mesh() {
            "point_to_triangle"
        } else {
            "point_to_point"
        }
        .into(),
        stats: Statistics::of_kept(&distances, is_kept, bins),
        signed: signed_distances
            .as_ref()
            .map(|s| Statistics::of_kept(s, is_kept, bins)),
    };
    let completeness = CompletenessReport {
        direction: "ground_truth_to_reconstruction".into(),
        source: if gt.is_mesh() {
            "surface_samples"
        } else {
            "ground_truth_points"
        }
        .into(),
        samples: completeness_points.len() as u64,
        seed: gt.sample_seed,
        stats: Statistics::of_kept(
            &completeness_distances,
            |i| completeness_distances[i].is_finite(),
            bins,
        ),
    };
    let crop = CropReport {
        kind: crop.kind(),
        kept: kept_n,
        discarded: outside + too_far,
        discarded_outside_volume: outside,
        discarded_farther_than_max_distance: too_far,
        volume: crop.volume.clone(),
        max_distance: crop.max_distance,
        ground_truth_samples_kept: completeness_points.len() as u64,
    };
    Ok(Measured {
        recon,
        slot_input,
        gt_from_recon: t,
        distances,
        signed_distances,
        status,
        completeness_points: completeness_points.into_owned(),
        completeness_distances,
        thresholds,
        scores,
        crop,
        accuracy,
        completeness,
        notes,
    })
}

/// The distance (and, when `signed` on a mesh, the signed distance) of every point to the
/// ground truth, in input order; the queries run in tree order, `in_gt(k)` giving slot `k`.
fn accuracy_distances(
    gt: &PreparedGroundTruth,
    slot_input: &[u32],
    signed: bool,
    in_gt: &(impl Fn(usize) -> Point3 + Sync),
    progress: &dyn Progress,
) -> (Vec<f64>, Option<Vec<f64>>) {
    let n = slot_input.len();
    progress.start(Stage::Accuracy, n as u64);
    let mut distances = vec![0.0f64; n];
    let mut signed_distances = (signed && gt.is_mesh()).then(|| vec![0.0f64; n]);
    for start in (0..n).step_by(BLOCK) {
        let end = (start + BLOCK).min(n);
        let block = parallel::map_range_with_state(start, end, progress, |hint, k| {
            gt.distance_from(in_gt(k), signed, hint)
        });
        for (k, (d, s)) in (start..end).zip(block) {
            let i = slot_input[k] as usize;
            distances[i] = d;
            if let Some(sd) = signed_distances.as_mut() {
                sd[i] = s.unwrap_or(d);
            }
        }
    }
    progress.finish();
    (distances, signed_distances)
}

/// Each point's status in input order, and the live mask of the kept slots (tree order, a bit
/// a slot), computed per slot in parallel.
fn crop_status(
    crop: &Crop,
    distances: &[f64],
    slot_input: &[u32],
    in_gt: &(impl Fn(usize) -> Point3 + Sync),
) -> (Vec<PointStatus>, Vec<u64>) {
    let n = slot_input.len();
    let slot_status = parallel::map_range(n, |k| {
        if !crop.in_volume(in_gt(k)) {
            PointStatus::OutsideVolume
        } else if crop
            .max_distance
            .is_some_and(|m| distances[slot_input[k] as usize] > m)
        {
            PointStatus::TooFar
        } else {
            PointStatus::Kept
        }
    });
    let live: Vec<u64> = parallel::map_range(n.div_ceil(64), |w| {
        let slots = &slot_status[w * 64..((w + 1) * 64).min(n)];
        (slots.iter().enumerate())
            .filter(|(_, s)| **s == PointStatus::Kept)
            .fold(0u64, |bits, (b, _)| bits | 1 << b)
    });
    let mut status = vec![PointStatus::Kept; n];
    for (&i, &s) in slot_input.iter().zip(&slot_status) {
        status[i as usize] = s;
    }
    (status, live)
}

impl Measured {
    /// The evaluation, with its report built once from the inputs, the alignment, what was
    /// measured and the `extras`; the notes in the order they arose (reading and aligning,
    /// measuring, then the extras').
    pub(crate) fn into_evaluation(
        self,
        gt: &PreparedGroundTruth,
        options: &EvalOptions,
        info: &InputInfo,
        alignment: &Alignment,
        extras: Extras,
    ) -> Evaluation {
        let mut notes = info.notes.clone();
        notes.extend(self.notes);
        notes.extend(extras.notes);
        let report = Report {
            schema: REPORT_SCHEMA.into(),
            tool: Tool::default(),
            inputs: Inputs {
                reconstruction: ReconstructionInput {
                    name: info.recon_name.clone(),
                    format: info.recon_format.clone(),
                    points: self.distances.len() as u64,
                    images: info.recon_images,
                },
                ground_truth: GroundTruthInput {
                    name: info.gt_name.clone(),
                    format: info.gt_format.clone(),
                    vertices: gt.vertices,
                    triangles: gt.triangles,
                    diagonal: self.thresholds.diagonal,
                    area: gt.area,
                },
            },
            options: ReportOptions {
                samples: if gt.is_mesh() {
                    options.samples as u64
                } else {
                    gt.samples.len() as u64
                },
                seed: gt.sample_seed,
                signed: options.signed,
                histogram_bins: options.histogram_bins as u64,
                tau: options.tau.clone(),
                tau_percent_of_diagonal: self.thresholds.percents_used.clone(),
                align: alignment.requested.name().into(),
                min_views: extras.min_views,
            },
            crop: self.crop,
            alignment: alignment.report(),
            accuracy: self.accuracy,
            completeness: self.completeness,
            thresholds: self.scores,
            cameras: extras.cameras,
            completeness_visible: extras.completeness_visible,
            track_error: extras.track_error,
            notes,
        };
        Evaluation {
            report,
            recon: self.recon,
            slot_input: self.slot_input,
            gt_from_recon: self.gt_from_recon,
            distances: self.distances,
            signed_distances: self.signed_distances,
            status: self.status,
            completeness_points: self.completeness_points,
            completeness_distances: self.completeness_distances,
            thresholds: self.thresholds,
            sample_views: extras.sample_views,
            sample_labels: extras.sample_labels,
            track_errors: extras.track_errors,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::crop::Volume;
    use crate::geometry::{GroundTruth, TriangleMesh};
    use crate::progress::NoProgress;

    /// Both storages reorder as a plain gather does: new slot `k` holds old point `order[k]`
    /// (a permutation of long cycles over many parallel work units).
    #[test]
    fn permute_gathers_by_order() {
        let n = 50_000u32;
        let order: Vec<u32> = (0..n).map(|k| (k * 7919 + 13) % n).collect();
        let points: Vec<Point3> = (0..n).map(|i| [i as f64, -(i as f64), 0.5]).collect();
        let want: Vec<Point3> = order.iter().map(|&i| points[i as usize]).collect();
        let mut p64 = Positions::F64(points.clone());
        into_tree_order(&mut p64, &order);
        let mut p32 = Positions::F32(points.iter().map(|p| p.map(|v| v as f32)).collect());
        into_tree_order(&mut p32, &order);
        for (k, w) in want.iter().enumerate() {
            assert_eq!(p64.get(k), *w, "f64 slot {k}");
            assert_eq!(p32.get(k), *w, "f32 slot {k}");
        }
    }

    /// Points stored in `f32` give the report and per-point data of the same points in `f64`,
    /// and both equal an independent brute-force evaluation: distances from the mesh index per
    /// point in input order, completeness as the minimum over every kept point.
    #[test]
    fn f32_storage_and_tree_order_match_brute_force() {
        let mesh = TriangleMesh {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.3],
            ],
            triangles: vec![[0, 1, 2], [1, 3, 2]],
        };
        let gt = PreparedGroundTruth::new(&GroundTruth::Mesh(mesh.clone()), 500, 3, &NoProgress)
            .unwrap();
        let index = crate::distance::MeshIndex::new(&mesh).unwrap();
        let raw: Vec<[f32; 3]> = (0..3000u32)
            .map(|i| {
                let h = u64::from(i).wrapping_mul(0x9e37_79b9_7f4a_7c15);
                let f = |s: u32| ((h >> s) & 0xffff) as f32 / 65535.0;
                [f(0) * 1.4 - 0.2, f(16) * 1.4 - 0.2, f(32) * 0.4 - 0.2]
            })
            .collect();
        let t = Similarity::from_matrix([
            [0.0, -1.1, 0.0, 1.0],
            [1.1, 0.0, 0.0, 0.05],
            [0.0, 0.0, 1.1, 0.01],
            [0.0, 0.0, 0.0, 1.0],
        ])
        .unwrap();
        let alignment = Alignment::given(t);
        let options = EvalOptions {
            samples: 500,
            seed: 3,
            signed: true,
            crop: Crop {
                volume: Some(Volume::Sphere {
                    center: [0.5, 0.5, 0.0],
                    radius: 0.6,
                }),
                max_distance: Some(0.1),
                ..Crop::default()
            },
            ..EvalOptions::default()
        };
        let info = InputInfo::default();
        let wide: Vec<Point3> = raw.iter().map(|p| p.map(f64::from)).collect();
        let a = evaluate(
            &gt,
            Positions::F32(raw),
            &alignment,
            &options,
            &info,
            &NoProgress,
        )
        .unwrap();
        let b = evaluate(
            &gt,
            Positions::F64(wide.clone()),
            &alignment,
            &options,
            &info,
            &NoProgress,
        )
        .unwrap();
        assert_eq!(a.report.to_json(), b.report.to_json());
        assert_eq!(a.points_in_gt(), b.points_in_gt());
        // Independent: per input point, straight through the mesh index.
        let in_gt: Vec<Point3> = wide.iter().map(|&p| t.apply(p)).collect();
        assert_eq!(a.points_in_gt(), in_gt);
        let mut kept = Vec::new();
        for (i, p) in in_gt.iter().enumerate() {
            let hit = index.closest(*p);
            assert_eq!(a.distances[i].to_bits(), hit.distance.to_bits());
            let sd = a.signed_distances.as_ref().unwrap()[i];
            assert_eq!(sd.to_bits(), index.signed(*p, &hit).to_bits());
            if a.status[i] == PointStatus::Kept {
                kept.push(*p);
            }
        }
        assert!(!kept.is_empty() && kept.len() < in_gt.len());
        // The sorted lists the page's curves read: the kept distances and every completeness
        // distance, as a plain sort of them.
        let mut want: Vec<f64> = (0..in_gt.len())
            .filter(|&i| a.status[i] == PointStatus::Kept)
            .map(|i| a.distances[i])
            .collect();
        want.sort_by(|x, y| x.partial_cmp(y).unwrap());
        assert_eq!(a.sorted_kept_distances(), want);
        let mut want = a.completeness_distances.clone();
        want.sort_by(|x, y| x.partial_cmp(y).unwrap());
        assert_eq!(a.sorted_completeness_distances(), want);
        for (q, d) in a.completeness_points.iter().zip(&a.completeness_distances) {
            let brute = kept
                .iter()
                .map(|p| {
                    (p[0] - q[0]) * (p[0] - q[0])
                        + (p[1] - q[1]) * (p[1] - q[1])
                        + (p[2] - q[2]) * (p[2] - q[2])
                })
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            assert_eq!(d.to_bits(), brute.to_bits());
        }
        let mut csv_points = Vec::new();
        a.for_each_point_in_gt(|i, p| csv_points.push((i, p)));
        assert!(
            csv_points
                .iter()
                .enumerate()
                .all(|(k, (i, p))| k == *i && *p == in_gt[k])
        );
    }
}
