//! Throws ≥ 10 000 random mutations of real files at every reader: any panic fails the test;
//! every outcome must be `Ok` or a typed error.

use std::collections::BTreeMap;
use std::path::PathBuf;

use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use sfmeval::io;

fn fixture(name: &str) -> Vec<u8> {
    let folder = if name.ends_with(".npy") {
        "npy"
    } else if name.starts_with("Synth") {
        "tanksandtemples"
    } else {
        "core"
    };
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/fixtures")
        .join(folder)
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// One random mutation: flip bits, overwrite bytes, truncate, duplicate or delete a span, or
/// rewrite a decimal number (header counts, coordinates, JSON lengths) with an extreme value.
fn mutate(rng: &mut ChaCha8Rng, src: &[u8]) -> Vec<u8> {
    let mut b = src.to_vec();
    let rounds = rng.random_range(1..4);
    for _ in 0..rounds {
        if b.is_empty() {
            break;
        }
        let i = rng.random_range(0..b.len());
        match rng.random_range(0..7) {
            0 => b[i] ^= 1 << rng.random_range(0..8),
            1 => b[i] = rng.random(),
            2 => b.truncate(i),
            3 => {
                let j = (i + rng.random_range(1..64)).min(b.len());
                let span = b[i..j].to_vec();
                b.splice(i..i, span);
            }
            4 => {
                let j = (i + rng.random_range(1..64)).min(b.len());
                b.drain(i..j);
            }
            _ => {
                // Replace the next run of digits with an extreme number.
                if let Some(start) = b[i..].iter().position(u8::is_ascii_digit).map(|p| p + i) {
                    let end = b[start..]
                        .iter()
                        .position(|c| !c.is_ascii_digit())
                        .map_or(b.len(), |p| p + start);
                    let repl: &[u8] = match rng.random_range(0..5) {
                        0 => b"0",
                        1 => b"4294967295",
                        2 => b"18446744073709551615",
                        3 => b"99999999999999999999999",
                        _ => b"nan",
                    };
                    b.splice(start..end, repl.iter().copied());
                }
            }
        }
    }
    b
}

/// `SFMEVAL_FUZZ_SCALE=20` multiplies the iterations for a longer local run.
fn run(name: &str, iterations: usize, read: impl Fn(&[u8])) {
    let scale: usize = std::env::var("SFMEVAL_FUZZ_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let iterations = iterations * scale;
    let src = fixture(name);
    let seed: u64 = std::env::var("SFMEVAL_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x5f3e);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ name.len() as u64);
    for _ in 0..iterations {
        let m = mutate(&mut rng, &src);
        read(&m);
    }
}

#[test]
fn tanksandtemples_readers_survive_mutations() {
    use sfmeval::tanksandtemples::{matrix, read_log, read_mapping};
    run("Synth_COLMAP_SfM.log", 3000, |b| {
        let _ = read_log(b);
    });
    run("Synth_mapping_reference.txt", 2000, |b| {
        let _ = read_mapping(b);
    });
    run("Synth_trans.txt", 2000, |b| {
        let _ = matrix::parse(b, "trans");
    });
    run("Synth.json", 3000, |b| {
        // A crop that parses can be applied.
        if let Ok(Some(v)) = sfmeval::crop::Crop::parse(b).map(|c| c.volume) {
            let _ = v.contains([0.1, 0.2, 0.3]);
        }
    });
    // The unmutated files read.
    assert_eq!(
        read_log(&fixture("Synth_COLMAP_SfM.log")).unwrap().len(),
        36
    );
    assert_eq!(
        read_mapping(&fixture("Synth_mapping_reference.txt"))
            .unwrap()
            .video_frames[35],
        351
    );
    assert!(matrix::parse(&fixture("Synth_trans.txt"), "trans").is_ok());
    assert!(
        sfmeval::crop::Crop::parse(&fixture("Synth.json"))
            .unwrap()
            .volume
            .is_some()
    );
}

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
