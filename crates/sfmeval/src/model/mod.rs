//! Sparse SfM models (cameras, registered images with poses, 3D points with tracks) read from the
//! bytes of every tool's output into one [`Reconstruction`].
//!
//! | format | reader |
//! |---|---|
//! | COLMAP text / binary (`cameras`, `images`, `points3D`), one or several sub-models | [`colmap::read_colmap_text`], [`colmap::read_colmap_binary`] |
//! | VisualSfM NVM v3 (several models in one file) | [`nvm::read_nvm`] |
//! | Bundler `.out` v0.3 + `list.txt` | [`bundler::read_bundler`] |
//! | OpenMVG `sfm_data.json` | [`openmvg::read_openmvg_json`] |
//! | `cameras.json` (`sfmeval.cameras/1`) | [`cameras_json::read_cameras_json`] |
//! | any of the above among a folder's files, by content and name | [`read_model_files`] |
//!
//! Poses are always `cam_from_world` in the OpenCV/COLMAP convention (x right, y down, z
//! forward; `x_cam = R·X + t`), and intrinsics use COLMAP's pixel convention (the image centre is
//! `(W/2, H/2)`), whatever the file's own convention. Inside the crate, `strip` removes the camera centres
//! that OpenMVG and Theia write into their PLY clouds and `matching` pairs images with
//! ground-truth images by file name.

pub mod bundler;
pub mod cameras_json;
pub mod colmap;
pub mod colmap_write;
pub(crate) mod matching;
pub mod nvm;
pub mod openmvg;
pub(crate) mod strip;
mod text;

#[cfg(test)]
pub(crate) mod fuzz_tests;

use crate::error::{Error, Result};
use crate::geometry::{MAX_COORDINATE, Point3, PointCloud, Positions, show};
use crate::note::{Code, Note};

/// Largest image width or height accepted, in pixels (a gigapixel panorama is 10⁵ wide); 0 means
/// unknown (NVM and Bundler store no size) and is allowed.
pub const MAX_IMAGE_SIZE: u64 = 1_000_000;

/// Focal lengths must lie in `[MIN_FOCAL_PX, MAX_FOCAL_PX]` pixels (positive; a telephoto lens
/// on a small-pixel sensor reaches 10⁶), except for models without one (equirectangular).
pub(crate) const MIN_FOCAL_PX: f64 = 1e-6;

/// See [`MIN_FOCAL_PX`]; principal points must also lie within ±`MAX_FOCAL_PX`.
pub(crate) const MAX_FOCAL_PX: f64 = 1e9;

/// A rotation matrix is accepted when every entry of `R·Rᵀ − I` is within this and its
/// determinant is positive (matrices written with 5 significant digits pass).
pub(crate) const ROTATION_TOLERANCE: f64 = 1e-4;

/// A row-major 3×3 matrix.
pub(crate) type Mat3 = [[f64; 3]; 3];

/// A rigid transform `x ↦ R·x + t`; for a camera pose, `cam_from_world`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rigid {
    /// Row-major rotation.
    pub rotation: Mat3,
    /// Translation.
    pub translation: Point3,
}

impl Rigid {
    /// The identity.
    pub const IDENTITY: Rigid = Rigid {
        rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        translation: [0.0, 0.0, 0.0],
    };

    /// From a Hamilton quaternion `[w, x, y, z]` (normalised here) and a translation. `None`
    /// when the quaternion has zero or non-finite norm.
    pub(crate) fn from_quaternion(q: [f64; 4], translation: Point3) -> Option<Rigid> {
        Some(Rigid {
            rotation: quaternion_to_matrix(q)?,
            translation,
        })
    }

    /// From a rotation and the camera centre `C` (so `t = −R·C`), as NVM and OpenMVG store it.
    pub(crate) fn from_rotation_center(rotation: Mat3, center: Point3) -> Rigid {
        let rc = mat_vec(&rotation, center);
        Rigid {
            rotation,
            translation: [-rc[0], -rc[1], -rc[2]],
        }
    }

    /// The camera centre `C = −Rᵀ·t` (the origin of the camera frame in world coordinates).
    pub fn center(&self) -> Point3 {
        let c = mat_t_vec(&self.rotation, self.translation);
        [-c[0], -c[1], -c[2]]
    }

    /// Applies the transform to a point.
    pub fn apply(&self, p: Point3) -> Point3 {
        let r = mat_vec(&self.rotation, p);
        [
            r[0] + self.translation[0],
            r[1] + self.translation[1],
            r[2] + self.translation[2],
        ]
    }

