//! Z-order (Morton) visiting order of 3D points: consecutive points in this order are close in
//! space, so consecutive closest-point queries walk the same BVH / k-d tree nodes while they are
//! still in cache. On a 1M-triangle mesh, 94k near-surface queries took 0.8 s in file order and
//! 0.3 s in this order (one thread).

use crate::geometry::Point3;

/// Bits per axis of the Morton code (3 × 21 = 63 bits).
const BITS: u32 = 21;

/// `(Morton code, index)` of each of `points`, in input order, the code taken on the points'
/// bounding box (non-finite points get `u64::MAX`). The keys are distinct, so sorting them by
/// any sort gives one order: the Morton order (ties by index, non-finite points last), which
/// `parallel::morton_order` computes.
pub(crate) fn morton_keys(points: &[Point3]) -> Vec<(u64, u32)> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points.iter().filter(|p| p.iter().all(|v| v.is_finite())) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
    let scale = if extent > 0.0 {
        f64::from((1u32 << BITS) - 1) / extent
    } else {
        0.0
    };
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let code = if p.iter().all(|v| v.is_finite()) {
                // In [0, 2^21 - 1] by construction; `as` saturates anything rounding outside.
                let cell = |k: usize| ((p[k] - lo[k]) * scale) as u64;
                spread(cell(0)) | (spread(cell(1)) << 1) | (spread(cell(2)) << 2)
            } else {
                u64::MAX
            };
            (code, i as u32)
        })
        .collect()
}

/// Spreads the low 21 bits of `x` so that bit i moves to bit 3i.
fn spread(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | (x << 32)) & 0x1f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x1f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    // The order the keys give, as the callers get it.
    use crate::parallel::morton_order;

    #[test]
    fn spread_moves_bit_i_to_3i() {
        for i in 0..BITS {
            assert_eq!(spread(1 << i), 1 << (3 * i), "bit {i}");
        }
        assert_eq!(spread(0x1f_ffff), 0x1249_2492_4924_9249);
    }

    #[test]
    fn order_is_a_permutation_following_the_z_curve() {
        // The 8 corners of a cube in scrambled order, plus a NaN point and a duplicate.
        let pts = vec![
            [1.0, 1.0, 1.0],
            [f64::NAN, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 1.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 0.0, 0.0],
        ];
        let order = morton_order(&pts);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..pts.len() as u32).collect::<Vec<_>>());
        // x is the lowest bit, then y, then z; the duplicate origin follows the first; NaN last.
        assert_eq!(order, vec![2, 9, 3, 5, 6, 7, 8, 4, 0, 1]);
    }

    #[test]
    fn degenerate_inputs() {
        assert!(morton_order(&[]).is_empty());
        assert_eq!(
            morton_order(&[[1.0, 2.0, 3.0], [1.0, 2.0, 3.0]]),
            vec![0, 1]
        );
    }
}
