//! Completeness: each scan point (in the global frame) is complete for a tolerance when a
//! reconstruction point lies within it, as the tool's `ComputeCompleteness` decides with PCL's
//! FLANN k-d tree: the squared distance summed as FLANN's `L2_Simple<float>` sums it
//! (`(d₀² + d₁²) + d₂²` in `float`), found by the radius search when strictly below the largest
//! tolerance squared, and complete for a smaller tolerance when at most its square.
//!
//! The search runs on the core's exact [`KdCloud`] in double precision. Where the nearest
//! distance lies within rounding of a tolerance, the few nearest points are measured again in
//! the tool's `float` arithmetic, and the smallest of those is the tool's nearest distance;
//! elsewhere the double distance falls on the same side of every tolerance as the float one.

use sfmeval::distance::{KdCloud, NO_POINT, NeighbourList};
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
    // The thresholds the tool compares the float distance with: the largest (strictly below)
    // and every other (at most).
    let thresholds: Vec<f64> = tolerances2.iter().map(|&t| f64::from(t)).collect();
    Ok(sfmeval::parallel::map_points_with_state(
        &scan_f64,
        &sfmeval::progress::NoProgress,
        |list: &mut NeighbourList, q| {
            if !q.iter().all(|c| c.is_finite()) {
                return n as u32;
            }
            // The nearest point in double, through the neighbour list the queries before this
            // one made (neighbours in the visiting order): exactly the tree's answer.
            let (d2, slot) = list.nearest_below(&tree, *q, (radius2, NO_POINT), radius2, None);
            if slot == NO_POINT {
                return n as u32;
            }
            // The float distance of each candidate lies within NEAR_THRESHOLD of its double one,
            // so the float nearest does too: unless a threshold lies that close, it falls on
            // the same side of every threshold as the double nearest.
            let near_threshold = thresholds
                .iter()
                .any(|&t| (d2 - t).abs() <= NEAR_THRESHOLD * t.max(d2))
                // (where the float square may underflow)
                || d2 < TINY2;
            let best = if near_threshold {
                float_nearest2(&tree, q, radius2)
            } else {
                d2
            };
            first_tolerance(best, &thresholds)
        },
    ))
}

/// Relative error bound, with a wide margin, of the float squared distance against the double
/// one: three float subtractions, squares and two additions are within 5 units in the last place
/// (3e-7).
const NEAR_THRESHOLD: f64 = 1e-5;

/// Squared distances below which the float squares may lose bits to underflow.
const TINY2: f64 = 1e-30;

/// The tool's squared nearest distance to `q` in float: the `CANDIDATES` nearest in double
/// measured again as FLANN measures them (infinite when none is within `radius2`).
fn float_nearest2(tree: &KdCloud, q: &Point3, radius2: f64) -> f64 {
    let mut found = [(0.0f64, 0u32); CANDIDATES];
    let (count, _) = tree.nearest_k_below(*q, radius2, &mut found);
    let qf = q.map(|c| c as f32);
    let mut best = f32::INFINITY;
    for &(_, slot) in &found[..count] {
        let p = tree.point(slot as usize).map(|c| c as f32);
        best = best.min(flann_distance2(&qf, &p));
    }
    f64::from(best)
}

/// The tool's loop on a squared distance: complete for the largest tolerance when strictly
/// closer (the radius search), then for each smaller one downwards while `d² ≤ tolerance²`.
fn first_tolerance(best2: f64, thresholds: &[f64]) -> u32 {
    let n = thresholds.len();
    if !(best2 < thresholds[n - 1]) {
        return n as u32;
    }
    (0..n - 1)
        .rev()
        .find(|&t| thresholds[t] < best2)
        .map_or(0, |t| t as u32 + 1)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use rand::{Rng as _, SeedableRng as _};
    use rand_chacha::ChaCha8Rng;

    /// The tool's rule by brute force: the float nearest over every point, then its loop.
    fn brute_force(scan: &[[f32; 3]], recon: &[[f32; 3]], tolerances2: &[f32]) -> Vec<u32> {
        let thresholds: Vec<f64> = tolerances2.iter().map(|&t| f64::from(t)).collect();
        scan.iter()
            .map(|q| {
                let best = recon
                    .iter()
                    .map(|p| flann_distance2(q, p))
                    .fold(f32::INFINITY, f32::min);
                first_tolerance(f64::from(best), &thresholds)
            })
            .collect()
    }

    #[test]
    fn equals_the_float_rule_also_at_the_tolerances() {
        let mut rng = ChaCha8Rng::seed_from_u64(0x9e37_79b9_7f4a_7c15u64);
        let mut next = move || rng.random::<f32>();
        let tolerances = [0.01f32, 0.02, 0.05, 0.1];
        let tolerances2: Vec<f32> = tolerances.iter().map(|t| t * t).collect();
        let recon: Vec<[f32; 3]> = (0..300)
            .map(|_| [next() * 0.5, next() * 0.5, next() * 0.05])
            .collect();
        let mut scan: Vec<[f32; 3]> = (0..3000)
            .map(|_| {
                [
                    next() * 0.6 - 0.05,
                    next() * 0.6 - 0.05,
                    next() * 0.2 - 0.07,
                ]
            })
            .collect();
        // Scan points at a tolerance from a reconstruction point, within rounding (along an
        // axis and along a diagonal), on a reconstruction point, and not finite.
        for (k, p) in recon.iter().enumerate().take(100) {
            let t = tolerances[k % tolerances.len()];
            let d = t / 3f32.sqrt();
            scan.push([p[0] + t, p[1], p[2]]);
            scan.push([p[0], p[1] - t, p[2]]);
            scan.push([p[0] + d, p[1] + d, p[2] + d]);
            scan.push([p[0] + f32::EPSILON * t, p[1], p[2] + t]);
            scan.push(*p);
        }
        scan.push([f32::NAN, 0.0, 0.0]);
        let got = first_complete(&scan, &recon, &tolerances2).unwrap();
        assert_eq!(got, brute_force(&scan, &recon, &tolerances2));
        let n = tolerances.len() as u32;
        // Every class occurs, so each branch of the rule was taken.
        for class in 0..=n {
            assert!(got.contains(&class), "no scan point of class {class}");
        }
        assert_eq!(
            first_complete(&scan, &[], &tolerances2).unwrap(),
            vec![n; scan.len()]
        );
    }
}
