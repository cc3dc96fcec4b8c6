//! ETH3D's multi-view evaluation (Schöps et al., "A Multi-View Stereo Benchmark with
//! High-Resolution Images and Multi-Camera Videos", CVPR 2017) as its official C++ tool
//! (ETH3D/multi-view-evaluation) computes it, on the sfmeval core: the ground truth as a MeshLab
//! project of laser scans with their poses ([`mlp`], [`scene`]), the accuracy of each
//! reconstruction point against the scans' beams (accurate, inaccurate or unobserved,
//! [`accuracy`]), the completeness of each scan point ([`completeness`]), both averaged over two
//! shifted voxel grids ([`voxel`]) for every tolerance in one pass, F1 per tolerance
//! ([`evaluate`]), the coloured clouds the tool writes ([`vis`]), `sfmeval.eth3d/1` and its
//! summary ([`report`]), and the scene's files recognised among dropped ones ([`files`], for
//! the page and the npm package).
//!
//! Every step is the tool's, in its single-precision arithmetic and in its order of
//! operations, so that the numbers are the tool's to the last float.

pub mod accuracy;
pub mod completeness;
pub mod files;
pub mod mlp;
mod protocol;
pub mod report;
pub mod scene;
pub mod vis;
pub mod voxel;

pub use files::{Eth3dFiles, Eth3dScanFile, recognise};
pub use protocol::{
    BEAM_DIVERGENCE_HALFANGLE_DEG, BEAM_START_RADIUS, DEFAULT_TOLERANCES, Eth3dEvaluation,
    Eth3dOptions, VOXEL_SIZE, evaluate,
};
pub use report::{ETH3D_SCHEMA, Eth3dReport};
pub use scene::{Eth3dScene, NamedBytes, Scan};
