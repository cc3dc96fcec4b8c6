//! A conservative lower bound on the distance from a point to each of up to four triangles,
//! computed together in `f32` lanes: it lets the BVH's leaves skip the exact f64 test of a
//! triangle that cannot be nearer than the best one found so far.
//!
//! Per triangle, relative to the leaf's lower corner: the unit normal `n̂`, the three in-plane
//! outward unit edge normals `m̂ᵢ`, and their offsets `n̂·a`, `m̂ᵢ·vᵢ`. For a point `p`, let
//! `h = |n̂·(p − a)|` (distance to the plane) and `s = max(maxᵢ m̂ᵢ·(p − vᵢ), 0)` (distance in
//! the plane to the edge line farthest outside). Every point `x` of the triangle has
//! `m̂ᵢ·(x − vᵢ) ≤ 0`, so `|p − x|² ≥ h² + s²`: equal to the squared distance in the face and
//! edge regions, below it in a vertex region.
//!
//! Stored as 16-bit integers, 32 bytes a triangle (the directions in units of 1/32767, the
//! offsets in units of the leaf's extent / 32767): each rounded direction is within
//! `ε = √3 / 65534` of the true one, which moves `h` and `s` by at most `ε (d + D)` (`d` the
//! distance, `D` the leaf's size). [`margin`] covers that, the offsets' rounding, the `f32`
//! arithmetic, and the f64 rounding of the exact test the bound is compared with. So a
//! triangle skipped because its bound is not below the best distance would not have replaced
//! the best in the exact test: the search returns the same triangle, bit for bit, as testing
//! every triangle of the leaf.

use crate::geometry::{Point3, cross, dot, norm, sub};

/// Triangles a block holds (one leaf of the BVH).
pub(crate) const LANES: usize = 4;

/// The integer a unit length is stored as.
const UNIT: f64 = 32767.0;

/// Relative guard on the final `f32` squares and sums (all terms non-negative there).
const SHRINK: f32 = 1.0 - 1.0 / (1u32 << 20) as f32;

/// Absolute guard on the final square (a normal number, so no operand is subnormal).
const TINY: f32 = f32::MIN_POSITIVE;

/// A triangle this thin (sine of its corner angle at `a` below this) gets no bound: its normal
/// is not known well enough, so it is always tested exactly.
const MIN_SINE: f64 = 1e-9;

/// The bound's data for up to [`LANES`] triangles, structure of arrays (128 bytes).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct LeafBound {
    /// Unit normal, per axis, in units of 1 / [`UNIT`].
    normal: [[i16; LANES]; 3],
    /// `n̂·a` in units of the offset scale ([`offset_scale`]).
    normal_offset: [i16; LANES],
    /// Outward in-plane unit normals of edges ab, bc, ca, per axis, in units of 1 / [`UNIT`].
    edge: [[[i16; LANES]; 3]; 3],
    /// `m̂ᵢ·vᵢ` (the edge's start corner) in units of the offset scale.
    edge_offset: [[i16; LANES]; 3],
}

/// The length one unit of a stored offset stands for, in a leaf of extent `extent`: offsets of
/// points inside the leaf's box lie within ±(sum of the extents).
#[inline(always)]
pub(crate) fn offset_scale(extent: Point3) -> f64 {
    let sum = extent[0].abs() + extent[1].abs() + extent[2].abs();
    if sum > 0.0 { sum / UNIT } else { 1.0 }
}

