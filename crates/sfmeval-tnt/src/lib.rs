//! The Tanks and Temples evaluation protocol, as the benchmark's own toolbox
//! (`python_toolbox/evaluation` of the TanksAndTemples repository) runs it, so that its
//! precision, recall and F-score compare with the benchmark's leaderboard: the scene's files
//! ([`scene`]), the `.log` trajectories ([`trajectory`]), the trajectory alignment, the three
//! ICP refinements, crop, voxel down-sampling, distances both ways, the scores and curves
//! ([`curves`]), the coloured clouds and the precision/recall plot ([`pr_svg`]), the summary
//! ([`TntReport::summary`]), and the scene's files recognised among dropped ones ([`files`], for
//! the page and the npm package).
//!
//! Where sfmeval can differ from the toolbox at all: the trajectory alignment is a RANSAC over
//! random samples (seeded here, unseeded in the toolbox), so the final transform can differ
//! slightly, and the toolbox's ICP stop rule (see [`IcpCriteria::TOOLBOX`]) passes such a
//! difference on; with the final transform fixed every step is deterministic and gives the
//! toolbox's numbers.

mod colors;
pub mod curves;
pub mod files;
mod icp;
pub mod matrix;
mod plot;
mod protocol;
mod report;
pub mod scene;
pub mod trajectory;
mod trajectory_alignment;
mod voxel;

pub use colors::hot_r;
pub use files::{TntFiles, recognise};
pub use icp::IcpCriteria;
#[cfg(feature = "png")]
pub use plot::svg_to_png;
pub use plot::{PLOT_SIZE, plot_stem, pr_svg};
pub use protocol::{
    PLOT_STRETCH, Registration, TntEvaluation, TntRequest, UNIFORM_MAX_POINTS, evaluate,
};
pub use report::*;
pub use scene::{SCENE_TAU, Scene, scene_tau};
pub use trajectory::{
    LogFrame, MAPPING_ABOVE_FRAMES, Mapping, log_from_model, read_log, read_mapping, write_log,
};
pub use trajectory_alignment::{TrajectoryAlignment, TrajectoryAlignmentOptions};
pub use voxel::voxel_down_sample;
