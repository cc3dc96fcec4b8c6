//! Distances from query points to the ground truth (mesh or cloud) and to clouds.

pub mod bvh;
pub mod cloud;
pub mod mesh;

pub use cloud::CloudIndex;
pub use mesh::{MeshHit, MeshIndex};
