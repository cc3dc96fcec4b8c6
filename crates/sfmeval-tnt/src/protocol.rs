//! The protocol end to end, step for step as the toolbox's `run.py` runs it:
//! 1. trajectory alignment of the reconstruction's `.log` against the reference trajectory
//!    taken into the ground-truth frame by `<scene>_trans.txt`;
//! 2. three ICP refinements (`registration_vol_ds` at voxel τ with correspondence distance 80τ,
//!    at τ/2 with 20τ, then `registration_unif` with 2τ), each on both clouds cropped (the
//!    reconstruction after the current transform) and down-sampled;
//! 3. `EvaluateHisto`: both clouds cropped and voxel down-sampled at τ/2, nearest-neighbour
//!    distances both ways, precision / recall / F at τ and the cumulative curves.
//!
//! The cropped and down-sampled ground truth is computed once per voxel size (the toolbox
//! recomputes the same clouds in every step), and one k-d tree serves the τ/2 refinement and the
//! evaluation.

use std::borrow::Cow;

use super::colors;
use super::curves::{self, Scores};
use super::icp::{IcpCriteria, registration_icp};
use super::matrix::{self, Matrix4};
use super::plot;
use super::report::*;
use super::scene::{Scene, scene_tau};
use super::trajectory::{LogFrame, MAPPING_ABOVE_FRAMES};
use super::trajectory_alignment::{TrajectoryAlignmentOptions, align_trajectories};
use super::voxel::voxel_down_sample;
use sfmeval::crop::{Axis, Volume};
use sfmeval::distance::{KdCloud, NO_POINT, NeighbourList};
use sfmeval::geometry::Point3;
use sfmeval::note::{Code, Note};
use sfmeval::parallel;
use sfmeval::progress::{Progress, Stage};
use sfmeval::report::Tool;
use sfmeval::{Error, Result};

/// The toolbox's point budget of the last refinement (`MAX_POINT_NUMBER`).
pub const UNIFORM_MAX_POINTS: u64 = 4_000_000;

/// The curves run to τ times this (the toolbox's `plot_stretch`).
pub const PLOT_STRETCH: f64 = 5.0;

/// How the reconstruction reaches the ground-truth frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Registration {
    /// The protocol's trajectory alignment and three ICP refinements, from this trajectory.
    Protocol {
        /// The reconstruction's `.log` frames.
        trajectory: Vec<LogFrame>,
        /// The name of the `.log` for the report.
        trajectory_name: String,
        /// Trajectory-alignment parameters.
        options: TrajectoryAlignmentOptions,
    },
    /// A known `gt_from_recon` (the registration skipped).
    Given(Matrix4),
}

/// One evaluation request.
#[derive(Debug, Clone)]
pub struct TntRequest {
    /// τ in ground-truth units; `None` takes the scene's from the toolbox's table.
    pub tau: Option<f64>,
    /// The registration.
    pub registration: Registration,
    /// ICP stop rule of the refinements.
    pub icp: IcpCriteria,
}

/// The report and the two measured clouds (for the coloured PLYs).
#[derive(Debug, Clone)]
pub struct TntEvaluation {
    /// The report.
    pub report: TntReport,
    /// Reconstruction points measured (ground-truth frame, cropped, down-sampled).
    pub precision_points: Vec<Point3>,
    /// Their distances to the ground truth.
    pub precision_distances: Vec<f64>,
    /// Ground-truth points measured.
    pub recall_points: Vec<Point3>,
    /// Their distances to the reconstruction.
    pub recall_distances: Vec<f64>,
}

impl TntEvaluation {
    /// The toolbox's `<scene>.precision.ply`: the measured reconstruction coloured by distance.
    pub fn precision_ply(&self) -> Vec<u8> {
        colors::distance_ply(
            &self.precision_points,
            &self.precision_distances,
            self.report.protocol.evaluation.color_max_distance,
        )
    }

    /// The toolbox's `<scene>.recall.ply`: the measured ground truth coloured by distance.
    pub fn recall_ply(&self) -> Vec<u8> {
        colors::distance_ply(
            &self.recall_points,
            &self.recall_distances,
            self.report.protocol.evaluation.color_max_distance,
        )
    }

    /// The report as written: pretty JSON with a trailing newline.
    pub fn report_json(&self) -> String {
        let mut json = serde_json::to_string_pretty(&self.report).unwrap_or_default();
        json.push('\n');
        json
    }

