//! Closed-form least-squares similarity between matched point sets (Umeyama 1991), with the
//! reflection correction, optionally weighted.

use nalgebra::{Matrix3, Vector3};

use super::{from_m, is_finite, to_v};
use crate::error::{Error, Result};
use crate::geometry::Point3;
use crate::transform::Similarity;

/// Below this √(λ₂/λ₁) of the source covariance the points count as collinear: the rotation
/// about their line is then undetermined.
pub(crate) const COLLINEAR_RATIO: f64 = 1e-7;

/// The similarity `dst ≈ s·R·src + t` minimising the sum of squared residuals; `with_scale =
/// false` fixes `s = 1` (a rigid motion). Needs ≥ 3 finite, non-collinear pairs.
///
/// ```
/// use sfmeval::align::umeyama;
/// let src = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let dst = src.map(|p| [2.0 * p[0] + 1.0, 2.0 * p[1], 2.0 * p[2] - 3.0]);
/// let t = umeyama(&src, &dst, true).unwrap();
/// assert!((t.scale() - 2.0).abs() < 1e-12);
/// ```
pub fn umeyama(src: &[Point3], dst: &[Point3], with_scale: bool) -> Result<Similarity> {
    umeyama_weighted(src, dst, None, with_scale)
}

/// [`umeyama`] with non-negative per-pair weights (`None` = all 1).
pub(crate) fn umeyama_weighted(
    src: &[Point3],
    dst: &[Point3],
    weights: Option<&[f64]>,
    with_scale: bool,
) -> Result<Similarity> {
    if src.len() != dst.len() {
        return Err(Error::InvalidOption(format!(
            "umeyama needs matched pairs: {} source and {} target points",
            src.len(),
            dst.len()
        )));
    }
    if let Some(w) = weights {
        if w.len() != src.len() {
            return Err(Error::InvalidOption(format!(
                "{} weights for {} pairs",
                w.len(),
                src.len()
            )));
        }
        if w.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return Err(Error::InvalidOption(
                "weights must be finite and ≥ 0".into(),
            ));
        }
    }
    if let Some(i) = src
        .iter()
        .zip(dst)
        .position(|(a, b)| !(is_finite(a) && is_finite(b)))
    {
        let count = src
            .iter()
            .zip(dst)
            .filter(|(a, b)| !(is_finite(a) && is_finite(b)))
            .count();
        return Err(Error::NonFinite {
            format: "alignment",
            what: "point pair",
            count,
            first_index: i,
        });
    }
    let w = |i: usize| weights.map_or(1.0, |w| w[i]);
    let used = (0..src.len()).filter(|&i| w(i) > 0.0).count();
    if used < 3 {
        return Err(Error::InvalidOption(format!(
            "a similarity needs at least 3 point pairs, got {used}"
        )));
    }
    let total: f64 = (0..src.len()).map(w).sum();
    let mut mu_s = Vector3::zeros();
    let mut mu_d = Vector3::zeros();
    for i in 0..src.len() {
        mu_s += w(i) * to_v(src[i]);
        mu_d += w(i) * to_v(dst[i]);
    }
    mu_s /= total;
    mu_d /= total;
    // Scale-safe: when the spreads leave [1e-100, 1e100] (squares and sums of squares would
    // underflow or overflow), work on the centred points divided by their largest deviation
    // and scale back at the end; otherwise divide by 1 (bit-identical to the plain formula).
    let spread = |pts: &[Point3], mu: &Vector3<f64>| {
        divisor(
            pts.iter()
                .map(|p| (to_v(*p) - mu).amax())
                .fold(0.0f64, f64::max),
        )
    };
    let (ks, kd) = (spread(src, &mu_s), spread(dst, &mu_d));
    let mut sums = CentredSums::ZERO;
    for i in 0..src.len() {
        let a = (to_v(src[i]) - mu_s) / ks;
        let b = (to_v(dst[i]) - mu_d) / kd;
        sums.add(w(i), &a, &b);
    }
    solve((mu_s, mu_d), (ks, kd), &sums, total, with_scale)
}

/// What the centred points are divided by, from their largest deviation from the mean: the
/// deviation itself when it leaves [1e-100, 1e100] (squares and sums of squares would underflow
/// or overflow), else 1 (bit-identical to the plain formula).
fn divisor(largest_deviation: f64) -> f64 {
    let m = largest_deviation;
    if m > 0.0 && !(1e-100..=1e100).contains(&m) {
        m
    } else {
        1.0
    }
}

