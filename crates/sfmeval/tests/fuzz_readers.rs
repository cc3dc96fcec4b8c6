//! Throws ≥ 10 000 random mutations of real files at every reader: any panic fails the test;
//! every outcome must be `Ok` or a typed error.

use std::collections::BTreeMap;

use sfmeval::io;

#[path = "support/mutate.rs"]
mod support;
use support::run;

#[test]
fn ply_reader_survives_mutations() {
    for name in [
        "open3d_cloud_ascii.ply",
        "open3d_cloud_binary.ply",
        "meshlab_mesh_binary.ply",
        "colmap_points.ply",
        "trimesh_mesh_binary.ply",
    ] {
        run(name, 4000, |b| {
            let _ = io::ply::read_ply(b);
            let _ = io::read_point_cloud(name, b);
        });
    }
}

#[test]
fn gltf_reader_survives_mutations() {
    for name in ["trimesh_mesh.glb", "blender_monkey.glb"] {
        run(name, 6000, |b| {
            let _ = io::gltf::read_gltf(b, &BTreeMap::new());
        });
    }
}

#[test]
fn npy_reader_survives_mutations() {
    for name in [
        "depth_f4_v1.npy",
        "depth_f8_v2.npy",
        "depth_f4_v3.npy",
        "small_f8_be.npy",
    ] {
        run(name, 3000, |b| {
            if let Ok(a) = io::npy::read_npy(b) {
                assert_eq!(a.values.len(), a.rows * a.cols);
            }
            let _ = io::npy::DepthMap::from_npy(b);
        });
    }
}

#[test]
fn obj_reader_survives_mutations() {
    run("trimesh_mesh.obj", 10_000, |b| {
        let _ = io::obj::read_obj(b);
    });
}

#[test]
fn ground_truth_dispatch_survives_mutations() {
    for name in ["open3d_mesh_binary.ply", "trimesh_mesh.glb"] {
        run(name, 3000, |b| {
            if let Ok(gt) = io::read_ground_truth(name, b, &BTreeMap::new()) {
                // Whatever is accepted must be usable.
                let _ = sfmeval::prepared::PreparedGroundTruth::new(
                    &gt.ground_truth,
                    100,
                    0,
                    &sfmeval::progress::NoProgress,
                );
            }
        });
    }
}
