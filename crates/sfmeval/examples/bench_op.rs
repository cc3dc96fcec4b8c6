//! One benchmark operation of the core, timed in-process, for `bench/compare.py`.
//!
//! ```text
//! cargo build --release -p sfmeval --features parallel --example bench_op
//! target/release/examples/bench_op OP --mesh MESH --cloud CLOUD [--threads N] [--samples N]
//!     [--seed N] [--queries CLOUD2] [--start 4x4.txt] [--gate F] [--iterations N]
//! ```
//!
//! Prints one JSON line `{"op", "seconds", "cpu_seconds", "threads", "result": {...}}`.
//! `seconds` covers the operation only: every op except `load` reads its files first, untimed;
//! `cpu_seconds` is the CPU time all the process's threads spent over the same span (Linux's
//! per-thread `schedstat`; `null` elsewhere). Ops:
//!
//! - `load`: read and parse the mesh and the cloud;
//! - `bvh`: build the mesh's BVH (parry);
//! - `kdtree`: build the cloud's k-d tree (kiddo);
//! - `accuracy`: BVH build + exact distance of every cloud point to the mesh;
//! - `completeness`: `--samples` area-uniform samples on the mesh + k-d tree of the cloud +
//!   nearest cloud point of every sample;
//! - `c2c`: k-d tree of the cloud + nearest cloud point of every point of `--queries`;
//! - `align`: BVH build + trimmed scaled ICP (`sfmeval::align::refine_icp`, default options)
//!   of the cloud from the `--start` similarity; prints the final `gt_from_recon` matrix;
//! - `cost`: the physical-limit inputs: seconds per exact point-triangle test, seconds per
//!   streamed point, and the BVH's mean nodes/triangles visited per accuracy query.
//!
//! Distance results: `n`, `mean`, `max` (sums in input order, so thread count does not change
//! them). `--threads N` sizes rayon's pool (default: all cores).

use std::error::Error;
use std::sync::Mutex;
use std::time::Duration;

use serde_json::{Value, json};
use sfmeval::align::{IcpOptions, refine_icp};
use sfmeval::distance::{CloudIndex, MeshIndex};
use sfmeval::geometry::{GroundTruth, Point3, TriangleMesh};
use sfmeval::prepared::PreparedGroundTruth;
use sfmeval::progress::NoProgress;
use sfmeval::transform::Similarity;

type Res<T> = Result<T, Box<dyn Error>>;

/// The CPU seconds of the last span a [`Clock`] measured ([`Clock::elapsed`]).
static CPU_SECONDS: Mutex<Option<f64>> = Mutex::new(None);

/// CPU time of every live thread of this process, in seconds (the first field of each
/// `/proc/self/task/*/schedstat`, nanoseconds on the CPU); `None` where it cannot be read.
/// rayon's pool threads live as long as the process, so none of the op's time is lost.
fn process_cpu_seconds() -> Option<f64> {
    let mut ns = 0u64;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let stat = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        ns += stat.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(ns as f64 * 1e-9)
}

/// A wall clock that also reads the process's CPU time: `elapsed` records the CPU seconds
/// since `now` for the output's `cpu_seconds`.
struct Clock {
    wall: std::time::Instant,
    cpu: Option<f64>,
}

impl Clock {
    fn now() -> Clock {
        Clock {
            cpu: process_cpu_seconds(),
            wall: std::time::Instant::now(),
        }
    }

    fn elapsed(&self) -> Duration {
        let wall = self.wall.elapsed();
        let cpu = process_cpu_seconds().zip(self.cpu).map(|(b, a)| b - a);
        if let Ok(mut last) = CPU_SECONDS.lock() {
            *last = cpu;
        }
        wall
    }
}

struct Args {
    op: String,
    mesh: Option<String>,
    cloud: Option<String>,
    queries: Option<String>,
    start: Option<String>,
    threads: Option<usize>,
    samples: usize,
    seed: u64,
}

fn parse_args() -> Res<Args> {
    let mut it = std::env::args().skip(1);
    let mut a = Args {
        op: it
            .next()
            .ok_or("usage: bench_op OP --mesh M --cloud C [options]")?,
        mesh: None,
        cloud: None,
        queries: None,
        start: None,
        threads: None,
        samples: 1_000_000,
        seed: 0,
    };
    while let Some(k) = it.next() {
        let v = it.next().ok_or(format!("{k} needs a value"))?;
        match k.as_str() {
            "--mesh" => a.mesh = Some(v),
            "--cloud" => a.cloud = Some(v),
            "--queries" => a.queries = Some(v),
            "--start" => a.start = Some(v),
            "--threads" => a.threads = Some(v.parse()?),
            "--samples" => a.samples = v.parse()?,
            "--seed" => a.seed = v.parse()?,
            _ => return Err(format!("unknown option {k}").into()),
        }
    }
    Ok(a)
}

