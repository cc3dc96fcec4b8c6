//! Readers, all on bytes. Format detection by name and content.

pub mod gltf;
pub mod npy;
pub mod obj;
pub mod ply;

use std::collections::BTreeMap;

use crate::error::{Error, Result};
use crate::geometry::{GroundTruth, PointCloud, TriangleMesh};

/// A file format the core reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Stanford PLY.
    Ply,
    /// Binary glTF.
    Glb,
    /// glTF JSON.
    Gltf,
    /// Wavefront OBJ.
    Obj,
}

impl Format {
    /// The report's name of the format.
    pub fn name(self) -> &'static str {
        match self {
            Format::Ply => "ply",
            Format::Glb => "glb",
            Format::Gltf => "gltf",
            Format::Obj => "obj",
        }
    }
}

/// Detects the format from the content first, the file name's extension second.
pub fn detect(name: &str, bytes: &[u8]) -> Result<Format> {
    if bytes.starts_with(b"ply") {
        return Ok(Format::Ply);
    }
    if gltf::is_glb(bytes) {
        return Ok(Format::Glb);
    }
    let ext = name.rsplit('.').next().unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "ply" => Ok(Format::Ply),
        "glb" => Ok(Format::Glb),
        "gltf" => Ok(Format::Gltf),
        "obj" => Ok(Format::Obj),
        _ => {
            let head = bytes.iter().copied().find(|c| !c.is_ascii_whitespace());
            if head == Some(b'{') {
                Ok(Format::Gltf)
            } else {
                Err(Error::UnknownFormat(format!(
                    "'{name}' is not PLY, glTF/GLB or OBJ (by content or extension)"
                )))
            }
        }
    }
}

/// A ground truth as read, with what the report needs to know.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedGroundTruth {
    /// The geometry.
    pub ground_truth: GroundTruth,
    /// The format read.
    pub format: Format,
    /// Notes for the report.
    pub warnings: Vec<String>,
}

/// Reads a ground truth: GLB/glTF/OBJ meshes, PLY meshes, or a PLY cloud (no faces).
/// `external` supplies the external buffers of a `.gltf` by relative URI.
pub fn read_ground_truth(
    name: &str,
    bytes: &[u8],
    external: &BTreeMap<String, Vec<u8>>,
) -> Result<LoadedGroundTruth> {
    let format = detect(name, bytes)?;
    let mut warnings = Vec::new();
    let ground_truth = match format {
        Format::Glb | Format::Gltf => {
            let g = gltf::read_gltf(bytes, external)?;
            warnings.extend(g.warnings);
            GroundTruth::Mesh(g.mesh)
        }
        Format::Obj => GroundTruth::Mesh(obj::read_obj(bytes)?),
        Format::Ply => {
            let p = ply::read_ply(bytes)?;
            if p.skipped_faces > 0 {
                warnings.push(format!(
                    "{} faces with fewer than 3 vertices were skipped",
                    p.skipped_faces
                ));
            }
            if p.has_faces && !p.triangles.is_empty() {
                let mesh = TriangleMesh {
                    vertices: p.vertices,
                    triangles: p.triangles,
                };
                mesh.validate("PLY")?;
                GroundTruth::Mesh(mesh)
            } else {
                if p.vertices.is_empty() {
                    return Err(Error::Empty {
                        what: "ground-truth PLY (no vertices)".into(),
                    });
                }
                GroundTruth::Cloud(PointCloud {
                    points: p.vertices,
                    colors: p.colors,
                })
            }
        }
    };
    Ok(LoadedGroundTruth {
        ground_truth,
        format,
        warnings,
    })
}

/// A reconstruction point cloud as read.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedCloud {
    /// The points.
    pub cloud: PointCloud,
    /// The format read.
    pub format: Format,
    /// Notes for the report.
    pub warnings: Vec<String>,
}

/// Reads a reconstructed point cloud (PLY; the vertices of a mesh PLY/OBJ/glTF are used as points).
pub fn read_point_cloud(name: &str, bytes: &[u8]) -> Result<LoadedCloud> {
    let format = detect(name, bytes)?;
    let mut warnings = Vec::new();
    let cloud = match format {
        Format::Ply => {
            let p = ply::read_ply(bytes)?;
            if !p.triangles.is_empty() {
                warnings.push(format!(
                    "the reconstruction PLY has {} triangles; only its vertices are evaluated",
                    p.triangles.len()
                ));
            }
            PointCloud {
                points: p.vertices,
                colors: p.colors,
            }
        }
        Format::Obj => {
            warnings.push("the reconstruction is a mesh; only its vertices are evaluated".into());
            PointCloud {
                points: obj::read_obj(bytes)?.vertices,
                colors: None,
            }
        }
        Format::Glb | Format::Gltf => {
            warnings.push("the reconstruction is a mesh; only its vertices are evaluated".into());
            PointCloud {
                points: gltf::read_gltf(bytes, &BTreeMap::new())?.mesh.vertices,
                colors: None,
            }
        }
    };
    if cloud.points.is_empty() {
        return Err(Error::Empty {
            what: format!("reconstruction '{name}' (no points)"),
        });
    }
    Ok(LoadedCloud {
        cloud,
        format,
        warnings,
    })
}
