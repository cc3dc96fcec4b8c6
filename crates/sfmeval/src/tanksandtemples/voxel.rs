//! Voxel down-sampling with Open3D's semantics (`PointCloud::VoxelDownSample`), which the
//! benchmark's toolbox applies before registration and evaluation: the grid starts half a voxel
//! below the cloud's minimum corner, a point falls in voxel `floor((p − start) / size)`, and each
//! occupied voxel becomes the mean of its points, summed in input order. Voxels come out in the
//! order of their first point (Open3D's order is its hash map's; the set of points is the same).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use crate::error::{Error, Result};
use crate::geometry::Point3;

/// The voxel means of `points` for voxels of edge `size`.
pub fn voxel_down_sample(points: &[Point3], size: f64) -> Result<Vec<Point3>> {
    if !(size.is_finite() && size > 0.0) {
        return Err(Error::InvalidOption(format!(
            "voxel size must be > 0, got {size}"
        )));
    }
    let Some(first) = points.first() else {
        return Ok(Vec::new());
    };
    let (mut min, mut max) = (*first, *first);
    for p in points {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
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
    let sums = if cells < f64::from(1u32 << 21) {
        group(points, |p| {
            let [x, y, z] = index(p).map(|i| u64::from(i as u32));
            (x << 42) | (y << 21) | z
        })
    } else {
        group(points, index)
    };
    Ok(sums
        .into_iter()
        .map(|(s, n)| {
            let n = f64::from(n);
            [s[0] / n, s[1] / n, s[2] / n]
        })
        .collect())
}

/// Sums and counts per key, in the order keys first appear, points summed in input order.
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
}