    /// True when every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.rotation.iter().flatten().all(|v| v.is_finite())
            && self.translation.iter().all(|v| v.is_finite())
    }
}

/// Rotation matrix of a Hamilton quaternion `[w, x, y, z]`, normalised first (without overflow
/// or underflow: any finite, non-zero quaternion is a rotation). `None` for a zero or
/// non-finite quaternion.
pub(crate) fn quaternion_to_matrix(q: [f64; 4]) -> Option<Mat3> {
    let m = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(m.is_finite() && m > 0.0) || q.iter().any(|v| !v.is_finite()) {
        return None;
    }
    // Scaled by the largest component first, so neither 1e308 nor 1e-300 breaks the norm.
    let q = q.map(|v| v / m);
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = q.map(|v| v / n);
    Some([
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ])
}

/// `M·v`.
pub(crate) fn mat_vec(m: &Mat3, v: Point3) -> Point3 {
    [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// `Mᵀ·v`.
pub(crate) fn mat_t_vec(m: &Mat3, v: Point3) -> Point3 {
    [0, 1, 2].map(|i| m[0][i] * v[0] + m[1][i] * v[1] + m[2][i] * v[2])
}

/// `A·B`.
pub(crate) fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

/// `Mᵀ`.
pub(crate) fn transpose(m: &Mat3) -> Mat3 {
    let mut t = [[0.0; 3]; 3];
    for (i, row) in t.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = m[j][i];
        }
    }
    t
}

/// `None` when `r` is a rotation within [`ROTATION_TOLERANCE`] (`R·Rᵀ = I`, determinant +1),
/// else what is wrong.
pub(crate) fn rotation_defect(r: &Mat3) -> Option<String> {
    if r.iter().flatten().any(|v| !v.is_finite()) {
        return Some("has a non-finite entry".into());
    }
    if let Some(v) = r
        .iter()
        .flatten()
        .find(|v| v.abs() > 1.0 + ROTATION_TOLERANCE)
    {
        return Some(format!(
            "is not a rotation: it has an entry of {} (a rotation's are within ±1)",
            show(*v)
        ));
    }
    let rrt = mat_mul(r, &transpose(r));
    let mut worst = 0.0f64;
    for (i, row) in rrt.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            let want = if i == j { 1.0 } else { 0.0 };
            worst = worst.max((v - want).abs());
        }
    }
    if !(worst <= ROTATION_TOLERANCE) {
        return Some(format!(
            "is not a rotation: R·Rᵀ differs from I by {worst:.2e} (tolerance {ROTATION_TOLERANCE:e})"
        ));
    }
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if det < 0.0 {
        return Some("is not a rotation: its determinant is −1 (a reflection)".into());
    }
    None
}

/// Rotation angle of a rotation matrix in degrees, in `[0, 180]`; robust near 0 and 180°
/// (`atan2` of the sine and cosine parts instead of `acos` of the trace).
pub(crate) fn rotation_angle_deg(r: &Mat3) -> f64 {
    let cos = ((r[0][0] + r[1][1] + r[2][2]) - 1.0) / 2.0;
    let v = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]];
    let sin = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() / 2.0;
    libm::atan2(sin, cos).to_degrees()
}

/// A camera (intrinsics) of a reconstruction.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// The file's camera id (COLMAP camera id, OpenMVG intrinsic key, NVM/Bundler camera index).
    pub id: u64,
    /// COLMAP model name (`PINHOLE`, `SIMPLE_RADIAL`, ...), or the format's own name when it has
    /// no COLMAP equivalent (OpenMVG `pinhole_brown_t2` ...).
    pub model: String,
    /// Image width in pixels; 0 when the format does not store it (NVM, Bundler).
    pub width: u64,
    /// Image height in pixels; 0 when unknown.
    pub height: u64,
    /// Focal length along x in pixels (0 when the model has none, e.g. equirectangular).
    pub fx: f64,
    /// Focal length along y in pixels (`fy = fx` for single-focal models).
    pub fy: f64,
    /// Principal point x, COLMAP convention (`W/2` is the image centre); 0 when unknown.
    pub cx: f64,
    /// Principal point y, COLMAP convention; 0 when unknown.
    pub cy: f64,
    /// All parameters as the file stores them (COLMAP order for COLMAP models).
    pub params: Vec<f64>,
}

