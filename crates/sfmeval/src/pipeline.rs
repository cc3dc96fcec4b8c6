//! One evaluation request as every front end makes it: read the reconstruction from named
//! bytes, align (none, a given transform, or the alignment stages), measure against a
//! [`Dataset`], and add what the dataset's parts allow (camera-pose metrics, visible
//! completeness, track error). The CLI, the wasm bindings and the runner all call [`run`] with
//! an [`EvalRequest`], so they give the same report for the same inputs.

use std::collections::BTreeMap;

use crate::align::{
    self, AlignInput, AlignMethod, AlignMode, AlignOptions, AlignRequest, Alignment, CameraPair,
    StageKind,
};
use crate::dataset::Dataset;
use crate::error::{Error, Result};
use crate::evaluate::{EvalOptions, Evaluation, Extras, InputInfo, Measured, PointStatus, measure};
use crate::geometry::PointCloud;
use crate::gt_views::GtView;
use crate::io;
use crate::model::{self, Reconstruction};
use crate::note::{Code, Note};
use crate::pose::{PoseOptions, evaluate_cameras_matched};
use crate::prepared::PreparedGroundTruth;
use crate::progress::{Progress, Stage};
use crate::report::{CamerasAlignment, CamerasSection};
use crate::transform::Similarity;
use crate::{track_error, visibility};

/// A reconstruction as read: its cloud, and its cameras when the format has them.
#[derive(Debug, Clone)]
pub struct ReconInput {
    /// The points to evaluate (camera-centre points removed).
    pub cloud: PointCloud,
    /// The SfM model, for formats with cameras (or the model given beside a PLY).
    pub model: Option<Reconstruction>,
    /// Name shown in the report.
    pub name: String,
    /// `ply`, `colmap`, `nvm`, `bundler`, `openmvg`, `cameras_json`, ...; `ply+nvm` (etc.) for
    /// a PLY cloud with the cameras of a model.
    pub format: String,
    /// Notes for the report.
    pub notes: Vec<Note>,
    /// Whether `cloud` is the model's own points in order ([`Reconstruction::to_point_cloud`]),
    /// so that per-point model data (tracks) lines up with the evaluated points.
    pub cloud_is_model_points: bool,
}

fn is_ply(name: &str) -> bool {
    name.to_ascii_lowercase().ends_with(".ply")
}

/// Reads a reconstruction from named files: one point-cloud file (PLY, or the vertices of a
/// mesh), or the files of an SfM model (a COLMAP folder with `sparse/N` sub-models, `.nvm`,
/// Bundler `.out` + `list.txt`, OpenMVG `sfm_data.json`, `cameras.json`). `name` is shown in the
/// report. PLY clouds lose the camera-centre points OpenMVG and Theia append (by marker colour).
///
/// Files holding both an SfM model and one PLY (a Theia output folder with `reconstruction.nvm`
/// and `points.ply`, COLMAP's `fused.ply` beside `sparse/`) evaluate the PLY with the model's
/// cameras, as [`read_reconstruction_with_cameras`]; several PLYs beside a model are an error.
pub fn read_reconstruction(name: &str, files: &BTreeMap<String, Vec<u8>>) -> Result<ReconInput> {
    if files.is_empty() {
        return Err(Error::Empty {
            what: format!("reconstruction '{name}' (no files)"),
        });
    }
    if model_file(files).is_some() {
        let plys: Vec<(&String, &Vec<u8>)> = files.iter().filter(|(n, _)| is_ply(n)).collect();
        match plys.as_slice() {
            [] => {}
            [(ply_name, ply_bytes)] => {
                let rec = model::read_model_files(files)?;
                return cloud_with_cameras(name, ply_name, ply_bytes, rec, name);
            }
            more => {
                let names: Vec<&str> = more.iter().take(5).map(|(n, _)| n.as_str()).collect();
                return Err(Error::InvalidContent(format!(
                    "reconstruction '{name}' holds an SfM model and {} PLY files ({}): give the one PLY to evaluate and the model as its cameras",
                    more.len(),
                    names.join(", ")
                )));
            }
        }
        let rec = model::read_model_files(files)?;
        if rec.images.is_empty() && rec.points.is_empty() {
            return Err(Error::Empty {
                what: format!(
                    "reconstruction '{name}' (an SfM model with no registered image and no 3D point)"
                ),
            });
        }
        let cloud = rec.to_point_cloud();
        let mut notes = rec.notes.clone();
        if cloud.points.is_empty() {
            notes.push(Note::new(
                Code::ModelNoPoints,
                "the SfM model has no 3D points",
            ));
        }
        return Ok(ReconInput {
            cloud,
            name: name.to_string(),
            format: rec.format.to_string(),
            notes,
            model: Some(rec),
            cloud_is_model_points: true,
        });
    }
    let (file_name, bytes) = point_cloud_file(name, files)?;
    Ok(reconstruction_from_cloud(
        name,
        io::read_point_cloud(file_name, bytes)?,
    ))
}

