//! Track-based ("true") error of reconstructed points. Each 2D observation of a point is
//! back-projected through its image's ground-truth camera onto the ground-truth depth map: that
//! is the surface point the feature actually was. The robust mean of a track's back-projections
//! is where the point should be; its distance to the aligned reconstructed point is the point's
//! true error. A point can lie on the surface (nearest-surface distance ≈ 0) and still be far
//! from where it should be: it *slid* along the surface. Sliding points are those whose true
//! error exceeds their surface distance by more than a threshold.
//!
//! - Observations are first brought to COLMAP pixels ([`ObservationConvention`]): COLMAP and
//!   OpenMVG readers already give them; Bundler's are relative to the principal point with y up;
//!   NVM's are relative to the principal point per the VisualSfM spec but absolute in COLMAP's
//!   export, told apart by the presence of negative coordinates.
//! - Depth at a sub-pixel position: inverse-depth bilinear interpolation of the 2×2 pixel
//!   neighbourhood, only when all four pixels hold a depth and their spread is below
//!   `DISCONTINUITY_RELATIVE · z + DISCONTINUITY_FOOTPRINTS · z / f`; otherwise the observation
//!   is rejected (it sits on a silhouette or a depth step, where its surface point is ambiguous).
//! - Robust mean: the coordinate-wise median seeds it; back-projections farther from the median
//!   than `max(TRIM_FACTOR · median distance, TRIM_FOOTPRINTS · median footprint)` are trimmed;
//!   the mean of the rest (in track order) is the truth. A point needs
//!   [`MIN_OBSERVATIONS`] kept back-projections to be measured.

use serde::Serialize;

use crate::geometry::{Point3, norm, sub};
use crate::gt_views::GtView;
use crate::metrics::share_below;
use crate::model::Reconstruction;
use crate::note::{Code, Note};
use crate::parallel;
use crate::progress::Progress;
use crate::report::{SlidingThresholdReport, TrackErrorReport};
use crate::stats::Statistics;
use crate::transform::Similarity;

/// Relative part of the depth spread that counts as a discontinuity.
pub(crate) const DISCONTINUITY_RELATIVE: f64 = 0.005;
/// Footprint part of the depth spread that counts as a discontinuity (pixel footprints).
pub(crate) const DISCONTINUITY_FOOTPRINTS: f64 = 6.0;
/// Back-projections farther than this many median distances from the median are trimmed.
pub(crate) const TRIM_FACTOR: f64 = 3.0;
/// ... but never closer than this many pixel footprints.
pub(crate) const TRIM_FOOTPRINTS: f64 = 3.0;
/// Kept back-projections a point needs to be measured.
pub(crate) const MIN_OBSERVATIONS: usize = 2;

/// How a reconstruction's `Observation::xy` relate to COLMAP pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum ObservationConvention {
    /// Already COLMAP pixels (COLMAP, OpenMVG after the reader's +0.5, NVM from COLMAP).
    ColmapPixels,
    /// Relative to the principal point, y down (VisualSfM NVM).
    CenteredYDown,
    /// Relative to the principal point, y up (Bundler).
    CenteredYUp,
}

impl ObservationConvention {
    /// The name written in reports.
    pub(crate) fn name(self) -> &'static str {
        match self {
            ObservationConvention::ColmapPixels => "colmap_pixels",
            ObservationConvention::CenteredYDown => "centered_y_down",
            ObservationConvention::CenteredYUp => "centered_y_up",
        }
    }

    /// The convention of a model's observations, from its format (and, for NVM, the signs).
    pub(crate) fn of(rec: &Reconstruction) -> ObservationConvention {
        match rec.format {
            "bundler" => ObservationConvention::CenteredYUp,
            "nvm" => {
                let negative = rec
                    .images
                    .iter()
                    .flat_map(|im| &im.observations)
                    .any(|o| o.xy[0] < 0.0 || o.xy[1] < 0.0);
                if negative {
                    ObservationConvention::CenteredYDown
                } else {
                    ObservationConvention::ColmapPixels
                }
            }
            _ => ObservationConvention::ColmapPixels,
        }
    }

    /// `xy` in COLMAP pixels of `view`.
    pub(crate) fn to_pixels(self, xy: [f64; 2], view: &GtView) -> (f64, f64) {
        match self {
            ObservationConvention::ColmapPixels => (xy[0], xy[1]),
            ObservationConvention::CenteredYDown => (view.cx + xy[0], view.cy + xy[1]),
            ObservationConvention::CenteredYUp => (view.cx + xy[0], view.cy - xy[1]),
        }
    }
}

