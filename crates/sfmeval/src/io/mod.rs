//! Readers, all on bytes. Format detection by name and content.

pub mod gltf;
pub mod npy;
pub mod obj;
pub mod ply;
pub mod ply_stream;

use std::collections::BTreeMap;

use crate::error::{Error, Result};
use crate::geometry::{GroundTruth, PointCloud, TriangleMesh};
use crate::note::{Code, Note};

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
    pub notes: Vec<Note>,
}

/// Limits on what a reader may build from a small file. A glTF scene instances meshes through
/// its node tree, so a few kilobytes can describe billions of triangles: the glTF reader counts
/// the triangles and vertices the scene expands to from the accessor counts, before decoding or
/// allocating anything, and refuses a scene beyond these limits with
/// [`Error::LimitExceeded`]. PLY and OBJ meshes are not held to these limits: each of their
/// triangles takes at least one byte of the file (one more index of a polygon face, fanned into
/// triangles; a separate triangle takes 13 bytes or more) and each vertex at least three, and the
/// PLY reader checks a declared count against the bytes left before it reserves anything, so the
/// file's size bounds what is built and a scan of any size is read, without a flag, up to what
/// memory allows (about 74 bytes a triangle through an evaluation).
///
/// The default, [`ReadLimits::DEFAULT_MAX_TRIANGLES`] = 10 M triangles and twice as many
/// vertices, keeps a whole evaluation under 2 GB: measured with `sfmeval eval` (reading, BVH,
/// 1 M completeness samples, alignment, exports), a mesh costs about 74 bytes per triangle and
/// 47 per vertex, and a 400 KB GLB instancing one mesh into exactly 10 M triangles and 20 M
/// vertices peaks at 1.7 GB. A front end raises the limit for a trusted large glTF with
/// [`ReadLimits::triangles`] (the CLI's `--max-triangles`); a non-indexed mesh has three
/// vertices per triangle, so it needs a limit of 1.5 × its triangle count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadLimits {
    /// Most triangles a ground-truth mesh may have once every node instance is expanded.
    pub max_triangles: u64,
    /// Most vertices it may have once expanded (glTF accessors without a buffer view, which
    /// cost no bytes, count too).
    pub max_vertices: u64,
}

impl ReadLimits {
    /// The default triangle limit: 10 M (and 20 M vertices).
    pub const DEFAULT_MAX_TRIANGLES: u64 = 10_000_000;

    /// Limits of `max_triangles` triangles and twice as many vertices (an indexed mesh has
    /// about half as many vertices as triangles).
    pub const fn triangles(max_triangles: u64) -> ReadLimits {
        ReadLimits {
            max_triangles,
            max_vertices: max_triangles.saturating_mul(2),
        }
    }

    /// Fails with [`Error::LimitExceeded`] when a mesh of `triangles` and `vertices` is beyond
    /// the limits.
    pub fn check(&self, format: &'static str, triangles: u64, vertices: u64) -> Result<()> {
        if triangles > self.max_triangles {
            return Err(Error::LimitExceeded {
                format,
                what: "triangles (every node instance expanded)".into(),
                count: triangles,
                limit: self.max_triangles,
                hint: LIMIT_HINT,
            });
        }
        if vertices > self.max_vertices {
            return Err(Error::LimitExceeded {
                format,
                what: "vertices (every node instance expanded)".into(),
                count: vertices,
                limit: self.max_vertices,
                hint: LIMIT_HINT,
            });
        }
        Ok(())
    }
}

/// How a user raises the limit, shown after [`Error::LimitExceeded`].
pub(crate) const LIMIT_HINT: &str =
    " (raise the max-triangles option for a trusted file: `--max-triangles N`, `maxTriangles`)";

impl Default for ReadLimits {
    fn default() -> Self {
        ReadLimits::triangles(Self::DEFAULT_MAX_TRIANGLES)
    }
}

/// Reads a ground truth: GLB/glTF/OBJ meshes, PLY meshes, or a PLY cloud (no faces).
/// `external` supplies the external buffers of a `.gltf` by relative URI. Uses the default
/// [`ReadLimits`]; see [`read_ground_truth_with_limits`].
pub fn read_ground_truth(
    name: &str,
    bytes: &[u8],
    external: &BTreeMap<String, Vec<u8>>,
) -> Result<LoadedGroundTruth> {
    read_ground_truth_with_limits(name, bytes, external, &ReadLimits::default())
}

