//! The `cameras` stage: a similarity from matched camera centres inside a seeded LO-RANSAC
//! loop (minimal sample 3, Umeyama hypotheses, MSAC scoring, local optimisation on the inliers).
//! When the inlier centres are nearly collinear (a straight camera path) or only two cameras
//! match, the rotation comes from the camera orientations instead and only scale and
//! translation from the centres.

use nalgebra::Matrix3;
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use super::points::sq_dist;
use super::{
    AlignStage, Rotation, StageKind, from_m, is_finite, make_stage, planarity_ratio,
    project_to_rotation, rotation_angle_deg, to_m, to_v,
};
use crate::error::{Error, Result};
use crate::geometry::Point3;
use crate::note::{Code, Note};
use crate::transform::Similarity;

/// One camera seen in both the reconstruction and the ground truth (matched by image name).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPair {
    /// Camera centre in the reconstruction's frame.
    pub recon_center: Point3,
    /// Camera centre in the ground-truth frame.
    pub gt_center: Point3,
    /// Reconstructed `cam_from_world` rotation (row-major), when known.
    pub recon_rotation: Option<Rotation>,
    /// Ground-truth `cam_from_world` rotation (row-major), when known.
    pub gt_rotation: Option<Rotation>,
}

impl CameraPair {
    /// A pair of centres only.
    pub fn centers(recon_center: Point3, gt_center: Point3) -> Self {
        CameraPair {
            recon_center,
            gt_center,
            recon_rotation: None,
            gt_rotation: None,
        }
    }

    fn finite(&self) -> bool {
        is_finite(&self.recon_center)
            && is_finite(&self.gt_center)
            && self
                .recon_rotation
                .is_none_or(|r| r.iter().flatten().all(|v| v.is_finite()))
            && self
                .gt_rotation
                .is_none_or(|r| r.iter().flatten().all(|v| v.is_finite()))
    }

    /// The `gt_from_recon` rotation this pair implies (`R = R_gtᵀ · R_recon`), if both known.
    fn implied_rotation(&self) -> Option<Matrix3<f64>> {
        let (g, c) = (self.gt_rotation?, self.recon_rotation?);
        project_to_rotation(&(to_m(&g).transpose() * to_m(&c)))
    }
}

/// Options of the `cameras` stage.
#[derive(Debug, Clone, PartialEq)]
pub struct CamerasOptions {
    /// Inlier threshold as a fraction of the spread (RMS distance to their centroid) of the
    /// ground-truth camera centres.
    pub threshold_fraction: f64,
    /// Most RANSAC iterations.
    pub max_iterations: usize,
    /// Confidence of the adaptive stopping rule.
    pub confidence: f64,
    /// Seed of the sampler.
    pub seed: u64,
    /// Below this √(λ₂/λ₁) of the inlier centres the path counts as collinear and the
    /// orientations decide the rotation.
    pub collinear_ratio: f64,
    /// Rotation agreement (degrees) for a camera to count as an orientation inlier.
    pub rotation_threshold_deg: f64,
}

impl Default for CamerasOptions {
    fn default() -> Self {
        CamerasOptions {
            threshold_fraction: 0.05,
            max_iterations: 10_000,
            confidence: 0.9999,
            seed: 0,
            collinear_ratio: 0.02,
            rotation_threshold_deg: 5.0,
        }
    }
}

impl CamerasOptions {
    fn validate(&self) -> Result<()> {
        if !(self.threshold_fraction > 0.0 && self.threshold_fraction.is_finite()) {
            return Err(Error::InvalidOption(
                "camera inlier threshold fraction must be > 0".into(),
            ));
        }
        if self.max_iterations == 0 {
            return Err(Error::InvalidOption(
                "camera RANSAC needs at least one iteration".into(),
            ));
        }
        if !(self.confidence > 0.0 && self.confidence < 1.0) {
            return Err(Error::InvalidOption(
                "RANSAC confidence must be in (0, 1)".into(),
            ));
        }
        if !(self.collinear_ratio >= 0.0 && self.rotation_threshold_deg > 0.0) {
            return Err(Error::InvalidOption(
                "collinear ratio must be ≥ 0 and rotation threshold > 0".into(),
            ));
        }
        Ok(())
    }
}

struct Model {
    t: Similarity,
    cost: f64,
    inliers: Vec<usize>,
}

