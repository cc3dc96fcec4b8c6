//! The ground-truth views of a dataset: each image's exact camera (`cameras.json`) with its depth
//! map (`depth/<stem>.npy`, `docs/dataset.md`). Projection, depth look-up in the 2×2 pixel
//! neighbourhood of a sub-pixel position, and back-projection of a pixel to its 3D surface point.
//! Used by [`crate::visibility`] and by the track-based error of [`crate::pipeline`].
//!
//! Pixel convention: COLMAP's (the top-left pixel's centre is at (0.5, 0.5)); depth pixel
//! `(i, j)` holds the depth of the ray through `(i + 0.5, j + 0.5)`.

use crate::error::{Error, Result};
use crate::geometry::Point3;
use crate::io::npy::DepthMap;
use crate::model::{Reconstruction, Rigid, mat_t_vec};

/// One ground-truth image: pinhole intrinsics, pose and depth map.
#[derive(Debug, Clone, PartialEq)]
pub struct GtView {
    /// Image name as in `cameras.json`.
    pub name: String,
    /// World (ground-truth frame) to camera, OpenCV axes.
    pub cam_from_world: Rigid,
    /// Focal lengths in pixels.
    pub fx: f64,
    /// Focal length along y in pixels.
    pub fy: f64,
    /// Principal point, COLMAP convention.
    pub cx: f64,
    /// Principal point y.
    pub cy: f64,
    /// The depth map (its size is the camera's width × height).
    pub depth: DepthMap,
}

/// The 2×2 depth neighbourhood of a sub-pixel position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Neighbourhood {
    /// Depths of the four pixels (0 when background or outside the image), in the order
    /// (i0, j0), (i0+1, j0), (i0, j0+1), (i0+1, j0+1).
    pub depths: [f64; 4],
    /// Bilinear weights of the four pixels (sum 1).
    pub weights: [f64; 4],
}

impl Neighbourhood {
    /// Whether all four pixels hold a depth.
    pub(crate) fn complete(&self) -> bool {
        self.depths.iter().all(|&d| d > 0.0)
    }

    /// Depth interpolated bilinearly in inverse depth (exact on a plane, whose inverse depth is
    /// affine in the pixel coordinates); `None` unless all four pixels hold a depth.
    pub(crate) fn interpolated(&self) -> Option<f64> {
        if !self.complete() {
            return None;
        }
        let mut inv = 0.0;
        for k in 0..4 {
            inv += self.weights[k] / self.depths[k];
        }
        (inv > 0.0).then(|| 1.0 / inv)
    }

    /// Largest minus smallest depth of the valid pixels (0 when fewer than two).
    pub(crate) fn spread(&self) -> f64 {
        let valid = self.depths.iter().filter(|&&d| d > 0.0);
        let (lo, hi) = valid.fold((f64::INFINITY, 0.0f64), |(lo, hi), &d| {
            (lo.min(d), hi.max(d))
        });
        if lo.is_finite() { hi - lo } else { 0.0 }
    }
}

impl GtView {
    /// Mean focal length in pixels.
    pub(crate) fn focal(&self) -> f64 {
        0.5 * (self.fx + self.fy)
    }

    /// Projects a ground-truth-frame point: `(u, v, z)` with `(u, v)` in COLMAP pixels and `z`
    /// the camera-frame depth; `None` behind the camera.
    #[inline]
    pub(crate) fn project(&self, point_in_gt: Point3) -> Option<(f64, f64, f64)> {
        let p = self.cam_from_world.apply(point_in_gt);
        if !(p[2] > 0.0) {
            return None;
        }
        Some((
            self.fx * p[0] / p[2] + self.cx,
            self.fy * p[1] / p[2] + self.cy,
            p[2],
        ))
    }

    /// Whether `(u, v)` lies inside the image (COLMAP convention: `[0, W) × [0, H)`).
    #[inline]
    pub(crate) fn inside(&self, u: f64, v: f64) -> bool {
        u >= 0.0 && v >= 0.0 && u < self.depth.width as f64 && v < self.depth.height as f64
    }

    /// The 2×2 pixel neighbourhood around `(u, v)` (pixels outside the image count as
    /// background). `None` when `(u, v)` is outside the image.
    pub(crate) fn neighbourhood(&self, u: f64, v: f64) -> Option<Neighbourhood> {
        if !self.inside(u, v) {
            return None;
        }
        let (fu, fv) = (u - 0.5, v - 0.5);
        let (i0, j0) = (fu.floor(), fv.floor());
        let (a, b) = (fu - i0, fv - j0);
        let mut depths = [0.0; 4];
        let offsets = [(0, 0), (1, 0), (0, 1), (1, 1)];
        for (k, (di, dj)) in offsets.iter().enumerate() {
            let (i, j) = (i0 as i64 + di, j0 as i64 + dj);
            if i >= 0 && j >= 0 {
                depths[k] = self.depth.at(i as usize, j as usize).unwrap_or(0.0);
            }
        }
        Some(Neighbourhood {
            depths,
            weights: [(1.0 - a) * (1.0 - b), a * (1.0 - b), (1.0 - a) * b, a * b],
        })
    }

