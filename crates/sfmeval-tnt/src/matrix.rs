//! Row-major 4×4 matrices as the Tanks and Temples files and Open3D use them: a transform is
//! applied as a homogeneous product and divided by `w`, products run in Eigen's order.

use sfmeval::geometry::{MAX_COORDINATE, Point3};
use sfmeval::{Error, Result};

/// A row-major 4×4 matrix.
pub type Matrix4 = [[f64; 4]; 4];

/// The identity.
pub const IDENTITY: Matrix4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// `m · [p, 1]` divided by its `w`, as Open3D's `PointCloud::Transform` (columns summed in
/// order: `((c0·x + c1·y) + c2·z) + c3`).
#[inline]
pub fn apply(m: &Matrix4, p: Point3) -> Point3 {
    let row = |r: &[f64; 4]| ((r[0] * p[0] + r[1] * p[1]) + r[2] * p[2]) + r[3];
    let w = row(&m[3]);
    [row(&m[0]) / w, row(&m[1]) / w, row(&m[2]) / w]
}

/// `a · b` (apply `b` first).
pub fn mul(a: &Matrix4, b: &Matrix4) -> Matrix4 {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = ((a[i][0] * b[0][j] + a[i][1] * b[1][j]) + a[i][2] * b[2][j]) + a[i][3] * b[3][j];
        }
    }
    m
}

/// Checks a transform: finite, entries within ±1e50, last row `0 0 0 1`, and an
/// invertible upper 3×3. `what` names it in the error.
pub fn validate(m: &Matrix4, what: &str) -> Result<()> {
    if let Some(v) = m
        .iter()
        .flatten()
        .find(|v| !(v.is_finite() && v.abs() <= MAX_COORDINATE))
    {
        return Err(Error::InvalidContent(format!(
            "{what}: entry {v} is not a finite number within ±1e50"
        )));
    }
    if m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(Error::InvalidContent(format!(
            "{what}: the last row is {:?}, expected [0, 0, 0, 1]",
            m[3]
        )));
    }
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if !(det.is_finite() && det != 0.0) {
        return Err(Error::InvalidContent(format!(
            "{what}: the 3×3 part is singular"
        )));
    }
    Ok(())
}

/// Parses 16 whitespace-separated numbers (a `<scene>_trans.txt`, `numpy.loadtxt`'s input) as
/// a row-major 4×4 and validates it. `format` names the file kind in errors.
pub fn parse(bytes: &[u8], format: &'static str) -> Result<Matrix4> {
    let text = std::str::from_utf8(bytes).map_err(|_| Error::Malformed {
        format,
        detail: "not UTF-8 text".into(),
    })?;
    let mut values = Vec::with_capacity(16);
    for (line_no, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        for token in line.split_whitespace() {
            let v: f64 = token.parse().map_err(|_| Error::Malformed {
                format,
                detail: format!("line {}: '{token}' is not a number", line_no + 1),
            })?;
            values.push(v);
        }
    }
    if values.len() != 16 {
        return Err(Error::Malformed {
            format,
            detail: format!("{} numbers, expected the 16 of a 4×4 matrix", values.len()),
        });
    }
    let mut m = [[0.0; 4]; 4];
    for (i, v) in values.into_iter().enumerate() {
        m[i / 4][i % 4] = v;
    }
    validate(&m, format)?;
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn apply_mul_parse() {
        let t = [
            [0.0, -2.0, 0.0, 1.0],
            [2.0, 0.0, 0.0, 2.0],
            [0.0, 0.0, 2.0, 3.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        assert_eq!(apply(&t, [1.0, 1.0, 1.0]), [-1.0, 4.0, 5.0]);
        assert_eq!(apply(&mul(&t, &IDENTITY), [1.0, 0.0, 0.0]), [1.0, 4.0, 3.0]);
        assert_eq!(
            apply(&mul(&t, &t), [1.0, 0.0, 0.0]),
            apply(&t, [1.0, 4.0, 3.0])
        );
        let text = b"0 -2 0 1\n2 0 0 2\n0 0 2 3\n0 0 0 1\n";
        assert_eq!(parse(text, "trans").unwrap(), t);
        let e = parse(b"1 0 0\n", "trans").unwrap_err().to_string();
        assert!(e.contains("3 numbers"), "{e}");
        let e = parse(b"1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1", "trans")
            .unwrap_err()
            .to_string();
        assert!(e.contains("last row"), "{e}");
        let e = parse(b"0 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", "trans")
            .unwrap_err()
            .to_string();
        assert!(e.contains("singular"), "{e}");
        assert!(parse(b"nan 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", "trans").is_err());
        assert!(parse(b"x 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", "trans").is_err());
    }
}
