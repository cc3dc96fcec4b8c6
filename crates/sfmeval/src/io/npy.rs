//! NumPy `.npy` files (format spec: `numpy/lib/format.py`), from bytes: header versions 1.0,
//! 2.0 and 3.0, dtypes `<f4`, `>f4`, `<f8`, `>f8` (and `=`/`|` byte orders meaning native
//! little-endian), C order, two dimensions. Anything else is a typed error, never a panic.
//! [`DepthMap`] is a depth image as the Blender generator writes it (`docs/dataset.md`).

use crate::error::{Error, Result};

const FMT: &str = "NPY";
const MAGIC: &[u8] = b"\x93NUMPY";

/// A 2-D floating-point array read from a `.npy` file, in C (row-major) order.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    /// Number of rows (the first dimension).
    pub rows: usize,
    /// Number of columns (the second dimension).
    pub cols: usize,
    /// `rows × cols` values, row after row, converted to f64.
    pub values: Vec<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dtype {
    F4 { big: bool },
    F8 { big: bool },
}

impl Dtype {
    fn size(self) -> usize {
        match self {
            Dtype::F4 { .. } => 4,
            Dtype::F8 { .. } => 8,
        }
    }
}

/// One value of the header dictionary (a Python literal).
#[derive(Debug, Clone, PartialEq)]
enum Literal {
    Str(String),
    Bool(bool),
    Tuple(Vec<u64>),
}

/// Parses the header dictionary `{'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }`.
fn parse_header(text: &str) -> Result<Vec<(String, Literal)>> {
    let bad = |what: &str| Error::malformed(FMT, format!("header dictionary: {what}"));
    let mut chars = text.trim().chars().peekable();
    let skip_ws = |c: &mut std::iter::Peekable<std::str::Chars>| {
        while c.peek().is_some_and(|ch| ch.is_whitespace()) {
            c.next();
        }
    };
    let read_str = |c: &mut std::iter::Peekable<std::str::Chars>| -> Result<String> {
        let quote = c.next().ok_or_else(|| bad("ends inside a key"))?;
        if quote != '\'' && quote != '"' {
            return Err(bad("expected a quoted string"));
        }
        let mut s = String::new();
        loop {
            match c.next() {
                Some(ch) if ch == quote => return Ok(s),
                Some(ch) => s.push(ch),
                None => return Err(bad("unterminated string")),
            }
        }
    };
    if chars.next() != Some('{') {
        return Err(bad("does not start with '{'"));
    }
    let mut out = Vec::new();
    loop {
        skip_ws(&mut chars);
        match chars.peek() {
            Some('}') => break,
            Some(_) => {}
            None => return Err(bad("missing '}'")),
        }
        let key = read_str(&mut chars)?;
        skip_ws(&mut chars);
        if chars.next() != Some(':') {
            return Err(bad(&format!("expected ':' after '{key}'")));
        }
        skip_ws(&mut chars);
        let value = match chars.peek() {
            Some('\'') | Some('"') => Literal::Str(read_str(&mut chars)?),
            Some('(') => {
                chars.next();
                let mut dims = Vec::new();
                let mut num = String::new();
                loop {
                    match chars.next() {
                        Some(d) if d.is_ascii_digit() => num.push(d),
                        Some(ch @ (',' | ')')) => {
                            if !num.is_empty() {
                                let n: u64 = num
                                    .parse()
                                    .map_err(|_| bad(&format!("shape entry '{num}' too large")))?;
                                dims.push(n);
                                num.clear();
                            }
                            if ch == ')' {
                                break;
                            }
                        }
                        Some(ch) if ch.is_whitespace() || ch == 'L' => {}
                        Some(ch) => return Err(bad(&format!("unexpected '{ch}' in shape"))),
                        None => return Err(bad("unterminated shape tuple")),
                    }
                }
                Literal::Tuple(dims)
            }
            _ => {
                let mut word = String::new();
                while let Some(&ch) = chars.peek() {
                    if !ch.is_ascii_alphanumeric() || word.len() > 20 {
                        break;
                    }
                    word.push(ch);
                    chars.next();
                }
                match word.as_str() {
                    "True" => Literal::Bool(true),
                    "False" => Literal::Bool(false),
                    _ => return Err(bad(&format!("unsupported value '{word}' for '{key}'"))),
                }
            }
        };
        out.push((key, value));
        skip_ws(&mut chars);
        match chars.next() {
            Some(',') => {}
            Some('}') => break,
            _ => return Err(bad("expected ',' or '}' after a value")),
        }
    }
    Ok(out)
}

fn parse_dtype(descr: &str) -> Result<Dtype> {
    let big = match descr.chars().next() {
        Some('>') => true,
        Some('<' | '=' | '|') => false,
        _ => {
            return Err(Error::unsupported(
                FMT,
                format!("dtype '{descr}' (expected '<f4', '>f4', '<f8' or '>f8')"),
            ));
        }
    };
    match descr.get(1..) {
        Some("f4") => Ok(Dtype::F4 { big }),
        Some("f8") => Ok(Dtype::F8 { big }),
        _ => Err(Error::unsupported(
            FMT,
            format!(
                "dtype '{}' (only float32 and float64 arrays are read)",
                descr.chars().take(40).collect::<String>()
            ),
        )),
    }
}

