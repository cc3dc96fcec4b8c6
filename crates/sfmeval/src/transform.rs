//! Similarity transforms (rotation, translation, uniform scale) as row-major 4×4 matrices.
//! `gt_from_recon` maps reconstruction coordinates into the ground-truth frame.

use crate::error::{Error, Result};
use crate::geometry::{MAX_COORDINATE, Point3, show};

/// A transform's scale must lie in `[MIN_SCALE, MAX_SCALE]`: beyond, the reconstruction would be
/// blown up past [`MAX_COORDINATE`] or collapsed below anything measurable.
pub(crate) const MIN_SCALE: f64 = 1e-50;

/// See [`MIN_SCALE`].
pub(crate) const MAX_SCALE: f64 = 1e50;

/// A similarity `x ↦ s·R·x + t`, stored as the row-major 4×4 `[[sR, t], [0, 1]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Similarity {
    /// Row-major 4×4 matrix.
    pub matrix: [[f64; 4]; 4],
}

impl Default for Similarity {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Similarity {
    /// The identity.
    pub const IDENTITY: Similarity = Similarity {
        matrix: [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    };

    /// Builds from scale, row-major rotation and translation.
    pub fn from_parts(scale: f64, rotation: [[f64; 3]; 3], translation: Point3) -> Similarity {
        let mut m = Self::IDENTITY.matrix;
        for r in 0..3 {
            for c in 0..3 {
                m[r][c] = scale * rotation[r][c];
            }
            m[r][3] = translation[r];
        }
        Similarity { matrix: m }
    }

    /// Validates a 4×4 as a similarity: finite, every entry within ±1e50, last row
    /// `0 0 0 1`, upper 3×3 = s·R with R a proper rotation (tolerance `1e-6` relative) and `s`
    /// in `[MIN_SCALE, MAX_SCALE]`.
    pub fn from_matrix(m: [[f64; 4]; 4]) -> Result<Similarity> {
        if m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(Error::InvalidContent(
                "transform has non-finite entries".into(),
            ));
        }
        for (r, row) in m.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                if !(v.abs() <= MAX_COORDINATE) {
                    return Err(Error::InvalidContent(format!(
                        "transform entry [{r}][{c}] is {}, beyond ±{} (the largest coordinate measured)",
                        show(*v),
                        show(MAX_COORDINATE)
                    )));
                }
            }
        }
        let last = m[3];
        if last[0].abs() > 1e-9
            || last[1].abs() > 1e-9
            || last[2].abs() > 1e-9
            || (last[3] - 1.0).abs() > 1e-9
        {
            return Err(Error::InvalidContent(format!(
                "transform's last row is {last:?}, expected [0, 0, 0, 1]"
            )));
        }
        let s = Similarity { matrix: m };
        let scale = s.scale();
        if !(scale > 0.0) {
            return Err(Error::InvalidContent("transform has a non-positive determinant (a reflection or a collapse), not a similarity".into()));
        }
        if !(MIN_SCALE..=MAX_SCALE).contains(&scale) {
            return Err(Error::InvalidContent(format!(
                "transform's scale is {}, outside [{}, {}]",
                show(scale),
                show(MIN_SCALE),
                show(MAX_SCALE)
            )));
        }
        // (A/s)ᵀ(A/s) must be the identity (divided first: s² may underflow).
        let r = s.rotation();
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum::<f64>();
                let want = if i == j { 1.0 } else { 0.0 };
                if !((d - want).abs() <= 1e-6) {
                    return Err(Error::InvalidContent(format!(
                        "transform's 3×3 part is not a scaled rotation (RᵀR differs from I by {:.2e})",
                        (d - want).abs()
                    )));
                }
            }
        }
        Ok(s)
    }

    /// Parses a transform from JSON (`[[..4], ×4]`, a flat list of 16, or an object with a
    /// `gt_from_recon` / `matrix` / `transform` field, e.g. an sfmeval report) or from text
    /// (16 whitespace-separated numbers, row-major; `#` comments allowed).
    pub fn parse(bytes: &[u8]) -> Result<Similarity> {
        let text = std::str::from_utf8(bytes)
            .map_err(|_| Error::InvalidContent("transform file is not text".into()))?;
        let trimmed = text.trim_start();
        let numbers: Vec<f64> = if trimmed.starts_with('[') || trimmed.starts_with('{') {
            let v: serde_json::Value = serde_json::from_str(text)
                .map_err(|e| Error::InvalidContent(format!("transform JSON: {e}")))?;
            let v = match &v {
                serde_json::Value::Object(o) => o
                    .get("gt_from_recon")
                    .or_else(|| o.get("alignment").and_then(|a| a.get("gt_from_recon")))
                    .or_else(|| o.get("matrix"))
                    .or_else(|| o.get("transform"))
                    .ok_or_else(|| Error::InvalidContent("transform JSON object has no 'gt_from_recon', 'matrix' or 'transform' field".into()))?,
                other => other,
            };
            flatten_numbers(v)?
        } else {
            text.lines()
                .map(|l| l.split('#').next().unwrap_or(""))
                .flat_map(|l| l.split(|c: char| c.is_whitespace() || c == ','))
                .filter(|w| !w.is_empty())
                .map(|w| {
                    w.parse::<f64>().map_err(|_| {
                        Error::InvalidContent(format!("transform: '{w}' is not a number"))
                    })
                })
                .collect::<Result<_>>()?
        };
        if numbers.len() != 16 {
            return Err(Error::InvalidContent(format!(
                "transform needs 16 numbers (a 4×4), found {}",
                numbers.len()
            )));
        }
        let mut m = [[0.0; 4]; 4];
        for (i, v) in numbers.into_iter().enumerate() {
            m[i / 4][i % 4] = v;
        }
        Self::from_matrix(m)
    }

    /// The uniform scale s (cube root of the 3×3 determinant), without overflow or underflow
    /// of the determinant for any finite matrix (it is taken of the matrix divided by its
    /// largest entry when the plain product leaves the safe range).
    pub fn scale(&self) -> f64 {
        let det = det3(&self.matrix, 1.0);
        if det.is_finite() && det.abs() > 1e-290 {
            return libm::cbrt(det);
        }
        let k = self.matrix[..3]
            .iter()
            .flat_map(|row| &row[..3])
            .fold(0.0f64, |k, v| k.max(v.abs()));
        if !(k > 0.0 && k.is_finite()) {
            return libm::cbrt(det);
        }
        k * libm::cbrt(det3(&self.matrix, k))
    }

    /// The rotation R (the 3×3 part divided by the scale).
    pub(crate) fn rotation(&self) -> [[f64; 3]; 3] {
        let s = self.scale();
        let mut r = [[0.0; 3]; 3];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.matrix[i][j] / s;
            }
        }
        r
    }

    /// The translation t.
    pub(crate) fn translation(&self) -> Point3 {
        [self.matrix[0][3], self.matrix[1][3], self.matrix[2][3]]
    }

    /// Applies the transform to a point.
    #[inline]
    pub fn apply(&self, p: Point3) -> Point3 {
        let m = &self.matrix;
        [
            m[0][0] * p[0] + m[0][1] * p[1] + m[0][2] * p[2] + m[0][3],
            m[1][0] * p[0] + m[1][1] * p[1] + m[1][2] * p[2] + m[1][3],
            m[2][0] * p[0] + m[2][1] * p[1] + m[2][2] * p[2] + m[2][3],
        ]
    }

    /// `self ∘ other` (apply `other` first).
    #[cfg(test)]
    pub(crate) fn compose(&self, other: &Similarity) -> Similarity {
        let mut m = [[0.0; 4]; 4];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..4).map(|k| self.matrix[i][k] * other.matrix[k][j]).sum();
            }
        }
        Similarity { matrix: m }
    }

    /// The inverse similarity.
    #[cfg(test)]
    pub(crate) fn inverse(&self) -> Similarity {
        let s = self.scale();
        let r = self.rotation();
        let t = self.translation();
        let mut rt = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                rt[i][j] = r[j][i];
            }
        }
        let ti = [0, 1, 2].map(|i| -(rt[i][0] * t[0] + rt[i][1] * t[1] + rt[i][2] * t[2]) / s);
        Similarity::from_parts(1.0 / s, rt, ti)
    }
}

