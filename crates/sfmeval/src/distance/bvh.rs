//! A compact bounding-volume hierarchy over triangles for exact closest-point queries.
//!
//! Why not parry's `TriMesh` BVH (used before): on the 1M-triangle bench mesh it needed about
//! 340 MB of peak memory to build (one node of 112 bytes per triangle plus build buffers) and
//! its f64 nodes do not fit the cache. Here a node is 32 bytes (`f32` bounds rounded outwards,
//! so a box never shrinks), leaves hold up to [`LEAF_SIZE`] triangles, and the two children of
//! a node sit side by side in one cache line. The leaf test is parry's exact f64
//! point-triangle projection, so every distance is as exact as before; only the pruning uses
//! the rounded boxes, and pruning with a box that contains the true one never drops the answer.
//!
//! Each leaf also keeps a [`LeafBound`] block: a conservative `f32` lower bound on the distance
//! to each of its triangles, four at a time. The exact test runs only for a triangle whose
//! bound is below the best distance so far (near-surface queries on a smooth mesh: about 4
//! exact tests instead of 24), and the answer stays the one testing every triangle gives.

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQueryWithLocation as _;
use parry3d_f64::shape::Triangle;

use super::leaf_bound::{self, LANES, LeafBound};
use super::{down, up};
use crate::geometry::{Point3, TriangleMesh, sub};

/// Most triangles in a leaf: one [`LeafBound`] block.
pub(crate) const LEAF_SIZE: usize = LANES;

/// Deepest tree the fixed traversal stack allows (median splits give ~log2(n / 4) + 1 ≤ 31).
const MAX_DEPTH: usize = 64;

/// One node: `count > 0` is a leaf over `tris[index .. index + count]` (`index` a multiple of
/// [`LEAF_SIZE`]: leaf `index / LEAF_SIZE`'s slots, its bound block `bounds[index / LEAF_SIZE]`);
/// `count == 0` is an inner node whose children are `nodes[index]` and `nodes[index + 1]`.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(32))]
struct Node {
    min: [f32; 3],
    count: u32,
    max: [f32; 3],
    index: u32,
}

impl Node {
    /// Squared distance from `p` to the node's box (0 inside).
    #[inline]
    fn distance2(&self, p: &Point3) -> f64 {
        let mut d2 = 0.0;
        for ((&min, &max), &pk) in self.min.iter().zip(&self.max).zip(p) {
            let d = (f64::from(min) - pk).max(pk - f64::from(max)).max(0.0);
            d2 += d * d;
        }
        d2
    }

    /// The lower corner and the size of the box, the frame of a leaf's bound block.
    #[inline]
    fn origin_extent(&self) -> (Point3, Point3) {
        let origin = self.min.map(f64::from);
        (origin, sub(self.max.map(f64::from), origin))
    }
}

/// The closest point of the hierarchy's triangles to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Closest {
    /// Squared Euclidean distance.
    pub distance2: f64,
    /// The closest point.
    pub point: Point3,
    /// Index of its triangle in the input mesh.
    pub triangle: u32,
    /// That triangle's corners.
    pub corners: [Point3; 3],
}

/// The hierarchy: nodes, the triangles in leaf order (vertex indices; [`LEAF_SIZE`] slots a
/// leaf, the unused ones never read), their input indices and each leaf's bound block.
pub(crate) struct TriangleBvh {
    nodes: Vec<Node>,
    vertices: Vec<Point3>,
    tris: Vec<[u32; 3]>,
    ids: Vec<u32>,
    bounds: Vec<LeafBound>,
}

