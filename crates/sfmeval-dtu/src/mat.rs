//! A reader of MATLAB level 5 `.mat` files (the format MATLAB writes with `save -v7` and
//! `-v6`, and scipy's `savemat`), for the numeric and logical arrays DTU ships: `ObsMask`
//! (a 3-D logical array), `BB`, `Res` and `P` (doubles).
//!
//! The file: a 128-byte header (text, subsystem offset, version `0x0100`, the endian indicator
//! `IM` or `MI`), then data elements, each an 8-byte tag (type, byte count; or the 4-byte
//! "small element" tag with its data in the next 4 bytes) and its data padded to 8 bytes. A
//! variable is an `miMATRIX` element (array flags with the class and the logical bit,
//! dimensions, name, real part), stored as is or inside an `miCOMPRESSED` element (a zlib
//! stream of one `miMATRIX`). Reference: MathWorks, "MAT-File Format", 2019 (the level 5
//! chapter).
//!
//! Why a reader of its own rather than a crate: the few variables DTU needs take 300 lines, and
//! this one bounds what a hostile file can make it allocate. A compressed element is inflated
//! in two steps: its first bytes (the array's header, [`HEAD_BYTES`]), then no further than the
//! size that header declares, which must agree with the dimensions and stay below
//! [`MAX_ARRAY_BYTES`]. Uncompressed data is never copied before its size is checked against
//! the bytes present. Complex, sparse, cell, struct, char and object arrays are refused with an
//! error that names the variable and its class.

use sfmeval::{Error, Result};

const FORMAT: &str = "MAT";

/// Most bytes one array's data may take once inflated (4 GiB): DTU's largest observation mask
/// holds some hundred million cells at one byte each.
pub const MAX_ARRAY_BYTES: u64 = 4 << 30;

/// How much of a compressed element is inflated first to read the array's header (flags,
/// dimensions, name and the data's tag).
pub const HEAD_BYTES: usize = 4096;

/// Most dimensions an array may have here.
const MAX_DIMS: usize = 32;

/// A variable's element values as read.
#[derive(Debug, Clone, PartialEq)]
pub enum MatData {
    /// Bytes of a `uint8` or logical array (logical arrays are `uint8` with the logical flag).
    U8(Vec<u8>),
    /// Values of any other numeric class, converted to `f64` (exact for every class but
    /// `int64`/`uint64` beyond 2⁵³).
    F64(Vec<f64>),
}

/// MATLAB's array classes that this reader accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MatClass {
    /// `double` (mxDOUBLE_CLASS, 6).
    Double,
    /// `single` (7).
    Single,
    /// `int8` (8).
    Int8,
    /// `uint8` (9), also the class of logical arrays.
    Uint8,
    /// `int16` (10).
    Int16,
    /// `uint16` (11).
    Uint16,
    /// `int32` (12).
    Int32,
    /// `uint32` (13).
    Uint32,
    /// `int64` (14).
    Int64,
    /// `uint64` (15).
    Uint64,
}

impl MatClass {
    fn from_code(code: u8) -> std::result::Result<MatClass, &'static str> {
        Ok(match code {
            6 => MatClass::Double,
            7 => MatClass::Single,
            8 => MatClass::Int8,
            9 => MatClass::Uint8,
            10 => MatClass::Int16,
            11 => MatClass::Uint16,
            12 => MatClass::Int32,
            13 => MatClass::Uint32,
            14 => MatClass::Int64,
            15 => MatClass::Uint64,
            1 => return Err("a cell array"),
            2 => return Err("a struct array"),
            3 => return Err("an object"),
            4 => return Err("a char array"),
            5 => return Err("a sparse array"),
            16 => return Err("a function handle"),
            17 => return Err("an opaque object"),
            _ => return Err("of an unknown class"),
        })
    }

    /// MATLAB's name of the class.
    pub fn name(self) -> &'static str {
        match self {
            MatClass::Double => "double",
            MatClass::Single => "single",
            MatClass::Int8 => "int8",
            MatClass::Uint8 => "uint8",
            MatClass::Int16 => "int16",
            MatClass::Uint16 => "uint16",
            MatClass::Int32 => "int32",
            MatClass::Uint32 => "uint32",
            MatClass::Int64 => "int64",
            MatClass::Uint64 => "uint64",
        }
    }
}

/// One variable of a `.mat` file.
#[derive(Debug, Clone, PartialEq)]
pub struct MatArray {
    /// The variable's name.
    pub name: String,
    /// Its dimensions, MATLAB's (column-major: the first index varies fastest in `data`).
    pub dims: Vec<usize>,
    /// Its class.
    pub class: MatClass,
    /// Whether MATLAB marks it logical.
    pub logical: bool,
    /// The values in column-major order.
    pub data: MatData,
}

