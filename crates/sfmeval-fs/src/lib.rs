//! # sfmeval-fs
//!
//! The filesystem layer of the native front ends (the `sfmeval` CLI and `sfmeval-runner`): the
//! core reads named bytes through [`sfmeval::files::FileSource`]; [`Disk`] is that source over
//! the real filesystem, and [`write_atomic`] is the one way outputs reach the disk.

mod disk;
mod report_args;
mod stream;
mod write;

pub use disk::{
    Disk, IMAGE_EXTENSIONS, image_names, name_of, path_str, read, read_dataset, read_input_files,
    read_point_pairs, read_transform,
};
pub use report_args::{named, pipeline_and_path};
pub use stream::{read_reconstruction, read_reconstruction_with_cameras};
pub use write::write_atomic;
