//! The `global` stage: alignment without any correspondence.
//!
//! 1. Normalisation: a robust centre (coordinate-wise median, then the centroid of the 80 %
//!    of points nearest to it), the principal axes and the RMS spread of the same trimmed set,
//!    for the reconstruction and for the ground-truth surface samples; the spread ratio is the
//!    starting scale.
//! 2. Starts: the 24 proper rotations that map the reconstruction's principal axes onto the
//!    ground truth's (every signed permutation with determinant +1), plus a well-spread set of
//!    extra rotations (super-Fibonacci sampling of SO(3)) for objects whose principal axes are
//!    ambiguous. Each rotation starts twice: centred and scaled by the moments of step 1, and
//!    by box normalisation (the reconstruction's robust box after the rotation onto the ground
//!    truth's box), which does not depend on where an SfM cloud is dense.
//! 3. Every start runs a short trimmed, scaled ICP on a small subsample (all starts in lock
//!    step, so one parallel closest-point pass serves all of them) and is scored by a
//!    symmetric trimmed Chamfer distance (reconstruction → ground truth and ground-truth
//!    samples → reconstruction, so a cloud shrunk onto a patch scores badly).
//! 4. The best distinct starts run a longer ICP on more points and are re-scored; the best wins.
//!
//! The search measures against a k-d tree of ground-truth surface samples (nearest sample, not
//! the exact closest surface point): from wrong poses exact BVH queries on a large mesh are
//! slow, and ranking starts needs no more. The stage's RMSE is against those samples; the
//! `icp` stage that normally follows uses the exact surface.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::icp::{box_corners, finite_subsample, motion, next_gate, update};
use super::{
    AlignStage, StageKind, from_m, make_stage, non_finite_ignored, rotation_angle_deg, sorted_eigen,
};
use crate::distance::CloudIndex;
use crate::error::{Error, Result};
use crate::geometry::Point3;
use crate::note::{Code, Note};
use crate::prepared::PreparedGroundTruth;
use crate::progress::NoProgress;
use crate::transform::Similarity;

/// Options of the `global` stage.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalOptions {
    /// Seed of the subsamples.
    pub seed: u64,
    /// Reconstruction points per start in the search.
    pub search_points: usize,
    /// Ground-truth samples for the normalisation and the score.
    pub gt_points: usize,
    /// Ground-truth surface samples standing in for the surface during the search.
    pub proxy_points: usize,
    /// Extra start rotations besides the 24 principal-axis ones.
    pub extra_rotations: usize,
    /// ICP iterations per start in the search.
    pub search_iterations: usize,
    /// Share of correspondences kept in the search ICP.
    pub trim: f64,
    /// Best distinct starts refined further.
    pub finalists: usize,
    /// Reconstruction points in the refinement of the finalists.
    pub final_points: usize,
    /// ICP iterations in the refinement of the finalists.
    pub final_iterations: usize,
}

impl Default for GlobalOptions {
    fn default() -> Self {
        GlobalOptions {
            seed: 0,
            search_points: 300,
            gt_points: 2_000,
            proxy_points: 20_000,
            extra_rotations: 96,
            search_iterations: 8,
            trim: 0.8,
            finalists: 3,
            final_points: 1_500,
            final_iterations: 25,
        }
    }
}

impl GlobalOptions {
    fn validate(&self) -> Result<()> {
        if self.search_points < 3
            || self.gt_points < 3
            || self.final_points < 3
            || self.proxy_points < 3
        {
            return Err(Error::InvalidOption(
                "global alignment needs ≥ 3 points per subsample".into(),
            ));
        }
        if self.search_iterations == 0 || self.final_iterations == 0 || self.finalists == 0 {
            return Err(Error::InvalidOption(
                "global alignment needs ≥ 1 iteration and ≥ 1 finalist".into(),
            ));
        }
        if !(self.trim > 0.0 && self.trim <= 1.0) {
            return Err(Error::InvalidOption(
                "global alignment trim must be in (0, 1]".into(),
            ));
        }
        if self.extra_rotations > 100_000 {
            return Err(Error::InvalidOption(
                "at most 100000 extra start rotations".into(),
            ));
        }
        Ok(())
    }
}

