//! COLMAP sparse models, text (`cameras.txt`, `images.txt`, `points3D.txt`) and binary (`.bin`),
//! from bytes. Accepts models written with or without `rigs`/`frames` files (COLMAP ≥ 3.12 adds
//! them; `cameras` and `images` are unchanged, so they are ignored). The folder reader (reached
//! through [`super::read_model_files`]) takes a folder's files by relative path, finds every model in it (`sparse/0`, `sparse/1`, ...), uses
//! the largest and reports the others.
//!
//! Layouts: COLMAP `doc/format.rst`; camera models and parameter counts as pycolmap 4.2.1 lists
//! them (`research/formats.md`).

use std::collections::{BTreeMap, BTreeSet};

use super::text;
use super::{Camera, Image, Observation, Point3D, Reconstruction, Rigid, TrackElement};
use crate::error::{Error, Result};
use crate::note::{Code, Note};

const TXT: &str = "COLMAP text";
const BIN: &str = "COLMAP binary";

/// A COLMAP camera model: id, name, number of parameters and where its focal lengths are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CameraModelInfo {
    /// Numeric id in `cameras.bin`.
    pub id: i32,
    /// Name in `cameras.txt`.
    pub name: &'static str,
    /// Number of parameters.
    pub num_params: usize,
    /// Focal layout.
    pub focal: FocalLayout,
}

/// Where a COLMAP model keeps its focal length(s) and principal point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FocalLayout {
    /// `f, cx, cy, ...` (`SIMPLE_*`, `RADIAL`, ...): `fx = fy = f`.
    Single,
    /// `fx, fy, cx, cy, ...`.
    Double,
    /// No focal length (equirectangular): `fx = fy = 0`, principal point at the image centre.
    None,
}

/// Every camera model of COLMAP 4 (ids 0..=17; COLMAP 3.8 stops at 10).
pub(crate) const CAMERA_MODELS: [CameraModelInfo; 18] = {
    use FocalLayout::{Double as D, None as N, Single as S};
    const fn m(
        id: i32,
        name: &'static str,
        num_params: usize,
        focal: FocalLayout,
    ) -> CameraModelInfo {
        CameraModelInfo {
            id,
            name,
            num_params,
            focal,
        }
    }
    [
        m(0, "SIMPLE_PINHOLE", 3, S),
        m(1, "PINHOLE", 4, D),
        m(2, "SIMPLE_RADIAL", 4, S),
        m(3, "RADIAL", 5, S),
        m(4, "OPENCV", 8, D),
        m(5, "OPENCV_FISHEYE", 8, D),
        m(6, "FULL_OPENCV", 12, D),
        m(7, "FOV", 5, D),
        m(8, "SIMPLE_RADIAL_FISHEYE", 4, S),
        m(9, "RADIAL_FISHEYE", 5, S),
        m(10, "THIN_PRISM_FISHEYE", 12, D),
        m(11, "RAD_TAN_THIN_PRISM_FISHEYE", 16, D),
        m(12, "SIMPLE_DIVISION", 4, S),
        m(13, "DIVISION", 5, D),
        m(14, "SIMPLE_FISHEYE", 3, S),
        m(15, "FISHEYE", 4, D),
        m(16, "EUCM", 6, D),
        m(17, "EQUIRECTANGULAR", 2, N),
    ]
};

/// The camera model with numeric id `id`.
pub(crate) fn camera_model_by_id(id: i64) -> Option<&'static CameraModelInfo> {
    CAMERA_MODELS.iter().find(|m| i64::from(m.id) == id)
}

/// The camera model named `name` (case-insensitive).
pub fn camera_model_by_name(name: &str) -> Option<&'static CameraModelInfo> {
    CAMERA_MODELS
        .iter()
        .find(|m| m.name.eq_ignore_ascii_case(name))
}

/// Builds a [`Camera`] from a COLMAP model and its parameters (count checked).
pub(crate) fn camera_from_params(
    format: &'static str,
    id: u64,
    model: &CameraModelInfo,
    width: u64,
    height: u64,
    params: Vec<f64>,
) -> Result<Camera> {
    if params.len() != model.num_params {
        return Err(Error::malformed(
            format,
            format!(
                "camera {id}: model {} takes {} parameters, found {}",
                model.name,
                model.num_params,
                params.len()
            ),
        ));
    }
    if let Some(i) = params.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            format,
            what: "camera parameter",
            count: params.iter().filter(|v| !v.is_finite()).count(),
            first_index: i,
        });
    }
    let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
    let (fx, fy, cx, cy) = match model.focal {
        FocalLayout::Single => (p(0), p(0), p(1), p(2)),
        FocalLayout::Double => (p(0), p(1), p(2), p(3)),
        FocalLayout::None => (0.0, 0.0, width as f64 / 2.0, height as f64 / 2.0),
    };
    Ok(Camera {
        id,
        model: model.name.to_string(),
        width,
        height,
        fx,
        fy,
        cx,
        cy,
        params,
    })
}

