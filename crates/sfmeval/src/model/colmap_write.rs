//! Writes a model as COLMAP text (`cameras.txt`, `images.txt`, `points3D.txt`), the writer
//! beside [`super::colmap`]'s reader: for tools whose own output is another format (NVM,
//! Bundler) and for exporting any model sfmeval reads.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::{Camera, Reconstruction};

/// Whether COLMAP knows `camera`'s model with that many parameters (NVM's `NVM_RADIAL`,
/// Bundler's `BUNDLER_RADIAL` and OpenMVG's models are not COLMAP models).
pub fn is_colmap_camera(camera: &Camera) -> bool {
    super::colmap::camera_model_by_name(&camera.model)
        .is_some_and(|m| m.num_params == camera.params.len())
}

/// A COLMAP text model (cameras.txt, images.txt, points3D.txt) of `rec`, for tools whose own
/// output is another format (NVM, Bundler). Image and point ids are 1-based indices. A camera
/// whose model COLMAP lacks ([`is_colmap_camera`]) is written as `PINHOLE fx fy cx cy`, without
/// its distortion (width and height stay 0 when the format stores none).
pub fn write_colmap_text(rec: &Reconstruction) -> BTreeMap<&'static str, String> {
    let mut cams = String::from(
        "# Camera list written by sfmeval\n# CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n",
    );
    for c in &rec.cameras {
        let (model, params): (&str, Vec<f64>) = if is_colmap_camera(c) {
            (c.model.as_str(), c.params.clone())
        } else {
            ("PINHOLE", vec![c.fx, c.fy, c.cx, c.cy])
        };
        let params: Vec<String> = params.iter().map(|v| v.to_string()).collect();
        let _ = writeln!(
            cams,
            "{} {} {} {} {}",
            c.id,
            model,
            c.width,
            c.height,
            params.join(" ")
        );
    }
    let mut imgs = String::from(
        "# Image list written by sfmeval\n# IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n# POINTS2D[] as (X, Y, POINT3D_ID)\n",
    );
    for (i, im) in rec.images.iter().enumerate() {
        let q = quaternion(&im.cam_from_world.rotation);
        let t = im.cam_from_world.translation;
        let _ = writeln!(
            imgs,
            "{} {} {} {} {} {} {} {} {} {}",
            i + 1,
            q[0],
            q[1],
            q[2],
            q[3],
            t[0],
            t[1],
            t[2],
            im.camera_id,
            im.name
        );
        let obs: Vec<String> = im
            .observations
            .iter()
            .map(|o| {
                let id = o.point.map_or(-1, |p| p as i64 + 1);
                format!("{} {} {id}", o.xy[0], o.xy[1])
            })
            .collect();
        let _ = writeln!(imgs, "{}", obs.join(" "));
    }
    let mut pts = String::from(
        "# 3D point list written by sfmeval\n# POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n",
    );
    for (i, p) in rec.points.iter().enumerate() {
        let c = p.color.unwrap_or([255, 255, 255]);
        let track: Vec<String> = p
            .track
            .iter()
            .map(|t| format!("{} {}", t.image + 1, t.keypoint))
            .collect();
        let _ = writeln!(
            pts,
            "{} {} {} {} {} {} {} {} {}",
            i + 1,
            p.xyz[0],
            p.xyz[1],
            p.xyz[2],
            c[0],
            c[1],
            c[2],
            p.error.unwrap_or(0.0),
            track.join(" ")
        );
    }
    BTreeMap::from([
        ("cameras.txt", cams),
        ("images.txt", imgs),
        ("points3D.txt", pts),
    ])
}