/// The reconstruction `name` from a point cloud already read (a dense PLY read in pieces by
/// the front end, [`io::point_cloud_from_ply`]), as [`read_reconstruction`] makes it from the
/// cloud's file.
pub fn reconstruction_from_cloud(name: &str, loaded: io::LoadedCloud) -> ReconInput {
    let mut notes = loaded.notes;
    let stripped = model::strip::strip_camera_points(loaded.cloud, None, name);
    notes.extend(stripped.note);
    ReconInput {
        cloud: stripped.cloud,
        model: None,
        name: name.to_string(),
        format: loaded.format.name().to_string(),
        notes,
        cloud_is_model_points: false,
    }
}

/// The first of `files` that is (part of) an SfM model.
fn model_file(files: &BTreeMap<String, Vec<u8>>) -> Option<&String> {
    files
        .iter()
        .find(|(n, b)| model::detect_model_format(n, b).is_some())
        .map(|(n, _)| n)
}

/// The point-cloud file among `files`: the PLY, else the only file.
fn point_cloud_file<'a>(
    name: &str,
    files: &'a BTreeMap<String, Vec<u8>>,
) -> Result<(&'a String, &'a Vec<u8>)> {
    match files.iter().find(|(n, _)| is_ply(n)) {
        Some(f) => Ok(f),
        None => files.iter().next().ok_or_else(|| Error::Empty {
            what: format!("reconstruction '{name}' (no files)"),
        }),
    }
}

/// A point cloud (`files`: a PLY, or a mesh whose vertices are the points) evaluated with the
/// cameras of an SfM model in the same frame (`cameras`, read with
/// [`model::read_model_files`]; `cameras_name` names it in the report). The points at the
/// model's camera centres (the centres OpenMVG and Theia write into their PLYs, in any colour)
/// are removed; the model provides the cameras for the `cameras` alignment and the pose metrics.
/// Errors when `files` are themselves an SfM model.
pub fn read_reconstruction_with_cameras(
    name: &str,
    files: &BTreeMap<String, Vec<u8>>,
    cameras: Reconstruction,
    cameras_name: &str,
) -> Result<ReconInput> {
    if let Some(n) = model_file(files) {
        return Err(Error::InvalidContent(format!(
            "reconstruction '{name}' is an SfM model ('{n}'), not a point cloud: separate cameras are only for a PLY"
        )));
    }
    let (file_name, bytes) = point_cloud_file(name, files)?;
    cloud_with_cameras(name, file_name, bytes, cameras, cameras_name)
}

fn cloud_with_cameras(
    name: &str,
    file_name: &str,
    bytes: &[u8],
    cameras: Reconstruction,
    cameras_name: &str,
) -> Result<ReconInput> {
    if cameras.images.is_empty() {
        return Err(Error::Empty {
            what: format!("cameras of '{cameras_name}' (the SfM model has no registered image)"),
        });
    }
    let loaded = io::read_point_cloud(file_name, bytes)?;
    let mut notes = cameras.notes.clone();
    notes.extend(loaded.notes);
    notes.push(
        Note::new(
            Code::CloudWithModelCameras,
            format!(
                "evaluating the points of '{file_name}' with the {} camera(s) of the {} model '{cameras_name}'",
                cameras.images.len(),
                cameras.format
            ),
        )
        .with("cloud", file_name)
        .with("model", cameras_name)
        .with("cameras", cameras.images.len()),
    );
    let centers = cameras.camera_centers();
    let stripped = model::strip::strip_camera_points(loaded.cloud, Some(&centers), file_name);
    if !stripped.by_centers {
        notes.push(
            Note::new(
                Code::NoPointAtCameraCentres,
                format!(
                    "no point of '{file_name}' lies at one of the {} camera centres of '{cameras_name}' (fine for a cloud without camera points; otherwise they are not in one frame)",
                    centers.len()
                ),
            )
            .with("cameras", centers.len()),
        );
    }
    notes.extend(stripped.note);
    Ok(ReconInput {
        cloud: stripped.cloud,
        name: name.to_string(),
        format: format!("{}+{}", loaded.format.name(), cameras.format),
        notes,
        model: Some(cameras),
        cloud_is_model_points: false,
    })
}

/// One evaluation request: how to align, what to measure, how to score the cameras. Every
/// front end builds one and hands it to [`run`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EvalRequest {
    /// Alignment.
    pub align: AlignRequest,
    /// Measurement options.
    pub eval: EvalOptions,
    /// Pose metric options.
    pub pose: PoseOptions,
}

