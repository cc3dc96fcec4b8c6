//! Bundler `.out` v0.3 (+ the image list), `research/formats.md`. Bundler's camera looks down
//! −Z with +Y up (OpenGL style): rows 2 and 3 of R and entries 2 and 3 of t are negated to get the
//! OpenCV/COLMAP `cam_from_world`. Cameras are in list order; a camera of all zeros (f = 0) is
//! unregistered. Bundler stores no image size or principal point (the image centre).

use super::text::{self, Tokens};
use super::{Camera, Image, Point3D, Reconstruction, Rigid};
use crate::error::{Error, Result};
use crate::note::{Code, Note};

const FMT: &str = "Bundler";

/// Reads a Bundler `.out` file; `list` is the companion `list.txt` (one image per line, the name
/// first, optionally followed by `0 f`). Without a list, images are named `camera_N`.
pub fn read_bundler(out: &[u8], list: Option<&[u8]>) -> Result<Reconstruction> {
    let text = text::utf8(FMT, out)?;
    let names: Vec<String> = match list {
        Some(l) => text::utf8(FMT, l)?
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .map(|l| l.split_whitespace().next().unwrap_or("").to_string())
            .collect(),
        None => Vec::new(),
    };
    // Skip the header comment(s).
    let body_start = text
        .lines()
        .take_while(|l| l.trim_start().starts_with('#') || l.trim().is_empty())
        .map(|l| l.len() + 1)
        .sum::<usize>()
        .min(text.len());
    let first = text.lines().next().unwrap_or("");
    if !first.trim_start().starts_with("# Bundle file") {
        if !first.trim_start().starts_with('#') && first.split_whitespace().count() != 2 {
            return Err(Error::malformed(
                FMT,
                format!(
                    "first line is '{}', expected '# Bundle file v0.3'",
                    text::clip(first)
                ),
            ));
        }
    } else if !first.contains("v0.3") {
        return Err(Error::unsupported(
            FMT,
            format!("'{}': only v0.3 is supported", text::clip(first.trim())),
        ));
    }
    let body = text.get(body_start..).unwrap_or("");
    let mut t = Tokens::new(FMT, body);
    let n_cams: u64 = t.parse("number of cameras")?;
    let n_points: u64 = t.parse("number of points")?;
    // A camera is 15 numbers, a point at least 7: at least 2 bytes each.
    let budget = (body.len() / 2) as u64;
    if n_cams.saturating_mul(15) > budget {
        return Err(Error::CountMismatch {
            format: FMT,
            what: "cameras",
            declared: n_cams,
            available: budget / 15,
        });
    }
    if n_points.saturating_mul(7) > budget {
        return Err(Error::CountMismatch {
            format: FMT,
            what: "points",
            declared: n_points,
            available: budget / 7,
        });
    }
    if !names.is_empty() && names.len() as u64 != n_cams {
        return Err(Error::CountMismatch {
            format: FMT,
            what: "cameras (list.txt lines)",
            declared: n_cams,
            available: names.len() as u64,
        });
    }
    let mut rec = Reconstruction::new("bundler");
    // Bundler camera index → index in rec.images (None when unregistered).
    let mut index_of: Vec<Option<usize>> = Vec::new();
    for k in 0..n_cams {
        let f = t.f64("focal length")?;
        let k1 = t.f64("k1")?;
        let k2 = t.f64("k2")?;
        let mut r = [[0.0; 3]; 3];
        for row in &mut r {
            for v in row.iter_mut() {
                *v = t.f64("rotation")?;
            }
        }
        let mut tr = [0.0; 3];
        for v in &mut tr {
            *v = t.f64("translation")?;
        }
        let name = names
            .get(k as usize)
            .cloned()
            .unwrap_or_else(|| format!("camera_{k}"));
        let all_zero = f == 0.0 && r.iter().flatten().all(|&v| v == 0.0);
        if all_zero {
            rec.unregistered.push(name);
            index_of.push(None);
            continue;
        }
        // OpenGL → OpenCV: negate rows 2, 3 of R and entries 2, 3 of t.
        for row in r.iter_mut().skip(1) {
            for v in row.iter_mut() {
                *v = -*v;
            }
        }
        tr[1] = -tr[1];
        tr[2] = -tr[2];
        index_of.push(Some(rec.images.len()));
        rec.cameras.push(Camera {
            id: k,
            model: "BUNDLER_RADIAL".into(),
            width: 0,
            height: 0,
            fx: f,
            fy: f,
            cx: 0.0,
            cy: 0.0,
            params: vec![f, k1, k2],
        });
        rec.images.push(Image {
            id: k,
            name,
            camera_id: k,
            cam_from_world: Rigid {
                rotation: r,
                translation: tr,
            },
            observations: Vec::new(),
        });
    }
    let mut bad_refs = 0usize;
    for _ in 0..n_points {
        let xyz = [t.f64("X")?, t.f64("Y")?, t.f64("Z")?];
        let mut rgb = [0u8; 3];
        for v in &mut rgb {
            *v = t.f64("colour")?.clamp(0.0, 255.0) as u8;
        }
        let n: u64 = t.parse("view list length")?;
        if n.saturating_mul(4) > budget {
            return Err(Error::CountMismatch {
                format: FMT,
                what: "views of a point",
                declared: n,
                available: budget / 4,
            });
        }
        let point_index = rec.points.len();
        let mut track = Vec::new();
        for _ in 0..n {
            let cam: u64 = t.parse("camera index")?;
            let key: u64 = t.parse("key index")?;
            let x = t.f64("x")?;
            let y = t.f64("y")?;
            match index_of.get(cam as usize).copied().flatten() {
                Some(i) => rec.observe(&mut track, i, key, [x, y], point_index),
                None => bad_refs += 1,
            }
        }
        rec.points.push(Point3D {
            xyz,
            color: Some(rgb),
            error: None,
            track,
        });
    }
    if bad_refs > 0 {
        rec.notes.push(
            Note::new(
                Code::DanglingReferences,
                format!(
                    "{bad_refs} point view(s) refer to unknown or unregistered cameras; dropped"
                ),
            )
            .with("count", bad_refs),
        );
    }
    rec.note_unregistered("camera(s) are unregistered (all zero)");
    if list.is_none() {
        rec.notes.push(Note::new(
            Code::NoImageList,
            "no image list: images are named camera_0, camera_1, ...",
        ));
    }
    rec.validate(FMT, false)?;
    Ok(rec)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::model::colmap::read_colmap_binary;
    use crate::model::fuzz_tests::fixture;

    #[test]
    fn colmap38_export_matches_the_colmap_model() {
        let b = read_bundler(
            &fixture("colmap38.bundle.out"),
            Some(&fixture("colmap38.list.txt")),
        )
        .unwrap();
        let c = read_colmap_binary(
            &fixture("colmap_bin/cameras.bin"),
            &fixture("colmap_bin/images.bin"),
            Some(&fixture("colmap_bin/points3D.bin")),
        )
        .unwrap();
        assert_eq!(b.images.len(), c.images.len());
        for im in &c.images {
            let o = b.images.iter().find(|o| o.name == im.name).unwrap();
            let (p, q) = (im.cam_from_world, o.cam_from_world);
            for k in 0..3 {
                assert!((p.translation[k] - q.translation[k]).abs() < 1e-9);
                for j in 0..3 {
                    assert!((p.rotation[k][j] - q.rotation[k][j]).abs() < 1e-9);
                }
            }
        }
        assert_eq!(b.points.len(), c.points.len());
        assert_eq!(b.cameras[0].fx, 210.0);
        assert!(b.notes.is_empty(), "{:?}", b.notes);
    }

    #[test]
    fn unregistered_cameras_and_no_list() {
        let out = "# Bundle file v0.3\n2 1\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n\
            100 0 0\n1 0 0\n0 1 0\n0 0 1\n0 0 -5\n\
            0 0 0\n10 20 30\n2 0 3 1.5 2.5 1 4 0.5 0.5\n";
        let r = read_bundler(out.as_bytes(), None).unwrap();
        assert_eq!(r.images.len(), 1);
        assert_eq!(r.unregistered, vec!["camera_0".to_string()]);
        assert_eq!(r.images[0].name, "camera_1");
        // R = diag(1,-1,-1), t = (0,0,5): centre (0,0,5) as in Bundler's frame.
        assert_eq!(r.images[0].cam_from_world.rotation[1][1], -1.0);
        assert_eq!(r.images[0].center(), [0.0, 0.0, 5.0]);
        assert_eq!(r.points[0].track.len(), 1);
        assert!(r.notes.iter().any(|w| w.message.contains("unregistered")));
        let list = b"a.jpg 0 100\nimages/b.jpg\n";
        let r = read_bundler(out.as_bytes(), Some(list)).unwrap();
        assert_eq!(r.images[0].name, "images/b.jpg");
    }

    #[test]
    fn bad_inputs() {
        assert!(matches!(
            read_bundler(b"# Bundle file v0.3\n", None),
            Err(Error::Truncated { .. })
        ));
        assert!(matches!(
            read_bundler(b"# Bundle file v0.3\n99999999 0\n", None),
            Err(Error::CountMismatch { .. })
        ));
        assert!(matches!(
            read_bundler(
                b"# Bundle file v0.3\n1 0\n1 0 0\n                                        ",
                None
            ),
            Err(Error::Truncated { .. })
        ));
        assert!(matches!(
            read_bundler(b"# Bundle file v0.2\n0 0\n", None),
            Err(Error::Unsupported { .. })
        ));
        assert!(matches!(
            read_bundler(b"hello world again\n", None),
            Err(Error::Malformed { .. })
        ));
        assert!(matches!(
            read_bundler(
                b"# Bundle file v0.3\n1 0\n1 0 0 1 0 0 0 1 0 0 0 1 0 0 inf\n",
                None
            ),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            read_bundler(b"# Bundle file v0.3\n0 0\n", Some(b"a.jpg\n")),
            Err(Error::CountMismatch { .. })
        ));
    }
}
