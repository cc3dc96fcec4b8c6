//! VisualSfM NVM v3 (`research/formats.md`): several models in one file, each a camera list
//! (`name f qw qx qy qz Cx Cy Cz r 0`: world-to-camera rotation and camera **centre**) and a
//! point list (`X Y Z R G B n (cam feat x y)×n`). An optional `FixedK fx cx fy cy r` on the header
//! line gives the principal point; NVM stores no image size, so without FixedK the principal point
//! is unknown (0). Names may contain folders and backslashes; they are kept as written.

use super::text::{self, clip};
use super::{Camera, Image, Point3D, Reconstruction, Rigid};
use crate::error::{Error, Result};
use crate::geometry::{MAX_COORDINATE, show};
use crate::note::{Code, Note};

const FMT: &str = "NVM";

/// Reads an NVM v3 file: every model in it, the largest returned, the others listed in
/// [`Reconstruction::sub_models`] (`model 1`, `model 2`, ... in file order).
pub fn read_nvm(bytes: &[u8]) -> Result<Reconstruction> {
    super::choose_largest(read_nvm_models(bytes)?)
}

/// Reads every model of an NVM file, in file order, named `model 1`, `model 2`, ...
pub(crate) fn read_nvm_models(bytes: &[u8]) -> Result<Vec<(String, Reconstruction)>> {
    let text = text::utf8(FMT, bytes)?;
    let lines: Vec<(usize, &str)> = text::data_lines(text, '#');
    let mut pos = 0usize;
    let (_, header) = lines.first().copied().ok_or_else(|| Error::Empty {
        what: "NVM file".into(),
    })?;
    let mut head = header.split_whitespace();
    if !head.next().is_some_and(|h| h.starts_with("NVM_V3")) {
        return Err(Error::malformed(
            FMT,
            format!("first line is '{}', expected NVM_V3", clip(header)),
        ));
    }
    pos += 1;
    // Optional FixedK fx cx fy cy r.
    let mut fixed_pp: Option<(f64, f64)> = None;
    let rest: Vec<&str> = head.collect();
    if let Some(i) = rest.iter().position(|t| t.eq_ignore_ascii_case("FixedK")) {
        let v = |k: usize, what: &str| text::parse_f64(FMT, rest.get(i + k).copied(), what, 1);
        let (_fx, cx, _fy, cy) = (
            v(1, "FixedK fx")?,
            v(2, "FixedK cx")?,
            v(3, "FixedK fy")?,
            v(4, "FixedK cy")?,
        );
        fixed_pp = Some((cx, cy));
    }
    let mut models = Vec::new();
    let mut trailing_note = None;
    while let Some(&(line, l)) = lines.get(pos) {
        let mut toks = l.split_whitespace();
        let n_cams: usize = match toks.next().map(str::parse::<usize>) {
            Some(Ok(n)) if toks.next().is_none() => n,
            _ => {
                trailing_note = Some(
                    Note::new(
                        Code::TrailingContent,
                        format!("NVM: stopped reading at line {line} ('{}')", clip(l)),
                    )
                    .with("line", line),
                );
                break;
            }
        };
        pos += 1;
        if n_cams == 0 {
            break;
        }
        let available = lines.len().saturating_sub(pos);
        if n_cams > available {
            return Err(Error::CountMismatch {
                format: FMT,
                what: "cameras",
                declared: n_cams as u64,
                available: available as u64,
            });
        }
        let mut rec = Reconstruction::new("nvm");
        for k in 0..n_cams {
            let (line, l) = lines.get(pos).copied().unwrap_or((0, ""));
            pos += 1;
            let (image, camera) = camera_line(line, l, k, fixed_pp)?;
            rec.images.push(image);
            rec.cameras.push(camera);
        }
        // Points: a count line (may be absent at the very end of a file: no points).
        let n_points = match lines.get(pos) {
            Some(&(line, l)) => {
                pos += 1;
                text::parse::<usize>(FMT, Some(l), "number of points", line)?
            }
            None => 0,
        };
        let available = lines.len().saturating_sub(pos);
        if n_points > available {
            return Err(Error::CountMismatch {
                format: FMT,
                what: "points",
                declared: n_points as u64,
                available: available as u64,
            });
        }
        let mut bad_refs = 0usize;
        rec.points.reserve(n_points);
        for _ in 0..n_points {
            let (line, l) = lines.get(pos).copied().unwrap_or((0, ""));
            pos += 1;
            let mut it = l.split_whitespace();
            let mut xyz = [0.0; 3];
            for (k, v) in xyz.iter_mut().enumerate() {
                *v = text::parse_f64(FMT, it.next(), ["X", "Y", "Z"][k], line)?;
            }
            let mut rgb = [0u8; 3];
            for (k, v) in rgb.iter_mut().enumerate() {
                // Some writers emit colours as integers above 255 or as floats; clamp.
                let c: f64 = text::parse_f64(FMT, it.next(), ["R", "G", "B"][k], line)?;
                *v = c.clamp(0.0, 255.0) as u8;
            }
            let n: usize = text::parse(FMT, it.next(), "number of measurements", line)?;
            let rest: Vec<&str> = it.collect();
            if rest.len() != n.saturating_mul(4) {
                return Err(Error::malformed(
                    FMT,
                    format!(
                        "line {line}: {n} measurements need {} values, found {}",
                        n.saturating_mul(4),
                        rest.len()
                    ),
                ));
            }
            let point_index = rec.points.len();
            let mut track = Vec::with_capacity(n);
            for m in rest.chunks_exact(4) {
                let cam: usize = text::parse(FMT, m.first().copied(), "camera index", line)?;
                let feat: u64 = text::parse(FMT, m.get(1).copied(), "feature index", line)?;
                let x = text::parse_f64(FMT, m.get(2).copied(), "x", line)?;
                let y = text::parse_f64(FMT, m.get(3).copied(), "y", line)?;
                if cam < rec.images.len() {
                    rec.observe(&mut track, cam, feat, [x, y], point_index);
                } else {
                    bad_refs += 1;
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
                    format!("{bad_refs} measurement(s) refer to cameras not in the model; dropped"),
                )
                .with("count", bad_refs),
            );
        }
        if fixed_pp.is_none() {
            rec.notes.push(Note::new(
                Code::NoPrincipalPoint,
                "NVM stores no image size and no principal point (FixedK absent): cx, cy unknown",
            ));
        }
        rec.validate(FMT, false)?;
        models.push((format!("model {}", models.len() + 1), rec));
    }
    if models.is_empty() {
        return Err(Error::Empty {
            what: "NVM file (no model with cameras)".into(),
        });
    }
    if let (Some(note), Some((_, first))) = (trailing_note, models.first_mut()) {
        first.notes.push(note);
    }
    Ok(models)
}

