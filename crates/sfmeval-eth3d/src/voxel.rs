//! The tool's volume normalisation: two voxel grids, the second shifted by half a voxel, and
//! each metric the mean over the grids' occupied cells of the cell's own fraction, so that a
//! densely reconstructed or densely scanned region counts as much as a sparse one of the same
//! volume. Cells are keyed as the tool's `CalcCellCoordinates` keys them (`float`
//! `p·(1/voxel) + shift`, floored through an `int` as x86 converts); the sums run over the cells
//! in key order (the tool's hash-map order differs, which moves only the last bits of a
//! `double` sum before the result is rounded to `float`).

use crate::accuracy::cvtt;

/// The two grids' shifts (in voxels).
pub const GRID_SHIFTS: [f32; 2] = [0.0, 0.5];

/// `float(1.0 / voxel_size)` as the tool computes it (in double, stored in float).
pub fn voxel_size_inv(voxel_size: f32) -> f32 {
    (1.0 / f64::from(voxel_size)) as f32
}

fn floor_coordinate(v: f32) -> i32 {
    let x = cvtt(v);
    if v - x as f32 != 0.0 && v < 0.0 {
        x.wrapping_sub(1)
    } else {
        x
    }
}

/// The tool's `CalcCellCoordinates`.
pub fn cell_of(p: &[f32; 3], voxel_size_inv: f32, shift: f32) -> [i32; 3] {
    p.map(|c| floor_coordinate(c * voxel_size_inv + shift))
}

/// For each occupied cell of the grid with `shift`, in key order, how many of its points are
/// of each class (`class(i) < classes` for point `i`): `visit(counts)` with
/// `counts.len() == classes`.
///
/// The cells are sorted as 64-bit keys when their coordinates' spans fit (each cell's key its
/// coordinates' offsets from the smallest, x above y above z, the point's class below them: one
/// sort of integers orders the cells and groups each cell's classes), and as coordinate
/// triples otherwise.
fn per_cell_classes(
    points: &[[f32; 3]],
    class: impl Fn(usize) -> u32 + Sync,
    classes: u32,
    voxel_size_inv: f32,
    shift: f32,
    visit: impl FnMut(&[usize]),
) {
    let cells: Vec<[i32; 3]> =
        sfmeval::parallel::map(points, &sfmeval::progress::NoProgress, |p| {
            cell_of(p, voxel_size_inv, shift)
        });
    if let Some(packing) = Packing::of(&cells, classes) {
        let mut keys: Vec<u64> =
            sfmeval::parallel::map_range(cells.len(), |i| packing.key(&cells[i], class(i)));
        drop(cells);
        sfmeval::parallel::sort_unstable(&mut keys);
        let class_mask = (1u64 << packing.class_bits) - 1;
        tally_runs(
            &keys,
            |key| (key >> packing.class_bits, (key & class_mask) as usize),
            classes,
            visit,
        );
    } else {
        let mut keyed: Vec<([i32; 3], u32)> =
            sfmeval::parallel::map_range(cells.len(), |i| (cells[i], class(i)));
        drop(cells);
        sfmeval::parallel::sort_unstable(&mut keyed);
        tally_runs(&keyed, |&(cell, c)| (cell, c as usize), classes, visit);
    }
}

/// Walks `sorted` (items grouped by cell), where `cell_class(item)` is an item's cell and
/// class, and calls `visit(counts)` for each run of one cell with its items' count per class.
fn tally_runs<T, C: PartialEq>(
    sorted: &[T],
    cell_class: impl Fn(&T) -> (C, usize),
    classes: u32,
    mut visit: impl FnMut(&[usize]),
) {
    let mut counts = vec![0usize; classes as usize];
    let mut current = None;
    for item in sorted {
        let (cell, class) = cell_class(item);
        if current.as_ref().is_some_and(|c| *c != cell) {
            visit(&counts);
            counts.iter_mut().for_each(|c| *c = 0);
        }
        current = Some(cell);
        counts[class] += 1;
    }
    if current.is_some() {
        visit(&counts);
    }
}

/// How cell coordinates and a class pack into one `u64` whose order is the coordinates' order,
/// then the class's.
#[derive(Debug, Clone, Copy)]
struct Packing {
    lo: [i32; 3],
    /// Bits of the y and z offsets.
    bits: [u32; 2],
    class_bits: u32,
}

