//! Completeness: each scan point (in the global frame) is complete for a tolerance when a
//! reconstruction point lies within it, as the tool's `ComputeCompleteness` decides with PCL's
//! FLANN k-d tree: the squared distance summed as FLANN's `L2_Simple<float>` sums it
//! (`(d₀² + d₁²) + d₂²` in `float`), found by the radius search when strictly below the largest
//! tolerance squared, and complete for a smaller tolerance when at most its square.
//!
//! The search runs on the core's exact [`KdCloud`] in double precision; the few nearest
//! points it returns are measured again in the tool's `float` arithmetic, and the smallest of
//! those is the tool's nearest distance.

use sfmeval::distance::KdCloud;
use sfmeval::geometry::Point3;

/// Candidates measured again in `float` (points within rounding of the nearest).
const CANDIDATES: usize = 4;

fn flann_distance2(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

/// For every scan point, the smallest tolerance index for which it is complete
/// (`tolerances2.len()` when none): `scan` the global scan points, `reconstruction` the
/// reconstruction's points (non-finite ones are never nearest, as in PCL's tree).
pub fn first_complete(
    scan: &[[f32; 3]],
    reconstruction: &[[f32; 3]],
    tolerances2: &[f32],
) -> sfmeval::Result<Vec<u32>> {
    let n = tolerances2.len();
    let finite: Vec<[f32; 3]> = reconstruction
        .iter()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .copied()
        .collect();
    if finite.is_empty() || n == 0 {
        return Ok(vec![n as u32; scan.len()]);
    }
    let as_f64: Vec<Point3> = finite.iter().map(|p| p.map(f64::from)).collect();
    let tree = KdCloud::new(&as_f64)?;
    drop(as_f64);
    let max2 = tolerances2[n - 1];
    // A little wider than the largest tolerance, so that no point the float test keeps is lost
    // to the double search's rounding.
    let radius2 = f64::from(max2) * (1.0 + 1e-5) + 1e-30;
    let scan_f64: Vec<Point3> = scan.iter().map(|p| p.map(f64::from)).collect();
    Ok(sfmeval::parallel::map_points(
        &scan_f64,
        &sfmeval::progress::NoProgress,
        |q| {
            if !q.iter().all(|c| c.is_finite()) {
                return n as u32;
            }
            let mut found = [(0.0f64, 0u32); CANDIDATES];
            let (count, _) = tree.nearest_k_below(*q, radius2, &mut found);
            let qf = q.map(|c| c as f32);
            let mut best = f32::INFINITY;
            for &(_, slot) in &found[..count] {
                let p = tree.point(slot as usize).map(|c| c as f32);
                best = best.min(flann_distance2(&qf, &p));
            }
            // The tool's loop: complete for the largest tolerance when the radius search
            // found a point (strictly closer), then downwards while d² ≤ tolerance².
            if !(best < max2) {
                return n as u32;
            }
            let mut first = 0u32;
            for t in (0..n - 1).rev() {
                if tolerances2[t] < best {
                    first = t as u32 + 1;
                    break;
                }
            }
            first
        },
    ))
}
