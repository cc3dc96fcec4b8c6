//! Exports: the reconstruction coloured by error (binary PLY with a `distance` scalar) and
//! per-point distances (CSV). Both return bytes; front ends write them to disk atomically.

use std::fmt::Write as _;

use crate::colormap::distance_color;
use crate::evaluate::{Evaluation, PointStatus};

/// Binary little-endian PLY of every kept point in the ground-truth frame, coloured by its
/// distance clipped at `clip` (viridis), with `float distance` (and `float signed_distance`).
pub fn colored_ply(eval: &Evaluation, clip: f64) -> Vec<u8> {
    let kept = eval
        .status
        .iter()
        .filter(|&&s| s == PointStatus::Kept)
        .count();
    let signed = eval.signed_distances.as_ref();
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment sfmeval {} error heat map, distances clipped at {clip} for colour\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty float distance\n",
        env!("CARGO_PKG_VERSION"),
        kept
    );
    if signed.is_some() {
        header.push_str("property float signed_distance\n");
    }
    header.push_str("end_header\n");
    let mut out = header.into_bytes();
    out.reserve(kept * 35);
    eval.for_each_point_in_gt(|i, p| {
        if eval.status[i] != PointStatus::Kept {
            return;
        }
        for c in p {
            out.extend(c.to_le_bytes());
        }
        out.extend(distance_color(eval.distances[i], clip));
        out.extend((eval.distances[i] as f32).to_le_bytes());
        if let Some(s) = signed {
            out.extend((s[i] as f32).to_le_bytes());
        }
    });
    out
}

/// CSV with one row per reconstructed point: index, position in the ground-truth frame,
/// distance, signed distance (empty when not computed) and status (`kept`, `outside_volume`,
/// `too_far`); with depth maps and tracks, a last column `track_error` (empty when the point
/// was not measured).
pub fn distances_csv(eval: &Evaluation) -> String {
    let mut s = String::with_capacity(eval.point_count() * 64);
    s.push_str("index,x,y,z,distance,signed_distance,status");
    let track = eval.track_errors.as_ref();
    s.push_str(if track.is_some() {
        ",track_error\n"
    } else {
        "\n"
    });
    eval.for_each_point_in_gt(|i, p| {
        let signed = eval
            .signed_distances
            .as_ref()
            .map(|v| v[i].to_string())
            .unwrap_or_default();
        let status = match eval.status[i] {
            PointStatus::Kept => "kept",
            PointStatus::OutsideVolume => "outside_volume",
            PointStatus::TooFar => "too_far",
        };
        let _ = write!(
            s,
            "{i},{},{},{},{},{signed},{status}",
            p[0], p[1], p[2], eval.distances[i]
        );
        if let Some(t) = track {
            let v = t.get(i).copied().flatten();
            let _ = write!(s, ",{}", v.map(|v| v.to_string()).unwrap_or_default());
        }
        s.push('\n');
    });
    s
}

/// CSV with one row per completeness sample (inside the crop volume): index, position in the
/// ground-truth frame, distance to the reconstruction, and with depth maps the number of
/// ground-truth images that see it and its label (`covered`, `missed`, `unseen`).
pub fn samples_csv(eval: &Evaluation) -> String {
    use crate::visibility::SampleLabel;
    let mut s = String::with_capacity(eval.completeness_points.len() * 64);
    s.push_str("index,x,y,z,distance,views,label\n");
    for (i, p) in eval.completeness_points.iter().enumerate() {
        let views = eval
            .sample_views
            .as_ref()
            .and_then(|v| v.get(i))
            .map(|v| v.to_string())
            .unwrap_or_default();
        let label = match eval.sample_labels.as_ref().and_then(|l| l.get(i)) {
            Some(SampleLabel::Covered) => "covered",
            Some(SampleLabel::Missed) => "missed",
            Some(SampleLabel::Unseen) => "unseen",
            None => "",
        };
        let d = eval
            .completeness_distances
            .get(i)
            .copied()
            .unwrap_or(f64::NAN);
        let _ = writeln!(s, "{i},{},{},{},{d},{views},{label}", p[0], p[1], p[2]);
    }
    s
}
/// A binary little-endian PLY of points (float x y z, uchar red green blue; white without
/// colours), as COLMAP writes its sparse clouds.
pub fn points_ply(points: &[[f64; 3]], colors: Option<&[[u8; 3]]>) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by sfmeval\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
        points.len()
    )
    .into_bytes();
    out.reserve(points.len() * 15);
    for (i, p) in points.iter().enumerate() {
        for v in p {
            out.extend_from_slice(&(*v as f32).to_le_bytes());
        }
        let c = colors
            .and_then(|c| c.get(i))
            .copied()
            .unwrap_or([255, 255, 255]);
        out.extend_from_slice(&c);
    }
    out
}
