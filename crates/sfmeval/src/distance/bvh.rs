//! A compact 4-wide bounding-volume hierarchy over triangles for exact closest-point queries.
//!
//! Why not parry's `TriMesh` BVH (used before): on the 1M-triangle bench mesh it needed about
//! 340 MB of peak memory to build (one node of 112 bytes per triangle plus build buffers) and
//! its f64 nodes do not fit the cache. Here a node holds the boxes of its four children as
//! `f32` lanes, structure of arrays (128 bytes, two cache lines; with the oriented boxes below,
//! 256 bytes), so one visit tests four boxes in a few vector instructions. The boxes are
//! relative to the mesh's centre (so they stay tight for georeferenced coordinates, where
//! absolute `f32` is coarser than a triangle) and rounded outwards, and the box distance is computed to be a lower bound (query rounded
//! outwards too, a margin for the `f64` exact test, a relative guard on the `f32` squares):
//! pruning with it never drops the answer. Leaves hold up to [`LEAF_SIZE`] triangles, tested
//! with parry's exact f64 point-triangle projection.
//!
//! Each node also keeps its children's oriented boxes ([`OrientedLanes`]: a patch's normal
//! and two tangents, the interval of its triangles along each), for children of up to
//! [`oriented::MAX_SLOTS`] triangles; a child is visited only if both its axis-aligned and its
//! oriented box are near enough. A query hovering over a finely tessellated surface (a
//! reconstruction's noise is several triangle widths) then expands about half as many nodes
//! and leaves: the axis-aligned box of a tilted patch is thick along the normal and reaches up
//! to queries far to the side of it.
//!
//! Each leaf also keeps a [`LeafBound`] block: a conservative `f32` lower bound on the distance
//! to each of its triangles, four at a time. The exact test runs only for a triangle whose
//! bound is not above the best distance so far (near-surface queries on a smooth mesh: about 4
//! exact tests instead of 24).
//!
//! The answer is the triangle with the smallest exact squared distance and, among equal ones,
//! the smallest input index: it does not depend on the tree's shape or the visiting order, so
//! a query may start from a hint (the previous query's triangle), and the result equals a
//! brute-force search over every triangle bit for bit.
//!
//! On x86-64 CPUs with AVX2 and FMA (detected at run time) the search runs a copy of itself
//! compiled for them, the one `unsafe` call of the workspace: the same arithmetic (Rust never
//! fuses a multiply and an add on its own), so the same bits, in fewer instructions (the
//! three-operand forms, 16-bit to `f32` lane widening in one step): about 0.91× the time of a
//! one-thread accuracy run on the 1M-triangle bench. Elsewhere, and in the wasm build, the
//! portable code runs.

use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQueryWithLocation as _;
use parry3d_f64::shape::Triangle;

use super::leaf_bound::{self, LANES, LeafBound};
use super::median_split;
use super::oriented::{self, OrientedLanes, OrientedQuery};
use super::split_key::Keyed;
use super::{down, up};
use crate::geometry::{Point3, TriangleMesh, sub};
use crate::parallel;

/// Most triangles in a leaf: one [`LeafBound`] block.
pub(crate) const LEAF_SIZE: usize = LANES;

/// Children of an inner node.
const WIDTH: usize = oriented::WIDTH;

/// A child code with this bit set is a leaf (the rest its index), else an inner node's index.
const LEAF: u32 = 1 << 31;

/// An unused lane's child code.
const EMPTY: u32 = u32::MAX;

/// The traversal stack: at most `WIDTH - 1` pending children a level; median splits of fewer
/// than 2^32 triangles give at most 32 binary levels, 16 of this tree's.
const STACK: usize = (WIDTH - 1) * 32 + 1;

/// Query coordinates relative to the centre are clamped into ±`CLAMP` (every box lies inside
/// ±`MAX_RELATIVE`, so the clamped point's distance to a box is not above the true one, and no
/// `f32` square overflows).
const CLAMP: f64 = (1u64 << 60) as f64;

/// Largest relative coordinate the `f32` boxes are used for; a mesh reaching farther gets
/// unbounded boxes (every leaf visited: correct, slow, and only for absurd inputs).
const MAX_RELATIVE: f64 = (1u64 << 59) as f64;

/// Relative guard on the `f32` box distances: the rounding of the differences, squares and
/// sums stays well within 2⁻²⁰.
const SHRINK: f32 = 1.0 - 1.0 / (1u32 << 20) as f32;

/// Absolute guard against `f32` underflow of a tiny squared distance (a normal number: a
/// subnormal operand would be slow on every node).
const TINY: f32 = f32::MIN_POSITIVE;

/// An inner node: the boxes of up to [`WIDTH`] children, per axis and lane, relative to the
/// tree's centre (an unused lane: `+∞` to `−∞`, never visited), and each child's code and
/// triangle count (a leaf's; 0 for an inner node).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
struct Node {
    min: [[f32; WIDTH]; 3],
    max: [[f32; WIDTH]; 3],
    child: [u32; WIDTH],
    count: [u8; WIDTH],
    /// The children's oriented boxes (none above [`oriented::MAX_SLOTS`] triangles).
    oriented: OrientedLanes,
}

const EMPTY_NODE: Node = Node {
    min: [[f32::INFINITY; WIDTH]; 3],
    max: [[f32::NEG_INFINITY; WIDTH]; 3],
    child: [EMPTY; WIDTH],
    count: [0; WIDTH],
    oriented: OrientedLanes::NONE,
};

impl Node {
    /// Lower bounds on the squared distances from the query to the four boxes (`+∞` for an
    /// unused lane). Computed in `f32` lanes; see [`Query`] for why each is a lower bound.
    #[inline(always)]
    fn lower_bounds2(&self, q: &Query) -> [f32; WIDTH] {
        let mut d2 = [0.0f32; WIDTH];
        for k in 0..3 {
            for (l, acc) in d2.iter_mut().enumerate() {
                // Branch-free forms (no NaN can occur: finite query, finite or infinite boxes).
                let below = self.min[k][l] - q.hi[k];
                let above = q.lo[k] - self.max[k][l];
                let d = if below > above { below } else { above } - q.margin;
                let d = if d > 0.0 { d } else { 0.0 };
                *acc += d * d;
            }
        }
        d2.map(|v| v * SHRINK - TINY)
    }

