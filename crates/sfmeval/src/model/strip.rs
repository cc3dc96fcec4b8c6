//! Camera centres written into point clouds. OpenMVG's PLY export adds the camera centres as
//! green `(0,255,0)` points (pose priors blue `(0,0,255)`, control points red `(255,0,0)`);
//! openmvg-rs writes green centres after the points; Theia's `WritePlyFile` appends every camera
//! centre in one caller-chosen colour. Such points are not part of the scene and must be removed
//! before measuring.
//!
//! With the model's camera centres known, points within a tiny distance of a centre are removed
//! ([`remove_camera_centers`]). Without them, [`remove_marker_runs`] removes leading and trailing
//! runs of points in one of the pure marker colours. [`strip_camera_points`] picks the method.

use crate::geometry::{Aabb, Point3, PointCloud};
use crate::note::{Code, Note};

/// What [`strip_camera_points`] removed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Stripped {
    /// The cloud without the camera points.
    pub cloud: PointCloud,
    /// How many points were removed.
    pub removed: usize,
    /// The report's note when points were removed.
    pub note: Option<Note>,
    /// Whether the points were found at the given camera centres (else: by marker colour, or
    /// nothing removed).
    pub by_centers: bool,
}

/// OpenMVG's marker colours: cameras, pose priors, control points.
pub(crate) const MARKER_COLORS: [[u8; 3]; 3] = [[0, 255, 0], [0, 0, 255], [255, 0, 0]];

/// Relative tolerance (of the cloud's bounding-box diagonal) within which a point is taken to
/// be a written camera centre. Writers print 6–9 significant digits.
pub(crate) const CENTER_TOLERANCE: f64 = 1e-5;

/// `cloud` without the points marked in `remove`, in place.
fn keep(mut cloud: PointCloud, remove: &[bool]) -> PointCloud {
    cloud.points.retain_indices(|i| !remove[i]);
    if let Some(c) = cloud.colors.as_mut() {
        let mut i = 0;
        c.retain(|_| (!remove[i], i += 1).0);
    }
    cloud
}

/// Marks the points that lie within `tolerance` × (bounding-box diagonal of cloud and centres)
/// of one of `centers`. When the cloud has colours, only points whose colour is the most common
/// colour among the matches are marked (all centres are written in one colour), so a real point
/// that happens to coincide keeps its place unless it has that colour too.
pub(crate) fn mark_camera_centers(
    cloud: &PointCloud,
    centers: &[Point3],
    tolerance: f64,
) -> Vec<bool> {
    let mut marks = vec![false; cloud.points.len()];
    let finite: Vec<Point3> = centers
        .iter()
        .copied()
        .filter(|c| c.iter().all(|v| v.is_finite()))
        .collect();
    if finite.is_empty() || cloud.points.is_empty() {
        return marks;
    }
    // The box of the centres and the finite points, without a copy of the cloud.
    let mut b = Aabb {
        min: finite[0],
        max: finite[0],
    };
    for p in finite.iter().copied().chain(
        cloud
            .points
            .iter()
            .filter(|p| p.iter().all(|v| v.is_finite())),
    ) {
        for (k, v) in p.into_iter().enumerate() {
            b.min[k] = b.min[k].min(v);
            b.max[k] = b.max[k].max(v);
        }
    }
    let diag = b.diagonal();
    let tol = (tolerance * diag).max(f64::MIN_POSITIVE);
    let mut sorted = finite;
    sorted.sort_by(|a, b| a[0].total_cmp(&b[0]));
    for (i, p) in cloud.points.iter().enumerate() {
        let lo = sorted.partition_point(|c| c[0] < p[0] - tol);
        let hit = sorted
            .get(lo..)
            .unwrap_or_default()
            .iter()
            .take_while(|c| c[0] <= p[0] + tol)
            .any(|c| (c[1] - p[1]).abs() <= tol && (c[2] - p[2]).abs() <= tol);
        if let Some(m) = marks.get_mut(i) {
            *m = hit;
        }
    }
    if let Some(colors) = &cloud.colors {
        let mut counts: Vec<([u8; 3], usize)> = Vec::new();
        for (c, _) in colors.iter().zip(&marks).filter(|(_, m)| **m) {
            match counts.iter_mut().find(|(k, _)| k == c) {
                Some((_, n)) => *n += 1,
                None => counts.push((*c, 1)),
            }
        }
        if let Some((mode, _)) = counts.iter().max_by_key(|(_, n)| *n).copied() {
            for (m, c) in marks.iter_mut().zip(colors) {
                if *c != mode {
                    *m = false;
                }
            }
        }
    }
    marks
}

/// Without known cameras: removes the leading and trailing runs of points whose colour is one
/// of [`MARKER_COLORS`] (OpenMVG writes cameras first or last, Theia and openmvg-rs last), as
/// long as at least one point remains. A cloud without colours is returned unchanged.
pub(crate) fn remove_marker_runs(cloud: PointCloud) -> (PointCloud, usize) {
    let Some(colors) = &cloud.colors else {
        return (cloud, 0);
    };
    let is_marker = |c: &[u8; 3]| MARKER_COLORS.contains(c);
    let head = colors.iter().take_while(|c| is_marker(c)).count();
    let tail = colors.iter().rev().take_while(|c| is_marker(c)).count();
    if head + tail >= colors.len() {
        return (cloud, 0);
    }
    let mut marks = vec![false; colors.len()];
    for m in marks.iter_mut().take(head) {
        *m = true;
    }
    for m in marks.iter_mut().rev().take(tail) {
        *m = true;
    }
    (keep(cloud, &marks), head + tail)
}