impl MatArray {
    /// Number of elements (the product of the dimensions).
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    /// Whether the array has no element.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values as `f64` (a `uint8`/logical array's bytes widened).
    pub fn to_f64(&self) -> Vec<f64> {
        match &self.data {
            MatData::U8(v) => v.iter().map(|&b| f64::from(b)).collect(),
            MatData::F64(v) => v.clone(),
        }
    }
}

/// The variables of a `.mat` file, in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct MatFile {
    /// The variables.
    pub arrays: Vec<MatArray>,
}

impl MatFile {
    /// The variable called `name`, or an error that names it and lists those present.
    pub fn get(&self, name: &str) -> Result<&MatArray> {
        self.arrays.iter().find(|a| a.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.arrays.iter().map(|a| a.name.as_str()).collect();
            Error::InvalidContent(format!(
                "the .mat file has no variable '{name}' (it has: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ))
        })
    }
}

// Data types of elements (miINT8 = 1, ...).
const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
const MI_UTF8: u32 = 16;

fn mi_size(ty: u32) -> Option<usize> {
    Some(match ty {
        MI_INT8 | MI_UINT8 | MI_UTF8 => 1,
        MI_INT16 | MI_UINT16 => 2,
        MI_INT32 | MI_UINT32 | MI_SINGLE => 4,
        MI_DOUBLE | MI_INT64 | MI_UINT64 => 8,
        _ => return None,
    })
}

#[derive(Clone, Copy)]
struct Endian {
    big: bool,
}

impl Endian {
    fn u16(self, b: [u8; 2]) -> u16 {
        if self.big {
            u16::from_be_bytes(b)
        } else {
            u16::from_le_bytes(b)
        }
    }
    fn u32(self, b: &[u8]) -> u32 {
        let a = [b[0], b[1], b[2], b[3]];
        if self.big {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        }
    }
}

/// A tag read at some offset: the element's type, its data and where the next element starts.
struct Element<'a> {
    ty: u32,
    data: &'a [u8],
    next: usize,
}

/// Reads the element at `at` of `bytes`; `pad` says whether its data is padded to 8 bytes (all
/// elements but a top-level compressed one, whose byte count is exact).
fn element<'a>(bytes: &'a [u8], at: usize, e: Endian, what: &str) -> Result<Element<'a>> {
    let tag = bytes.get(at..at + 8).ok_or_else(|| {
        Error::truncated_detail(format!("{what}: the element's tag at byte {at}"))
    })?;
    let first = e.u32(&tag[0..4]);
    // A small element: the byte count in the upper half of the first word (big-endian files
    // store the halves swapped with the word), the data in the next four bytes.
    let small_len = if e.big {
        e.u16([tag[0], tag[1]])
    } else {
        e.u16([tag[2], tag[3]])
    };
    if small_len != 0 {
        let ty = if e.big {
            u32::from(e.u16([tag[2], tag[3]]))
        } else {
            u32::from(e.u16([tag[0], tag[1]]))
        };
        if small_len > 4 {
            return Err(Error::malformed_detail(format!(
                "{what}: a small element declares {small_len} bytes (at most 4)"
            )));
        }
        return Ok(Element {
            ty,
            data: &tag[4..4 + usize::from(small_len)],
            next: at + 8,
        });
    }
    let len = e.u32(&tag[4..8]) as usize;
    let start = at + 8;
    let available = bytes.len() - start;
    if len > available {
        return Err(Error::truncated_detail(format!(
            "{what}: the element at byte {at} declares {len} bytes but {available} follow"
        )));
    }
    let padded = if first == MI_COMPRESSED {
        len
    } else {
        len.div_ceil(8) * 8
    };
    Ok(Element {
        ty: first,
        data: &bytes[start..start + len],
        next: (start + padded).min(bytes.len()),
    })
}

trait MatError {
    fn truncated_detail(detail: String) -> Error;
    fn malformed_detail(detail: String) -> Error;
}

impl MatError for Error {
    fn truncated_detail(detail: String) -> Error {
        Error::Truncated {
            format: FORMAT,
            detail,
        }
    }
    fn malformed_detail(detail: String) -> Error {
        Error::Malformed {
            format: FORMAT,
            detail,
        }
    }
}

