//! Accuracy: each reconstruction point classified against each scan's laser beams as the tool's
//! `ComputeAccuracy` does. A scan point's beam is the ray from the scanner (the scan frame's
//! origin) through it, `beam_start_radius + r·tan(divergence)` wide at distance `r`. A
//! reconstruction point inside a beam is accurate for every tolerance at least its distance to
//! that beam's scan point; otherwise, if it lies in front of a scan point whose beam holds it, it
//! is inaccurate (the laser saw through it); otherwise unobserved. Accurate given any scan wins,
//! then inaccurate given any scan.
//!
//! The beams are found as the tool finds them: the scan points sorted into a 2048 × 1024 grid
//! over azimuth and inclination, and the cells of the box of angles the point's beam radius
//! subtends searched, in the tool's `float` arithmetic (Eigen's order of sums, `atan2f`,
//! `acosf`, `asinf` from the `libm` crate), with its integer conversions.

use crate::scene::{Eth3dScene, ScanFromGlobal};

const CELLS_INCLINATION: i32 = 1024;
const CELLS_AZIMUTH: i32 = 2 * CELLS_INCLINATION;
const PI_F32: f32 = std::f64::consts::PI as f32;

/// `static_cast<int>(float)` as x86-64 computes it (`cvttss2si`): truncation, and `INT_MIN` for
/// NaN and values out of range.
pub(crate) fn cvtt(v: f32) -> i32 {
    if !(-2_147_483_648.0..2_147_483_648.0).contains(&v) {
        i32::MIN
    } else {
        v as i32
    }
}

/// C++'s `mod` of the tool: the remainder made non-negative.
fn wrap(k: i32, n: i32) -> i32 {
    let r = k.wrapping_rem(n);
    if r < 0 { r + n } else { r }
}

fn dot(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    a[0] * b[0] + (a[1] * b[1] + a[2] * b[2])
}

fn squared_norm(a: &[f32; 3]) -> f32 {
    dot(a, a)
}

/// A scan point in spherical coordinates with its unit direction.
#[derive(Debug, Clone, Copy)]
struct SphericalPoint {
    point: [f32; 3],
    direction: [f32; 3],
    radius: f32,
    inclination: f32,
}

/// Radius, azimuth and inclination as the tool's `SphericalPoint` computes them.
fn spherical(p: &[f32; 3]) -> (f32, f32, f32) {
    let radius = squared_norm(p).sqrt();
    let azimuth = libm::atan2f(p[1], p[0]);
    let inclination = libm::acosf(p[2] / radius);
    (radius, azimuth, inclination)
}

/// The azimuth × inclination grid of one scan's points.
pub struct SphericalGrid {
    extent_azimuth: f32,
    extent_inclination: f32,
    /// `starts[c]..starts[c + 1]` are cell `c`'s points in `points`.
    starts: Vec<u32>,
    points: Vec<SphericalPoint>,
}

impl SphericalGrid {
    /// Sorts a scan's points (in its frame) into the grid.
    pub fn new(points: &[[f32; 3]]) -> SphericalGrid {
        let mut grid = SphericalGrid {
            extent_azimuth: (2.0 * std::f64::consts::PI / f64::from(CELLS_AZIMUTH)) as f32,
            extent_inclination: (std::f64::consts::PI / f64::from(CELLS_INCLINATION)) as f32,
            starts: Vec::new(),
            points: Vec::new(),
        };
        let cells = (CELLS_AZIMUTH * CELLS_INCLINATION) as usize;
        let located: Vec<(u32, SphericalPoint)> =
            sfmeval::parallel::map(points, &sfmeval::progress::NoProgress, |p| {
                let (radius, azimuth, inclination) = spherical(p);
                let n = squared_norm(p);
                let direction = if n > 0.0 {
                    let s = n.sqrt();
                    [p[0] / s, p[1] / s, p[2] / s]
                } else {
                    *p
                };
                let (a, i) = grid.cell_coordinates(azimuth, inclination);
                let cell = (wrap(a, CELLS_AZIMUTH) + CELLS_AZIMUTH * i) as u32;
                (
                    cell,
                    SphericalPoint {
                        point: *p,
                        direction,
                        radius,
                        inclination,
                    },
                )
            });
        // Cells in order, each cell's points by inclination (non-negative, or NaN last: the
        // bits order them), for the window of `classify`: a counting sort by cell (which keeps
        // the points' order in a cell), then each cell's few points sorted.
        let mut starts = vec![0u32; cells + 1];
        for (c, _) in &located {
            starts[*c as usize + 1] += 1;
        }
        for c in 0..cells {
            starts[c + 1] += starts[c];
        }
        let mut next = starts.clone();
        let mut order = vec![0u32; located.len()];
        for (k, (c, _)) in located.iter().enumerate() {
            let slot = &mut next[*c as usize];
            order[*slot as usize] = k as u32;
            *slot += 1;
        }
        drop(next);
        for w in starts.windows(2) {
            let cell = &mut order[w[0] as usize..w[1] as usize];
            if cell.len() > 1 {
                cell.sort_unstable_by_key(|&k| (located[k as usize].1.inclination.to_bits(), k));
            }
        }
        let sorted: Vec<SphericalPoint> =
            sfmeval::parallel::map_range(order.len(), |j| located[order[j] as usize].1);
        grid.starts = starts;
        grid.points = sorted;
        grid
    }