fn read_mesh(path: &str) -> Res<TriangleMesh> {
    let bytes = std::fs::read(path)?;
    match sfmeval::io::read_ground_truth(path, &bytes, &Default::default())?.ground_truth {
        GroundTruth::Mesh(m) => Ok(m),
        GroundTruth::Cloud(_) => Err(format!("{path} has no triangles").into()),
    }
}

fn read_cloud(path: &str) -> Res<Vec<Point3>> {
    let bytes = std::fs::read(path)?;
    Ok(sfmeval::io::read_point_cloud(path, &bytes)?
        .cloud
        .points
        .into_f64())
}

/// `n`, mean and max of distances, summed in input order.
fn summary(d: &[f64]) -> Value {
    let mean = d.iter().sum::<f64>() / d.len().max(1) as f64;
    let max = d.iter().copied().fold(0.0, f64::max);
    json!({ "n": d.len(), "mean": mean, "max": max })
}

fn main() -> Res<()> {
    let a = parse_args()?;
    let threads = match a.threads {
        Some(n) => n,
        None => std::thread::available_parallelism()?.get(),
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build_global()?;
    let mesh_path = || a.mesh.as_deref().ok_or("--mesh is required");
    let cloud_path = || a.cloud.as_deref().ok_or("--cloud is required");
    let (seconds, result) = match a.op.as_str() {
        "load" => {
            let t = Clock::now();
            let m = read_mesh(mesh_path()?)?;
            let c = read_cloud(cloud_path()?)?;
            let s = t.elapsed().as_secs_f64();
            let r = json!({"vertices": m.vertices.len(), "triangles": m.triangles.len(), "points": c.len()});
            (s, r)
        }
        "bvh" => {
            let m = read_mesh(mesh_path()?)?;
            let t = Clock::now();
            let idx = MeshIndex::new(&m)?;
            let s = t.elapsed().as_secs_f64();
            drop(idx);
            (s, json!({"triangles": m.triangles.len()}))
        }
        "kdtree" => {
            let c = read_cloud(cloud_path()?)?;
            let t = Clock::now();
            let idx = CloudIndex::new(&c)?;
            let s = t.elapsed().as_secs_f64();
            drop(idx);
            (s, json!({"points": c.len()}))
        }
        "accuracy" => {
            let m = read_mesh(mesh_path()?)?;
            let c = read_cloud(cloud_path()?)?;
            let t = Clock::now();
            let idx = MeshIndex::new(&m)?;
            let d = sfmeval::parallel::map_points_with_state(&c, &NoProgress, |hint, p| {
                idx.closest_from(*p, hint).distance
            });
            (t.elapsed().as_secs_f64(), summary(&d))
        }
        "completeness" => {
            let m = read_mesh(mesh_path()?)?;
            let c = read_cloud(cloud_path()?)?;
            let t = Clock::now();
            let samples = sfmeval::sampling::sample_surface(&m, a.samples, a.seed)?;
            let idx = CloudIndex::new(&c)?;
            let d = sfmeval::parallel::map_points(&samples, &NoProgress, |p| idx.nearest(*p).0);
            (t.elapsed().as_secs_f64(), summary(&d))
        }
        "c2c" => {
            let c = read_cloud(cloud_path()?)?;
            let q = read_cloud(a.queries.as_deref().ok_or("--queries is required")?)?;
            let t = Clock::now();
            let idx = CloudIndex::new(&c)?;
            let d = sfmeval::parallel::map_points(&q, &NoProgress, |p| idx.nearest(*p).0);
            (t.elapsed().as_secs_f64(), summary(&d))
        }
        "align" => {
            let m = read_mesh(mesh_path()?)?;
            let c = read_cloud(cloud_path()?)?;
            let start = Similarity::parse(&std::fs::read(
                a.start.as_deref().ok_or("--start is required")?,
            )?)?;
            let t = Clock::now();
            let gt = PreparedGroundTruth::new(&GroundTruth::Mesh(m), 1, 0, &NoProgress)?;
            let index_s = t.elapsed().as_secs_f64();
            let (sim, stage) = refine_icp(&gt, &c, &start, &IcpOptions::default())?;
            let s = t.elapsed().as_secs_f64();
            let r = json!({"matrix": sim.matrix, "iterations": stage.iterations,
                           "notes": stage.notes, "index_seconds": index_s});
            (s, r)
        }
        "cost" => cost(&read_mesh(mesh_path()?)?, &read_cloud(cloud_path()?)?)?,
        other => return Err(format!("unknown op {other}").into()),
    };
    let cpu_seconds = CPU_SECONDS.lock().ok().and_then(|c| *c);
    let out = json!({"op": a.op, "seconds": seconds, "cpu_seconds": cpu_seconds,
                     "threads": threads, "result": result});
    println!("{out}");
    Ok(())
}

/// Exact closest point on one triangle (Ericson, Real-Time Collision Detection 5.1.5), squared.
fn point_triangle_sq(p: Point3, t: [Point3; 3]) -> f64 {
    use sfmeval::geometry::{dot, sub};
    let [a, b, c] = t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let at = |u: f64, v: f64| {
        let q = [
            a[0] + u * ab[0] + v * ac[0],
            a[1] + u * ab[1] + v * ac[1],
            a[2] + u * ab[2] + v * ac[2],
        ];
        let d = sub(p, q);
        dot(d, d)
    };
    if d1 <= 0.0 && d2 <= 0.0 {
        return at(0.0, 0.0);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return at(1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return at(d1 / (d1 - d3), 0.0);
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return at(0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return at(0.0, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at(1.0 - w, w);
    }
    let denom = 1.0 / (va + vb + vc);
    at(vb * denom, vc * denom)
}

/// Single-thread costs for the physical-limit estimate: one exact point-triangle test, one
/// streamed point (read + write 24 bytes), and the BVH's visits per query (counted by
/// replaying the query with parry's best-first traversal is not public, so the count is the
/// number of triangles whose bounding box is nearer than the answer: a lower bound on the
/// triangles any exact BVH must test).
fn cost(mesh: &TriangleMesh, cloud: &[Point3]) -> Res<(f64, Value)> {
    let n = cloud.len().min(200_000);
    let tris: Vec<[Point3; 3]> = mesh.triangles.iter().map(|t| mesh.corners(t)).collect();
    // point-triangle tests: every query against a sliding window of triangles (cache-resident)
    let reps = 2_000_000usize;
    let t = Clock::now();
    let mut acc = 0.0;
    for i in 0..reps {
        acc += point_triangle_sq(cloud[i % n], tris[(i * 7) % 4096 % tris.len()]);
    }
    let per_test = t.elapsed().as_secs_f64() / reps as f64;
    std::hint::black_box(acc);
    // streaming: a pass reading the cloud and writing one f64 per point
    let t = Clock::now();
    let out: Vec<f64> = cloud.iter().map(|p| p[0] + p[1] + p[2]).collect();
    let per_point = t.elapsed().as_secs_f64() / cloud.len() as f64;
    std::hint::black_box(out);
    // lower bound on triangles tested: boxes nearer than the exact answer, on a small subsample
    let idx = MeshIndex::new(mesh)?;
    let boxes: Vec<([f64; 3], [f64; 3])> = tris
        .iter()
        .map(|t| {
            let lo = [0, 1, 2].map(|k| t[0][k].min(t[1][k]).min(t[2][k]));
            let hi = [0, 1, 2].map(|k| t[0][k].max(t[1][k]).max(t[2][k]));
            (lo, hi)
        })
        .collect();
    let probe = 200.min(cloud.len());
    let mut nearer = 0usize;
    for p in cloud.iter().take(probe) {
        let d = idx.closest(*p).distance;
        nearer += boxes
            .iter()
            .filter(|(lo, hi)| {
                let mut s = 0.0;
                for k in 0..3 {
                    let e = (lo[k] - p[k]).max(0.0).max(p[k] - hi[k]);
                    s += e * e;
                }
                s <= d * d
            })
            .count();
    }
    let tests_per_query = nearer as f64 / probe as f64;
    let r = json!({
        "seconds_per_triangle_test": per_test,
        "seconds_per_streamed_point": per_point,
        "triangle_tests_per_query_lower_bound": tests_per_query,
    });
    Ok((0.0, r))
}
