//! The `icp` stage: trimmed, scaled point-to-surface ICP against the ground truth.
//!
//! Correspondences are the exact closest points on the ground-truth mesh (nearest points for
//! a cloud ground truth) of a seeded subsample of the reconstruction. Only pairs inside a
//! distance gate take part; the gate starts at a fraction of the ground-truth diagonal and
//! shrinks coarse-to-fine to a multiple of the robust residual spread (1.4826 × median). Each
//! update is the Umeyama similarity of the gated pairs. A coarse phase runs on a small part of
//! the subsample, the fine phase on all of it; iteration stops when the transform moves the
//! subsample's bounding box by less than `tolerance` × the ground-truth diagonal.
//!
//! Speed without changing the answer: points farther than twice the gate are skipped until
//! the transform has moved any point by more than the gate (so none of them can have come
//! back inside it), and two consecutive, nearly parallel steps are extrapolated (Besl & McKay)
//! — the extrapolated pose is kept only if it lowers the truncated cost, otherwise the plain
//! step is restored and extrapolation is off for the rest of the phase.
//!
//! Scale-collapse guard (CloudCompare #1034: scaled ICP shrinking an SfM cloud onto a patch of
//! the template): the scale may change by at most `max_scale_step` per iteration and by at most
//! `max_scale_drift` from the start; the result is rejected — the stage keeps the start
//! transform and says why in its note — when the drift bound is hit, when fewer than
//! `min_overlap` of the points end inside the gate, or when the scale fell while the part of
//! the ground truth the inliers cover shrank.

use nalgebra::Vector3;

use super::{AlignStage, StageKind, is_finite, make_stage, subsample_indices, to_v};
use crate::error::{Error, Result};
use crate::geometry::{Aabb, Point3};
use crate::note::{Code, Note};
use crate::prepared::PreparedGroundTruth;
use crate::progress::NoProgress;
use crate::transform::Similarity;

/// Options of the `icp` stage.
#[derive(Debug, Clone, PartialEq)]
pub struct IcpOptions {
    /// Most iterations (coarse and fine phases together).
    pub max_iterations: usize,
    /// Reconstruction points used (a seeded random subsample when there are more).
    pub max_points: usize,
    /// Points of the coarse phase (the first ones of the subsample).
    pub coarse_points: usize,
    /// Seed of the subsample.
    pub seed: u64,
    /// Estimate the scale too (`false`: rigid, the start's scale is kept).
    pub with_scale: bool,
    /// First distance gate as a fraction of the ground-truth bounding-box diagonal.
    pub initial_gate: f64,
    /// The gate shrinks to this many robust standard deviations of the gated residuals.
    pub gate_sigmas: f64,
    /// Stop when the update moves the subsample's bounding box corners by less than this
    /// fraction of the ground-truth diagonal (RMS over the corners).
    pub tolerance: f64,
    /// Largest relative scale change per iteration.
    pub max_scale_step: f64,
    /// Largest relative scale change from the start (`s ∈ [s₀/(1+d), s₀·(1+d)]`); reaching
    /// it rejects the result.
    pub max_scale_drift: f64,
    /// Smallest share of the subsample that must end inside the gate.
    pub min_overlap: f64,
    /// Restart the refinement from its own answer until a restart moves the subsample's box by
    /// less than `tolerance` (its fixed point), at most this many runs in all; 1 = one run.
    /// One run stops when a step is small, which on a sparse cloud can leave it a few hundredths
    /// of a degree short of where a restart (with its wide first gate) settles; `icp` alone,
    /// refining a hand placement, runs to the fixed point.
    pub max_restarts: usize,
}

impl Default for IcpOptions {
    fn default() -> Self {
        IcpOptions {
            max_iterations: 100,
            max_points: 16_384,
            coarse_points: 2_000,
            seed: 0,
            with_scale: true,
            initial_gate: 0.1,
            gate_sigmas: 3.0,
            tolerance: 1e-5,
            max_scale_step: 0.05,
            max_scale_drift: 0.25,
            min_overlap: 0.2,
            max_restarts: 1,
        }
    }
}

impl IcpOptions {
    fn validate(&self) -> Result<()> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if self.max_iterations == 0
            || self.max_points < 3
            || self.coarse_points < 3
            || self.max_restarts == 0
        {
            return Err(Error::InvalidOption(
                "ICP needs ≥ 1 iteration, ≥ 1 run and ≥ 3 points".into(),
            ));
        }
        if !(pos(self.initial_gate)
            && pos(self.gate_sigmas)
            && pos(self.tolerance)
            && pos(self.max_scale_step)
            && pos(self.max_scale_drift))
        {
            return Err(Error::InvalidOption(
                "ICP gate, tolerance and scale bounds must be > 0".into(),
            ));
        }
        if !(self.min_overlap >= 0.0 && self.min_overlap <= 1.0) {
            return Err(Error::InvalidOption(
                "ICP minimum overlap must be in [0, 1]".into(),
            ));
        }
        Ok(())
    }
}

