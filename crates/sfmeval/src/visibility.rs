//! Which ground-truth surface samples the images could see: for each sample and each
//! ground-truth view, the sample is seen when it projects inside the image, in front of the
//! camera, and passes a depth test against the view's depth map. A sample seen in at least
//! `min_views` images is *visible*; completeness measured over visible samples only says how
//! much of what the cameras saw was reconstructed.
//!
//! Depth test, with `z` the sample's camera depth and `s = z / f` the size of one pixel at that
//! depth (the pixel footprint):
//!
//! - tolerance `tol = RELATIVE_TOLERANCE · z + FOOTPRINT_TOLERANCE · s`;
//! - when the 2×2 neighbourhood of the projection holds four depths, they are interpolated in
//!   inverse depth (exact on a plane, even at grazing angles where neighbouring depths differ by
//!   many footprints) and the sample is seen when `|z − d̂| ≤ tol`;
//!   when it fails and the four depths are continuous (spread at most
//!   `MAX_SLOPE_FOOTPRINTS · s`: one surface), the sample is hidden;
//! - otherwise (silhouette edges, where a neighbour is background, or creases and steps, where
//!   the four pixels see two faces), the sample is seen when it is within
//!   `tol + dist · slope` of one valid neighbour's depth, `dist` its pixel distance to that pixel
//!   centre and `slope` the neighbourhood's depth spread capped at `MAX_SLOPE_FOOTPRINTS · s`
//!   per pixel, so a step between two surfaces (an occluder) never widens the test beyond a steep
//!   but continuous surface; at a silhouette (a background pixel in the neighbourhood) the slope
//!   is `RIM_SLOPE_FOOTPRINTS · s`, because the surface there turns away from the camera (a
//!   sphere's limb) and its one-pixel rim covers a wide band of the surface.
//!
//! Samples hidden behind the surface by less than `tol` count as seen: the thickness below which
//! two surfaces are not told apart is about `RELATIVE_TOLERANCE · z + FOOTPRINT_TOLERANCE · s`.

use serde::Serialize;

use crate::geometry::Point3;
use crate::gt_views::GtView;
use crate::metrics::{f_score, share_below};
use crate::note::{Code, Note};
use crate::parallel;
use crate::progress::Progress;
use crate::report::{ThresholdReport, VisibleCompletenessReport, VisibleThresholdReport};
use crate::stats::Statistics;

/// Relative part of the depth tolerance (of the sample's depth).
pub(crate) const RELATIVE_TOLERANCE: f64 = 0.0005;
/// Pixel-footprint part of the depth tolerance (in footprints).
pub(crate) const FOOTPRINT_TOLERANCE: f64 = 1.5;
/// Steepest depth slope accepted between neighbouring pixels, in footprints per pixel
/// (a surface at about 70° to the view direction; steeper ones are judged by the inverse-depth
/// interpolation alone).
pub(crate) const MAX_SLOPE_FOOTPRINTS: f64 = 3.0;

/// Depth slope assumed at a silhouette (a 2×2 neighbourhood with a background pixel), in
/// footprints per pixel: the surface there turns away from the camera and its depth changes
/// much faster than the valid pixels alone show (a sphere's limb).
pub(crate) const RIM_SLOPE_FOOTPRINTS: f64 = 8.0;

/// Default number of images a sample must be seen in to count as visible (two views are the
/// least any SfM pipeline needs to triangulate a point).
pub const DEFAULT_MIN_VIEWS: u32 = 2;

/// What became of one completeness sample (for the viewer).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
#[repr(u8)]
pub enum SampleLabel {
    /// Visible and reconstructed (a reconstructed point closer than the labels' tau).
    Covered = 0,
    /// Visible but not reconstructed.
    Missed = 1,
    /// Seen in fewer than `min_views` images.
    Unseen = 2,
}