    /// The ground-truth-frame point at depth `z` on the ray through pixel position `(u, v)`.
    pub(crate) fn back_project(&self, u: f64, v: f64, z: f64) -> Point3 {
        let cam = [z * (u - self.cx) / self.fx, z * (v - self.cy) / self.fy, z];
        let t = self.cam_from_world.translation;
        mat_t_vec(
            &self.cam_from_world.rotation,
            [cam[0] - t[0], cam[1] - t[1], cam[2] - t[2]],
        )
    }
}

/// The key that pairs an image name with its depth file: the file stem without folders
/// (`images/0007.jpg` → `0007`, looked up as `depth/0007.npy`).
pub fn depth_stem(image_name: &str) -> String {
    let base = image_name.rsplit(['/', '\\']).next().unwrap_or(image_name);
    match base.rsplit_once('.') {
        Some((stem, _)) if !stem.is_empty() => stem.to_string(),
        _ => base.to_string(),
    }
}

/// Builds the views of `gt_cameras` from their depth maps, looked up by [`depth_stem`] of each
/// image name in `depth_by_stem`. Every image needs a depth map whose size is its camera's
/// width × height; only pinhole cameras (`PINHOLE`, `SIMPLE_PINHOLE`, or models whose extra
/// parameters are all zero) are accepted, since the depth maps are rendered without distortion.
pub(crate) fn build_views(
    gt_cameras: &Reconstruction,
    depth_by_stem: &std::collections::BTreeMap<String, DepthMap>,
) -> Result<Vec<GtView>> {
    if gt_cameras.images.is_empty() {
        return Err(Error::Empty {
            what: "ground-truth cameras (no images) for the depth maps".into(),
        });
    }
    let mut views = Vec::with_capacity(gt_cameras.images.len());
    for im in &gt_cameras.images {
        let stem = depth_stem(&im.name);
        let cam = gt_cameras
            .camera_of(im)
            .ok_or_else(|| Error::InvalidContent(format!("image '{}' has no camera", im.name)))?;
        let extra = match cam.model.as_str() {
            "SIMPLE_PINHOLE" | "PINHOLE" => 0.0,
            _ => {
                let skip = if cam.model.starts_with("SIMPLE") || cam.model == "RADIAL" {
                    3
                } else {
                    4
                };
                cam.params.iter().skip(skip).map(|v| v.abs()).sum()
            }
        };
        if extra != 0.0 {
            return Err(Error::InvalidContent(format!(
                "image '{}': camera model {} has distortion; depth maps need pinhole cameras",
                im.name, cam.model
            )));
        }
        if !(cam.fx > 0.0 && cam.fy > 0.0) {
            return Err(Error::InvalidContent(format!(
                "image '{}': camera {} has no positive focal length",
                im.name, cam.id
            )));
        }
        let depth = depth_by_stem.get(&stem).ok_or_else(|| {
            Error::InvalidContent(format!(
                "missing depth map for image '{}' (expected depth/{stem}.npy)",
                im.name
            ))
        })?;
        if (depth.width as u64, depth.height as u64) != (cam.width, cam.height) {
            return Err(Error::InvalidContent(format!(
                "depth/{stem}.npy is {}×{} but camera {} of image '{}' is {}×{}",
                depth.width, depth.height, cam.id, im.name, cam.width, cam.height
            )));
        }
        views.push(GtView {
            name: im.name.clone(),
            cam_from_world: im.cam_from_world,
            fx: cam.fx,
            fy: cam.fy,
            cx: cam.cx,
            cy: cam.cy,
            depth: depth.clone(),
        });
    }
    Ok(views)
}

#[cfg(test)]
pub(crate) mod test_scenes {
    //! Analytic scenes for the visibility and track-error tests: cameras looking at a target,
    //! depth maps ray-traced exactly against a sphere or an axis-aligned box.

    use super::*;
    use crate::geometry::{cross, dot, norm, sub};

    /// A camera at `center` looking at `target`, world up +y (OpenCV axes: y down in the image).
    pub(crate) fn look_at(center: Point3, target: Point3) -> Rigid {
        let f = sub(target, center);
        let z = f.map(|v| v / norm(f));
        let up = [0.0, 1.0, 0.0];
        let mut x = cross(z, up);
        if norm(x) < 1e-9 {
            x = cross(z, [0.0, 0.0, 1.0]);
        }
        let x = x.map(|v| v / norm(x));
        let y = cross(z, x);
        let rotation = [x, y, z];
        Rigid::from_rotation_center(rotation, center)
    }