/// Reads a 2-D float32/float64 C-order `.npy` file.
pub fn read_npy(bytes: &[u8]) -> Result<NpyArray> {
    if bytes.len() < 10 {
        return Err(Error::truncated(
            FMT,
            format!("{} bytes, a header needs at least 10", bytes.len()),
        ));
    }
    if !bytes.starts_with(MAGIC) {
        return Err(Error::malformed(FMT, "missing the \\x93NUMPY magic"));
    }
    let major = bytes[6];
    let (header_len, start) = match major {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10usize),
        2 | 3 => {
            let b = bytes
                .get(8..12)
                .ok_or_else(|| Error::truncated(FMT, "header length"))?;
            (
                u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
                12usize,
            )
        }
        v => {
            return Err(Error::unsupported(
                FMT,
                format!(
                    "format version {v}.{} (1.0, 2.0 and 3.0 are read)",
                    bytes[7]
                ),
            ));
        }
    };
    let end = start
        .checked_add(header_len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| {
            Error::truncated(
                FMT,
                format!(
                    "the header declares {header_len} bytes but the file has {}",
                    bytes.len().saturating_sub(start)
                ),
            )
        })?;
    let header_bytes = &bytes[start..end];
    let header = if major == 3 {
        std::str::from_utf8(header_bytes)
            .map_err(|_| Error::malformed(FMT, "header is not UTF-8"))?
    } else {
        if !header_bytes.is_ascii() {
            return Err(Error::malformed(FMT, "header is not ASCII"));
        }
        std::str::from_utf8(header_bytes).map_err(|_| Error::malformed(FMT, "header"))?
    };
    let entries = parse_header(header)?;
    let get = |k: &str| entries.iter().find(|(key, _)| key == k).map(|(_, v)| v);
    let dtype = match get("descr") {
        Some(Literal::Str(s)) => parse_dtype(s)?,
        Some(_) => {
            return Err(Error::unsupported(
                FMT,
                "structured dtype (only plain float32/float64 arrays are read)",
            ));
        }
        None => return Err(Error::malformed(FMT, "header has no 'descr'")),
    };
    match get("fortran_order") {
        Some(Literal::Bool(false)) => {}
        Some(Literal::Bool(true)) => {
            return Err(Error::unsupported(
                FMT,
                "Fortran-order array (save it with np.ascontiguousarray)",
            ));
        }
        _ => {
            return Err(Error::malformed(
                FMT,
                "header has no boolean 'fortran_order'",
            ));
        }
    }
    let (rows, cols) = match get("shape") {
        Some(Literal::Tuple(s)) if s.len() == 2 => (s[0], s[1]),
        Some(Literal::Tuple(s)) => {
            return Err(Error::unsupported(
                FMT,
                format!(
                    "{}-D array (a 2-D (rows, columns) array is expected)",
                    s.len()
                ),
            ));
        }
        _ => return Err(Error::malformed(FMT, "header has no 'shape' tuple")),
    };
    let data = &bytes[end..];
    let size = dtype.size() as u64;
    let available = data.len() as u64 / size;
    let count = rows.checked_mul(cols).ok_or(Error::CountMismatch {
        format: FMT,
        what: "values",
        declared: u64::MAX,
        available,
    })?;
    if count > available {
        return Err(Error::CountMismatch {
            format: FMT,
            what: "values",
            declared: count,
            available,
        });
    }
    let count = count as usize;
    let values: Vec<f64> = match dtype {
        Dtype::F4 { big } => data
            .chunks_exact(4)
            .take(count)
            .map(|c| {
                let b = [c[0], c[1], c[2], c[3]];
                f64::from(if big {
                    f32::from_be_bytes(b)
                } else {
                    f32::from_le_bytes(b)
                })
            })
            .collect(),
        Dtype::F8 { big } => data
            .chunks_exact(8)
            .take(count)
            .map(|c| {
                let b = [c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]];
                if big {
                    f64::from_be_bytes(b)
                } else {
                    f64::from_le_bytes(b)
                }
            })
            .collect(),
    };
    Ok(NpyArray {
        rows: rows as usize,
        cols: cols as usize,
        values,
    })
}

/// A depth image (`docs/dataset.md`): metres along the camera's optical axis (OpenCV z) of the
/// surface seen through the centre of each pixel, row 0 at the top; 0 where nothing was hit.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthMap {
    /// Width in pixels (columns).
    pub width: usize,
    /// Height in pixels (rows).
    pub height: usize,
    /// `width × height` depths, row-major, row 0 at the top; 0 = background.
    pub depth: Vec<f32>,
}