/// An image as stored, before ids are resolved.
struct RawImage {
    id: u64,
    q: [f64; 4],
    t: [f64; 3],
    camera_id: u64,
    name: String,
    points2d: Vec<([f64; 2], Option<u64>)>,
}

/// A 3D point as stored, before ids are resolved.
struct RawPoint {
    id: u64,
    xyz: [f64; 3],
    rgb: [u8; 3],
    error: f64,
    track: Vec<(u64, u64)>,
}

// ---------------------------------------------------------------- text

fn cameras_text(bytes: &[u8]) -> Result<Vec<Camera>> {
    let text = text::utf8(TXT, bytes)?;
    let mut out = Vec::new();
    for (line, l) in text::data_lines(text, '#') {
        let mut it = l.split_whitespace();
        let id: u64 = text::parse(TXT, it.next(), "camera id", line)?;
        let model_tok = it.next().ok_or_else(|| {
            Error::truncated(TXT, format!("cameras.txt line {line}: missing model"))
        })?;
        let model = match model_tok.parse::<i64>() {
            Ok(n) => camera_model_by_id(n),
            Err(_) => camera_model_by_name(model_tok),
        }
        .ok_or_else(|| {
            Error::unsupported(
                TXT,
                format!(
                    "cameras.txt line {line}: unknown camera model '{}'",
                    text::clip(model_tok)
                ),
            )
        })?;
        let width: u64 = text::parse(TXT, it.next(), "width", line)?;
        let height: u64 = text::parse(TXT, it.next(), "height", line)?;
        let params = it
            .map(|t| text::parse::<f64>(TXT, Some(t), "camera parameter", line))
            .collect::<Result<Vec<f64>>>()?;
        out.push(camera_from_params(TXT, id, model, width, height, params)?);
    }
    Ok(out)
}

fn images_text(bytes: &[u8]) -> Result<Vec<RawImage>> {
    let text = text::utf8(TXT, bytes)?;
    let mut lines = text.lines().enumerate();
    let mut out = Vec::new();
    while let Some((i, l)) = lines.next() {
        let line = i + 1;
        let l = l.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let mut it = l.split_whitespace();
        let id: u64 = text::parse(TXT, it.next(), "image id", line)?;
        let mut q = [0.0; 4];
        for (k, v) in q.iter_mut().enumerate() {
            *v = text::parse_f64(TXT, it.next(), ["qw", "qx", "qy", "qz"][k], line)?;
        }
        let mut t = [0.0; 3];
        for (k, v) in t.iter_mut().enumerate() {
            *v = text::parse_f64(TXT, it.next(), ["tx", "ty", "tz"][k], line)?;
        }
        let camera_id: u64 = text::parse(TXT, it.next(), "camera id", line)?;
        let name = it.collect::<Vec<_>>().join(" ");
        if name.is_empty() {
            return Err(Error::truncated(
                TXT,
                format!("images.txt line {line}: missing image name"),
            ));
        }
        // The next line holds the 2D points; it is empty for an image without any.
        let mut points2d = Vec::new();
        if let Some((j, pl)) = lines.next() {
            let toks: Vec<&str> = pl.split_whitespace().collect();
            if !toks.len().is_multiple_of(3) {
                return Err(Error::malformed(
                    TXT,
                    format!(
                        "images.txt line {}: {} values, expected triplets X Y POINT3D_ID",
                        j + 1,
                        toks.len()
                    ),
                ));
            }
            points2d.reserve(toks.len() / 3);
            for c in toks.chunks_exact(3) {
                let x = text::parse_f64(TXT, c.first().copied(), "x", j + 1)?;
                let y = text::parse_f64(TXT, c.get(1).copied(), "y", j + 1)?;
                let pid: i64 = text::parse(TXT, c.get(2).copied(), "point3D id", j + 1)?;
                points2d.push(([x, y], u64::try_from(pid).ok()));
            }
        }
        out.push(RawImage {
            id,
            q,
            t,
            camera_id,
            name,
            points2d,
        });
    }
    Ok(out)
}