    /// The tool's `CellCoordinatesWithoutWrap`: the azimuth cell (not wrapped) and the clamped
    /// inclination cell (its inclination index goes through an `int`, as the tool's does).
    fn cell_coordinates(&self, azimuth: f32, inclination: f32) -> (i32, i32) {
        let fa = azimuth / self.extent_azimuth;
        let a = cvtt(fa).wrapping_add(if fa < 0.0 { -1 } else { 0 });
        let fi = cvtt(inclination / self.extent_inclination);
        let i = fi
            .wrapping_add(if fi < 0 { -1 } else { 0 })
            .clamp(0, CELLS_INCLINATION - 1);
        (a, i)
    }

    fn cell(&self, c: i32) -> &[SphericalPoint] {
        let c = c as usize;
        &self.points[self.starts[c] as usize..self.starts[c + 1] as usize]
    }
}

/// One point's classification given one scan: the first (smallest) tolerance index for which
/// it is accurate (`tolerances² .len()` for none), and whether it lies in front of a scan
/// point whose beam holds it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Classification {
    /// First accurate tolerance index.
    pub first_accurate: u32,
    /// In front of a scan point, inside its beam.
    pub inaccurate: bool,
}

/// The beam model's two parameters.
#[derive(Debug, Clone, Copy)]
pub struct Beam {
    /// Beam radius at the scanner (m).
    pub start_radius: f32,
    /// `tanf` of the divergence half-angle.
    pub tan_divergence: f32,
}

/// The tool's `ClassifyPoint` of `q` (in the scan's frame).
fn classify(
    q: &[f32; 3],
    tolerances2: &[f32],
    beam: &Beam,
    grid: &SphericalGrid,
) -> Classification {
    let n = tolerances2.len() as u32;
    let mut out = Classification {
        first_accurate: n,
        inaccurate: false,
    };
    let (radius, azimuth, inclination) = spherical(q);
    let radius_horizontal = (q[0] * q[0] + q[1] * q[1]).sqrt();
    let beam_radius = beam.start_radius + radius * beam.tan_divergence;
    let beam_radius2 = beam_radius * beam_radius;
    let full = beam_radius >= radius;
    let (vertical, horizontal) = if full {
        (PI_F32, PI_F32)
    } else {
        let v = libm::asinf(beam_radius / radius);
        let h = if beam_radius >= radius_horizontal {
            PI_F32
        } else {
            libm::asinf(beam_radius / radius_horizontal)
        };
        (v, h)
    };
    // The scan points whose beam can hold q are within `vertical` of its direction, so within
    // `vertical` of its inclination: only that window of each cell (sorted by inclination) is
    // looked at. The window is widened far beyond float rounding (1e-5 rad, 0.1 %), and used
    // only away from the poles, where acos is well conditioned; a point outside it is one the
    // tool rejects too.
    const POLE: f32 = 0.05;
    let window = (!full && inclination - vertical > POLE && inclination + vertical < PI_F32 - POLE)
        .then(|| {
            let w = vertical * 1.001 + 1e-5;
            (inclination - w, inclination + w)
        });
    let (min_a, min_i) = grid.cell_coordinates(azimuth - horizontal, inclination - vertical);
    let (max_a, max_i) = grid.cell_coordinates(azimuth + horizontal, inclination + vertical);
    // The tool's SphericalPointGridIterator, step for step.
    let mut a = min_a.wrapping_sub(1);
    let mut i = min_i;
    loop {
        a = a.wrapping_add(1);
        if a > max_a {
            a = min_a;
            i += 1;
            if i > max_i {
                break;
            }
        }
        let cell = wrap(a, CELLS_AZIMUTH) + CELLS_AZIMUTH * i;
        let mut points = grid.cell(cell);
        if let Some((lo, hi)) = window {
            let a = points.partition_point(|s| s.inclination < lo);
            let b = points.partition_point(|s| s.inclination <= hi);
            points = &points[a..b.max(a)];
        }
        for s in points {
            let along = dot(&s.direction, q);
            if along < 0.0 {
                continue;
            }
            let closest = s.direction.map(|d| along * d);
            let off = [q[0] - closest[0], q[1] - closest[1], q[2] - closest[2]];
            if squared_norm(&off) <= beam_radius2 {
                let d = [s.point[0] - q[0], s.point[1] - q[1], s.point[2] - q[2]];
                let d2 = squared_norm(&d);
                for (t, &tol2) in tolerances2.iter().enumerate() {
                    if t as u32 >= out.first_accurate {
                        break;
                    }
                    if d2 <= tol2 {
                        out.first_accurate = t as u32;
                        if t == 0 {
                            return out;
                        }
                        break;
                    }
                }
                if along < s.radius {
                    out.inaccurate = true;
                }
            }
        }
    }
    out
}

