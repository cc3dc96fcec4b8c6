//! The evaluation, step for step as `eval.py` of DTUeval-python runs it:
//!
//! 1. a mesh is sampled ([`sample_mesh`]): its vertices, then a grid of points in each
//!    triangle of non-zero area whose spacing follows the down-sampling density;
//! 2. the points are shuffled (the port shuffles unseeded; here a seeded Fisher–Yates, or the
//!    file's order with [`Shuffle::None`]) and down-sampled by [`radius_filter`]: in that
//!    order, a point is kept when no point kept before it lies within the density (0.2 mm);
//! 3. points outside the bounding box `BB` widened by the patch size (60 mm below, 120 mm
//!    above: the port's `BB[1:]+patch*2`, in `float32` as it casts `BB`) are dropped, and of
//!    the rest those whose observation-mask cell (rounded half to even) is observed are
//!    measured;
//! 4. accuracy: each observed point's distance to its nearest STL point, the mean over those
//!    below `max_dist` (20 mm); completeness: each STL point above the ground plane, its
//!    distance to the nearest reconstruction point inside the widened box, the mean over those
//!    below `max_dist`; overall: the mean of the two.
//!
//! Nearest distances are exact (`KdCloud`, the squared sum summed x, y, z as scikit-learn's
//! k-d tree does), the radius test is scikit-learn's leaf test `d² ≤ r²`, and the means are
//! pairwise sums as numpy's. Where a result can differ from the port at all: points within
//! rounding of the radius, of a mask cell's half-way point or of the ground plane, and the
//! shuffle (the port's is unseeded, so two of its runs differ too).

use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use sfmeval::distance::{KdCloud, NO_POINT, NeighbourList};
use sfmeval::geometry::Point3;
use sfmeval::progress::{NoProgress, Progress, Stage};
use sfmeval::{Error, Result, parallel};

use crate::radius_filter::radius_filter;
use crate::scan::DtuScan;

/// The evaluator's defaults.
pub const DOWNSAMPLE_DENSITY: f64 = 0.2;
/// The patch size the bounding box is widened by (mm).
pub const PATCH_SIZE: f64 = 60.0;
/// The distance cap (mm).
pub const MAX_DIST: f64 = 20.0;
/// The distance at which the error clouds turn fully red (mm).
pub const VISUALIZE_THRESHOLD: f64 = 10.0;

/// The order points are down-sampled in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shuffle {
    /// A Fisher–Yates shuffle drawn from ChaCha8 seeded with this seed (the evaluator shuffles
    /// at random).
    Seeded(u64),
    /// The input's order: the file's points, or a mesh's vertices then its samples.
    None,
}

/// The evaluator's options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DtuOptions {
    /// `downsample_density` (mm).
    pub downsample_density: f64,
    /// `patch_size` (mm).
    pub patch_size: f64,
    /// `max_dist` (mm).
    pub max_dist: f64,
    /// `visualize_threshold` (mm).
    pub visualize_threshold: f64,
    /// The down-sampling order.
    pub shuffle: Shuffle,
}

impl Default for DtuOptions {
    fn default() -> Self {
        DtuOptions {
            downsample_density: DOWNSAMPLE_DENSITY,
            patch_size: PATCH_SIZE,
            max_dist: MAX_DIST,
            visualize_threshold: VISUALIZE_THRESHOLD,
            shuffle: Shuffle::Seeded(0),
        }
    }
}

impl DtuOptions {
    fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("downsample density", self.downsample_density),
            ("patch size", self.patch_size),
            ("max_dist", self.max_dist),
            ("visualize threshold", self.visualize_threshold),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::InvalidOption(format!(
                    "the {name} must be a positive number, got {v}"
                )));
            }
        }
        Ok(())
    }
}

/// The reconstruction: a point cloud, or a mesh the evaluator samples.
#[derive(Debug, Clone, PartialEq)]
pub enum DtuInput {
    /// Points (the port's `--mode pcd`).
    Cloud(Vec<Point3>),
    /// A triangle mesh (`--mode mesh`).
    Mesh {
        /// Vertices.
        vertices: Vec<Point3>,
        /// Triangles.
        triangles: Vec<[u32; 3]>,
    },
}