impl Camera {
    /// A pinhole camera with one focal length and the given principal point.
    #[cfg(test)]
    pub(crate) fn simple(id: u64, model: &str, f: f64, cx: f64, cy: f64) -> Camera {
        Camera {
            id,
            model: model.to_string(),
            width: 0,
            height: 0,
            fx: f,
            fy: f,
            cx,
            cy,
            params: vec![f, cx, cy],
        }
    }

    /// Mean focal length `(fx + fy) / 2` in pixels.
    pub(crate) fn focal(&self) -> f64 {
        0.5 * (self.fx + self.fy)
    }

    /// Whether the model has a focal length at all (equirectangular / OpenMVG `spherical` have
    /// none: `fx = fy = 0`).
    pub(crate) fn has_focal(&self) -> bool {
        let none = colmap::camera_model_by_name(&self.model)
            .is_some_and(|m| m.focal == colmap::FocalLayout::None);
        !(none || self.model.eq_ignore_ascii_case("spherical"))
    }

    /// Checks the intrinsics for sense; `item` names the camera in messages (`camera 3`,
    /// `camera 2 (image 'a.jpg')`). Errors ([`Error::OutOfRange`]): a width or height beyond
    /// [`MAX_IMAGE_SIZE`], only one of them 0, a focal length (of a model with one) outside
    /// `[1e-6, 1e9]` px — negative, zero or absurd —, a principal point or parameter
    /// beyond ±1e9 / ±1e50, a non-finite value. Warnings
    /// (returned): both sizes 0 (unknown) when `size_stored`, a principal point outside the
    /// image.
    pub fn check(
        &self,
        format: &'static str,
        item: &str,
        size_stored: bool,
    ) -> Result<Vec<CameraWarning>> {
        let mut warnings = Vec::new();
        let bad =
            |field: &str, problem: String| Err(Error::out_of_range(format, item, field, problem));
        for (field, v) in [("width", self.width), ("height", self.height)] {
            if v > MAX_IMAGE_SIZE {
                return bad(
                    field,
                    format!("is {v} px, beyond the {MAX_IMAGE_SIZE} px accepted"),
                );
            }
        }
        if (self.width == 0) != (self.height == 0) {
            let field = if self.width == 0 { "width" } else { "height" };
            return bad(
                field,
                format!(
                    "is 0 while the image is {} px {}: image sizes must be 1..={MAX_IMAGE_SIZE} px",
                    self.width.max(self.height),
                    if self.width == 0 { "high" } else { "wide" }
                ),
            );
        }
        if size_stored && self.width == 0 {
            warnings.push(CameraWarning::UnknownSize);
        }
        if self.has_focal() {
            for (field, f) in [("focal length fx", self.fx), ("focal length fy", self.fy)] {
                if !(MIN_FOCAL_PX..=MAX_FOCAL_PX).contains(&f) {
                    return bad(
                        field,
                        format!(
                            "is {} px; a focal length must be positive, in [{}, {}] px",
                            show(f),
                            show(MIN_FOCAL_PX),
                            show(MAX_FOCAL_PX)
                        ),
                    );
                }
            }
        }
        for (field, c) in [
            ("principal point cx", self.cx),
            ("principal point cy", self.cy),
        ] {
            if !(c.abs() <= MAX_FOCAL_PX) {
                return bad(
                    field,
                    format!("is {} px, beyond ±{} px", show(c), show(MAX_FOCAL_PX)),
                );
            }
        }
        if let Some(i) = self.params.iter().position(|v| !v.is_finite()) {
            return bad(&format!("parameter #{i}"), "is not finite".into());
        }
        if let Some(i) = self
            .params
            .iter()
            .position(|v| !(v.abs() <= MAX_COORDINATE))
        {
            return bad(
                &format!("parameter #{i}"),
                format!(
                    "is {}, beyond ±{}",
                    show(self.params[i]),
                    show(MAX_COORDINATE)
                ),
            );
        }
        if self.width > 0 {
            let (w, h) = (self.width as f64, self.height as f64);
            if !(0.0..=w).contains(&self.cx) || !(0.0..=h).contains(&self.cy) {
                warnings.push(CameraWarning::PrincipalPointOutside);
            }
        }
        Ok(warnings)
    }
}

/// Something odd but measurable about a camera ([`Camera::check`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum CameraWarning {
    /// Width and height are both 0 in a format that stores them: unknown.
    UnknownSize,
    /// The principal point lies outside the image.
    PrincipalPointOutside,
}