impl TriangleBvh {
    /// Builds the hierarchy by median splits of the triangle centroids along the longest axis.
    /// The mesh must be valid (vertex indices in range, finite vertices); deterministic.
    pub(crate) fn new(mesh: &TriangleMesh) -> Self {
        let centroids: Vec<Point3> = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = mesh.corners(t);
                [
                    (a[0] + b[0] + c[0]) / 3.0,
                    (a[1] + b[1] + c[1]) / 3.0,
                    (a[2] + b[2] + c[2]) / 3.0,
                ]
            })
            .collect();
        let mut order: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * mesh.triangles.len() / LEAF_SIZE + 2);
        nodes.push(Node::default());
        let mut leaves = Vec::with_capacity(mesh.triangles.len() / (LEAF_SIZE - 1) + 1);
        let mut builder = Builder {
            mesh,
            centroids: &centroids,
            order: &mut order,
            nodes: &mut nodes,
            leaves: &mut leaves,
        };
        if !mesh.triangles.is_empty() {
            builder.build(0, 0, mesh.triangles.len(), 0);
        }
        drop(centroids);
        let slots = leaves.len() * LEAF_SIZE;
        let mut tris = vec![[0u32; 3]; slots];
        let mut ids = vec![0u32; slots];
        let mut bounds = Vec::with_capacity(leaves.len());
        for (leaf, &(start, end, origin, extent)) in leaves.iter().enumerate() {
            let slot = leaf * LEAF_SIZE;
            let mut corners = [[[0.0; 3]; 3]; LEAF_SIZE];
            for (k, &i) in order[start..end].iter().enumerate() {
                tris[slot + k] = mesh.triangles[i as usize];
                ids[slot + k] = i;
                corners[k] = mesh.corners(&mesh.triangles[i as usize]);
            }
            bounds.push(LeafBound::new(&corners[..end - start], origin, extent));
        }
        TriangleBvh {
            nodes,
            vertices: mesh.vertices.clone(),
            tris,
            ids,
            bounds,
        }
    }

    /// Number of nodes (for tests and the memory estimate).
    #[cfg(test)]
    pub(crate) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The corners of leaf-order triangle `k`.
    fn corners(&self, k: usize) -> [Point3; 3] {
        let t = self.tris[k];
        [
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        ]
    }

    /// The exact closest surface point to `p`; `None` for an empty mesh or a non-finite `p`.
    /// Of triangles at the same distance, the first in the traversal's order.
    pub(crate) fn closest(&self, p: Point3) -> Option<Closest> {
        self.search::<true>(p)
    }

    /// The search; `BOUND` false tests every triangle of a visited leaf exactly (the reference
    /// the bounds are checked against in the tests).
    fn search<const BOUND: bool>(&self, p: Point3) -> Option<Closest> {
        if self.tris.is_empty() || !p.iter().all(|v| v.is_finite()) {
            return None;
        }
        let q = Vector::new(p[0], p[1], p[2]);
        let mut best = Closest {
            distance2: f64::INFINITY,
            point: p,
            triangle: 0,
            corners: [p; 3],
        };
        let mut stack = [(0u32, 0.0f64); MAX_DEPTH];
        let mut depth = 0;
        let mut node = self.nodes[0];
        loop {
            if node.count > 0 {
                let start = node.index as usize;
                let bounds2 = if BOUND {
                    let (origin, extent) = node.origin_extent();
                    let local = sub(p, origin);
                    let margin = leaf_bound::margin(local, origin, extent);
                    let scale = leaf_bound::offset_scale(extent) as f32;
                    self.bounds[start / LEAF_SIZE].lower_bounds2(
                        local.map(|v| v as f32),
                        scale,
                        margin,
                    )
                } else {
                    [0.0; LANES]
                };
                for (lane, &bound2) in bounds2.iter().enumerate().take(node.count as usize) {
                    if f64::from(bound2) >= best.distance2 {
                        continue;
                    }
                    let k = start + lane;
                    #[cfg(test)]
                    tests::EXACT_TESTS.with(|n| n.set(n.get() + 1));
                    let [a, b, c] = self.corners(k);
                    let tri = Triangle::new(
                        Vector::new(a[0], a[1], a[2]),
                        Vector::new(b[0], b[1], b[2]),
                        Vector::new(c[0], c[1], c[2]),
                    );
                    let (proj, _) = tri.project_local_point_and_get_location(q, false);
                    let d = proj.point - q;
                    let d2 = d.dot(d);
                    if d2 < best.distance2 {
                        best = Closest {
                            distance2: d2,
                            point: [proj.point.x, proj.point.y, proj.point.z],
                            triangle: self.ids[k],
                            corners: [a, b, c],
                        };
                    }
                }
            } else {
                let (l, r) = (node.index as usize, node.index as usize + 1);
                let (dl, dr) = (self.nodes[l].distance2(&p), self.nodes[r].distance2(&p));
                let ((near, dn), (far, df)) = if dl <= dr {
                    ((l, dl), (r, dr))
                } else {
                    ((r, dr), (l, dl))
                };
                if dn < best.distance2 {
                    if df < best.distance2 && depth < MAX_DEPTH {
                        stack[depth] = (far as u32, df);
                        depth += 1;
                    }
                    node = self.nodes[near];
                    continue;
                }
            }
            // Next pending node still closer than the best so far.
            loop {
                if depth == 0 {
                    return Some(best);
                }
                depth -= 1;
                let (i, d) = stack[depth];
                if d < best.distance2 {
                    node = self.nodes[i as usize];
                    break;
                }
            }
        }
    }
}

