//! The coloured error clouds the evaluator writes, `vis_{scan:03}_d2s.ply` (the down-sampled
//! reconstruction) and `vis_{scan:03}_s2d.ply` (the STL points): blue outside the bounding box
//! or the observation mask (below the ground plane for the STL points), green at `max_dist` or
//! more, white to red up to the visualisation threshold. Written as Open3D's
//! `write_point_cloud` writes the port's: binary little endian, `double` x y z and `uchar`
//! colours rounded from `[0, 1]` × 255, so the bodies are the port's byte for byte.

use sfmeval::geometry::Point3;

use crate::protocol::DtuEvaluation;

const BLUE: [f64; 3] = [0.0, 0.0, 1.0];
const GREEN: [f64; 3] = [0.0, 1.0, 0.0];

/// `R * alpha + W * (1 - alpha)` per channel, in the port's operations.
fn error_colour(d: f64, max_dist: f64, vis: f64) -> [f64; 3] {
    if d >= max_dist {
        return GREEN;
    }
    let a = d.min(vis) / vis;
    let r = [1.0, 0.0, 0.0];
    r.map(|c| c * a + 1.0 * (1.0 - a))
}

/// Open3D's colour conversion: clamp to [0, 1], × 255, rounded half away from zero.
fn to_u8(c: f64) -> u8 {
    (c.clamp(0.0, 1.0) * 255.0).round() as u8
}

fn ply(points: &[Point3], colours: &[[f64; 3]]) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment Created by sfmeval\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
        points.len()
    )
    .into_bytes();
    out.reserve(points.len() * 27);
    for (p, c) in points.iter().zip(colours) {
        for v in p {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend(c.map(to_u8));
    }
    out
}

/// The d2s cloud: every down-sampled point.
pub fn d2s_ply(e: &DtuEvaluation) -> Vec<u8> {
    let mut colours = vec![BLUE; e.downsampled.len()];
    for (&i, &d) in e.observed.iter().zip(&e.d2s) {
        colours[i as usize] = error_colour(d, e.options.max_dist, e.options.visualize_threshold);
    }
    ply(&e.downsampled, &colours)
}

/// The s2d cloud: every STL point.
pub fn s2d_ply(e: &DtuEvaluation, stl: &[Point3]) -> Vec<u8> {
    let mut colours = vec![BLUE; stl.len()];
    for (&i, &d) in e.above.iter().zip(&e.s2d) {
        colours[i as usize] = error_colour(d, e.options.max_dist, e.options.visualize_threshold);
    }
    ply(stl, &colours)
}

/// The two files' names for scan `scan`.
pub fn vis_names(scan: u32) -> (String, String) {
    (
        format!("vis_{scan:03}_d2s.ply"),
        format!("vis_{scan:03}_s2d.ply"),
    )
}

/// The evaluator's two coloured error clouds of evaluation `e` on scan number `scan` (`stl`
/// its STL points), by file name: what every front end writes into its output folder.
pub fn output_files(e: &DtuEvaluation, scan: u32, stl: &[Point3]) -> [(String, Vec<u8>); 2] {
    let (d2s, s2d) = vis_names(scan);
    [(d2s, d2s_ply(e)), (s2d, s2d_ply(e, stl))]
}