fn evaluate(t: &Similarity, pairs: &[CameraPair], thr2: f64) -> Model {
    let mut cost = 0.0;
    let mut inliers = Vec::new();
    for (i, p) in pairs.iter().enumerate() {
        let r2 = sq_dist(t.apply(p.recon_center), p.gt_center);
        if r2 <= thr2 {
            inliers.push(i);
            cost += r2;
        } else {
            cost += thr2;
        }
    }
    Model {
        t: *t,
        cost,
        inliers,
    }
}

fn better(a: &Model, b: &Option<Model>) -> bool {
    match b {
        None => true,
        Some(b) => {
            a.inliers.len() > b.inliers.len()
                || (a.inliers.len() == b.inliers.len() && a.cost < b.cost)
        }
    }
}

fn needed_iterations(inliers: usize, n: usize, sample: i32, confidence: f64, max: usize) -> usize {
    let w = inliers as f64 / n as f64;
    let p_good = libm::pow(w, f64::from(sample));
    if p_good >= 1.0 {
        return 1;
    }
    if p_good <= 0.0 {
        return max;
    }
    let k = libm::log(1.0 - confidence) / libm::log(1.0 - p_good);
    if k.is_finite() {
        (k.ceil() as usize).clamp(1, max)
    } else {
        max
    }
}

/// Fits the full similarity to the given pair indices by Umeyama.
fn fit_centres(pairs: &[CameraPair], idx: &[usize]) -> Result<Similarity> {
    let src: Vec<Point3> = idx.iter().map(|&i| pairs[i].recon_center).collect();
    let dst: Vec<Point3> = idx.iter().map(|&i| pairs[i].gt_center).collect();
    super::umeyama(&src, &dst, true)
}

/// Fits scale and translation with the rotation fixed (least squares).
fn fit_scale_translation(
    r: &Matrix3<f64>,
    pairs: &[CameraPair],
    idx: &[usize],
) -> Option<Similarity> {
    if idx.len() < 2 {
        return None;
    }
    let n = idx.len() as f64;
    let mu_a = idx.iter().fold(nalgebra::Vector3::zeros(), |s, &i| {
        s + to_v(pairs[i].recon_center)
    }) / n;
    let mu_b = idx.iter().fold(nalgebra::Vector3::zeros(), |s, &i| {
        s + to_v(pairs[i].gt_center)
    }) / n;
    let (mut num, mut den) = (0.0, 0.0);
    for &i in idx {
        let a = r * (to_v(pairs[i].recon_center) - mu_a);
        let b = to_v(pairs[i].gt_center) - mu_b;
        num += a.dot(&b);
        den += a.norm_squared();
    }
    let s = num / den;
    if !(s.is_finite() && s > 0.0) {
        return None;
    }
    let t = mu_b - s * r * mu_a;
    Some(Similarity::from_parts(s, from_m(r), [t.x, t.y, t.z]))
}

fn rms(t: &Similarity, pairs: &[CameraPair], idx: &[usize]) -> f64 {
    if idx.is_empty() {
        return 0.0;
    }
    (idx.iter()
        .map(|&i| sq_dist(t.apply(pairs[i].recon_center), pairs[i].gt_center))
        .sum::<f64>()
        / idx.len() as f64)
        .sqrt()
}