impl Packing {
    /// The packing of `cells` with `classes` classes, if their spans fit in 64 bits.
    fn of(cells: &[[i32; 3]], classes: u32) -> Option<Packing> {
        let mut lo = [i32::MAX; 3];
        let mut hi = [i32::MIN; 3];
        for c in cells {
            for a in 0..3 {
                lo[a] = lo[a].min(c[a]);
                hi[a] = hi[a].max(c[a]);
            }
        }
        let bits_of = |span: u64| 64 - span.leading_zeros();
        let span = |a: usize| (i64::from(hi[a]) - i64::from(lo[a])).max(0) as u64;
        let class_bits = bits_of(u64::from(classes.saturating_sub(1)));
        let [bx, by, bz] = [0, 1, 2].map(|a| bits_of(span(a)));
        (bx + by + bz + class_bits <= 64).then_some(Packing {
            lo,
            bits: [by, bz],
            class_bits,
        })
    }

    fn key(&self, c: &[i32; 3], class: u32) -> u64 {
        let off = |a: usize| (i64::from(c[a]) - i64::from(self.lo[a])) as u64;
        let [by, bz] = self.bits;
        // (a shift by 64 when all spans are empty and there is one class: `checked_shl`)
        let shl = |v: u64, s: u32| v.checked_shl(s).unwrap_or(0);
        shl(shl(shl(off(0), by) | off(1), bz) | off(2), self.class_bits) | u64::from(class)
    }
}

/// The tool's accuracy per tolerance: per cell, `accurate / (accurate + inaccurate)` in
/// `float` over cells with any, summed in `double` over both grids and divided by their
/// number (0 when none). `first_accurate[i]` and `inaccurate[i]` are point `i`'s
/// classification; returns the results and, per tolerance, the cells that counted.
pub fn accuracy(
    points: &[[f32; 3]],
    first_accurate: &[u32],
    inaccurate: &[bool],
    tolerances: usize,
    voxel_size_inv: f32,
) -> (Vec<f32>, Vec<usize>) {
    let mut sum = vec![0f64; tolerances];
    let mut valid = vec![0usize; tolerances];
    let mut acc = vec![0usize; tolerances];
    let mut inacc = vec![0usize; tolerances];
    // A point's class: its first accurate tolerance (up to `tolerances`), twice, plus one when
    // inaccurate.
    let class = |i: usize| first_accurate[i].min(tolerances as u32) * 2 + u32::from(inaccurate[i]);
    let classes = 2 * tolerances as u32 + 2;
    for shift in GRID_SHIFTS {
        per_cell_classes(points, class, classes, voxel_size_inv, shift, |counts| {
            acc.iter_mut().for_each(|c| *c = 0);
            inacc.iter_mut().for_each(|c| *c = 0);
            for (k, &count) in counts.iter().enumerate().filter(|(_, c)| **c > 0) {
                let first = k / 2;
                for c in acc.iter_mut().skip(first) {
                    *c += count;
                }
                if k % 2 == 1 {
                    for c in inacc.iter_mut().take(first) {
                        *c += count;
                    }
                }
            }
            for t in 0..tolerances {
                let all = acc[t] + inacc[t];
                if all > 0 {
                    sum[t] += f64::from(acc[t] as f32 / all as f32);
                    valid[t] += 1;
                }
            }
        });
    }
    let results = (0..tolerances)
        .map(|t| {
            if valid[t] == 0 {
                0.0
            } else {
                (sum[t] / valid[t] as f64) as f32
            }
        })
        .collect();
    (results, valid)
}