/// Reads every variable of a level 5 `.mat` file.
pub fn read_mat(bytes: &[u8]) -> Result<MatFile> {
    if bytes.len() < 128 {
        if bytes.starts_with(b"\x89HDF") || bytes.len() >= 4 && &bytes[..4] == b"MATL" {
            return Err(Error::truncated_detail(format!(
                "the 128-byte header: the file has {} bytes",
                bytes.len()
            )));
        }
        return Err(Error::truncated_detail(format!(
            "the 128-byte header of a level 5 .mat file: the file has {} bytes",
            bytes.len()
        )));
    }
    if bytes.starts_with(b"\x89HDF") || bytes[512.min(bytes.len() - 8)..].starts_with(b"\x89HDF") {
        return Err(Error::Unsupported {
            format: FORMAT,
            detail: "this is a MATLAB 7.3 file (HDF5); save it with `save -v7` (DTU's files are level 5)".into(),
        });
    }
    let e = match &bytes[126..128] {
        b"IM" => Endian { big: false },
        b"MI" => Endian { big: true },
        _ => {
            return Err(Error::malformed_detail(
                "no level 5 .mat header (the endian indicator at bytes 126-127 is not IM or MI; a level 4 file or not a .mat file)".into(),
            ));
        }
    };
    let version = e.u16([bytes[124], bytes[125]]);
    if version != 0x0100 {
        return Err(Error::malformed_detail(format!(
            "header version {version:#06x}, expected 0x0100"
        )));
    }
    let mut arrays = Vec::new();
    let mut at = 128;
    while at < bytes.len() {
        let el = element(bytes, at, e, "a top-level element")?;
        match el.ty {
            MI_MATRIX => {
                if let Some(a) = matrix(el.data, e, at)? {
                    arrays.push(a);
                }
            }
            MI_COMPRESSED => {
                if let Some(a) = compressed(el.data, e, at)? {
                    arrays.push(a);
                }
            }
            // Other top-level elements (none are written in practice) are skipped.
            _ => {}
        }
        at = el.next;
    }
    Ok(MatFile { arrays })
}

/// Inflates the compressed element at byte `at`: its head first, then as far as the head
/// declares.
fn compressed(z: &[u8], e: Endian, at: usize) -> Result<Option<MatArray>> {
    use miniz_oxide::inflate::{TINFLStatus, decompress_to_vec_zlib_with_limit};
    let bad = |status: TINFLStatus| {
        let what = match status {
            TINFLStatus::FailedCannotMakeProgress => "the zlib stream ends early",
            TINFLStatus::Adler32Mismatch => "its checksum does not match",
            _ => "the zlib stream is corrupt",
        };
        Error::malformed_detail(format!(
            "the compressed element at byte {at} does not inflate: {what}"
        ))
    };
    let head = match decompress_to_vec_zlib_with_limit(z, HEAD_BYTES) {
        Ok(all) => all,
        Err(err) if err.status == TINFLStatus::HasMoreOutput => err.output,
        Err(err)
            if err.status == TINFLStatus::FailedCannotMakeProgress && err.output.len() >= 8 =>
        {
            err.output
        }
        Err(err) => return Err(bad(err.status)),
    };
    if head.len() < 8 {
        return Err(Error::truncated_detail(format!(
            "the compressed element at byte {at} inflates to {} bytes, less than a tag",
            head.len()
        )));
    }
    let ty = e.u32(&head[0..4]);
    if ty != MI_MATRIX {
        return Ok(None);
    }
    let declared = u64::from(e.u32(&head[4..8]));
    // The array's own header bounds the data: check the dimensions and class against the
    // declared size before inflating the rest.
    let total = declared + 8;
    if total > MAX_ARRAY_BYTES + 4096 {
        return Err(Error::LimitExceeded {
            format: FORMAT,
            what: format!("bytes declared by the compressed variable at byte {at}"),
            count: declared,
            limit: MAX_ARRAY_BYTES,
            hint: "",
        });
    }
    if head.len() as u64 >= total {
        let el = element(&head, 0, e, "a compressed variable")?;
        return matrix(el.data, e, at);
    }
    // Reads what the head holds of the header to refuse a wrong class or bad dimensions
    // before the large inflation.
    header_check(&head[8..], e, at, declared)?;
    let full = match decompress_to_vec_zlib_with_limit(z, total as usize) {
        Ok(all) => all,
        Err(err) if err.status == TINFLStatus::HasMoreOutput => err.output,
        Err(err) if err.status == TINFLStatus::FailedCannotMakeProgress => {
            return Err(Error::truncated_detail(format!(
                "the compressed element at byte {at} ends after {} of the {total} bytes its variable declares",
                err.output.len()
            )));
        }
        Err(err) => return Err(bad(err.status)),
    };
    let el = element(&full, 0, e, "a compressed variable")?;
    matrix(el.data, e, at)
}