/// [`read_ground_truth`] with explicit limits on the expanded mesh size.
pub fn read_ground_truth_with_limits(
    name: &str,
    bytes: &[u8],
    external: &BTreeMap<String, Vec<u8>>,
    limits: &ReadLimits,
) -> Result<LoadedGroundTruth> {
    let format = detect(name, bytes)?;
    let mut warnings = Vec::new();
    let ground_truth = match format {
        Format::Glb | Format::Gltf => {
            let g = gltf::read_gltf_with_limits(bytes, external, limits)?;
            warnings.extend(g.notes);
            GroundTruth::Mesh(g.mesh)
        }
        Format::Obj => {
            // No limit: the triangles are in the file (see `ReadLimits`).
            let m = obj::read_obj(bytes)?;
            GroundTruth::Mesh(m)
        }
        Format::Ply => {
            // No limit: the triangles are in the file (see `ReadLimits`).
            return ground_truth_from_ply(ply::read_ply(bytes)?);
        }
    };
    Ok(LoadedGroundTruth {
        ground_truth,
        format,
        notes: warnings,
    })
}

/// The ground truth of a PLY file already decoded ([`ply::read_ply`], or
/// [`ply::PlyData::from_memory`] for geometry a front end holds in memory), as
/// [`read_ground_truth`] makes it from the file: a mesh when it has faces, else a cloud. No
/// triangle limit: the triangles are present in the data (see [`ReadLimits`]).
pub fn ground_truth_from_ply(p: ply::PlyData) -> Result<LoadedGroundTruth> {
    let mut notes = Vec::new();
    if p.skipped_faces > 0 {
        notes.push(
            Note::new(
                Code::DegenerateFacesSkipped,
                format!(
                    "{} faces with fewer than 3 vertices were skipped",
                    p.skipped_faces
                ),
            )
            .with("count", p.skipped_faces),
        );
    }
    let ground_truth = if p.has_faces && !p.triangles.is_empty() {
        let mesh = TriangleMesh {
            vertices: p.vertices.into_f64(),
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
    };
    Ok(LoadedGroundTruth {
        ground_truth,
        format: Format::Ply,
        notes,
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
    pub notes: Vec<Note>,
}

/// Reads a reconstructed point cloud (PLY; the vertices of a mesh PLY/OBJ/glTF are used as
/// points), with the default [`ReadLimits`] (a glTF's node tree is expanded to read its
/// vertices).
pub fn read_point_cloud(name: &str, bytes: &[u8]) -> Result<LoadedCloud> {
    read_point_cloud_with_limits(name, bytes, &ReadLimits::default())
}

/// [`read_point_cloud`] with explicit limits (they matter for glTF only).
pub fn read_point_cloud_with_limits(
    name: &str,
    bytes: &[u8],
    limits: &ReadLimits,
) -> Result<LoadedCloud> {
    let format = detect(name, bytes)?;
    let mut warnings = Vec::new();
    let cloud = match format {
        Format::Ply => return point_cloud_from_ply(name, ply::read_ply(bytes)?),
        Format::Obj => {
            warnings.push(Note::new(
                Code::MeshVerticesOnly,
                "the reconstruction is a mesh; only its vertices are evaluated",
            ));
            PointCloud {
                points: obj::read_obj(bytes)?.vertices.into(),
                colors: None,
            }
        }
        Format::Glb | Format::Gltf => {
            warnings.push(Note::new(
                Code::MeshVerticesOnly,
                "the reconstruction is a mesh; only its vertices are evaluated",
            ));
            PointCloud {
                points: gltf::read_gltf_with_limits(bytes, &BTreeMap::new(), limits)?
                    .mesh
                    .vertices
                    .into(),
                colors: None,
            }
        }
    };
    loaded(name, cloud, format, warnings)
}

/// The reconstructed point cloud of a PLY file `name` already read ([`ply::read_ply`], or
/// in pieces by [`ply_stream::PlyCloudStream`]), as [`read_point_cloud`] gives it.
pub fn point_cloud_from_ply(name: &str, p: ply::PlyData) -> Result<LoadedCloud> {
    let mut warnings = Vec::new();
    if !p.triangles.is_empty() {
        warnings.push(
            Note::new(
                Code::MeshVerticesOnly,
                format!(
                    "the reconstruction PLY has {} triangles; only its vertices are evaluated",
                    p.triangles.len()
                ),
            )
            .with("triangles", p.triangles.len()),
        );
    }
    let cloud = PointCloud {
        points: p.vertices,
        colors: p.colors,
    };
    loaded(name, cloud, Format::Ply, warnings)
}

fn loaded(name: &str, cloud: PointCloud, format: Format, notes: Vec<Note>) -> Result<LoadedCloud> {
    if cloud.points.is_empty() {
        return Err(Error::Empty {
            what: format!("reconstruction '{name}' (no points)"),
        });
    }
    Ok(LoadedCloud {
        cloud,
        format,
        notes,
    })
}