fn camera_pairs(
    gt_cameras: &Reconstruction,
    est: &Reconstruction,
) -> (Vec<CameraPair>, model::matching::ImageMatches) {
    let matches = model::matching::match_images(gt_cameras, est);
    let pairs = matches
        .pairs
        .iter()
        .filter_map(|&(g, e)| {
            let (gi, ei) = (gt_cameras.images.get(g)?, est.images.get(e)?);
            Some(CameraPair {
                recon_center: ei.center(),
                gt_center: gi.center(),
                recon_rotation: Some(ei.cam_from_world.rotation),
                gt_rotation: Some(gi.cam_from_world.rotation),
            })
        })
        .collect();
    (pairs, matches)
}

/// Aligns `recon` to the ground truth of `dataset`, measures it, and adds what the dataset's
/// parts allow: camera-pose metrics with its cameras, completeness over the visible surface
/// and (for models with tracks) the track-based error with its depth maps. The dataset is
/// prepared for the request's sample count and seed first (reused when they match).
pub fn run(
    dataset: &mut Dataset,
    recon: &ReconInput,
    request: &EvalRequest,
    progress: &dyn Progress,
) -> Result<Evaluation> {
    run_owned(dataset, recon.clone(), request, progress)
}

/// [`run`] on a reconstruction it may keep: its points move into the [`Evaluation`] instead
/// of being copied (what a front end that reads a dense cloud once wants).
pub fn run_owned(
    dataset: &mut Dataset,
    mut recon: ReconInput,
    request: &EvalRequest,
    progress: &dyn Progress,
) -> Result<Evaluation> {
    request.eval.validate()?;
    request.align.validate()?;
    dataset.prepare(request.eval.samples, request.eval.seed, progress)?;
    let Some(gt) = dataset.prepared() else {
        return Err(Error::InvalidOption(
            "the ground truth is not prepared".into(),
        ));
    };
    let gt_cameras = dataset.cameras();
    let gt_camera_notes = gt_cameras.into_iter().flat_map(|c| &c.notes).map(|n| {
        n.clone()
            .prefixed("ground-truth cameras: ")
            .with("side", "ground_truth")
    });
    let mut notes: Vec<Note> = dataset
        .loaded
        .notes
        .iter()
        .cloned()
        .chain(gt_camera_notes)
        .chain(recon.notes.iter().cloned())
        .collect();
    let (pairs, matches) = match (gt_cameras, &recon.model) {
        (Some(g), Some(e)) => {
            let (p, m) = camera_pairs(g, e);
            (p, Some(m))
        }
        _ => (Vec::new(), None),
    };
    if gt_cameras.is_some() && recon.model.is_none() {
        notes.push(Note::new(
            Code::ReconstructionHasNoCameras,
            "ground-truth cameras were given but the reconstruction has no cameras (a bare point cloud): no camera-based alignment or pose metrics",
        ));
    }
    // Cameras on both sides but no image name in common: say so once, skip the camera stage
    // and the pose metrics instead of failing the whole evaluation.
    let no_match = match (gt_cameras, &recon.model, &matches) {
        (Some(g), Some(e), Some(m)) if m.pairs.is_empty() => Some(no_match_detail(g, e)),
        _ => None,
    };
    if let Some(detail) = &no_match {
        notes.push(Note::new(
            Code::NoImageInCommon,
            format!("cameras: {detail}: no camera alignment and no pose metrics"),
        ));
    }
    let alignment = align_recon(
        gt,
        &recon,
        &pairs,
        no_match.as_deref(),
        gt_cameras.is_some(),
        request,
        progress,
    )?;
    notes.extend(alignment.notes().cloned());
    notes.extend(align::fit_verdict(&alignment, gt.aabb.diagonal()));
    let info = InputInfo {
        recon_name: recon.name.clone(),
        recon_format: recon.format.clone(),
        recon_images: recon.model.as_ref().map_or(0, |m| m.images.len() as u64),
        gt_name: dataset.name.clone(),
        gt_format: dataset.loaded.format.name().into(),
        notes,
    };
    let points = std::mem::take(&mut recon.cloud.points);
    recon.cloud.colors = None;
    let measured = measure(gt, points, alignment.gt_from_recon, &request.eval, progress)?;
    let mut extras = Extras::default();
    if let (Some(g), Some(e), Some(m), None) = (gt_cameras, &recon.model, &matches, &no_match) {
        extras.cameras = Some(camera_section(
            g,
            e,
            m,
            &pairs,
            &alignment,
            request,
            &mut extras.notes,
        )?);
    }
    if let Some(views) = dataset.views() {
        add_visibility(&mut extras, &measured, gt, views, request, progress);
        match (gt_cameras, &recon.model) {
            (Some(_), Some(_)) if !recon.cloud_is_model_points => extras.notes.push(Note::new(
                Code::NoTrackError,
                "depth maps were given but the evaluated cloud is not the SfM model's own points: no track-based error",
            )),
            (Some(g), Some(e)) if e.points.iter().any(|p| !p.track.is_empty()) => {
                add_track_error(&mut extras, &measured, g, e, views, &alignment, request, progress)?;
            }
            _ => extras.notes.push(Note::new(
                Code::NoTrackError,
                "depth maps were given but the reconstruction has no tracks (or no ground-truth cameras): no track-based error",
            )),
        }
    }
    Ok(measured.into_evaluation(gt, &request.eval, &info, &alignment, extras))
}

