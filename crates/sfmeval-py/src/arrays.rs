//! numpy arrays in: rows of three numbers read straight from the array's memory (through
//! numpy's `__array_interface__`; the limited API of an abi3 wheel before Python 3.11 has no
//! buffer protocol) into the core's own storage, one copy, under the GIL. The Python wrapper
//! hands over C-contiguous, aligned arrays (it makes a contiguous copy only of an array whose
//! layout is not: Fortran order, a strided view); this checks again and refuses anything else.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::InputError;

/// The typestr of `f32`/`f64`/`u32` in this machine's byte order, as numpy writes it.
fn typestr(kind: char, size: usize) -> String {
    let order = if cfg!(target_endian = "little") {
        '<'
    } else {
        '>'
    };
    format!("{order}{kind}{size}")
}

/// The rows of the `(N, 3)` array `array` of `T` (numpy kind `kind`: `f` or `u`), copied.
/// `what` names the argument in errors.
fn rows<T: Copy>(array: &Bound<'_, PyAny>, kind: char, what: &str) -> PyResult<Vec<[T; 3]>> {
    let want = typestr(kind, std::mem::size_of::<T>());
    let bad = |why: String| InputError::new_err(format!("{what}: {why}"));
    let interface = array
        .getattr("__array_interface__")
        .map_err(|_| bad("not a numpy array".into()))?;
    let interface = interface
        .cast::<PyDict>()
        .map_err(|_| bad("no array interface".into()))?;
    let item = |key: &str| -> PyResult<Bound<'_, PyAny>> {
        interface
            .get_item(key)?
            .ok_or_else(|| bad(format!("the array interface has no '{key}'")))
    };
    let found: String = item("typestr")?.extract()?;
    if found != want {
        return Err(bad(format!("an array of {want} is needed, got {found}")));
    }
    let shape: Vec<usize> = item("shape")?.extract()?;
    let [n, 3] = shape[..] else {
        return Err(bad(format!(
            "an (N, 3) array is needed, got shape {shape:?}"
        )));
    };
    if !item("strides")?.is_none() {
        return Err(bad("the array is not C-contiguous".into()));
    }
    let (address, _read_only): (usize, bool) = item("data")?.extract()?;
    if n == 0 {
        return Ok(Vec::new());
    }
    if address == 0 || !address.is_multiple_of(std::mem::align_of::<T>()) {
        return Err(bad("the array's memory is not aligned".into()));
    }
    // SAFETY: numpy's interface says `address` starts `n` C-contiguous rows of three `T`
    // (typestr, shape and no strides checked above), aligned (checked); `array` is borrowed
    // for this whole function, so the memory stays allocated, and it is read under the GIL,
    // as numpy's own C code reads it.
    #[allow(unsafe_code)]
    let view = unsafe { std::slice::from_raw_parts(address as *const [T; 3], n) };
    Ok(view.to_vec())
}

/// An `(N, 3)` float64 array's rows.
pub(crate) fn rows_f64(array: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    rows(array, 'f', what)
}

/// An `(N, 3)` float32 array's rows.
pub(crate) fn rows_f32(array: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f32; 3]>> {
    rows(array, 'f', what)
}

/// An `(N, 3)` uint32 array's rows (triangles' vertex indices).
pub(crate) fn rows_u32(array: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[u32; 3]>> {
    rows(array, 'u', what)
}

/// Positions as the array stores them: `f32` rows stay `f32` (as a float PLY is read), `f64`
/// rows `f64`.
pub(crate) fn positions(
    array: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<sfmeval::geometry::Positions> {
    let dtype: String = array.getattr("dtype")?.getattr("str")?.extract()?;
    if dtype == typestr('f', 4) {
        Ok(sfmeval::geometry::Positions::F32(rows_f32(array, what)?))
    } else {
        Ok(sfmeval::geometry::Positions::F64(rows_f64(array, what)?))
    }
}
