//! Oriented boxes for a BVH node's four children: a second lower bound on the distance from a
//! query to a child's triangles, tight where the child is a thin, tilted patch of surface.
//!
//! An axis-aligned box around a patch of a tilted surface is thick along the surface's normal,
//! so a query hovering at distance `d` over the surface reaches every child whose box corner
//! sticks up to within `d`, far to the side of the query's nearest point. A box aligned with the
//! patch (its area-weighted normal `n̂`, a tangent `t̂₁` along the child's longest box axis, and
//! `t̂₂ = n̂ × t̂₁`) is only as thick as the patch's curvature, so its distance grows with the
//! sideways offset as the true distance does.
//!
//! Per child lane, stored in 16-bit integers (120 bytes a node, inside the node): the three
//! axes `aₖ` in units of 2⁻¹⁵ (so each is exactly an `f32`), and per axis the interval
//! `[loₖ, hiₖ]` that holds `aₖ·(x − c)` for every corner `x` of the child's triangles, in units
//! of the child's box size / 32000 ([`unit`]; rounded outwards), where `c` is the child's
//! axis-aligned box's lower corner (relative to the tree's centre, the same `f32` the query
//! subtracts). The interval holds every point of the triangles too (`aₖ·x` is linear); it is
//! computed in `f64` with a slack for that arithmetic.
//!
//! Why the bound is a lower bound: the query `v = q − c` is computed in `f32` from the query's
//! rounded-down coordinates; per axis, `tₖ = aₖ·v` is within `spread + 2⁻²⁰ |v|₁` of the true
//! value (`spread` the query's rounding, `|aₖⱼ| ≤ 1`), the interval's ends are within
//! `unit · 2⁻⁸` of the stored ones after the `f32` product, and `margin` (the exact test's
//! rounding, as the axis-aligned test's) is added to that. So `gₖ = max(loₖ − tₖ, tₖ − hiₖ) −
//! that ≤ |aₖ·(q − x)|` for every point `x` of the child. The rounded axes are orthonormal to
//! within 2⁻¹⁵ a component, so `|q − x|² ≥ Σ gₖ² / σ²` with `σ² < 1 + 2⁻¹²·0.8`; [`SHRINK`]
//! covers that and the rounding of the squares and sums. An unconstrained lane (zero axes and
//! intervals) and non-finite lanes (unused, or a mesh too large for the boxes) come out as a
//! bound of at most 0: the axis-aligned bound decides there.

use super::up;
use crate::geometry::{Point3, cross, dot, norm, sub};

/// Children of a node (the BVH's width).
pub(crate) const WIDTH: usize = 4;

/// Largest child (in triangle slots) that gets an oriented box: above it a patch is rarely
/// thin, and the boxes would cost build time for nothing.
pub(crate) const MAX_SLOTS: usize = 1024;

/// Relative guard on the final squares and sums: the axes' departure from orthonormality
/// (`σ² − 1` below 2⁻¹²·0.8) and the `f32` rounding of the gaps, squares and sums.
const SHRINK: f32 = 1.0 - 1.0 / (1u32 << 11) as f32;

/// Absolute guard against `f32` underflow of a tiny square.
const TINY: f32 = f32::MIN_POSITIVE;

/// The `f32` error of `aₖ·v` relative to `|v|₁`: the subtraction giving `v` and the dot product
/// (each within a few units of 2⁻²⁴).
const REL: f32 = 1.0 / (1u32 << 20) as f32;

/// An axis component's unit: 2⁻¹⁵.
const AXIS_UNIT: f64 = 1.0 / 32768.0;

/// Interval units in a box of size sum 1 (the intervals lie within ±that size, so within
/// ±32001 units even after the outward rounding: an `i16`).
const PER_SIZE: f32 = 1.0 / 32000.0;

/// The interval unit of a child lane whose box runs from `min` to `max` (relative `f32`): the
/// build and the query compute it the same way, bit for bit.
#[inline(always)]
fn unit(min: [f32; 3], max: [f32; 3]) -> f32 {
    ((max[0] - min[0]) + (max[1] - min[1]) + (max[2] - min[2])) * PER_SIZE
}