    /// The frame of child `lane`'s leaf bound block: its box's lower corner and size.
    #[inline(always)]
    fn leaf_frame(&self, lane: usize, centre: Point3) -> (Point3, Point3) {
        frame(
            [0, 1, 2].map(|k| self.min[k][lane]),
            [0, 1, 2].map(|k| self.max[k][lane]),
            centre,
        )
    }
}

/// A leaf bound block's frame from its box (relative to `centre`): lower corner and size.
#[inline(always)]
fn frame(min: [f32; 3], max: [f32; 3], centre: Point3) -> (Point3, Point3) {
    let origin = [0, 1, 2].map(|k| centre[k] + f64::from(min[k]));
    let extent = [0, 1, 2].map(|k| f64::from(max[k]) - f64::from(min[k]));
    (origin, extent)
}

/// A query point as the box test sees it: relative to the centre, clamped, rounded down and
/// up to `f32`, and the absolute margin that covers the `f64` exact test's rounding.
///
/// Why the result is a lower bound: the box distance of the rounded-outwards query to the
/// rounded-outwards box, less the margin, is not above the true distance per axis; the `f32`
/// subtraction, squares and sums round by at most 2⁻²⁴ each, which [`SHRINK`] covers.
struct Query {
    lo: [f32; 3],
    hi: [f32; 3],
    margin: f32,
}

impl Query {
    fn new(p: Point3, centre: Point3) -> Self {
        let local = [0, 1, 2].map(|k| (p[k] - centre[k]).clamp(-CLAMP, CLAMP));
        let sum = |v: Point3| v[0].abs() + v[1].abs() + v[2].abs();
        // As the leaf bound's global term (`leaf_bound::margin`): 2⁻⁴⁴ of the coordinates.
        let margin = up((sum(p) + sum(centre)) / 17_592_186_044_416.0);
        Query {
            lo: local.map(down),
            hi: local.map(up),
            margin,
        }
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
    /// Its slot in leaf order (a [`Hint`] for the next query).
    slot: u32,
}

impl Closest {
    /// Whether this beats `other`: nearer, or as near with a smaller input index.
    #[inline(always)]
    fn beats(&self, other: &Closest) -> bool {
        self.distance2 < other.distance2
            || (self.distance2 == other.distance2 && self.triangle < other.triangle)
    }
}

/// Where a query starts: the triangle that answered the previous query, if any. Queries that
/// follow each other in space (the reconstruction in k-d tree order, ICP in Morton order) prune
/// from the first node on; the answer does not depend on it.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Hint(Option<u32>);

/// The hierarchy: inner nodes, the triangles in leaf order (vertex indices; [`LEAF_SIZE`]
/// slots a leaf, the unused ones never read), their input indices and each leaf's bound block.
pub(crate) struct TriangleBvh {
    nodes: Vec<Node>,
    centre: Point3,
    /// The boxes are unbounded (a mesh beyond [`MAX_RELATIVE`]): no leaf bounds either.
    unbounded: bool,
    vertices: Vec<Point3>,
    tris: Vec<[u32; 3]>,
    ids: Vec<u32>,
    bounds: Vec<LeafBound>,
}

impl TriangleBvh {
    /// Builds the hierarchy by median splits of the triangle centroids along the longest axis,
    /// two levels of them a node (the splits made ahead on disjoint ranges in parallel:
    /// [`median_split`]). The mesh must be valid (vertex indices in range, finite vertices);
    /// deterministic.
    pub(crate) fn new(mesh: &TriangleMesh) -> Self {
        Self::build(mesh, true)
    }

    /// [`Self::new`]; `split_ahead` false takes the serial path (the tests' reference).
    fn build(mesh: &TriangleMesh, split_ahead: bool) -> Self {
        // The bounds of the triangles' corners, ranges in parallel (minima and maxima are
        // exact: the same whatever the cuts).
        let parts = parallel::map_ranges(mesh.triangles.len(), |range| {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for t in &mesh.triangles[range] {
                for v in mesh.corners(t) {
                    for k in 0..3 {
                        lo[k] = lo[k].min(v[k]);
                        hi[k] = hi[k].max(v[k]);
                    }
                }
            }
            (lo, hi)
        });
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (l, h) in parts {
            for k in 0..3 {
                lo[k] = lo[k].min(l[k]);
                hi[k] = hi[k].max(h[k]);
            }
        }
        let centre = if mesh.triangles.is_empty() {
            [0.0; 3]
        } else {
            [0, 1, 2].map(|k| lo[k] + (hi[k] - lo[k]) / 2.0)
        };
        let unbounded = (0..3).any(|k| !((hi[k] - lo[k]) / 2.0 < MAX_RELATIVE / 2.0));
        let unbounded = unbounded && !mesh.triangles.is_empty();
        // The triangles in input order, each with its centroid in `f32` relative to the centre
        // (it only chooses the splits: 16 bytes a triangle).
        let input_order = || -> Vec<Keyed> {
            parallel::map_range(mesh.triangles.len(), |i| {
                let [a, b, c] = mesh.corners(&mesh.triangles[i]);
                let centroid = [0, 1, 2].map(|k| ((a[k] + b[k] + c[k]) / 3.0 - centre[k]) as f32);
                (centroid, i as u32)
            })
        };
        let mut keyed = input_order();
        // The median splits ahead, in parallel; the serial path where copies are dropped.
        let partitioned = split_ahead && median_split::split_all(&mut keyed, LEAF_SIZE);
        if !partitioned {
            keyed = input_order();
        }
        // Sized before they are filled (a grown vector peaks at up to twice its length).
        let (node_count, leaf_count) = shape(mesh.triangles.len());
        let mut nodes = Vec::with_capacity(node_count);
        let mut leaves = Vec::with_capacity(leaf_count);
        let mut builder = Builder {
            mesh,
            order: &mut keyed,
            nodes: &mut nodes,
            leaves: &mut leaves,
            partitioned,
        };
        if !mesh.triangles.is_empty() {
            builder.root(mesh.triangles.len());
        }
        // Only the triangles' indices from here (the centroids dropped before the leaf slots
        // are filled: the build's peak stays that of the splits).
        let order: Vec<u32> = keyed.iter().map(|&(_, i)| i).collect();
        drop(keyed);
        // The leaves' slots (input indices, then triangles), leaves in parallel.
        let leaf_count = leaves.len();
        let ids: Vec<[u32; LEAF_SIZE]> = parallel::map_range(leaf_count, |leaf| {
            let (start, end) = leaves[leaf];
            let mut slot = [u32::MAX; LEAF_SIZE];
            slot[..(end - start) as usize].copy_from_slice(&order[start as usize..end as usize]);
            slot
        });
        drop(order);
        drop(leaves);
        let tris: Vec<[[u32; 3]; LEAF_SIZE]> = parallel::map_range(leaf_count, |leaf| {
            ids[leaf].map(|id| {
                if id == u32::MAX {
                    [0; 3]
                } else {
                    mesh.triangles[id as usize]
                }
            })
        });
        // Each leaf's box and bound block, leaves in parallel.
        let (bounds, leaf_boxes) = parallel::map_range_unzip(leaf_count, |leaf| {
            let count = ids[leaf].iter().take_while(|&&id| id != u32::MAX).count();
            let mut corners = [[[0.0; 3]; 3]; LEAF_SIZE];
            for (k, t) in tris[leaf][..count].iter().enumerate() {
                corners[k] = mesh.corners(t);
            }
            let (lo, hi) = leaf_box(&corners[..count], centre);
            let bound = if unbounded {
                LeafBound::default()
            } else {
                let (origin, extent) = frame(lo, hi, centre);
                LeafBound::new(&corners[..count], origin, extent)
            };
            (bound, (lo, hi))
        });
        place_boxes(&mut nodes, &leaf_boxes, unbounded);
        drop(leaf_boxes);
        let (tris, ids) = (tris.into_flattened(), ids.into_flattened());
        if !unbounded {
            oriented_boxes(&mut nodes, &tris, &ids, mesh, centre);
        }
        TriangleBvh {
            nodes,
            centre,
            unbounded,
            vertices: mesh.vertices.clone(),
            tris,
            ids,
            bounds,
        }
    }

