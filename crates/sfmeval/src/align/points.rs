//! The `points` stage: a similarity from ≥ 3 user-given point pairs (for instance clicked in
//! the browser page), read from `{"pairs": [{"recon": [x, y, z], "gt": [x, y, z]}, ...]}`.

use serde::{Deserialize, Serialize};

use super::{is_finite, make_stage, planarity_ratio};
use crate::error::{Error, Result};
use crate::geometry::Point3;
use crate::report::AlignmentStage;
use crate::transform::Similarity;

/// One correspondence: a point of the reconstruction and the same point in the ground truth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointPair {
    /// Position in the reconstruction's frame.
    pub recon: Point3,
    /// Position in the ground-truth frame.
    pub gt: Point3,
}

#[derive(Deserialize)]
struct PairsFile {
    pairs: Vec<PointPair>,
}

/// Parses a point-pairs file: `{"pairs": [{"recon": [x, y, z], "gt": [x, y, z]}, ...]}`
/// (a bare list of pairs is accepted too).
pub fn parse_point_pairs(bytes: &[u8]) -> Result<Vec<PointPair>> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| Error::malformed("point pairs", "not UTF-8 text"))?;
    let trimmed = text.trim_start();
    let pairs = if trimmed.starts_with('[') {
        serde_json::from_str::<Vec<PointPair>>(text)
    } else {
        serde_json::from_str::<PairsFile>(text).map(|f| f.pairs)
    }
    .map_err(|e| {
        Error::malformed(
            "point pairs",
            format!(
                "{e} (expected {{\"pairs\": [{{\"recon\": [x, y, z], \"gt\": [x, y, z]}}, ...]}})"
            ),
        )
    })?;
    check_finite(&pairs)?;
    Ok(pairs)
}

/// Fails on the first pair with a NaN or infinite coordinate (counting them all).
fn check_finite(pairs: &[PointPair]) -> Result<()> {
    let bad = |p: &PointPair| !(is_finite(&p.recon) && is_finite(&p.gt));
    match pairs.iter().position(bad) {
        Some(first_index) => Err(Error::NonFinite {
            format: "point pairs",
            what: "pair",
            count: pairs.iter().filter(|p| bad(p)).count(),
            first_index,
        }),
        None => Ok(()),
    }
}

/// Minimum √(λ₂/λ₁) of the picked points on either side: below it they are too close to a
/// line to fix the rotation about it.
const MIN_PLANARITY: f64 = 1e-3;

/// The `points` stage: the least-squares similarity of the pairs (all used; a user picks them
/// by hand). RMSE is the residual of the pairs in ground-truth units.
pub fn align_points(pairs: &[PointPair]) -> Result<(Similarity, AlignmentStage)> {
    if pairs.len() < 3 {
        return Err(Error::InvalidOption(format!(
            "the points alignment needs at least 3 point pairs, got {}",
            pairs.len()
        )));
    }
    let src: Vec<Point3> = pairs.iter().map(|p| p.recon).collect();
    let dst: Vec<Point3> = pairs.iter().map(|p| p.gt).collect();
    check_finite(pairs)?;
    for (name, set) in [("reconstruction", &src), ("ground-truth", &dst)] {
        let r = planarity_ratio(set);
        if !(r >= MIN_PLANARITY) {
            return Err(Error::Geometry(format!(
                "the {} {name} points of the pairs are (nearly) collinear or identical (spread ratio {r:.1e}): pick at least 3 points not on one line",
                pairs.len()
            )));
        }
    }
    let t = super::umeyama(&src, &dst, true)?;
    let ss: f64 = src
        .iter()
        .zip(&dst)
        .map(|(a, b)| sq_dist(t.apply(*a), *b))
        .sum();
    let rmse = (ss / pairs.len() as f64).sqrt();
    let stage = make_stage("points", &t, Some(rmse), Some(1.0), 1, true, None);
    Ok((t, stage))
}

pub(crate) fn sq_dist(a: Point3, b: Point3) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_align() {
        let json = br#"{"pairs": [
            {"recon": [0, 0, 0], "gt": [1, 1, 1]},
            {"recon": [1, 0, 0], "gt": [3, 1, 1]},
            {"recon": [0, 1, 0], "gt": [1, 3, 1]},
            {"recon": [0, 0, 1], "gt": [1, 1, 3]}]}"#;
        let pairs = parse_point_pairs(json).unwrap();
        let (t, stage) = align_points(&pairs).unwrap();
        assert!((t.scale() - 2.0).abs() < 1e-12);
        assert!(stage.rmse.unwrap() < 1e-12);
        assert_eq!(stage.method, "points");
        assert_eq!(
            parse_point_pairs(b"[{\"recon\": [0,0,0], \"gt\": [1,1,1]}]")
                .unwrap()
                .len(),
            1
        );
    }

    #[test]
    fn bad_pairs() {
        assert!(matches!(
            parse_point_pairs(b"{\"pairs\": 3}"),
            Err(Error::Malformed { .. })
        ));
        assert!(matches!(
            parse_point_pairs(b"{\"pairs\": [{\"recon\": [0,0], \"gt\": [1,1,1]}]}"),
            Err(Error::Malformed { .. })
        ));
        assert!(parse_point_pairs(b"\xff").is_err());
        let two = [
            PointPair {
                recon: [0.0; 3],
                gt: [0.0; 3],
            },
            PointPair {
                recon: [1.0, 0.0, 0.0],
                gt: [1.0, 0.0, 0.0],
            },
        ];
        assert!(matches!(align_points(&two), Err(Error::InvalidOption(_))));
        let line: Vec<PointPair> = (0..5)
            .map(|i| PointPair {
                recon: [f64::from(i), 0.0, 0.0],
                gt: [0.0, f64::from(i), 0.0],
            })
            .collect();
        assert!(matches!(align_points(&line), Err(Error::Geometry(_))));
        let same: Vec<PointPair> = (0..5)
            .map(|_| PointPair {
                recon: [1.0, 2.0, 3.0],
                gt: [1.0, 2.0, 3.0],
            })
            .collect();
        assert!(matches!(align_points(&same), Err(Error::Geometry(_))));
        let mut nan = line.clone();
        nan[0].gt[1] = f64::NAN;
        assert!(matches!(align_points(&nan), Err(Error::NonFinite { .. })));
    }
}