/// The oriented boxes of a node's children, structure of arrays (120 bytes).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C)]
pub(crate) struct OrientedLanes {
    /// `axis[k][j][l]`: component `j` of lane `l`'s axis `k`, in units of 2⁻¹⁵.
    axis: [[[i16; WIDTH]; 3]; 3],
    /// Per axis and lane, the interval of `aₖ·(x − c)` over the child's triangles, in units of
    /// the lane's [`unit`].
    lo: [[i16; WIDTH]; 3],
    hi: [[i16; WIDTH]; 3],
}

/// A query as the oriented test sees it: its rounded-down coordinates relative to the tree's
/// centre, and the absolute error allowance independent of the lane.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OrientedQuery {
    pub(crate) lo: [f32; 3],
    /// The exact test's margin plus the query's own `f32` rounding (`Σ hi − lo`).
    pub(crate) margin: f32,
}

impl OrientedQuery {
    /// From the query's outward-rounded relative coordinates and the exact test's margin.
    pub(crate) fn new(lo: [f32; 3], hi: [f32; 3], margin: f32) -> Self {
        let spread: f64 = (0..3)
            .map(|k| f64::from(hi[k]) - f64::from(lo[k]))
            .sum::<f64>()
            + f64::from(margin);
        OrientedQuery {
            lo,
            margin: up(spread),
        }
    }
}

impl OrientedLanes {
    /// Every lane unconstrained (zero axes and intervals: a bound of at most 0).
    pub(crate) const NONE: OrientedLanes = OrientedLanes {
        axis: [[[0; WIDTH]; 3]; 3],
        lo: [[0; WIDTH]; 3],
        hi: [[0; WIDTH]; 3],
    };

    /// Lower bounds on the squared distances from the query to the four children's triangles;
    /// `min` and `max` are the node's axis-aligned boxes (`Node::min`, `Node::max`).
    #[inline(always)]
    pub(crate) fn lower_bounds2(
        &self,
        q: &OrientedQuery,
        min: &[[f32; WIDTH]; 3],
        max: &[[f32; WIDTH]; 3],
    ) -> [f32; WIDTH] {
        let mut v = [[0.0f32; WIDTH]; 3];
        let mut l1 = [0.0f32; WIDTH];
        for j in 0..3 {
            for l in 0..WIDTH {
                v[j][l] = q.lo[j] - min[j][l];
                l1[l] += v[j][l].abs();
            }
        }
        let scale: [f32; WIDTH] = std::array::from_fn(|l| {
            unit(
                [min[0][l], min[1][l], min[2][l]],
                [max[0][l], max[1][l], max[2][l]],
            )
        });
        let margin: [f32; WIDTH] =
            std::array::from_fn(|l| q.margin + l1[l] * REL + scale[l] * (1.0 / 256.0));
        let axis_unit = AXIS_UNIT as f32;
        let mut d2 = [0.0f32; WIDTH];
        for k in 0..3 {
            let a = &self.axis[k];
            for l in 0..WIDTH {
                let t = (f32::from(a[0][l]) * v[0][l]
                    + f32::from(a[1][l]) * v[1][l]
                    + f32::from(a[2][l]) * v[2][l])
                    * axis_unit;
                let below = f32::from(self.lo[k][l]) * scale[l] - t;
                let above = t - f32::from(self.hi[k][l]) * scale[l];
                // NaN (an infinite lane) and negative gaps count as 0.
                let g = if below > above { below } else { above } - margin[l];
                let g = if g > 0.0 { g } else { 0.0 };
                d2[l] += g * g;
            }
        }
        d2.map(|x| x * SHRINK - TINY)
    }