    /// Every file the toolbox writes beside the report, by file name, encoded:
    /// [`Self::data_files`] then [`Self::plot_files`], made side by side. What the runner and
    /// the Python package write into a report folder (`sfmeval tnt` writes the data files
    /// while the plot renders).
    pub fn output_files(&self) -> Vec<(String, Vec<u8>)> {
        let (mut files, plots) = parallel::join(|| self.data_files(), || self.plot_files());
        files.extend(plots);
        files
    }

    /// The clouds and texts the toolbox writes beside the report, by file name, encoded (the
    /// two clouds side by side): `<scene>.precision.ply`, `<scene>.recall.ply`, the curves and
    /// `<scene>.prf_tau_plotstr.txt`.
    pub fn data_files(&self) -> Vec<(String, Vec<u8>)> {
        let name = &self.report.protocol.scene;
        let (precision, recall) = parallel::join(|| self.precision_ply(), || self.recall_ply());
        let mut files = vec![
            (format!("{name}.precision.ply"), precision),
            (format!("{name}.recall.ply"), recall),
        ];
        for (suffix, text) in self.toolbox_texts() {
            files.push((format!("{name}{suffix}"), text.into_bytes()));
        }
        files
    }

    /// The precision/recall plot `PR_<scene>_@d_th_0_<τ>.svg` (and `.png` first, with the `png`
    /// feature, where the system has a font), by file name.
    pub fn plot_files(&self) -> Vec<(String, Vec<u8>)> {
        let stem = plot::plot_stem(&self.report.protocol.scene, self.report.protocol.tau);
        let svg = plot::pr_svg(&self.report);
        let mut files = Vec::new();
        #[cfg(feature = "png")]
        if let Some(png) = plot::svg_to_png(&svg) {
            files.push((format!("{stem}.png"), png));
        }
        files.push((format!("{stem}.svg"), svg.into_bytes()));
        files
    }