/// The tool's completeness per tolerance: per cell, `complete / points` in `double`, summed
/// over both grids' cells and divided by their number, rounded to `float`. Returns the results
/// and the number of cells.
pub fn completeness(
    points: &[[f32; 3]],
    first_complete: &[u32],
    tolerances: usize,
    voxel_size_inv: f32,
) -> (Vec<f32>, usize) {
    let mut sum = vec![0f64; tolerances];
    let mut cell_count = 0usize;
    let mut complete = vec![0usize; tolerances];
    let class = |i: usize| first_complete[i].min(tolerances as u32);
    for shift in GRID_SHIFTS {
        per_cell_classes(
            points,
            class,
            tolerances as u32 + 1,
            voxel_size_inv,
            shift,
            |counts| {
                complete.iter_mut().for_each(|c| *c = 0);
                let mut all = 0usize;
                for (first, &count) in counts.iter().enumerate() {
                    for c in complete.iter_mut().skip(first) {
                        *c += count;
                    }
                    all += count;
                }
                let count = all as f64;
                for t in 0..tolerances {
                    sum[t] += complete[t] as f64 / count;
                }
                cell_count += 1;
            },
        );
    }
    let results = (0..tolerances)
        .map(|t| (sum[t] / cell_count as f64) as f32)
        .collect();
    (results, cell_count)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn cells_floor_as_the_tool_does() {
        let inv = voxel_size_inv(0.01);
        assert_eq!(cell_of(&[0.015, -0.015, -0.02], inv, 0.0), [1, -2, -2]);
        assert_eq!(cell_of(&[0.015, -0.015, 0.0], inv, 0.5), [2, -1, 0]);
    }

    /// The counts per cell in key order, from a map: what `per_cell_classes` must visit.
    fn counts_by_map(points: &[[f32; 3]], class: &[u32], classes: u32) -> Vec<Vec<usize>> {
        let mut map = std::collections::BTreeMap::<[i32; 3], Vec<usize>>::new();
        for (p, &c) in points.iter().zip(class) {
            map.entry(cell_of(p, voxel_size_inv(0.01), 0.5))
                .or_insert_with(|| vec![0; classes as usize])[c as usize] += 1;
        }
        map.into_values().collect()
    }

    #[test]
    fn cells_are_visited_in_key_order_with_their_class_counts() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x2545_f491_4f6c_dd1du64);
        let mut next = move || rng.random::<f64>();
        // A cloud whose cells pack into 64 bits, one whose spans do not (about 2^32 cells an
        // axis: the coordinate-triple sort), and one with a non-finite point.
        for (scale, n) in [(0.3f64, 5000), (2.0e7, 3000), (0.05, 2000)] {
            let mut points: Vec<[f32; 3]> = (0..n)
                .map(|_| [0, 1, 2].map(|_| ((next() - 0.5) * scale) as f32))
                .collect();
            if scale == 0.05 {
                points[7] = [f32::NAN, 0.0, 1.0];
                // Several points in one cell.
                for k in 0..50 {
                    points[100 + k] = [0.001, 0.002, 0.003];
                }
            }
            let classes = 7;
            let class: Vec<u32> = (0..n).map(|_| (next() * 7.0) as u32).collect();
            let mut visited = Vec::new();
            per_cell_classes(
                &points,
                |i| class[i],
                classes,
                voxel_size_inv(0.01),
                0.5,
                |counts| visited.push(counts.to_vec()),
            );
            assert_eq!(
                visited,
                counts_by_map(&points, &class, classes),
                "scale {scale}"
            );
        }
        let packs = |cells: &[[i32; 3]]| Packing::of(cells, 7).is_some();
        assert!(packs(&[[-5, 0, 3], [9, 2, -1]]));
        assert!(!packs(&[
            [i32::MIN, i32::MIN, i32::MIN],
            [i32::MAX, i32::MAX, i32::MAX]
        ]));
    }

    #[test]
    fn means_over_both_grids() {
        // Two points in one cell of both grids: one accurate, one inaccurate → 0.5.
        let p = [[0.011f32, 0.011, 0.011], [0.012, 0.012, 0.012]];
        let (a, valid) = accuracy(&p, &[0, 1], &[false, true], 1, voxel_size_inv(0.01));
        assert_eq!((a, valid), (vec![0.5], vec![2]));
        // An unobserved point counts nowhere.
        let (a, valid) = accuracy(&p, &[1, 1], &[false, false], 1, voxel_size_inv(0.01));
        assert_eq!((a, valid), (vec![0.0], vec![0]));
        let (c, cells) = completeness(&p, &[0, 1], 1, voxel_size_inv(0.01));
        assert_eq!((c, cells), (vec![0.5], 2));
    }
}