    /// Number of inner nodes (for tests and the memory estimate).
    #[cfg(test)]
    pub(crate) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Exact closest point of leaf-order triangle `k` to `q`.
    #[inline]
    fn project(&self, k: usize, q: Vector) -> Closest {
        #[cfg(test)]
        tests::EXACT_TESTS.with(|n| n.set(n.get() + 1));
        let t = self.tris[k];
        let [a, b, c] = t.map(|v| self.vertices[v as usize]);
        let tri = Triangle::new(
            Vector::new(a[0], a[1], a[2]),
            Vector::new(b[0], b[1], b[2]),
            Vector::new(c[0], c[1], c[2]),
        );
        let (proj, _) = tri.project_local_point_and_get_location(q, false);
        let d = proj.point - q;
        Closest {
            distance2: d.dot(d),
            point: [proj.point.x, proj.point.y, proj.point.z],
            triangle: self.ids[k],
            corners: [a, b, c],
            slot: k as u32,
        }
    }

    /// The exact closest surface point to `p`; `None` for an empty mesh or a non-finite `p`.
    /// Of triangles at the same distance, the one with the smallest input index.
    pub(crate) fn closest(&self, p: Point3) -> Option<Closest> {
        self.search_dispatched(p, None)
    }

    /// [`Self::closest`], starting from `hint` (the same answer; faster when the hint's
    /// triangle is near the answer), and leaving this answer in `hint`.
    pub(crate) fn closest_from(&self, p: Point3, hint: &mut Hint) -> Option<Closest> {
        let found = self.search_dispatched(p, hint.0);
        if let Some(c) = &found {
            hint.0 = Some(c.slot);
        }
        found
    }