/// Every reconstruction point's classification over all scans (the tool's aggregate: the
/// smallest accurate tolerance of any scan, inaccurate if any scan says so). A non-finite point
/// is unobserved (in the tool its spherical coordinates are NaN and no beam holds it).
pub fn classify_points(
    scene: &Eth3dScene,
    grids: &[SphericalGrid],
    reconstruction: &[[f32; 3]],
    tolerances2: &[f32],
    beam: &Beam,
) -> Vec<Classification> {
    let transforms: Vec<ScanFromGlobal> = scene
        .scans
        .iter()
        .map(|s| ScanFromGlobal::new(&s.entry.global_from_scan))
        .collect();
    let n = tolerances2.len() as u32;
    // Visited in Morton order (neighbours in space one after the other keep the scans' cells in
    // cache; a reconstruction file's order is often shuffled), results in input order.
    let as_f64: Vec<sfmeval::geometry::Point3> =
        reconstruction.iter().map(|p| p.map(f64::from)).collect();
    sfmeval::parallel::map_points(&as_f64, &sfmeval::progress::NoProgress, |q| {
        let p = &q.map(|c| c as f32);
        let mut out = Classification {
            first_accurate: n,
            inaccurate: false,
        };
        if !p.iter().all(|c| c.is_finite()) {
            return out;
        }
        for (t, grid) in transforms.iter().zip(grids) {
            let c = classify(&t.apply(p), tolerances2, beam, grid);
            out.inaccurate |= c.inaccurate;
            if c.first_accurate < out.first_accurate {
                out.first_accurate = c.first_accurate;
                if out.first_accurate == 0 {
                    break;
                }
            }
        }
        out
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_conversions_are_x86s() {
        assert_eq!(cvtt(-1.5), -1);
        assert_eq!(cvtt(2.9), 2);
        assert_eq!(cvtt(f32::NAN), i32::MIN);
        assert_eq!(cvtt(3e9), i32::MIN);
        assert_eq!(wrap(-2, 10), 8);
        assert_eq!(wrap(-10, 10), 0);
        assert_eq!(wrap(i32::MIN, 2048), 0);
    }

    #[test]
    fn a_point_on_a_beam_is_accurate_in_front_inaccurate_beside_unobserved() {
        // One scan point 10 m along x; tolerances 1 cm and 10 cm.
        let grid = SphericalGrid::new(&[[10.0, 0.0, 0.0]]);
        let beam = Beam {
            start_radius: 0.5 * 0.00225,
            tan_divergence: libm::tanf((std::f64::consts::PI / 180.0) as f32 * 0.011),
        };
        let tol2 = [0.01f32 * 0.01, 0.1 * 0.1];
        let on = classify(&[10.005, 0.0, 0.0], &tol2, &beam, &grid);
        assert_eq!((on.first_accurate, on.inaccurate), (0, false));
        let near = classify(&[9.95, 0.0, 0.0], &tol2, &beam, &grid);
        assert_eq!((near.first_accurate, near.inaccurate), (1, true));
        let front = classify(&[5.0, 0.0, 0.0], &tol2, &beam, &grid);
        assert_eq!((front.first_accurate, front.inaccurate), (2, true));
        let behind = classify(&[12.0, 0.0, 0.0], &tol2, &beam, &grid);
        assert_eq!((behind.first_accurate, behind.inaccurate), (2, false));
        let beside = classify(&[10.0, 0.5, 0.0], &tol2, &beam, &grid);
        assert_eq!((beside.first_accurate, beside.inaccurate), (2, false));
    }
}