/// Robust frame of a point set: centre, principal axes (columns, descending variance), spread.
struct Frame {
    centre: Vector3<f64>,
    axes: Matrix3<f64>,
    spread: f64,
}

fn robust_frame(points: &[Point3]) -> Option<Frame> {
    if points.len() < 3 {
        return None;
    }
    let med =
        [0, 1, 2].map(|k| super::quantile(&points.iter().map(|p| p[k]).collect::<Vec<_>>(), 0.5));
    let d: Vec<f64> = points
        .iter()
        .map(|p| super::points::sq_dist(*p, med))
        .collect();
    let cut = super::quantile(&d, 0.8);
    let kept: Vec<Point3> = points
        .iter()
        .zip(&d)
        .filter(|(_, d)| **d <= cut)
        .map(|(p, _)| *p)
        .collect();
    let (c, cov) = super::centroid_cov(&kept)?;
    let (_, axes) = sorted_eigen(&cov);
    let spread = cov.trace().max(0.0).sqrt();
    (spread > 0.0 && spread.is_finite()).then_some(Frame {
        centre: c,
        axes,
        spread,
    })
}

/// Reconstruction points whose rotated bounding box gives the box-normalised starts.
const BOX_POINTS: usize = 20_000;

/// Share of the reconstruction's points left out at each end of every axis of its box
/// (SfM outliers); the ground truth's box is exact.
const BOX_TRIM: f64 = 0.005;

/// Box normalisation of a start rotation `r`: the scale and translation that map the
/// reconstruction's robust axis-aligned box after `r` (per-axis quantiles `BOX_TRIM` and
/// `1 - BOX_TRIM`) onto the ground truth's box, matching centres and diagonals. SfM clouds
/// are far denser on textured, well-seen parts than area-uniform samples, so their moments
/// can put the centre a quarter of the object away (measured on the built-in statue from
/// pycolmap: 0.27 of its height), while their extent still spans the object.
fn box_start(
    r: &Matrix3<f64>,
    pts: &[Point3],
    gt_box: (Point3, Point3),
) -> Option<(f64, Vector3<f64>)> {
    let rotated: Vec<Vector3<f64>> = pts.iter().map(|p| r * super::to_v(*p)).collect();
    let mut lo = Vector3::zeros();
    let mut hi = Vector3::zeros();
    for k in 0..3 {
        let c: Vec<f64> = rotated.iter().map(|v| v[k]).collect();
        lo[k] = super::quantile(&c, BOX_TRIM);
        hi[k] = super::quantile(&c, 1.0 - BOX_TRIM);
    }
    let (gmin, gmax) = (super::to_v(gt_box.0), super::to_v(gt_box.1));
    let s = (gmax - gmin).norm() / (hi - lo).norm();
    let t = (gmin + gmax) / 2.0 - s * (lo + hi) / 2.0;
    (s.is_finite() && s > 0.0 && t.iter().all(|v| v.is_finite())).then_some((s, t))
}

/// The 24 proper rotations mapping the principal axes of `r` onto those of `g`.
fn axis_rotations(r: &Matrix3<f64>, g: &Matrix3<f64>) -> Vec<Matrix3<f64>> {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out = Vec::with_capacity(24);
    for p in perms {
        for signs in 0..8u32 {
            let mut m = Matrix3::zeros();
            for (row, &col) in p.iter().enumerate() {
                m[(row, col)] = if signs >> row & 1 == 1 { -1.0 } else { 1.0 };
            }
            let rot = g * m * r.transpose();
            if rot.determinant() > 0.0 {
                out.push(rot);
            }
        }
    }
    out
}