/// Determinant of the upper 3×3 of `m` divided by `k`.
fn det3(m: &[[f64; 4]; 4], k: f64) -> f64 {
    let a = |r: usize, c: usize| m[r][c] / k;
    a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1))
        - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
        + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0))
}

fn flatten_numbers(v: &serde_json::Value) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    fn walk(v: &serde_json::Value, out: &mut Vec<f64>) -> Result<()> {
        match v {
            serde_json::Value::Array(a) => a.iter().try_for_each(|x| walk(x, out)),
            serde_json::Value::Number(n) => {
                out.push(
                    n.as_f64()
                        .ok_or_else(|| Error::InvalidContent("bad number in transform".into()))?,
                );
                Ok(())
            }
            _ => Err(Error::InvalidContent(
                "transform must contain only numbers".into(),
            )),
        }
    }
    walk(v, &mut out)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_text_and_json_and_reject_shear() {
        let t = Similarity::parse(b"# rot z 90, scale 2\n0 -2 0 1\n2 0 0 2\n0 0 2 3\n0 0 0 1\n")
            .unwrap();
        assert!((t.scale() - 2.0).abs() < 1e-12);
        assert_eq!(t.apply([1.0, 0.0, 0.0]), [1.0, 4.0, 3.0]);
        let j =
            Similarity::parse(b"{\"gt_from_recon\": [[0,-2,0,1],[2,0,0,2],[0,0,2,3],[0,0,0,1]]}")
                .unwrap();
        assert_eq!(t, j);
        let inv = t.inverse();
        let p = inv.apply(t.apply([0.3, -0.2, 5.0]));
        assert!((p[0] - 0.3).abs() < 1e-12 && (p[2] - 5.0).abs() < 1e-12);
        assert!(Similarity::parse(b"1 0.5 0 0 0 1 0 0 0 0 1 0 0 0 0 1").is_err());
        assert!(Similarity::parse(b"-1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1").is_err());
        assert!(Similarity::parse(b"1 0 0").is_err());
    }

    #[test]
    fn huge_and_tiny_entries() {
        // 1e150 (its determinant overflows) and 1e308 are refused with the entry named.
        for big in ["1e150", "1e308"] {
            let text = format!("{big} 0 0 0 0 {big} 0 0 0 0 {big} 0 0 0 0 1");
            let e = Similarity::parse(text.as_bytes()).unwrap_err().to_string();
            assert!(e.contains("entry [0][0]") && e.contains("beyond"), "{e}");
        }
        let e = Similarity::parse(b"1 0 0 1e300 0 1 0 0 0 0 1 0 0 0 0 1")
            .unwrap_err()
            .to_string();
        assert!(e.contains("entry [0][3]"), "{e}");
        // The scale is exact where the determinant alone would overflow or underflow.
        let t = Similarity::from_parts(
            1e40,
            [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            [0.0; 3],
        );
        assert!((t.scale() / 1e40 - 1.0).abs() < 1e-14, "{}", t.scale());
        let t = Similarity::from_parts(
            1e-40,
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            [0.0; 3],
        );
        assert!((t.scale() / 1e-40 - 1.0).abs() < 1e-14);
        assert!(Similarity::from_matrix(t.matrix).is_ok());
        // Outside [1e-50, 1e50]: refused.
        let t = Similarity::from_parts(
            1e-60,
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            [0.0; 3],
        );
        let e = Similarity::from_matrix(t.matrix).unwrap_err().to_string();
        assert!(e.contains("scale"), "{e}");
    }
}