/// The samples of a mesh as the port takes them: every vertex, then for each triangle of
/// non-zero area (in order) the points `v0 + e1 (i + ½)/n1 + e2 (j + ½)/n2` with
/// `(i + ½)/n1 + (j + ½)/n2 < 1`, `i` outer, where `n = ⌊|e| / t⌋` and
/// `t = density √(|e1| |e2| / |e1 × e2|)`, in the port's floating-point operations.
pub fn sample_mesh(
    vertices: &[Point3],
    triangles: &[[u32; 3]],
    density: f64,
) -> Result<Vec<Point3>> {
    let n_vertices = vertices.len();
    for (k, t) in triangles.iter().enumerate() {
        if t.iter().any(|&v| v as usize >= n_vertices) {
            return Err(Error::InvalidContent(format!(
                "triangle {k} names vertex {} of {n_vertices}",
                t.iter().max().copied().unwrap_or(0)
            )));
        }
    }
    // Per triangle: the edge vectors, the counts and the corner, or None for zero area.
    let plans: Vec<Option<Plan>> = parallel::map(triangles, &NoProgress, |t| {
        let p0 = vertices[t[0] as usize];
        let p1 = vertices[t[1] as usize];
        let p2 = vertices[t[2] as usize];
        let v1 = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
        let v2 = [p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]];
        let l1 = norm(v1);
        let l2 = norm(v2);
        // numpy's cross: each component a product minus a product, rounded in turn.
        let c = [
            v1[1] * v2[2] - v1[2] * v2[1],
            v1[2] * v2[0] - v1[0] * v2[2],
            v1[0] * v2[1] - v1[1] * v2[0],
        ];
        let area2 = norm(c);
        if !(area2 > 0.0) {
            return None;
        }
        let thr = density * (l1 * l2 / area2).sqrt();
        let n1 = (l1 / thr).floor();
        let n2 = (l2 / thr).floor();
        Some((v1, v2, p0, n1, n2))
    });
    // The samples must be numbered in u32: bound their count before allocating.
    let mut bound: f64 = n_vertices as f64;
    for (_, _, _, n1, n2) in plans.iter().flatten() {
        bound += (n1 + 1.0) * (n2 + 1.0);
    }
    let limit = u32::MAX as f64;
    if !(bound <= limit) {
        // The exact count is about half the bound; count before refusing.
        let exact: f64 = plans
            .iter()
            .flatten()
            .map(|&(_, _, _, n1, n2)| triangle_count(n1, n2) as f64)
            .sum::<f64>()
            + n_vertices as f64;
        if !(exact <= limit) {
            return Err(Error::LimitExceeded {
                format: "mesh",
                what: format!("points sampled at a density of {density}"),
                count: exact as u64,
                limit: u32::MAX as u64,
                hint: "",
            });
        }
    }
    let chunks: Vec<&[Option<Plan>]> = plans.chunks(4096).collect();
    let pieces: Vec<Vec<Point3>> = parallel::map(&chunks, &NoProgress, |chunk| {
        let mut out = Vec::new();
        for (v1, v2, p0, n1, n2) in chunk.iter().flatten() {
            sample_triangle(*v1, *v2, *p0, *n1, *n2, &mut out);
        }
        out
    });
    let total: usize = n_vertices + pieces.iter().map(Vec::len).sum::<usize>();
    let mut points = Vec::with_capacity(total);
    points.extend_from_slice(vertices);
    for p in pieces {
        points.extend_from_slice(&p);
    }
    Ok(points)
}

/// A triangle's edge vectors, corner and sample counts.
type Plan = (Point3, Point3, Point3, f64, f64);

fn norm(v: Point3) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// `sample_single_tri`: `c = mgrid[:n1+1, :n2+1] + 0.5`, divided by `max(n, 1e-7)`, the cells
/// with `c0 + c1 < 1` in C order, `q = v1 c0 + v2 c1 + v0`.
fn sample_triangle(v1: Point3, v2: Point3, p0: Point3, n1: f64, n2: f64, out: &mut Vec<Point3>) {
    let d1 = n1.max(1e-7);
    let d2 = n2.max(1e-7);
    let mut i = 0.0;
    while i <= n1 {
        let k0 = (i + 0.5) / d1;
        if !(k0 + 0.5 / d2 < 1.0) {
            break;
        }
        let mut j = 0.0;
        while j <= n2 {
            let k1 = (j + 0.5) / d2;
            if !(k0 + k1 < 1.0) {
                break;
            }
            out.push([
                v1[0] * k0 + v2[0] * k1 + p0[0],
                v1[1] * k0 + v2[1] * k1 + p0[1],
                v1[2] * k0 + v2[2] * k1 + p0[2],
            ]);
            j += 1.0;
        }
        i += 1.0;
    }
}

fn triangle_count(n1: f64, n2: f64) -> u64 {
    let mut out = 0u64;
    let d1 = n1.max(1e-7);
    let d2 = n2.max(1e-7);
    let mut i = 0.0;
    while i <= n1 {
        let k0 = (i + 0.5) / d1;
        // The largest j with k0 + (j + ½)/d2 < 1, found by stepping back from the estimate.
        let mut j = ((1.0 - k0) * d2 - 0.5).floor().min(n2);
        while j >= 0.0 && !(k0 + (j + 0.5) / d2 < 1.0) {
            j -= 1.0;
        }
        while j + 1.0 <= n2 && k0 + (j + 1.5) / d2 < 1.0 {
            j += 1.0;
        }
        if j < 0.0 {
            break;
        }
        out += j as u64 + 1;
        i += 1.0;
    }
    out
}

