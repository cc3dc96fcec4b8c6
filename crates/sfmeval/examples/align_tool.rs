//! Runs sfmeval's alignment stages on files and prints JSON, for tests against independent
//! code (tests/python/test_align_*.py) and for timing.
//!
//! ```text
//! align_tool umeyama PAIRS.json [--no-scale]
//! align_tool icp GT RECON START.json [--max-points N] [--rigid]
//! align_tool auto GT RECON [--cameras PAIRS.json] [--pairs PAIRS.json] [--method auto|cameras|points|global|icp]
//! ```
//! `GT` is a mesh or cloud (PLY/OBJ/glTF), `RECON` a PLY; `PAIRS.json` is
//! `{"pairs": [{"recon": [x, y, z], "gt": [x, y, z]}, ...]}` (camera centres for `--cameras`);
//! `START.json` holds a 4×4 (`{"matrix": ...}` or a bare list). Timings exclude file reading.

use std::collections::BTreeMap;
use std::time::Instant;

use sfmeval::align::{self, AlignInput, AlignMethod, AlignOptions, CameraPair, IcpOptions};
use sfmeval::prepared::PreparedGroundTruth;
use sfmeval::progress::NoProgress;
use sfmeval::transform::Similarity;

fn read(path: &str) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| format!("{path}: {e}"))
}

fn flag(args: &[String], name: &str) -> Option<String> {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

fn load_gt(path: &str) -> Result<(PreparedGroundTruth, f64), String> {
    let bytes = read(path)?;
    let gt = sfmeval::io::read_ground_truth(path, &bytes, &BTreeMap::new())
        .map_err(|e| e.to_string())?;
    let t0 = Instant::now();
    let p = PreparedGroundTruth::new(&gt.ground_truth, 100_000, 0, &NoProgress)
        .map_err(|e| e.to_string())?;
    Ok((p, t0.elapsed().as_secs_f64()))
}

fn load_cloud(path: &str) -> Result<Vec<[f64; 3]>, String> {
    let bytes = read(path)?;
    Ok(sfmeval::io::read_point_cloud(path, &bytes)
        .map_err(|e| e.to_string())?
        .cloud
        .points
        .into_f64())
}

fn run(args: &[String]) -> Result<serde_json::Value, String> {
    let cmd = args.first().map(String::as_str).unwrap_or("");
    match cmd {
        "umeyama" => {
            let pairs = align::parse_point_pairs(&read(args.get(1).ok_or("missing PAIRS.json")?)?)
                .map_err(|e| e.to_string())?;
            let src: Vec<_> = pairs.iter().map(|p| p.recon).collect();
            let dst: Vec<_> = pairs.iter().map(|p| p.gt).collect();
            let t = align::umeyama(&src, &dst, !args.iter().any(|a| a == "--no-scale"))
                .map_err(|e| e.to_string())?;
            Ok(serde_json::json!({"matrix": t.matrix, "scale": t.scale()}))
        }
        "icp" => {
            let (gt, prep) = load_gt(args.get(1).ok_or("missing GT")?)?;
            let recon = load_cloud(args.get(2).ok_or("missing RECON")?)?;
            let start = Similarity::parse(&read(args.get(3).ok_or("missing START.json")?)?)
                .map_err(|e| e.to_string())?;
            let mut opts = IcpOptions::default();
            if let Some(n) = flag(args, "--max-points") {
                opts.max_points = n.parse().map_err(|_| "bad --max-points")?;
            }
            opts.with_scale = !args.iter().any(|a| a == "--rigid");
            let t0 = Instant::now();
            let (t, stage) =
                align::refine_icp(&gt, &recon, &start, &opts).map_err(|e| e.to_string())?;
            let secs = t0.elapsed().as_secs_f64();
            let report = align::Alignment {
                gt_from_recon: t,
                stages: vec![stage],
                requested: align::AlignMode::Icp,
            }
            .report();
            Ok(
                serde_json::json!({"matrix": t.matrix, "scale": t.scale(), "stage": report.stages[0], "seconds": secs, "prepare_seconds": prep}),
            )
        }
        "auto" => {
            let (gt, prep) = load_gt(args.get(1).ok_or("missing GT")?)?;
            let recon = load_cloud(args.get(2).ok_or("missing RECON")?)?;
            let cameras: Vec<CameraPair> = match flag(args, "--cameras") {
                Some(p) => align::parse_point_pairs(&read(&p)?)
                    .map_err(|e| e.to_string())?
                    .iter()
                    .map(|p| CameraPair::centers(p.recon, p.gt))
                    .collect(),
                None => Vec::new(),
            };
            let pairs = match flag(args, "--pairs") {
                Some(p) => align::parse_point_pairs(&read(&p)?).map_err(|e| e.to_string())?,
                None => Vec::new(),
            };
            let method =
                AlignMethod::parse(&flag(args, "--method").unwrap_or_else(|| "auto".into()))
                    .map_err(|e| e.to_string())?;
            let input = AlignInput {
                recon: &recon,
                cameras: &cameras,
                point_pairs: &pairs,
                start: None,
            };
            let t0 = Instant::now();
            let alignment = align::align(&gt, &input, method, &AlignOptions::default())
                .map_err(|e| e.to_string())?;
            let secs = t0.elapsed().as_secs_f64();
            let (t, report) = (alignment.gt_from_recon, alignment.report());
            Ok(
                serde_json::json!({"matrix": t.matrix, "scale": t.scale(), "report": report, "seconds": secs, "prepare_seconds": prep}),
            )
        }
        "prepare" => {
            // Only reads and indexes (to subtract from timings of `auto`).
            let (_, prep) = load_gt(args.get(1).ok_or("missing GT")?)?;
            let recon = load_cloud(args.get(2).ok_or("missing RECON")?)?;
            Ok(serde_json::json!({"points": recon.len(), "prepare_seconds": prep}))
        }
        "probe" => {
            // Times closest-point queries of the reconstruction's first points, mapped by START.
            let (gt, _) = load_gt(args.get(1).ok_or("missing GT")?)?;
            let recon = load_cloud(args.get(2).ok_or("missing RECON")?)?;
            let start = Similarity::parse(&read(args.get(3).ok_or("missing START.json")?)?)
                .map_err(|e| e.to_string())?;
            let pts: Vec<[f64; 3]> = recon.iter().take(16_384).map(|p| start.apply(*p)).collect();
            let t0 = Instant::now();
            let d: f64 = pts
                .iter()
                .map(|p| gt.closest_point(*p, &mut Default::default()).1)
                .sum();
            let serial = t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let d2: f64 = sfmeval::parallel::map(&pts, &NoProgress, |p| {
                gt.closest_point(*p, &mut Default::default()).1
            })
            .iter()
            .sum();
            let par = t0.elapsed().as_secs_f64();
            Ok(
                serde_json::json!({"queries": pts.len(), "serial_seconds": serial, "parallel_seconds": par, "mean": d / pts.len() as f64, "same": d == d2}),
            )
        }
        _ => Err("usage: align_tool umeyama|icp|auto ... (see the source)".into()),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(v) => println!("{v}"),
        Err(e) => {
            eprintln!("align_tool: {e}");
            std::process::exit(2);
        }
    }
}
