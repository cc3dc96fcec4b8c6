//! The `points` stage: a similarity from ≥ 3 user-given point pairs (for instance clicked in
//! the browser page), read from `{"pairs": [{"recon": [x, y, z], "gt": [x, y, z]}, ...]}`.

use serde::{Deserialize, Serialize};

use super::{AlignStage, StageKind, is_finite, make_stage, planarity_ratio};
use crate::error::{Error, Result};
use crate::geometry::{MAX_COORDINATE, Point3, show};
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

/// The format name of every error about a pairs file ([`Error::concerns_point_pairs`]).
pub(crate) const PAIRS_FORMAT: &str = crate::error::POINT_PAIRS_FORMAT;

/// Parses a point-pairs file: `{"pairs": [{"recon": [x, y, z], "gt": [x, y, z]}, ...]}`
/// (a bare list of pairs is accepted too). Coordinates must be finite and within
/// ±1e50 ([`Error::OutOfRange`] naming the pair and the side otherwise).
pub fn parse_point_pairs(bytes: &[u8]) -> Result<Vec<PointPair>> {
    let text =
        std::str::from_utf8(bytes).map_err(|_| Error::malformed(PAIRS_FORMAT, "not UTF-8 text"))?;
    let trimmed = text.trim_start();
    let pairs = if trimmed.starts_with('[') {
        serde_json::from_str::<Vec<PointPair>>(text)
    } else {
        serde_json::from_str::<PairsFile>(text).map(|f| f.pairs)
    }
    .map_err(|e| {
        Error::malformed(
            PAIRS_FORMAT,
            format!(
                "{e} (expected {{\"pairs\": [{{\"recon\": [x, y, z], \"gt\": [x, y, z]}}, ...]}})"
            ),
        )
    })?;
    check_finite(&pairs)?;
    Ok(pairs)
}

/// Fails on the first pair with a NaN or infinite coordinate (counting them all), then on the
/// first coordinate beyond ±[`MAX_COORDINATE`].
fn check_finite(pairs: &[PointPair]) -> Result<()> {
    let bad = |p: &PointPair| !(is_finite(&p.recon) && is_finite(&p.gt));
    if let Some(first_index) = pairs.iter().position(bad) {
        return Err(Error::NonFinite {
            format: PAIRS_FORMAT,
            what: "pair",
            count: pairs.iter().filter(|p| bad(p)).count(),
            first_index,
        });
    }
    for (i, p) in pairs.iter().enumerate() {
        for (side, v) in [("recon", p.recon), ("gt", p.gt)] {
            if let Some(k) = (0..3).find(|&k| !(v[k].abs() <= MAX_COORDINATE)) {
                return Err(Error::out_of_range(
                    PAIRS_FORMAT,
                    format!("pair #{i}"),
                    format!("{side}[{k}]"),
                    format!(
                        "is {}, beyond ±{} (the largest coordinate measured)",
                        show(v[k]),
                        show(MAX_COORDINATE)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Minimum √(λ₂/λ₁) of the picked points on either side: below it they are too close to a
/// line to fix the rotation about it.
const MIN_PLANARITY: f64 = 1e-3;

/// The `points` stage: the least-squares similarity of the pairs (all used; a user picks them
/// by hand). RMSE is the residual of the pairs in ground-truth units. Every failure is an
/// [`Error::PointPairs`] (too few pairs, collinear or identical points, out-of-range values, no
/// similarity), so front ends can name the pairs file.
pub fn align_points(pairs: &[PointPair]) -> Result<(Similarity, AlignStage)> {
    align_points_inner(pairs).map_err(|e| match e {
        Error::PointPairs(_) => e,
        other => Error::PointPairs(other.to_string()),
    })
}

fn align_points_inner(pairs: &[PointPair]) -> Result<(Similarity, AlignStage)> {
    if pairs.len() < 3 {
        return Err(Error::PointPairs(format!(
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
            return Err(Error::PointPairs(format!(
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
    let stage = make_stage(
        StageKind::Points,
        &t,
        Some(rmse),
        Some(1.0),
        1,
        true,
        Vec::new(),
    );
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
        assert_eq!(stage.kind, StageKind::Points);
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
        assert!(matches!(align_points(&two), Err(Error::PointPairs(_))));
        let line: Vec<PointPair> = (0..5)
            .map(|i| PointPair {
                recon: [f64::from(i), 0.0, 0.0],
                gt: [0.0, f64::from(i), 0.0],
            })
            .collect();
        let e = align_points(&line).unwrap_err();
        assert!(matches!(e, Error::PointPairs(_)) && e.concerns_point_pairs());
        assert!(e.to_string().starts_with("point pairs: ") && e.to_string().contains("collinear"));
        let same: Vec<PointPair> = (0..5)
            .map(|_| PointPair {
                recon: [1.0, 2.0, 3.0],
                gt: [1.0, 2.0, 3.0],
            })
            .collect();
        assert!(matches!(align_points(&same), Err(Error::PointPairs(_))));
        let mut nan = line.clone();
        nan[0].gt[1] = f64::NAN;
        let e = align_points(&nan).unwrap_err();
        assert!(matches!(e, Error::PointPairs(_)) && e.to_string().contains("non-finite"));
        // Huge but finite: refused with the pair and the side, and the file is the pairs'.
        let e = parse_point_pairs(
            br#"[{"recon": [0,0,0], "gt": [1,1,1]}, {"recon": [1e150, 0, 0], "gt": [2,1,1]}]"#,
        )
        .unwrap_err();
        assert_eq!(e.kind(), "out_of_range");
        assert!(e.concerns_point_pairs());
        let msg = e.to_string();
        assert!(
            msg.contains("pair #1") && msg.contains("recon[0]") && msg.contains("1e150"),
            "{msg}"
        );
        assert!(
            parse_point_pairs(b"{\"pairs\": 3}")
                .unwrap_err()
                .concerns_point_pairs()
        );
    }
}
