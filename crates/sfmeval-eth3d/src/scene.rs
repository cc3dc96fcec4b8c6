//! The ground truth: the project's scans with their points (read from PLY as PCL's
//! `loadPLYFile` reads them into `pcl::PointXYZ`: `float` x y z, doubles rounded to float) and
//! poses, and the two transforms the tool applies in its own single-precision order.

use sfmeval::{Error, Result};

use crate::mlp::{MlpScan, read_mlp};

/// A file's name and bytes.
#[derive(Clone, Copy, Debug)]
pub struct NamedBytes<'a> {
    /// The name errors give.
    pub name: &'a str,
    /// The bytes.
    pub bytes: &'a [u8],
}

/// One laser scan in its own frame (the scanner at the origin, z up).
#[derive(Debug, Clone)]
pub struct Scan {
    /// The file the points came from.
    pub file: String,
    /// The project's entry for it.
    pub entry: MlpScan,
    /// The points in the scan's frame.
    pub points: Vec<[f32; 3]>,
}

/// An ETH3D ground truth: the scans of a MeshLab project.
#[derive(Debug, Clone)]
pub struct Eth3dScene {
    /// The scans in the project's order.
    pub scans: Vec<Scan>,
}

/// A PLY's vertices as the tool reads them into `pcl::PointXYZ` (single precision).
pub fn read_points_f32(bytes: &[u8]) -> Result<Vec<[f32; 3]>> {
    let ply = sfmeval::io::ply::read_ply(bytes)?;
    Ok(match ply.vertices {
        sfmeval::geometry::Positions::F32(v) => v,
        sfmeval::geometry::Positions::F64(v) => v.iter().map(|p| p.map(|c| c as f32)).collect(),
    })
}

impl Eth3dScene {
    /// The project's scans: `mlp` the project, `scan_bytes` called with each entry to give its
    /// file (name and bytes; the caller resolves the path with [`crate::mlp::scan_path`]).
    pub fn read<'a, F>(mlp: NamedBytes<'_>, mut scan_bytes: F) -> Result<Eth3dScene>
    where
        F: FnMut(&MlpScan) -> Result<NamedBytes<'a>>,
    {
        let entries =
            read_mlp(mlp.bytes).map_err(|e| e.in_file("ground-truth project", mlp.name))?;
        let mut scans = Vec::with_capacity(entries.len());
        for entry in entries {
            let file = scan_bytes(&entry)?;
            let points = read_points_f32(file.bytes).map_err(|e| e.in_file("scan", file.name))?;
            if let Some(k) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
                return Err(Error::InvalidContent(format!(
                    "vertex {k} is not finite ({:?}): a scan's points must all be",
                    points[k]
                ))
                .in_file("scan", file.name));
            }
            scans.push(Scan {
                file: file.name.to_string(),
                entry,
                points,
            });
        }
        Ok(Eth3dScene { scans })
    }

    /// Every scan point in the global frame, the scans one after the other in the project's
    /// order (the tool's merged cloud and its completeness cloud's order).
    pub fn global_points(&self) -> Vec<[f32; 3]> {
        let mut out = Vec::with_capacity(self.scans.iter().map(|s| s.points.len()).sum());
        for s in &self.scans {
            out.extend(
                s.points
                    .iter()
                    .map(|p| global_from_scan(&s.entry.global_from_scan, p)),
            );
        }
        out
    }
}

/// `pcl::transformPointCloud` with a `Matrix4f` as PCL 1.13 computes it with SSE2 (its
/// `Transformer<float>::se3`): `m₀₀x + (m₀₁y + (m₀₂z + m₀₃))` per row, in `float`.
pub fn global_from_scan(m: &[[f32; 4]; 4], p: &[f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|i| m[i][0] * p[0] + (m[i][1] * p[1] + (m[i][2] * p[2] + m[i][3])))
}

/// `scan_from_global` as the tool's accuracy caches it: `Rᵀ` and `Rᵀ(−t)` (not checked to be a
/// rotation, as in the tool), applied as Eigen 3.4 evaluates `Matrix3f * Vector3f + Vector3f`
/// (each row's products summed `a₀ + (a₁ + a₂)`, then the translation added).
#[derive(Debug, Clone, Copy)]
pub struct ScanFromGlobal {
    r: [[f32; 3]; 3],
    t: [f32; 3],
}

fn mat3_vec3(r: &[[f32; 3]; 3], p: &[f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|i| r[i][0] * p[0] + (r[i][1] * p[1] + r[i][2] * p[2]))
}

impl ScanFromGlobal {
    /// The inverse of `global_from_scan` (its rotation block transposed).
    pub fn new(global_from_scan: &[[f32; 4]; 4]) -> ScanFromGlobal {
        let m = global_from_scan;
        let r = [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[j][i]));
        let minus_t = [0, 1, 2].map(|i| -m[i][3]);
        ScanFromGlobal {
            r,
            t: mat3_vec3(&r, &minus_t),
        }
    }

    /// `p` in the scan's frame.
    pub fn apply(&self, p: &[f32; 3]) -> [f32; 3] {
        let q = mat3_vec3(&self.r, p);
        [q[0] + self.t[0], q[1] + self.t[1], q[2] + self.t[2]]
    }
}