/// Runs the requested alignment (none, the given transform, or the stages).
fn align_recon(
    gt: &PreparedGroundTruth,
    recon: &ReconInput,
    pairs: &[CameraPair],
    no_match: Option<&str>,
    have_gt_cameras: bool,
    request: &EvalRequest,
    progress: &dyn Progress,
) -> Result<Alignment> {
    let a = &request.align;
    let Some((method, refine)) = a.mode.stages() else {
        return Ok(match (a.mode, a.transform) {
            (AlignMode::Given, Some(t)) => Alignment::given(t),
            _ => Alignment::none(),
        });
    };
    if a.mode.needs_cameras() && pairs.is_empty() {
        return Err(cameras_unavailable(have_gt_cameras, recon, no_match));
    }
    progress.start(Stage::Alignment, 1);
    // The stages read `f64` points (a widened copy of an `f32` cloud while they run).
    let points = recon.cloud.points.as_f64();
    let input = AlignInput {
        recon: &points,
        cameras: pairs,
        point_pairs: &a.pairs,
        start: a.transform,
    };
    let opts = AlignOptions {
        refine,
        ..AlignOptions::default()
    }
    .with_seed(request.eval.seed);
    let mut alignment = align::align(gt, &input, method, &opts)?;
    progress.finish();
    if let (AlignMethod::Auto, Some(detail)) = (method, no_match)
        && let Some(first) = alignment.stages.first_mut()
    {
        let fell_back = align::fell_back(first.kind.name());
        first.prepend_notes(vec![
            Note::new(
                Code::StageFailed,
                format!("the camera-based alignment was skipped: {detail}"),
            )
            .with("stage", "cameras"),
            fell_back,
        ]);
    }
    alignment.requested = a.mode;
    Ok(alignment)
}

/// The pose errors of the matched cameras, measured after the camera alignment whatever the
/// points were aligned by (as ATE aligns the trajectory itself): the camera stage's transform
/// when one ran, else the same camera alignment run for the poses alone (so `given`, `icp` and
/// `global` report the pose errors `auto` reports). The point refinement may move the scale by
/// the SfM's own camera/point inconsistency (e.g. a focal error), which the point metrics then
/// show. Only when the cameras cannot be aligned (fewer than 3 usable pairs) are the poses
/// measured after the final transform; `cameras.alignment.stage` names the transform used.
fn camera_section(
    gt_cameras: &Reconstruction,
    est: &Reconstruction,
    matches: &model::matching::ImageMatches,
    pairs: &[CameraPair],
    alignment: &Alignment,
    request: &EvalRequest,
    notes: &mut Vec<Note>,
) -> Result<CamerasSection> {
    let (t, used) = match alignment.stage(StageKind::Cameras) {
        Some(stage) => (stage.gt_from_recon, StageKind::Cameras.name().to_string()),
        None => {
            let opts = AlignOptions::default().with_seed(request.eval.seed);
            match align::align_cameras(pairs, &opts.cameras) {
                Ok((t, _)) => (t, StageKind::Cameras.name().to_string()),
                Err(_) => (alignment.gt_from_recon, alignment.method()),
            }
        }
    };
    let errors = evaluate_cameras_matched(gt_cameras, est, matches, &t, &request.pose)?;
    if used != StageKind::Cameras.name() {
        notes.push(
            Note::new(
                Code::PosesAfterFinalTransform,
                format!(
                    "the cameras could not be aligned on their own (fewer than 3 usable camera pairs): the pose errors are measured after the final transform ({used})"
                ),
            )
            .with("transform", used.as_str()),
        );
    }
    notes.extend(errors.notes.iter().map(|n| n.clone().prefixed("cameras: ")));
    Ok(CamerasSection {
        errors,
        alignment: CamerasAlignment {
            stage: used,
            gt_from_recon: t.matrix,
            scale: t.scale(),
        },
    })
}

/// "none of the N estimated image(s) matches one of the M ground-truth image names (e.g. ...)".
fn no_match_detail(gt: &Reconstruction, est: &Reconstruction) -> String {
    let example = match (gt.images.first(), est.images.first()) {
        (Some(g), Some(e)) => format!(" (e.g. ground truth '{}', estimate '{}')", g.name, e.name),
        _ => String::new(),
    };
    format!(
        "none of the {} estimated image(s) matches one of the {} ground-truth image names{example}",
        est.images.len(),
        gt.images.len()
    )
}