fn points_text(bytes: &[u8]) -> Result<Vec<RawPoint>> {
    let text = text::utf8(TXT, bytes)?;
    let mut out = Vec::new();
    for (line, l) in text::data_lines(text, '#') {
        let mut it = l.split_whitespace();
        let id: u64 = text::parse(TXT, it.next(), "point3D id", line)?;
        let mut xyz = [0.0; 3];
        for (k, v) in xyz.iter_mut().enumerate() {
            *v = text::parse_f64(TXT, it.next(), ["X", "Y", "Z"][k], line)?;
        }
        let mut rgb = [0u8; 3];
        for (k, v) in rgb.iter_mut().enumerate() {
            *v = text::parse(TXT, it.next(), ["R", "G", "B"][k], line)?;
        }
        let error: f64 = text::parse(TXT, it.next(), "error", line)?;
        let rest: Vec<&str> = it.collect();
        if !rest.len().is_multiple_of(2) {
            return Err(Error::malformed(
                TXT,
                format!("points3D.txt line {line}: track has an odd number of values"),
            ));
        }
        let track = rest
            .chunks_exact(2)
            .map(|c| {
                Ok((
                    text::parse::<u64>(TXT, c.first().copied(), "track image id", line)?,
                    text::parse::<u64>(TXT, c.get(1).copied(), "track point2D index", line)?,
                ))
            })
            .collect::<Result<Vec<_>>>()?;
        out.push(RawPoint {
            id,
            xyz,
            rgb,
            error,
            track,
        });
    }
    Ok(out)
}

/// Reads a COLMAP text model from the bytes of `cameras.txt`, `images.txt` and (optionally)
/// `points3D.txt`.
pub fn read_colmap_text(
    cameras: &[u8],
    images: &[u8],
    points3d: Option<&[u8]>,
) -> Result<Reconstruction> {
    let cams = cameras_text(cameras)?;
    let imgs = images_text(images)?;
    let pts = match points3d {
        Some(b) => points_text(b)?,
        None => Vec::new(),
    };
    assemble(TXT, "colmap", cams, imgs, pts, points3d.is_none())
}

// ---------------------------------------------------------------- binary

struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    file: &'static str,
}

impl<'a> Cursor<'a> {
    fn new(bytes: &'a [u8], file: &'static str) -> Self {
        Cursor {
            bytes,
            pos: 0,
            file,
        }
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| {
                Error::truncated(
                    BIN,
                    format!("{}: ends inside {what} at byte {}", self.file, self.pos),
                )
            })?;
        let s = self.bytes.get(self.pos..end).unwrap_or_default();
        self.pos = end;
        Ok(s)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let s = self.take(N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    fn u8(&mut self, what: &str) -> Result<u8> {
        Ok(self.array::<1>(what)?[0])
    }
    fn u32(&mut self, what: &str) -> Result<u32> {
        Ok(u32::from_le_bytes(self.array(what)?))
    }
    fn i32(&mut self, what: &str) -> Result<i32> {
        Ok(i32::from_le_bytes(self.array(what)?))
    }
    fn u64(&mut self, what: &str) -> Result<u64> {
        Ok(u64::from_le_bytes(self.array(what)?))
    }
    fn f64(&mut self, what: &str) -> Result<f64> {
        Ok(f64::from_le_bytes(self.array(what)?))
    }

    /// A count of records of at least `min_size` bytes each, checked against the bytes left.
    fn count(&mut self, what: &'static str, min_size: usize) -> Result<usize> {
        let n = self.u64(what)?;
        let available = (self.remaining() / min_size.max(1)) as u64;
        if n > available {
            return Err(Error::CountMismatch {
                format: BIN,
                what,
                declared: n,
                available,
            });
        }
        usize::try_from(n)
            .map_err(|_| Error::malformed(BIN, format!("{} count {n} too large", self.file)))
    }

    fn cstring(&mut self, what: &str) -> Result<String> {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let len = rest.iter().position(|&b| b == 0).ok_or_else(|| {
            Error::truncated(
                BIN,
                format!(
                    "{}: {what} at byte {} has no terminating NUL",
                    self.file, self.pos
                ),
            )
        })?;
        let s = self.take(len, what)?;
        self.pos += 1;
        String::from_utf8(s.to_vec())
            .map_err(|_| Error::malformed(BIN, format!("{}: {what} is not UTF-8", self.file)))
    }

    fn finish(&self) -> Result<()> {
        if self.remaining() != 0 {
            return Err(Error::malformed(
                BIN,
                format!(
                    "{}: {} unexpected bytes after the last record",
                    self.file,
                    self.remaining()
                ),
            ));
        }
        Ok(())
    }
}

fn cameras_binary(bytes: &[u8]) -> Result<Vec<Camera>> {
    let mut c = Cursor::new(bytes, "cameras.bin");
    let n = c.count("cameras", 24)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let id = c.u32("camera id")?;
        let model_id = c.i32("camera model")?;
        let model = camera_model_by_id(i64::from(model_id)).ok_or_else(|| {
            Error::unsupported(
                BIN,
                format!("cameras.bin: camera {id} has unknown model id {model_id}"),
            )
        })?;
        let width = c.u64("width")?;
        let height = c.u64("height")?;
        let mut params = Vec::with_capacity(model.num_params);
        for _ in 0..model.num_params {
            params.push(c.f64("camera parameter")?);
        }
        out.push(camera_from_params(
            BIN,
            u64::from(id),
            model,
            width,
            height,
            params,
        )?);
    }
    c.finish()?;
    Ok(out)
}

