//! Distances from query points to the ground truth (mesh or cloud) and to clouds.

mod bvh;
mod cloud;
mod kd_cloud;
mod leaf_bound;
mod median_split;
mod mesh;
mod neighbour_list;
mod oriented;
pub(crate) mod slot_tree;
mod split_key;

pub use cloud::CloudIndex;
pub use kd_cloud::{KdCloud, NO_POINT, distance2};
pub use mesh::{MeshHint, MeshHit, MeshIndex};
pub use neighbour_list::NeighbourList;

/// `f32` not above `v` (rounds towards −∞): the lower corner of a box that must contain `v`
/// (the BVH's and the slot tree's `f32` boxes).
fn down(v: f64) -> f32 {
    let f = v as f32;
    if f64::from(f) > v { f.next_down() } else { f }
}

/// `f32` not below `v` (rounds towards +∞): the upper corner of such a box.
fn up(v: f64) -> f32 {
    let f = v as f32;
    if f64::from(f) < v { f.next_up() } else { f }
}