/// Robust residual spread (1.4826 × median) of the distances inside `gate`, and the next gate.
pub(crate) fn next_gate(dists: &[f64], gate: f64, sigmas: f64, floor: f64) -> f64 {
    let inside: Vec<f64> = dists.iter().copied().filter(|d| *d <= gate).collect();
    if inside.is_empty() {
        return gate;
    }
    let sigma = 1.4826 * super::quantile(&inside, 0.5);
    gate.min((sigmas * sigma).max(floor))
}

/// Result of one similarity update.
pub(crate) struct Update {
    pub t: Similarity,
    pub hit_drift: bool,
}

/// One gated Umeyama update from `src` (reconstruction frame) to its correspondences, with the
/// scale bounded per step (relative to `s_prev`) and in total (relative to `s_ref`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn update(
    src: &[Point3],
    closest: &[(Point3, f64)],
    gate: f64,
    s_prev: f64,
    s_ref: f64,
    step: f64,
    drift: f64,
    with_scale: bool,
) -> Option<Update> {
    let mut a = Vec::with_capacity(src.len());
    let mut b = Vec::with_capacity(src.len());
    for (p, (q, d)) in src.iter().zip(closest) {
        if *d <= gate {
            a.push(*p);
            b.push(*q);
        }
    }
    if a.len() < 3 {
        return None;
    }
    let t = super::umeyama(&a, &b, true).ok()?;
    let s = t.scale();
    let (lo, hi) = if with_scale {
        let lo = (s_prev / (1.0 + step)).max(s_ref / (1.0 + drift));
        let hi = (s_prev * (1.0 + step)).min(s_ref * (1.0 + drift));
        (lo.min(hi), hi.max(lo))
    } else {
        (s_ref, s_ref)
    };
    let s_new = s.clamp(lo, hi);
    let hit_drift = with_scale
        && (s_new <= s_ref / (1.0 + drift) * (1.0 + 1e-12)
            || s_new >= s_ref * (1.0 + drift) * (1.0 - 1e-12));
    let t = if s_new != s {
        // Same rotation, clamped scale, the translation that is optimal for them.
        let n = a.len() as f64;
        let mu_a = a.iter().fold(Vector3::zeros(), |acc, p| acc + to_v(*p)) / n;
        let mu_b = b.iter().fold(Vector3::zeros(), |acc, p| acc + to_v(*p)) / n;
        let r = t.rotation();
        let rm = super::to_m(&r);
        let tt = mu_b - s_new * rm * mu_a;
        Similarity::from_parts(s_new, r, [tt.x, tt.y, tt.z])
    } else {
        t
    };
    Some(Update { t, hit_drift })
}

/// RMS displacement of `corners` between two transforms.
pub(crate) fn motion(a: &Similarity, b: &Similarity, corners: &[Point3]) -> f64 {
    let ss: f64 = corners
        .iter()
        .map(|c| super::points::sq_dist(a.apply(*c), b.apply(*c)))
        .sum();
    (ss / corners.len().max(1) as f64).sqrt()
}

pub(crate) fn box_corners(points: &[Point3]) -> Vec<Point3> {
    match Aabb::of(points) {
        Some(b) => (0..8)
            .map(|k| [0, 1, 2].map(|a| if k >> a & 1 == 1 { b.max[a] } else { b.min[a] }))
            .collect(),
        None => Vec::new(),
    }
}

/// Closest ground-truth points of the transformed points (parallel, order-preserving).
pub(crate) fn correspondences(
    gt: &PreparedGroundTruth,
    t: &Similarity,
    pts: &[Point3],
) -> Vec<(Point3, f64)> {
    let moved: Vec<Point3> = pts.iter().map(|p| t.apply(*p)).collect();
    crate::parallel::map_points_with_state(&moved, &NoProgress, |hint, p| {
        gt.closest_point(*p, hint)
    })
}

/// RMS distance of points to their centroid.
pub(crate) fn spread(points: &[Point3]) -> f64 {
    super::centroid_cov(points).map_or(0.0, |(_, cov)| cov.trace().max(0.0).sqrt())
}