/// Removes camera-centre points from a cloud: by position when `centers` are given and match at
/// least one point, else by marker colour runs. `source` names the cloud in the warning.
/// The cloud is filtered in place.
pub(crate) fn strip_camera_points(
    cloud: PointCloud,
    centers: Option<&[Point3]>,
    source: &str,
) -> Stripped {
    if let Some(centers) = centers.filter(|c| !c.is_empty()) {
        // The points that coincide with known camera centres (see [`mark_camera_centers`]).
        let marks = mark_camera_centers(&cloud, centers, CENTER_TOLERANCE);
        let n = marks.iter().filter(|m| **m).count();
        if n > 0 {
            return Stripped {
                cloud: keep(cloud, &marks),
                removed: n,
                by_centers: true,
                note: Some(
                    Note::new(
                        Code::CameraCentresRemoved,
                        format!(
                            "{source}: removed {n} point(s) at the {} known camera centre(s) (written by the SfM tool)",
                            centers.len()
                        ),
                    )
                    .with("removed", n)
                    .with("cameras", centers.len()),
                ),
            };
        }
    }
    let (c, n) = remove_marker_runs(cloud);
    Stripped {
        cloud: c,
        removed: n,
        by_centers: false,
        note: (n > 0).then(|| {
            Note::new(
                Code::CameraCentresRemoved,
                format!("{source}: removed {n} point(s) in camera-marker colours at the start/end of the cloud (camera centres written by OpenMVG/Theia)"),
            )
            .with("removed", n)
        }),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::io::ply::read_ply;
    use crate::model::colmap::read_colmap_text;
    use crate::model::fuzz_tests::fixture;

    fn cloud(name: &str) -> PointCloud {
        let p = read_ply(&fixture(name)).unwrap();
        PointCloud {
            points: p.vertices,
            colors: p.colors,
        }
    }

    #[test]
    fn openmvg_rs_ply_with_known_cameras_and_by_colour() {
        let c = cloud("openmvg.ply");
        let model = read_colmap_text(
            &fixture("openmvg_colmap/cameras.txt"),
            &fixture("openmvg_colmap/images.txt"),
            Some(&fixture("openmvg_colmap/points3D.txt")),
        )
        .unwrap();
        let s = strip_camera_points(c.clone(), Some(&model.camera_centers()), "openmvg.ply");
        assert_eq!(s.removed, 6);
        assert_eq!(s.cloud.points.len(), model.points.len());
        assert!(s.note.unwrap().message.contains("6 point"));
        let s = strip_camera_points(c.clone(), None, "openmvg.ply");
        assert_eq!(s.removed, 6);
        assert!(!s.by_centers);
        assert!(
            s.cloud
                .colors
                .unwrap()
                .iter()
                .all(|c| *c == [255, 255, 255])
        );
    }

    #[test]
    fn theia_ply_with_known_cameras_and_by_colour() {
        let c = cloud("theia.ply");
        let model = read_colmap_text(
            &fixture("theia_colmap/cameras.txt"),
            &fixture("theia_colmap/images.txt"),
            Some(&fixture("theia_colmap/points3D.txt")),
        )
        .unwrap();
        let s = strip_camera_points(c.clone(), Some(&model.camera_centers()), "theia.ply");
        assert_eq!(s.removed, 6);
        assert!(s.by_centers);
        let (_, n) = remove_marker_runs(c.clone());
        assert_eq!(n, 6);
    }

    #[test]
    fn nothing_to_remove_and_degenerate_inputs() {
        let c = PointCloud {
            points: vec![[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]].into(),
            colors: Some(vec![[0, 255, 0], [0, 255, 0]]),
        };
        // All marker-coloured: keep everything rather than empty the cloud.
        assert_eq!(remove_marker_runs(c.clone()).1, 0);
        assert_eq!(
            strip_camera_points(c.clone(), Some(&[[5.0, 5.0, 5.0]]), "x").removed,
            0
        );
        assert_eq!(
            strip_camera_points(c.clone(), Some(&[[f64::NAN, 0.0, 0.0]]), "x").removed,
            0
        );
        let empty = PointCloud::default();
        assert_eq!(
            strip_camera_points(empty.clone(), Some(&[[0.0; 3]]), "x").removed,
            0
        );
        // Without colours, position still works.
        let nc = PointCloud {
            points: vec![[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]].into(),
            colors: None,
        };
        let s = strip_camera_points(nc, Some(&[[1.0, 1.0, 1.0]]), "x");
        assert_eq!(
            (s.removed, s.cloud.points.iter().collect::<Vec<_>>()),
            (1, vec![[0.0; 3]])
        );
    }
}