/// The sums the closed form needs over the centred points `a` (source) and `b` (target),
/// each divided by its spread: Σ w·b·aᵀ, Σ w·a·aᵀ and Σ w·|a|².
#[derive(Clone, Copy)]
struct CentredSums {
    sigma: Matrix3<f64>,
    cov_s: Matrix3<f64>,
    var_s: f64,
}

impl CentredSums {
    const ZERO: CentredSums = CentredSums {
        sigma: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        cov_s: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        var_s: 0.0,
    };

    fn add(&mut self, w: f64, a: &Vector3<f64>, b: &Vector3<f64>) {
        self.sigma += w * b * a.transpose();
        self.cov_s += w * a * a.transpose();
        self.var_s += w * a.norm_squared();
    }

    fn merge(&mut self, other: &CentredSums) {
        self.sigma += other.sigma;
        self.cov_s += other.cov_s;
        self.var_s += other.var_s;
    }
}

/// Pairs per partial sum of [`umeyama_pairs`].
const PAIRS_PER_SUM: usize = 4096;

/// [`umeyama`] (with scale) of `n` pairs `(src(i), dst(i))`, read in place and summed in
/// parallel: partial sums over fixed runs of `PAIRS_PER_SUM` (4096) pairs, added in run order, so
/// the result does not depend on the thread count (its last bits differ from [`umeyama`]'s,
/// which adds the pairs one by one). For ICP's fits over a million matches.
pub fn umeyama_pairs(
    n: usize,
    src: impl Fn(usize) -> Point3 + Sync,
    dst: impl Fn(usize) -> Point3 + Sync,
) -> Result<Similarity> {
    if n < 3 {
        return Err(Error::InvalidOption(format!(
            "a similarity needs at least 3 point pairs, got {n}"
        )));
    }
    let parts = crate::parallel::map_fixed_ranges(n, PAIRS_PER_SUM, |r| {
        let (mut s, mut d) = (Vector3::zeros(), Vector3::zeros());
        for i in r {
            s += to_v(src(i));
            d += to_v(dst(i));
        }
        (s, d)
    });
    let (mut mu_s, mut mu_d) = (Vector3::<f64>::zeros(), Vector3::<f64>::zeros());
    for (s, d) in parts {
        mu_s += s;
        mu_d += d;
    }
    let total = n as f64;
    mu_s /= total;
    mu_d /= total;
    // The spreads (largest deviation from the mean) come with the undivided sums; in the rare
    // case that one leaves [1e-100, 1e100] the sums are made again on divided points.
    let centred = |ks: f64, kd: f64| {
        let parts = crate::parallel::map_fixed_ranges(n, PAIRS_PER_SUM, |r| {
            let mut sums = CentredSums::ZERO;
            let (mut ms, mut md) = (0.0f64, 0.0f64);
            for i in r {
                let a = to_v(src(i)) - mu_s;
                let b = to_v(dst(i)) - mu_d;
                ms = ms.max(a.amax());
                md = md.max(b.amax());
                sums.add(1.0, &(a / ks), &(b / kd));
            }
            (sums, ms, md)
        });
        let mut sums = CentredSums::ZERO;
        let (mut ms, mut md) = (0.0f64, 0.0f64);
        for (part, a, b) in &parts {
            sums.merge(part);
            ms = ms.max(*a);
            md = md.max(*b);
        }
        (sums, ms, md)
    };
    let (mut sums, ms, md) = centred(1.0, 1.0);
    let (ks, kd) = (divisor(ms), divisor(md));
    if ks != 1.0 || kd != 1.0 {
        sums = centred(ks, kd).0;
    }
    solve((mu_s, mu_d), (ks, kd), &sums, total, true)
}

/// The sums for a scaled Umeyama fit gathered in one pass over the pairs, for a fit whose pairs
/// are found on the fly (ICP's matches) and never stored: each side is taken relative to a
/// shift near its points (for ICP the moved cloud's centroid, for both sides), and the centred
/// sums follow from `Σ(b−μ_b)(a−μ_a)ᵀ = Σ b·aᵀ − n·μ_b·μ_aᵀ`. With each shift within a few
/// spreads of its points, the cancellation costs a digit or two against [`umeyama_pairs`]' two
/// passes. Partial sums over fixed runs merged in run order give the same bits for any thread
/// count.
#[derive(Clone, Copy)]
pub struct PairSums {
    shift_src: [f64; 3],
    shift_dst: [f64; 3],
    n: u64,
    /// Σ a, Σ b (a = source − shift_src, b = target − shift_dst).
    sum_a: [f64; 3],
    sum_b: [f64; 3],
    /// Σ b·aᵀ, row-major.
    ba: [[f64; 3]; 3],
    /// Σ a·aᵀ on and above the diagonal: 00, 01, 02, 11, 12, 22.
    aa: [f64; 6],
    /// Σ |b|².
    bb: f64,
}

