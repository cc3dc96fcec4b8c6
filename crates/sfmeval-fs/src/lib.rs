//! # sfmeval-fs
//!
//! The filesystem layer of the native front ends (the `sfmeval` CLI and `sfmeval-runner`): the
//! core reads named bytes through [`sfmeval::files::FileSource`]; [`Disk`] is that source over
//! the real filesystem, and [`write_atomic`] is the one way outputs reach the disk. [`run_dtu`] is `sfmeval dtu` on files: the scan's files and any reconstruction
//! `sfmeval eval` reads, and [`run_eth3d`] is `sfmeval eth3d` on files (the scene's MeshLab project
//! and its scans, a reconstruction PLY), for the CLI, the Python package and the runner alike;
//! [`cameras_on_files`] and [`poses_on_files`] are `sfmeval cameras` and `sfmeval poses` on files.

mod cameras;
mod disk;
mod dtu;
mod eth3d;
mod report_args;
mod stream;
mod write;

pub use cameras::{CamerasOutputs, cameras_on_files, poses_on_files, read_camera_models};
pub use disk::{
    Disk, IMAGE_EXTENSIONS, image_names, name_of, path_str, read, read_dataset, read_input_files,
    read_point_pairs, read_transform,
};
pub use dtu::{DtuOutputs, DtuRecon, DtuRun, read_dtu_recon, read_dtu_scan, run_dtu};
pub use eth3d::{Eth3dOutputs, Eth3dRun, eth3d_on_scene, read_eth3d_scene, run_eth3d};
pub use report_args::{named, pipeline_and_path};
pub use stream::{read_reconstruction, read_reconstruction_with_cameras};
pub use write::write_atomic;
