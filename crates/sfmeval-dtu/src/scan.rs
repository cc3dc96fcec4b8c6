//! A DTU scan's ground-truth files as the benchmark ships them: the STL points
//! (`Points/stl/stl{scan:03}_total.ply`), the observation mask
//! (`ObsMask/ObsMask{scan}_10.mat`: `ObsMask`, `BB`, `Res`) and the ground plane
//! (`ObsMask/Plane{scan}.mat`: `P`).

use sfmeval::geometry::Point3;
use sfmeval::{Error, Result};

use crate::mat::{MatData, MatFile, read_mat};

/// The STL points' path inside the dataset folder, as the benchmark names it.
pub fn stl_path(scan: u32) -> String {
    format!("Points/stl/stl{scan:03}_total.ply")
}

/// The observation mask's path inside the dataset folder.
pub fn obs_mask_path(scan: u32) -> String {
    format!("ObsMask/ObsMask{scan}_10.mat")
}

/// The ground plane's path inside the dataset folder.
pub fn plane_path(scan: u32) -> String {
    format!("ObsMask/Plane{scan}.mat")
}

/// The observation mask: which cells of a grid over the bounding box the scanner saw.
#[derive(Debug, Clone, PartialEq)]
pub struct ObsMask {
    /// The cells, column-major as MATLAB stores them: cell (i, j, k) at
    /// `i + dims[0] * (j + dims[1] * k)`; non-zero = observed.
    pub cells: Vec<u8>,
    /// The grid's size.
    pub dims: [usize; 3],
    /// `BB`: the bounding box's minimum (row 0) and maximum (row 1) corner, in mm.
    pub bb: [[f64; 3]; 2],
    /// `Res`: the grid's cell size, in mm.
    pub res: f64,
}

impl ObsMask {
    /// Reads `ObsMask`, `BB` and `Res` from the bytes of an `ObsMask*.mat` file.
    pub fn from_mat(bytes: &[u8]) -> Result<ObsMask> {
        let mat = read_mat(bytes)?;
        let mask = mat.get("ObsMask")?;
        let dims: [usize; 3] = match mask.dims.as_slice() {
            [a, b] => [*a, *b, 1],
            [a, b, c] => [*a, *b, *c],
            d => {
                return Err(Error::InvalidContent(format!(
                    "ObsMask has {} dimensions; a 3-D array is expected",
                    d.len()
                )));
            }
        };
        let cells = match &mask.data {
            MatData::U8(v) => v.clone(),
            MatData::F64(v) => v.iter().map(|&x| u8::from(x != 0.0)).collect(),
        };
        let bb_arr = mat.get("BB")?;
        if bb_arr.dims != [2, 3] {
            return Err(Error::InvalidContent(format!(
                "BB is {:?}; a 2x3 array (minimum and maximum corner) is expected",
                bb_arr.dims
            )));
        }
        let v = bb_arr.to_f64();
        // Column-major: BB(r, c) at r + 2 c.
        let bb = [[v[0], v[2], v[4]], [v[1], v[3], v[5]]];
        if !v.iter().all(|x| x.is_finite()) {
            return Err(Error::InvalidContent(format!(
                "BB holds a non-finite value: {v:?}"
            )));
        }
        let res = scalar(&mat, "Res")?;
        if !(res.is_finite() && res > 0.0) {
            return Err(Error::InvalidContent(format!(
                "Res is {res}; a positive cell size is expected"
            )));
        }
        Ok(ObsMask {
            cells,
            dims,
            bb,
            res,
        })
    }
}

fn scalar(mat: &MatFile, name: &str) -> Result<f64> {
    let a = mat.get(name)?;
    match a.to_f64().as_slice() {
        [x] => Ok(*x),
        v => Err(Error::InvalidContent(format!(
            "{name} has {} values; one is expected",
            v.len()
        ))),
    }
}

/// Reads the ground plane `P` (a, b, c, d: a point is above when a x + b y + c z + d > 0) from
/// the bytes of a `Plane*.mat` file.
pub fn plane_from_mat(bytes: &[u8]) -> Result<[f64; 4]> {
    let mat = read_mat(bytes)?;
    let p = mat.get("P")?.to_f64();
    match p.as_slice() {
        [a, b, c, d] if p.iter().all(|x| x.is_finite()) => Ok([*a, *b, *c, *d]),
        _ => Err(Error::InvalidContent(format!(
            "P is {p:?}; four finite numbers (the plane a x + b y + c z + d = 0) are expected"
        ))),
    }
}

/// A scan's ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct DtuScan {
    /// The STL points, in mm.
    pub stl: Vec<Point3>,
    /// The observation mask.
    pub obs_mask: ObsMask,
    /// The ground plane.
    pub plane: [f64; 4],
}

/// A named file's bytes.
pub struct NamedBytes<'a> {
    /// The file's name as the user gave it (for messages).
    pub name: &'a str,
    /// Its bytes.
    pub bytes: &'a [u8],
}

impl DtuScan {
    /// Reads the three files; an error names the file it is about.
    pub fn read(
        stl: NamedBytes<'_>,
        obs_mask: NamedBytes<'_>,
        plane: NamedBytes<'_>,
    ) -> Result<DtuScan> {
        let obs = ObsMask::from_mat(obs_mask.bytes)
            .map_err(|e| e.in_file("DTU observation mask", obs_mask.name))?;
        let plane_p =
            plane_from_mat(plane.bytes).map_err(|e| e.in_file("DTU ground plane", plane.name))?;
        let stl_points =
            read_points(stl.bytes).map_err(|e| e.in_file("DTU STL points", stl.name))?;
        Ok(DtuScan {
            stl: stl_points,
            obs_mask: obs,
            plane: plane_p,
        })
    }
}

/// The vertices of a PLY file as `f64`.
fn read_points(bytes: &[u8]) -> Result<Vec<Point3>> {
    let ply = sfmeval::io::ply::read_ply(bytes)?;
    if ply.vertices.is_empty() {
        return Err(Error::Empty {
            what: "the STL point cloud".into(),
        });
    }
    Ok(ply.vertices.into_f64())
}