/// Why an observation gave no back-projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Rejection {
    /// Its pixel lies outside the ground-truth image.
    OutsideImage,
    /// A pixel of its neighbourhood is background (a silhouette).
    Background,
    /// Its neighbourhood straddles a depth step.
    Discontinuity,
}

impl Rejection {
    /// The slot of [`PointOutcome::rejected`] counting observations whose image has no
    /// ground-truth image of the same name (they never reach a back-projection).
    const UNMATCHED_IMAGE: usize = 0;

    /// This reason's slot of [`PointOutcome::rejected`].
    fn slot(self) -> usize {
        match self {
            Rejection::OutsideImage => 1,
            Rejection::Background => 2,
            Rejection::Discontinuity => 3,
        }
    }
}

/// The ground-truth surface point seen through pixel position `(u, v)` of `view`, with the
/// pixel footprint there.
pub(crate) fn back_project(view: &GtView, u: f64, v: f64) -> Result<(Point3, f64), Rejection> {
    let n = view.neighbourhood(u, v).ok_or(Rejection::OutsideImage)?;
    let d = n.interpolated().ok_or(Rejection::Background)?;
    let footprint = d / view.focal();
    if n.spread() > DISCONTINUITY_RELATIVE * d + DISCONTINUITY_FOOTPRINTS * footprint {
        return Err(Rejection::Discontinuity);
    }
    Ok((view.back_project(u, v, d), footprint))
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_unstable_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// Median-seeded trimmed mean of `points` (see the module doc); `footprint` is the scale below
/// which nothing is trimmed. Returns the mean and how many points it kept.
pub(crate) fn robust_mean(points: &[Point3], footprint: f64) -> Option<(Point3, usize)> {
    if points.is_empty() {
        return None;
    }
    let mut m = [0.0; 3];
    for (k, mk) in m.iter_mut().enumerate() {
        let mut c: Vec<f64> = points.iter().map(|p| p[k]).collect();
        *mk = median(&mut c);
    }
    let dist: Vec<f64> = points.iter().map(|p| norm(sub(*p, m))).collect();
    let mut sorted = dist.clone();
    let limit = (TRIM_FACTOR * median(&mut sorted)).max(TRIM_FOOTPRINTS * footprint);
    let mut sum = [0.0; 3];
    let mut kept = 0usize;
    for (p, d) in points.iter().zip(&dist) {
        if *d <= limit {
            for k in 0..3 {
                sum[k] += p[k];
            }
            kept += 1;
        }
    }
    (kept > 0).then(|| (sum.map(|s| s / kept as f64), kept))
}

/// The report section of the measured points: `outcomes` of every model point (in point order),
/// with their nearest-surface `distances` and crop `kept` flags in the same order, at the
/// evaluation's thresholds `taus` (ground-truth units). Returns the section and a warning when
/// no point could be measured.
pub(crate) fn aggregate(
    convention: ObservationConvention,
    outcomes: &[PointOutcome],
    distances: &[f64],
    kept: &[bool],
    taus: &[f64],
    bins: usize,
) -> (TrackErrorReport, Option<Note>) {
    let mut errors = Vec::new();
    let mut surface = Vec::new();
    let mut sums = [0u64; 7];
    let mut kept_points = 0u64;
    for ((o, d), k) in outcomes.iter().zip(distances).zip(kept) {
        if !*k {
            continue;
        }
        kept_points += 1;
        sums[0] += u64::from(o.observations);
        sums[1] += u64::from(o.used);
        sums[2] += u64::from(o.trimmed);
        for k in 0..4 {
            sums[3 + k] += u64::from(o.rejected[k]);
        }
        if let Some(e) = o.true_error {
            errors.push(e);
            surface.push(*d);
        }
    }
    let n = errors.len().max(1) as f64;
    let thresholds = taus
        .iter()
        .map(|&tau| SlidingThresholdReport {
            tau,
            sliding_fraction: errors
                .iter()
                .zip(&surface)
                .filter(|(e, s)| **e - **s > tau)
                .count() as f64
                / n,
            true_error_below: share_below(&errors, tau),
        })
        .collect();
    let warning = errors.is_empty().then(|| {
        Note::new(
            Code::NoTrackMeasured,
            "no reconstructed point could be measured against its track (no image matched by name, or every observation fell on a silhouette)",
        )
    });
    let report = TrackErrorReport {
        direction: "reconstruction_to_track_truth".into(),
        observation_convention: convention.name().into(),
        min_observations: MIN_OBSERVATIONS as u64,
        points: kept_points,
        measured: errors.len() as u64,
        observations: sums[0],
        observations_used: sums[1],
        observations_trimmed: sums[2],
        rejected_unmatched_image: sums[3],
        rejected_outside_image: sums[4],
        rejected_background: sums[5],
        rejected_discontinuity: sums[6],
        stats: Statistics::of(&errors, bins),
        surface_distance: Statistics::of(&surface, bins),
        thresholds,
    };
    (report, warning)
}

/// The outcome for one 3D point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct PointOutcome {
    /// Where the point should be (ground-truth frame), when measured.
    pub truth_in_gt: Option<Point3>,
    /// Its true error (distance of the aligned point to the truth), when measured.
    pub true_error: Option<f64>,
    /// Observations of the point.
    pub observations: u32,
    /// Back-projections kept by the robust mean.
    pub used: u32,
    /// Back-projections trimmed as outliers.
    pub trimmed: u32,
    /// Rejected: image without ground truth, outside, background, discontinuity.
    pub rejected: [u32; 4],
}