/// Shuffles `points` in place as [`Shuffle`] says.
pub fn shuffle(points: &mut [Point3], order: Shuffle) {
    if let Shuffle::Seeded(seed) = order {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for i in (1..points.len()).rev() {
            let j = rng.random_range(0..=i);
            points.swap(i, j);
        }
    }
}

/// numpy's pairwise sum (blocks of 8 partial sums up to 128 values, halves above), so means
/// agree with `ndarray.mean` to the last bits in most cases.
pub fn pairwise_sum(a: &[f64]) -> f64 {
    let n = a.len();
    if n < 8 {
        let mut res = 0.0;
        for &x in a {
            res += x;
        }
        res
    } else if n <= 128 {
        let mut r = [0.0; 8];
        r.copy_from_slice(&a[..8]);
        let mut i = 8;
        while i < n - n % 8 {
            for (j, rj) in r.iter_mut().enumerate() {
                *rj += a[i + j];
            }
            i += 8;
        }
        let mut res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        while i < n {
            res += a[i];
            i += 1;
        }
        res
    } else {
        let mut n2 = n / 2;
        n2 -= n2 % 8;
        pairwise_sum(&a[..n2]) + pairwise_sum(&a[n2..])
    }
}

/// The mean of the values below `cap`, or `None` when there is none.
fn capped_mean(d: &[f64], cap: f64) -> (Option<f64>, usize) {
    let below: Vec<f64> = d.iter().copied().filter(|&x| x < cap).collect();
    if below.is_empty() {
        (None, 0)
    } else {
        (Some(pairwise_sum(&below) / below.len() as f64), below.len())
    }
}

/// Everything an evaluation measured, with what the error clouds need.
#[derive(Debug, Clone, PartialEq)]
pub struct DtuEvaluation {
    /// The options used.
    pub options: DtuOptions,
    /// Points before down-sampling (a mesh's vertices and samples).
    pub sampled_points: usize,
    /// The down-sampled points, in the shuffled order (the d2s cloud's points).
    pub downsampled: Vec<Point3>,
    /// How many of them lie in the widened bounding box.
    pub in_box: usize,
    /// Indices into `downsampled` of the observed points, in order.
    pub observed: Vec<u32>,
    /// Their distances to the STL points (mm).
    pub d2s: Vec<f64>,
    /// Indices of the STL points above the ground plane, in order.
    pub above: Vec<u32>,
    /// Their distances to the reconstruction points in the widened box (mm).
    pub s2d: Vec<f64>,
    /// How many STL points there are.
    pub stl_points: usize,
    /// Mean accuracy (mm): the mean of `d2s` below `max_dist`.
    pub mean_d2s: Option<f64>,
    /// How many `d2s` values are below `max_dist`.
    pub d2s_counted: usize,
    /// Mean completeness (mm): the mean of `s2d` below `max_dist`.
    pub mean_s2d: Option<f64>,
    /// How many `s2d` values are below `max_dist`.
    pub s2d_counted: usize,
    /// The mean of the two.
    pub overall: Option<f64>,
}