impl PairSums {
    /// No pairs yet, each side relative to its shift.
    pub fn new(shift_src: Point3, shift_dst: Point3) -> PairSums {
        PairSums {
            shift_src,
            shift_dst,
            n: 0,
            sum_a: [0.0; 3],
            sum_b: [0.0; 3],
            ba: [[0.0; 3]; 3],
            aa: [0.0; 6],
            bb: 0.0,
        }
    }

    /// Adds the pair (`src`, `dst`).
    #[inline]
    pub fn add(&mut self, src: Point3, dst: Point3) {
        let a = [0, 1, 2].map(|k| src[k] - self.shift_src[k]);
        let b = [0, 1, 2].map(|k| dst[k] - self.shift_dst[k]);
        self.n += 1;
        for k in 0..3 {
            self.sum_a[k] += a[k];
            self.sum_b[k] += b[k];
        }
        for (row, bi) in self.ba.iter_mut().zip(b) {
            for (s, aj) in row.iter_mut().zip(a) {
                *s += bi * aj;
            }
        }
        let c = &mut self.aa;
        c[0] += a[0] * a[0];
        c[1] += a[0] * a[1];
        c[2] += a[0] * a[2];
        c[3] += a[1] * a[1];
        c[4] += a[1] * a[2];
        c[5] += a[2] * a[2];
        self.bb += b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
    }

    /// Adds the pairs summed in `other` (same shifts).
    pub fn merge(&mut self, other: &PairSums) {
        self.n += other.n;
        for k in 0..3 {
            self.sum_a[k] += other.sum_a[k];
            self.sum_b[k] += other.sum_b[k];
            for j in 0..3 {
                self.ba[k][j] += other.ba[k][j];
            }
        }
        for k in 0..6 {
            self.aa[k] += other.aa[k];
        }
        self.bb += other.bb;
    }

    /// Pairs added.
    pub fn len(&self) -> u64 {
        self.n
    }

    /// Whether no pair was added.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The scaled fit, or `None` when the one-pass sums cannot be trusted: a spread outside
    /// [1e-90, 1e90] (where squares lose range; [`umeyama_pairs`] divides the points first) or
    /// a sum that is not finite. Errors as [`umeyama`]'s for fewer than 3 pairs or degenerate
    /// points.
    pub fn similarity(&self) -> Option<Result<Similarity>> {
        if self.n < 3 {
            return Some(Err(Error::InvalidOption(format!(
                "a similarity needs at least 3 point pairs, got {}",
                self.n
            ))));
        }
        let total = self.n as f64;
        let mu_a = Vector3::from(self.sum_a) / total;
        let mu_b = Vector3::from(self.sum_b) / total;
        let c = &self.aa;
        let aa = Matrix3::new(c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5]);
        let sums = CentredSums {
            sigma: Matrix3::from_fn(|i, j| self.ba[i][j]) - total * mu_b * mu_a.transpose(),
            cov_s: aa - total * mu_a * mu_a.transpose(),
            var_s: (c[0] + c[3] + c[5]) - total * mu_a.norm_squared(),
        };
        let var_d = self.bb - total * mu_b.norm_squared();
        let fine = |v: f64| (1e-180..=1e180).contains(&(v / total));
        let finite = sums
            .sigma
            .iter()
            .chain(sums.cov_s.iter())
            .all(|v| v.is_finite());
        if !(finite && fine(sums.var_s) && fine(var_d)) {
            return None;
        }
        Some(solve(
            (
                Vector3::from(self.shift_src) + mu_a,
                Vector3::from(self.shift_dst) + mu_b,
            ),
            (1.0, 1.0),
            &sums,
            total,
            true,
        ))
    }
}

