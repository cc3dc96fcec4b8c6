//! The DTU MVS evaluation (Aanæs et al., "Large-Scale Data for Multiple-View Stereopsis",
//! IJCV 2016) as its widely used Python port (jzhangbs/DTUeval-python, `eval.py`) runs it, on
//! the sfmeval core: the benchmark's files ([`scan`]: the STL points, the observation mask, the
//! ground plane, read from the `.mat` files by [`mat`]), the reconstruction sampled when it is a
//! mesh, the down-sampling, the bounding box and observation-mask filtering, accuracy and
//! completeness capped at 20 mm, and the coloured error clouds.

pub mod files;
pub mod mat;
mod protocol;
mod radius_filter;
mod report;
pub mod scan;
pub mod vis;

pub use files::{DtuFiles, read_reconstruction, recognise};
pub use protocol::{
    DOWNSAMPLE_DENSITY, DtuEvaluation, DtuInput, DtuOptions, MAX_DIST, PATCH_SIZE, Shuffle,
    VISUALIZE_THRESHOLD, evaluate, pairwise_sum, sample_mesh, shuffle,
};
pub use radius_filter::radius_filter;
pub use report::{DTU_SCHEMA, DtuCounts, DtuReport, DtuReportOptions};
pub use scan::{DtuScan, NamedBytes, ObsMask};

/// How a reconstruction with faces is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DtuMode {
    /// A mesh when the reconstruction has faces, points otherwise.
    Auto,
    /// A mesh, sampled as the evaluator samples it (its vertices and a grid in each triangle).
    Mesh,
    /// The vertices or points only (faces ignored).
    Pcd,
}

impl DtuMode {
    /// The mode's name as the CLI and the Python package spell it.
    pub fn name(self) -> &'static str {
        match self {
            DtuMode::Auto => "auto",
            DtuMode::Mesh => "mesh",
            DtuMode::Pcd => "pcd",
        }
    }
}

impl DtuMode {
    /// The evaluator's input from a reconstruction's `vertices` and `triangles` (empty for
    /// points): a mesh or points as the mode says, and whether it is a mesh. `what` names the
    /// reconstruction in the error of `mesh` mode on one without faces.
    pub fn input(
        self,
        vertices: Vec<sfmeval::geometry::Point3>,
        triangles: Vec<[u32; 3]>,
        what: &str,
    ) -> sfmeval::Result<(DtuInput, bool)> {
        let mesh = match self {
            DtuMode::Auto => !triangles.is_empty(),
            DtuMode::Mesh if triangles.is_empty() => {
                return Err(sfmeval::Error::InvalidContent(format!(
                    "mode mesh, but {what} has no faces"
                )));
            }
            DtuMode::Mesh => true,
            DtuMode::Pcd => false,
        };
        let input = if mesh {
            DtuInput::Mesh {
                vertices,
                triangles,
            }
        } else {
            DtuInput::Cloud(vertices)
        };
        Ok((input, mesh))
    }
}

impl std::str::FromStr for DtuMode {
    type Err = sfmeval::Error;

    fn from_str(s: &str) -> sfmeval::Result<DtuMode> {
        match s {
            "auto" => Ok(DtuMode::Auto),
            "mesh" => Ok(DtuMode::Mesh),
            "pcd" => Ok(DtuMode::Pcd),
            _ => Err(sfmeval::Error::InvalidOption(format!(
                "mode '{s}': expected auto, mesh or pcd"
            ))),
        }
    }
}
