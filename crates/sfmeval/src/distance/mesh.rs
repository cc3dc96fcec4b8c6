//! Exact point-to-triangle-mesh distance through a compact BVH ([`super::bvh`]) whose leaves
//! run parry's exact f64 point-triangle projection.

use super::bvh::{Hint, TriangleBvh};
use crate::error::Result;
use crate::geometry::{Point3, TriangleMesh, cross, dot, norm, sub};

/// The closest point of the mesh to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshHit {
    /// Unsigned Euclidean distance.
    pub distance: f64,
    /// The closest point on the surface.
    pub closest: Point3,
    /// Index of the triangle the closest point lies on.
    pub triangle: u32,
    /// Its corners (for the signed distance).
    corners: [Point3; 3],
}

/// Where a query of [`MeshIndex::closest_from`] starts: the previous answer. One a thread,
/// carried from query to query (a new one is a cold start).
#[derive(Debug, Clone, Copy, Default)]
pub struct MeshHint(Hint);

/// The hit of a BVH answer (`None`: NaN distance).
fn hit(p: Point3, found: Option<super::bvh::Closest>) -> MeshHit {
    match found {
        Some(c) => MeshHit {
            distance: norm(sub(p, c.point)),
            closest: c.point,
            triangle: c.triangle,
            corners: c.corners,
        },
        None => MeshHit {
            distance: f64::NAN,
            closest: p,
            triangle: 0,
            corners: [[0.0; 3]; 3],
        },
    }
}

/// A triangle mesh indexed for closest-point queries.
pub struct MeshIndex {
    bvh: TriangleBvh,
}

impl MeshIndex {
    /// Builds the BVH. The mesh must be valid ([`TriangleMesh::validate`]).
    pub fn new(mesh: &TriangleMesh) -> Result<Self> {
        mesh.validate("mesh")?;
        Ok(Self::of_validated(mesh))
    }

    /// [`Self::new`] of a mesh its caller has validated already.
    pub(crate) fn of_validated(mesh: &TriangleMesh) -> Self {
        MeshIndex {
            bvh: TriangleBvh::new(mesh),
        }
    }

    /// The closest surface point to `p` (a non-finite `p` gets a NaN distance). Of triangles
    /// at the same distance, the one with the smallest index.
    pub fn closest(&self, p: Point3) -> MeshHit {
        hit(p, self.bvh.closest(p))
    }

    /// [`Self::closest`] (the same answer, bit for bit) starting from where the previous query
    /// with this `hint` ended: faster when consecutive queries are near each other in space.
    pub fn closest_from(&self, p: Point3, hint: &mut MeshHint) -> MeshHit {
        hit(p, self.bvh.closest_from(p, &mut hint.0))
    }

    /// Distance signed by the normal of the closest triangle (positive on the side the
    /// counter-clockwise normal points to), as CloudCompare's C2M does.
    pub(crate) fn signed(&self, p: Point3, hit: &MeshHit) -> f64 {
        // The triangle's normal, computed when asked (a stored one costs 24 bytes a triangle).
        let [a, b, c] = hit.corners;
        let n = cross(sub(b, a), sub(c, a));
        if dot(sub(p, hit.closest), n) < 0.0 {
            -hit.distance
        } else {
            hit.distance
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> TriangleMesh {
        TriangleMesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
        }
    }

    #[test]
    fn face_edge_and_vertex_regions() {
        let idx = MeshIndex::new(&tri()).unwrap();
        // Face region: straight above the interior.
        let h = idx.closest([0.25, 0.25, 2.0]);
        assert!((h.distance - 2.0).abs() < 1e-15);
        assert!(idx.signed([0.25, 0.25, -2.0], &idx.closest([0.25, 0.25, -2.0])) < 0.0);
        // Edge region (beyond the hypotenuse x + y = 1): closest point is on the edge.
        let h = idx.closest([1.0, 1.0, 0.0]);
        assert!((h.distance - (0.5f64).sqrt()).abs() < 1e-15);
        // Vertex region (beyond vertex (1,0,0) along +x, and below in y).
        let h = idx.closest([2.0, -1.0, 1.0]);
        assert!((h.distance - 3.0f64.sqrt()).abs() < 1e-15, "{}", h.distance);
        assert_eq!(h.closest, [1.0, 0.0, 0.0]);
    }

    #[test]
    fn degenerate_triangle_does_not_break_queries() {
        let mut m = tri();
        m.vertices.push([5.0, 0.0, 0.0]);
        m.vertices.push([6.0, 0.0, 0.0]);
        m.triangles.push([3, 4, 1]); // collinear: a segment from x=1 to x=6 on the x axis
        let idx = MeshIndex::new(&m).unwrap();
        let h = idx.closest([5.5, 0.0, 1.0]);
        assert!(h.distance.is_finite());
        assert!((h.distance - 1.0).abs() < 1e-12, "{}", h.distance);
    }
}
