//! In-memory geometry: point clouds, triangle meshes, and the ground truth as either.

use crate::error::{Error, Result};

/// A 3D point or vector in f64.
pub type Point3 = [f64; 3];

/// The largest coordinate magnitude the core measures: every reader refuses a vertex, point,
/// camera centre or translation, point-pair coordinate or transform entry beyond ±1e50 with
/// [`Error::OutOfRange`], and the evaluation refuses a transform that maps a reconstructed
/// point beyond it.
///
/// Why 1e50: distances, areas, covariances and the exact point-triangle projection multiply up
/// to four or six coordinates (`(2·10⁵⁰)⁶ ≈ 6·10³⁰¹` still fits an `f64`), and sums of squares
/// over a billion points stay finite, so no derived quantity overflows. Every finite `f32` value
/// (≤ 3.4·10³⁸) is accepted, and no physical scene comes near: 10⁵⁰ m is 10²⁴ light years.
pub const MAX_COORDINATE: f64 = 1e50;

/// `v` for an error message: plain for ordinary magnitudes, in exponent form otherwise.
pub(crate) fn show(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Point positions as stored: `f32` where the file stores `f32` (half the memory of `f64`; a
/// dense cloud of 100M points takes 1.2 GB), `f64` otherwise. Every position is read out as the
/// [`Point3`] it stands for (`f32` widens exactly), so all arithmetic stays in `f64`. Equal
/// when the points are (whatever the storage).
#[derive(Debug, Clone)]
pub enum Positions {
    /// Double precision.
    F64(Vec<Point3>),
    /// Single precision, as the file stored them.
    F32(Vec<[f32; 3]>),
}

impl PartialEq for Positions {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().zip(other.iter()).all(|(a, b)| a == b)
    }
}

impl Default for Positions {
    fn default() -> Self {
        Positions::F64(Vec::new())
    }
}

impl From<Vec<Point3>> for Positions {
    fn from(v: Vec<Point3>) -> Self {
        Positions::F64(v)
    }
}

impl Positions {
    /// Number of points.
    pub fn len(&self) -> usize {
        match self {
            Positions::F64(v) => v.len(),
            Positions::F32(v) => v.len(),
        }
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `i` in `f64` (panics when out of range, as indexing does).
    #[inline]
    pub fn get(&self, i: usize) -> Point3 {
        match self {
            Positions::F64(v) => v[i],
            Positions::F32(v) => v[i].map(f64::from),
        }
    }

    /// The points in order, in `f64`.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Point3> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }

    /// The points as an `f64` slice: borrowed when stored in `f64`, widened into a new vector
    /// otherwise.
    pub fn as_f64(&self) -> std::borrow::Cow<'_, [Point3]> {
        match self {
            Positions::F64(v) => std::borrow::Cow::Borrowed(v),
            Positions::F32(v) => {
                std::borrow::Cow::Owned(v.iter().map(|p| p.map(f64::from)).collect())
            }
        }
    }

    /// The points in `f64`, consuming the storage.
    pub fn into_f64(self) -> Vec<Point3> {
        match self {
            Positions::F64(v) => v,
            Positions::F32(v) => v.into_iter().map(|p| p.map(f64::from)).collect(),
        }
    }

    /// Keeps the points whose `keep(i)` is true, in order, in place.
    pub(crate) fn retain_indices(&mut self, keep: impl Fn(usize) -> bool) {
        let mut i = 0;
        match self {
            Positions::F64(v) => v.retain(|_| (keep(i), i += 1).0),
            Positions::F32(v) => v.retain(|_| (keep(i), i += 1).0),
        }
    }
}

/// Reorders `v` in place so that new slot `k` holds old item `order[k]`, following the
/// permutation's cycles (a bit a slot marks the slots done).
pub(crate) fn permute_in_place<T: Copy>(v: &mut [T], order: &[u32]) {
    debug_assert_eq!(v.len(), order.len());
    let mut done = vec![0u64; v.len().div_ceil(64)];
    for start in 0..v.len() {
        if done[start / 64] >> (start % 64) & 1 == 1 {
            continue;
        }
        let first = v[start];
        let mut k = start;
        loop {
            done[k / 64] |= 1 << (k % 64);
            let from = order[k] as usize;
            if from == start {
                v[k] = first;
                break;
            }
            v[k] = v[from];
            k = from;
        }
    }
}

/// A point cloud with optional per-point colours.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    /// Point positions.
    pub points: Positions,
    /// Per-point RGB colours, when the file has them.
    pub colors: Option<Vec<[u8; 3]>>,
}

/// An indexed triangle mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub vertices: Vec<Point3>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// The reference geometry: a mesh (exact point-to-triangle distances) or a dense cloud
/// (nearest-neighbour distances, the usual laser-scan case).
#[derive(Debug, Clone, PartialEq)]
pub enum GroundTruth {
    /// A triangle mesh.
    Mesh(TriangleMesh),
    /// A dense point cloud.
    Cloud(PointCloud),
}

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: Point3,
    /// Maximum corner.
    pub max: Point3,
}

impl Aabb {
    /// The bounding box of `points`, `None` when there are none.
    pub fn of(points: &[Point3]) -> Option<Aabb> {
        let first = *points.first()?;
        let mut b = Aabb {
            min: first,
            max: first,
        };
        for p in points {
            for (k, &v) in p.iter().enumerate() {
                b.min[k] = b.min[k].min(v);
                b.max[k] = b.max[k].max(v);
            }
        }
        Some(b)
    }

