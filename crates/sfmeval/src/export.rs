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

/// A binary little-endian PLY of points with `double` x, y, z (exact: every `f64` as it is),
/// and `uchar` red, green, blue only when `colors` is given (one per point); what `sfmeval
/// export` writes, so a front end evaluates the reconstruction's own positions, not a `float`
/// copy of them.
pub fn points_ply_f64(points: &[[f64; 3]], colors: Option<&[[u8; 3]]>) -> Vec<u8> {
    let colors = colors.filter(|c| c.len() == points.len());
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by sfmeval {}\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n{}end_header\n",
        env!("CARGO_PKG_VERSION"),
        points.len(),
        if colors.is_some() {
            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
        } else {
            ""
        }
    )
    .into_bytes();
    out.reserve(points.len() * if colors.is_some() { 27 } else { 24 });
    for (i, p) in points.iter().enumerate() {
        for v in p {
            out.extend_from_slice(&v.to_le_bytes());
        }
        if let Some(c) = colors.and_then(|c| c.get(i)) {
            out.extend_from_slice(c);
        }
    }
    out
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::points_ply_f64;
    use crate::io::ply::read_ply;

    #[test]
    fn points_ply_f64_keeps_every_bit_and_the_colours() {
        let points = [
            [0.1, -2.5e-9, 1.0 / 3.0],
            [1.234_567_890_123_456_7e40, 7.0, -0.0],
        ];
        let colors = [[1u8, 2, 3], [250, 251, 252]];
        for with in [false, true] {
            let bytes = points_ply_f64(&points, with.then_some(&colors[..]));
            let ply = read_ply(&bytes).unwrap();
            let props: Vec<&str> = ply.vertex_properties.iter().map(String::as_str).collect();
            let want: &[&str] = if with {
                &["x", "y", "z", "red", "green", "blue"]
            } else {
                &["x", "y", "z"]
            };
            assert_eq!(props, want);
            let header_end = bytes
                .windows(11)
                .position(|w| w == b"end_header\n")
                .unwrap()
                + 11;
            let stride = if with { 27 } else { 24 };
            assert_eq!(bytes.len(), header_end + 2 * stride);
            for (i, p) in points.iter().enumerate() {
                for (k, v) in p.iter().enumerate() {
                    let at = header_end + i * stride + 8 * k;
                    let got = f64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
                    assert_eq!(got.to_bits(), v.to_bits());
                }
                if with {
                    let at = header_end + i * stride + 24;
                    assert_eq!(&bytes[at..at + 3], &colors[i]);
                }
            }
        }
    }
}
