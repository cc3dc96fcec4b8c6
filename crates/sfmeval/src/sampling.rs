//! Area-uniform random sampling of a triangle mesh surface, seeded and platform-independent
//! (ChaCha8 stream; the same seed gives the same samples natively and in wasm).

use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use crate::error::{Error, Result};
use crate::geometry::{Point3, TriangleMesh, triangle_area};
use crate::parallel;

/// Words of the ChaCha stream a sample draws: three `f64`, two 32-bit words each.
const WORDS_PER_SAMPLE: u128 = 6;

/// Draws `n` points uniformly by area on the mesh surface.
pub fn sample_surface(mesh: &TriangleMesh, n: usize, seed: u64) -> Result<Vec<Point3>> {
    sample_surface_with_area(mesh, n, seed).map(|(samples, _)| samples)
}

/// [`sample_surface`] and the mesh's surface area, the sum its sampling adds up anyway (the
/// same bits as [`TriangleMesh::area`]: the same areas added in the same order).
pub fn sample_surface_with_area(
    mesh: &TriangleMesh,
    n: usize,
    seed: u64,
) -> Result<(Vec<Point3>, f64)> {
    // The areas in parallel, their running sum in order (the same bits as one loop).
    let mut cumulative = parallel::map_range(mesh.triangles.len(), |i| {
        triangle_area(mesh.corners(&mesh.triangles[i]))
    });
    let mut total = 0.0f64;
    for c in &mut cumulative {
        total += *c;
        *c = total;
    }
    if !(total > 0.0) || !total.is_finite() {
        return Err(Error::Geometry(
            "the ground-truth mesh has zero surface area".into(),
        ));
    }
    // The stream is drawn in the same order as a per-sample loop would (target, u, v), then
    // the triangle of each target is found by walking the cumulative areas once in target
    // order instead of a binary search per sample: 1M binary searches over 1M triangles miss
    // the cache on nearly every step (~1 s); the sort and the walk take a tenth of that.
    // In parallel, without changing a bit: each chunk of the stream starts at its sample's
    // word of the ChaCha stream, each chunk of the walk at its first target's triangle.
    let mut draws = vec![[0.0f64; 3]; n];
    parallel::fill_with_state(&mut draws, |rng: &mut Option<ChaCha8Rng>, j| {
        let rng = rng.get_or_insert_with(|| {
            let mut r = ChaCha8Rng::seed_from_u64(seed);
            r.set_word_pos(j as u128 * WORDS_PER_SAMPLE);
            r
        });
        let target = rng.random::<f64>() * total;
        [target, rng.random(), rng.random()]
    });
    // Sorted by (target, index) as plain integers: a target is finite and ≥ 0, where the
    // order of the bits is the order of the numbers.
    let mut keyed: Vec<(u64, u32)> = parallel::map_range(n, |k| (draws[k][0].to_bits(), k as u32));
    parallel::sort_unstable(&mut keyed);
    let by_target: Vec<u32> = parallel::map_range(n, |j| keyed[j].1);
    drop(keyed);
    let last = cumulative.len() - 1;
    let mut sorted = vec![[0.0f64; 3]; n];
    parallel::fill_with_state(&mut sorted, |i: &mut Option<usize>, j| {
        let [target, u, v] = draws[by_target[j] as usize];
        // First triangle whose cumulative area exceeds the target (as `partition_point`).
        let i = i.get_or_insert_with(|| cumulative.partition_point(|&c| c <= target).min(last));
        while *i < last && cumulative[*i] <= target {
            *i += 1;
        }
        let [a, b, c] = mesh.corners(&mesh.triangles[*i]);
        let su = u.sqrt();
        let (wa, wb, wc) = (1.0 - su, su * (1.0 - v), su * v);
        [
            wa * a[0] + wb * b[0] + wc * c[0],
            wa * a[1] + wb * b[1] + wc * c[1],
            wa * a[2] + wb * b[2] + wc * c[2],
        ]
    });
    drop(draws);
    // Back to sample order: each sample's place in target order, then a parallel gather.
    let mut place = vec![0u32; n];
    for (j, &k) in by_target.iter().enumerate() {
        place[k as usize] = j as u32;
    }
    drop(by_target);
    Ok((parallel::map_range(n, |k| sorted[place[k] as usize]), total))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_by_area_and_deterministic() {
        // Two triangles: area 0.5 and 4.5 (ratio 1:9).
        let mesh = TriangleMesh {
            vertices: vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [0., 1., 0.],
                [10., 0., 0.],
                [13., 0., 0.],
                [10., 3., 0.],
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
        };
        let s = sample_surface(&mesh, 100_000, 7).unwrap();
        let small = s.iter().filter(|p| p[0] < 5.0).count() as f64 / 1e5;
        assert!((small - 0.1).abs() < 0.005, "{small}");
        assert!(
            s.iter()
                .all(|p| p[2] == 0.0 && (p[0] < 5.0 && p[0] + p[1] <= 1.0 + 1e-12 || p[0] >= 10.0))
        );
        assert_eq!(s, sample_surface(&mesh, 100_000, 7).unwrap());
        // The area of the sampling's running sum is the mesh's own, to the bit, on a mesh of
        // many uneven triangles.
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let uneven = TriangleMesh {
            vertices: (0..3000)
                .map(|_| [0; 3].map(|_: i32| rng.random::<f64>() * 10.0 - 5.0))
                .collect(),
            triangles: (0..1000).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
        };
        let (samples, area) = sample_surface_with_area(&uneven, 1000, 3).unwrap();
        assert_eq!(area.to_bits(), uneven.area().to_bits());
        assert_eq!(samples, sample_surface(&uneven, 1000, 3).unwrap());
        // The chunks drawn in parallel continue one stream: the samples of a per-sample loop.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let total = 0.5 + 4.5;
        let in_order: Vec<Point3> = (0..100_000)
            .map(|_| {
                let target = rng.random::<f64>() * total;
                let (u, v): (f64, f64) = (rng.random(), rng.random());
                let [a, b, c] = if target < 0.5 {
                    [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]
                } else {
                    [[10., 0., 0.], [13., 0., 0.], [10., 3., 0.]]
                };
                let su = u.sqrt();
                let (wa, wb, wc) = (1.0 - su, su * (1.0 - v), su * v);
                [0, 1, 2].map(|i| wa * a[i] + wb * b[i] + wc * c[i])
            })
            .collect();
        assert_eq!(s, in_order);
        assert_ne!(s, sample_surface(&mesh, 100_000, 8).unwrap());
    }
}