/// One camera line: the name is everything before the last 10 numbers (names may hold spaces).
fn camera_line(
    line: usize,
    l: &str,
    index: usize,
    fixed_pp: Option<(f64, f64)>,
) -> Result<(Image, Camera)> {
    let toks: Vec<(usize, &str)> = token_offsets(l);
    if toks.len() < 11 {
        return Err(Error::truncated(
            FMT,
            format!(
                "line {line}: camera needs a name and 10 numbers, found {} values",
                toks.len()
            ),
        ));
    }
    let first_num = toks.len() - 10;
    let name_end = toks.get(first_num).map(|&(o, _)| o).unwrap_or(l.len());
    let name = l.get(..name_end).unwrap_or("").trim().to_string();
    let num = |k: usize, what: &str| {
        text::parse_f64(FMT, toks.get(first_num + k).map(|t| t.1), what, line)
    };
    let f = num(0, "focal length")?;
    let q = [num(1, "qw")?, num(2, "qx")?, num(3, "qy")?, num(4, "qz")?];
    let c = [num(5, "Cx")?, num(6, "Cy")?, num(7, "Cz")?];
    if let Some(k) = (0..3).find(|&k| !(c[k].abs() <= MAX_COORDINATE)) {
        return Err(Error::out_of_range(
            FMT,
            format!("line {line}: camera '{}'", clip(&name)),
            ["centre Cx", "centre Cy", "centre Cz"][k],
            format!("is {}, beyond ±{}", show(c[k]), show(MAX_COORDINATE)),
        ));
    }
    let r = num(8, "radial distortion")?;
    let rotation = super::quaternion_to_matrix(q).ok_or_else(|| {
        Error::malformed(
            FMT,
            format!(
                "line {line}: camera '{}' has a zero quaternion",
                clip(&name)
            ),
        )
    })?;
    let (cx, cy) = fixed_pp.unwrap_or((0.0, 0.0));
    let id = index as u64;
    let camera = Camera {
        id,
        model: "NVM_RADIAL".into(),
        width: 0,
        height: 0,
        fx: f,
        fy: f,
        cx,
        cy,
        params: vec![f, r],
    };
    let image = Image {
        id,
        name,
        camera_id: id,
        cam_from_world: Rigid::from_rotation_center(rotation, c),
        observations: Vec::new(),
    };
    Ok((image, camera))
}

