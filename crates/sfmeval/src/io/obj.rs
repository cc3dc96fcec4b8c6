//! Wavefront OBJ reader (vertices and faces; polygons fan-triangulated), from bytes.
//!
//! Only geometry is read: `v` and `f` records. Face corners may be `v`, `v/vt`, `v//vn` or
//! `v/vt/vn`, with positive (1-based) or negative (relative) indices. Everything else (normals,
//! texture coordinates, groups, materials, lines, points) is ignored.

use crate::error::{Error, Result};
use crate::geometry::TriangleMesh;

const FMT: &str = "OBJ";

/// Reads an OBJ file as a triangle mesh.
pub fn read_obj(bytes: &[u8]) -> Result<TriangleMesh> {
    let mut mesh = TriangleMesh::default();
    let mut poly: Vec<u32> = Vec::new();
    let mut lineno = 0usize;
    let mut rest = bytes;
    while !rest.is_empty() {
        let end = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
        let raw = &rest[..end];
        rest = rest.get(end + 1..).unwrap_or(&[]);
        lineno += 1;
        let line = String::from_utf8_lossy(raw);
        let line = line.split('#').next().unwrap_or("").trim();
        let mut words = line.split_ascii_whitespace();
        let bad = |what: &str| Error::malformed(FMT, format!("line {lineno}: {what}"));
        match words.next() {
            Some("v") => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    *c = words
                        .next()
                        .and_then(|w| w.parse::<f64>().ok())
                        .ok_or_else(|| bad("vertex needs three numbers"))?;
                }
                mesh.vertices.push(p);
            }
            Some("f") => {
                poly.clear();
                let n = mesh.vertices.len() as i64;
                for corner in words {
                    let v = corner.split('/').next().unwrap_or("");
                    let i: i64 = v
                        .parse()
                        .map_err(|_| bad(&format!("bad face corner '{corner}'")))?;
                    let idx = if i > 0 { i - 1 } else { n + i };
                    if i == 0 || idx < 0 || idx >= n {
                        return Err(bad(&format!(
                            "face index {i} with {n} vertices defined so far"
                        )));
                    }
                    poly.push(idx as u32);
                }
                if poly.len() < 3 {
                    return Err(bad("face with fewer than 3 corners"));
                }
                for k in 1..poly.len() - 1 {
                    mesh.triangles.push([poly[0], poly[k], poly[k + 1]]);
                }
            }
            _ => {}
        }
    }
    if mesh.vertices.is_empty()
        && mesh.triangles.is_empty()
        && !bytes.is_empty()
        && !looks_like_text(bytes)
    {
        return Err(Error::malformed(FMT, "not a text file"));
    }
    mesh.validate(FMT)?;
    Ok(mesh)
}

fn looks_like_text(bytes: &[u8]) -> bool {
    bytes
        .iter()
        .take(4096)
        .all(|&c| c == b'\t' || c == b'\n' || c == b'\r' || (0x20..0x7f).contains(&c) || c >= 0x80)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_with_slashes_and_negative_indices() {
        let obj = "# cube face\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\nf -4/1/1 -3/1/1 -2/1/1\n";
        let m = read_obj(obj.as_bytes()).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
    }

    #[test]
    fn errors() {
        assert!(matches!(read_obj(b"v 0 0\n"), Err(Error::Malformed { .. })));
        assert!(matches!(
            read_obj(b"v 0 0 0\nf 1 2 3\n"),
            Err(Error::Malformed { .. })
        ));
        assert!(matches!(read_obj(b"v 0 0 0\n"), Err(Error::Empty { .. })));
        assert!(matches!(
            read_obj(b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            Err(Error::NonFinite { .. })
        ));
    }
}
