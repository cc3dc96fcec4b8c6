//! Files written by other programs (Open3D, trimesh, MeshLab, COLMAP, Blender) read back with
//! the counts and bounds their writers recorded in `tests/fixtures/core/manifest.json`.

use std::collections::BTreeMap;
use std::path::PathBuf;

use sfmeval::geometry::{Aabb, GroundTruth};
use sfmeval::io;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/fixtures/core")
}

#[test]
fn every_fixture_matches_its_writers_manifest() {
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(fixtures().join("manifest.json")).unwrap()).unwrap();
    let entries = manifest.as_object().unwrap();
    assert!(entries.len() >= 9);
    for (name, want) in entries {
        let bytes = std::fs::read(fixtures().join(name)).unwrap();
        let gt = io::read_ground_truth(name, &bytes, &BTreeMap::new())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let (points, triangles) = match &gt.ground_truth {
            GroundTruth::Mesh(m) => (m.vertices.len(), m.triangles.len()),
            GroundTruth::Cloud(c) => (c.points.len(), 0),
        };
        if let Some(v) = want["vertices"].as_u64() {
            assert_eq!(points as u64, v, "{name}: vertices");
        }
        assert_eq!(
            triangles as u64,
            want["triangles"].as_u64().unwrap(),
            "{name}: triangles"
        );
        let b = Aabb::of(&gt.ground_truth.points()).unwrap();
        for k in 0..3 {
            let (lo, hi) = (
                want["min"][k].as_f64().unwrap(),
                want["max"][k].as_f64().unwrap(),
            );
            // Writers differ in precision (Open3D ascii keeps 6 decimals, float32 binaries).
            assert!(
                (b.min[k] - lo).abs() < 1e-5 && (b.max[k] - hi).abs() < 1e-5,
                "{name}: bounds {:?} vs {lo} {hi}",
                b
            );
        }
    }
}

#[test]
fn colmap_ply_colours_and_clouds_are_clouds() {
    let bytes = std::fs::read(fixtures().join("colmap_points.ply")).unwrap();
    let cloud = io::read_point_cloud("colmap_points.ply", &bytes).unwrap();
    assert_eq!(cloud.cloud.points.len(), 200);
    assert!(
        cloud
            .cloud
            .colors
            .unwrap()
            .iter()
            .all(|c| *c == [200, 100, 50])
    );
}

/// Every PLY another program wrote: streamed in pieces, the same as read whole (clouds), or
/// left to the whole-file reader (meshes, ascii). Open3D's and COLMAP's binary clouds stream.
#[test]
fn streamed_ply_equals_the_whole_file_read() {
    use sfmeval::io::ply_stream::{HEAD_BYTES, PlyCloudStream};
    let mut streamed = Vec::new();
    for entry in std::fs::read_dir(fixtures()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("ply") {
            continue;
        }
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let bytes = std::fs::read(&path).unwrap();
        let head = &bytes[..bytes.len().min(HEAD_BYTES)];
        let Some(mut s) = PlyCloudStream::new(head, bytes.len() as u64).unwrap() else {
            continue;
        };
        for piece in bytes[s.body_start()..].chunks(1000) {
            s.push(piece);
        }
        let got = s.finish().unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(got, io::ply::read_ply(&bytes).unwrap(), "{name}");
        streamed.push(name);
    }
    streamed.sort();
    assert_eq!(streamed, ["colmap_points.ply", "open3d_cloud_binary.ply"]);
}
