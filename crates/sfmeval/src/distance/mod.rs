//! Distances from query points to the ground truth (mesh or cloud) and to clouds.

mod bvh;
mod cloud;
mod mesh;
pub(crate) mod slot_tree;

pub use cloud::CloudIndex;
pub use mesh::{MeshHit, MeshIndex};
