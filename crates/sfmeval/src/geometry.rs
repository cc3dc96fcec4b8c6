//! In-memory geometry: point clouds, triangle meshes, and the ground truth as either.

use crate::error::{Error, Result};

/// A 3D point or vector in f64.
pub type Point3 = [f64; 3];

/// A point cloud with optional per-point colours.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    /// Point positions.
    pub points: Vec<Point3>,
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

    /// Length of the box diagonal.
    pub fn diagonal(&self) -> f64 {
        norm(sub(self.max, self.min))
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
    /// The points that bound the ground truth (mesh vertices or cloud points).
    pub fn points(&self) -> &[Point3] {
        match self {
            GroundTruth::Mesh(m) => &m.vertices,
            GroundTruth::Cloud(c) => &c.points,
        }
    }
}

/// Fails with [`Error::NonFinite`] if any coordinate is NaN or infinite.
pub fn check_finite(format: &'static str, what: &'static str, points: &[Point3]) -> Result<()> {
    let mut count = 0;
    let mut first_index = 0;
    for (i, p) in points.iter().enumerate() {
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
pub fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean norm.
#[inline]
pub fn norm(a: Point3) -> f64 {
    dot(a, a).sqrt()
}

/// Area of a triangle.
#[inline]
pub fn triangle_area(c: [Point3; 3]) -> f64 {
    0.5 * norm(cross(sub(c[1], c[0]), sub(c[2], c[0])))
}
