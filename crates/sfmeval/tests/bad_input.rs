//! Every kind of bad input gives its typed error (checked by kind), never a panic.

use std::collections::BTreeMap;

use sfmeval::align::Alignment;
use sfmeval::evaluate::{EvalOptions, InputInfo, evaluate};
use sfmeval::geometry::{GroundTruth, PointCloud, TriangleMesh};
use sfmeval::io;
use sfmeval::prepared::PreparedGroundTruth;
use sfmeval::progress::NoProgress;

fn ply_cloud(n_declared: u64, body: &[u8]) -> Vec<u8> {
    let mut b = format!("ply\nformat binary_little_endian 1.0\nelement vertex {n_declared}\nproperty float x\nproperty float y\nproperty float z\nend_header\n").into_bytes();
    b.extend_from_slice(body);
    b
}

fn floats(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|f| f.to_le_bytes()).collect()
}

fn kind_of(r: Result<io::LoadedCloud, sfmeval::Error>) -> &'static str {
    r.err().map_or("ok", |e| e.kind())
}

#[test]
fn point_cloud_errors_by_kind() {
    let good = floats(&[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    assert_eq!(
        kind_of(io::read_point_cloud("a.ply", &ply_cloud(2, &good))),
        "ok"
    );
    // truncated body / wrong count
    assert_eq!(
        kind_of(io::read_point_cloud("a.ply", &ply_cloud(3, &good))),
        "count_mismatch"
    );
    // truncated header
    assert_eq!(
        kind_of(io::read_point_cloud(
            "a.ply",
            b"ply\nformat ascii 1.0\nelement vertex 2\n"
        )),
        "truncated"
    );
    // garbage with a PLY name / unknown name
    assert_eq!(
        kind_of(io::read_point_cloud("a.ply", b"\x00\x01garbage")),
        "malformed"
    );
    assert_eq!(
        kind_of(io::read_point_cloud("a.xyz", b"\x00\x01garbage")),
        "unknown_format"
    );
    // NaN and infinity
    assert_eq!(
        kind_of(io::read_point_cloud(
            "a.ply",
            &ply_cloud(2, &floats(&[0.0, f32::NAN, 0.0, 1.0, 1.0, 1.0]))
        )),
        "non_finite"
    );
    assert_eq!(
        kind_of(io::read_point_cloud(
            "a.ply",
            &ply_cloud(1, &floats(&[f32::INFINITY, 0.0, 0.0]))
        )),
        "non_finite"
    );
    // empty cloud
    assert_eq!(
        kind_of(io::read_point_cloud("a.ply", &ply_cloud(0, &[]))),
        "empty"
    );
    // huge declared count: refused before allocating
    assert_eq!(
        kind_of(io::read_point_cloud("a.ply", &ply_cloud(u64::MAX, &good))),
        "count_mismatch"
    );
    assert_eq!(
        kind_of(io::read_point_cloud("a.ply", &ply_cloud(1 << 40, &good))),
        "count_mismatch"
    );
}

#[test]
fn ground_truth_errors_by_kind() {
    let none = BTreeMap::new();
    let kind = |name: &str, b: &[u8]| {
        io::read_ground_truth(name, b, &none)
            .err()
            .map_or("ok", |e| e.kind())
    };
    // Draco-compressed GLB
    let json = br#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"],"meshes":[]}  "#;
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(((20 + json.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(0x4E4F_534Au32.to_le_bytes());
    glb.extend_from_slice(json);
    assert_eq!(kind("gt.glb", &glb), "unsupported");
    assert_eq!(kind("gt.glb", &glb[..30]), "truncated");
    assert_eq!(kind("gt.gltf", b"{\"asset\": 3}"), "malformed");
    assert_eq!(kind("gt.obj", b"v 0 0 0\nv 1 0 0\nf 1 2 7\n"), "malformed");
    assert_eq!(
        kind("gt.obj", b"v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n"),
        "non_finite"
    );
}

#[test]
fn degenerate_ground_truth_and_empty_reconstruction() {
    // All triangles degenerate: no surface to sample.
    let flat = GroundTruth::Mesh(TriangleMesh {
        vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        triangles: vec![[0, 1, 2]],
    });
    let e = PreparedGroundTruth::new(&flat, 10, 0, &NoProgress)
        .err()
        .map(|e| e.kind());
    assert_eq!(e, Some("geometry"));
    // A single point as ground truth has zero extent.
    let dot = GroundTruth::Cloud(PointCloud {
        points: vec![[1.0, 2.0, 3.0]].into(),
        colors: None,
    });
    assert_eq!(
        PreparedGroundTruth::new(&dot, 10, 0, &NoProgress)
            .err()
            .map(|e| e.kind()),
        Some("geometry")
    );
    // An empty reconstruction.
    let tri = GroundTruth::Mesh(TriangleMesh {
        vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2]],
    });
    let gt = PreparedGroundTruth::new(&tri, 10, 0, &NoProgress).unwrap();
    let options = EvalOptions {
        samples: 10,
        ..EvalOptions::default()
    };
    let r = evaluate(
        &gt,
        PointCloud::default().points,
        &Alignment::none(),
        &options,
        &InputInfo::default(),
        &NoProgress,
    );
    assert_eq!(r.err().map(|e| e.kind()), Some("empty"));
    // Bad options.
    let bad = EvalOptions {
        samples: 10,
        tau: vec![-1.0],
        ..EvalOptions::default()
    };
    let cloud = PointCloud {
        points: vec![[0.1, 0.1, 0.0]].into(),
        colors: None,
    };
    let r = evaluate(
        &gt,
        cloud.points.clone(),
        &Alignment::none(),
        &bad,
        &InputInfo::default(),
        &NoProgress,
    );
    assert_eq!(r.err().map(|e| e.kind()), Some("invalid_option"));
}
