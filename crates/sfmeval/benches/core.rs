//! Inner loops of the core: exact closest point on a mesh through the BVH, k-d tree build and
//! nearest neighbour, PLY parsing, area-uniform sampling, Umeyama. `cargo bench -p sfmeval`.

// Synthetic inputs only: platform maths is fine here, and a failed setup stops the bench loudly.
#![allow(clippy::disallowed_methods, clippy::expect_used)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng as _, SeedableRng as _};
use rand_chacha::ChaCha8Rng;
use sfmeval::distance::{CloudIndex, MeshIndex};
use sfmeval::geometry::{Point3, TriangleMesh};

/// A bumpy latitude-longitude sphere with about `2 · n_lat · n_lon` triangles.
fn bumpy_sphere(n_lat: u32, n_lon: u32) -> TriangleMesh {
    let mut vertices = vec![[0.0, 1.0, 0.0]];
    for i in 1..n_lat {
        let th = std::f64::consts::PI * f64::from(i) / f64::from(n_lat);
        for j in 0..n_lon {
            let ph = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(n_lon);
            let d = [th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()];
            let r = 1.0 + 0.15 * (3.0 * d[0] + 0.5).sin() * (2.0 * d[1]).cos();
            vertices.push([d[0] * r, d[1] * r * 0.8, d[2] * r * 0.65]);
        }
    }
    vertices.push([0.0, -1.0, 0.0]);
    let idx = |i: u32, j: u32| 1 + i * n_lon + (j % n_lon);
    let mut triangles = Vec::new();
    for j in 0..n_lon {
        triangles.push([0, idx(0, j + 1), idx(0, j)]);
    }
    for i in 0..n_lat - 2 {
        for j in 0..n_lon {
            triangles.push([idx(i, j), idx(i, j + 1), idx(i + 1, j + 1)]);
            triangles.push([idx(i, j), idx(i + 1, j + 1), idx(i + 1, j)]);
        }
    }
    let last = vertices.len() as u32 - 1;
    for j in 0..n_lon {
        triangles.push([last, idx(n_lat - 2, j), idx(n_lat - 2, j + 1)]);
    }
    TriangleMesh {
        vertices,
        triangles,
    }
}

fn noisy_points(mesh: &TriangleMesh, n: usize, seed: u64) -> Vec<Point3> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    sfmeval::sampling::sample_surface(mesh, n, seed)
        .expect("the bench mesh has area")
        .into_iter()
        .map(|p| p.map(|c| c + (rng.random::<f64>() - 0.5) * 0.02))
        .collect()
}

fn ply_bytes(points: &[Point3], ascii: bool) -> Vec<u8> {
    let fmt = if ascii {
        "ascii"
    } else {
        "binary_little_endian"
    };
    let mut b = format!(
        "ply\nformat {fmt} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
        points.len()
    )
    .into_bytes();
    for p in points {
        if ascii {
            b.extend(format!("{} {} {} 10 20 30\n", p[0] as f32, p[1] as f32, p[2] as f32).bytes());
        } else {
            for c in p {
                b.extend((*c as f32).to_le_bytes());
            }
            b.extend([10u8, 20, 30]);
        }
    }
    b
}

fn bench_mesh(c: &mut Criterion) {
    let mesh = bumpy_sphere(160, 320); // ~100k triangles
    let queries = noisy_points(&mesh, 10_000, 1);
    c.bench_function("bvh build, 100k triangles", |b| {
        b.iter(|| MeshIndex::new(black_box(&mesh)))
    });
    let index = MeshIndex::new(&mesh).expect("the bench mesh is indexable");
    c.bench_function("closest point on mesh, 10k queries, 100k triangles", |b| {
        b.iter(|| {
            queries
                .iter()
                .map(|&q| index.closest(black_box(q)).distance)
                .sum::<f64>()
        })
    });
    c.bench_function("area-uniform sampling, 100k samples", |b| {
        b.iter(|| sfmeval::sampling::sample_surface(black_box(&mesh), 100_000, 0))
    });
}

fn bench_kdtree(c: &mut Criterion) {
    let mesh = bumpy_sphere(100, 200);
    let cloud = noisy_points(&mesh, 100_000, 2);
    let queries = noisy_points(&mesh, 10_000, 3);
    c.bench_function("k-d tree build, 100k points", |b| {
        b.iter(|| CloudIndex::new(black_box(&cloud)))
    });
    let index = CloudIndex::new(&cloud).expect("the bench cloud is indexable");
    c.bench_function("nearest neighbour, 10k queries in 100k points", |b| {
        b.iter(|| {
            queries
                .iter()
                .map(|&q| index.nearest(black_box(q)).0)
                .sum::<f64>()
        })
    });
}

fn bench_ply(c: &mut Criterion) {
    let mesh = bumpy_sphere(100, 200);
    let points = noisy_points(&mesh, 100_000, 4);
    let binary = ply_bytes(&points, false);
    let ascii = ply_bytes(&points[..10_000], true);
    c.bench_function("PLY parse, binary, 100k points with colour", |b| {
        b.iter(|| sfmeval::io::ply::read_ply(black_box(&binary)))
    });
    c.bench_function("PLY parse, ascii, 10k points with colour", |b| {
        b.iter(|| sfmeval::io::ply::read_ply(black_box(&ascii)))
    });
}

fn bench_umeyama(c: &mut Criterion) {
    let mesh = bumpy_sphere(40, 80);
    let src = noisy_points(&mesh, 1000, 5);
    let dst: Vec<Point3> = src
        .iter()
        .map(|p| [2.0 * p[1] + 1.0, -2.0 * p[0], 2.0 * p[2] - 3.0])
        .collect();
    c.bench_function("Umeyama similarity, 1000 pairs", |b| {
        b.iter(|| sfmeval::align::umeyama(black_box(&src), black_box(&dst), true))
    });
}

criterion_group!(benches, bench_mesh, bench_kdtree, bench_ply, bench_umeyama);
criterion_main!(benches);