/// Whether `view` sees `point_in_gt`.
pub(crate) fn sees(view: &GtView, point_in_gt: Point3) -> bool {
    let Some((u, v, z)) = view.project(point_in_gt) else {
        return false;
    };
    let Some(n) = view.neighbourhood(u, v) else {
        return false;
    };
    let footprint = z / view.focal();
    let tol = RELATIVE_TOLERANCE * z + FOOTPRINT_TOLERANCE * footprint;
    if let Some(d) = n.interpolated() {
        if (z - d).abs() <= tol {
            return true;
        }
        // A continuous neighbourhood (one surface, however steep) has said it all.
        if n.spread() <= MAX_SLOPE_FOOTPRINTS * footprint {
            return false;
        }
    }
    let slope = if n.depths.iter().any(|&d| d <= 0.0) {
        RIM_SLOPE_FOOTPRINTS * footprint
    } else {
        n.spread().min(MAX_SLOPE_FOOTPRINTS * footprint)
    };
    let (fu, fv) = (u - 0.5, v - 0.5);
    let (a, b) = (fu - fu.floor(), fv - fv.floor());
    let offsets = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
    n.depths.iter().zip(offsets).any(|(&d, (di, dj))| {
        let dist = ((a - di) * (a - di) + (b - dj) * (b - dj)).sqrt();
        d > 0.0 && (z - d).abs() <= tol + dist * slope
    })
}

/// For each sample, the number of views that see it (in sample order; independent of the
/// thread count).
pub(crate) fn count_views(
    views: &[GtView],
    samples_in_gt: &[Point3],
    progress: &dyn Progress,
) -> Vec<u32> {
    parallel::map(samples_in_gt, progress, |&p| {
        views.iter().filter(|v| sees(v, p)).count() as u32
    })
}

/// Labels of samples from their view counts and their distances to the reconstruction.
pub(crate) fn labels(
    views: &[u32],
    completeness_distances: &[f64],
    min_views: u32,
    tau: f64,
) -> Vec<SampleLabel> {
    views
        .iter()
        .zip(completeness_distances)
        .map(|(&n, &d)| {
            if n < min_views {
                SampleLabel::Unseen
            } else if d < tau {
                SampleLabel::Covered
            } else {
                SampleLabel::Missed
            }
        })
        .collect()
}