/// `n` well-spread rotations (super-Fibonacci spirals, Alexa 2022).
fn spread_rotations(n: usize) -> Vec<Matrix3<f64>> {
    let phi = std::f64::consts::SQRT_2;
    let psi = 1.533_751_168_755_204_3_f64;
    (0..n)
        .map(|i| {
            let s = i as f64 + 0.5;
            let r = (s / n as f64).sqrt();
            let big_r = (1.0 - s / n as f64).sqrt();
            let alpha = std::f64::consts::TAU * s / phi;
            let beta = std::f64::consts::TAU * s / psi;
            let q = UnitQuaternion::from_quaternion(Quaternion::new(
                big_r * libm::cos(beta),
                r * libm::sin(alpha),
                r * libm::cos(alpha),
                big_r * libm::sin(beta),
            ));
            *q.to_rotation_matrix().matrix()
        })
        .collect()
}

/// Symmetric trimmed Chamfer score of a transform (lower is better).
fn score(
    t: &Similarity,
    recon: &[Point3],
    recon_dists: &[f64],
    gt_pts: &[Point3],
    trim: f64,
) -> f64 {
    let moved: Vec<Point3> = recon.iter().map(|p| t.apply(*p)).collect();
    let a = trimmed_mean(recon_dists, trim);
    let b = match CloudIndex::new(&moved) {
        Ok(tree) => {
            let d: Vec<f64> = gt_pts.iter().map(|q| tree.nearest(*q).0).collect();
            trimmed_mean(&d, trim)
        }
        Err(_) => f64::INFINITY,
    };
    a + b
}

fn trimmed_mean(d: &[f64], keep: f64) -> f64 {
    if d.is_empty() {
        return f64::INFINITY;
    }
    let mut v = d.to_vec();
    v.sort_by(f64::total_cmp);
    let k = ((v.len() as f64 * keep).ceil() as usize).clamp(1, v.len());
    v[..k].iter().sum::<f64>() / k as f64
}

struct Candidate {
    t: Similarity,
    s_ref: f64,
    gate: f64,
    score: f64,
    index: usize,
    moved: f64,
    inliers: usize,
    rmse: f64,
}

/// Runs `iterations` ICP steps for all candidates in lock step (one parallel pass per step).
/// The search's stand-in for the ground truth: a k-d tree over surface samples (nearest
/// sample instead of the exact closest surface point — far cheaper from wrong poses, and
/// precise enough to rank starts; the `icp` stage that follows uses the exact surface).
struct Proxy {
    index: CloudIndex,
    points: Vec<Point3>,
}

impl Proxy {
    fn closest(&self, p: Point3) -> (Point3, f64) {
        let (d, i) = self.index.nearest(p);
        (self.points.get(i).copied().unwrap_or(p), d)
    }
}

fn lockstep(
    gt: &Proxy,
    cands: &mut [Candidate],
    pts: &[Point3],
    iterations: usize,
    trim: Option<f64>,
    gate_sigmas: f64,
    diag: f64,
) -> Vec<Vec<f64>> {
    let corners = box_corners(pts);
    let m = pts.len();
    let mut last = vec![Vec::new(); cands.len()];
    for _ in 0..iterations {
        let moved: Vec<Point3> = cands
            .iter()
            .flat_map(|c| pts.iter().map(|p| c.t.apply(*p)))
            .collect();
        let corr = crate::parallel::map_points(&moved, &NoProgress, |p| gt.closest(*p));
        for (k, c) in cands.iter_mut().enumerate() {
            let cs = &corr[k * m..(k + 1) * m];
            let d: Vec<f64> = cs.iter().map(|x| x.1).collect();
            c.gate = match trim {
                Some(q) => super::quantile(&d, q),
                None => next_gate(&d, c.gate, gate_sigmas, 1e-12 * diag),
            };
            let inside: Vec<f64> = d.iter().copied().filter(|x| *x <= c.gate).collect();
            c.inliers = inside.len();
            c.rmse =
                (inside.iter().map(|x| x * x).sum::<f64>() / inside.len().max(1) as f64).sqrt();
            if let Some(u) = update(pts, cs, c.gate, c.t.scale(), c.s_ref, 0.1, 1.0, true) {
                c.moved = motion(&c.t, &u.t, &corners) / diag;
                c.t = u.t;
            }
            last[k] = d;
        }
    }
    // Distances at the final transforms, for scoring.
    let moved: Vec<Point3> = cands
        .iter()
        .flat_map(|c| pts.iter().map(|p| c.t.apply(*p)))
        .collect();
    let corr = crate::parallel::map_points(&moved, &NoProgress, |p| gt.closest(*p).1);
    for (k, l) in last.iter_mut().enumerate() {
        *l = corr[k * m..(k + 1) * m].to_vec();
    }
    last
}

