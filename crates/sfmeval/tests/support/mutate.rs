//! Shared by the reader fuzz tests of the core and of `sfmeval-tnt` (included with `#[path]`):
//! the fixtures and the random mutations.

use std::path::PathBuf;

use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

/// A file of `tests/fixtures` (its folder chosen by the name).
pub fn fixture(name: &str) -> Vec<u8> {
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
pub fn mutate(rng: &mut ChaCha8Rng, src: &[u8]) -> Vec<u8> {
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
pub fn run(name: &str, iterations: usize, read: impl Fn(&[u8])) {
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