/// Completeness over the visible surface, from each completeness sample's view count and
/// distance to the reconstruction: the samples seen in `min_views` or more of the `views`
/// images, their distance statistics, and per threshold (`scores`: the evaluation's resolved
/// thresholds with their precision and whole-surface recall) the recall and F-score over the
/// visible samples. `surface_area` is the whole ground-truth area when the samples cover all of
/// it (a mesh, no crop volume). Returns the report section and a warning when nothing is visible.
pub(crate) fn visible_completeness(
    view_counts: &[u32],
    completeness_distances: &[f64],
    scores: &[ThresholdReport],
    min_views: u32,
    views: usize,
    surface_area: Option<f64>,
    bins: usize,
) -> (VisibleCompletenessReport, Option<Note>) {
    let visible: Vec<f64> = view_counts
        .iter()
        .zip(completeness_distances)
        .filter(|(n, _)| **n >= min_views)
        .map(|(_, d)| *d)
        .collect();
    let finite: Vec<f64> = visible.iter().copied().filter(|d| d.is_finite()).collect();
    let samples = view_counts.len();
    let fraction = if samples > 0 {
        visible.len() as f64 / samples as f64
    } else {
        0.0
    };
    let thresholds = scores
        .iter()
        .map(|t| {
            let recall_visible = share_below(&visible, t.tau);
            VisibleThresholdReport {
                tau: t.tau,
                recall: t.recall,
                recall_visible,
                f_score_visible: f_score(t.precision, recall_visible),
            }
        })
        .collect();
    let warning = visible.is_empty().then(|| {
        Note::new(
            Code::NothingVisible,
            format!(
                "no ground-truth sample is seen in {min_views} or more images: check that the depth maps belong to these cameras"
            ),
        )
        .with("min_views", min_views)
    });
    let report = VisibleCompletenessReport {
        direction: "ground_truth_to_reconstruction".into(),
        min_views: u64::from(min_views),
        views: views as u64,
        samples: samples as u64,
        visible_samples: visible.len() as u64,
        visible_fraction: fraction,
        visible_area: surface_area.map(|a| fraction * a),
        labels_tau: scores.first().map_or(0.0, |t| t.tau),
        stats: Statistics::of(&finite, bins),
        thresholds,
    };
    (report, warning)
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::*;
    use crate::gt_views::test_scenes::*;
    use crate::progress::NoProgress;
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::PI;

    fn ring(
        elevation_deg: f64,
        distance: f64,
        n: usize,
        f: f64,
        w: usize,
        h: usize,
        hit: &dyn Fn(Point3, Point3) -> Option<f64>,
    ) -> Vec<GtView> {
        let e = elevation_deg.to_radians();
        (0..n)
            .map(|k| {
                let phi = 2.0 * PI * k as f64 / n as f64 + 0.1;
                let c = [
                    distance * e.cos() * phi.cos(),
                    distance * e.sin(),
                    distance * e.cos() * phi.sin(),
                ];
                render(look_at(c, [0.0; 3]), f, w, h, hit)
            })
            .collect()
    }

    /// Uniform samples on the surface of the cube [-0.5, 0.5]³ with their face index
    /// (0..6: −x, +x, −y, +y, −z, +z).
    fn cube_samples(n: usize) -> Vec<(Point3, usize)> {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        (0..n)
            .map(|_| {
                let face = rng.random_range(0..6usize);
                let (a, b): (f64, f64) = (rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
                let s = if face % 2 == 0 { -0.5 } else { 0.5 };
                let p = match face / 2 {
                    0 => [s, a, b],
                    1 => [a, s, b],
                    _ => [a, b, s],
                };
                (p, face)
            })
            .collect()
    }

    #[test]
    fn cube_seen_from_above_hides_its_bottom_face() {
        // A unit cube, 24 cameras on a ring 40° above the horizon at distance 4: every face but
        // the bottom one (−y) faces some cameras, so the visible fraction is 5/6 of the area.
        // The only deviation: a bottom sample δ from an edge hides behind the side face by a
        // depth of about δ / cos 40° ≈ 1.3 δ, below the depth tolerance
        // tol = 0.0005 z + 1.5 z / f ≈ 0.012 (z ≈ 4, f = 600) when δ < tol; so the seen part of
        // the bottom is a band narrower than 2 tol along its four edges: at most 4 · 2 tol of its
        // unit area, (4 · 2 · 0.012) / 6 = 0.016 of the whole surface.
        let hit = aabox([-0.5; 3], [0.5; 3]);
        let views = ring(40.0, 4.0, 24, 600.0, 480, 480, &hit);
        let samples = cube_samples(60_000);
        let pts: Vec<Point3> = samples.iter().map(|s| s.0).collect();
        let counts = count_views(&views, &pts, &NoProgress);
        let visible = counts.iter().filter(|&&c| c >= 2).count() as f64 / pts.len() as f64;
        let tol = RELATIVE_TOLERANCE * 4.5 + FOOTPRINT_TOLERANCE * 4.5 / 600.0;
        assert!(
            visible > 5.0 / 6.0 - 0.002 && visible < 5.0 / 6.0 + 4.0 * 2.0 * tol / 6.0,
            "visible fraction {visible}"
        );
        eprintln!(
            "cube from above: visible fraction {visible} (5/6 = {})",
            5.0 / 6.0
        );
        for ((p, face), &c) in samples.iter().zip(&counts) {
            if *face == 2 && p[0].abs() < 0.5 - 2.0 * tol && p[2].abs() < 0.5 - 2.0 * tol {
                assert_eq!(c, 0, "bottom sample {p:?} seen");
            }
            if *face == 3 {
                assert_eq!(c, 24, "top sample {p:?} seen by {c}");
            }
        }
        // A side face is seen by the cameras in front of it: from a ring, those within ±90° of
        // its normal, i.e. about half of them.
        let side: Vec<u32> = samples
            .iter()
            .zip(&counts)
            .filter(|((p, f), _)| *f == 1 && p[1].abs() < 0.4 && p[2].abs() < 0.4)
            .map(|(_, &c)| c)
            .collect();
        assert!(
            side.iter().all(|&c| (10..=13).contains(&c)),
            "{:?}",
            &side[..10]
        );
    }

    #[test]
    fn sphere_seen_from_an_orbit_ring_shows_the_band_of_its_caps() {
        // A unit sphere and a ring of 72 cameras in its equatorial plane at distance D = 2.
        // A camera at C sees the cap of points x with x·Ĉ > r/D (angular radius
        // α = acos(r/D) = 60°); the union over a dense ring is the band |latitude| < α, whose
        // area fraction is sin α = √3/2. With 72 cameras (5° apart), a point needs two cameras
        // within its longitude window ±acos((r/D)/cos β), which fails only for |β| within 0.1°
        // of α: the loss is below 0.002. With two rings at ±45° the caps cover
        // latitudes (−90°, 90°) except the polar caps above 45° + 60° = 105°: all of it.
        let hit = sphere([0.0; 3], 1.0);
        let views = ring(0.0, 2.0, 72, 300.0, 480, 480, &hit);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let pts: Vec<Point3> = (0..50_000)
            .map(|_| {
                loop {
                    let v: Point3 = [
                        rng.random::<f64>() * 2.0 - 1.0,
                        rng.random::<f64>() * 2.0 - 1.0,
                        rng.random::<f64>() * 2.0 - 1.0,
                    ];
                    let n = crate::geometry::norm(v);
                    if n > 0.1 && n <= 1.0 {
                        break v.map(|x| x / n);
                    }
                }
            })
            .collect();
        let counts = count_views(&views, &pts, &NoProgress);
        let frac = |k: u32| counts.iter().filter(|&&c| c >= k).count() as f64 / pts.len() as f64;
        let expected = 3f64.sqrt() / 2.0;
        // Sampling error: √(0.87·0.13/50000) ≈ 0.0015.
        assert!(
            (frac(2) - expected).abs() < 0.006,
            "{} vs {expected}",
            frac(2)
        );
        assert!(frac(1) >= frac(2));
        // Per sample: latitudes well inside the band are seen, well outside are not.
        for (p, &c) in pts.iter().zip(&counts) {
            let lat = p[1].asin().to_degrees();
            if lat.abs() < 55.0 {
                assert!(c >= 2, "lat {lat} seen by {c}");
            }
            if lat.abs() > 64.0 {
                assert_eq!(c, 0, "lat {lat} seen by {c}");
            }
        }
        // Two tilted rings see the whole sphere.
        let mut both = ring(45.0, 2.0, 36, 80.0, 128, 128, &hit);
        both.extend(ring(-45.0, 2.0, 36, 80.0, 128, 128, &hit));
        let counts = count_views(&both, &pts, &NoProgress);
        let all = counts.iter().filter(|&&c| c >= 2).count() as f64 / pts.len() as f64;
        assert!(all > 0.995, "{all}");
    }

    #[test]
    fn occluded_points_are_not_seen_and_labels_follow() {
        // A camera looking down −z at the unit sphere: the back point is hidden.
        let hit = sphere([0.0; 3], 1.0);
        let v = render(look_at([0.0, 0.0, 3.0], [0.0; 3]), 100.0, 64, 64, &hit);
        assert!(sees(&v, [0.0, 0.0, 1.0]));
        assert!(!sees(&v, [0.0, 0.0, -1.0]));
        assert!(!sees(&v, [0.0, 0.0, 0.9])); // 10 cm inside the surface at 2 m: hidden
        assert!(!sees(&v, [0.0, 0.0, 5.0])); // behind the camera
        let l = labels(&[0, 2, 3], &[0.0, 0.5, 0.01], 2, 0.1);
        assert_eq!(
            l,
            vec![
                SampleLabel::Unseen,
                SampleLabel::Missed,
                SampleLabel::Covered
            ]
        );
    }
}