    /// Sets lane `lane` to the oriented box of `triangles` (their corners, absolute; `normals`
    /// their [`area_normal`]s), for a child whose axis-aligned box runs from `min` to `max`
    /// (relative to `centre`). A degenerate patch (no net normal, a box of size 0, non-finite)
    /// stays unconstrained.
    pub(crate) fn set(
        &mut self,
        lane: usize,
        triangles: &[[Point3; 3]],
        normals: &[(Point3, f64)],
        min: [f32; 3],
        max: [f32; 3],
        centre: Point3,
    ) {
        let unit = f64::from(unit(min, max));
        let extent = [0, 1, 2].map(|k| f64::from(max[k]) - f64::from(min[k]));
        if !(unit.is_finite() && unit > 0.0) {
            return;
        }
        let Some(axes) = axes(normals, extent) else {
            return;
        };
        // Components in units of 2⁻¹⁵ (1 itself rounds down to 32767: |aₖⱼ| ≤ 1 either way).
        let axes16 =
            axes.map(|a| a.map(|c| (c / AXIS_UNIT).round().clamp(-32767.0, 32767.0) as i16));
        let axes64 = axes16.map(|a| a.map(|c| f64::from(c) * AXIS_UNIT));
        let corner64 = min.map(f64::from);
        // The corner in absolute coordinates: the rounding of this and of each `x − origin`
        // below is far inside `slack`, as every corner lies in the lane's box.
        let origin = [0, 1, 2].map(|k| centre[k] + corner64[k]);
        let sum = |v: Point3| v[0].abs() + v[1].abs() + v[2].abs();
        let scale = 2.0 * (sum(centre) + sum(corner64)) + sum(extent);
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for x in triangles.iter().flatten() {
            let local = sub(*x, origin);
            for k in 0..3 {
                let t = dot(axes64[k], local);
                lo[k] = lo[k].min(t);
                hi[k] = hi[k].max(t);
            }
        }
        let slack = scale / 1_099_511_627_776.0;
        let lo = lo.map(|v| ((v - slack) / unit).floor());
        let hi = hi.map(|v| ((v + slack) / unit).ceil());
        // (the division's rounding is far below the slack; an interval outside ±32767 units,
        // impossible for points in the box, leaves the lane unconstrained)
        if !lo.iter().chain(&hi).all(|v| v.abs() <= 32767.0) {
            return;
        }
        for k in 0..3 {
            for (j, &a) in axes16[k].iter().enumerate() {
                self.axis[k][j][lane] = a;
            }
            self.lo[k][lane] = lo[k] as i16;
            self.hi[k][lane] = hi[k] as i16;
        }
    }
}

/// A triangle's normal scaled by twice its area, `(b − a) × (c − a)`, and that length: what
/// a patch's axes sum over its triangles (computed once a triangle for all the levels of a
/// tree).
pub(crate) fn area_normal([a, b, c]: &[Point3; 3]) -> (Point3, f64) {
    let m = cross(sub(*b, *a), sub(*c, *a));
    (m, norm(m))
}