impl CameraWarning {
    /// The note for the cameras named in `items` (at most five are listed).
    pub(crate) fn note(self, items: &[String]) -> Note {
        let code = match self {
            CameraWarning::UnknownSize => Code::UnknownImageSize,
            CameraWarning::PrincipalPointOutside => Code::PrincipalPointOutside,
        };
        Note::new(code, self.message(items)).with("cameras", items.len())
    }

    /// The words of [`CameraWarning::note`].
    fn message(self, items: &[String]) -> String {
        let mut list = items.iter().take(5).cloned().collect::<Vec<_>>().join(", ");
        if items.len() > 5 {
            list.push_str(&format!(" and {} more", items.len() - 5));
        }
        match self {
            CameraWarning::UnknownSize => format!(
                "{list}: width and height are 0 (unknown): the principal point and the focal-length error cannot be checked against the image size"
            ),
            CameraWarning::PrincipalPointOutside => {
                format!("{list}: the principal point lies outside the image")
            }
        }
    }
}

/// One 2D observation of an image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Pixel coordinates as the file stores them (COLMAP: absolute, COLMAP convention; NVM and
    /// Bundler writers differ, see `research/formats.md`).
    pub xy: [f64; 2],
    /// Index into [`Reconstruction::points`] of the 3D point it observes, if any.
    pub point: Option<usize>,
}

/// A registered image.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// The file's image id (COLMAP image id, OpenMVG view id, NVM/Bundler camera index).
    pub id: u64,
    /// Image file name as written by the tool (may contain folders or backslashes).
    pub name: String,
    /// Id of its [`Camera`] (`Camera::id`).
    pub camera_id: u64,
    /// World-to-camera pose (OpenCV convention).
    pub cam_from_world: Rigid,
    /// 2D observations (empty when the format has none or they were not kept).
    pub observations: Vec<Observation>,
}

impl Image {
    /// The camera centre in world coordinates.
    pub fn center(&self) -> Point3 {
        self.cam_from_world.center()
    }
}

/// One element of a 3D point's track.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrackElement {
    /// Index into [`Reconstruction::images`].
    pub image: usize,
    /// Index of the keypoint in that image (the file's 2D point index / feature id).
    pub keypoint: u64,
}

/// A 3D point.
#[derive(Debug, Clone, PartialEq)]
pub struct Point3D {
    /// Position in the reconstruction's frame.
    pub xyz: Point3,
    /// RGB colour, when the format stores one.
    pub color: Option<[u8; 3]>,
    /// Mean reprojection error in pixels, when the format stores it.
    pub error: Option<f64>,
    /// Observations of the point.
    pub track: Vec<TrackElement>,
}

/// Size of a sub-model that was read but not used (the largest one is used).
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct SubModel {
    /// Where it came from (`sparse/1`, `model 2`, ...).
    pub name: String,
    /// Registered images.
    pub images: usize,
    /// 3D points.
    pub points: usize,
}

/// A sparse reconstruction in memory: the one type every SfM reader returns.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Reconstruction {
    /// Cameras (intrinsics).
    pub cameras: Vec<Camera>,
    /// Registered images.
    pub images: Vec<Image>,
    /// Names of images the file lists without a pose (Bundler zero cameras, OpenMVG views
    /// without extrinsics).
    pub unregistered: Vec<String>,
    /// 3D points.
    pub points: Vec<Point3D>,
    /// Format name for the report (`colmap`, `colmap_binary`, `nvm`, `bundler`, `openmvg`,
    /// `cameras_json`).
    pub format: &'static str,
    /// Things a user should know (dropped references, other sub-models, ...).
    pub notes: Vec<Note>,
    /// The other sub-models found beside this one (this one is the largest).
    pub sub_models: Vec<SubModel>,
}

impl Reconstruction {
    /// Notes the images the file lists without a pose ([`Reconstruction::unregistered`]),
    /// when there are any: one `input.unregistered_images` note with their `count`, its
    /// message the count and the format's words for them (`what`).
    pub(crate) fn note_unregistered(&mut self, what: &str) {
        let count = self.unregistered.len();
        if count > 0 {
            self.notes.push(
                Note::new(Code::UnregisteredImages, format!("{count} {what}")).with("count", count),
            );
        }
    }

    /// An empty reconstruction of the given format.
    pub fn new(format: &'static str) -> Reconstruction {
        Reconstruction {
            format,
            ..Default::default()
        }
    }

