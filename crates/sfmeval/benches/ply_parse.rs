//! PLY parsing: `sfmeval::io::ply::read_ply` against the `ply-rs` crate on the same bytes.
//!
//! A seeded cloud of 1M points (`float x y z`, `uchar red green blue`: the layout COLMAP and
//! OpenMVG write) is encoded twice in memory, binary little endian and ascii, and each encoding
//! is parsed into `Vec<[f64; 3]>` positions and `Vec<[u8; 3]>` colours by
//!
//! - `sfmeval`: `read_ply(&bytes)`;
//! - `ply-rs typed`: ply-rs's fast path, a `PropertyAccess` struct per vertex
//!   (`Parser::<Vertex>::read_header` + `read_payload_for_element`);
//! - `ply-rs DefaultElement`: ply-rs's generic `read_ply`, a hash map per vertex.
//!
//! Before timing, every parser's output is checked against the points that were written: both
//! encodings must give the same positions and colours from all three parsers (the ascii file
//! declares `double` coordinates, written as the shortest decimals of the `float` values, so
//! every parser reads the same f64 from them). No file I/O is timed.
//!
//! `cargo bench -p sfmeval --bench ply_parse`; `SFMEVAL_PLY_BENCH_POINTS=N` changes the size.

// Synthetic inputs: a failed setup must stop the bench loudly.
#![allow(clippy::expect_used)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use ply_rs::parser::Parser;
use ply_rs::ply::{DefaultElement, Property, PropertyAccess};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;

/// Positions and colours, as every parser here returns them.
type Cloud = (Vec<[f64; 3]>, Vec<[u8; 3]>);

/// A seeded cloud of `n` points in a 20-unit cube, f32 positions, random colours.
fn cloud(n: usize) -> (Vec<[f32; 3]>, Vec<[u8; 3]>) {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    (0..n)
        .map(|_| {
            let p = [0; 3].map(|_| rng.random::<f32>() * 20.0 - 10.0);
            let c = [0; 3].map(|_| rng.random::<u8>());
            (p, c)
        })
        .unzip()
}

/// The cloud as a PLY file: binary little endian with `float` positions, or ascii with `double`
/// positions printed as the shortest decimals that read back as the `float` values.
fn ply_bytes(points: &[[f32; 3]], colors: &[[u8; 3]], ascii: bool) -> Vec<u8> {
    let (fmt, ty) = if ascii {
        ("ascii", "double")
    } else {
        ("binary_little_endian", "float")
    };
    let mut b = format!(
        "ply\nformat {fmt} 1.0\ncomment sfmeval ply_parse bench\nelement vertex {}\n\
         property {ty} x\nproperty {ty} y\nproperty {ty} z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
        points.len()
    )
    .into_bytes();
    for (p, c) in points.iter().zip(colors) {
        if ascii {
            b.extend(format!("{} {} {} {} {} {}\n", p[0], p[1], p[2], c[0], c[1], c[2]).bytes());
        } else {
            for v in p {
                b.extend(v.to_le_bytes());
            }
            b.extend(c);
        }
    }
    b
}

/// What each encoding must read back as: the f32 values (binary), or the f64 nearest to their
/// shortest decimals (ascii).
fn expected(points: &[[f32; 3]], colors: &[[u8; 3]], ascii: bool) -> Cloud {
    let pts = points
        .iter()
        .map(|p| {
            p.map(|v| {
                if ascii {
                    v.to_string().parse::<f64>().expect("a decimal")
                } else {
                    f64::from(v)
                }
            })
        })
        .collect();
    (pts, colors.to_vec())
}

fn sfmeval_parse(bytes: &[u8]) -> Cloud {
    let ply = sfmeval::io::ply::read_ply(bytes).expect("sfmeval reads the bench PLY");
    (
        ply.vertices.into_f64(),
        ply.colors.expect("the bench PLY has colours"),
    )
}

/// One vertex for ply-rs's typed path.
#[derive(Default)]
struct Vertex {
    p: [f64; 3],
    c: [u8; 3],
}