/// The finite points of `recon` subsampled deterministically to at most `m`, and how many
/// non-finite points were skipped.
pub(crate) fn finite_subsample(recon: &[Point3], m: usize, seed: u64) -> (Vec<Point3>, usize) {
    let finite: Vec<Point3> = recon.iter().copied().filter(is_finite).collect();
    let skipped = recon.len() - finite.len();
    let idx = subsample_indices(finite.len(), m, seed);
    (idx.into_iter().map(|i| finite[i]).collect(), skipped)
}

/// The `icp` stage from `start`. Returns the refined transform, or `start` itself with a note
/// when the guard rejects the result. Errors only on invalid options or fewer than 3 finite
/// reconstruction points. With `max_restarts` > 1 the refinement restarts from its own answer
/// until a restart moves the subsample's box by less than `tolerance` × the ground-truth
/// diagonal (its fixed point); a rejected restart keeps the last accepted answer. The stage
/// counts the iterations of every run and is converged when the last run converged at the
/// fixed point.
pub fn refine_icp(
    gt: &PreparedGroundTruth,
    recon: &[Point3],
    start: &Similarity,
    opts: &IcpOptions,
) -> Result<(Similarity, AlignStage)> {
    opts.validate()?;
    let (mut t, mut stage) = refine_once(gt, recon, start, opts)?;
    if opts.max_restarts == 1 || stage.notes.iter().any(|n| n.code == Code::IcpRejected) {
        return Ok((t, stage));
    }
    let (pts, _) = finite_subsample(recon, opts.max_points, opts.seed);
    let corners = box_corners(&pts);
    let diag = gt.aabb.diagonal();
    let mut iterations = stage.iterations;
    let mut fixed = false;
    for _ in 1..opts.max_restarts {
        let (t2, next) = refine_once(gt, recon, &t, opts)?;
        iterations += next.iterations;
        if next.notes.iter().any(|n| n.code == Code::IcpRejected) {
            break;
        }
        let moved = motion(&t, &t2, &corners) / diag;
        t = t2;
        stage = next;
        if moved < opts.tolerance {
            fixed = true;
            break;
        }
    }
    stage.iterations = iterations;
    stage.converged &= fixed;
    Ok((t, stage))
}

