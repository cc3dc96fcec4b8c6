//! Voxel down-sampling with Open3D's semantics (`PointCloud::VoxelDownSample`), which the
//! benchmark's toolbox applies before registration and evaluation: the grid starts half a voxel
//! below the cloud's minimum corner, a point falls in voxel `floor((p − start) / size)`, and each
//! occupied voxel becomes the mean of its points, summed in input order. Voxels come out in the
//! order of their first point (Open3D's order is its hash map's; the set of points is the same).
//!
//! The voxels are found by sorting `(voxel key, index)` pairs rather than through a hash map: a
//! map over a few million points misses the cache at almost every point, and one thread had to
//! fill it. Voxel numbers below 2³² (the common case) are sorted by a radix sort of the numbers
//! alone, a few passes over the pairs where a comparison sort took ~20 comparisons a point;
//! wider grids by a (parallel) comparison sort. Either keeps each voxel's points in input
//! order, so the sums are the same to the bit.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use sfmeval::geometry::Point3;
use sfmeval::parallel;
use sfmeval::{Error, Result};

/// The voxel means of `points` for voxels of edge `size`.
pub fn voxel_down_sample(points: &[Point3], size: f64) -> Result<Vec<Point3>> {
    if !(size.is_finite() && size > 0.0) {
        return Err(Error::InvalidOption(format!(
            "voxel size must be > 0, got {size}"
        )));
    }
    if points.is_empty() {
        return Ok(Vec::new());
    }
    let (min, max) = bounds(points);
    let start = [0, 1, 2].map(|k| min[k] - size * 0.5);
    let end = [0, 1, 2].map(|k| max[k] + size * 0.5);
    let extent = (0..3).map(|k| end[k] - start[k]).fold(0.0, f64::max);
    if size * f64::from(i32::MAX) < extent {
        return Err(Error::InvalidOption(format!(
            "voxel size {size} is too small for a cloud {extent} across"
        )));
    }
    // Voxel indices as one u64 key (21 bits an axis) when the grid is small enough, the common
    // case, else the index triple.
    let cells = (0..3)
        .map(|k| ((max[k] - start[k]) / size).floor())
        .fold(0.0, f64::max);
    // `(p − start) / size` is not negative (`start` is half a voxel below the minimum), so the
    // truncation of `as` is the floor (and saturates the same for ±∞ and NaN) without a call
    // to `floor`.
    let index = |p: &Point3| [0, 1, 2].map(|k| ((p[k] - start[k]) / size) as i32);
    // Voxels per axis (a point's index is at most the maximum's, computed the same way).
    let per_axis = [0, 1, 2].map(|k| ((max[k] - start[k]) / size).floor() + 1.0);
    let voxels = per_axis.iter().product::<f64>();
    // Both sorted paths hold point indices in 32 bits; larger clouds take the hash map.
    let indexable = u32::try_from(points.len()).is_ok();
    if indexable && voxels <= f64::from(u32::MAX) {
        let [_, ny, nz] = per_axis.map(|c| c as u64);
        Ok(packed_means(points, |p| {
            let [x, y, z] = index(p).map(|i| u64::from(i as u32));
            (x * ny + y) * nz + z
        }))
    } else if indexable && cells < f64::from(1u32 << 21) {
        Ok(sorted_means(points, |p| {
            let [x, y, z] = index(p).map(|i| u64::from(i as u32));
            (x << 42) | (y << 21) | z
        }))
    } else {
        Ok(group(points, index)
            .into_iter()
            .map(|(s, n)| mean(s, n))
            .collect())
    }
}