/// Whether the covariance `cov` (symmetric, positive semi-definite up to rounding) has
/// `λ₂/λ₁` far above the collinear threshold, proven from its invariants without an eigen
/// decomposition (which took most of a RANSAC sample's fit): with `T = λ₁+λ₂+λ₃` (the trace)
/// and `M = λ₁λ₂+λ₁λ₃+λ₂λ₃` (the principal 2×2 minors), `M ≤ 3λ₁λ₂` and `λ₁ ≤ T` give
/// `λ₂/λ₁ ≥ M/(3T²)`. A bound of 1e-12 (with rounding of a few 1e-16 T²) is a hundred times
/// the threshold's 1e-14, so the eigenvalues would decide the same; below it they decide.
fn clearly_not_collinear(cov: &Matrix3<f64>) -> bool {
    let c = |i: usize, j: usize| cov[(i, j)];
    let trace = c(0, 0) + c(1, 1) + c(2, 2);
    let minors = (c(0, 0) * c(1, 1) - c(0, 1) * c(1, 0))
        + (c(0, 0) * c(2, 2) - c(0, 2) * c(2, 0))
        + (c(1, 1) * c(2, 2) - c(1, 2) * c(2, 1));
    trace > 0.0 && minors >= 3e-12 * trace * trace
}

/// Umeyama's closed form with the reflection fix, from the means, the spreads the centred
/// points were divided by (1 unless extreme), the sums over the centred, divided points and
/// the total weight.
fn solve(
    (mu_s, mu_d): (Vector3<f64>, Vector3<f64>),
    (ks, kd): (f64, f64),
    sums: &CentredSums,
    total: f64,
    with_scale: bool,
) -> Result<Similarity> {
    let sigma = sums.sigma / total;
    let cov_s = sums.cov_s / total;
    let var_s = sums.var_s / total;
    if !clearly_not_collinear(&cov_s) {
        let (l, _) = super::sorted_eigen(&cov_s);
        if !(l[0] > 0.0) {
            return Err(Error::Geometry(
                "all source points coincide: no similarity is defined".into(),
            ));
        }
        if (l[1] / l[0]).sqrt() < COLLINEAR_RATIO {
            return Err(Error::Geometry(
                "the source points are collinear: the rotation about their line is undetermined"
                    .into(),
            ));
        }
    }
    let svd = sigma.svd(true, true);
    let (u, vt) = match (svd.u, svd.v_t) {
        (Some(u), Some(vt)) => (u, vt),
        _ => return Err(Error::Geometry("SVD of the cross-covariance failed".into())),
    };
    let mut s_diag = Matrix3::identity();
    if u.determinant() * vt.determinant() < 0.0 {
        s_diag[(2, 2)] = -1.0;
    }
    let r = u * s_diag * vt;
    let scale = if with_scale {
        let d = svd.singular_values;
        (d[0] + d[1] + s_diag[(2, 2)] * d[2]) / var_s * (kd / ks)
    } else {
        1.0
    };
    if !(scale.is_finite() && scale > 0.0) {
        return Err(Error::Geometry(
            "the target points collapse to a point: the similarity's scale would be 0".into(),
        ));
    }
    let t = mu_d - scale * r * mu_s;
    let out = Similarity::from_parts(scale, from_m(&r), [t.x, t.y, t.z]);
    if out.matrix.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Error::Geometry("the similarity is not finite".into()));
    }
    Ok(out)
}

// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#[cfg(test)]
#[allow(clippy::disallowed_methods)]
mod tests {
    use super::*;
    use crate::align::rotation_angle_deg;

    fn rot(axis: [f64; 3], deg: f64) -> [[f64; 3]; 3] {
        let a = nalgebra::Unit::new_normalize(Vector3::new(axis[0], axis[1], axis[2]));
        let r = nalgebra::Rotation3::from_axis_angle(&a, deg.to_radians());
        from_m(r.matrix())
    }