/// The `cameras` stage. Pairs with a non-finite value are skipped (and counted in the note).
/// Errors when fewer than 3 usable pairs remain (2 with orientations), when all centres
/// coincide, or when the centres are collinear and no orientations are given.
pub fn align_cameras(
    pairs: &[CameraPair],
    opts: &CamerasOptions,
) -> Result<(Similarity, AlignStage)> {
    opts.validate()?;
    let mut notes = Vec::new();
    let usable: Vec<CameraPair> = pairs.iter().copied().filter(CameraPair::finite).collect();
    if usable.len() < pairs.len() {
        let skipped = pairs.len() - usable.len();
        notes.push(
            Note::new(
                Code::NonFiniteCameraPairs,
                format!(
                    "the camera-based alignment skipped {skipped} camera(s) with non-finite poses"
                ),
            )
            .with("stage", "cameras")
            .with("count", skipped),
        );
    }
    let n = usable.len();
    if n == 0 {
        return Err(Error::Empty {
            what: "matched cameras (none with a finite pose)".into(),
        });
    }
    if n == 1 {
        return Err(Error::Geometry(
            "only 1 matched camera with a finite pose: the cameras stage needs at least 3 (2 with orientations)".into(),
        ));
    }
    let gt_centres: Vec<Point3> = usable.iter().map(|p| p.gt_center).collect();
    let recon_centres: Vec<Point3> = usable.iter().map(|p| p.recon_center).collect();
    let spread =
        |pts: &[Point3]| super::centroid_cov(pts).map_or(0.0, |(_, cov)| cov.trace().sqrt());
    let gt_spread = spread(&gt_centres);
    let magnitude = gt_centres
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if !(gt_spread > 1e-12 * magnitude.max(1e-300)) {
        return Err(Error::Geometry(format!(
            "all {n} matched ground-truth camera centres coincide: no scale or rotation can be found from them"
        )));
    }
    let r_mag = recon_centres
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if !(spread(&recon_centres) > 1e-12 * r_mag.max(1e-300)) {
        return Err(Error::Geometry(format!(
            "all {n} matched reconstructed camera centres coincide: no scale or rotation can be found from them"
        )));
    }
    let thr = opts.threshold_fraction * gt_spread;
    let thr2 = thr * thr;
    let have_rotations = usable
        .iter()
        .filter(|p| p.implied_rotation().is_some())
        .count();

    let collinear_all = n < 3
        || planarity_ratio(&gt_centres) < opts.collinear_ratio
        || planarity_ratio(&recon_centres) < opts.collinear_ratio;
    let mut best: Option<Model> = None;
    let mut iterations = 0usize;
    let mut stopped = false;
    if !collinear_all {
        let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
        let mut needed = opts.max_iterations;
        while iterations < needed {
            iterations += 1;
            let i = rng.random_range(0..n);
            let mut j = rng.random_range(0..n - 1);
            if j >= i {
                j += 1;
            }
            let mut k = rng.random_range(0..n - 2);
            for m in [i.min(j), i.max(j)] {
                if k >= m {
                    k += 1;
                }
            }
            let sample = [i, j, k];
            let tri = sample.map(|s| usable[s].recon_center);
            let tri_gt = sample.map(|s| usable[s].gt_center);
            if planarity_ratio(&tri) < opts.collinear_ratio
                || planarity_ratio(&tri_gt) < opts.collinear_ratio
            {
                continue;
            }
            let Ok(t) = fit_centres(&usable, &sample) else {
                continue;
            };
            let mut m = evaluate(&t, &usable, thr2);
            if better(&m, &best) {
                // Local optimisation: refit on the inliers while it improves.
                for _ in 0..10 {
                    if m.inliers.len() < 3 {
                        break;
                    }
                    let Ok(t2) = fit_centres(&usable, &m.inliers) else {
                        break;
                    };
                    let m2 = evaluate(&t2, &usable, thr2);
                    if better(
                        &m2,
                        &Some(Model {
                            t: m.t,
                            cost: m.cost,
                            inliers: m.inliers.clone(),
                        }),
                    ) {
                        m = m2;
                    } else {
                        break;
                    }
                }
                needed =
                    needed_iterations(m.inliers.len(), n, 3, opts.confidence, opts.max_iterations);
                best = Some(m);
            }
        }
        stopped =
            iterations < opts.max_iterations || best.as_ref().is_some_and(|b| b.inliers.len() == n);
    }

    // Collinear inliers leave the rotation about their line free: use the orientations.
    let best_collinear = best.as_ref().is_none_or(|b| {
        let idx = &b.inliers;
        let a: Vec<Point3> = idx.iter().map(|&i| usable[i].recon_center).collect();
        let g: Vec<Point3> = idx.iter().map(|&i| usable[i].gt_center).collect();
        idx.len() < 3
            || planarity_ratio(&a) < opts.collinear_ratio
            || planarity_ratio(&g) < opts.collinear_ratio
    });
    if best_collinear {
        if have_rotations < 2 {
            return Err(Error::Geometry(format!(
                "the {n} matched camera centres are {} and camera orientations are not available for at least 2 of them: the rotation is undetermined",
                if n < 3 {
                    "fewer than 3"
                } else {
                    "(nearly) collinear"
                }
            )));
        }
        let why = if n < 3 {
            "fewer than 3"
        } else {
            "nearly collinear"
        };
        notes.push(
            Note::new(
                Code::CameraCentresDegenerate,
                format!(
                    "the camera centres are {why}, so the rotation comes from the camera orientations and the scale and translation from the centres"
                ),
            )
            .with("stage", "cameras")
            .with("cameras", n),
        );
        let (t, inliers, its) = with_rotations(&usable, thr2, opts)?;
        iterations += its;
        stopped = true;
        best = Some(evaluate_subset(t, inliers, &usable, thr2));
    }
    let Some(best) = best else {
        return Err(Error::Geometry(
            "no camera triple gave a valid similarity".into(),
        ));
    };
    let rmse = rms(&best.t, &usable, &best.inliers);
    let ratio = best.inliers.len() as f64 / n as f64;
    if best.inliers.len() < n {
        let outliers = n - best.inliers.len();
        notes.push(
            Note::new(
                Code::CameraOutliers,
                format!(
                    "the camera-based alignment left out {outliers} of {n} cameras as outliers: their centres end farther than {thr:.3e} from the ground-truth ones"
                ),
            )
            .with("stage", "cameras")
            .with("outliers", outliers)
            .with("cameras", n)
            .with_number("threshold", thr),
        );
    }
    let stage = make_stage(
        StageKind::Cameras,
        &best.t,
        Some(rmse),
        Some(ratio),
        iterations as u64,
        stopped,
        notes,
    );
    Ok((best.t, stage))
}