/// The observations of one 3D point: (image index, `Observation::xy`).
type PointObservations = Vec<(usize, [f64; 2])>;

/// Track errors of every 3D point of `recon` (in point order). `view_of_image[i]` is the
/// ground-truth view of `recon.images[i]` (by name), `gt_from_recon` the alignment.
pub(crate) fn track_errors(
    recon: &Reconstruction,
    views: &[GtView],
    view_of_image: &[Option<usize>],
    gt_from_recon: &Similarity,
    progress: &dyn Progress,
) -> (ObservationConvention, Vec<PointOutcome>) {
    let convention = ObservationConvention::of(recon);
    // Observations per point, in image order then observation order.
    let mut per_point: Vec<PointObservations> = vec![Vec::new(); recon.points.len()];
    for (i, im) in recon.images.iter().enumerate() {
        for o in &im.observations {
            if let Some(list) = o.point.and_then(|p| per_point.get_mut(p)) {
                list.push((i, o.xy));
            }
        }
    }
    let indexed: Vec<(usize, &PointObservations)> = per_point.iter().enumerate().collect();
    let outcomes = parallel::map(&indexed, progress, |&(p, obs)| {
        let mut out = PointOutcome {
            observations: obs.len() as u32,
            ..PointOutcome::default()
        };
        let mut hits = Vec::with_capacity(obs.len());
        let mut footprints = Vec::with_capacity(obs.len());
        for &(image, xy) in obs {
            let Some(view) = view_of_image
                .get(image)
                .copied()
                .flatten()
                .and_then(|v| views.get(v))
            else {
                out.rejected[Rejection::UNMATCHED_IMAGE] += 1;
                continue;
            };
            let (u, v) = convention.to_pixels(xy, view);
            match back_project(view, u, v) {
                Ok((x, f)) => {
                    hits.push(x);
                    footprints.push(f);
                }
                Err(r) => {
                    out.rejected[r.slot()] += 1;
                }
            }
        }
        let footprint = median(&mut footprints);
        if let Some((truth, kept)) = robust_mean(&hits, footprint) {
            out.used = kept as u32;
            out.trimmed = (hits.len() - kept) as u32;
            if kept >= MIN_OBSERVATIONS {
                let xyz = recon.points.get(p).map_or([f64::NAN; 3], |q| q.xyz);
                let aligned = gt_from_recon.apply(xyz);
                out.truth_in_gt = Some(truth);
                out.true_error = Some(norm(sub(aligned, truth)));
            }
        }
        out
    });
    (convention, outcomes)
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::*;
    use crate::gt_views::test_scenes::*;
    use crate::model::{Camera, Image};
    use crate::progress::NoProgress;

    /// A recon equal to the ground truth: 8 cameras around a unit sphere, points on the sphere,
    /// observations by exact projection. Back-projections through the float32 depth maps of a
    /// curved surface are exact to a small part of the pixel footprint (≈ 0.007 here); "zero"
    /// below means under 1e-3, 0.15 footprints.
    fn scene(points: &[Point3]) -> (Vec<GtView>, Reconstruction) {
        let hit = sphere([0.0; 3], 1.0);
        let mut views = Vec::new();
        let mut rec = Reconstruction::new("colmap");
        rec.cameras
            .push(Camera::simple(1, "PINHOLE", 300.0, 160.0, 120.0));
        for k in 0..8 {
            let a = k as f64 * std::f64::consts::PI / 12.0 - 0.9;
            let c = [3.0 * a.sin(), 0.8, 3.0 * a.cos()];
            let mut v = render(look_at(c, [0.0; 3]), 300.0, 320, 240, &hit);
            v.name = format!("{k:04}.jpg");
            rec.images.push(Image {
                id: k as u64 + 1,
                name: v.name.clone(),
                camera_id: 1,
                cam_from_world: v.cam_from_world,
                observations: vec![],
            });
            views.push(v);
        }
        for p in points {
            add_observed_point(&mut rec, &views, *p);
        }
        (views, rec)
    }

    fn on_sphere(lat: f64, lon: f64) -> Point3 {
        let (lat, lon) = (lat.to_radians(), lon.to_radians());
        [lat.cos() * lon.sin(), lat.sin(), lat.cos() * lon.cos()]
    }

    #[test]
    fn exact_tracks_have_zero_error_and_a_slid_point_its_shift() {
        let pts: Vec<Point3> = (0..20)
            .map(|k| on_sphere(-20.0 + 2.0 * k as f64, -30.0 + 3.0 * k as f64))
            .collect();
        let (views, mut rec) = scene(&pts);
        let view_of: Vec<Option<usize>> = (0..views.len()).map(Some).collect();
        let (conv, out) = track_errors(&rec, &views, &view_of, &Similarity::IDENTITY, &NoProgress);
        assert_eq!(conv, ObservationConvention::ColmapPixels);
        for o in &out {
            let e = o.true_error.expect("measured");
            assert!(e < 1e-3, "exact track error {e}");
            assert!(o.used >= 3);
        }
        // Slide point 3 along the sphere by 5° of latitude (surface distance stays 0): its
        // true error is the chord 2 sin(2.5°).
        let moved = on_sphere(-20.0 + 6.0 + 5.0, -30.0 + 9.0);
        rec.points[3].xyz = moved;
        // Point 4 moves off the surface along its normal by 0.02: true error 0.02 too.
        rec.points[4].xyz = pts[4].map(|x| x * 1.02);
        let (_, out) = track_errors(&rec, &views, &view_of, &Similarity::IDENTITY, &NoProgress);
        let chord = 2.0 * (2.5f64).to_radians().sin();
        let e3 = out[3].true_error.unwrap();
        assert!((e3 - chord).abs() < 1e-3, "{e3} vs {chord}");
        assert!((out[4].true_error.unwrap() - 0.02).abs() < 1e-3);
        // Sliding at tau = 0.01: the true error exceeds the surface distance (0 for point 3,
        // 0.02 for point 4) by more than tau for point 3 only.
        let surface = |p: Point3| (norm(p) - 1.0).abs();
        let sliding: Vec<usize> = (0..pts.len())
            .filter(|&i| out[i].true_error.unwrap() - surface(rec.points[i].xyz) > 0.01)
            .collect();
        assert_eq!(sliding, vec![3]);
    }

    #[test]
    fn alignment_and_conventions_are_applied() {
        let pts: Vec<Point3> = (0..5).map(|k| on_sphere(5.0 * k as f64, 10.0)).collect();
        let (views, rec) = scene(&pts);
        // The recon in another frame: recon = inverse(gt_from_recon)(gt).
        let gt_from_recon = Similarity::from_matrix([
            [0.0, -2.0, 0.0, 1.0],
            [2.0, 0.0, 0.0, -0.5],
            [0.0, 0.0, 2.0, 0.25],
            [0.0, 0.0, 0.0, 1.0],
        ])
        .unwrap();
        let recon_from_gt = gt_from_recon.inverse();
        let mut moved = rec.clone();
        for p in &mut moved.points {
            p.xyz = recon_from_gt.apply(p.xyz);
        }
        let view_of: Vec<Option<usize>> = (0..views.len()).map(Some).collect();
        let (_, out) = track_errors(&moved, &views, &view_of, &gt_from_recon, &NoProgress);
        let errs: Vec<f64> = out.iter().map(|o| o.true_error.unwrap()).collect();
        assert!(errs.iter().all(|&e| e < 1e-3), "{errs:?}");
        // Bundler: centred, y up.
        let mut bundler = rec.clone();
        bundler.format = "bundler";
        for im in &mut bundler.images {
            for o in &mut im.observations {
                o.xy = [o.xy[0] - 160.0, 120.0 - o.xy[1]];
            }
        }
        let (conv, out) = track_errors(
            &bundler,
            &views,
            &view_of,
            &Similarity::IDENTITY,
            &NoProgress,
        );
        assert_eq!(conv, ObservationConvention::CenteredYUp);
        assert!(out.iter().all(|o| o.true_error.unwrap() < 1e-3));
        // An image with no ground truth rejects its observations.
        let none: Vec<Option<usize>> = vec![None; views.len()];
        let (_, out) = track_errors(&rec, &views, &none, &Similarity::IDENTITY, &NoProgress);
        assert!(
            out.iter()
                .all(|o| o.true_error.is_none() && o.rejected[0] == o.observations)
        );
    }

    #[test]
    fn robust_mean_trims_a_wrong_observation() {
        let mut pts = vec![[1.0, 0.0, 0.0]; 5];
        pts[1][1] = 0.001;
        pts.push([1.0, 0.5, 0.0]); // a mismatched feature
        let (m, kept) = robust_mean(&pts, 0.001).unwrap();
        assert_eq!(kept, 5);
        assert!((m[1] - 0.0002).abs() < 1e-12);
    }
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod convention_tests {
    //! The observation convention of every reader, on files written by the real programs
    //! (tests/fixtures/models): each observation, brought to COLMAP pixels, must lie where its
    //! 3D point projects through its image's pose and focal length.
    use super::*;
    use crate::io::npy::DepthMap;
    use crate::model::fuzz_tests::fixture;
    use std::collections::BTreeMap;

    fn median_reprojection(rec: &Reconstruction) -> (ObservationConvention, f64, usize) {
        let conv = ObservationConvention::of(rec);
        let mut errors = Vec::new();
        for im in &rec.images {
            let cam = rec.camera_of(im).unwrap();
            // NVM and Bundler store no principal point: the images' centre (240×180).
            let (cx, cy) = if cam.cx > 0.0 {
                (cam.cx, cam.cy)
            } else {
                (120.0, 90.0)
            };
            let view = GtView {
                name: im.name.clone(),
                cam_from_world: im.cam_from_world,
                fx: cam.fx,
                fy: cam.fy,
                cx,
                cy,
                depth: DepthMap {
                    width: 240,
                    height: 180,
                    depth: vec![0.0; 240 * 180],
                },
            };
            for o in &im.observations {
                let Some(pi) = o.point else { continue };
                let p = rec.points[pi].xyz;
                let (u, v, _) = view.project(p).unwrap();
                let (ou, ov) = conv.to_pixels(o.xy, &view);
                errors.push(((u - ou).powi(2) + (v - ov).powi(2)).sqrt());
            }
        }
        let n = errors.len();
        (conv, median(&mut errors), n)
    }

    #[test]
    fn every_reader_gives_observations_where_their_points_project() {
        let mut colmap = BTreeMap::new();
        for f in ["cameras.txt", "images.txt", "points3D.txt"] {
            colmap.insert(f.to_string(), fixture(&format!("colmap_text/{f}")));
        }
        let cases = [
            (
                "colmap_text",
                crate::model::read_model_files(&colmap).unwrap(),
                ObservationConvention::ColmapPixels,
            ),
            (
                "colmap38.nvm",
                crate::model::nvm::read_nvm(&fixture("colmap38.nvm")).unwrap(),
                ObservationConvention::ColmapPixels,
            ),
            (
                "theia.nvm",
                crate::model::nvm::read_nvm(&fixture("theia.nvm")).unwrap(),
                ObservationConvention::CenteredYDown,
            ),
            (
                "colmap38.bundle.out",
                crate::model::bundler::read_bundler(
                    &fixture("colmap38.bundle.out"),
                    Some(&fixture("colmap38.list.txt")),
                )
                .unwrap(),
                ObservationConvention::CenteredYUp,
            ),
            (
                "openmvg_sfm_data.json",
                crate::model::openmvg::read_openmvg_json(&fixture("openmvg_sfm_data.json"))
                    .unwrap(),
                ObservationConvention::ColmapPixels,
            ),
        ];
        for (name, rec, want) in cases {
            let (conv, med, n) = median_reprojection(&rec);
            assert_eq!(conv, want, "{name}");
            assert!(n > 20, "{name}: {n} observations");
            // SfM residuals are well below a pixel; a wrong convention is off by ~W/2.
            assert!(med < 1.0, "{name}: median reprojection {med} px");
        }
    }
}
