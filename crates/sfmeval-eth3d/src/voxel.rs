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

/// The points' order grouped by cell of the grid with `shift` (cells in key order) and the
/// bounds of each cell's run in it.
fn grouped(points: &[[f32; 3]], voxel_size_inv: f32, shift: f32) -> (Vec<u32>, Vec<usize>) {
    let mut keyed: Vec<([i32; 3], u32)> = sfmeval::parallel::map_range(points.len(), |i| {
        (cell_of(&points[i], voxel_size_inv, shift), i as u32)
    });
    sfmeval::parallel::sort_unstable(&mut keyed);
    let mut bounds = vec![0usize];
    for k in 1..keyed.len() {
        if keyed[k].0 != keyed[k - 1].0 {
            bounds.push(k);
        }
    }
    bounds.push(keyed.len());
    (keyed.into_iter().map(|(_, i)| i).collect(), bounds)
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
    for shift in GRID_SHIFTS {
        let (order, bounds) = grouped(points, voxel_size_inv, shift);
        for w in bounds.windows(2) {
            acc.iter_mut().for_each(|c| *c = 0);
            inacc.iter_mut().for_each(|c| *c = 0);
            for &i in &order[w[0]..w[1]] {
                let first = first_accurate[i as usize] as usize;
                for c in acc.iter_mut().skip(first) {
                    *c += 1;
                }
                if inaccurate[i as usize] {
                    for c in inacc.iter_mut().take(first.min(tolerances)) {
                        *c += 1;
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
        }
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
    for shift in GRID_SHIFTS {
        let (order, bounds) = grouped(points, voxel_size_inv, shift);
        for w in bounds.windows(2) {
            complete.iter_mut().for_each(|c| *c = 0);
            for &i in &order[w[0]..w[1]] {
                for c in complete
                    .iter_mut()
                    .skip(first_complete[i as usize] as usize)
                {
                    *c += 1;
                }
            }
            let count = (w[1] - w[0]) as f64;
            for t in 0..tolerances {
                sum[t] += complete[t] as f64 / count;
            }
            cell_count += 1;
        }
    }
    let results = (0..tolerances)
        .map(|t| (sum[t] / cell_count as f64) as f32)
        .collect();
    (results, cell_count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_floor_as_the_tool_does() {
        let inv = voxel_size_inv(0.01);
        assert_eq!(cell_of(&[0.015, -0.015, -0.02], inv, 0.0), [1, -2, -2]);
        assert_eq!(cell_of(&[0.015, -0.015, 0.0], inv, 0.5), [2, -1, 0]);
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