fn evaluate_subset(t: Similarity, inliers: Vec<usize>, pairs: &[CameraPair], thr2: f64) -> Model {
    let cost = inliers
        .iter()
        .map(|&i| sq_dist(t.apply(pairs[i].recon_center), pairs[i].gt_center).min(thr2))
        .sum();
    Model { t, cost, inliers }
}

/// Rotation by consensus of the per-camera implied rotations (chordal mean of the largest
/// agreeing set), then scale and translation by RANSAC over pairs of centres with that
/// rotation, refined by least squares on the inliers.
fn with_rotations(
    pairs: &[CameraPair],
    thr2: f64,
    opts: &CamerasOptions,
) -> Result<(Similarity, Vec<usize>, usize)> {
    let implied: Vec<(usize, Matrix3<f64>)> = pairs
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.implied_rotation().map(|r| (i, r)))
        .collect();
    let mut best_group: Vec<usize> = Vec::new();
    for (_, ri) in &implied {
        let group: Vec<usize> = implied
            .iter()
            .filter(|(_, rj)| {
                rotation_angle_deg(&from_m(ri), &from_m(rj)) <= opts.rotation_threshold_deg
            })
            .map(|(j, _)| *j)
            .collect();
        if group.len() > best_group.len() {
            best_group = group;
        }
    }
    let sum = best_group
        .iter()
        .filter_map(|&i| pairs[i].implied_rotation())
        .fold(Matrix3::zeros(), |s, r| s + r);
    let r = project_to_rotation(&sum)
        .ok_or_else(|| Error::Geometry("camera orientations do not agree on a rotation".into()))?;
    let cand = best_group;
    if cand.len() < 2 {
        return Err(Error::Geometry(
            "fewer than 2 cameras agree on the rotation: scale is undetermined".into(),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed ^ 0x5eed);
    let mut best: Option<Model> = None;
    let mut needed = opts.max_iterations;
    let mut it = 0;
    let sub: Vec<CameraPair> = cand.iter().map(|&i| pairs[i]).collect();
    let m = sub.len();
    while it < needed {
        it += 1;
        let i = rng.random_range(0..m);
        let mut j = rng.random_range(0..m - 1);
        if j >= i {
            j += 1;
        }
        let Some(t) = fit_scale_translation(&r, &sub, &[i, j]) else {
            continue;
        };
        let mut model = evaluate(&t, &sub, thr2);
        if better(&model, &best) {
            if let Some(t2) = fit_scale_translation(&r, &sub, &model.inliers) {
                let m2 = evaluate(&t2, &sub, thr2);
                if !better(
                    &model,
                    &Some(Model {
                        t: m2.t,
                        cost: m2.cost,
                        inliers: m2.inliers.clone(),
                    }),
                ) {
                    model = m2;
                }
            }
            needed = needed_iterations(
                model.inliers.len(),
                m,
                2,
                opts.confidence,
                opts.max_iterations,
            );
            best = Some(model);
        }
    }
    let best = best.ok_or_else(|| Error::Geometry("no camera pair gave a valid scale".into()))?;
    let inliers: Vec<usize> = best.inliers.iter().map(|&k| cand[k]).collect();
    Ok((best.t, inliers, it))
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Unit, Vector3};

    fn rot(axis: [f64; 3], deg: f64) -> Rotation {
        from_m(
            Rotation3::from_axis_angle(
                &Unit::new_normalize(Vector3::new(axis[0], axis[1], axis[2])),
                deg.to_radians(),
            )
            .matrix(),
        )
    }

    /// Orbit cameras looking at the origin; returns (gt centre, gt cam_from_world).
    fn orbit(n: usize, flat: bool) -> Vec<(Point3, Rotation)> {
        (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                let c = if flat {
                    [i as f64 * 0.5 - 3.0, 1.0, 4.0]
                } else {
                    [3.0 * a.cos(), 0.5 + 0.3 * (3.0 * a).sin(), 3.0 * a.sin()]
                };
                (c, rot([0.1, 1.0, 0.2 * (i as f64)], a.to_degrees()))
            })
            .collect()
    }

    fn make_pairs(truth: &Similarity, cams: &[(Point3, Rotation)]) -> Vec<CameraPair> {
        let inv = truth.inverse();
        let r = to_m(&truth.rotation());
        cams.iter()
            .map(|(c, g)| CameraPair {
                recon_center: inv.apply(*c),
                gt_center: *c,
                gt_rotation: Some(*g),
                // R_recon = R_gt · R
                recon_rotation: Some(from_m(&(to_m(g) * r))),
            })
            .collect()
    }

    #[test]
    fn recovers_with_outliers() {
        let truth = Similarity::from_parts(7.5, rot([1.0, 2.0, -0.5], 140.0), [1.0, -20.0, 3.0]);
        let mut pairs = make_pairs(&truth, &orbit(40, false));
        for (k, p) in pairs.iter_mut().enumerate().filter(|(k, _)| k % 4 == 1) {
            p.recon_center[0] += 0.3 + k as f64 * 0.01; // 25 % outliers
        }
        let (t, stage) = align_cameras(&pairs, &CamerasOptions::default()).unwrap();
        assert!(rotation_angle_deg(&t.rotation(), &truth.rotation()) < 1e-6);
        assert!((t.scale() / 7.5 - 1.0).abs() < 1e-9);
        assert!((stage.inlier_ratio.unwrap() - 0.75).abs() < 1e-12);
        assert!(stage.converged && stage.rmse.unwrap() < 1e-9);
        // Deterministic.
        assert_eq!(
            align_cameras(&pairs, &CamerasOptions::default()).unwrap().0,
            t
        );
    }

    #[test]
    fn collinear_uses_rotations_and_two_cameras_work() {
        let truth = Similarity::from_parts(0.02, rot([0.0, 1.0, 1.0], -70.0), [0.5, 0.0, 9.0]);
        let pairs = make_pairs(&truth, &orbit(10, true));
        let (t, stage) = align_cameras(&pairs, &CamerasOptions::default()).unwrap();
        assert!(rotation_angle_deg(&t.rotation(), &truth.rotation()) < 1e-6);
        assert!((t.scale() / 0.02 - 1.0).abs() < 1e-9);
        assert!(stage.notes.iter().any(|n| n.code == Code::CameraCentresDegenerate
            && n.message.contains("collinear")));
        let (t2, _) = align_cameras(&pairs[..2], &CamerasOptions::default()).unwrap();
        assert!((t2.scale() / 0.02 - 1.0).abs() < 1e-9);
    }

    #[test]
    fn bad_inputs() {
        let o = CamerasOptions::default();
        let truth = Similarity::from_parts(2.0, rot([0.0, 1.0, 0.0], 30.0), [0.0; 3]);
        let cams = orbit(10, true);
        // Collinear without rotations.
        let no_rot: Vec<CameraPair> = make_pairs(&truth, &cams)
            .iter()
            .map(|p| CameraPair::centers(p.recon_center, p.gt_center))
            .collect();
        assert!(matches!(
            align_cameras(&no_rot, &o),
            Err(Error::Geometry(_))
        ));
        assert!(matches!(
            align_cameras(&no_rot[..2], &o),
            Err(Error::Geometry(_))
        ));
        assert!(matches!(align_cameras(&[], &o), Err(Error::Empty { .. })));
        let one = make_pairs(&truth, &orbit(1, true));
        assert!(
            matches!(align_cameras(&one, &o), Err(Error::Geometry(m)) if m.contains("only 1 matched camera"))
        );
        let same = vec![CameraPair::centers([1.0; 3], [2.0; 3]); 5];
        assert!(matches!(align_cameras(&same, &o), Err(Error::Geometry(_))));
        let nan = vec![CameraPair::centers([f64::NAN; 3], [2.0; 3]); 5];
        assert!(matches!(align_cameras(&nan, &o), Err(Error::Empty { .. })));
        // NaN pairs among good ones are skipped with a note.
        let mut pairs = make_pairs(&truth, &orbit(12, false));
        pairs[3].recon_center[1] = f64::NAN;
        let (t, stage) = align_cameras(&pairs, &o).unwrap();
        assert!((t.scale() - 2.0).abs() < 1e-9);
        assert!(
            stage
                .notes
                .iter()
                .any(|n| n.code == Code::NonFiniteCameraPairs && n.message.contains("non-finite"))
        );
    }
}