/// One run of the refinement from `start` ([`refine_icp`] without restarts).
fn refine_once(
    gt: &PreparedGroundTruth,
    recon: &[Point3],
    start: &Similarity,
    opts: &IcpOptions,
) -> Result<(Similarity, AlignStage)> {
    if start.matrix.iter().flatten().any(|v| !v.is_finite()) || !(start.scale() > 0.0) {
        return Err(Error::InvalidOption(
            "ICP start transform is not a finite similarity".into(),
        ));
    }
    let (pts, skipped) = finite_subsample(recon, opts.max_points, opts.seed);
    if pts.len() < 3 {
        return Err(Error::Empty {
            what: format!("reconstruction for ICP ({} finite points)", pts.len()),
        });
    }
    let mut notes = Vec::new();
    if skipped > 0 {
        notes.push(super::non_finite_ignored("icp", skipped));
    }
    let diag = gt.aabb.diagonal();
    let floor = 1e-12 * diag;
    let corners = box_corners(&pts);
    let s0 = start.scale();
    // Phases of growing size: the coarse part, ×3 each phase, then all points.
    let mut phases = Vec::new();
    let mut n = opts.coarse_points.min(pts.len());
    while n < pts.len() {
        phases.push(n);
        n = n.saturating_mul(16);
    }
    phases.push(pts.len());
    let phase_tol = opts.tolerance.max(5e-5);

    let mut t = *start;
    let mut gate = opts.initial_gate * diag;
    let mut phase = 0usize;
    let mut iterations = 0u64;
    let mut converged = false;
    let mut hit_drift = false;
    let mut last: Option<(Vec<(Point3, f64)>, f64)> = None; // last-phase correspondences and gate
    let mut start_cover: Option<f64> = None;
    // Why the result is rejected: a reason key for the note's values, and the words.
    let mut failure: Option<(&str, String)> = None;
    // Active set: points farther than 2 × gate at the last full pass are skipped until the
    // transform has moved any point by more than that gate (exactly the same result).
    let mut active: Vec<usize> = Vec::new();
    let mut full_pass = true;
    let mut full_gate = gate;
    let mut travelled = 0.0;
    let mut prev_step: Option<[f64; 7]> = None;
    // An extrapolated transform is kept only if it lowers the truncated cost; otherwise the
    // plain step is restored and extrapolation is off for the rest of the phase.
    let mut pending: Option<(Similarity, f64, f64)> = None; // (plain step, cost before, its gate)
    let mut extrapolate_ok = true;
    while (iterations as usize) < opts.max_iterations {
        let n = phases[phase];
        if full_pass || travelled > full_gate {
            active = (0..n).collect();
        }
        let src: Vec<Point3> = active.iter().map(|&i| pts[i]).collect();
        let corr = correspondences(gt, &t, &src);
        let dists: Vec<f64> = corr.iter().map(|c| c.1).collect();
        if let Some((plain, cost_before, g)) = pending.take()
            && truncated_cost(&dists, g, n) >= cost_before
        {
            travelled += max_motion(&t, &plain, &corners);
            t = plain;
            extrapolate_ok = false;
            iterations += 1;
            continue;
        }
        if start_cover.is_none() {
            start_cover = Some(covered_spread(&corr, gate));
        }
        gate = next_gate(&dists, gate, opts.gate_sigmas, floor);
        let (src, corr) = if active.len() == n && (full_pass || travelled > full_gate) {
            // A full pass: shrink the active set.
            full_pass = false;
            travelled = 0.0;
            full_gate = gate;
            let keep: Vec<usize> = (0..n).filter(|&k| corr[k].1 <= 2.0 * gate).collect();
            active = keep.iter().map(|&k| active[k]).collect();
            (
                keep.iter().map(|&k| src[k]).collect::<Vec<_>>(),
                keep.iter().map(|&k| corr[k]).collect::<Vec<_>>(),
            )
        } else {
            (src, corr)
        };
        iterations += 1;
        let cost_here = truncated_cost(&corr.iter().map(|c| c.1).collect::<Vec<_>>(), gate, n);
        let Some(u) = update(
            &src,
            &corr,
            gate,
            t.scale(),
            s0,
            opts.max_scale_step,
            opts.max_scale_drift,
            opts.with_scale,
        ) else {
            failure = Some((
                "few_correspondences",
                format!(
                    "fewer than 3 correspondences within {gate:.3e} of the ground truth (is the start transform far off?)"
                ),
            ));
            break;
        };
        let moved = motion(&t, &u.t, &corners) / diag;
        hit_drift = u.hit_drift;
        let last_phase = phase + 1 == phases.len();
        if last_phase {
            last = Some((corr, gate));
        }
        let step = step_params(&t, &u.t, &corners);
        travelled += max_motion(&t, &u.t, &corners);
        let old = t;
        t = u.t;
        let tol = if last_phase {
            opts.tolerance
        } else {
            phase_tol
        };
        if moved < tol {
            if last_phase {
                converged = true;
                break;
            }
            phase += 1;
            full_pass = true;
            prev_step = None;
            extrapolate_ok = true;
            continue;
        }
        // Extrapolate along two consecutive, nearly parallel, shrinking steps (Besl & McKay).
        match prev_step {
            Some(prev) if !hit_drift && extrapolate_ok => {
                let (a, b) = (norm7(&step), norm7(&prev));
                let cos = dot7(&step, &prev) / (a * b);
                if cos > libm::cos(20f64.to_radians()) && a < b {
                    let rho = a / b;
                    let lambda = (rho / (1.0 - rho)).min(25.0);
                    let ext = extrapolate(&old, &t, &corners, lambda);
                    let s = ext.scale();
                    if (s0 / (1.0 + opts.max_scale_drift)..=s0 * (1.0 + opts.max_scale_drift))
                        .contains(&s)
                        || !opts.with_scale
                    {
                        travelled += max_motion(&t, &ext, &corners);
                        pending = Some((t, cost_here, gate));
                        t = ext;
                    }
                    prev_step = None;
                } else {
                    prev_step = Some(step);
                }
            }
            _ => prev_step = Some(step),
        }
    }
    // Statistics of the last fine-phase correspondences (or one extra pass if there were none).
    let (corr, gate) = match last {
        Some(l) => l,
        None => {
            let c = correspondences(gt, &t, &pts);
            (c, gate)
        }
    };
    let inside: Vec<f64> = corr.iter().map(|c| c.1).filter(|d| *d <= gate).collect();
    let inlier_ratio = inside.len() as f64 / pts.len() as f64;
    let rmse = if inside.is_empty() {
        None
    } else {
        Some((inside.iter().map(|d| d * d).sum::<f64>() / inside.len() as f64).sqrt())
    };
    let s1 = t.scale();
    if failure.is_none() {
        if hit_drift {
            failure = Some((
                "scale_drift",
                format!(
                    "the scale drifted to the bound ×{:.3} of the start (scale {s0:.6} → {s1:.6}): likely a collapse onto part of the surface",
                    s1 / s0
                ),
            ));
        } else if inlier_ratio < opts.min_overlap {
            failure = Some((
                "low_overlap",
                format!(
                    "only {:.1} % of the points lie within {gate:.3e} of the ground truth (minimum {:.1} %)",
                    100.0 * inlier_ratio,
                    100.0 * opts.min_overlap
                ),
            ));
        } else if let Some(c0) = start_cover {
            let c1 = covered_spread(&corr, gate);
            if opts.with_scale && s1 < 0.9 * s0 && c0 > 0.0 && c1 < 0.8 * c0 {
                failure = Some((
                    "shrank",
                    format!(
                        "the cloud shrank onto part of the surface: scale ×{:.3} of the start while the covered part of the ground truth shrank ×{:.3}",
                        s1 / s0,
                        c1 / c0
                    ),
                ));
            }
        }
    }
    if let Some((reason, why)) = failure {
        notes.push(
            Note::new(
                Code::IcpRejected,
                format!(
                    "the ICP refinement was rejected, the previous stage's transform is used: {why}"
                ),
            )
            .with("stage", "icp")
            .with("reason", reason),
        );
        let stage = make_stage(
            StageKind::Icp,
            start,
            rmse,
            Some(inlier_ratio),
            iterations,
            false,
            notes,
        );
        return Ok((*start, stage));
    }
    let stage = make_stage(
        StageKind::Icp,
        &t,
        rmse,
        Some(inlier_ratio),
        iterations,
        converged,
        notes,
    );
    Ok((t, stage))
}