/// The parts of an `miMATRIX` header that decide its size, read from a prefix of its data
/// (flags, dimensions), checked against the size the element declares.
fn header_check(m: &[u8], e: Endian, at: usize, declared: u64) -> Result<()> {
    let flags = element(m, 0, e, "the array flags")?;
    let class_code = flags.data.first().copied();
    let class_code = if e.big {
        flags.data.get(3).copied()
    } else {
        class_code
    };
    if let Some(code) = class_code {
        MatClass::from_code(code).map_err(|kind| {
            Error::Unsupported {
                format: FORMAT,
                detail: format!("the variable at byte {at} is {kind} (class {code}); only numeric and logical arrays are read"),
            }
        })?;
    }
    let dims = element(m, flags.next, e, "the dimensions")?;
    let n = dims_product(&dims, e, at)?;
    // Each element takes at least one byte: more elements than declared bytes is a lie.
    if n > declared {
        return Err(Error::CountMismatch {
            format: FORMAT,
            what: "array elements",
            declared: n,
            available: declared,
        });
    }
    Ok(())
}

fn dims_product(dims: &Element<'_>, e: Endian, at: usize) -> Result<u64> {
    if dims.ty != MI_INT32 || !dims.data.len().is_multiple_of(4) || dims.data.len() < 8 {
        return Err(Error::malformed_detail(format!(
            "the variable at byte {at} has no valid dimensions element"
        )));
    }
    let count = dims.data.len() / 4;
    if count > MAX_DIMS {
        return Err(Error::malformed_detail(format!(
            "the variable at byte {at} has {count} dimensions"
        )));
    }
    let mut n: u64 = 1;
    for c in dims.data.chunks_exact(4) {
        let d = e.u32(c) as i32;
        if d < 0 {
            return Err(Error::malformed_detail(format!(
                "the variable at byte {at} has a negative dimension ({d})"
            )));
        }
        n = n.saturating_mul(d as u64);
        if n > MAX_ARRAY_BYTES {
            return Err(Error::LimitExceeded {
                format: FORMAT,
                what: format!(
                    "elements of the variable at byte {at} (the product of its dimensions)"
                ),
                count: n,
                limit: MAX_ARRAY_BYTES,
                hint: "",
            });
        }
    }
    Ok(n)
}

/// Decodes the data of one `miMATRIX` element (starting at byte `at` of the file, for
/// messages). `None` for an array this reader skips (none at present).
fn matrix(m: &[u8], e: Endian, at: usize) -> Result<Option<MatArray>> {
    let flags = element(m, 0, e, "the array flags")?;
    if flags.ty != MI_UINT32 || flags.data.len() != 8 {
        return Err(Error::malformed_detail(format!(
            "the variable at byte {at} does not start with its array flags"
        )));
    }
    let word = e.u32(&flags.data[0..4]);
    let class_code = (word & 0xff) as u8;
    let complex = word & 0x0800 != 0;
    let logical = word & 0x0200 != 0;
    let dims_el = element(m, flags.next, e, "the dimensions")?;
    let n = dims_product(&dims_el, e, at)? as usize;
    let dims: Vec<usize> = dims_el
        .data
        .chunks_exact(4)
        .map(|c| e.u32(c) as usize)
        .collect();
    let name_el = element(m, dims_el.next, e, "the array name")?;
    if name_el.ty != MI_INT8 && name_el.ty != MI_UINT8 && name_el.ty != MI_UTF8 {
        return Err(Error::malformed_detail(format!(
            "the variable at byte {at} has no array name element"
        )));
    }
    let name = String::from_utf8_lossy(name_el.data).into_owned();
    let class = MatClass::from_code(class_code).map_err(|kind| Error::Unsupported {
        format: FORMAT,
        detail: format!(
            "variable '{name}' is {kind} (class {class_code}); only numeric and logical arrays are read"
        ),
    })?;
    if complex {
        return Err(Error::Unsupported {
            format: FORMAT,
            detail: format!("variable '{name}' is complex; only real arrays are read"),
        });
    }
    let real = element(m, name_el.next, e, &format!("variable '{name}''s data"))?;
    let size = mi_size(real.ty).ok_or_else(|| {
        Error::malformed_detail(format!(
            "variable '{name}''s data has the element type {}, which is no numeric type",
            real.ty
        ))
    })?;
    let stored = real.data.len() / size;
    if !real.data.len().is_multiple_of(size) || stored != n {
        return Err(Error::CountMismatch {
            format: FORMAT,
            what: "elements (the product of the dimensions)",
            declared: n as u64,
            available: stored as u64,
        });
    }
    let data = if class == MatClass::Uint8 {
        if real.ty != MI_UINT8 {
            // MATLAB may store any class in a narrower type; uint8 data is stored as uint8.
            let v = convert(real.data, real.ty, e);
            let mut out = Vec::with_capacity(n);
            for x in v {
                if !(0.0..=255.0).contains(&x) || x.fract() != 0.0 {
                    return Err(Error::malformed_detail(format!(
                        "variable '{name}' is uint8 but holds {x}"
                    )));
                }
                out.push(x as u8);
            }
            MatData::U8(out)
        } else {
            MatData::U8(real.data.to_vec())
        }
    } else {
        MatData::F64(convert(real.data, real.ty, e))
    };
    Ok(Some(MatArray {
        name,
        dims,
        class,
        logical,
        data,
    }))
}