/// The smallest and largest coordinate of `points` (not empty) on each axis, NaN ignored.
fn bounds(points: &[Point3]) -> (Point3, Point3) {
    let parts = parallel::map_ranges(points.len(), |range| {
        // Four running bounds of plain comparisons, which the compiler vectorises and which do
        // not wait on one another (NaN fails them: ignored, as `f64::min` ignores it).
        let mut los = [[f64::INFINITY; 3]; 4];
        let mut his = [[f64::NEG_INFINITY; 3]; 4];
        let slice = &points[range];
        let chunks = slice.chunks_exact(4);
        let rest = chunks.remainder();
        for chunk in chunks {
            for ((p, lo), hi) in chunk.iter().zip(&mut los).zip(&mut his) {
                for k in 0..3 {
                    lo[k] = if p[k] < lo[k] { p[k] } else { lo[k] };
                    hi[k] = if p[k] > hi[k] { p[k] } else { hi[k] };
                }
            }
        }
        for (p, (lo, hi)) in rest.iter().zip(los.iter_mut().zip(&mut his)) {
            for k in 0..3 {
                lo[k] = if p[k] < lo[k] { p[k] } else { lo[k] };
                hi[k] = if p[k] > hi[k] { p[k] } else { hi[k] };
            }
        }
        let (mut min, mut max) = (los[0], his[0]);
        for (lo, hi) in los[1..].iter().zip(&his[1..]) {
            for k in 0..3 {
                min[k] = if lo[k] < min[k] { lo[k] } else { min[k] };
                max[k] = if hi[k] > max[k] { hi[k] } else { max[k] };
            }
        }
        // An axis with NaN only: NaN, as the pairwise minimum gives.
        for k in 0..3 {
            if min[k] == f64::INFINITY && max[k] == f64::NEG_INFINITY {
                (min[k], max[k]) = (f64::NAN, f64::NAN);
            }
        }
        (min, max)
    });
    let (mut min, mut max) = parts[0];
    for (lo, hi) in &parts[1..] {
        for k in 0..3 {
            min[k] = min[k].min(lo[k]);
            max[k] = max[k].max(hi[k]);
        }
    }
    (min, max)
}

/// `sum / n`, per axis.
fn mean(sum: [f64; 3], n: u32) -> Point3 {
    let n = f64::from(n);
    [sum[0] / n, sum[1] / n, sum[2] / n]
}

/// The voxel means, in the order of each voxel's first point, through a sort of the
/// `(key, index)` pairs: a voxel's points are then one run, in input order (for grids of 2³²
/// voxels or more, with 21 bits an axis).
fn sorted_means(points: &[Point3], key: impl Fn(&Point3) -> u64 + Sync + Send) -> Vec<Point3> {
    let mut keyed = parallel::map_range(points.len(), |i| (key(&points[i]), i as u32));
    parallel::sort_unstable(&mut keyed);
    means_in_first_order(points, keyed, |e| e.0, |e| e.1 as usize)
}

/// [`sorted_means`] for voxel numbers below 2³² (the common case): each point's voxel number
/// and index packed in one `u64` (number above, index below), so that the sort compares plain
/// integers (and keeps each voxel's points in input order).
fn packed_means(points: &[Point3], voxel: impl Fn(&Point3) -> u64 + Sync + Send) -> Vec<Point3> {
    let mut keyed = parallel::map_range(points.len(), |i| (voxel(&points[i]) << 32) | i as u64);
    // The entries are in index order: a stable sort by voxel number alone orders them by
    // (voxel, index), as a sort of the whole keys would.
    let top = keyed.iter().map(|e| e >> 32).max().unwrap_or(0);
    radix_sort_high(&mut keyed, bits(top));
    means_in_first_order(
        points,
        keyed,
        |e| e >> 32,
        |e| (e & u64::from(u32::MAX)) as usize,
    )
}

/// The means of the voxels `keyed` names (an entry a point, sorted by voxel and then by point
/// index, read by `voxel_of` and `index_of`; fewer than 2³² points), in the order of each
/// voxel's first point: each voxel's points are one run of `keyed` in input order, and the
/// voxels are put in first-point order by a second sort of packed `u64`s (first point, voxel)
/// rather than of the means.
fn means_in_first_order<E: Copy + Send + Sync>(
    points: &[Point3],
    keyed: Vec<E>,
    voxel_of: impl Fn(E) -> u64 + Sync,
    index_of: impl Fn(E) -> usize + Sync,
) -> Vec<Point3> {
    let starts: Vec<usize> = (0..keyed.len())
        .filter(|&k| k == 0 || voxel_of(keyed[k]) != voxel_of(keyed[k - 1]))
        .collect();
    let means = parallel::map_range(starts.len(), |v| {
        let end = starts.get(v + 1).copied().unwrap_or(keyed.len());
        let mut sum = [0.0; 3];
        for &e in &keyed[starts[v]..end] {
            let p = points[index_of(e)];
            for a in 0..3 {
                sum[a] += p[a];
            }
        }
        mean(sum, (end - starts[v]) as u32)
    });
    let mut firsts = parallel::map_range(starts.len(), |v| {
        ((index_of(keyed[starts[v]]) as u64) << 32) | v as u64
    });
    drop(keyed);
    // The first points are distinct: sorting by them alone orders the entries fully.
    radix_sort_high(&mut firsts, bits(points.len() as u64));
    parallel::map_range(firsts.len(), |j| {
        means[(firsts[j] & u64::from(u32::MAX)) as usize]
    })
}