fn images_binary(bytes: &[u8]) -> Result<Vec<RawImage>> {
    let mut c = Cursor::new(bytes, "images.bin");
    // id + q + t + camera + NUL + n2d
    let n = c.count("images", 4 + 56 + 4 + 1 + 8)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let id = c.u32("image id")?;
        let mut q = [0.0; 4];
        for v in &mut q {
            *v = c.f64("quaternion")?;
        }
        let mut t = [0.0; 3];
        for v in &mut t {
            *v = c.f64("translation")?;
        }
        let camera_id = c.u32("camera id")?;
        let name = c.cstring("image name")?;
        let n2d = c.count("2D points", 24)?;
        let mut points2d = Vec::with_capacity(n2d);
        for _ in 0..n2d {
            let x = c.f64("x")?;
            let y = c.f64("y")?;
            let pid = c.u64("point3D id")?;
            points2d.push(([x, y], (pid != u64::MAX).then_some(pid)));
        }
        out.push(RawImage {
            id: u64::from(id),
            q,
            t,
            camera_id: u64::from(camera_id),
            name,
            points2d,
        });
    }
    c.finish()?;
    Ok(out)
}

fn points_binary(bytes: &[u8]) -> Result<Vec<RawPoint>> {
    let mut c = Cursor::new(bytes, "points3D.bin");
    let n = c.count("3D points", 8 + 24 + 3 + 8 + 8)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let id = c.u64("point3D id")?;
        let mut xyz = [0.0; 3];
        for v in &mut xyz {
            *v = c.f64("xyz")?;
        }
        let mut rgb = [0u8; 3];
        for v in &mut rgb {
            *v = c.u8("colour")?;
        }
        let error = c.f64("error")?;
        let len = c.count("track elements", 8)?;
        let mut track = Vec::with_capacity(len);
        for _ in 0..len {
            let im = c.u32("track image id")?;
            let kp = c.u32("track point2D index")?;
            track.push((u64::from(im), u64::from(kp)));
        }
        out.push(RawPoint {
            id,
            xyz,
            rgb,
            error,
            track,
        });
    }
    c.finish()?;
    Ok(out)
}

/// Reads a COLMAP binary model from the bytes of `cameras.bin`, `images.bin` and (optionally)
/// `points3D.bin`.
pub fn read_colmap_binary(
    cameras: &[u8],
    images: &[u8],
    points3d: Option<&[u8]>,
) -> Result<Reconstruction> {
    let cams = cameras_binary(cameras)?;
    let imgs = images_binary(images)?;
    let pts = match points3d {
        Some(b) => points_binary(b)?,
        None => Vec::new(),
    };
    assemble(BIN, "colmap_binary", cams, imgs, pts, points3d.is_none())
}

// ---------------------------------------------------------------- assembly