    /// Number of separate models the source held (this one plus [`Self::sub_models`]).
    pub fn num_models(&self) -> usize {
        1 + self.sub_models.len()
    }

    /// Camera centres of the registered images, in image order.
    pub(crate) fn camera_centers(&self) -> Vec<Point3> {
        self.images.iter().map(Image::center).collect()
    }

    /// Records that image `image` (an index) sees the point about to be pushed as number
    /// `point` at pixel `xy`, feature `keypoint`: the image's observation and the track element.
    /// Readers whose tracks name images directly (NVM, Bundler, OpenMVG) share this.
    pub(crate) fn observe(
        &mut self,
        track: &mut Vec<TrackElement>,
        image: usize,
        keypoint: u64,
        xy: [f64; 2],
        point: usize,
    ) {
        if let Some(im) = self.images.get_mut(image) {
            im.observations.push(Observation {
                xy,
                point: Some(point),
            });
        }
        track.push(TrackElement { image, keypoint });
    }

    /// The camera of an image, if present.
    pub(crate) fn camera_of(&self, image: &Image) -> Option<&Camera> {
        self.cameras.iter().find(|c| c.id == image.camera_id)
    }

    /// The 3D points as a cloud (colours when every point has one).
    pub fn to_point_cloud(&self) -> PointCloud {
        let colors: Option<Vec<[u8; 3]>> = self.points.iter().map(|p| p.color).collect();
        PointCloud {
            points: Positions::F64(self.points.iter().map(|p| p.xyz).collect()),
            colors: if self.points.is_empty() { None } else { colors },
        }
    }

    /// A summary of this model's size under `name`.
    pub(crate) fn summary(&self, name: &str) -> SubModel {
        SubModel {
            name: name.to_string(),
            images: self.images.len(),
            points: self.points.len(),
        }
    }

    /// Checks what a reader returns, and adds its warnings: every camera's intrinsics
    /// ([`Camera::check`]; `size_stored` when the format stores the image size), every pose
    /// (finite, a rotation within 1e-4, translation and camera centre within ±1e50), every 3D
    /// point and 2D observation within ±1e50.
    /// Errors name the camera or image and the field ([`Error::OutOfRange`]).
    pub fn validate(&mut self, format: &'static str, size_stored: bool) -> Result<()> {
        // One camera per image (NVM, Bundler): name the image too.
        let mut first_image: std::collections::BTreeMap<u64, &str> = Default::default();
        if !size_stored {
            for im in &self.images {
                first_image.entry(im.camera_id).or_insert(im.name.as_str());
            }
        }
        let mut noted: std::collections::BTreeMap<CameraWarning, Vec<String>> = Default::default();
        for cam in &self.cameras {
            let item = match first_image.get(&cam.id) {
                Some(name) => format!("camera {} (image '{}')", cam.id, text::clip(name)),
                None => format!("camera {}", cam.id),
            };
            for w in cam.check(format, &item, size_stored)? {
                noted.entry(w).or_default().push(item.clone());
            }
        }
        let notes: Vec<Note> = noted.into_iter().map(|(w, items)| w.note(&items)).collect();
        for im in &self.images {
            let item = || format!("image '{}' (id {})", text::clip(&im.name), im.id);
            if let Some(defect) = rotation_defect(&im.cam_from_world.rotation) {
                return Err(Error::out_of_range(format, item(), "rotation", defect));
            }
            for (field, v) in [
                ("translation", im.cam_from_world.translation),
                ("camera centre", im.center()),
            ] {
                if let Some(k) = (0..3).find(|&k| !(v[k].abs() <= MAX_COORDINATE)) {
                    return Err(Error::out_of_range(
                        format,
                        item(),
                        format!("{field} {}", ["x", "y", "z"][k]),
                        format!(
                            "is {}, beyond ±{} (the largest coordinate measured)",
                            show(v[k]),
                            show(MAX_COORDINATE)
                        ),
                    ));
                }
            }
            if let Some((k, o)) = im
                .observations
                .iter()
                .enumerate()
                .find(|(_, o)| o.xy.iter().any(|v| !(v.abs() <= MAX_COORDINATE)))
            {
                return Err(Error::out_of_range(
                    format,
                    item(),
                    format!("observation #{k}"),
                    format!(
                        "is at ({}, {}), beyond ±{} px",
                        show(o.xy[0]),
                        show(o.xy[1]),
                        show(MAX_COORDINATE)
                    ),
                ));
            }
        }
        self.check_finite(format)?;
        self.notes.extend(notes);
        Ok(())
    }