    /// Renders a depth map of `hit(origin, dir) -> Option<t>` (t along a unit direction) through
    /// each pixel centre.
    pub(crate) fn render(
        pose: Rigid,
        f: f64,
        w: usize,
        h: usize,
        hit: &dyn Fn(Point3, Point3) -> Option<f64>,
    ) -> GtView {
        let mut view = GtView {
            name: String::new(),
            cam_from_world: pose,
            fx: f,
            fy: f,
            cx: w as f64 / 2.0,
            cy: h as f64 / 2.0,
            depth: DepthMap {
                width: w,
                height: h,
                depth: vec![0.0; w * h],
            },
        };
        let c = pose.center();
        for j in 0..h {
            for i in 0..w {
                let (u, v) = (i as f64 + 0.5, j as f64 + 0.5);
                let p = view.back_project(u, v, 1.0); // a point at z = 1 on the ray
                let d = sub(p, c);
                let len = norm(d);
                let dir = d.map(|x| x / len);
                if let Some(t) = hit(c, dir) {
                    // z of the hit = t / len (the ray reaches z = 1 after `len`).
                    view.depth.depth[j * w + i] = (t / len) as f32;
                }
            }
        }
        view
    }

    /// Ray–sphere intersection (nearest positive t).
    pub(crate) fn sphere(center: Point3, r: f64) -> impl Fn(Point3, Point3) -> Option<f64> {
        move |o, d| {
            let oc = sub(o, center);
            let b = dot(oc, d);
            let c = dot(oc, oc) - r * r;
            let disc = b * b - c;
            if disc < 0.0 {
                return None;
            }
            let t = -b - disc.sqrt();
            (t > 0.0).then_some(t)
        }
    }

    /// Ray–box intersection (slab method), axis-aligned box `[lo, hi]`.
    pub(crate) fn aabox(lo: Point3, hi: Point3) -> impl Fn(Point3, Point3) -> Option<f64> {
        move |o, d| {
            let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
            for k in 0..3 {
                let inv = 1.0 / d[k];
                let (mut a, mut b) = ((lo[k] - o[k]) * inv, (hi[k] - o[k]) * inv);
                if a > b {
                    std::mem::swap(&mut a, &mut b);
                }
                t0 = t0.max(a);
                t1 = t1.min(b);
            }
            (t0 <= t1 && t0 > 0.0).then_some(t0)
        }
    }

    /// Appends `x` to `rec` as a 3D point observed, by exact projection, in every view that
    /// sees it (`views[i]` belongs to `rec.images[i]`).
    pub(crate) fn add_observed_point(rec: &mut Reconstruction, views: &[GtView], x: Point3) {
        let point = rec.points.len();
        let mut track = Vec::new();
        for (i, v) in views.iter().enumerate() {
            if !crate::visibility::sees(v, x) {
                continue;
            }
            if let (Some((u, vv, _)), Some(im)) = (v.project(x), rec.images.get_mut(i)) {
                track.push(crate::model::TrackElement {
                    image: i,
                    keypoint: im.observations.len() as u64,
                });
                im.observations.push(crate::model::Observation {
                    xy: [u, vv],
                    point: Some(point),
                });
            }
        }
        rec.points.push(crate::model::Point3D {
            xyz: x,
            color: None,
            error: None,
            track,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::test_scenes::*;
    use super::*;

    #[test]
    fn projection_and_back_projection_are_inverse() {
        let pose = look_at([0.3, 1.0, 4.0], [0.0, 0.0, 0.0]);
        let view = render(pose, 100.0, 64, 48, &sphere([0.0; 3], 1.0));
        let p = [0.2, -0.1, 0.3];
        let (u, v, z) = view.project(p).unwrap();
        let q = view.back_project(u, v, z);
        assert!(crate::geometry::norm(crate::geometry::sub(p, q)) < 1e-12);
        // The depth map of the sphere's front point through the image centre.
        let n = view.neighbourhood(32.0, 24.0).unwrap();
        let d = n.interpolated().unwrap();
        let c = norm3([0.3, 1.0, 4.0]);
        assert!((d - (c - 1.0)).abs() < 1e-3, "{d} vs {}", c - 1.0);
        assert!(view.neighbourhood(64.0, 0.0).is_none());
    }

    fn norm3(p: Point3) -> f64 {
        crate::geometry::norm(p)
    }

    #[test]
    fn build_views_names_the_problem() {
        use crate::model::{Camera, Image};
        let mut rec = Reconstruction::new("cameras_json");
        let mut cam = Camera::simple(1, "PINHOLE", 100.0, 2.0, 1.5);
        cam.width = 4;
        cam.height = 3;
        rec.cameras.push(cam);
        rec.images.push(Image {
            id: 1,
            name: "images/0007.jpg".into(),
            camera_id: 1,
            cam_from_world: Rigid::IDENTITY,
            observations: vec![],
        });
        let mut maps = std::collections::BTreeMap::new();
        let e = build_views(&rec, &maps).unwrap_err().to_string();
        assert!(
            e.contains("depth/0007.npy") && e.contains("0007.jpg"),
            "{e}"
        );
        maps.insert(
            "0007".to_string(),
            DepthMap {
                width: 5,
                height: 3,
                depth: vec![1.0; 15],
            },
        );
        let e = build_views(&rec, &maps).unwrap_err().to_string();
        assert!(e.contains("5×3") && e.contains("4×3"), "{e}");
        maps.insert(
            "0007".to_string(),
            DepthMap {
                width: 4,
                height: 3,
                depth: vec![1.0; 12],
            },
        );
        assert_eq!(build_views(&rec, &maps).unwrap().len(), 1);
    }
}