impl DepthMap {
    /// Reads a depth map from `.npy` bytes (shape `(height, width)`). Non-finite or negative
    /// depths are refused, and so are `float64` depths beyond the `f32` range (≈ 3.4·10³⁸) the
    /// map is kept in.
    pub fn from_npy(bytes: &[u8]) -> Result<DepthMap> {
        let a = read_npy(bytes)?;
        if a.rows == 0 || a.cols == 0 {
            return Err(Error::Empty {
                what: format!("depth map ({}×{})", a.cols, a.rows),
            });
        }
        let bad: Vec<usize> = a
            .values
            .iter()
            .enumerate()
            .filter(|(_, v)| !((**v as f32).is_finite() && **v >= 0.0))
            .map(|(i, _)| i)
            .collect();
        if let Some(&first) = bad.first() {
            return Err(Error::malformed(
                FMT,
                format!(
                    "{} depth value(s) are negative, not finite or beyond the f32 range; the first at row {}, column {}",
                    bad.len(),
                    first / a.cols,
                    first % a.cols
                ),
            ));
        }
        Ok(DepthMap {
            width: a.cols,
            height: a.rows,
            depth: a.values.iter().map(|&v| v as f32).collect(),
        })
    }

    /// The depth of pixel (column `u`, row `v`); `None` outside the image.
    #[inline]
    pub(crate) fn at(&self, u: usize, v: usize) -> Option<f64> {
        if u >= self.width || v >= self.height {
            return None;
        }
        self.depth.get(v * self.width + u).map(|&d| f64::from(d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn dir() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/fixtures/npy")
    }

    fn fixture(name: &str) -> Vec<u8> {
        std::fs::read(dir().join(name)).unwrap()
    }

    #[test]
    fn numpy_files_match_their_manifest() {
        let manifest: serde_json::Value =
            serde_json::from_slice(&fixture("manifest.json")).unwrap();
        let entries = manifest.as_object().unwrap();
        assert!(entries.len() >= 9);
        let mut read = 0;
        for (name, want) in entries {
            let got = read_npy(&fixture(name));
            let shape: Vec<u64> = want["shape"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap())
                .collect();
            let dtype = want["dtype"].as_str().unwrap();
            let readable = shape.len() == 2
                && !want["fortran_order"].as_bool().unwrap()
                && dtype.ends_with("f4") | dtype.ends_with("f8");
            if !readable {
                let e = got.expect_err(name);
                assert_eq!(e.kind(), "unsupported", "{name}: {e}");
                continue;
            }
            let a = got.unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(
                [a.rows as u64, a.cols as u64],
                [shape[0], shape[1]],
                "{name}"
            );
            let sum: f64 = a.values.iter().sum();
            let want_sum = want["sum"].as_f64().unwrap();
            assert!(
                (sum - want_sum).abs() < 1e-9 * want_sum.abs().max(1.0),
                "{name}"
            );
            if let Some(values) = want["values"].as_array() {
                let v: Vec<f64> = values.iter().map(|v| v.as_f64().unwrap()).collect();
                assert_eq!(a.values, v, "{name}");
            }
            read += 1;
        }
        assert_eq!(read, 6);
    }

    #[test]
    fn depth_map_layout_is_row_major_top_first() {
        let d = DepthMap::from_npy(&fixture("small_f4.npy")).unwrap();
        assert_eq!((d.width, d.height), (4, 3));
        // np.arange(12).reshape(3, 4) * 0.25: row 1, column 2 holds 6 * 0.25.
        assert_eq!(d.at(2, 1), Some(1.5));
        assert_eq!(d.at(4, 0), None);
        let be = read_npy(&fixture("small_f4_be.npy")).unwrap();
        assert_eq!(be.values, vec![0.5, 1.5, 2.5, 3.5, 4.5, 5.5]);
    }

    #[test]
    fn errors_are_typed() {
        let good = fixture("small_f4.npy");
        assert_eq!(read_npy(&good[..5]).unwrap_err().kind(), "truncated");
        assert_eq!(read_npy(b"NOTNUMPY__xx").unwrap_err().kind(), "malformed");
        assert_eq!(
            read_npy(&good[..good.len() - 4]).unwrap_err().kind(),
            "count_mismatch"
        );
        let mut v9 = good.clone();
        v9[6] = 9;
        assert_eq!(read_npy(&v9).unwrap_err().kind(), "unsupported");
        // A negative depth is refused with its position.
        let mut neg = good.clone();
        let n = neg.len();
        neg[n - 4..].copy_from_slice(&(-1.0f32).to_le_bytes());
        let e = DepthMap::from_npy(&neg).unwrap_err();
        assert!(e.to_string().contains("row 2, column 3"), "{e}");
        assert!(
            parse_header("{'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }").is_ok()
        );
        assert!(parse_header("{'descr': '<f4' 'x'}").is_err());
        assert!(parse_header("{'shape': (99999999999999999999999, 4)}").is_err());
    }
}