fn assemble(
    fmt: &'static str,
    format: &'static str,
    cameras: Vec<Camera>,
    mut images: Vec<RawImage>,
    mut points: Vec<RawPoint>,
    no_points_file: bool,
) -> Result<Reconstruction> {
    let mut rec = Reconstruction::new(format);
    if no_points_file {
        rec.notes.push(Note::new(
            Code::ModelNoPoints,
            "no points3D file: the model has cameras only",
        ));
    }
    let mut camera_ids = BTreeSet::new();
    for cam in &cameras {
        if !camera_ids.insert(cam.id) {
            return Err(Error::malformed(
                fmt,
                format!("camera id {} appears twice", cam.id),
            ));
        }
    }
    images.sort_by_key(|im| im.id);
    points.sort_by_key(|p| p.id);
    if let Some(w) = images.windows(2).find(|w| w[0].id == w[1].id) {
        return Err(Error::malformed(
            fmt,
            format!("image id {} appears twice", w[0].id),
        ));
    }
    if let Some(w) = points.windows(2).find(|w| w[0].id == w[1].id) {
        return Err(Error::malformed(
            fmt,
            format!("point3D id {} appears twice", w[0].id),
        ));
    }
    let point_index: BTreeMap<u64, usize> =
        points.iter().enumerate().map(|(i, p)| (p.id, i)).collect();
    let image_index: BTreeMap<u64, usize> = images
        .iter()
        .enumerate()
        .map(|(i, im)| (im.id, i))
        .collect();
    let mut dangling_obs = 0usize;
    for im in images {
        if !camera_ids.contains(&im.camera_id) {
            return Err(Error::malformed(
                fmt,
                format!(
                    "image {} ('{}') uses camera {} which is not in cameras",
                    im.id,
                    text::clip(&im.name),
                    im.camera_id
                ),
            ));
        }
        let pose = Rigid::from_quaternion(im.q, im.t).ok_or_else(|| {
            Error::malformed(
                fmt,
                format!(
                    "image {} ('{}') has a zero quaternion",
                    im.id,
                    text::clip(&im.name)
                ),
            )
        })?;
        let observations = im
            .points2d
            .into_iter()
            .map(|(xy, pid)| {
                let point = pid.and_then(|p| {
                    let idx = point_index.get(&p).copied();
                    if idx.is_none() && !no_points_file {
                        dangling_obs += 1;
                    }
                    idx
                });
                Observation { xy, point }
            })
            .collect();
        rec.images.push(Image {
            id: im.id,
            name: im.name,
            camera_id: im.camera_id,
            cam_from_world: pose,
            observations,
        });
    }
    let mut dangling_track = 0usize;
    for p in points {
        let track = p
            .track
            .into_iter()
            .filter_map(|(img, kp)| match image_index.get(&img) {
                Some(&image) => Some(TrackElement {
                    image,
                    keypoint: kp,
                }),
                None => {
                    dangling_track += 1;
                    None
                }
            })
            .collect();
        rec.points.push(Point3D {
            xyz: p.xyz,
            color: Some(p.rgb),
            error: Some(p.error),
            track,
        });
    }
    rec.cameras = cameras;
    if dangling_obs > 0 {
        rec.notes.push(
            Note::new(
                Code::DanglingReferences,
                format!(
                    "{dangling_obs} 2D observation(s) refer to 3D points that are not in points3D"
                ),
            )
            .with("count", dangling_obs),
        );
    }
    if dangling_track > 0 {
        rec.notes.push(
            Note::new(
                Code::DanglingReferences,
                format!(
                    "{dangling_track} track element(s) refer to images that are not in images; dropped"
                ),
            )
            .with("count", dangling_track),
        );
    }
    rec.validate(fmt, true)?;
    Ok(rec)
}

// ---------------------------------------------------------------- folders