/// Orthonormal axes for a patch of triangles with these [`area_normal`]s: its area-weighted
/// unit normal, a tangent along the world axis of the box's longest extent that is not near
/// the normal, and their cross product. `None` when the triangles' normals cancel out (a
/// closed or folded patch) or are not finite.
fn axes(normals: &[(Point3, f64)], extent: [f64; 3]) -> Option<[Point3; 3]> {
    let mut n = [0.0; 3];
    let mut total = 0.0;
    for (m, length) in normals {
        n = [n[0] + m[0], n[1] + m[1], n[2] + m[2]];
        total += length;
    }
    let length = norm(n);
    // Normals that mostly cancel: no useful orientation.
    if !(length.is_finite() && length > 0.25 * total) {
        return None;
    }
    let n = n.map(|v| v / length);
    // The longest box axis that is at least 30° away from the normal (one always is).
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| extent[b].total_cmp(&extent[a]));
    let k = order.into_iter().find(|&k| n[k].abs() < 0.87)?;
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let t = sub(e, n.map(|v| v * n[k]));
    let t = t.map(|v| v / norm(t));
    let s = cross(n, t);
    let s = s.map(|v| v / norm(s));
    let all = [n, t, s];
    all.iter().flatten().all(|v| v.is_finite()).then_some(all)
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::*;
    use crate::distance::down;
    use crate::distance::leaf_bound::tests::exact2;

    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A gently curved patch of `n` triangles near `at` with size `size`, tilted.
    fn patch(at: Point3, size: f64, n: usize, next: &mut impl FnMut() -> f64) -> Vec<[Point3; 3]> {
        let tilt = [next() - 0.5, next() - 0.5, 1.0];
        let u = cross(tilt, [1.0, 0.0, 0.0]);
        let u = u.map(|v| v / norm(u));
        let w = cross(tilt, u);
        let w = w.map(|v| v / norm(w));
        let nt = tilt.map(|v| v / norm(tilt));
        let point = |x: f64, y: f64| {
            let h = 0.1 * (x * x + y * y) / size;
            [0, 1, 2].map(|k| at[k] + x * u[k] + y * w[k] + h * nt[k])
        };
        (0..n)
            .map(|_| {
                let (x, y) = ((next() - 0.5) * size, (next() - 0.5) * size);
                let e = size / 8.0;
                [point(x, y), point(x + e, y), point(x, y + e)]
            })
            .collect()
    }

    /// The oriented bound never exceeds the exact squared distance to any of the lane's
    /// triangles: patches at unit scale, tiny, and 10⁶ from the tree's centre; queries on,
    /// near, and far from them.
    #[test]
    fn never_above_the_exact_distance() {
        let mut next = rng(7);
        let mut tighter = 0;
        let mut lanes = 0;
        for (offset, size) in [
            ([0.0; 3], 1.0),
            ([0.0; 3], 1e-6),
            ([4e5, -1e6, 2.5e5], 0.05),
            ([3.0, -2.0, 1.0], 0.01),
        ] {
            let centre = [offset[0] * 0.999, offset[1], offset[2] + 1.0];
            for _ in 0..200 {
                let mut lanes_of = OrientedLanes::NONE;
                let mut corners = [[0.0f32; WIDTH]; 3];
                let mut far_corners = [[0.0f32; WIDTH]; 3];
                let mut tris = Vec::new();
                for lane in 0..WIDTH {
                    let at = [0, 1, 2].map(|k| offset[k] + (next() - 0.5) * 4.0 * size);
                    let t = patch(at, size, 1 + (next() * 20.0) as usize, &mut next);
                    let mut lo = [f64::INFINITY; 3];
                    let mut hi = [f64::NEG_INFINITY; 3];
                    for x in t.iter().flatten() {
                        for k in 0..3 {
                            lo[k] = lo[k].min(x[k] - centre[k]);
                            hi[k] = hi[k].max(x[k] - centre[k]);
                        }
                    }
                    let (c, f) = (lo.map(down), hi.map(up));
                    for k in 0..3 {
                        corners[k][lane] = c[k];
                        far_corners[k][lane] = f[k];
                    }
                    let normals: Vec<_> = t.iter().map(area_normal).collect();
                    lanes_of.set(lane, &t, &normals, c, f, centre);
                    tris.push(t);
                }
                for _ in 0..20 {
                    let reach = [0.0, 0.01, 0.3, 3.0][(next() * 4.0) as usize];
                    let base = tris[0][0][0];
                    let p = [0, 1, 2].map(|k| base[k] + (next() - 0.5) * reach * size * 8.0);
                    let rel = [0, 1, 2].map(|k| p[k] - centre[k]);
                    let q = OrientedQuery::new(rel.map(down), rel.map(up), 0.0);
                    let bounds = lanes_of.lower_bounds2(&q, &corners, &far_corners);
                    for lane in 0..WIDTH {
                        let exact = tris[lane]
                            .iter()
                            .map(|t| exact2(p, *t))
                            .fold(f64::INFINITY, f64::min);
                        assert!(
                            f64::from(bounds[lane]) <= exact,
                            "{offset:?} {size}: bound {} > exact {exact}",
                            bounds[lane]
                        );
                        lanes += 1;
                        tighter += usize::from(f64::from(bounds[lane]) > 0.5 * exact);
                    }
                }
            }
        }
        // and it is a useful bound, not zero
        assert!(
            tighter * 3 > lanes,
            "{tighter} of {lanes} lanes above half the distance"
        );
    }

    /// Patches whose normals cancel (a closed box) get no orientation.
    #[test]
    fn cancelling_normals_stay_unconstrained() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let flipped = [t[0], t[2], t[1]];
        let normals = |ts: &[[Point3; 3]]| ts.iter().map(area_normal).collect::<Vec<_>>();
        assert!(axes(&normals(&[t, flipped]), [1.0, 1.0, 0.0]).is_none());
        let a = axes(&normals(&[t]), [1.0, 1.0, 0.0]).unwrap();
        assert_eq!(a[0], [0.0, 0.0, 1.0]);
        for (i, x) in a.iter().enumerate() {
            for (j, y) in a.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((dot(*x, *y) - want).abs() < 1e-15);
            }
        }
    }
}