/// The stored values as `f64`.
fn convert(data: &[u8], ty: u32, e: Endian) -> Vec<f64> {
    macro_rules! each {
        ($t:ty, $n:expr) => {
            data.chunks_exact($n)
                .map(|c| {
                    let mut a = [0u8; $n];
                    a.copy_from_slice(c);
                    let v = if e.big {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    };
                    v as f64
                })
                .collect()
        };
    }
    match ty {
        MI_INT8 => each!(i8, 1),
        MI_UINT8 | MI_UTF8 => each!(u8, 1),
        MI_INT16 => each!(i16, 2),
        MI_UINT16 => each!(u16, 2),
        MI_INT32 => each!(i32, 4),
        MI_UINT32 => each!(u32, 4),
        MI_SINGLE => each!(f32, 4),
        MI_DOUBLE => each!(f64, 8),
        MI_INT64 => each!(i64, 8),
        _ => each!(u64, 8),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A level 5 file with one uncompressed double matrix, written by hand as scipy writes it.
    fn double_file(name: &str, dims: &[i32], values: &[f64]) -> Vec<u8> {
        let mut m = Vec::new();
        let push_el = |m: &mut Vec<u8>, ty: u32, data: &[u8]| {
            m.extend_from_slice(&ty.to_le_bytes());
            m.extend_from_slice(&(data.len() as u32).to_le_bytes());
            m.extend_from_slice(data);
            while !m.len().is_multiple_of(8) {
                m.push(0);
            }
        };
        let mut flags = Vec::new();
        flags.extend_from_slice(&6u32.to_le_bytes());
        flags.extend_from_slice(&0u32.to_le_bytes());
        push_el(&mut m, MI_UINT32, &flags);
        let d: Vec<u8> = dims.iter().flat_map(|d| d.to_le_bytes()).collect();
        push_el(&mut m, MI_INT32, &d);
        push_el(&mut m, MI_INT8, name.as_bytes());
        let v: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        push_el(&mut m, MI_DOUBLE, &v);
        let mut f = vec![b' '; 116];
        f[..10].copy_from_slice(b"MATLAB 5.0");
        f.extend_from_slice(&[0; 8]);
        f.extend_from_slice(&0x0100u16.to_le_bytes());
        f.extend_from_slice(b"IM");
        f.extend_from_slice(&MI_MATRIX.to_le_bytes());
        f.extend_from_slice(&(m.len() as u32).to_le_bytes());
        f.extend_from_slice(&m);
        f
    }

    #[test]
    fn reads_a_double_matrix() {
        let f = double_file("BB", &[2, 3], &[1.0, 4.0, 2.0, 5.0, 3.0, 6.0]);
        let mat = read_mat(&f).unwrap();
        let bb = mat.get("BB").unwrap();
        assert_eq!(bb.dims, vec![2, 3]);
        assert_eq!(bb.class, MatClass::Double);
        assert_eq!(bb.to_f64(), vec![1.0, 4.0, 2.0, 5.0, 3.0, 6.0]);
        assert!(mat.get("Res").unwrap_err().to_string().contains("BB"));
    }

    #[test]
    fn every_truncation_is_an_error() {
        let f = double_file("BB", &[2, 3], &[1.0, 4.0, 2.0, 5.0, 3.0, 6.0]);
        for cut in 0..f.len() {
            // A cut between elements leaves a valid file with fewer variables.
            if let Ok(m) = read_mat(&f[..cut]) {
                assert!(m.arrays.is_empty(), "cut at {cut}");
            }
        }
    }

    #[test]
    fn huge_dimensions_are_refused_before_allocating() {
        let f = double_file("X", &[100_000, 100_000, 100_000], &[1.0]);
        let err = read_mat(&f).unwrap_err().to_string();
        assert!(err.contains("above the limit"), "{err}");
    }
}