    /// The bounded search, compiled for x86-64-v3 where the CPU has it.
    #[inline]
    fn search_dispatched(&self, p: Point3, start: Option<u32>) -> Option<Closest> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX2 and FMA, the features `search_v3` is compiled with.
            return unsafe { self.search_v3(p, start) };
        }
        self.search::<true>(p, start)
    }

    /// [`Self::search`] compiled with AVX2 and FMA (no fused operations are formed: the
    /// arithmetic is the same, bit for bit).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn search_v3(&self, p: Point3, start: Option<u32>) -> Option<Closest> {
        self.search::<true>(p, start)
    }

    /// The search from triangle slot `start` (if any); `BOUND` false tests every triangle of
    /// a visited leaf exactly (the reference the bounds are checked against in the tests).
    #[inline(always)]
    fn search<const BOUND: bool>(&self, p: Point3, start: Option<u32>) -> Option<Closest> {
        if self.nodes.is_empty() || !p.iter().all(|v| v.is_finite()) {
            return None;
        }
        let q = Vector::new(p[0], p[1], p[2]);
        let mut best = match start {
            // (an unused slot's id is `u32::MAX`)
            Some(k) if self.ids.get(k as usize).is_some_and(|&id| id != u32::MAX) => {
                self.project(k as usize, q)
            }
            _ => Closest {
                distance2: f64::INFINITY,
                point: p,
                triangle: u32::MAX,
                corners: [p; 3],
                slot: u32::MAX,
            },
        };
        let query = Query::new(p, self.centre);
        let oriented_query = OrientedQuery::new(query.lo, query.hi, query.margin);
        // Pending children: (node × WIDTH + lane, squared box distance). Two plain 32-bit
        // fields: the array's zeroing is one memset (a padded tuple was zeroed field by field,
        // a tenth of the search's time on a small mesh). Node indices stay below 2³⁰: a node
        // has at least two children, so there are fewer nodes than the 2³⁰ leaves of 2³²
        // triangles.
        let mut stack = [(0u32, 0.0f32); STACK];
        let mut depth = 0;
        let mut node = 0usize;
        loop {
            // Expand `node`: its children nearer than the best, nearest first.
            #[cfg(test)]
            tests::NODE_VISITS.with(|v| v.set(v.get() + 1));
            let n = &self.nodes[node];
            let mut d2 = n.lower_bounds2(&query);
            if BOUND && d2.iter().any(|&d| f64::from(d) <= best.distance2) {
                let o = n.oriented.lower_bounds2(&oriented_query, &n.min, &n.max);
                for (d, o) in d2.iter_mut().zip(o) {
                    if o > *d {
                        *d = o;
                    }
                }
            }
            let mut near = [(0.0f32, 0u8); WIDTH];
            let mut m = 0;
            for (lane, &d) in d2.iter().enumerate() {
                if n.child[lane] != EMPTY && f64::from(d) <= best.distance2 {
                    // insertion by distance, ties by lane
                    let mut j = m;
                    while j > 0 && near[j - 1].0 > d {
                        near[j] = near[j - 1];
                        j -= 1;
                    }
                    near[j] = (d, lane as u8);
                    m += 1;
                }
            }
            // Farthest first onto the stack, so the nearest is taken next.
            for &(d, lane) in near[..m].iter().rev() {
                stack[depth] = (node as u32 * WIDTH as u32 + u32::from(lane), d);
                depth += 1;
            }
            // Next pending child still not farther than the best: test leaves on the way.
            loop {
                if depth == 0 {
                    return (best.slot != u32::MAX).then_some(best);
                }
                depth -= 1;
                let (code, d) = stack[depth];
                if f64::from(d) > best.distance2 {
                    continue;
                }
                let parent = &self.nodes[code as usize / WIDTH];
                let lane = code as usize % WIDTH;
                let child = parent.child[lane];
                if child & LEAF == 0 {
                    node = child as usize;
                    break;
                }
                self.test_leaf::<BOUND>(parent, lane, p, q, &mut best);
            }
        }
    }

    /// Tests the triangles of `parent`'s leaf child `lane` that could beat `best`.
    #[inline(always)]
    fn test_leaf<const BOUND: bool>(
        &self,
        parent: &Node,
        lane: usize,
        p: Point3,
        q: Vector,
        best: &mut Closest,
    ) {
        #[cfg(test)]
        tests::NODE_VISITS.with(|v| v.set(v.get() + 1));
        let leaf = (parent.child[lane] & !LEAF) as usize;
        let count = usize::from(parent.count[lane]);
        let start = leaf * LEAF_SIZE;
        let bounds2 = if BOUND && !self.unbounded {
            let (origin, extent) = parent.leaf_frame(lane, self.centre);
            let local = sub(p, origin);
            let margin = leaf_bound::margin(local, origin, extent);
            let scale = leaf_bound::offset_scale(extent) as f32;
            self.bounds[leaf].lower_bounds2(local.map(|v| v as f32), scale, margin)
        } else {
            [0.0; LANES]
        };
        for (t, &bound2) in bounds2.iter().enumerate().take(count) {
            if f64::from(bound2) > best.distance2 {
                continue;
            }
            let c = self.project(start + t, q);
            if c.beats(best) {
                *best = c;
            }
        }
    }
}

/// A node whose children together span at most this many slots is the root of a block: its
/// subtree's triangles are read (corners and area normals) once for the oriented boxes of all
/// its nodes, about five levels, instead of once a level.
const BLOCK_SLOTS: usize = WIDTH * oriented::MAX_SLOTS;

/// Each node's children's oriented boxes: a child's triangles are a run of leaf slots (leaves
/// are numbered depth first), found from the deepest nodes up; the blocks' nodes in parallel,
/// a block's triangles read once, the few nodes above the blocks lane by lane.
fn oriented_boxes(
    nodes: &mut [Node],
    tris: &[[u32; 3]],
    ids: &[u32],
    mesh: &TriangleMesh,
    centre: Point3,
) {
    if nodes.is_empty() {
        return;
    }
    // Per node and lane, the child's slot range, and each node's subtree size in nodes
    // (children come after their parent, the subtree is the nodes that follow it).
    let mut spans = vec![[(0usize, 0usize); WIDTH]; nodes.len()];
    let mut sizes = vec![1usize; nodes.len()];
    for i in (0..nodes.len()).rev() {
        let n = &nodes[i];
        for lane in 0..WIDTH {
            let code = n.child[lane];
            spans[i][lane] = if code == EMPTY {
                (0, 0)
            } else if code & LEAF != 0 {
                let start = (code & !LEAF) as usize * LEAF_SIZE;
                (start, start + usize::from(n.count[lane]))
            } else {
                sizes[i] += sizes[code as usize];
                node_span(&nodes[code as usize], &spans[code as usize])
            };
        }
    }
    // The blocks (the highest nodes spanning at most `BLOCK_SLOTS`), from the root down.
    let mut blocks = Vec::new();
    let mut above = Vec::new();
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        let (start, end) = node_span(&nodes[i], &spans[i]);
        if end - start <= BLOCK_SLOTS {
            blocks.push(i);
        } else {
            above.push(i);
            let inner = nodes[i]
                .child
                .iter()
                .filter(|&&c| c != EMPTY && c & LEAF == 0);
            stack.extend(inner.map(|&c| c as usize));
        }
    }
    blocks.sort_unstable();
    // A run of slots' triangles: their corners and area normals, and per slot of the run the
    // position of its triangle (unused slots have none).
    let read = |start: usize, end: usize, patch: &mut Patch| {
        patch.corners.clear();
        patch.normals.clear();
        patch.at.clear();
        for k in start..end {
            patch.at.push(patch.corners.len());
            if ids[k] != u32::MAX {
                let corners = mesh.corners(&tris[k]);
                patch.normals.push(oriented::area_normal(&corners));
                patch.corners.push(corners);
            }
        }
        patch.at.push(patch.corners.len());
    };
    // The lanes of a block's node `n` (its lanes' spans `spans`), from the block's patch read
    // from slot `first` on.
    let set_lanes = |n: &mut Node, spans: &[(usize, usize); WIDTH], first: usize, patch: &Patch| {
        for (lane, &(start, end)) in spans.iter().enumerate() {
            if n.child[lane] == EMPTY || end - start > oriented::MAX_SLOTS {
                continue;
            }
            let (a, b) = (patch.at[start - first], patch.at[end - first]);
            let min = [0, 1, 2].map(|k| n.min[k][lane]);
            let max = [0, 1, 2].map(|k| n.max[k][lane]);
            n.oriented.set(
                lane,
                &patch.corners[a..b],
                &patch.normals[a..b],
                min,
                max,
                centre,
            );
        }
    };
    // Above the blocks, a lane small enough for a box is read on its own.
    let mut patch = Patch::default();
    for &i in &above {
        let n = &mut nodes[i];
        for (lane, &(start, end)) in spans[i].iter().enumerate() {
            if n.child[lane] != EMPTY && end - start <= oriented::MAX_SLOTS {
                read(start, end, &mut patch);
                let min = [0, 1, 2].map(|k| n.min[k][lane]);
                let max = [0, 1, 2].map(|k| n.max[k][lane]);
                n.oriented
                    .set(lane, &patch.corners, &patch.normals, min, max, centre);
            }
        }
    }
    // The blocks' node ranges, disjoint, in order.
    let mut pieces = Vec::with_capacity(blocks.len());
    let mut rest = &mut nodes[..];
    let mut offset = 0;
    for &b in &blocks {
        let (_, tail) = std::mem::take(&mut rest).split_at_mut(b - offset);
        let (block, tail) = tail.split_at_mut(sizes[b]);
        pieces.push((b, block));
        rest = tail;
        offset = b + sizes[b];
    }
    parallel::map_mut(&mut pieces, |_, (first, block)| {
        let (start, end) = node_span(&block[0], &spans[*first]);
        let mut patch = Patch::default();
        read(start, end, &mut patch);
        for (j, n) in block.iter_mut().enumerate() {
            set_lanes(n, &spans[*first + j], start, &patch);
        }
    });
}