/// The `global` stage: a coarse similarity from the shapes alone (see the module docs).
pub(crate) fn align_global(
    gt: &PreparedGroundTruth,
    recon: &[Point3],
    opts: &GlobalOptions,
) -> Result<(Similarity, AlignStage)> {
    opts.validate()?;
    let diag = gt.aabb.diagonal();
    let (all, skipped) = finite_subsample(recon, usize::MAX, 0);
    if all.len() < 3 {
        return Err(Error::Empty {
            what: format!(
                "reconstruction for global alignment ({} finite points)",
                all.len()
            ),
        });
    }
    let (search_pts, _) = finite_subsample(&all, opts.search_points, opts.seed);
    let (final_pts, _) = finite_subsample(&all, opts.final_points, opts.seed ^ 0x9e37_79b9);
    let (gt_pts, _) = finite_subsample(gt.samples(), opts.gt_points, opts.seed ^ 0x7f4a_7c15);
    let (proxy_pts, _) = finite_subsample(gt.samples(), opts.proxy_points, opts.seed ^ 0x2545_f491);
    let proxy = Proxy {
        index: CloudIndex::new(&proxy_pts)?,
        points: proxy_pts,
    };
    let fr = robust_frame(&all).ok_or_else(|| {
        Error::Geometry("the reconstruction has zero extent: all points coincide".into())
    })?;
    let fg = robust_frame(gt.samples())
        .ok_or_else(|| Error::Geometry("the ground truth has zero extent".into()))?;
    let s0 = fg.spread / fr.spread;
    if !(s0.is_finite() && s0 > 0.0) {
        return Err(Error::Geometry(
            "cannot normalise the scale: zero or infinite spread".into(),
        ));
    }
    let mut rotations = axis_rotations(&fr.axes, &fg.axes);
    rotations.extend(spread_rotations(opts.extra_rotations));
    let (box_pts, _) = finite_subsample(&all, BOX_POINTS, opts.seed ^ 0x51ed_270b);
    let gt_box = (gt.aabb.min, gt.aabb.max);
    // Two starts per rotation: centre and scale from the robust moments, and from the robust
    // bounding boxes (see `box_start`).
    let mut starts: Vec<(Matrix3<f64>, f64, Vector3<f64>)> =
        Vec::with_capacity(2 * rotations.len());
    for r in &rotations {
        starts.push((*r, s0, fg.centre - s0 * r * fr.centre));
        if let Some((s, t)) = box_start(r, &box_pts, gt_box) {
            starts.push((*r, s, t));
        }
    }
    let mut cands: Vec<Candidate> = starts
        .iter()
        .enumerate()
        .map(|(index, (r, s, t))| Candidate {
            t: Similarity::from_parts(*s, from_m(r), [t.x, t.y, t.z]),
            s_ref: *s,
            gate: f64::INFINITY,
            score: f64::INFINITY,
            index,
            moved: 1.0,
            inliers: 0,
            rmse: 0.0,
        })
        .collect();
    let dists = lockstep(
        &proxy,
        &mut cands,
        &search_pts,
        opts.search_iterations,
        Some(opts.trim),
        3.0,
        diag,
    );
    for (c, d) in cands.iter_mut().zip(&dists) {
        c.score = score(&c.t, &search_pts, d, &gt_pts, opts.trim);
    }
    cands.sort_by(|a, b| a.score.total_cmp(&b.score).then(a.index.cmp(&b.index)));
    // Distinct finalists: skip starts that reached the pose of a better one.
    let mut finalists: Vec<Candidate> = Vec::new();
    for c in cands {
        if finalists.len() >= opts.finalists {
            break;
        }
        let dup = finalists.iter().any(|f| {
            rotation_angle_deg(&f.t.rotation(), &c.t.rotation()) < 2.0
                && super::points::sq_dist(f.t.translation(), c.t.translation()).sqrt() < 0.01 * diag
        });
        if !dup && c.score.is_finite() {
            finalists.push(Candidate {
                s_ref: c.t.scale(),
                gate: f64::INFINITY,
                ..c
            });
        }
    }
    if finalists.is_empty() {
        return Err(Error::Geometry(
            "global alignment found no valid start".into(),
        ));
    }
    // Refine: first gate = the trim quantile, then shrinking to 3 robust sigmas.
    lockstep(
        &proxy,
        &mut finalists,
        &final_pts,
        1,
        Some(opts.trim),
        3.0,
        diag,
    );
    let dists = lockstep(
        &proxy,
        &mut finalists,
        &final_pts,
        opts.final_iterations,
        None,
        3.0,
        diag,
    );
    for (c, d) in finalists.iter_mut().zip(&dists) {
        c.score = score(&c.t, &final_pts, d, &gt_pts, opts.trim);
    }
    finalists.sort_by(|a, b| a.score.total_cmp(&b.score).then(a.index.cmp(&b.index)));
    let best = &finalists[0];
    let mut notes = Vec::new();
    if skipped > 0 {
        notes.push(non_finite_ignored("global", skipped));
    }
    notes.push(
        Note::new(
            Code::GlobalSearchResult,
            format!(
                "a global shape search tried {} starting poses; the best (#{}) scores {:.3e} (the mean of the smallest {:.0} % of distances from a subsample of the reconstruction to ground-truth surface samples, plus the same from those samples to the subsample, in ground-truth units; lower is better)",
                starts.len(),
                best.index,
                best.score,
                100.0 * opts.trim
            ),
        )
        .with("stage", "global")
        .with("starts", starts.len())
        .with("best_start", best.index)
        .with_number("score", best.score),
    );
    if let Some(second) = finalists
        .iter()
        .skip(1)
        .find(|c| rotation_angle_deg(&c.t.rotation(), &best.t.rotation()) > 10.0)
        && second.score < 1.05 * best.score
    {
        let angle = rotation_angle_deg(&second.t.rotation(), &best.t.rotation());
        notes.push(
            Note::new(
                Code::AmbiguousPose,
                format!(
                    "the automatic alignment may have picked the wrong pose: another pose {angle:.0}° away fits almost as well (score {:.3e}, within 5 %); the object may be symmetric: check the view, or give a transform or point pairs",
                    second.score
                ),
            )
            .with("stage", "global")
            .with_number("angle_deg", angle)
            .with_number("score", second.score)
            .with_number("best_score", best.score)
            .with_number("within", 0.05),
        );
    }
    let iterations = (opts.search_iterations + 1 + opts.final_iterations) as u64;
    // A coarse stage: settled when the best start's last step moved < 0.1 % of the diagonal.
    let converged = best.moved < 1e-3;
    let stage = make_stage(
        StageKind::Global,
        &best.t,
        Some(best.rmse),
        Some(best.inliers as f64 / final_pts.len() as f64),
        iterations,
        converged,
        notes,
    );
    Ok((best.t, stage))
}