impl LeafBound {
    /// The block of `triangles` (at most [`LANES`]; missing lanes and degenerate or very thin
    /// triangles get a zero bound) in a leaf whose box starts at `origin` with size `extent`.
    pub(crate) fn new(triangles: &[[Point3; 3]], origin: Point3, extent: Point3) -> Self {
        let scale = offset_scale(extent);
        // A unit vector rounded to the grid, and the grid vector's offset through `at`.
        let quantise = |unit: Point3, at: Point3| -> ([i16; 3], i16) {
            let q = unit.map(|v| nearest(v * UNIT) as i16);
            let offset = dot(q.map(|v| f64::from(v) / UNIT), at) / scale;
            (q, nearest(offset).clamp(-UNIT, UNIT) as i16)
        };
        let mut block = LeafBound::default();
        for (lane, corners) in triangles.iter().take(LANES).enumerate() {
            let [a, b, c] = corners.map(|v| sub(v, origin));
            let n = cross(sub(b, a), sub(c, a));
            let area2 = norm(n);
            let thin = area2 <= MIN_SINE * norm(sub(b, a)) * norm(sub(c, a));
            if !(area2.is_finite() && area2 > 0.0) || thin {
                continue;
            }
            let unit = n.map(|v| v / area2);
            let (q, offset) = quantise(unit, a);
            for (axis, &v) in block.normal.iter_mut().zip(&q) {
                axis[lane] = v;
            }
            block.normal_offset[lane] = offset;
            for (i, (start, end)) in [(a, b), (b, c), (c, a)].into_iter().enumerate() {
                let e = sub(end, start);
                // e × n̂ lies in the plane, points away from the third corner, and has length |e|.
                let (q, offset) = quantise(cross(e, unit).map(|v| v / norm(e)), start);
                for (axis, &v) in block.edge[i].iter_mut().zip(&q) {
                    axis[lane] = v;
                }
                block.edge_offset[i][lane] = offset;
            }
        }
        block
    }

    /// Lower bounds on the squared distances from `p` (relative to the block's origin) to the
    /// block's triangles; `scale` the leaf's [`offset_scale`], `margin` from [`margin`]. A lane
    /// whose arithmetic overflows gets 0.
    #[inline(always)]
    pub(crate) fn lower_bounds2(&self, p: [f32; 3], scale: f32, margin: f32) -> [f32; LANES] {
        // Everything in units of 1 / UNIT until the end.
        let dot3 = |v: &[[i16; LANES]; 3], l: usize| {
            f32::from(v[0][l]) * p[0] + f32::from(v[1][l]) * p[1] + f32::from(v[2][l]) * p[2]
        };
        let unit_scale = scale * UNIT as f32;
        let at = |o: i16| f32::from(o) * unit_scale;
        let inv = (1.0 / UNIT) as f32;
        let mut out = [0.0f32; LANES];
        for (l, o) in out.iter_mut().enumerate() {
            let h = (dot3(&self.normal, l) - at(self.normal_offset[l])).abs();
            let s = (dot3(&self.edge[0], l) - at(self.edge_offset[0][l]))
                .max(dot3(&self.edge[1], l) - at(self.edge_offset[1][l]))
                .max(dot3(&self.edge[2], l) - at(self.edge_offset[2][l]));
            // `max` returns the other operand for a NaN, so an overflow ends at 0 here.
            let h = (h * inv - margin).max(0.0);
            let s = (s * inv - margin).max(0.0);
            // TINY: a squared distance that underflows rounds by up to one subnormal step.
            *o = ((h * h + s * s) * SHRINK - TINY).max(0.0);
        }
        out
    }
}

/// `x` rounded to an integer, half away from zero, within `0.5 + ulp(x)` of `x` (`f64::round`
/// is a library call on baseline x86-64: 7 % of the instructions of a BVH build); `x` within
/// ±2⁶². The extra ulp is far inside [`margin`]'s slack.
#[inline]
fn nearest(x: f64) -> f64 {
    (x + 0.5f64.copysign(x)) as i64 as f64
}