    /// Fails with [`Error::NonFinite`] when a pose or a point is NaN/infinite, and with
    /// [`Error::OutOfRange`] when a point lies beyond ±[`MAX_COORDINATE`].
    pub(crate) fn check_finite(&self, format: &'static str) -> Result<()> {
        let bad: Vec<usize> = self
            .images
            .iter()
            .enumerate()
            .filter(|(_, im)| !im.cam_from_world.is_finite())
            .map(|(i, _)| i)
            .collect();
        if let Some(&first_index) = bad.first() {
            return Err(Error::NonFinite {
                format,
                what: "image pose",
                count: bad.len(),
                first_index,
            });
        }
        let pts: Vec<Point3> = self.points.iter().map(|p| p.xyz).collect();
        crate::geometry::check_finite(format, "3D point", &pts)
    }
}

/// Picks the largest model (most registered images, then most points; the first on ties) of
/// several named ones and records the others in its [`Reconstruction::sub_models`] with a
/// warning. Fails with [`Error::Empty`] when `models` is empty.
pub(crate) fn choose_largest(models: Vec<(String, Reconstruction)>) -> Result<Reconstruction> {
    let mut best: Option<usize> = None;
    for (i, (_, m)) in models.iter().enumerate() {
        let better = match best.and_then(|b| models.get(b)) {
            None => true,
            Some((_, b)) => (m.images.len(), m.points.len()) > (b.images.len(), b.points.len()),
        };
        if better {
            best = Some(i);
        }
    }
    let best = best.ok_or_else(|| Error::Empty {
        what: "SfM model (no sub-model found)".into(),
    })?;
    let summaries: Vec<SubModel> = models
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != best)
        .map(|(_, (name, m))| m.summary(name))
        .collect();
    let mut models = models;
    let (name, mut chosen) = models.swap_remove(best);
    if !summaries.is_empty() {
        let others: Vec<String> = summaries
            .iter()
            .map(|s| format!("{} ({} images, {} points)", s.name, s.images, s.points))
            .collect();
        let note = Note::new(
            Code::SeveralModels,
            format!(
                "{} separate models; using the largest, {} ({} images, {} points); not used: {}",
                summaries.len() + 1,
                name,
                chosen.images.len(),
                chosen.points.len(),
                others.join(", ")
            ),
        )
        .with("models", summaries.len() + 1)
        .with("used", name.as_str());
        chosen.notes.push(note);
    }
    chosen.sub_models.extend(summaries);
    Ok(chosen)
}

/// An SfM model format [`detect_model_format`] recognises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ModelFormat {
    /// A COLMAP model file (`cameras`/`images`/`points3D`, `.txt` or `.bin`).
    Colmap,
    /// VisualSfM NVM.
    Nvm,
    /// Bundler `.out`.
    Bundler,
    /// OpenMVG `sfm_data.json`.
    OpenMvg,
    /// `cameras.json` (`sfmeval.cameras/1`).
    CamerasJson,
}

/// Recognises an SfM model file by content first (`NVM_V3`, `# Bundle file`, JSON with
/// `sfm_data_version`/`views` or `"schema": "sfmeval.cameras/1"` at its start or end), then by
/// name.
pub(crate) fn detect_model_format(name: &str, bytes: &[u8]) -> Option<ModelFormat> {
    let base = name.rsplit(['/', '\\']).next().unwrap_or(name);
    let head = bytes.get(..bytes.len().min(4096)).unwrap_or_default();
    let head_text = String::from_utf8_lossy(head);
    let trimmed = head_text.trim_start_matches('\u{feff}').trim_start();
    if trimmed.starts_with("NVM_V3") {
        return Some(ModelFormat::Nvm);
    }
    if trimmed.starts_with("# Bundle file") {
        return Some(ModelFormat::Bundler);
    }
    if trimmed.starts_with('{') {
        // The schema tag may sit anywhere: writers that sort keys put it last.
        let tail = bytes
            .get(bytes.len().saturating_sub(4096)..)
            .unwrap_or_default();
        let tail_text = String::from_utf8_lossy(tail);
        if head_text.contains("sfmeval.cameras/") || tail_text.contains("sfmeval.cameras/") {
            return Some(ModelFormat::CamerasJson);
        }
        if head_text.contains("sfm_data_version") || head_text.contains("\"views\"") {
            return Some(ModelFormat::OpenMvg);
        }
    }
    let lower = base.to_ascii_lowercase();
    match lower.as_str() {
        "cameras.txt" | "images.txt" | "points3d.txt" | "cameras.bin" | "images.bin"
        | "points3d.bin" => Some(ModelFormat::Colmap),
        _ if lower.ends_with(".nvm") => Some(ModelFormat::Nvm),
        _ if lower.ends_with(".out") => Some(ModelFormat::Bundler),
        "cameras.json" => Some(ModelFormat::CamerasJson),
        "sfm_data.json" => Some(ModelFormat::OpenMvg),
        _ => None,
    }
}