    #[test]
    fn exact_recovery_and_reflection_safe() {
        let src: Vec<Point3> = (0..20)
            .map(|i| {
                let f = f64::from(i);
                [(f * 0.7).sin() * 3.0, (f * 1.3).cos(), f * 0.1]
            })
            .collect();
        let truth = Similarity::from_parts(0.37, rot([0.3, -1.0, 0.2], 123.0), [5.0, -2.0, 1e3]);
        let dst: Vec<Point3> = src.iter().map(|p| truth.apply(*p)).collect();
        let t = umeyama(&src, &dst, true).unwrap();
        assert!((t.scale() - 0.37).abs() < 1e-12);
        assert!(rotation_angle_deg(&t.rotation(), &truth.rotation()) < 1e-6);
        // A mirrored target: the best proper rotation, never a reflection.
        let mirrored: Vec<Point3> = src.iter().map(|p| [-p[0], p[1], p[2]]).collect();
        let m = umeyama(&src, &mirrored, true).unwrap();
        assert!(m.scale() > 0.0);
        assert!(Similarity::from_matrix(m.matrix).is_ok());
        // Rigid variant keeps scale 1.
        assert!((umeyama(&src, &dst, false).unwrap().scale() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let a = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        assert!(matches!(
            umeyama(&a, &a, true),
            Err(Error::InvalidOption(_))
        ));
        let line = [
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
            [2.0, 2.0, 2.0],
            [3.0, 3.0, 3.0],
        ];
        assert!(matches!(
            umeyama(&line, &line, true),
            Err(Error::Geometry(_))
        ));
        let same = [[1.0, 2.0, 3.0]; 4];
        assert!(matches!(
            umeyama(&same, &line, true),
            Err(Error::Geometry(_))
        ));
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(matches!(
            umeyama(&tri, &same[..3], true),
            Err(Error::Geometry(_))
        ));
        let nan = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(matches!(
            umeyama(&nan, &tri, true),
            Err(Error::NonFinite { .. })
        ));
        assert!(umeyama(&tri, &a, true).is_err());
        // Weighted: zero weights drop pairs.
        assert!(umeyama_weighted(&tri, &tri, Some(&[1.0, 1.0, 0.0]), true).is_err());
        assert!(umeyama_weighted(&tri, &tri, Some(&[1.0, 1.0, -1.0]), true).is_err());
    }

    /// `n` source points on a smooth curve of size `spread` around `offset`, and their images
    /// under `truth` with a small deterministic noise.
    fn noisy_pairs(
        n: usize,
        spread: f64,
        offset: f64,
        truth: &Similarity,
    ) -> (Vec<Point3>, Vec<Point3>) {
        let src: Vec<Point3> = (0..n)
            .map(|i| {
                let f = i as f64;
                [
                    (f * 0.37).sin(),
                    (f * 0.11).cos() * 0.5,
                    (f * 0.07).sin() * 0.2,
                ]
                .map(|v| v * spread + offset)
            })
            .collect();
        let dst = src
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let q = truth.apply(*p);
                let e = 1e-3 * spread * ((i as f64) * 0.9).sin();
                [q[0] + e, q[1] - e, q[2] + 0.5 * e]
            })
            .collect();
        (src, dst)
    }

    /// The parallel sums give the one-by-one fit to rounding, across several runs of
    /// `PAIRS_PER_SUM`, at ordinary and at extreme spreads (where both divide by the spread),
    /// and the same bits on one thread as on several; degenerate pairs are errors as in
    /// `umeyama`.
    #[test]
    fn pairs_in_parallel_equal_the_one_by_one_fit() {
        let n = 3 * PAIRS_PER_SUM + 17;
        for spread in [1.0, 1e-120, 1e120] {
            let truth = Similarity::from_parts(
                1.7,
                rot([1.0, 2.0, -0.5], 31.0),
                [0.4, -3.0, 2.0].map(|v| v * spread),
            );
            let (src, dst) = noisy_pairs(n, spread, 5.0 * spread, &truth);
            let one = umeyama(&src, &dst, true).unwrap();
            let par = umeyama_pairs(n, |i| src[i], |i| dst[i]).unwrap();
            for r in 0..3 {
                for c in 0..4 {
                    // Rotation and scale entries are O(1), translations O(spread).
                    let size = if c == 3 { 10.0 * spread } else { 1.0 };
                    let (a, b) = (one.matrix[r][c], par.matrix[r][c]);
                    assert!((a - b).abs() <= 1e-12 * size, "{spread}: {a} vs {b}");
                }
            }
            #[cfg(feature = "parallel")]
            {
                let single = rayon::ThreadPoolBuilder::new()
                    .num_threads(1)
                    .build()
                    .unwrap();
                let alone = single.install(|| umeyama_pairs(n, |i| src[i], |i| dst[i]).unwrap());
                assert_eq!(alone.matrix, par.matrix);
            }
        }
        let line: Vec<Point3> = (0..10).map(|i| [f64::from(i); 3]).collect();
        assert!(umeyama_pairs(10, |i| line[i], |i| line[i]).is_err());
        assert!(umeyama_pairs(2, |i| line[i], |i| line[i]).is_err());
    }

