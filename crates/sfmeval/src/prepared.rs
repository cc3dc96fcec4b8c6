//! A ground truth indexed once for many evaluations and alignments: its BVH (mesh) or k-d tree
//! (cloud), its bounding box, and its seeded completeness samples.

use crate::distance::{CloudIndex, MeshHint, MeshIndex};
use crate::error::{Error, Result};
use crate::geometry::{Aabb, GroundTruth, Point3};
use crate::progress::{Progress, Stage};
use crate::sampling::sample_surface_with_area;

enum GtIndex {
    Mesh(Box<MeshIndex>),
    Cloud(CloudIndex),
}

/// A ground truth ready for many evaluations: its BVH or k-d tree and its completeness samples.
pub struct PreparedGroundTruth {
    index: GtIndex,
    pub(crate) samples: Vec<Point3>,
    pub(crate) sample_seed: u64,
    pub(crate) requested_samples: usize,
    /// Bounding box of the ground truth.
    pub aabb: Aabb,
    pub(crate) vertices: u64,
    pub(crate) triangles: u64,
    pub(crate) area: f64,
}

impl PreparedGroundTruth {
    /// Indexes the ground truth and draws `samples` surface samples with `seed` (a cloud ground
    /// truth uses its own points instead).
    pub fn new(
        gt: &GroundTruth,
        samples: usize,
        seed: u64,
        progress: &dyn Progress,
    ) -> Result<Self> {
        let aabb = Aabb::of(&gt.points()).ok_or_else(|| Error::Empty {
            what: "ground truth".into(),
        })?;
        if !(aabb.diagonal() > 0.0) {
            return Err(Error::Geometry(
                "the ground truth has zero extent (all points identical)".into(),
            ));
        }
        progress.start(Stage::IndexGroundTruth, 1);
        let (index, pts, vertices, triangles, area) = match gt {
            GroundTruth::Mesh(m) => {
                // The samples and the area are drawn while the BVH is built (its serial
                // steps leave cores idle); the mesh is checked first, as both read it.
                m.validate("mesh")?;
                let (idx, sampled) = crate::parallel::join(
                    || MeshIndex::of_validated(m),
                    || sample_surface_with_area(m, samples, seed),
                );
                progress.finish();
                progress.start(Stage::Sampling, 1);
                let (s, area) = sampled?;
                (
                    GtIndex::Mesh(Box::new(idx)),
                    s,
                    m.vertices.len(),
                    m.triangles.len(),
                    area,
                )
            }
            GroundTruth::Cloud(c) => (
                GtIndex::Cloud(CloudIndex::new(&c.points.as_f64())?),
                c.points.as_f64().into_owned(),
                c.points.len(),
                0,
                0.0,
            ),
        };
        progress.finish();
        Ok(PreparedGroundTruth {
            index,
            samples: pts,
            sample_seed: seed,
            requested_samples: samples,
            aabb,
            vertices: vertices as u64,
            triangles: triangles as u64,
            area,
        })
    }

    /// Distance from `p` to the ground truth, and its signed version (mesh only).
    pub fn distance(&self, p: Point3, signed: bool) -> (f64, Option<f64>) {
        self.distance_from(p, signed, &mut MeshHint::default())
    }

    /// [`Self::distance`] for a query near the previous one with the same `hint` (a mesh
    /// query starts from the previous answer: the same result, faster).
    pub(crate) fn distance_from(
        &self,
        p: Point3,
        signed: bool,
        hint: &mut MeshHint,
    ) -> (f64, Option<f64>) {
        match &self.index {
            GtIndex::Mesh(m) => {
                let hit = m.closest_from(p, hint);
                (hit.distance, signed.then(|| m.signed(p, &hit)))
            }
            GtIndex::Cloud(c) => (c.nearest(p).0, None),
        }
    }

    /// The closest ground-truth point to `p` (for ICP correspondences), starting from `hint`
    /// as `distance_from` does.
    pub fn closest_point(&self, p: Point3, hint: &mut MeshHint) -> (Point3, f64) {
        match &self.index {
            GtIndex::Mesh(m) => {
                let hit = m.closest_from(p, hint);
                (hit.closest, hit.distance)
            }
            GtIndex::Cloud(c) => {
                let (d, i) = c.nearest(p);
                (self.samples.get(i).copied().unwrap_or(p), d)
            }
        }
    }

    /// Whether this was prepared with `samples` completeness samples drawn with `seed` (a cloud
    /// ground truth uses its own points: only the seed, which the report echoes, counts).
    pub(crate) fn prepared_with(&self, samples: usize, seed: u64) -> bool {
        self.sample_seed == seed && (self.requested_samples == samples || !self.is_mesh())
    }

    /// Whether the ground truth is a mesh.
    pub fn is_mesh(&self) -> bool {
        matches!(self.index, GtIndex::Mesh(_))
    }

    /// The completeness samples (surface samples, or the cloud's points).
    pub fn samples(&self) -> &[Point3] {
        &self.samples
    }
}