struct Builder<'a> {
    mesh: &'a TriangleMesh,
    centroids: &'a [Point3],
    order: &'a mut [u32],
    nodes: &'a mut Vec<Node>,
    /// Per leaf, in slot order: its range of `order`, its node's lower corner and extent (as
    /// the search computes them from the node).
    leaves: &'a mut Vec<(usize, usize, Point3, Point3)>,
}

impl Builder<'_> {
    /// Fills `nodes[slot]` with the subtree over `order[start..end]`.
    fn build(&mut self, slot: usize, start: usize, end: usize, depth: usize) {
        let n = end - start;
        // Median splits halve the range: a depth of at most 31 for u32 triangle indices, so
        // the traversal stack (MAX_DEPTH) always suffices.
        debug_assert!(depth < MAX_DEPTH);
        if n <= LEAF_SIZE {
            self.nodes[slot] = self.leaf(start, end);
            return;
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &i in &self.order[start..end] {
            let c = self.centroids[i as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
        if (0..3).all(|k| hi[k] == lo[k]) {
            // Every centroid in one place: copies of one triangle (a glTF node graph that
            // instances a mesh many times in the same place) would make every query visit
            // them all, since the rounded boxes never prune an equally distant copy. Only the
            // distinct ones are kept (the first of each by input order, so results do not
            // change: a copy is never strictly closer).
            let unique = self.drop_copies(start, end);
            if unique < n {
                self.build(slot, start, start + unique, depth);
                return;
            }
        }
        let axis = (0..3)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap_or(0);
        let mid = n / 2;
        let centroids = self.centroids;
        self.order[start..end].select_nth_unstable_by(mid, |&a, &b| {
            centroids[a as usize][axis]
                .total_cmp(&centroids[b as usize][axis])
                .then(a.cmp(&b))
        });
        let children = self.nodes.len();
        self.nodes.push(Node::default());
        self.nodes.push(Node::default());
        self.build(children, start, start + mid, depth + 1);
        self.build(children + 1, start + mid, end, depth + 1);
        let (l, r) = (self.nodes[children], self.nodes[children + 1]);
        self.nodes[slot] = Node {
            min: [0, 1, 2].map(|k| l.min[k].min(r.min[k])),
            count: 0,
            max: [0, 1, 2].map(|k| l.max[k].max(r.max[k])),
            index: children as u32,
        };
    }

    /// Moves the distinct triangles of `order[start..end]` (same corners in the same cyclic
    /// order = a copy) to its front, the first of each by input index, and returns how many.
    fn drop_copies(&mut self, start: usize, end: usize) -> usize {
        let mesh = self.mesh;
        // Corners rotated so the smallest comes first (a rotation keeps the winding).
        let key = |i: u32| -> [u64; 9] {
            let c = mesh.corners(&mesh.triangles[i as usize]);
            let bits = |p: Point3| p.map(f64::to_bits);
            let smallest = (0..3)
                .min_by(|&a, &b| {
                    let (pa, pb) = (c[a], c[b]);
                    (0..3)
                        .map(|k| pa[k].total_cmp(&pb[k]))
                        .find(|o| o.is_ne())
                        .unwrap_or(std::cmp::Ordering::Equal)
                })
                .unwrap_or(0);
            let [a, b, d] = [0, 1, 2].map(|k| bits(c[(smallest + k) % 3]));
            [a[0], a[1], a[2], b[0], b[1], b[2], d[0], d[1], d[2]]
        };
        // Sorted by a hash of the key (16 bytes a triangle, the key itself computed once),
        // then each hash run compared exactly.
        let hash = |k: &[u64; 9]| {
            k.iter().fold(0x9e37_79b9_7f4a_7c15u64, |h, &w| {
                let mut z = (h ^ w).wrapping_add(0x9e37_79b9_7f4a_7c15);
                z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                z ^ (z >> 31)
            })
        };
        let slice = &mut self.order[start..end];
        let mut keyed: Vec<(u64, u32)> = slice.iter().map(|&i| (hash(&key(i)), i)).collect();
        keyed.sort_unstable();
        let mut unique = 0;
        let mut run_start = 0;
        for (k, &(h, i)) in keyed.iter().enumerate() {
            if k == 0 || keyed[k - 1].0 != h {
                run_start = unique;
            }
            let ki = key(i);
            if !slice[run_start..unique].iter().any(|&u| key(u) == ki) {
                slice[unique] = i;
                unique += 1;
            }
        }
        // The copies left behind are never referenced by a leaf.
        unique
    }

    /// A leaf over `order[start..end]` (at most [`LEAF_SIZE`] triangles), its box rounded
    /// outwards to `f32`, recorded in `leaves`.
    fn leaf(&mut self, start: usize, end: usize) -> Node {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &i in &self.order[start..end] {
            for v in self.mesh.corners(&self.mesh.triangles[i as usize]) {
                for k in 0..3 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
        }
        let node = Node {
            min: lo.map(down),
            count: (end - start) as u32,
            max: hi.map(up),
            index: (self.leaves.len() * LEAF_SIZE) as u32,
        };
        let (origin, extent) = node.origin_extent();
        self.leaves.push((start, end, origin, extent));
        node
    }
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::*;
    use parry3d_f64::shape::{TriMesh, TriMeshFlags};
    use std::cell::Cell;

    thread_local! {
        /// Exact point-triangle tests run on this thread.
        pub(super) static EXACT_TESTS: Cell<usize> = const { Cell::new(0) };
    }

    fn exact_tests() -> usize {
        EXACT_TESTS.with(Cell::get)
    }

    /// The leaf bounds change nothing, bit for bit, and skip most exact tests: on a smooth
    /// surface with near-surface queries (the usual case), at unit scale and far from the
    /// origin, and for queries far from the surface.
    #[test]
    fn leaf_bounds_keep_the_answer_and_skip_most_tests() {
        for (offset, scale, spread) in [
            ([0.0; 3], 1.0, 0.05),
            ([0.0; 3], 1.0, 3.0),
            ([4e5, -1e6, 2.5e5], 1e-2, 0.05),
        ] {
            let mut mesh = blob(60);
            for v in &mut mesh.vertices {
                *v = [0, 1, 2].map(|k| offset[k] + scale * v[k]);
            }
            let bvh = TriangleBvh::new(&mesh);
            let (mut with, mut without) = (0, 0);
            for (i, p) in queries(2000).into_iter().enumerate() {
                // near the surface: a surface point pushed along its radius
                let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt().max(1e-9);
                let t = 1.0 + spread * ((i % 7) as f64 / 3.0 - 1.0);
                let p = [0, 1, 2].map(|k| offset[k] + scale * p[k] / r * t);
                let before = exact_tests();
                let reference = bvh.search::<false>(p).unwrap();
                let middle = exact_tests();
                let hit = bvh.closest(p).unwrap();
                without += middle - before;
                with += exact_tests() - middle;
                assert_eq!(hit, reference, "{p:?}");
            }
            eprintln!("{offset:?} {spread}: {with} exact tests with the bounds, {without} without");
            assert!(
                spread > 1.0 || with * 4 < without,
                "{offset:?} {spread}: {with} exact tests with the bounds, {without} without"
            );
        }
    }

    /// A bumpy closed sphere of 2·n·(n-1) triangles with scrambled triangle order.
    fn blob(n: usize) -> TriangleMesh {
        let mut vertices = Vec::new();
        for i in 0..=n {
            for j in 0..n {
                let th = std::f64::consts::PI * i as f64 / n as f64;
                let ph = std::f64::consts::TAU * j as f64 / n as f64;
                let r = 1.0 + 0.2 * (3.0 * th).sin() * (5.0 * ph).cos();
                vertices.push([
                    r * th.sin() * ph.cos(),
                    r * th.sin() * ph.sin(),
                    r * th.cos(),
                ]);
            }
        }
        let id = |i: usize, j: usize| (i * n + j % n) as u32;
        let mut triangles = Vec::new();
        for i in 0..n {
            for j in 0..n {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        // scramble deterministically
        let len = triangles.len();
        for k in 0..len {
            triangles.swap(k, (k * 7919 + 13) % len);
        }
        TriangleMesh {
            vertices,
            triangles,
        }
    }

    fn queries(m: usize) -> Vec<Point3> {
        (0..m as u64)
            .map(|i| {
                let h = i.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x5bd1_e995;
                let f = |s: u32| ((h >> s) & 0xffff) as f64 / 65535.0 * 3.0 - 1.5;
                [f(0), f(16), f(32)]
            })
            .collect()
    }

    /// A glTF that instances one mesh in many nodes at the same place stacks exact copies:
    /// queries must not visit every copy (they did: the f32 boxes never prune an equally
    /// distant copy), and the answer must not change.
    #[test]
    fn stacked_copies_do_not_slow_queries() {
        let mut mesh = blob(20);
        let n0 = mesh.triangles.len();
        let first = mesh.triangles[7];
        assert!(n0 > 7);
        for k in 0..200_000 {
            // The same triangle, also with its corners rotated (same winding).
            let t = first;
            mesh.triangles.push(match k % 3 {
                0 => t,
                1 => [t[1], t[2], t[0]],
                _ => [t[2], t[0], t[1]],
            });
        }
        // And the mesh again in the same place (every triangle copied once).
        let again: Vec<[u32; 3]> = mesh.triangles[..n0].to_vec();
        mesh.triangles.extend(again);
        let bvh = TriangleBvh::new(&mesh);
        let reference = TriangleBvh::new(&blob(20));
        assert!(
            bvh.node_count() < 4 * reference.node_count(),
            "{}",
            bvh.node_count()
        );
        let t = std::time::Instant::now();
        for p in queries(3000) {
            let hit = bvh.closest(p).unwrap();
            let want = reference.closest(p).unwrap();
            assert_eq!(hit.distance2, want.distance2, "{p:?}");
        }
        assert!(t.elapsed().as_secs_f64() < 2.0, "{:?}", t.elapsed());
    }

    #[test]
    fn rounding_outwards() {
        for v in [0.1, -0.1, 1.0 / 3.0, 1e30, -7.25, 0.0] {
            assert!(f64::from(down(v)) <= v && f64::from(up(v)) >= v, "{v}");
        }
        assert_eq!(down(0.5), 0.5);
        assert_eq!(up(0.5), 0.5);
    }

    #[test]
    fn same_answer_as_a_brute_force_search_and_as_parry() {
        let mesh = blob(40);
        let bvh = TriangleBvh::new(&mesh);
        let parry = TriMesh::with_flags(
            mesh.vertices
                .iter()
                .map(|p| Vector::new(p[0], p[1], p[2]))
                .collect(),
            mesh.triangles.clone(),
            TriMeshFlags::empty(),
        )
        .unwrap();
        for p in queries(400) {
            let hit = bvh.closest(p).unwrap();
            let q = Vector::new(p[0], p[1], p[2]);
            // brute force over every triangle with the same exact leaf test
            let brute = mesh
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = mesh.corners(t);
                    let tri = Triangle::new(
                        Vector::new(a[0], a[1], a[2]),
                        Vector::new(b[0], b[1], b[2]),
                        Vector::new(c[0], c[1], c[2]),
                    );
                    let d = tri.project_local_point_and_get_location(q, false).0.point - q;
                    d.dot(d)
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!(hit.distance2, brute, "at {p:?}");
            let (proj, _) = parry.project_local_point_and_get_location(q, false);
            let dp = (proj.point - q).length();
            assert!(
                (hit.distance2.sqrt() - dp).abs() <= 1e-15 * dp.max(1.0),
                "{p:?}"
            );
            // the reported triangle holds the reported point
            let [a, b, c] = mesh.corners(&mesh.triangles[hit.triangle as usize]);
            let tri = Triangle::new(
                Vector::new(a[0], a[1], a[2]),
                Vector::new(b[0], b[1], b[2]),
                Vector::new(c[0], c[1], c[2]),
            );
            let own = tri.project_local_point_and_get_location(q, false).0.point;
            assert_eq!([own.x, own.y, own.z], hit.point);
        }
    }

    #[test]
    fn compact_and_deterministic() {
        let mesh = blob(30);
        let a = TriangleBvh::new(&mesh);
        let b = TriangleBvh::new(&mesh);
        assert_eq!(a.ids, b.ids);
        assert_eq!(std::mem::size_of::<Node>(), 32);
        // a binary tree over ceil(n / 4)..n / 2 leaves
        assert!(a.node_count() < mesh.triangles.len());
        // every triangle in exactly one leaf slot
        let mut ids: Vec<u32> = a
            .nodes
            .iter()
            .filter(|n| n.count > 0)
            .flat_map(|n| &a.ids[n.index as usize..(n.index + n.count) as usize])
            .copied()
            .collect();
        ids.sort_unstable();
        assert_eq!(a.bounds.len() * LEAF_SIZE, a.ids.len());
        assert_eq!(ids, (0..mesh.triangles.len() as u32).collect::<Vec<_>>());
    }

    #[test]
    fn single_triangle_and_non_finite_queries() {
        let mesh = TriangleMesh {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
        };
        let bvh = TriangleBvh::new(&mesh);
        let hit = bvh.closest([0.25, 0.25, 2.0]).unwrap();
        assert_eq!(hit.distance2, 4.0);
        assert_eq!(hit.point, [0.25, 0.25, 0.0]);
        assert!(bvh.closest([f64::NAN, 0.0, 0.0]).is_none());
        assert!(bvh.closest([f64::INFINITY, 0.0, 0.0]).is_none());
    }
}