/// Unit quaternion `[w, x, y, z]` of a rotation matrix (Shepperd's method).
pub(crate) fn quaternion(r: &[[f64; 3]; 3]) -> [f64; 4] {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let q = if tr > 0.0 {
        let s = libm::sqrt(tr + 1.0) * 2.0;
        [
            0.25 * s,
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
        ]
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = libm::sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2.0;
        [
            (r[2][1] - r[1][2]) / s,
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
        ]
    } else if r[1][1] > r[2][2] {
        let s = libm::sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2.0;
        [
            (r[0][2] - r[2][0]) / s,
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
        ]
    } else {
        let s = libm::sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2.0;
        [
            (r[1][0] - r[0][1]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
        ]
    };
    let n = libm::sqrt(q.iter().map(|v| v * v).sum::<f64>());
    let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
    q.map(|v| sign * v / n)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used, clippy::disallowed_methods)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_round_trip() {
        for q in [
            [1.0, 0.0, 0.0, 0.0],
            [0.5, 0.5, -0.5, 0.5],
            [0.1, -0.7, 0.2, 0.67],
        ] {
            let n = (q as [f64; 4]).iter().map(|v| v * v).sum::<f64>().sqrt();
            let q = q.map(|v| v / n);
            let r = crate::model::quaternion_to_matrix(q).unwrap();
            let back = quaternion(&r);
            for k in 0..4 {
                assert!((back[k] - q[k]).abs() < 1e-12, "{q:?} {back:?}");
            }
        }
    }

    /// The model in written COLMAP text files, read back by the core.
    fn read_back(written: BTreeMap<&'static str, String>) -> Reconstruction {
        let files: BTreeMap<String, Vec<u8>> = written
            .into_iter()
            .map(|(k, v)| (k.to_string(), v.into_bytes()))
            .collect();
        crate::model::read_model_files(&files).unwrap()
    }

    #[test]
    fn nvm_cameras_become_pinhole_in_write_colmap_text() {
        // NVM_V3: 2 cameras (name f qw qx qy qz cx cy cz r 0), 1 point (xyz rgb, 2 measurements).
        let nvm = "NVM_V3\n\n2\na.jpg 700 1 0 0 0 0 0 -5 0.01 0\nb.jpg 710 1 0 0 0 1 0 -5 0 0\n\n1\n0.1 0.2 0.3 10 20 30 2 0 0 12.5 -3 1 0 40 -3\n";
        let files: BTreeMap<String, Vec<u8>> =
            BTreeMap::from([("m.nvm".to_string(), nvm.as_bytes().to_vec())]);
        let rec = crate::model::read_model_files(&files).unwrap();
        assert!(rec.cameras.iter().all(|c| !is_colmap_camera(c)));
        let written = write_colmap_text(&rec);
        assert!(written["cameras.txt"].contains(" PINHOLE 0 0 710 710 0 0\n"));
        let back = read_back(written);
        assert_eq!(back.images.len(), 2);
        assert_eq!(back.points.len(), 1);
        for (a, b) in rec.images.iter().zip(&back.images) {
            assert_eq!(a.name, b.name);
            let (ca, cb) = (a.cam_from_world.center(), b.cam_from_world.center());
            assert!(
                (0..3).all(|k| (ca[k] - cb[k]).abs() < 1e-12),
                "{ca:?} {cb:?}"
            );
        }
        let (fa, fb): (Vec<f64>, Vec<f64>) = (
            rec.cameras.iter().map(|c| c.fx).collect(),
            back.cameras.iter().map(|c| c.fx).collect(),
        );
        assert_eq!(fa, fb);
    }

    #[test]
    fn colmap_text_reads_back() {
        let files: BTreeMap<String, Vec<u8>> = [
            ("cameras.txt", "1 PINHOLE 640 360 700 700 320 180\n"),
            ("images.txt", "1 1 0 0 0 0 0 5 1 a.jpg\n10 20 1 30 40 -1\n2 0.7071067811865476 0 0.7071067811865476 0 1 0 5 1 b.jpg\n11 21 1\n"),
            ("points3D.txt", "1 0.1 0.2 0.3 10 20 30 0.5 1 0 2 0\n"),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.as_bytes().to_vec()))
        .collect();
        let rec = crate::model::read_model_files(&files).unwrap();
        let back = read_back(write_colmap_text(&rec));
        assert_eq!(back.images.len(), 2);
        assert_eq!(back.points.len(), 1);
        assert_eq!(back.points[0].track.len(), 2);
        for (a, b) in rec.images.iter().zip(&back.images) {
            assert_eq!(a.name, b.name);
            for k in 0..3 {
                assert!((a.center()[k] - b.center()[k]).abs() < 1e-9);
            }
        }
        let ply = crate::export::points_ply(&[[1.0, 2.0, 3.0]], None);
        let cloud = crate::io::read_point_cloud("x.ply", &ply).unwrap();
        assert_eq!(cloud.cloud.points, vec![[1.0, 2.0, 3.0]].into());
    }
}