    /// The one-pass sums, in runs merged in order, against the two-pass fit: within 1e-12 with
    /// shifts inside the clouds, near the origin or 100 to 7000 spreads from it; extreme spreads
    /// decline (the caller then takes the two-pass fit); fewer than 3 pairs and collinear points
    /// are errors.
    #[test]
    fn one_pass_sums_equal_the_two_pass_fit_or_decline() {
        let n = 10_000;
        for (spread, offset) in [
            (1.0, 0.0),
            (1.0, 100.0),
            (1e-3, 7.0),
            (1e-120, 0.0),
            (1e120, 0.0),
        ] {
            let truth = Similarity::from_parts(
                0.8,
                rot([0.2, -1.0, 0.4], -17.0),
                [0.4, -3.0, 2.0].map(|v| v * spread),
            );
            let (src, dst) = noisy_pairs(n, spread, offset, &truth);
            // Shifts a spread or so from each side's centroid.
            let shifts = (src[n / 2], truth.apply(src[n / 3]));
            let mut sums = PairSums::new(shifts.0, shifts.1);
            for run in (0..n).collect::<Vec<_>>().chunks(1000) {
                let mut part = PairSums::new(shifts.0, shifts.1);
                for &i in run {
                    part.add(src[i], dst[i]);
                }
                sums.merge(&part);
            }
            assert_eq!(sums.len(), n as u64);
            let Some(fitted) = sums.similarity() else {
                assert!(!(1e-90..=1e90).contains(&spread), "{spread} declined");
                continue;
            };
            assert!((1e-90..=1e90).contains(&spread), "{spread} accepted");
            let one_pass = fitted.unwrap();
            let two_pass = umeyama_pairs(n, |i| src[i], |i| dst[i]).unwrap();
            for r in 0..3 {
                for c in 0..4 {
                    let size = if c == 3 {
                        10.0 * (spread + offset)
                    } else {
                        1.0
                    };
                    let (a, b) = (one_pass.matrix[r][c], two_pass.matrix[r][c]);
                    assert!(
                        (a - b).abs() <= 1e-12 * size,
                        "{spread} {offset}: {a} vs {b}"
                    );
                }
            }
        }
        let line: Vec<Point3> = (0..10).map(|i| [f64::from(i); 3]).collect();
        let mut sums = PairSums::new([0.0; 3], [0.0; 3]);
        for p in &line[..2] {
            sums.add(*p, *p);
        }
        assert!(matches!(sums.similarity(), Some(Err(_))));
        for p in &line[2..] {
            sums.add(*p, *p);
        }
        assert!(matches!(sums.similarity(), Some(Err(_))));
    }

    /// The invariant test only answers "not collinear" where the eigenvalues say so too, and
    /// answers it for ordinary point sets (so that the eigen decomposition is skipped there).
    #[test]
    fn invariant_test_agrees_with_the_eigenvalues() {
        for thickness in [1.0, 1e-3, 1e-5, 1e-6, 3e-7, 1e-7, 3e-8, 1e-9, 0.0] {
            for tilt in [0.0, 0.3, 1.1] {
                let pts: Vec<Point3> = (0..12)
                    .map(|i| {
                        let f = f64::from(i);
                        let (u, v) = (f - 5.5, thickness * (f * 1.7).sin());
                        [u, v * (1.0 - tilt) + u * tilt, 2.0 + 0.5 * v]
                    })
                    .collect();
                let n = pts.len() as f64;
                let mu = pts.iter().fold(Vector3::zeros(), |m, p| m + to_v(*p)) / n;
                let cov = pts.iter().fold(Matrix3::zeros(), |c, p| {
                    let a = to_v(*p) - mu;
                    c + a * a.transpose()
                }) / n;
                let (l, _) = crate::align::sorted_eigen(&cov);
                let ratio = (l[1] / l[0]).sqrt();
                if clearly_not_collinear(&cov) {
                    assert!(
                        ratio >= 10.0 * COLLINEAR_RATIO,
                        "{thickness} {tilt}: {ratio}"
                    );
                }
                if ratio > 1e-5 {
                    assert!(clearly_not_collinear(&cov), "{thickness} {tilt}: {ratio}");
                }
            }
        }
    }
}