/// Bits needed to write `v`.
fn bits(v: u64) -> u32 {
    u64::BITS - v.leading_zeros()
}

/// Sorts `keys` by their high 32 bits, of which only the lowest `key_bits` may be set, keeping
/// the order of equal ones (a least-significant-digit radix sort, up to 11 bits a pass): for
/// the few million keys of a voxel grid, a fraction of a comparison sort's work.
fn radix_sort_high(keys: &mut Vec<u64>, key_bits: u32) {
    let passes = key_bits.div_ceil(11);
    if passes == 0 || keys.len() < 2 {
        return;
    }
    let digit = key_bits.div_ceil(passes);
    let mask = (1usize << digit) - 1;
    let mut other = vec![0u64; keys.len()];
    let mut counts = vec![0usize; mask + 1];
    for pass in 0..passes {
        let shift = 32 + pass * digit;
        counts.iter_mut().for_each(|c| *c = 0);
        for &k in keys.iter() {
            counts[(k >> shift) as usize & mask] += 1;
        }
        let mut total = 0;
        for c in counts.iter_mut() {
            let n = *c;
            *c = total;
            total += n;
        }
        for &k in keys.iter() {
            let b = (k >> shift) as usize & mask;
            other[counts[b]] = k;
            counts[b] += 1;
        }
        std::mem::swap(keys, &mut other);
    }
}

/// Sums and counts per key, in the order keys first appear, points summed in input order (for
/// grids too wide for [`sorted_means`]' 63-bit keys).
/// A point in the previous point's voxel reuses its slot without a hash look-up (clouds
/// written in spatial runs, as scanners write them; on a shuffled cloud it costs one comparison).
fn group<K: std::hash::Hash + Eq + Copy>(
    points: &[Point3],
    key: impl Fn(&Point3) -> K,
) -> Vec<([f64; 3], u32)> {
    let mut voxel_of: HashMap<K, u32, BuildHasherDefault<VoxelHasher>> =
        HashMap::with_capacity_and_hasher(points.len() / 4, Default::default());
    let mut sums: Vec<([f64; 3], u32)> = Vec::new();
    let mut last: Option<(K, u32)> = None;
    for p in points {
        let key = key(p);
        let slot = match last {
            Some((k, slot)) if k == key => slot,
            _ => {
                let next = sums.len() as u32;
                let slot = *voxel_of.entry(key).or_insert(next);
                if slot == next {
                    sums.push(([0.0; 3], 0));
                }
                last = Some((key, slot));
                slot
            }
        };
        let (sum, n) = &mut sums[slot as usize];
        for k in 0..3 {
            sum[k] += p[k];
        }
        *n += 1;
    }
    sums
}

/// A fast hasher for voxel keys (multiply–rotate, then a finaliser); the map's order is never
/// used, so its quality only matters for speed.
#[derive(Default)]
struct VoxelHasher(u64);