/// Why the `cameras` stage has no camera pair to work from.
fn cameras_unavailable(have_gt_cameras: bool, recon: &ReconInput, no_match: Option<&str>) -> Error {
    if !have_gt_cameras {
        return Error::InvalidOption(
            "the cameras alignment needs the ground-truth cameras (cameras.json)".into(),
        );
    }
    if recon.model.is_none() {
        return Error::InvalidOption(format!(
            "the cameras alignment needs a reconstruction with cameras; '{}' is a bare point cloud",
            recon.name
        ));
    }
    match no_match {
        Some(detail) => Error::Geometry(format!("cameras alignment: {detail}")),
        None => Error::Geometry("cameras alignment: no matched camera".into()),
    }
}

/// The visible completeness: which completeness samples the ground-truth images see, and the
/// recall over those.
fn add_visibility(
    extras: &mut Extras,
    measured: &Measured,
    gt: &PreparedGroundTruth,
    views: &[GtView],
    request: &EvalRequest,
    progress: &dyn Progress,
) {
    let min_views = request.eval.min_views;
    progress.start(Stage::Visibility, measured.completeness_points.len() as u64);
    let counts = visibility::count_views(views, &measured.completeness_points, progress);
    progress.finish();
    let whole_surface = request.eval.crop.volume.is_none() && gt.area > 0.0;
    let (section, warning) = visibility::visible_completeness(
        &counts,
        &measured.completeness_distances,
        &measured.scores,
        min_views,
        views.len(),
        whole_surface.then_some(gt.area),
        request.eval.histogram_bins,
    );
    extras.notes.extend(warning);
    extras.min_views = Some(u64::from(min_views));
    extras.sample_labels = Some(visibility::labels(
        &counts,
        &measured.completeness_distances,
        min_views,
        section.labels_tau,
    ));
    extras.completeness_visible = Some(section);
    extras.sample_views = Some(counts);
}

/// The track-based true error of the model's points (the evaluated cloud is the model's points
/// in order, `Reconstruction::to_point_cloud`).
#[allow(clippy::too_many_arguments)]
fn add_track_error(
    extras: &mut Extras,
    measured: &Measured,
    gt_cameras: &Reconstruction,
    est: &Reconstruction,
    views: &[GtView],
    alignment: &Alignment,
    request: &EvalRequest,
    progress: &dyn Progress,
) -> Result<()> {
    if views.len() != gt_cameras.images.len() {
        return Err(Error::InvalidOption(format!(
            "{} ground-truth views for {} ground-truth images: build the views from the same cameras",
            views.len(),
            gt_cameras.images.len()
        )));
    }
    let matches = model::matching::match_images(gt_cameras, est);
    let mut view_of_image: Vec<Option<usize>> = vec![None; est.images.len()];
    for &(g, e) in &matches.pairs {
        if let Some(slot) = view_of_image.get_mut(e) {
            *slot = Some(g);
        }
    }
    progress.start(Stage::TrackError, est.points.len() as u64);
    let (convention, outcomes) = track_error::track_errors(
        est,
        views,
        &view_of_image,
        &alignment.gt_from_recon,
        progress,
    );
    progress.finish();
    if outcomes.len() != measured.distances.len() {
        extras.notes.push(
            Note::new(
                Code::NoTrackError,
                format!(
                    "track error skipped: the model has {} points but {} were evaluated",
                    outcomes.len(),
                    measured.distances.len()
                ),
            )
            .with("model_points", outcomes.len())
            .with("evaluated", measured.distances.len()),
        );
        return Ok(());
    }
    let kept: Vec<bool> = measured
        .status
        .iter()
        .map(|s| *s == PointStatus::Kept)
        .collect();
    let (section, warning) = track_error::aggregate(
        convention,
        &outcomes,
        &measured.distances,
        &kept,
        &measured.thresholds.taus,
        request.eval.histogram_bins,
    );
    extras.notes.extend(warning);
    extras.track_error = Some(section);
    extras.track_errors = Some(outcomes.iter().map(|o| o.true_error).collect());
    Ok(())
}

