//! The coloured clouds the tool writes, one per tolerance, byte for byte as PCL 1.13's
//! `savePLYFileBinary` writes a `PointXYZRGB` cloud: `<base>.tolerance_<t>.ply` (`t` as
//! `std::ostream` prints a `float`, `%g`), binary little endian with `float` x y z, `uchar`
//! colours, an empty `face` element and PCL's `camera` element.
//! - Accuracy (the reconstruction's points): green accurate, red inaccurate, blue unobserved.
//! - Completeness (the scan points in the global frame, scans in the project's order): green
//!   complete, red incomplete.

use crate::protocol::Eth3dEvaluation;

const GREEN: [u8; 3] = [0, 255, 0];
const RED: [u8; 3] = [255, 0, 0];
const BLUE: [u8; 3] = [0, 0, 255];

/// `v` as C's `%g` prints it (6 significant digits, trailing zeros removed, an exponent of at
/// least two digits when below 1e-4 or from 1e6 on).
pub fn format_g(v: f64) -> String {
    const P: i32 = 6;
    if v == 0.0 {
        return if v.is_sign_negative() { "-0" } else { "0" }.into();
    }
    if !v.is_finite() {
        return if v.is_nan() {
            "nan".into()
        } else if v > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    let sci = format!("{:.*e}", (P - 1) as usize, v);
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let strip = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if !(-4..P).contains(&exp) {
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", strip(mantissa), exp.abs())
    } else {
        strip(&format!("{:.*}", (P - 1 - exp) as usize, v))
    }
}

/// The file name the tool gives tolerance `t`'s cloud of `base`.
pub fn file_name(base: &str, tolerance: f32) -> String {
    format!("{base}.tolerance_{}.ply", format_g(f64::from(tolerance)))
}

/// A `PointXYZRGB` cloud as PCL writes it.
pub fn pcl_ply(points: &[[f32; 3]], colours: impl Iterator<Item = [u8; 3]>) -> Vec<u8> {
    let mut cloud = PclCloud::new(points);
    cloud.colour(colours);
    cloud.bytes
}

/// A `PointXYZRGB` cloud encoded once and coloured again for each tolerance: a kind's clouds
/// differ only in their colour bytes.
#[derive(Debug, Clone)]
pub struct PclCloud {
    bytes: Vec<u8>,
    /// Where the first vertex starts.
    vertices: usize,
    n: usize,
}

/// Bytes a vertex: `float` x, y, z and three `uchar` colours.
const VERTEX_BYTES: usize = 15;

impl PclCloud {
    /// `points` encoded, every colour black.
    pub fn new(points: &[[f32; 3]]) -> PclCloud {
        let n = points.len();
        let mut bytes = format!(
            "ply\nformat binary_little_endian 1.0\ncomment PCL generated\nelement vertex {n}\n\
             property float x\nproperty float y\nproperty float z\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\n\
             element face 0\nelement camera 1\n\
             property float view_px\nproperty float view_py\nproperty float view_pz\n\
             property float x_axisx\nproperty float x_axisy\nproperty float x_axisz\n\
             property float y_axisx\nproperty float y_axisy\nproperty float y_axisz\n\
             property float z_axisx\nproperty float z_axisy\nproperty float z_axisz\n\
             property float focal\nproperty float scalex\nproperty float scaley\n\
             property float centerx\nproperty float centery\n\
             property int viewportx\nproperty int viewporty\n\
             property float k1\nproperty float k2\nend_header\n"
        )
        .into_bytes();
        let vertices = bytes.len();
        bytes.reserve(n * VERTEX_BYTES + 84);
        for p in points {
            for v in p {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            bytes.extend_from_slice(&[0; 3]);
        }
        // The camera: the sensor at the origin, identity axes, zeros, the viewport width × 1.
        let camera: [f32; 17] = [
            0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ];
        for v in camera {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&(n as i32).to_le_bytes());
        bytes.extend_from_slice(&1i32.to_le_bytes());
        bytes.extend_from_slice(&0f32.to_le_bytes());
        bytes.extend_from_slice(&0f32.to_le_bytes());
        PclCloud { bytes, vertices, n }
    }

    /// The file with the points coloured by `colours` (one a point, in order; points past
    /// its end keep their colour).
    pub fn colour(&mut self, colours: impl Iterator<Item = [u8; 3]>) -> &[u8] {
        let vertices = &mut self.bytes[self.vertices..self.vertices + self.n * VERTEX_BYTES];
        for (vertex, c) in vertices.chunks_exact_mut(VERTEX_BYTES).zip(colours) {
            vertex[12..].copy_from_slice(&c);
        }
        &self.bytes
    }
}

/// Tolerance index `t`'s colours of the accuracy cloud: green accurate, red inaccurate, blue
/// unobserved.
pub fn accuracy_colours(e: &Eth3dEvaluation, t: usize) -> impl Iterator<Item = [u8; 3]> + '_ {
    e.first_accurate
        .iter()
        .zip(&e.inaccurate)
        .map(move |(&first, &inaccurate)| {
            if t as u32 >= first {
                GREEN
            } else if inaccurate {
                RED
            } else {
                BLUE
            }
        })
}

/// Tolerance index `t`'s colours of the completeness cloud: green complete, red incomplete.
pub fn completeness_colours(e: &Eth3dEvaluation, t: usize) -> impl Iterator<Item = [u8; 3]> + '_ {
    e.first_complete
        .iter()
        .map(move |&first| if t as u32 >= first { GREEN } else { RED })
}