/// Runs the evaluation of `input` against `scan`, telling `progress` of its long stages
/// (indexing the STL points, accuracy, indexing the reconstruction, completeness).
pub fn evaluate(
    scan: &DtuScan,
    input: DtuInput,
    options: &DtuOptions,
    progress: &dyn Progress,
) -> Result<DtuEvaluation> {
    options.validate()?;
    let mut points = match input {
        DtuInput::Cloud(p) => p,
        DtuInput::Mesh {
            vertices,
            triangles,
        } => sample_mesh(&vertices, &triangles, options.downsample_density)?,
    };
    if points.is_empty() {
        return Err(Error::Empty {
            what: "the reconstruction".into(),
        });
    }
    if points.len() > u32::MAX as usize {
        return Err(Error::LimitExceeded {
            format: "DTU",
            what: "reconstruction points".into(),
            count: points.len() as u64,
            limit: u32::MAX as u64,
            hint: "",
        });
    }
    let sampled_points = points.len();
    shuffle(&mut points, options.shuffle);
    let kept = radius_filter(&points, options.downsample_density);
    let mut downsampled = Vec::with_capacity(kept.iter().filter(|&&k| k).count());
    for (p, k) in points.iter().zip(&kept) {
        if *k {
            downsampled.push(*p);
        }
    }
    drop(points);
    drop(kept);

    // The box in float32, as the port casts BB before widening it.
    let om = &scan.obs_mask;
    let bb_lo32 = om.bb[0].map(|v| v as f32);
    let bb_hi32 = om.bb[1].map(|v| v as f32);
    let patch32 = options.patch_size as f32;
    let patch2_32 = (options.patch_size * 2.0) as f32;
    let lo = bb_lo32.map(|v| f64::from(v - patch32));
    let hi = bb_hi32.map(|v| f64::from(v + patch2_32));
    let origin = bb_lo32.map(f64::from);
    let mut data_in = Vec::new();
    let mut observed = Vec::new();
    for (i, p) in downsampled.iter().enumerate() {
        if !(0..3).all(|a| p[a] >= lo[a] && p[a] < hi[a]) {
            continue;
        }
        data_in.push(*p);
        let mut cell = [0usize; 3];
        let mut inside = true;
        for a in 0..3 {
            let g = ((p[a] - origin[a]) / om.res).round_ties_even();
            if g >= 0.0 && g < om.dims[a] as f64 {
                cell[a] = g as usize;
            } else {
                inside = false;
            }
        }
        if inside && om.cells[cell[0] + om.dims[0] * (cell[1] + om.dims[1] * cell[2])] != 0 {
            observed.push(i as u32);
        }
    }
    if data_in.is_empty() {
        return Err(Error::InvalidContent(format!(
            "no reconstruction point lies in the scan's bounding box widened by the patch size ({lo:?} to {hi:?}); is the reconstruction in the scan's frame, in mm?"
        )));
    }
    let in_box = data_in.len();

    progress.start(Stage::IndexGroundTruth, 1);
    let stl_index = KdCloud::new(&scan.stl)?;
    progress.finish();
    let obs_points: Vec<Point3> = observed.iter().map(|&i| downsampled[i as usize]).collect();
    progress.start(Stage::Accuracy, obs_points.len() as u64);
    let d2s: Vec<f64> =
        parallel::map_points_with_state(&obs_points, progress, |start: &mut NearStart, p| {
            let (d, k) = stl_index.nearest_from(*p, start.0);
            start.0 = k;
            d
        });
    progress.finish();
    drop(stl_index);
    drop(obs_points);

    let pl = scan.plane;
    let above: Vec<u32> = (0..scan.stl.len())
        .filter(|&i| {
            let s = scan.stl[i];
            pl[0] * s[0] + pl[1] * s[1] + pl[2] * s[2] + pl[3] > 0.0
        })
        .map(|i| i as u32)
        .collect();
    let above_points: Vec<Point3> = above.iter().map(|&i| scan.stl[i as usize]).collect();
    progress.start(Stage::IndexReconstruction, 1);
    let data_index = KdCloud::new(&data_in)?;
    progress.finish();
    progress.start(Stage::Completeness, above_points.len() as u64);
    // The STL points are denser than the down-sampled reconstruction: consecutive queries (in
    // Morton order) mostly find their nearest within the coverage of the neighbour list the
    // queries before them made (the 8 nearest around where it was made), which answers
    // exactly (the tree's distance, bit for bit) without a walk of the tree.
    let s2d: Vec<f64> =
        parallel::map_points_with_state(&above_points, progress, |list: &mut NeighbourList, p| {
            let (d2, _) = list.nearest_below(
                &data_index,
                *p,
                (f64::INFINITY, NO_POINT),
                f64::INFINITY,
                None,
            );
            d2.sqrt()
        });
    progress.finish();

    let (mean_d2s, d2s_counted) = capped_mean(&d2s, options.max_dist);
    let (mean_s2d, s2d_counted) = capped_mean(&s2d, options.max_dist);
    let overall = match (mean_d2s, mean_s2d) {
        (Some(a), Some(b)) => Some((a + b) / 2.0),
        _ => None,
    };
    Ok(DtuEvaluation {
        options: *options,
        sampled_points,
        downsampled,
        in_box,
        observed,
        d2s,
        above,
        s2d,
        stl_points: scan.stl.len(),
        mean_d2s,
        d2s_counted,
        mean_s2d,
        s2d_counted,
        overall,
    })
}

/// The previous query's answer, where the next query starts.
struct NearStart(usize);

impl Default for NearStart {
    fn default() -> Self {
        NearStart(sfmeval::distance::NO_POINT)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn triangle_count_matches_the_samples() {
        for (n1, n2) in [
            (0.0, 0.0),
            (1.0, 0.0),
            (3.0, 5.0),
            (17.0, 4.0),
            (40.0, 41.0),
        ] {
            let mut out = Vec::new();
            sample_triangle([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0; 3], n1, n2, &mut out);
            assert_eq!(out.len() as u64, triangle_count(n1, n2), "{n1} {n2}");
        }
    }

    #[test]
    fn pairwise_sum_adds_up() {
        let v: Vec<f64> = (0..1000).map(|i| f64::from(i) * 0.5).collect();
        assert_eq!(pairwise_sum(&v), 0.5 * 999.0 * 1000.0 / 2.0);
    }
}