/// Which files of one model directory are present.
#[derive(Default)]
struct ModelFiles<'a> {
    bin: [Option<&'a [u8]>; 3],
    txt: [Option<&'a [u8]>; 3],
}

/// Reads every COLMAP model in a folder given as `relative path → bytes` (paths with `/` or
/// `\`), e.g. `sparse/0/cameras.bin`, `sparse/1/images.txt`, or just `cameras.txt` at the root.
/// A directory is a model when it holds `cameras` and `images` (`.bin` preferred over `.txt`, as
/// COLMAP does); `points3D` is optional (a warning). Models under a `dense` folder (undistorted
/// copies) are ignored when any other model exists. Returns the largest model; the others are
/// listed in [`Reconstruction::sub_models`].
pub(crate) fn read_colmap_folder(files: &BTreeMap<String, Vec<u8>>) -> Result<Reconstruction> {
    let models = read_colmap_models(files)?;
    super::choose_largest(models)
}

/// Reads every COLMAP model of a folder (see [`read_colmap_folder`]), named by directory (`.`
/// for the root), in path order.
pub(crate) fn read_colmap_models(
    files: &BTreeMap<String, Vec<u8>>,
) -> Result<Vec<(String, Reconstruction)>> {
    let mut dirs: BTreeMap<String, ModelFiles> = BTreeMap::new();
    for (path, bytes) in files {
        let path = path.replace('\\', "/");
        let (dir, base) = match path.rsplit_once('/') {
            Some((d, b)) => (d.trim_end_matches('/').to_string(), b.to_string()),
            None => (String::new(), path.clone()),
        };
        let slot = match base.as_str() {
            "cameras.bin" => Some((true, 0)),
            "images.bin" => Some((true, 1)),
            "points3D.bin" => Some((true, 2)),
            "cameras.txt" => Some((false, 0)),
            "images.txt" => Some((false, 1)),
            "points3D.txt" => Some((false, 2)),
            _ => None,
        };
        if let Some((is_bin, k)) = slot {
            let entry = dirs.entry(dir).or_default();
            let arr = if is_bin {
                &mut entry.bin
            } else {
                &mut entry.txt
            };
            if let Some(s) = arr.get_mut(k) {
                *s = Some(bytes.as_slice());
            }
        }
    }
    let complete = |m: &ModelFiles| {
        (m.bin[0].is_some() && m.bin[1].is_some()) || (m.txt[0].is_some() && m.txt[1].is_some())
    };
    let is_dense = |d: &str| d.split('/').any(|c| c.eq_ignore_ascii_case("dense"));
    let any_sparse = dirs.iter().any(|(d, m)| complete(m) && !is_dense(d));
    let mut out = Vec::new();
    let mut skipped = Vec::new();
    for (dir, m) in &dirs {
        let name = if dir.is_empty() {
            ".".to_string()
        } else {
            dir.clone()
        };
        if !complete(m) {
            skipped.push(name);
            continue;
        }
        if any_sparse && is_dense(dir) {
            continue;
        }
        let rec = match (m.bin, m.txt) {
            ([Some(c), Some(i), p], _) => read_colmap_binary(c, i, p)?,
            (_, [Some(c), Some(i), p]) => read_colmap_text(c, i, p)?,
            _ => continue,
        };
        out.push((name, rec));
    }
    if out.is_empty() {
        return Err(Error::Empty {
            what: if skipped.is_empty() {
                "COLMAP folder (no cameras/images .bin or .txt files)".to_string()
            } else {
                format!("COLMAP folder (incomplete model in {})", skipped.join(", "))
            },
        });
    }
    if !skipped.is_empty() {
        let note = Note::new(
            Code::IncompleteModelIgnored,
            format!(
                "incomplete COLMAP model files ignored in {}",
                skipped.join(", ")
            ),
        )
        .with("folders", skipped.join(", "));
        for (_, m) in &mut out {
            m.notes.push(note.clone());
        }
    }
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::model::fuzz_tests::fixture;

    fn text_model() -> Reconstruction {
        read_colmap_text(
            &fixture("colmap_text/cameras.txt"),
            &fixture("colmap_text/images.txt"),
            Some(&fixture("colmap_text/points3D.txt")),
        )
        .unwrap()
    }

    #[test]
    fn pycolmap_text_fixture() {
        let r = text_model();
        assert_eq!(r.cameras.len(), 1);
        let c = &r.cameras[0];
        assert_eq!((c.model.as_str(), c.width, c.height), ("PINHOLE", 240, 180));
        assert_eq!((c.fx, c.fy, c.cx, c.cy), (210.0, 210.0, 120.0, 90.0));
        assert_eq!(r.images.len(), 6);
        assert!(r.points.len() > 50);
        assert!(r.notes.is_empty(), "{:?}", r.notes);
        // Every track element points back at an observation of that point.
        for (pi, p) in r.points.iter().enumerate() {
            assert!(p.track.len() >= 2);
            for t in &p.track {
                let obs = r.images[t.image].observations[t.keypoint as usize];
                assert_eq!(obs.point, Some(pi));
            }
        }
    }

    #[test]
    fn binary_equals_text() {
        let t = text_model();
        let b = read_colmap_binary(
            &fixture("colmap_bin/cameras.bin"),
            &fixture("colmap_bin/images.bin"),
            Some(&fixture("colmap_bin/points3D.bin")),
        )
        .unwrap();
        assert_eq!(b.format, "colmap_binary");
        assert_eq!(t.cameras, b.cameras);
        assert_eq!(t.images.len(), b.images.len());
        for (a, b) in t.images.iter().zip(&b.images) {
            assert_eq!(a.name, b.name);
            for k in 0..3 {
                assert!(
                    (a.cam_from_world.translation[k] - b.cam_from_world.translation[k]).abs()
                        < 1e-12
                );
                for j in 0..3 {
                    assert!(
                        (a.cam_from_world.rotation[k][j] - b.cam_from_world.rotation[k][j]).abs()
                            < 1e-12
                    );
                }
            }
            assert_eq!(a.observations.len(), b.observations.len());
        }
        assert_eq!(t.points.len(), b.points.len());
        for (p, q) in t.points.iter().zip(&b.points) {
            assert_eq!(p.track, q.track);
            assert_eq!(p.color, q.color);
            assert!((0..3).all(|k| (p.xyz[k] - q.xyz[k]).abs() < 1e-9));
        }
    }

    #[test]
    fn theia_and_openmvg_colmap_text() {
        // Theia: camera id 0, RADIAL, images in reverse id order, error 0.
        let th = read_colmap_text(
            &fixture("theia_colmap/cameras.txt"),
            &fixture("theia_colmap/images.txt"),
            Some(&fixture("theia_colmap/points3D.txt")),
        )
        .unwrap();
        assert_eq!(th.cameras[0].model, "RADIAL");
        assert_eq!(th.cameras[0].fx, 210.0);
        assert_eq!(th.images.len(), 6);
        assert_eq!(th.images[0].name, "0000.png");
        // openmvg-rs: SIMPLE_PINHOLE, fx = fy = f.
        let om = read_colmap_text(
            &fixture("openmvg_colmap/cameras.txt"),
            &fixture("openmvg_colmap/images.txt"),
            Some(&fixture("openmvg_colmap/points3D.txt")),
        )
        .unwrap();
        assert_eq!(om.cameras[0].model, "SIMPLE_PINHOLE");
        assert_eq!(
            (om.cameras[0].fx, om.cameras[0].fy, om.cameras[0].cx),
            (210.0, 210.0, 120.0)
        );
        assert_eq!(om.images.len(), 6);
    }

    #[test]
    fn every_camera_model_maps_focal_and_principal_point() {
        for m in &CAMERA_MODELS {
            let params: Vec<f64> = (0..m.num_params).map(|i| 100.0 + i as f64).collect();
            let line = format!(
                "7 {} 640 480 {}\n",
                m.name,
                params
                    .iter()
                    .map(|p| p.to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            );
            let c = &cameras_text(line.as_bytes()).unwrap()[0];
            match m.focal {
                FocalLayout::Single => assert_eq!(
                    (c.fx, c.fy, c.cx, c.cy),
                    (100.0, 100.0, 101.0, 102.0),
                    "{}",
                    m.name
                ),
                FocalLayout::Double => assert_eq!(
                    (c.fx, c.fy, c.cx, c.cy),
                    (100.0, 101.0, 102.0, 103.0),
                    "{}",
                    m.name
                ),
                FocalLayout::None => assert_eq!((c.fx, c.cx, c.cy), (0.0, 320.0, 240.0)),
            }
            // Numeric model id works too, and a wrong parameter count is refused.
            let by_id = format!(
                "7 {} 640 480 {}\n",
                m.id,
                params
                    .iter()
                    .map(|p| p.to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            );
            assert_eq!(cameras_text(by_id.as_bytes()).unwrap()[0].model, m.name);
            let short = format!("7 {} 640 480 1\n", m.name);
            if m.num_params != 1 {
                assert!(matches!(
                    cameras_text(short.as_bytes()),
                    Err(Error::Malformed { .. })
                ));
            }
        }
        assert!(matches!(
            cameras_text(b"1 WEIRD 1 1 1"),
            Err(Error::Unsupported { .. })
        ));
    }

    #[test]
    fn empty_points_line_and_name_with_space() {
        let cams = b"1 SIMPLE_PINHOLE 100 80 90 50 40\n";
        let imgs = b"# comment\n1 1 0 0 0 0 0 1 1 my image.jpg\n\n2 1 0 0 0 1 0 1 1 b.jpg\n10 20 5 11 21 -1\n";
        let pts = b"5 0 0 0 1 2 3 0.5 2 0 3 0\n";
        let r = read_colmap_text(cams, imgs, Some(pts)).unwrap();
        assert_eq!(r.images[0].name, "my image.jpg");
        assert!(r.images[0].observations.is_empty());
        assert_eq!(r.images[1].observations[0].point, Some(0));
        assert_eq!(r.images[1].observations[1].point, None);
        assert_eq!(
            r.points[0].track,
            vec![TrackElement {
                image: 1,
                keypoint: 0
            }]
        );
        assert!(r.notes.iter().any(|w| w.message.contains("track element")));
        assert_eq!(r.images[1].center(), [-1.0, 0.0, -1.0]);
    }

    #[test]
    fn bad_inputs_are_typed_errors() {
        let cams = b"1 SIMPLE_PINHOLE 100 80 90 50 40\n";
        // Unknown camera, zero quaternion, NaN translation, bad triplets.
        assert!(matches!(
            read_colmap_text(cams, b"1 1 0 0 0 0 0 1 2 a.jpg\n\n", None),
            Err(Error::Malformed { .. })
        ));
        assert!(matches!(
            read_colmap_text(cams, b"1 0 0 0 0 0 0 1 1 a.jpg\n\n", None),
            Err(Error::Malformed { .. })
        ));
        assert!(matches!(
            read_colmap_text(cams, b"1 1 0 0 0 nan 0 1 1 a.jpg\n\n", None),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            read_colmap_text(cams, b"1 1 0 0 0 0 0 1 1 a.jpg\n1 2\n", None),
            Err(Error::Malformed { .. })
        ));
        assert!(matches!(
            read_colmap_text(cams, b"1 1 0 0 0 0 0 1\n", None),
            Err(Error::Truncated { .. })
        ));
        // Binary: a huge count is refused before allocating.
        let mut b = u64::MAX.to_le_bytes().to_vec();
        b.extend_from_slice(&[0u8; 30]);
        assert!(matches!(
            cameras_binary(&b),
            Err(Error::CountMismatch { .. })
        ));
        assert!(matches!(
            images_binary(&b),
            Err(Error::CountMismatch { .. })
        ));
        assert!(matches!(
            points_binary(&b),
            Err(Error::CountMismatch { .. })
        ));
        // Truncated binary.
        let imgs = fixture("colmap_bin/images.bin");
        assert!(matches!(
            images_binary(&imgs[..imgs.len() - 5]),
            Err(Error::Truncated { .. } | Error::CountMismatch { .. })
        ));
        // Empty model: no images is fine for the reader (the metrics complain).
        let r = read_colmap_text(cams, b"", Some(b"")).unwrap();
        assert!(r.images.is_empty());
    }

    #[test]
    fn folder_with_sub_models_uses_the_largest() {
        let mut files = BTreeMap::new();
        for f in [
            "cameras.bin",
            "images.bin",
            "points3D.bin",
            "rigs.bin",
            "frames.bin",
        ] {
            files.insert(format!("sparse/1/{f}"), fixture(&format!("colmap_bin/{f}")));
        }
        // Same number of images but no points: smaller.
        for f in ["cameras.txt", "images.txt"] {
            files.insert(
                format!("sparse\\0\\{f}"),
                fixture(&format!("theia_colmap/{f}")),
            );
        }
        // A smaller model: only the first image.
        files.insert(
            "sparse/2/cameras.txt".into(),
            b"1 PINHOLE 240 180 210 210 120 90\n".to_vec(),
        );
        files.insert(
            "sparse/2/images.txt".into(),
            b"1 1 0 0 0 0 0 0 1 0000.png\n\n".to_vec(),
        );
        files.insert(
            "sparse/3/cameras.txt".into(),
            b"1 PINHOLE 240 180 210 210 120 90\n".to_vec(),
        );
        files.insert(
            "dense/0/sparse/cameras.txt".into(),
            b"1 PINHOLE 240 180 210 210 120 90\n".to_vec(),
        );
        files.insert("dense/0/sparse/images.txt".into(), b"".to_vec());
        files.insert("database.db".into(), b"x".to_vec());
        let r = read_colmap_folder(&files).unwrap();
        assert_eq!(r.format, "colmap_binary");
        assert_eq!(r.num_models(), 3);
        let names: Vec<&str> = r.sub_models.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["sparse/0", "sparse/2"]);
        assert!(r.notes.iter().any(|w| w.message.contains("largest")));
        assert!(r.notes.iter().any(|w| w.message.contains("sparse/3")));
        assert!(
            r.notes.iter().any(|w| w.message.contains("no points3D"))
                || r.sub_models[1].points == 0
        );
        assert!(matches!(
            read_colmap_folder(&BTreeMap::new()),
            Err(Error::Empty { .. })
        ));
    }
}
