//! Random byte mutations of real files thrown at every reader: each must return `Ok` or a typed
//! error, never panic, never allocate absurdly. Deterministic (fixed seed).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;

use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

use super::*;

/// Bytes of a file under `tests/fixtures/models/`.
pub(crate) fn fixture(name: &str) -> Vec<u8> {
    let path = format!(
        "{}/../../tests/fixtures/models/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read(&path).unwrap_or_else(|e| panic!("fixture {path}: {e}"))
}

const INTERESTING: &[&[u8]] = &[
    b"0",
    b"-1",
    b"nan",
    b"inf",
    b"1e308",
    b"18446744073709551615",
    b"4294967295",
    b"\n",
    b" ",
    b"\xff\xff\xff\xff\xff\xff\xff\x7f",
    b"\x00",
    b"{",
    b"}",
    b"[",
    b"]",
    b"\"",
    b",",
    b"null",
    b"-0",
];

/// One random mutation: flip bytes, overwrite with an interesting token, insert, delete a span,
/// truncate, or duplicate a span.
fn mutate(rng: &mut ChaCha8Rng, src: &[u8]) -> Vec<u8> {
    let mut b = src.to_vec();
    let rounds = 1 + rng.random_range(0..4);
    for _ in 0..rounds {
        let len = b.len();
        let pos = rng.random_range(0..len + 1);
        match rng.random_range(0..7) {
            0 => {
                if let Some(x) = b.get_mut(pos) {
                    *x ^= 1 << rng.random_range(0..8);
                }
            }
            1 => {
                if let Some(x) = b.get_mut(pos) {
                    *x = rng.random::<u8>();
                }
            }
            2 => {
                let tok = INTERESTING[rng.random_range(0..INTERESTING.len())];
                let end = (pos + tok.len()).min(len);
                b.splice(pos..end, tok.iter().copied());
            }
            3 => {
                let tok = INTERESTING[rng.random_range(0..INTERESTING.len())];
                b.splice(pos..pos, tok.iter().copied());
            }
            4 => {
                let end = (pos + rng.random_range(0..64)).min(len);
                b.drain(pos..end);
            }
            5 => b.truncate(pos),
            _ => {
                let end = (pos + rng.random_range(0..64)).min(len);
                let chunk: Vec<u8> = b.get(pos..end).unwrap_or_default().to_vec();
                b.splice(pos..pos, chunk);
            }
        }
    }
    b
}

/// Mutations per reader input.
const N: usize = 10_000;

fn hammer(label: &str, sources: &[Vec<u8>], seed: u64, mut read: impl FnMut(usize, &[u8])) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for i in 0..N {
        let which = rng.random_range(0..sources.len());
        let m = mutate(&mut rng, &sources[which]);
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| read(which, &m)));
        assert!(
            result.is_ok(),
            "{label}: mutation {i} of source {which} panicked"
        );
    }
}

#[test]
fn colmap_text_never_panics() {
    let files = ["cameras.txt", "images.txt", "points3D.txt"];
    let src: Vec<Vec<u8>> = files
        .iter()
        .map(|f| fixture(&format!("colmap_text/{f}")))
        .collect();
    let theia: Vec<Vec<u8>> = files
        .iter()
        .map(|f| fixture(&format!("theia_colmap/{f}")))
        .collect();
    let all: Vec<Vec<u8>> = src.iter().chain(&theia).cloned().collect();
    hammer("COLMAP text", &all, 1, |which, m| {
        let base = if which < 3 { &src } else { &theia };
        let mut f = base.clone();
        f[which % 3] = m.to_vec();
        let _ = colmap::read_colmap_text(&f[0], &f[1], Some(&f[2]));
    });
}

#[test]
fn colmap_binary_never_panics() {
    let files = ["cameras.bin", "images.bin", "points3D.bin"];
    let src: Vec<Vec<u8>> = files
        .iter()
        .map(|f| fixture(&format!("colmap_bin/{f}")))
        .collect();
    hammer("COLMAP binary", &src, 2, |which, m| {
        let mut f = src.clone();
        f[which] = m.to_vec();
        let _ = colmap::read_colmap_binary(&f[0], &f[1], Some(&f[2]));
    });
}

#[test]
fn colmap_folder_never_panics() {
    let mut files = BTreeMap::new();
    for f in ["cameras.bin", "images.bin", "points3D.bin"] {
        files.insert(format!("sparse/0/{f}"), fixture(&format!("colmap_bin/{f}")));
    }
    for f in ["cameras.txt", "images.txt", "points3D.txt"] {
        files.insert(
            format!("sparse/1/{f}"),
            fixture(&format!("openmvg_colmap/{f}")),
        );
    }
    let keys: Vec<String> = files.keys().cloned().collect();
    let src: Vec<Vec<u8>> = files.values().cloned().collect();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for _ in 0..N / 10 {
        let which = rng.random_range(0..src.len());
        let mut f = files.clone();
        f.insert(keys[which].clone(), mutate(&mut rng, &src[which]));
        let _ = colmap::read_colmap_folder(&f);
    }
}

#[test]
fn nvm_never_panics() {
    let src = vec![fixture("colmap38.nvm"), fixture("theia.nvm")];
    hammer("NVM", &src, 4, |_, m| {
        let _ = nvm::read_nvm(m);
    });
}

#[test]
fn bundler_never_panics() {
    let out = fixture("colmap38.bundle.out");
    let list = fixture("colmap38.list.txt");
    let src = vec![out.clone(), list.clone()];
    hammer("Bundler", &src, 5, |which, m| {
        let _ = if which == 0 {
            bundler::read_bundler(m, Some(&list))
        } else {
            bundler::read_bundler(&out, Some(m))
        };
    });
}

#[test]
fn openmvg_never_panics() {
    let src = vec![fixture("openmvg_sfm_data.json")];
    hammer("OpenMVG", &src, 6, |_, m| {
        let _ = openmvg::read_openmvg_json(m);
    });
}

#[test]
fn cameras_json_never_panics() {
    let src = vec![fixture("gt_cameras.json")];
    hammer("cameras.json", &src, 7, |_, m| {
        let _ = cameras_json::read_cameras_json(m);
    });
}

#[test]
fn strip_and_pose_metrics_never_panic_on_mutated_models() {
    // Whatever a mutated model reads as, the downstream code must cope.
    let gt = cameras_json::read_cameras_json(&fixture("gt_cameras.json")).unwrap();
    let src = [fixture("colmap38.nvm")];
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let mut evaluated = 0;
    for _ in 0..N / 5 {
        let m = mutate(&mut rng, &src[0]);
        if let Ok(est) = nvm::read_nvm(&m) {
            let cloud = est.to_point_cloud();
            let _ = strip::strip_camera_points(cloud.clone(), Some(&est.camera_centers()), "x");
            let _ = crate::pose::evaluate_cameras(
                &gt,
                &est,
                &crate::transform::Similarity::IDENTITY,
                &crate::pose::PoseOptions::default(),
            );
            evaluated += 1;
        }
    }
    assert!(evaluated > 10);
}