    /// Length of the box diagonal, computed without overflow for any finite corners (the
    /// halves of the extents are taken first when the extents themselves would overflow).
    pub fn diagonal(&self) -> f64 {
        let d = sub(self.max, self.min);
        if d.iter().all(|v| v.is_finite()) {
            return norm(d);
        }
        let half = [0, 1, 2].map(|k| self.max[k] / 2.0 - self.min[k] / 2.0);
        2.0 * norm(half)
    }
}

impl TriangleMesh {
    /// Checks indices and coordinates; `format` names the source in errors.
    pub fn validate(&self, format: &'static str) -> Result<()> {
        if self.triangles.is_empty() {
            return Err(Error::Empty {
                what: format!("{format} mesh (no triangles)"),
            });
        }
        check_finite(format, "vertex", &self.vertices)?;
        let n = self.vertices.len() as u64;
        for (i, t) in self.triangles.iter().enumerate() {
            if let Some(bad) = t.iter().find(|&&v| u64::from(v) >= n) {
                return Err(Error::malformed(
                    format,
                    format!("triangle #{i} uses vertex index {bad} but there are {n} vertices"),
                ));
            }
        }
        Ok(())
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| triangle_area(self.corners(t)))
            .sum()
    }

    /// The three corner positions of triangle `t` (indices must be valid).
    pub fn corners(&self, t: &[u32; 3]) -> [Point3; 3] {
        [
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        ]
    }
}

impl GroundTruth {
    /// The points that bound the ground truth (mesh vertices or cloud points), in `f64`.
    pub fn points(&self) -> std::borrow::Cow<'_, [Point3]> {
        match self {
            GroundTruth::Mesh(m) => std::borrow::Cow::Borrowed(&m.vertices),
            GroundTruth::Cloud(c) => c.points.as_f64(),
        }
    }
}

/// Fails with [`Error::NonFinite`] if any coordinate is NaN or infinite, and with
/// [`Error::OutOfRange`] (naming `what #index` and the axis) if one lies beyond
/// ±[`MAX_COORDINATE`].
pub(crate) fn check_finite(
    format: &'static str,
    what: &'static str,
    points: &[Point3],
) -> Result<()> {
    check_finite_with(format, what, points.len(), |i| points[i])
}

/// [`check_finite`] on the `n` points `point(0..n)`, computed on the fly.
pub(crate) fn check_finite_with(
    format: &'static str,
    what: &'static str,
    n: usize,
    point: impl Fn(usize) -> Point3,
) -> Result<()> {
    check_not_nan_inf(format, what, n, &point)?;
    check_coordinate_range_with(format, what, n, &point)
}

/// Fails with [`Error::OutOfRange`] on the first coordinate beyond ±[`MAX_COORDINATE`] (the
/// coordinates must be finite).
fn check_coordinate_range_with(
    format: &'static str,
    what: &'static str,
    n: usize,
    point: impl Fn(usize) -> Point3,
) -> Result<()> {
    for i in 0..n {
        let p = point(i);
        if let Some(k) = (0..3).find(|&k| !(p[k].abs() <= MAX_COORDINATE)) {
            let count = (0..n)
                .map(&point)
                .filter(|p| p.iter().any(|v| !(v.abs() <= MAX_COORDINATE)))
                .count();
            return Err(Error::out_of_range(
                format,
                format!("{what} #{i}"),
                ["x", "y", "z"][k],
                format!(
                    "is {}, beyond ±{} (the largest coordinate measured); {count} {what}(s) affected",
                    show(p[k]),
                    show(MAX_COORDINATE)
                ),
            ));
        }
    }
    Ok(())
}

/// [`check_finite`] on `f32` positions (every finite `f32` is within range).
pub(crate) fn check_finite_f32(
    format: &'static str,
    what: &'static str,
    points: &[[f32; 3]],
) -> Result<()> {
    let bad = |p: &[f32; 3]| !p.iter().all(|v| v.is_finite());
    let Some(first_index) = points.iter().position(bad) else {
        return Ok(());
    };
    Err(Error::NonFinite {
        format,
        what,
        count: points.iter().filter(|p| bad(p)).count(),
        first_index,
    })
}

fn check_not_nan_inf(
    format: &'static str,
    what: &'static str,
    n: usize,
    point: impl Fn(usize) -> Point3,
) -> Result<()> {
    let mut count = 0;
    let mut first_index = 0;
    for i in 0..n {
        let p = point(i);
        if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
            if count == 0 {
                first_index = i;
            }
            count += 1;
        }
    }
    if count > 0 {
        return Err(Error::NonFinite {
            format,
            what,
            count,
            first_index,
        });
    }
    Ok(())
}

/// a − b.
#[inline]
pub fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Dot product.
#[inline]
pub fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
#[inline]
pub(crate) fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean norm, without overflow or underflow for any finite vector: the plain `√(a·a)`
/// when the squares stay in range (bit-identical to it), else computed on the vector scaled by
/// its largest component.
#[inline]
pub(crate) fn norm(a: Point3) -> f64 {
    let d = dot(a, a);
    if d.is_finite() && d > 1e-290 {
        return d.sqrt();
    }
    norm_scaled(a, d)
}

#[cold]
fn norm_scaled(a: Point3, d: f64) -> f64 {
    if d.is_nan() {
        return f64::NAN;
    }
    let m = a[0].abs().max(a[1].abs()).max(a[2].abs());
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    let s = a.map(|v| v / m);
    m * dot(s, s).sqrt()
}

/// Area of a triangle.
#[inline]
pub(crate) fn triangle_area(c: [Point3; 3]) -> f64 {
    0.5 * norm(cross(sub(c[1], c[0]), sub(c[2], c[0])))
}