impl Hasher for VoxelHasher {
    fn finish(&self) -> u64 {
        // MurmurHash3's finaliser: the map takes its bucket from the low bits, which the
        // multiplications alone fill from the key's low bits only.
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_i32(&mut self, v: i32) {
        self.write_u64(u64::from(v as u32));
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn means_per_voxel_anchored_half_a_voxel_below_the_minimum() {
        // min = 0 → the grid starts at -0.5: voxels [-0.5, 0.5), [0.5, 1.5), ...
        let pts = [
            [0.0, 0.0, 0.0],
            [0.4, 0.0, 0.0],
            [0.5, 0.0, 0.0],
            [1.25, 0.0, 0.0],
            [3.0, 0.2, -0.2],
        ];
        let out = voxel_down_sample(&pts, 1.0).unwrap();
        assert_eq!(
            out,
            vec![[0.2, 0.0, 0.0], [0.875, 0.0, 0.0], [3.0, 0.2, -0.2]]
        );
        assert!(voxel_down_sample(&pts, 0.0).is_err());
        assert!(voxel_down_sample(&pts, f64::NAN).is_err());
        assert!(voxel_down_sample(&pts, 1e-12).is_err());
        assert!(voxel_down_sample(&[], 1.0).unwrap().is_empty());
        // A grid wider than 2^21 voxels takes the triple-key path: the same means.
        let wide = [[0.0, 0.0, 0.0], [0.2, 0.0, 0.0], [5e6, 1.0, 1.0]];
        assert_eq!(
            voxel_down_sample(&wide, 1.0).unwrap(),
            vec![[0.1, 0.0, 0.0], [5e6, 1.0, 1.0]]
        );
    }

    #[test]
    fn bounds_equal_the_pairwise_minimum_and_maximum() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x9e37_79b9_7f4a_7c15u64);
        let mut next = move || rng.random::<f64>() - 0.5;
        let specials = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0];
        for n in [1usize, 3, 4, 5, 17, 70_001] {
            for special in [None, Some(0), Some(1), Some(2), Some(3)] {
                let mut pts: Vec<Point3> = (0..n).map(|_| [next(), next(), next()]).collect();
                if let Some(s) = special {
                    for (i, p) in pts.iter_mut().enumerate().filter(|(i, _)| i % 3 == 0) {
                        p[i % 3] = specials[s];
                    }
                }
                // An axis that is NaN throughout.
                if n == 5 {
                    pts.iter_mut().for_each(|p| p[1] = f64::NAN);
                }
                let (mut min, mut max) = (pts[0], pts[0]);
                for p in &pts {
                    for k in 0..3 {
                        min[k] = min[k].min(p[k]);
                        max[k] = max[k].max(p[k]);
                    }
                }
                let (lo, hi) = bounds(&pts);
                for k in 0..3 {
                    let same = |a: f64, b: f64| a == b || (a.is_nan() && b.is_nan());
                    assert!(same(lo[k], min[k]), "{n} {special:?}: {lo:?} {min:?}");
                    assert!(same(hi[k], max[k]), "{n} {special:?}: {hi:?} {max:?}");
                }
            }
        }
    }

    #[test]
    fn radix_sort_orders_by_the_high_bits_stably() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x853c_49e6_748f_ea9b);
        let mut keys: Vec<u64> = (0..20_000u64)
            .map(|i| (rng.random_range(0..3000u64) << 32) | i)
            .collect();
        let mut want = keys.clone();
        want.sort_unstable();
        radix_sort_high(&mut keys, bits(2999));
        assert_eq!(keys, want);
        // 30 key bits: three passes of 10.
        let mut keys: Vec<u64> = (0..5000u64)
            .rev()
            .map(|i| ((i * 214_013) % (1 << 30)) << 32 | i)
            .collect();
        let mut want = keys.clone();
        want.sort_unstable();
        radix_sort_high(&mut keys, 30);
        assert_eq!(keys, want);
    }

    #[test]
    fn sorted_and_packed_runs_equal_the_hash_map_in_voxels_order_and_bits() {
        // 60k seeded points over ~4k voxels, in no spatial order, several chunks of the sort.
        let mut rng = ChaCha8Rng::seed_from_u64(0x2545_f491_4f6c_dd1d);
        let mut next = move || rng.random::<f64>();
        let pts: Vec<Point3> = (0..60_000)
            .map(|_| [next() * 16.0, next() * 16.0 - 8.0, next() * 16.0 + 1e3])
            .collect();
        let key = |p: &Point3| {
            let [x, y, z] = [0, 1, 2].map(|k| (p[k].floor() as i64 + 100) as u64);
            (x << 42) | (y << 21) | z
        };
        let want: Vec<Point3> = group(&pts, key)
            .into_iter()
            .map(|(s, n)| mean(s, n))
            .collect();
        let got = sorted_means(&pts, key);
        assert!(want.len() > 4000);
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g.map(f64::to_bits), w.map(f64::to_bits));
        }
        // The packed path: voxel numbers below 2³² (a 17 × 17 × 1200 grid here).
        let packed = packed_means(&pts, |p| {
            let [x, y, z] = [0, 1, 2].map(|k| (p[k].floor() as i64 + 100) as u64);
            ((x - 100) * 17 + (y - 92)) * 1200 + (z - 100)
        });
        assert_eq!(packed.len(), want.len());
        for (g, w) in packed.iter().zip(&want) {
            assert_eq!(g.map(f64::to_bits), w.map(f64::to_bits));
        }
        // And through voxel_down_sample, which takes it for this cloud: the hash map's means
        // on the grid anchored half a voxel below the minimum.
        let (min, _) = bounds(&pts);
        let start = min.map(|m| m - 0.5);
        let want: Vec<Point3> = group(&pts, |p| [0, 1, 2].map(|k| (p[k] - start[k]) as i32))
            .into_iter()
            .map(|(s, n)| mean(s, n))
            .collect();
        let got = voxel_down_sample(&pts, 1.0).unwrap();
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g.map(f64::to_bits), w.map(f64::to_bits));
        }
    }
}