/// The triangles of a run of slots, as [`oriented_boxes`] reads them.
#[derive(Default)]
struct Patch {
    corners: Vec<[Point3; 3]>,
    normals: Vec<(Point3, f64)>,
    /// Per slot of the run and one past it: the position of its triangle.
    at: Vec<usize>,
}

/// The slots a node's children span together.
fn node_span(n: &Node, spans: &[(usize, usize); WIDTH]) -> (usize, usize) {
    let used = (0..WIDTH).filter(|&l| n.child[l] != EMPTY);
    let start = used.clone().map(|l| spans[l].0).min().unwrap_or(0);
    let end = used.map(|l| spans[l].1).max().unwrap_or(0);
    (start, end)
}

/// Each used lane's box: a leaf's from `leaf_boxes`, an inner node's the union of its
/// children's (children come after their parent, so the deepest nodes are done first);
/// unbounded, every lane's box is all of space.
fn place_boxes(nodes: &mut [Node], leaf_boxes: &[([f32; 3], [f32; 3])], unbounded: bool) {
    for i in (0..nodes.len()).rev() {
        for lane in 0..WIDTH {
            let code = nodes[i].child[lane];
            let (lo, hi) = if code == EMPTY {
                continue;
            } else if unbounded {
                ([f32::NEG_INFINITY; 3], [f32::INFINITY; 3])
            } else if code & LEAF != 0 {
                leaf_boxes[(code & !LEAF) as usize]
            } else {
                let n = &nodes[code as usize];
                (
                    [0, 1, 2].map(|k| n.min[k].iter().copied().fold(f32::INFINITY, f32::min)),
                    [0, 1, 2].map(|k| n.max[k].iter().copied().fold(f32::NEG_INFINITY, f32::max)),
                )
            };
            for k in 0..3 {
                nodes[i].min[k][lane] = lo[k];
                nodes[i].max[k][lane] = hi[k];
            }
        }
    }
}

/// A leaf's box relative to `centre`, rounded outwards to `f32`.
fn leaf_box(corners: &[[Point3; 3]], centre: Point3) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in corners.iter().flatten() {
        for k in 0..3 {
            let r = v[k] - centre[k];
            lo[k] = lo[k].min(r);
            hi[k] = hi[k].max(r);
        }
    }
    (lo.map(down), hi.map(up))
}

/// The numbers of inner nodes and leaves the build makes over `n` triangles (fewer where it
/// drops stacked copies), to size its vectors: the splits halve, so a level has a few
/// range lengths, remembered.
fn shape(n: usize) -> (usize, usize) {
    fn node(n: usize, memo: &mut Vec<(usize, (usize, usize))>) -> (usize, usize) {
        if let Some(&(_, found)) = memo.iter().find(|(m, _)| *m == n) {
            return found;
        }
        let mut total = (1, 0);
        let once = levels(n) % 2 == 1;
        let mid = median_split::split_len(n, LEAF_SIZE);
        for half in [mid, n - mid] {
            let parts = if once || half <= LEAF_SIZE {
                vec![half]
            } else {
                let m = median_split::split_len(half, LEAF_SIZE);
                vec![m, half - m]
            };
            for part in parts {
                let (a, b) = if part <= LEAF_SIZE {
                    (0, 1)
                } else {
                    node(part, memo)
                };
                total = (total.0 + a, total.1 + b);
            }
        }
        memo.push((n, total));
        total
    }
    match n {
        0 => (0, 0),
        n if n <= LEAF_SIZE => (1, 1),
        n => node(n, &mut Vec::new()),
    }
}

/// Splits from `n` triangles down to leaves of at most [`LEAF_SIZE`] ([`median_split::split_len`]
/// halves the number of leaves, rounded up).
fn levels(n: usize) -> u32 {
    let mut levels = 0;
    let mut largest = n.div_ceil(LEAF_SIZE);
    while largest > 1 {
        largest = largest.div_ceil(2);
        levels += 1;
    }
    levels
}

struct Builder<'a> {
    mesh: &'a TriangleMesh,
    order: &'a mut [Keyed],
    nodes: &'a mut Vec<Node>,
    /// Per leaf, in slot order: its range of `order`.
    leaves: &'a mut Vec<(u32, u32)>,
    /// The order is split already ([`median_split::split_all`]): only the nodes are placed.
    partitioned: bool,
}