/// A ply-rs scalar as f64 (the bench files hold only these types).
fn scalar(p: &Property) -> Option<f64> {
    match *p {
        Property::Float(v) => Some(f64::from(v)),
        Property::Double(v) => Some(v),
        Property::UChar(v) => Some(f64::from(v)),
        _ => None,
    }
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex::default()
    }

    fn set_property(&mut self, key: String, property: Property) {
        let slot = match key.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            "red" | "green" | "blue" => {
                if let Property::UChar(v) = property {
                    self.c[match key.as_str() {
                        "red" => 0,
                        "green" => 1,
                        _ => 2,
                    }] = v;
                }
                return;
            }
            _ => return,
        };
        if let Some(v) = scalar(&property) {
            self.p[slot] = v;
        }
    }
}

fn plyrs_typed(bytes: &[u8]) -> Cloud {
    let mut r = bytes;
    let parser = Parser::<Vertex>::new();
    let header = parser.read_header(&mut r).expect("ply-rs reads the header");
    let element = header.elements.get("vertex").expect("a vertex element");
    let vertices = parser
        .read_payload_for_element(&mut r, element, &header)
        .expect("ply-rs reads the vertices");
    vertices.into_iter().map(|v| (v.p, v.c)).unzip()
}

fn plyrs_default(bytes: &[u8]) -> Cloud {
    let mut r = bytes;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut r)
        .expect("ply-rs reads the PLY");
    let get = |e: &DefaultElement, k: &str| e.get(k).and_then(scalar).expect("a scalar");
    ply.payload["vertex"]
        .iter()
        .map(|e| {
            (
                [get(e, "x"), get(e, "y"), get(e, "z")],
                ["red", "green", "blue"].map(|k| get(e, k) as u8),
            )
        })
        .unzip()
}

/// Panics, naming the first difference, unless `got` is exactly `want`.
fn check(parser: &str, encoding: &str, got: &Cloud, want: &Cloud) {
    assert_eq!(
        got.0.len(),
        want.0.len(),
        "{parser}, {encoding}: point count"
    );
    assert_eq!(
        got.1.len(),
        want.1.len(),
        "{parser}, {encoding}: colour count"
    );
    let first = (0..want.0.len()).find(|&i| got.0[i] != want.0[i] || got.1[i] != want.1[i]);
    if let Some(i) = first {
        panic!(
            "{parser}, {encoding}: point {i} is {:?} {:?}, written {:?} {:?}",
            got.0[i], got.1[i], want.0[i], want.1[i]
        );
    }
}

fn bench_ply_parse(c: &mut Criterion) {
    let n = std::env::var("SFMEVAL_PLY_BENCH_POINTS")
        .ok()
        .map(|s| s.parse().expect("SFMEVAL_PLY_BENCH_POINTS is a count"))
        .unwrap_or(1_000_000);
    let (points, colors) = cloud(n);
    for ascii in [false, true] {
        let bytes = ply_bytes(&points, &colors, ascii);
        let want = expected(&points, &colors, ascii);
        let encoding = if ascii { "ascii" } else { "binary LE" };
        // Same points from every parser, or the timings compare different work.
        check("sfmeval", encoding, &sfmeval_parse(&bytes), &want);
        check("ply-rs typed", encoding, &plyrs_typed(&bytes), &want);
        check(
            "ply-rs DefaultElement",
            encoding,
            &plyrs_default(&bytes),
            &want,
        );

        let mut g = c.benchmark_group(format!("PLY parse {encoding}, {n} points xyz+rgb"));
        g.sample_size(10);
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function("sfmeval read_ply", |b| {
            b.iter(|| sfmeval_parse(black_box(&bytes)))
        });
        g.bench_function("ply-rs typed", |b| {
            b.iter(|| plyrs_typed(black_box(&bytes)))
        });
        g.bench_function("ply-rs DefaultElement", |b| {
            b.iter(|| plyrs_default(black_box(&bytes)))
        });
        g.finish();
    }
}

criterion_group!(benches, bench_ply_parse);
criterion_main!(benches);
