//! The DTU MVS evaluation (Aanæs et al., "Large-Scale Data for Multiple-View Stereopsis",
//! IJCV 2016) as its widely used Python port (jzhangbs/DTUeval-python, `eval.py`) runs it, on
//! the sfmeval core: the benchmark's files ([`scan`]: the STL points, the observation mask, the
//! ground plane, read from the `.mat` files by [`mat`]), the reconstruction sampled when it is a
//! mesh, the down-sampling, the bounding box and observation-mask filtering, accuracy and
//! completeness capped at 20 mm, and the coloured error clouds.

pub mod files;
pub mod mat;
mod protocol;
mod report;
pub mod scan;
pub mod vis;

pub use files::{DtuFiles, ReconMode, read_reconstruction, recognise};
pub use protocol::{
    DOWNSAMPLE_DENSITY, DtuEvaluation, DtuInput, DtuOptions, MAX_DIST, PATCH_SIZE, Shuffle,
    VISUALIZE_THRESHOLD, evaluate, pairwise_sum, radius_filter, sample_mesh, shuffle,
};
pub use report::{DTU_SCHEMA, DtuCounts, DtuReport, DtuReportOptions};
pub use scan::{DtuScan, NamedBytes, ObsMask};