impl Builder<'_> {
    /// Builds the tree over `order[..n]` (n > 0) with its root at node 0.
    fn root(&mut self, n: usize) {
        let (end, axis) = self.prepare(0, n);
        if end <= LEAF_SIZE {
            // One leaf: a root with one used lane.
            let mut root = EMPTY_NODE;
            self.nodes.push(EMPTY_NODE);
            self.child(&mut root, 0, 0, end, axis);
            self.nodes[0] = root;
        } else {
            self.node(0, end, axis);
        }
    }

    /// An inner node over `order[start..end]` (more than [`LEAF_SIZE`] triangles, prepared):
    /// two levels of median splits give its two to four children. Returns its index.
    fn node(&mut self, start: usize, end: usize, axis: usize) -> u32 {
        let index = self.nodes.len();
        self.nodes.push(EMPTY_NODE);
        let mut node = EMPTY_NODE;
        let mut lane = 0;
        let mid = self.halve(start, end, axis);
        // An odd number of halvings to the leaves: split once here, so that the nodes below
        // (even numbers) all get four children rather than the lowest ones two.
        let once = levels(end - start) % 2 == 1;
        for (s, e) in [(start, mid), (mid, end)] {
            let (e, axis) = self.prepare(s, e);
            if once || e - s <= LEAF_SIZE {
                self.child(&mut node, lane, s, e, axis);
                lane += 1;
            } else {
                let m = self.halve(s, e, axis);
                for (s, e) in [(s, m), (m, e)] {
                    let (e, axis) = self.prepare(s, e);
                    self.child(&mut node, lane, s, e, axis);
                    lane += 1;
                }
            }
        }
        self.nodes[index] = node;
        index as u32
    }

    /// Fills lane `lane` of `node` with the child over `order[start..end]` (prepared): a leaf
    /// if it fits one, else an inner node. The lane's box is placed later ([`place_boxes`]).
    fn child(&mut self, node: &mut Node, lane: usize, start: usize, end: usize, axis: usize) {
        let (code, count) = if end - start <= LEAF_SIZE {
            let leaf = self.leaves.len();
            self.leaves.push((start as u32, end as u32));
            (LEAF | leaf as u32, (end - start) as u8)
        } else {
            (self.node(start, end, axis), 0)
        };
        node.child[lane] = code;
        node.count[lane] = count;
    }

    /// Drops stacked copies from `order[start..end]` when all its centroids coincide; returns
    /// the range's new end and the longest axis of its centroids (the axis to split along).
    fn prepare(&mut self, start: usize, end: usize) -> (usize, usize) {
        if self.partitioned {
            return (end, 0);
        }
        let (axis, same) = median_split::centroid_axis(&self.order[start..end]);
        if end - start > LEAF_SIZE && same {
            // Every centroid in one place: copies of one triangle (a glTF node graph that
            // instances a mesh many times in the same place) would make every query visit
            // them all, since the boxes never prune an equally distant copy. Only the
            // distinct ones are kept (the first of each by input order, so results do not
            // change: a copy is never strictly closer, and the smaller index wins a tie).
            return (start + self.drop_copies(start, end), axis);
        }
        (end, axis)
    }

    /// Median split of `order[start..end]` along `axis` (ties by input index); the middle.
    fn halve(&mut self, start: usize, end: usize, axis: usize) -> usize {
        if self.partitioned {
            return start + median_split::split_len(end - start, LEAF_SIZE);
        }
        start + median_split::median_split(&mut self.order[start..end], axis, LEAF_SIZE)
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
        // (every centroid of the range is this one)
        let centroid = slice[0].0;
        let mut keyed: Vec<(u64, u32)> = slice.iter().map(|&(_, i)| (hash(&key(i)), i)).collect();
        keyed.sort_unstable();
        let mut unique = 0;
        let mut run_start = 0;
        for (k, &(h, i)) in keyed.iter().enumerate() {
            if k == 0 || keyed[k - 1].0 != h {
                run_start = unique;
            }
            let ki = key(i);
            if !slice[run_start..unique].iter().any(|&(_, u)| key(u) == ki) {
                slice[unique] = (centroid, i);
                unique += 1;
            }
        }
        // The copies left behind are never referenced by a leaf.
        unique
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
        /// Inner nodes expanded and leaves tested on this thread.
        pub(super) static NODE_VISITS: Cell<usize> = const { Cell::new(0) };
    }

    fn exact_tests() -> usize {
        EXACT_TESTS.with(Cell::get)
    }

    fn node_visits() -> usize {
        NODE_VISITS.with(Cell::get)
    }

    /// The oriented boxes change nothing, bit for bit, and prune most of the nodes an
    /// axis-aligned box lets through, for queries hovering over a finely tessellated surface
    /// (noise of a few triangle widths, as a reconstruction's); from the previous answer too.
    #[test]
    fn oriented_boxes_keep_the_answer_and_prune_nodes() {
        for offset in [[0.0; 3], [4e5, -1e6, 2.5e5]] {
            let mesh = placed(blob(150), offset, 1.0);
            let bvh = TriangleBvh::new(&mesh);
            let (mut with, mut without) = (0, 0);
            let mut hint = Hint::default();
            // a spacing of about 0.02, noise up to 0.1 either side
            for p in near_surface(3000, 0.1, 11) {
                let p = [0, 1, 2].map(|k| offset[k] + p[k]);
                let before = node_visits();
                let reference = bvh.search::<false>(p, None).unwrap();
                let middle = node_visits();
                let hit = bvh.closest(p).unwrap();
                without += middle - before;
                with += node_visits() - middle;
                assert_eq!(hit, reference, "{p:?}");
                assert_eq!(bvh.closest_from(p, &mut hint), Some(hit));
            }
            eprintln!("{offset:?}: {with} nodes with the oriented boxes, {without} without");
            assert!(
                with * 5 < without * 3,
                "{offset:?}: {with} nodes with the oriented boxes, {without} without"
            );
        }
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
            let mesh = placed(blob(60), offset, scale);
            let bvh = TriangleBvh::new(&mesh);
            let (mut with, mut without) = (0, 0);
            for p in near_surface(2000, spread, 7) {
                let p = [0, 1, 2].map(|k| offset[k] + scale * p[k]);
                let before = exact_tests();
                let reference = bvh.search::<false>(p, None).unwrap();
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

    /// The build's vectors are sized exactly: `shape` counts the nodes and leaves the build
    /// makes, for odd and even numbers of halvings and a single leaf.
    #[test]
    fn shape_counts_the_nodes_and_leaves_built() {
        for n in [1, 2, 3, 5, 9, 17, 40, 101] {
            let mut mesh = blob(n);
            for keep in [mesh.triangles.len(), 3, 4, 5, 33, 1000] {
                mesh.triangles.truncate(keep);
                let bvh = TriangleBvh::new(&mesh);
                let (nodes, leaves) = shape(mesh.triangles.len());
                assert_eq!(bvh.nodes.len(), nodes, "{} triangles", mesh.triangles.len());
                assert_eq!(bvh.nodes.capacity(), nodes);
                assert_eq!(bvh.bounds.len(), leaves);
                assert_eq!(bvh.tris.len(), leaves * LEAF_SIZE);
            }
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

    /// `mesh` scaled by `scale` about the origin, then moved by `offset`.
    fn placed(mut mesh: TriangleMesh, offset: Point3, scale: f64) -> TriangleMesh {
        for v in &mut mesh.vertices {
            *v = [0, 1, 2].map(|k| offset[k] + scale * v[k]);
        }
        mesh
    }

    /// [`queries`] pushed along their radius to 1 ± `spread` (a unit sphere's surface points
    /// with noise), the noise cycling through `period` (odd) steps from −spread to +spread.
    fn near_surface(m: usize, spread: f64, period: usize) -> Vec<Point3> {
        let half = ((period - 1) / 2) as f64;
        queries(m)
            .into_iter()
            .enumerate()
            .map(|(i, p)| {
                let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt().max(1e-9);
                let t = 1.0 + spread * ((i % period) as f64 / half - 1.0);
                p.map(|v| v / r * t)
            })
            .collect()
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

    /// Brute force over every triangle with the same exact test: the smallest squared
    /// distance, ties to the smallest input index.
    fn brute(mesh: &TriangleMesh, p: Point3) -> (f64, u32) {
        mesh.triangles
            .iter()
            .enumerate()
            .map(|(i, t)| (exact2(mesh, t, p), i as u32))
            .fold((f64::INFINITY, u32::MAX), |a, b| if b < a { b } else { a })
    }

    /// parry's exact squared distance from `p` to triangle `t`.
    fn exact2(mesh: &TriangleMesh, t: &[u32; 3], p: Point3) -> f64 {
        let q = Vector::new(p[0], p[1], p[2]);
        let [a, b, c] = mesh.corners(t);
        let tri = Triangle::new(
            Vector::new(a[0], a[1], a[2]),
            Vector::new(b[0], b[1], b[2]),
            Vector::new(c[0], c[1], c[2]),
        );
        let d = tri.project_local_point_and_get_location(q, false).0.point - q;
        d.dot(d)
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
        let mut hint = Hint::default();
        for p in queries(400) {
            let hit = bvh.closest(p).unwrap();
            let q = Vector::new(p[0], p[1], p[2]);
            assert_eq!((hit.distance2, hit.triangle), brute(&mesh, p), "at {p:?}");
            assert_eq!(bvh.closest_from(p, &mut hint), Some(hit));
            // The portable build of the search (the dispatch takes the AVX2 one where the CPU
            // has it) gives the same bits.
            assert_eq!(bvh.search::<true>(p, None), Some(hit));
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

    /// Exact ties (a query nearest to a vertex shared by six triangles, or on the surface at
    /// distance 0) go to the smallest input index, whatever the tree, the leaf bounds or the
    /// hint.
    #[test]
    fn ties_go_to_the_smallest_index_from_any_start() {
        let mesh = blob(24);
        let bvh = TriangleBvh::new(&mesh);
        let mut ties = 0;
        let mut hints = [Hint::default(), Hint::default()];
        for (i, v) in mesh.vertices.iter().enumerate() {
            for p in [
                [v[0] * 1.3, v[1] * 1.3, v[2] * 1.3],
                *v,
                [v[0] * 0.7, v[1] * 0.7, v[2] * 0.7],
            ] {
                let want = brute(&mesh, p);
                let hit = bvh.closest(p).unwrap();
                assert_eq!((hit.distance2, hit.triangle), want, "vertex {i} at {p:?}");
                assert_eq!(bvh.search::<false>(p, None), Some(hit));
                // a hint from elsewhere: the previous query's answer, and a fixed far one
                assert_eq!(bvh.closest_from(p, &mut hints[0]), Some(hit));
                bvh.closest_from([-p[0], 0.5 - p[1], -p[2]], &mut hints[1]);
                assert_eq!(bvh.closest_from(p, &mut hints[1]), Some(hit));
                let equal = mesh
                    .triangles
                    .iter()
                    .filter(|t| exact2(&mesh, t, p) == want.0)
                    .count();
                ties += usize::from(equal > 1);
            }
        }
        assert!(ties > mesh.vertices.len(), "{ties} tied queries");
    }

    /// Georeferenced coordinates (a 20 m object 10^6 m from the origin), meshes beyond the
    /// `f32` boxes' range, and microscopic ones: the brute-force answer, and at 10^6 the
    /// boxes still prune (an absolute `f32` box there is 6 cm wide).
    #[test]
    fn far_huge_and_tiny_meshes() {
        for (offset, scale, max_tests) in [
            ([4e5, -1e6, 2.5e5], 10.0, Some(40)),
            ([0.0; 3], 1e20, None),
            ([1e21, 0.0, -3e20], 1e19, None),
            ([1e-12, 0.0, 0.0], 1e-15, Some(40)),
            // squared distances below f32's normal range: correct, not pruned
            ([1e-20, 0.0, 0.0], 1e-22, None),
        ] {
            let mesh = placed(blob(16), offset, scale);
            let bvh = TriangleBvh::new(&mesh);
            let mut hint = Hint::default();
            let before = exact_tests();
            let m = 300;
            for p in queries(m) {
                let p = [0, 1, 2].map(|k| offset[k] + scale * p[k]);
                let hit = bvh.closest(p).unwrap();
                assert_eq!((hit.distance2, hit.triangle), brute(&mesh, p), "{p:?}");
                assert_eq!(bvh.closest_from(p, &mut hint), Some(hit));
            }
            let per_query = (exact_tests() - before) / (2 * m);
            if let Some(max) = max_tests {
                assert!(
                    per_query < max,
                    "{offset:?}: {per_query} exact tests a query"
                );
            }
        }
    }

    /// The splits made ahead in parallel give the serial build's tree, bit for bit; and a
    /// mesh with stacked copies takes the serial path.
    #[test]
    fn splits_ahead_give_the_serial_tree() {
        let mut stacked = blob(20);
        let t = stacked.triangles[3];
        stacked.triangles.extend(std::iter::repeat_n(t, 50));
        for mesh in [blob(150), blob(7), stacked] {
            let a = TriangleBvh::new(&mesh);
            let b = TriangleBvh::build(&mesh, false);
            assert!(a.nodes == b.nodes, "{} triangles", mesh.triangles.len());
            assert_eq!((a.tris, a.ids), (b.tris, b.ids));
            assert!(a.bounds == b.bounds);
        }
    }

    #[test]
    fn compact_and_deterministic() {
        let mesh = blob(30);
        let a = TriangleBvh::new(&mesh);
        let b = TriangleBvh::new(&mesh);
        assert_eq!(a.ids, b.ids);
        assert_eq!(std::mem::size_of::<Node>(), 256);
        // a 4-wide tree over ceil(n / 4)..n / 2 leaves: two to four children a node
        assert!(a.node_count() * 2 * LEAF_SIZE <= mesh.triangles.len());
        // every triangle in exactly one leaf slot
        let mut ids: Vec<u32> = a
            .nodes
            .iter()
            .flat_map(|n| (0..WIDTH).map(move |l| (n.child[l], n.count[l])))
            .filter(|&(code, _)| code != EMPTY && code & LEAF != 0)
            .flat_map(|(code, count)| {
                let start = (code & !LEAF) as usize * LEAF_SIZE;
                &a.ids[start..start + usize::from(count)]
            })
            .copied()
            .collect();
        ids.sort_unstable();
        assert_eq!(a.bounds.len() * LEAF_SIZE, a.ids.len());
        assert_eq!(ids, (0..mesh.triangles.len() as u32).collect::<Vec<_>>());
    }

    /// The boxes of the children's slots read lane by lane, each lane's triangles on their own
    /// (the build before the blocks).
    /// Returns how many of the boxed lanes lie in nodes spanning more than a block.
    fn lane_by_lane(
        nodes: &mut [Node],
        tris: &[[u32; 3]],
        ids: &[u32],
        mesh: &TriangleMesh,
    ) -> usize {
        let centre = {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for v in mesh.triangles.iter().flat_map(|t| mesh.corners(t)) {
                for k in 0..3 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            [0, 1, 2].map(|k| lo[k] + (hi[k] - lo[k]) / 2.0)
        };
        let mut spans = vec![[(0usize, 0usize); WIDTH]; nodes.len()];
        for i in (0..nodes.len()).rev() {
            for lane in 0..WIDTH {
                let code = nodes[i].child[lane];
                spans[i][lane] = if code == EMPTY {
                    (0, 0)
                } else if code & LEAF != 0 {
                    let start = (code & !LEAF) as usize * LEAF_SIZE;
                    (start, start + usize::from(nodes[i].count[lane]))
                } else {
                    node_span(&nodes[code as usize], &spans[code as usize])
                };
            }
        }
        let mut above = 0;
        for (i, n) in nodes.iter_mut().enumerate() {
            n.oriented = OrientedLanes::NONE;
            let (node_start, node_end) = node_span(n, &spans[i]);
            for (lane, &(start, end)) in spans[i].iter().enumerate() {
                if n.child[lane] == EMPTY || end - start > oriented::MAX_SLOTS {
                    continue;
                }
                above += usize::from(node_end - node_start > BLOCK_SLOTS);
                let corners: Vec<_> = (start..end)
                    .filter(|&k| ids[k] != u32::MAX)
                    .map(|k| mesh.corners(&tris[k]))
                    .collect();
                let normals: Vec<_> = corners.iter().map(oriented::area_normal).collect();
                let min = [0, 1, 2].map(|k| n.min[k][lane]);
                let max = [0, 1, 2].map(|k| n.max[k][lane]);
                n.oriented.set(lane, &corners, &normals, min, max, centre);
            }
        }
        above
    }

    /// The oriented boxes read a block's triangles once for all its nodes, and the lanes above
    /// the blocks one by one: every node comes out bit for bit as read lane by lane, for
    /// counts that leave uneven splits (lanes of at most `MAX_SLOTS` above the blocks).
    #[test]
    fn block_oriented_boxes_equal_lane_by_lane() {
        let full = blob(120);
        // Stacked copies of one triangle, which the build drops, leave small lanes in nodes
        // that span more than a block (far from the rest, so that they are the last along
        // every axis and fill whole ranges).
        let mut stacked = blob(60);
        let v = stacked.vertices.len() as u32;
        stacked
            .vertices
            .extend([[10.0, 10.0, 10.0], [10.1, 10.0, 10.0], [10.0, 10.1, 10.0]]);
        stacked
            .triangles
            .extend(std::iter::repeat_n([v, v + 1, v + 2], 12_000));
        let mut meshes: Vec<TriangleMesh> = [5, 4100, 8193, 16_390, full.triangles.len() - 7]
            .into_iter()
            .map(|m| TriangleMesh {
                vertices: full.vertices.clone(),
                triangles: full.triangles[..m].to_vec(),
            })
            .collect();
        meshes.push(stacked);
        let mut above = 0;
        for mesh in &meshes {
            let m = mesh.triangles.len();
            let bvh = TriangleBvh::new(mesh);
            let mut reference = bvh.nodes.clone();
            above += lane_by_lane(&mut reference, &bvh.tris, &bvh.ids, mesh);
            assert!(reference == bvh.nodes, "{m} triangles");
            let constrained = bvh
                .nodes
                .iter()
                .filter(|n| n.oriented != OrientedLanes::NONE)
                .count();
            assert!(constrained * 2 > bvh.nodes.len(), "{m}: {constrained}");
        }
        assert!(above > 0, "no boxed lane above the blocks");
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