    /// The toolbox's text outputs by file suffix: `.precision.txt`, `.recall.txt` (the curves)
    /// and `.prf_tau_plotstr.txt` (P, R, F, τ, stretch), as `numpy.savetxt` writes them.
    pub fn toolbox_texts(&self) -> [(&'static str, String); 3] {
        let r = &self.report;
        [
            (".precision.txt", curves::savetxt(&r.curves.precision)),
            (".recall.txt", curves::savetxt(&r.curves.recall)),
            (
                ".prf_tau_plotstr.txt",
                curves::savetxt(&[
                    r.precision.value,
                    r.recall.value,
                    r.f_score,
                    r.protocol.tau,
                    r.protocol.evaluation.plot_stretch,
                ]),
            ),
        ]
    }
}

/// Evaluates the reconstructed cloud `recon_points` (named `recon_name`) on `scene`.
pub fn evaluate(
    scene: &Scene,
    recon_name: &str,
    recon_points: &[Point3],
    request: &TntRequest,
    progress: &dyn Progress,
) -> Result<TntEvaluation> {
    let (tau, tau_source) = match (request.tau, scene_tau(&scene.name)) {
        (Some(t), _) => (t, "option"),
        (None, Some(t)) => (t, "scene table"),
        (None, None) => {
            return Err(Error::InvalidOption(format!(
                "scene '{}' is not one of the benchmark's (Barn, Caterpillar, Church, Courthouse, Ignatius, Meetingroom, Truck): give τ",
                scene.name
            )));
        }
    };
    if !(tau.is_finite() && tau > 0.0) {
        return Err(Error::InvalidOption(format!("τ must be > 0, got {tau}")));
    }
    if recon_points.is_empty() {
        return Err(Error::Empty {
            what: format!("reconstruction '{recon_name}'"),
        });
    }
    let volume = &scene.crop;
    // The crops run in parallel, the kept points come in input order (a kept point is moved
    // twice, to the same bits).
    let crop = |pts: &[Point3]| -> Vec<Point3> {
        parallel::keep_map(pts, |p| volume.contains(*p), |p| *p)
    };
    let crop_moved = |t: &Matrix4| -> Vec<Point3> {
        parallel::keep_map(
            recon_points,
            |p| volume.contains(matrix::apply(t, *p)),
            |p| matrix::apply(t, *p),
        )
    };
    let nonempty = |pts: Vec<Point3>, what: &str| -> Result<Vec<Point3>> {
        if pts.is_empty() {
            Err(Error::Geometry(format!(
                "no {what} point lies inside the crop of scene '{}'",
                scene.name
            )))
        } else {
            Ok(pts)
        }
    };
    let mut notes = Vec::new();

    progress.start(Stage::Alignment, 5);
    let gt_cropped = nonempty(crop(&scene.ground_truth), "ground-truth")?;
    // The τ/2 grid, which the τ/2 refinement and the evaluation search.
    let half_grid = || -> Result<(Vec<Point3>, KdCloud)> {
        let gt_half = voxel_down_sample(&gt_cropped, tau / 2.0)?;
        let index = KdCloud::new(&gt_half)?;
        Ok((gt_half, index))
    };

    let mut stage_params = Vec::new();
    let mut stage_results = Vec::new();
    let (mode, alignment, trajectory_input, gt_from_recon, gt_half, gt_half_index) = match &request
        .registration
    {
        Registration::Given(t) => {
            matrix::validate(t, "the given transform")?;
            let (gt_half, gt_half_index) = half_grid()?;
            progress.advance(4);
            ("given", None, None, *t, gt_half, gt_half_index)
        }
        Registration::Protocol {
            trajectory,
            trajectory_name,
            options,
        } => {
            let (centers, mapped) = trajectory_centers(scene, trajectory)
                .map_err(|e| e.in_file("trajectory", trajectory_name.as_str()))?;
            let reference: Vec<Point3> = scene
                .reference_trajectory
                .iter()
                .map(|f| matrix::apply(&scene.gt_from_reference, f.center()))
                .collect();
            // The trajectory RANSAC, the τ/2 and τ grids with their indexes and the uniform
            // refinement's index over the whole cropped ground truth run side by side: none
            // depends on another (each is the same whichever thread makes it), and each has
            // serial steps (the first median splits, the RANSAC's chunk ends) that the others
            // fill.
            let ((aligned, half), (gt_full_index, uniform_index)) = parallel::join(
                || {
                    parallel::join(
                        || {
                            align_trajectories(&centers, &reference, options)
                                .map_err(|e| e.in_file("trajectory", trajectory_name.as_str()))
                        },
                        half_grid,
                    )
                },
                || {
                    parallel::join(
                        || voxel_down_sample(&gt_cropped, tau).and_then(|v| KdCloud::new(&v)),
                        // Indexed in place: no copy of the cropped ground truth within the
                        // budget.
                        || KdCloud::new(&uniform_down_sample(&gt_cropped)),
                    )
                },
            );
            let (aligned, (gt_half, gt_half_index)) = (aligned?, half?);
            let (gt_full_index, index) = (gt_full_index?, uniform_index?);
            progress.advance(2);
            let mut t = aligned.gt_from_recon;
            // Two voxel refinements, then the uniform one.
            for (voxel, distance, index) in [
                (tau, 80.0 * tau, &gt_full_index),
                (tau / 2.0, 20.0 * tau, &gt_half_index),
            ] {
                let source = voxel_down_sample(&nonempty(crop_moved(&t), "reconstructed")?, voxel)?;
                let r = registration_icp(&source, index, distance, request.icp);
                t = matrix::mul(&r.transformation, &t);
                stage_params.push(StageParams::new(
                    "voxel",
                    Some(voxel),
                    None,
                    distance,
                    request.icp,
                ));
                stage_results.push(StageResult::of_icp(source.len(), index.len(), &r, t));
                progress.advance(1);
            }
            let source = nonempty(crop_moved(&t), "reconstructed")?;
            let source = uniform_down_sample(&source);
            let r = registration_icp(&source, &index, 2.0 * tau, request.icp);
            t = matrix::mul(&r.transformation, &t);
            stage_params.push(StageParams::new(
                "uniform",
                None,
                Some(UNIFORM_MAX_POINTS),
                2.0 * tau,
                request.icp,
            ));
            stage_results.push(StageResult::of_icp(source.len(), index.len(), &r, t));
            progress.advance(1);
            if aligned.fitness < 0.5 {
                notes.push(
                    Note::new(
                        Code::TrajectoryPoorlyAligned,
                        format!(
                            "trajectory alignment: only {:.0} % of the cameras came within {} of the reference",
                            100.0 * aligned.fitness,
                            options.max_correspondence_distance
                        ),
                    )
                    .with_number("fitness", aligned.fitness)
                    .with_number(
                        "max_correspondence_distance",
                        options.max_correspondence_distance,
                    ),
                );
            }
            let registered = trajectory
                .iter()
                .filter(|f| f.metadata.get(1).is_some_and(|v| *v >= 0))
                .count();
            (
                "protocol",
                Some(aligned),
                Some(TrajectoryInput {
                    name: trajectory_name.clone(),
                    frames: trajectory.len(),
                    registered,
                    mapped,
                }),
                t,
                gt_half,
                gt_half_index,
            )
        }
    };
    progress.finish();

    // EvaluateHisto.
    let recon_cropped = crop_moved(&gt_from_recon);
    let recon_cropped_count = recon_cropped.len();
    let precision_points = voxel_down_sample(&recon_cropped, tau / 2.0)?;
    drop(recon_cropped);
    progress.start(Stage::Accuracy, precision_points.len() as u64);
    let precision_distances = nearest_distances(&precision_points, &gt_half_index, progress);
    progress.finish();
    let recall_distances = if precision_points.is_empty() {
        notes.push(Note::new(
            Code::NothingInSceneCrop,
            "no reconstructed point lies inside the crop: precision, recall and F are 0",
        ));
        Vec::new()
    } else {
        let recon_index = KdCloud::new(&precision_points)?;
        progress.start(Stage::Completeness, gt_half.len() as u64);
        let d = nearest_distances(&gt_half, &recon_index, progress);
        progress.finish();
        d
    };
    // Each side's distances sorted once, for the scores, the curves and the median (finite
    // distances: the order is the total order's, whichever sort makes it).
    let sorted = |d: &[f64]| {
        let mut s = d.to_vec();
        parallel::sort_floats(&mut s);
        s
    };
    let (precision_sorted, recall_sorted) = parallel::join(
        || sorted(&precision_distances),
        || sorted(&recall_distances),
    );
    let scores = curves::scores(&precision_sorted, &recall_sorted, tau, PLOT_STRETCH);

    let (axis, axis_min, axis_max, polygon_vertices) = match volume {
        Volume::PolygonPrism {
            polygon,
            axis,
            axis_min,
            axis_max,
        } => (
            match axis {
                Axis::X => "x",
                Axis::Y => "y",
                Axis::Z => "z",
            },
            *axis_min,
            *axis_max,
            polygon.len(),
        ),
        _ => ("", f64::NAN, f64::NAN, 0),
    };
    let Scores {
        precision,
        recall,
        f_score,
        edges,
        precision_curve,
        recall_curve,
    } = scores;
    let report = TntReport {
        schema: TNT_SCHEMA.into(),
        tool: Tool::default(),
        protocol: ProtocolSection {
            name: "tanksandtemples".into(),
            reference: "Tanks and Temples python_toolbox/evaluation (run.py)".into(),
            scene: scene.name.clone(),
            tau,
            tau_source: tau_source.into(),
            crop: CropSection {
                file: format!("{}.json", scene.name),
                kind: volume.kind().into(),
                axis: axis.into(),
                axis_min,
                axis_max,
                polygon_vertices,
            },
            trajectory_alignment: match &request.registration {
                Registration::Protocol { options, .. } => Some(options.into()),
                Registration::Given(_) => None,
            },
            refinement: stage_params,
            evaluation: EvaluationParams {
                voxel_size: tau / 2.0,
                threshold: tau,
                plot_stretch: PLOT_STRETCH,
                bin_width: tau / 100.0,
                color_max_distance: 3.0 * tau,
                colormap: "hot_r".into(),
            },
        },
        inputs: InputsSection {
            reconstruction: NamedCount {
                name: recon_name.into(),
                points: recon_points.len(),
            },
            trajectory: trajectory_input,
            ground_truth: NamedCount {
                name: scene.ground_truth_path.clone(),
                points: scene.ground_truth.len(),
            },
            reference_frames: scene.reference_trajectory.len(),
            gt_from_reference: scene.gt_from_reference,
        },
        registration: RegistrationSection {
            mode: mode.into(),
            trajectory_alignment: alignment,
            refinement: stage_results,
            gt_from_recon,
        },
        precision: side(
            precision,
            recon_cropped_count,
            &precision_distances,
            &precision_sorted,
        ),
        recall: side(recall, gt_cropped.len(), &recall_distances, &recall_sorted),
        f_score,
        curves: CurvesSection {
            edges,
            precision: precision_curve,
            recall: recall_curve,
        },
        notes,
    };
    Ok(TntEvaluation {
        report,
        precision_points,
        precision_distances,
        recall_points: gt_half,
        recall_distances,
    })
}

/// Each point's distance to its nearest point of `index` (the toolbox's
/// `compute_point_cloud_distance`), each search bounded from the start by the previous point's
/// answer in the Morton visiting order; the distances are those of an unbounded search.
fn nearest_distances(points: &[Point3], index: &KdCloud, progress: &dyn Progress) -> Vec<f64> {
    if points.len() >= LISTED_QUERIES_PER_POINT * index.len() {
        // Queries much denser than the index (the recall of a sparse cloud): consecutive ones
        // mostly find their nearest within the coverage of the neighbour list the queries
        // before them made, without a walk of the tree (the same bits).
        return parallel::map_points_with_state(points, progress, |list: &mut NeighbourList, p| {
            let (d2, _) =
                list.nearest_below(index, *p, (f64::INFINITY, NO_POINT), f64::INFINITY, None);
            d2.sqrt()
        });
    }
    parallel::map_points_with_state(points, progress, |previous: &mut Option<usize>, p| {
        let (d, k) = index.nearest_from(*p, previous.unwrap_or(NO_POINT));
        if k != NO_POINT {
            *previous = Some(k);
        }
        d
    })
}

/// Queries per index point from which [`nearest_distances`] reads neighbour lists.
const LISTED_QUERIES_PER_POINT: usize = 8;

/// The camera centres the alignment uses: every frame's, or through the mapping file the
/// reference frames of a video trajectory (longer than [`MAPPING_ABOVE_FRAMES`]).
fn trajectory_centers(scene: &Scene, trajectory: &[LogFrame]) -> Result<(Vec<Point3>, bool)> {
    if trajectory.len() <= MAPPING_ABOVE_FRAMES {
        return Ok((trajectory.iter().map(LogFrame::center).collect(), false));
    }
    let Some(mapping) = &scene.mapping else {
        return Err(Error::Missing {
            what: format!(
                "mapping reference for a trajectory of {} frames (more than {MAPPING_ABOVE_FRAMES})",
                trajectory.len()
            ),
            file: format!("{}_mapping_reference.txt", scene.name),
        });
    };
    let centers = mapping
        .video_frames
        .iter()
        .map(|&k| {
            trajectory
                .get(k as usize - 1)
                .map(LogFrame::center)
                .ok_or_else(|| {
                    Error::InvalidContent(format!(
                        "the mapping reference names video frame {k}, the trajectory has {}",
                        trajectory.len()
                    ))
                })
        })
        .collect::<Result<_>>()?;
    Ok((centers, true))
}

/// The toolbox's `uniform` down-sampling: every k-th point with `k = round(n / 4e6)` (Python's
/// round, halves to even) when `n` exceeds the budget.
fn uniform_down_sample(points: &[Point3]) -> Cow<'_, [Point3]> {
    let n = points.len() as u64;
    if n <= UNIFORM_MAX_POINTS {
        return Cow::Borrowed(points);
    }
    let k = (n as f64 / UNIFORM_MAX_POINTS as f64)
        .round_ties_even()
        .max(1.0) as usize;
    Cow::Owned(points.iter().step_by(k).copied().collect())
}

/// One side's section: the mean sums `distances` in their order; the median is taken of the
/// same values `sorted`.
fn side(value: f64, cropped_points: usize, distances: &[f64], sorted: &[f64]) -> SideSection {
    let n = sorted.len();
    let (mean, median) = if n == 0 {
        (0.0, 0.0)
    } else if n % 2 == 1 {
        (distances.iter().sum::<f64>() / n as f64, sorted[n / 2])
    } else {
        (
            distances.iter().sum::<f64>() / n as f64,
            0.5 * (sorted[n / 2 - 1] + sorted[n / 2]),
        )
    };
    SideSection {
        value,
        cropped_points,
        points: n,
        mean_distance: mean,
        median_distance: median,
    }
}