/// Tolerance index `t`'s accuracy cloud of `reconstruction`.
pub fn accuracy_ply(e: &Eth3dEvaluation, reconstruction: &[[f32; 3]], t: usize) -> Vec<u8> {
    pcl_ply(reconstruction, accuracy_colours(e, t))
}

/// Tolerance index `t`'s completeness cloud.
pub fn completeness_ply(e: &Eth3dEvaluation, t: usize) -> Vec<u8> {
    pcl_ply(&e.scan_points, completeness_colours(e, t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerances_print_as_ostream_prints_floats() {
        assert_eq!(file_name("a", 0.01), "a.tolerance_0.01.ply");
        assert_eq!(file_name("a", 0.5), "a.tolerance_0.5.ply");
        assert_eq!(file_name("a", 2.0), "a.tolerance_2.ply");
        assert_eq!(format_g(f64::from(0.1f32)), "0.1");
        assert_eq!(format_g(0.00001), "1e-05");
        assert_eq!(format_g(0.000123456789), "0.000123457");
        assert_eq!(format_g(1234567.0), "1.23457e+06");
        assert_eq!(format_g(100.0), "100");
        assert_eq!(format_g(0.0), "0");
    }

    #[test]
    fn a_recoloured_cloud_is_the_cloud_encoded_with_those_colours() {
        let points = [[1.0f32, -2.0, 3.5], [0.25, 0.0, -1.0], [7.0, 8.0, 9.0]];
        let first = [[1u8, 2, 3], [4, 5, 6], [7, 8, 9]];
        let second = [GREEN, RED, BLUE];
        let mut cloud = PclCloud::new(&points);
        assert_eq!(
            cloud.colour(first.into_iter()),
            pcl_ply(&points, first.into_iter())
        );
        assert_eq!(
            cloud.colour(second.into_iter()),
            pcl_ply(&points, second.into_iter())
        );
        let bytes = pcl_ply(&points, second.into_iter());
        let header = bytes.len() - 3 * VERTEX_BYTES - 84;
        assert!(bytes[..header].ends_with(b"end_header\n"));
        assert_eq!(&bytes[header + 12..header + 15], &GREEN);
        assert_eq!(&bytes[header + 27..header + 30], &RED);
        assert_eq!(&bytes[header..header + 4], &1.0f32.to_le_bytes());
    }
}