/// Mean of min(d², gate²) over `n` points, of which those not in `dists` lie beyond the gate.
fn truncated_cost(dists: &[f64], gate: f64, n: usize) -> f64 {
    let g2 = gate * gate;
    let inside: f64 = dists.iter().map(|d| (d * d).min(g2)).sum();
    (inside + n.saturating_sub(dists.len()) as f64 * g2) / n.max(1) as f64
}

/// Largest displacement of any point of the box spanned by `corners` between two transforms
/// (the displacement is affine, so its norm peaks at a corner).
fn max_motion(a: &Similarity, b: &Similarity, corners: &[Point3]) -> f64 {
    corners
        .iter()
        .map(|c| super::points::sq_dist(a.apply(*c), b.apply(*c)).sqrt())
        .fold(0.0, f64::max)
}

fn centre_of(corners: &[Point3]) -> Vector3<f64> {
    corners.iter().fold(Vector3::zeros(), |s, c| s + to_v(*c)) / corners.len().max(1) as f64
}

/// A step between two transforms as 7 numbers in ground-truth units: rotation vector and log
/// scale times the mapped box's half-diagonal, and the motion of the box centre.
fn step_params(a: &Similarity, b: &Similarity, corners: &[Point3]) -> [f64; 7] {
    let c = centre_of(corners);
    let ca = to_v(a.apply([c.x, c.y, c.z]));
    let cb = to_v(b.apply([c.x, c.y, c.z]));
    let radius = corners.first().map_or(1.0, |k| (to_v(*k) - c).norm()) * b.scale();
    let dr = super::to_m(&b.rotation()) * super::to_m(&a.rotation()).transpose();
    let w = nalgebra::Rotation3::from_matrix_unchecked(dr).scaled_axis() * radius;
    let ls = libm::log(b.scale() / a.scale()) * radius;
    let d = cb - ca;
    [w.x, w.y, w.z, ls, d.x, d.y, d.z]
}

fn dot7(a: &[f64; 7], b: &[f64; 7]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm7(a: &[f64; 7]) -> f64 {
    dot7(a, a).sqrt()
}

/// `b` pushed `lambda` further along the step from `a` to `b`.
fn extrapolate(a: &Similarity, b: &Similarity, corners: &[Point3], lambda: f64) -> Similarity {
    let c = centre_of(corners);
    let cp = [c.x, c.y, c.z];
    let ca = to_v(a.apply(cp));
    let cb = to_v(b.apply(cp));
    let rb = super::to_m(&b.rotation());
    let dr = rb * super::to_m(&a.rotation()).transpose();
    let w = nalgebra::Rotation3::from_matrix_unchecked(dr).scaled_axis();
    let r = nalgebra::Rotation3::new(w * lambda).matrix() * rb;
    let s = b.scale() * libm::pow(b.scale() / a.scale(), lambda);
    let target = cb + (cb - ca) * lambda;
    let t = target - s * r * c;
    Similarity::from_parts(s, super::from_m(&r), [t.x, t.y, t.z])
}

/// Spread of the ground-truth points that the gated correspondences reach.
fn covered_spread(corr: &[(Point3, f64)], gate: f64) -> f64 {
    let q: Vec<Point3> = corr.iter().filter(|c| c.1 <= gate).map(|c| c.0).collect();
    spread(&q)
}