/// Whitespace-separated tokens with their byte offsets.
fn token_offsets(l: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, ch) in l.char_indices() {
        if ch.is_whitespace() {
            if let Some(s) = start.take() {
                out.push((s, l.get(s..i).unwrap_or("")));
            }
        } else if start.is_none() {
            start = Some(i);
        }
    }
    if let Some(s) = start {
        out.push((s, l.get(s..).unwrap_or("")));
    }
    out
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::model::colmap::read_colmap_binary;
    use crate::model::fuzz_tests::fixture;

    fn colmap() -> Reconstruction {
        read_colmap_binary(
            &fixture("colmap_bin/cameras.bin"),
            &fixture("colmap_bin/images.bin"),
            Some(&fixture("colmap_bin/points3D.bin")),
        )
        .unwrap()
    }

    fn assert_same_poses(a: &Reconstruction, b: &Reconstruction, tol: f64) {
        assert_eq!(a.images.len(), b.images.len());
        for im in &a.images {
            let other = b.images.iter().find(|o| o.name == im.name).unwrap();
            let (p, q) = (im.cam_from_world, other.cam_from_world);
            for k in 0..3 {
                assert!(
                    (p.translation[k] - q.translation[k]).abs() < tol,
                    "{} t{k}",
                    im.name
                );
                for j in 0..3 {
                    assert!(
                        (p.rotation[k][j] - q.rotation[k][j]).abs() < tol,
                        "{} R",
                        im.name
                    );
                }
            }
        }
    }

    #[test]
    fn colmap38_export_matches_the_colmap_model() {
        let n = read_nvm(&fixture("colmap38.nvm")).unwrap();
        let c = colmap();
        assert_same_poses(&n, &c, 1e-9);
        assert_eq!(n.points.len(), c.points.len());
        assert_eq!(n.cameras[0].fx, 210.0);
        assert_eq!(n.num_models(), 1);
        let tracks: usize = n.points.iter().map(|p| p.track.len()).sum();
        let tracks_c: usize = c.points.iter().map(|p| p.track.len()).sum();
        // COLMAP's exporter drops the second observation of a point by the same image.
        let repeats: usize = c
            .points
            .iter()
            .map(|p| {
                let mut ims: Vec<usize> = p.track.iter().map(|t| t.image).collect();
                ims.sort_unstable();
                ims.dedup();
                p.track.len() - ims.len()
            })
            .sum();
        assert_eq!(tracks + repeats, tracks_c);
    }

    #[test]
    fn theia_export_matches_the_colmap_model() {
        let n = read_nvm(&fixture("theia.nvm")).unwrap();
        // Theia prints 6 significant digits.
        assert_same_poses(&n, &colmap(), 2e-5);
        assert!(!n.points.is_empty());
    }

    #[test]
    fn several_models_fixed_k_and_backslash_names() {
        let nvm = "NVM_V3 FixedK 500 320 500 240 0\n\n\
            1\n\
            C:\\data\\img 1.JPG 500 1 0 0 0 0 0 -5 0 0\n\n\
            0\n\n\
            2\n\
            a/b/x.jpg 500 1 0 0 0 0 0 -5 0 0\n\
            y.jpg 510 0 1 0 0 1 0 -5 0 0\n\n\
            1\n\
            0 0 0 255 0 0 2 0 3 1.0 2.0 1 7 -1 -2\n\n\
            0\n\n#the last part of NVM file points to the PLY files\n1 0\n";
        let r = read_nvm(nvm.as_bytes()).unwrap();
        assert_eq!(r.images.len(), 2);
        assert_eq!(r.num_models(), 2);
        assert_eq!(r.sub_models[0].images, 1);
        assert_eq!(
            (r.cameras[1].cx, r.cameras[1].cy, r.cameras[1].fx),
            (320.0, 240.0, 510.0)
        );
        // quaternion (0,1,0,0) = 180° about x; C = (1,0,-5) so t = -R C = (-1, 0, -5).
        let t = r.images[1].cam_from_world.translation;
        assert!((t[0] + 1.0).abs() < 1e-12 && t[1].abs() < 1e-12 && (t[2] + 5.0).abs() < 1e-12);
        assert_eq!(r.points[0].track.len(), 2);
        assert_eq!(r.images[1].observations[0].point, Some(0));
        let all = read_nvm_models(nvm.as_bytes()).unwrap();
        assert_eq!(all[0].1.images[0].name, "C:\\data\\img 1.JPG");
    }

    #[test]
    fn bad_inputs() {
        assert!(matches!(read_nvm(b""), Err(Error::Empty { .. })));
        assert!(matches!(read_nvm(b"PLY\n"), Err(Error::Malformed { .. })));
        assert!(matches!(read_nvm(b"NVM_V3\n0\n"), Err(Error::Empty { .. })));
        assert!(matches!(
            read_nvm(b"NVM_V3\n99999999999\na 1 1 0 0 0 0 0 0 0 0\n"),
            Err(Error::CountMismatch { .. })
        ));
        assert!(matches!(
            read_nvm(b"NVM_V3\n1\na 1 0 0 0 0 0 0 0 0 0\n0\n"),
            Err(Error::Malformed { .. })
        ));
        assert!(matches!(
            read_nvm(b"NVM_V3\n1\na 1 1 0 0 0 nan 0 0 0 0\n0\n"),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            read_nvm(b"NVM_V3\n1\na 1 1 0 0\n"),
            Err(Error::Truncated { .. })
        ));
    }
}
