//! The toolbox's coloured clouds (`write_color_distances`): each point coloured by
//! matplotlib's `hot_r` map at `min(d, max) / max` (max = 3τ), written as a PLY with the
//! distance as a property too. The map is built as matplotlib builds it: a 256-entry lookup table
//! interpolated from `hot`'s segment data reversed, a value `x` picking entry `⌊256·x⌋` (the last
//! for `x = 1`); Open3D stores a channel `c` as the byte nearest `255·c`.

use std::sync::OnceLock;

use sfmeval::geometry::Point3;

/// Lookup-table size (matplotlib's default `N`).
const N: usize = 256;

/// matplotlib's `_hot_data`: per channel, `(x, y_left, y_right)` anchors.
const HOT: [&[(f64, f64, f64)]; 3] = [
    &[(0.0, 0.0416, 0.0416), (0.365079, 1.0, 1.0), (1.0, 1.0, 1.0)],
    &[
        (0.0, 0.0, 0.0),
        (0.365079, 0.0, 0.0),
        (0.746032, 1.0, 1.0),
        (1.0, 1.0, 1.0),
    ],
    &[(0.0, 0.0, 0.0), (0.746032, 0.0, 0.0), (1.0, 1.0, 1.0)],
];

/// One channel's table from its anchors (matplotlib's `_create_lookup_table`, gamma 1).
fn channel_table(anchors: &[(f64, f64, f64)]) -> [f64; N] {
    let x: Vec<f64> = anchors.iter().map(|a| a.0 * (N - 1) as f64).collect();
    let mut lut = [0.0; N];
    lut[0] = anchors[0].2;
    lut[N - 1] = anchors[anchors.len() - 1].1;
    for (i, v) in lut.iter_mut().enumerate().take(N - 1).skip(1) {
        // numpy.linspace(0, 1, N)[i] * (N - 1)
        let xi = (N - 1) as f64 * (i as f64 * (1.0 / (N - 1) as f64));
        // searchsorted (left): first anchor ≥ xi
        let j = x.partition_point(|a| *a < xi).clamp(1, x.len() - 1);
        let distance = (xi - x[j - 1]) / (x[j] - x[j - 1]);
        *v = (distance * (anchors[j].1 - anchors[j - 1].2) + anchors[j - 1].2).clamp(0.0, 1.0);
    }
    lut
}

/// The `hot_r` table: `hot`'s anchors reversed (`x → 1 − x`, left and right values swapped).
fn hot_r_table() -> &'static [[f64; 3]; N] {
    static TABLE: OnceLock<[[f64; 3]; N]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut rgb = [[0.0; 3]; N];
        for (c, anchors) in HOT.iter().enumerate() {
            let reversed: Vec<(f64, f64, f64)> = anchors
                .iter()
                .rev()
                .map(|&(x, y0, y1)| (1.0 - x, y1, y0))
                .collect();
            for (i, v) in channel_table(&reversed).iter().enumerate() {
                rgb[i][c] = *v;
            }
        }
        rgb
    })
}

/// The `hot_r` colour (channels in 0..1) of a value in 0..1.
pub fn hot_r(x: f64) -> [f64; 3] {
    let scaled = x * N as f64;
    let i = if scaled == N as f64 {
        N - 1
    } else {
        (scaled.clamp(-1.0, N as f64) as i64).clamp(0, N as i64 - 1) as usize
    };
    hot_r_table()[i]
}

/// The byte Open3D's PLY writer stores for a channel: `255·c` rounded, within 0..=255.
pub fn channel_byte(c: f64) -> u8 {
    (c * 255.0).clamp(0.0, 255.0).round() as u8
}

/// A binary little-endian PLY: `double x y z`, `uchar red green blue` (hot_r of the distance
/// clipped at `max_distance`) and `double distance`.
pub fn distance_ply(points: &[Point3], distances: &[f64], max_distance: f64) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by sfmeval (Tanks and Temples protocol): colour = hot_r(min(distance, {max_distance}) / {max_distance})\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty double distance\nend_header\n",
        points.len()
    )
    .into_bytes();
    out.reserve(points.len() * 35);
    for (p, d) in points.iter().zip(distances) {
        for v in p {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let c = hot_r(d.min(max_distance) / max_distance);
        out.extend(c.map(channel_byte));
        out.extend_from_slice(&d.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hot_r_ends_and_ramps() {
        // x = 0 is hot's top (white), x = 1 its bottom (dark red 0.0416).
        assert_eq!(hot_r(0.0), [1.0, 1.0, 1.0]);
        assert_eq!(hot_r(1.0), [0.0416, 0.0, 0.0]);
        // Past 1 - 0.365079 only red remains, falling; before 1 - 0.746032 blue is still on.
        let c = hot_r(0.8);
        assert!(c[1] == 0.0 && c[2] == 0.0 && c[0] > 0.0416 && c[0] < 1.0);
        let c = hot_r(0.1);
        assert!(c[0] == 1.0 && c[1] == 1.0 && c[2] > 0.0 && c[2] < 1.0);
        assert_eq!(channel_byte(1.0), 255);
        assert_eq!(channel_byte(0.0416), 11);
        let ply = distance_ply(&[[0.0; 3]], &[0.5], 1.0);
        assert!(ply.starts_with(b"ply\nformat binary_little_endian"));
        assert_eq!(
            ply.len() - ply.windows(11).position(|w| w == b"end_header\n").unwrap() - 11,
            35
        );
    }
}
