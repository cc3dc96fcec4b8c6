//! The median splits of the k-d order and of the BVH: points (or triangle centroids) as `f32`
//! keys carried with their index, so that a split reads and permutes one contiguous slice
//! instead of looking each key up, and compares one `u64` that orders as the coordinate
//! (`total_cmp`) then the index.

/// A point's or a centroid's `f32` coordinates and its index.
pub(crate) type Keyed = ([f32; 3], u32);

/// `e`'s coordinate on `axis` and its index as one integer that orders as `total_cmp` on the
/// coordinate, then the index.
#[inline(always)]
pub(crate) fn split_key(e: &Keyed, axis: usize) -> u64 {
    let bits = e.0[axis].to_bits();
    // `total_cmp`'s flip of the negative values' magnitude bits, and the sign bit flipped so
    // that unsigned order is signed order.
    let ordered = (bits ^ ((((bits as i32) >> 31) as u32) >> 1)) ^ (1 << 31);
    (u64::from(ordered) << 32) | u64::from(e.1)
}

/// Moves the key of rank `mid` (by [`split_key`] on `axis`) to `mid`, the smaller ones before
/// it and the larger after (`select_nth_unstable`: deterministic for the same slice). The
/// axis is fixed in each closure.
pub(crate) fn select_at(keys: &mut [Keyed], mid: usize, axis: usize) {
    match axis {
        0 => keys.select_nth_unstable_by_key(mid, |e| split_key(e, 0)),
        1 => keys.select_nth_unstable_by_key(mid, |e| split_key(e, 1)),
        _ => keys.select_nth_unstable_by_key(mid, |e| split_key(e, 2)),
    };
}

/// The axis along which `lo..hi` is longest; the last of equally long ones.
pub(crate) fn longest_axis(lo: [f32; 3], hi: [f32; 3]) -> usize {
    (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0)
}

/// The smallest and largest finite coordinate of `keys` on each axis (±∞ for none): one pass
/// of comparisons the compiler vectorises (NaN fails them and counts for none), redone with
/// the finiteness test in the rare case an infinite coordinate reached the bounds.
pub(crate) fn key_bounds(keys: &[Keyed]) -> ([f32; 3], [f32; 3]) {
    // Four running bounds, so that the comparisons do not wait on one another.
    let mut los = [[f32::INFINITY; 4]; 4];
    let mut his = [[f32::NEG_INFINITY; 4]; 4];
    let chunks = keys.chunks_exact(4);
    let rest = chunks.remainder();
    for chunk in chunks {
        for ((e, lo), hi) in chunk.iter().zip(&mut los).zip(&mut his) {
            // A fourth lane (z again) fills a 4-wide register; only the first three are read.
            let p = [e.0[0], e.0[1], e.0[2], e.0[2]];
            for k in 0..4 {
                lo[k] = if p[k] < lo[k] { p[k] } else { lo[k] };
                hi[k] = if p[k] > hi[k] { p[k] } else { hi[k] };
            }
        }
    }
    for (e, (lo, hi)) in rest.iter().zip(los.iter_mut().zip(&mut his)) {
        for k in 0..3 {
            lo[k] = if e.0[k] < lo[k] { e.0[k] } else { lo[k] };
            hi[k] = if e.0[k] > hi[k] { e.0[k] } else { hi[k] };
        }
    }
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (l, h) in los.iter().zip(&his) {
        for k in 0..3 {
            lo[k] = if l[k] < lo[k] { l[k] } else { lo[k] };
            hi[k] = if h[k] > hi[k] { h[k] } else { hi[k] };
        }
    }
    if lo.iter().chain(&hi).all(|v| v.is_finite()) {
        return (lo, hi);
    }
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (p, _) in keys {
        for k in 0..3 {
            if p[k].is_finite() {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key orders as `total_cmp`, then the index, also for signed zeros, subnormals,
    /// infinities and NaN.
    #[test]
    fn key_orders_as_total_cmp_then_index() {
        let values = [
            f32::NEG_INFINITY,
            -1.5,
            -0.0,
            0.0,
            1e-40,
            2.0,
            f32::INFINITY,
            f32::NAN,
        ];
        for a in values {
            for b in values {
                for (i, j) in [(1, 2), (2, 1), (3, 3)] {
                    let (x, y) = (([a, 0.0, 0.0], i), ([b, 0.0, 0.0], j));
                    let want = a.total_cmp(&b).then(i.cmp(&j));
                    assert_eq!(split_key(&x, 0).cmp(&split_key(&y, 0)), want, "{a} {b}");
                }
            }
        }
    }

    /// The bounds are those of the finite coordinates, whatever the count's remainder by four
    /// and wherever NaN and infinities sit.
    #[test]
    fn bounds_are_those_of_the_finite_coordinates() {
        let specials = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.0];
        for n in [0usize, 1, 3, 4, 5, 17, 203] {
            for special_every in [0usize, 2, 7] {
                let keys: Vec<Keyed> = (0..n)
                    .map(|i| {
                        let v = ((i * 37 % 101) as f32 - 50.0) * 0.21;
                        let mut p = [v, -v * 0.5, v * v];
                        if special_every > 0 && i % special_every == 0 {
                            p[i % 3] = specials[(i / special_every) % specials.len()];
                        }
                        (p, i as u32)
                    })
                    .collect();
                let mut lo = [f32::INFINITY; 3];
                let mut hi = [f32::NEG_INFINITY; 3];
                for (p, _) in &keys {
                    for k in 0..3 {
                        if p[k].is_finite() {
                            lo[k] = lo[k].min(p[k]);
                            hi[k] = hi[k].max(p[k]);
                        }
                    }
                }
                let (glo, ghi) = key_bounds(&keys);
                // (`==`: a zero's sign is either's choice)
                assert_eq!(
                    (glo, ghi),
                    (lo, hi),
                    "{n} keys, a special value every {special_every}"
                );
            }
        }
    }
}