/// The absolute margin for a query at `p_local` (relative to the block's origin `origin`) in a
/// leaf of extent `extent`: `2⁻¹³` (1 / 8192) of the local coordinates' size covers the
/// rounded directions (`ε (d + D)` with `d ≤ |p_local| + D`), the rounded offsets (`D / 65534`) and the
/// `f32` arithmetic; `2⁻⁴⁴` of the global coordinates' size covers the f64 exact test.
#[inline(always)]
pub(crate) fn margin(p_local: Point3, origin: Point3, extent: Point3) -> f32 {
    let sum = |v: Point3| v[0].abs() + v[1].abs() + v[2].abs();
    let local = sum(p_local) + sum(extent);
    let global = sum(origin) + local;
    (local / 8192.0 + global / 17_592_186_044_416.0) as f32
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
pub(super) mod tests {
    use super::*;
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    /// Exact squared point-triangle distance (Ericson's region walk), f64; the oriented boxes'
    /// tests use it too.
    pub(crate) fn exact2(p: Point3, [a, b, c]: [Point3; 3]) -> f64 {
        let n = cross(sub(b, a), sub(c, a));
        let inside = |u: Point3, v: Point3| dot(cross(sub(v, u), sub(p, u)), n) >= 0.0;
        let seg2 = |u: Point3, v: Point3| {
            let e = sub(v, u);
            let t = (dot(sub(p, u), e) / dot(e, e)).clamp(0.0, 1.0);
            let q = [u[0] + t * e[0], u[1] + t * e[1], u[2] + t * e[2]];
            dot(sub(p, q), sub(p, q))
        };
        if inside(a, b) && inside(b, c) && inside(c, a) {
            let h = dot(sub(p, a), n);
            h * h / dot(n, n)
        } else {
            seg2(a, b).min(seg2(b, c)).min(seg2(c, a))
        }
    }

    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        move || rng.random::<f64>()
    }

    fn check(origin: Point3, size: f64, far: f64, seed: u64) -> usize {
        let mut r = rng(seed);
        let mut tight = 0;
        for _ in 0..2000 {
            let mut pt = || [0, 1, 2].map(|k| origin[k] + size * r());
            let tris: Vec<[Point3; 3]> = (0..LANES).map(|_| [pt(), pt(), pt()]).collect();
            let lo = [0, 1, 2].map(|k| {
                tris.iter()
                    .flatten()
                    .map(|v| v[k])
                    .fold(f64::INFINITY, f64::min)
            });
            let hi = [0, 1, 2].map(|k| {
                tris.iter()
                    .flatten()
                    .map(|v| v[k])
                    .fold(f64::NEG_INFINITY, f64::max)
            });
            let extent = sub(hi, lo);
            let block = LeafBound::new(&tris, lo, extent);
            let p = [0, 1, 2].map(|k| origin[k] + size * (r() * (1.0 + 2.0 * far) - far));
            let local = sub(p, lo);
            let m = margin(local, lo, extent);
            let scale = offset_scale(extent) as f32;
            let lb = block.lower_bounds2(local.map(|v| v as f32), scale, m);
            for (l, t) in tris.iter().enumerate() {
                let d2 = exact2(p, *t);
                assert!(
                    f64::from(lb[l]) <= d2,
                    "bound {} above {} at {p:?} for {t:?}",
                    lb[l],
                    d2
                );
                if f64::from(lb[l]) >= 0.9 * d2 {
                    tight += 1;
                }
            }
        }
        tight
    }

    #[test]
    fn never_above_the_exact_distance_and_usually_close() {
        // unit scale, near and far queries; far from the origin; tiny triangles far out
        let tight = check([0.0; 3], 1.0, 0.5, 1);
        assert!(tight > 2000, "{tight} of 8000 within 10 %");
        check([0.0; 3], 1.0, 20.0, 2);
        check([1e6, -2e6, 3e5], 1.0, 0.5, 3);
        let tight = check([1e6, -2e6, 3e5], 1e-3, 0.5, 4);
        assert!(tight > 2000, "{tight} of 8000 within 10 %");
        check([-3e3, 5e2, 7e1], 1e-7, 2.0, 5);
    }

    #[test]
    fn degenerate_and_thin_triangles_are_always_tested() {
        let tris = [
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
            [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 1e-12, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        ];
        let extent = [2.0, 1.0, 0.0];
        let block = LeafBound::new(&tris, [0.0; 3], extent);
        let scale = offset_scale(extent) as f32;
        let lb = block.lower_bounds2([0.25, 0.25, 3.0], scale, 0.0);
        assert_eq!(&lb[..3], &[0.0; 3]);
        // the good one: straight above its face, distance 3
        assert!(lb[3] <= 9.0 && lb[3] > 8.99, "{}", lb[3]);
        // a vertex region: below the distance, above zero
        let lb = block.lower_bounds2([-1.0, -1.0, 0.0], scale, 0.0);
        assert!(lb[3] > 0.99 && lb[3] <= 2.0, "{}", lb[3]);
    }

    #[test]
    fn overflow_gives_no_bound() {
        let tris = [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]];
        let block = LeafBound::new(&tris, [0.0; 3], [1.0, 1.0, 0.0]);
        let lb = block.lower_bounds2([f32::MAX, f32::MAX, f32::MAX], 1.0, f32::INFINITY);
        assert_eq!(lb, [0.0; LANES]);
    }
}