/// Camera-pose metrics without a ground-truth geometry: aligns by the matched camera centres
/// (LO-RANSAC, rotations when the centres are nearly collinear), or uses `given`.
pub fn cameras_only(
    gt_cameras: &Reconstruction,
    recon: &Reconstruction,
    given: Option<Similarity>,
    seed: u64,
    pose: &PoseOptions,
) -> Result<(
    Similarity,
    crate::report::AlignmentReport,
    crate::pose::CamerasReport,
)> {
    let (pairs, matches) = camera_pairs(gt_cameras, recon);
    if pairs.is_empty() && given.is_none() {
        return Err(Error::Geometry(format!(
            "cameras alignment: {}",
            no_match_detail(gt_cameras, recon)
        )));
    }
    let alignment = match given {
        Some(t) => Alignment::given(t),
        None => {
            let opts = AlignOptions::default().with_seed(seed);
            let (t, stage) = align::align_cameras(&pairs, &opts.cameras)?;
            Alignment {
                gt_from_recon: t,
                stages: vec![stage],
                requested: AlignMode::Cameras,
            }
        }
    };
    let t = alignment.gt_from_recon;
    let cams = evaluate_cameras_matched(gt_cameras, recon, &matches, &t, pose)?;
    Ok((t, alignment.report(), cams))
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::*;
    use crate::geometry::{GroundTruth, TriangleMesh};
    use crate::gt_views::test_scenes::{add_observed_point, look_at, render, sphere};
    use crate::model::{Camera, Image};
    use crate::progress::NoProgress;

    /// A UV sphere of radius 1 (sag below 3e-4, far below the depth tolerance).
    fn uv_sphere(n_lon: usize, n_lat: usize) -> TriangleMesh {
        let mut vertices = Vec::new();
        for i in 0..=n_lat {
            let lat = std::f64::consts::PI * (i as f64 / n_lat as f64 - 0.5);
            for j in 0..n_lon {
                let lon = 2.0 * std::f64::consts::PI * j as f64 / n_lon as f64;
                vertices.push([lat.cos() * lon.cos(), lat.sin(), lat.cos() * lon.sin()]);
            }
        }
        let mut triangles = Vec::new();
        for i in 0..n_lat {
            for j in 0..n_lon {
                let a = (i * n_lon + j) as u32;
                let b = (i * n_lon + (j + 1) % n_lon) as u32;
                let c = a + n_lon as u32;
                let d = b + n_lon as u32;
                triangles.push([a, c, b]);
                triangles.push([b, c, d]);
            }
        }
        TriangleMesh {
            vertices,
            triangles,
        }
    }

    #[test]
    fn run_with_views_adds_visible_completeness_and_track_error() {
        // 36 cameras on the equator at distance 2: the visible band is |latitude| < 60°, area
        // fraction sin 60° (see the visibility tests). The reconstruction: points on the sphere
        // with exact observations in every camera that sees them, named like the GT images.
        let hit = sphere([0.0; 3], 1.0);
        let mut gt_cams = Reconstruction::new("cameras_json");
        let mut cam = Camera::simple(1, "PINHOLE", 300.0, 240.0, 240.0);
        cam.width = 480;
        cam.height = 480;
        gt_cams.cameras.push(cam);
        let mut views = Vec::new();
        for k in 0..36 {
            let phi = 2.0 * std::f64::consts::PI * k as f64 / 36.0;
            let c = [2.0 * phi.cos(), 0.0, 2.0 * phi.sin()];
            let mut v = render(look_at(c, [0.0; 3]), 300.0, 480, 480, &hit);
            v.name = format!("{k:04}.png");
            gt_cams.images.push(Image {
                id: k + 1,
                name: v.name.clone(),
                camera_id: 1,
                cam_from_world: v.cam_from_world,
                observations: vec![],
            });
            views.push(v);
        }
        let mut est = gt_cams.clone();
        est.format = "colmap";
        for im in &mut est.images {
            im.name = format!("images/{}", im.name.replace(".png", ".PNG"));
        }
        let mut rng_state = 1u64;
        let mut next = || {
            rng_state = rng_state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (rng_state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..400 {
            let (lat, lon): (f64, f64) = ((next() - 0.5) * 1.6, next() * std::f64::consts::TAU);
            let x = [lat.cos() * lon.cos(), lat.sin(), lat.cos() * lon.sin()];
            add_observed_point(&mut est, &views, x);
        }
        let recon = ReconInput {
            cloud: est.to_point_cloud(),
            model: Some(est),
            name: "synthetic".into(),
            format: "colmap".into(),
            notes: vec![],
            cloud_is_model_points: true,
        };
        let gt = GroundTruth::Mesh(uv_sphere(128, 64));
        let options = EvalRequest {
            eval: EvalOptions {
                samples: 20_000,
                tau: vec![0.01, 0.05],
                ..EvalOptions::default()
            },
            align: AlignRequest::none(),
            ..EvalRequest::default()
        };
        let mut with_views = dataset(gt.clone(), Some(gt_cams.clone()), Some(views));
        let e = run(&mut with_views, &recon, &options, &NoProgress).unwrap();
        let vis = e.report.completeness_visible.as_ref().unwrap();
        assert_eq!((vis.views, vis.min_views, vis.samples), (36, 2, 20_000));
        let expected = 3f64.sqrt() / 2.0;
        assert!(
            (vis.visible_fraction - expected).abs() < 0.01,
            "{}",
            vis.visible_fraction
        );
        assert_eq!(e.report.options.min_views, Some(2));
        assert_eq!(e.sample_labels.as_ref().unwrap().len(), 20_000);
        assert_eq!(vis.labels_tau, 0.01);
        // Recall over the visible part is higher: the points cover |lat| < 46° only.
        assert!(vis.thresholds[1].recall_visible > vis.thresholds[1].recall);
        let te = e.report.track_error.as_ref().unwrap();
        assert_eq!(te.points, 400);
        assert!(te.measured >= 395, "{}", te.measured);
        assert_eq!(te.rejected_unmatched_image, 0);
        assert!(te.stats.max < 2e-3, "{}", te.stats.max);
        assert_eq!(te.thresholds[0].sliding_fraction, 0.0);
        assert_eq!(e.track_errors.as_ref().unwrap().len(), 400);
        let json = e.report.to_json();
        assert!(json.contains("\"completeness_visible\"") && json.contains("\"track_error\""));
        // Without views, nothing changes in the report shape.
        let mut plain_dataset = dataset(gt, Some(gt_cams), None);
        let plain = run(&mut plain_dataset, &recon, &options, &NoProgress).unwrap();
        assert!(plain.report.completeness_visible.is_none() && plain.report.track_error.is_none());
        assert!(!plain.report.to_json().contains("completeness_visible"));
        // A cloud that is not the model's own points (a PLY with the model's cameras): the
        // tracks do not line up with the evaluated points, so no track error.
        let ply_like = ReconInput {
            cloud_is_model_points: false,
            ..recon.clone()
        };
        let e = run(&mut with_views, &ply_like, &options, &NoProgress).unwrap();
        assert!(e.report.track_error.is_none() && e.report.completeness_visible.is_some());
        assert!(
            e.report
                .notes
                .iter()
                .any(|w| w.message.contains("not the SfM model's own points")),
            "{:?}",
            e.report.notes
        );
    }

    use crate::model::fuzz_tests::fixture;

    /// theia.ply with its camera centres in a colour that is no OpenMVG marker.
    fn theia_ply_recoloured() -> Vec<u8> {
        let text = String::from_utf8(fixture("theia.ply")).unwrap();
        let out = text.replace(" 255   0   0", " 10 200 30");
        assert_eq!(out.matches(" 10 200 30").count(), 6);
        out.into_bytes()
    }

    #[test]
    fn ply_beside_a_model_is_stripped_at_the_model_camera_centres() {
        let ply = theia_ply_recoloured();
        // Alone, the recoloured centres are not recognised (no marker colour, no cameras).
        let alone = read_reconstruction(
            "points.ply",
            &BTreeMap::from([("points.ply".to_string(), ply.clone())]),
        )
        .unwrap();
        assert_eq!(alone.cloud.points.len(), 107);
        assert!(alone.model.is_none() && alone.notes.is_empty());
        // Beside the Theia NVM (a Theia output folder), or with the model given separately.
        let folder = BTreeMap::from([
            ("reconstruction.nvm".to_string(), fixture("theia.nvm")),
            ("points.ply".to_string(), ply.clone()),
        ]);
        let nvm = model::read_model_files(&BTreeMap::from([(
            "theia.nvm".to_string(),
            fixture("theia.nvm"),
        )]))
        .unwrap();
        let files = BTreeMap::from([("points.ply".to_string(), ply)]);
        for r in [
            read_reconstruction("theia_out", &folder).unwrap(),
            read_reconstruction_with_cameras("points.ply", &files, nvm, "theia.nvm").unwrap(),
        ] {
            assert_eq!(r.cloud.points.len(), 101, "{:?}", r.notes);
            assert_eq!(r.format, "ply+nvm");
            assert!(!r.cloud_is_model_points);
            assert_eq!(r.model.as_ref().unwrap().images.len(), 6);
            assert!(
                r.notes.iter().any(|w| w
                    .message
                    .contains("removed 6 point(s) at the 6 known camera centre(s)")),
                "{:?}",
                r.notes
            );
            let colors = r.cloud.colors.unwrap();
            assert!(colors.iter().all(|c| *c != [10, 200, 30]));
        }
    }

    #[test]
    fn ambiguous_or_wrong_cloud_files_are_errors() {
        let folder = BTreeMap::from([
            ("reconstruction.nvm".to_string(), fixture("theia.nvm")),
            ("a.ply".to_string(), fixture("theia.ply")),
            ("b.ply".to_string(), fixture("openmvg.ply")),
        ]);
        let e = read_reconstruction("out", &folder).unwrap_err().to_string();
        assert!(e.contains("2 PLY files (a.ply, b.ply)"), "{e}");
        let nvm = model::read_model_files(&BTreeMap::from([(
            "theia.nvm".to_string(),
            fixture("theia.nvm"),
        )]))
        .unwrap();
        let model_files = BTreeMap::from([("colmap38.nvm".to_string(), fixture("colmap38.nvm"))]);
        let e = read_reconstruction_with_cameras("m", &model_files, nvm, "theia.nvm")
            .unwrap_err()
            .to_string();
        assert!(e.contains("is an SfM model"), "{e}");
        // An SfM model with nothing in it.
        let header = "# Camera list\n";
        let empty = BTreeMap::from([
            (
                "cameras.txt".to_string(),
                fixture("colmap_text/cameras.txt"),
            ),
            ("images.txt".to_string(), header.as_bytes().to_vec()),
            ("points3D.txt".to_string(), header.as_bytes().to_vec()),
        ]);
        let e = read_reconstruction("empty", &empty)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no registered image and no 3D point"), "{e}");
    }

    /// A dataset of `gt` with these cameras and views.
    fn dataset(
        gt: GroundTruth,
        cameras: Option<Reconstruction>,
        views: Option<Vec<GtView>>,
    ) -> Dataset {
        let loaded = crate::io::LoadedGroundTruth {
            ground_truth: gt,
            format: crate::io::Format::Ply,
            notes: vec![],
        };
        let mut d = Dataset::new("gt.ply", loaded);
        d.set_cameras(cameras);
        if let Some(v) = views {
            d.set_views(v);
        }
        d
    }

    fn err_of(r: Result<Evaluation>) -> String {
        match r {
            Ok(_) => panic!("expected an error"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn no_image_name_in_common_skips_the_camera_stage_and_pose_metrics() {
        // GT cameras named 0000.png...; the model's images are named differently.
        let mut gt_cams = Reconstruction::new("cameras_json");
        gt_cams
            .cameras
            .push(Camera::simple(1, "PINHOLE", 300.0, 240.0, 240.0));
        let mut points = Vec::new();
        for k in 0..8u64 {
            let phi = std::f64::consts::TAU * k as f64 / 8.0;
            let c = [3.0 * phi.cos(), 0.5 * (k % 2) as f64, 3.0 * phi.sin()];
            gt_cams.images.push(Image {
                id: k + 1,
                name: format!("{k:04}.png"),
                camera_id: 1,
                cam_from_world: look_at(c, [0.0; 3]),
                observations: vec![],
            });
        }
        for i in 0..400 {
            let (lat, lon) = ((i as f64 * 0.618).fract() * 2.8 - 1.4, i as f64 * 2.399_963);
            points.push(crate::model::Point3D {
                xyz: [lat.cos() * lon.cos(), lat.sin(), lat.cos() * lon.sin()],
                color: None,
                error: None,
                track: vec![],
            });
        }
        let mut est = gt_cams.clone();
        est.format = "colmap";
        for im in &mut est.images {
            im.name = format!("other_{}", im.name);
        }
        est.points = points;
        let recon = ReconInput {
            cloud: est.to_point_cloud(),
            model: Some(est),
            name: "renamed".into(),
            format: "colmap".into(),
            notes: vec![],
            cloud_is_model_points: true,
        };
        let gt = GroundTruth::Mesh(uv_sphere(32, 16));
        let mut with_cameras = dataset(gt.clone(), Some(gt_cams.clone()), None);
        let mut without_cameras = dataset(gt, None, None);
        let options = |align: &str| EvalRequest {
            eval: EvalOptions {
                samples: 2_000,
                ..EvalOptions::default()
            },
            align: AlignRequest::mode(AlignMode::parse(align).unwrap()),
            ..EvalRequest::default()
        };
        let e = run(&mut with_cameras, &recon, &options("auto"), &NoProgress).unwrap();
        assert!(e.report.cameras.is_none());
        let w = &e.report.notes;
        assert!(
            w.iter().any(|w| w.code == Code::NoImageInCommon
                && w.message
                    .starts_with("cameras: none of the 8 estimated image(s)")
                && w.message.contains("'other_0000.png'")),
            "{w:?}"
        );
        assert!(
            w.iter().any(|w| w.code == Code::StageFailed
                && w.message.contains("skipped")
                && w.values["stage"] == "cameras"),
            "{w:?}"
        );
        assert!(
            w.iter()
                .any(|w| w.code == Code::FellBack && w.values["to"] == "global"),
            "{w:?}"
        );
        assert_eq!(e.report.alignment.method, "global+icp");
        for method in ["cameras", "cameras+icp"] {
            let err = err_of(run(
                &mut with_cameras,
                &recon,
                &options(method),
                &NoProgress,
            ));
            assert!(
                err.contains("none of the 8 estimated image(s) matches"),
                "{err}"
            );
        }
        // Without GT cameras, or with a bare cloud, `cameras` says what is missing.
        let err = err_of(run(
            &mut without_cameras,
            &recon,
            &options("cameras"),
            &NoProgress,
        ));
        assert!(err.contains("needs the ground-truth cameras"), "{err}");
        let bare = ReconInput {
            model: None,
            ..recon.clone()
        };
        let err = err_of(run(
            &mut with_cameras,
            &bare,
            &options("cameras"),
            &NoProgress,
        ));
        assert!(err.contains("'renamed' is a bare point cloud"), "{err}");
        // `sfmeval cameras` (cameras_only) names the mismatch too.
        let err = cameras_only(
            &gt_cams,
            recon.model.as_ref().unwrap(),
            None,
            0,
            &PoseOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("none of the 8 estimated image(s) matches"),
            "{err}"
        );
    }
}