/// Reads an SfM model from a set of files (`relative path → bytes`): a COLMAP folder (one or
/// several sub-models), or one NVM, Bundler `.out` (with its `list.txt` / `*.list.txt` beside
/// it when present), OpenMVG `sfm_data.json` or `cameras.json` file. COLMAP wins when both are
/// present. Fails with [`Error::UnknownFormat`] when nothing is recognised.
pub fn read_model_files(
    files: &std::collections::BTreeMap<String, Vec<u8>>,
) -> Result<Reconstruction> {
    let detected: Vec<(&String, &Vec<u8>, ModelFormat)> = files
        .iter()
        .filter_map(|(n, b)| detect_model_format(n, b).map(|f| (n, b, f)))
        .collect();
    if detected.iter().any(|d| d.2 == ModelFormat::Colmap) {
        return colmap::read_colmap_folder(files);
    }
    let Some(&(name, bytes, format)) = detected.first() else {
        return Err(Error::UnknownFormat(format!(
            "no SfM model among {} file(s) (expected a COLMAP model, .nvm, Bundler .out, sfm_data.json or cameras.json)",
            files.len()
        )));
    };
    let mut rec = match format {
        ModelFormat::Nvm => nvm::read_nvm(bytes)?,
        ModelFormat::OpenMvg => openmvg::read_openmvg_json(bytes)?,
        ModelFormat::CamerasJson => cameras_json::read_cameras_json(bytes)?,
        ModelFormat::Bundler => {
            let norm = name.replace('\\', "/");
            let (dir, base) = norm.rsplit_once('/').unwrap_or(("", norm.as_str()));
            let stem = base.strip_suffix(".out").unwrap_or(base);
            let stem = stem.strip_suffix(".bundle").unwrap_or(stem);
            let join = |f: &str| {
                if dir.is_empty() {
                    f.to_string()
                } else {
                    format!("{dir}/{f}")
                }
            };
            let list = [join(&format!("{stem}.list.txt")), join("list.txt")]
                .iter()
                .find_map(|k| files.get(k))
                .map(Vec::as_slice);
            bundler::read_bundler(bytes, list)?
        }
        ModelFormat::Colmap => colmap::read_colmap_folder(files)?,
    };
    if detected.len() > 1 {
        rec.notes.push(
            Note::new(
                Code::SeveralModelFiles,
                format!(
                    "{} model files found; read '{}'",
                    detected.len(),
                    text::clip(name)
                ),
            )
            .with("files", detected.len())
            .with("read", name.as_str()),
        );
    }
    Ok(rec)
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used, clippy::disallowed_methods)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_and_center() {
        // 90° about z.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let p = Rigid::from_quaternion([h, 0.0, 0.0, h], [1.0, 2.0, 3.0]).unwrap();
        let r = p.rotation;
        assert!((r[0][1] + 1.0).abs() < 1e-15 && (r[1][0] - 1.0).abs() < 1e-15);
        let c = p.center();
        let back = p.apply(c);
        assert!(back.iter().all(|v| v.abs() < 1e-12));
        let q = Rigid::from_rotation_center(r, c);
        assert!((q.translation[2] - 3.0).abs() < 1e-12);
        assert!((rotation_angle_deg(&r) - 90.0).abs() < 1e-12);
        assert!(Rigid::from_quaternion([0.0; 4], [0.0; 3]).is_none());
        assert!(Rigid::from_quaternion([f64::NAN, 0.0, 0.0, 0.0], [0.0; 3]).is_none());
    }

    #[test]
    fn rotation_angle_small_and_half_turn() {
        let t = 1e-7f64;
        let r = [
            [t.cos(), -t.sin(), 0.0],
            [t.sin(), t.cos(), 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert!((rotation_angle_deg(&r) - t.to_degrees()).abs() < 1e-15);
        let half = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
        assert!((rotation_angle_deg(&half) - 180.0).abs() < 1e-12);
    }

    #[test]
    fn largest_is_chosen_and_others_reported() {
        let mut a = Reconstruction::new("colmap");
        a.images.push(Image {
            id: 1,
            name: "a.jpg".into(),
            camera_id: 1,
            cam_from_world: Rigid::IDENTITY,
            observations: vec![],
        });
        let b = Reconstruction::new("colmap");
        let chosen = choose_largest(vec![("sparse/0".into(), b), ("sparse/1".into(), a)]).unwrap();
        assert_eq!(chosen.images.len(), 1);
        assert_eq!(chosen.num_models(), 2);
        assert_eq!(chosen.sub_models[0].name, "sparse/0");
        assert!(chosen.notes[0].message.contains("sparse/1"));
        assert!(matches!(choose_largest(vec![]), Err(Error::Empty { .. })));
    }

    #[test]
    fn read_model_files_dispatches_by_content_and_name() {
        use crate::model::fuzz_tests::fixture;
        use std::collections::BTreeMap;
        let one = |name: &str, fix: &str| {
            let mut m = BTreeMap::new();
            m.insert(name.to_string(), fixture(fix));
            m
        };
        let nvm = read_model_files(&one("run/model.NVM", "colmap38.nvm")).unwrap();
        assert_eq!((nvm.format, nvm.images.len()), ("nvm", 6));
        let om = read_model_files(&one(
            "reconstruction/sfm_data.json",
            "openmvg_sfm_data.json",
        ))
        .unwrap();
        assert_eq!(om.format, "openmvg");
        let cj = read_model_files(&one("x.json", "gt_cameras.json")).unwrap();
        assert_eq!(cj.format, "cameras_json");
        let mut b = one("out/colmap38.bundle.out", "colmap38.bundle.out");
        b.insert("out/colmap38.list.txt".into(), fixture("colmap38.list.txt"));
        let bu = read_model_files(&b).unwrap();
        assert_eq!(bu.images[0].name, "0003.png");
        let mut c = BTreeMap::new();
        for f in ["cameras.txt", "images.txt", "points3D.txt"] {
            c.insert(
                format!("sparse/0/{f}"),
                fixture(&format!("colmap_text/{f}")),
            );
        }
        c.insert("notes.txt".into(), b"hello".to_vec());
        assert_eq!(read_model_files(&c).unwrap().format, "colmap");
        assert!(matches!(
            read_model_files(&one("a.ply", "openmvg.ply")),
            Err(Error::UnknownFormat(_))
        ));
        assert_eq!(
            detect_model_format("x", b"NVM_V3\n"),
            Some(ModelFormat::Nvm)
        );
        assert_eq!(
            detect_model_format("points3D.BIN", b"\0"),
            Some(ModelFormat::Colmap)
        );
    }

    /// A cameras.json with sorted keys has its schema tag last, beyond the first 4 KiB (the
    /// runner writes them so): still recognised, by content and under any name.
    #[test]
    fn cameras_json_with_the_schema_at_the_end() {
        let images: Vec<String> = (0..100)
            .map(|i| {
                format!(
                    r#"{{"cam_from_world": {{"rotation": [[1,0,0],[0,1,0],[0,0,1]], "translation": [{i},0,0]}}, "camera_id": 1, "name": "{i:04}.jpg"}}"#
                )
            })
            .collect();
        let text = format!(
            r#"{{"cameras": [{{"cx": 320.0, "cy": 180.0, "fx": 700.0, "fy": 700.0, "height": 360, "id": 1, "model": "PINHOLE", "width": 640}}], "frame": "reconstruction", "images": [{}], "schema": "sfmeval.cameras/1"}}"#,
            images.join(", ")
        );
        assert!(text.len() > 8192);
        assert_eq!(
            detect_model_format("run/out.json", text.as_bytes()),
            Some(ModelFormat::CamerasJson)
        );
        let model = read_model_files(&std::collections::BTreeMap::from([(
            "run/out.json".to_string(),
            text.into_bytes(),
        )]))
        .unwrap();
        assert_eq!(model.format, "cameras_json");
        assert_eq!(model.images.len(), 100);
        // by name when the content says nothing
        assert_eq!(
            detect_model_format("a/cameras.json", b"{}"),
            Some(ModelFormat::CamerasJson)
        );
        assert_eq!(
            detect_model_format("a/sfm_data.json", b"{}"),
            Some(ModelFormat::OpenMvg)
        );
    }
}
