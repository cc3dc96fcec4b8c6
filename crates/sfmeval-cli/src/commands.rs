//! Command-line interface definitions and their implementations.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use clap::{Args, Parser, Subcommand};
use sfmeval::crop::{Crop, Volume};
use sfmeval::evaluate::{
    AlignmentInput, DEFAULT_SAMPLES, EvalOptions, InputInfo, PreparedGroundTruth, evaluate,
};
use sfmeval::geometry::{Aabb, GroundTruth};
use sfmeval::io;
use sfmeval::transform::Similarity;

use crate::files::{name_of, read, write_atomic};
use crate::progress::Bars;
use crate::summary;

/// Measure Structure-from-Motion reconstructions against ground truth.
#[derive(Parser, Debug)]
#[command(name = "sfmeval", version, about, propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Evaluate a reconstruction against a ground truth and write the report.
    Eval(EvalArgs),
    /// Show what a file holds: format, counts, bounds.
    Info {
        /// A PLY, GLB, glTF or OBJ file.
        file: PathBuf,
    },
    /// Evaluate the demo pair shipped with sfmeval and print the summary.
    Demo {
        /// Print the report JSON instead of the summary.
        #[arg(long)]
        json: bool,
        /// Write the report here.
        #[arg(long, value_name = "OUT.json")]
        report: Option<PathBuf>,
    },
}

#[derive(Args, Debug)]
struct EvalArgs {
    /// Ground truth: GLB, glTF, OBJ or PLY (mesh, or a dense cloud).
    #[arg(long, value_name = "FILE")]
    gt: PathBuf,
    /// Reconstruction: a PLY point cloud.
    #[arg(long, value_name = "FILE")]
    recon: PathBuf,
    /// A 4×4 row-major similarity gt_from_recon (JSON or 16 numbers as text).
    #[arg(long, value_name = "FILE")]
    transform: Option<PathBuf>,
    /// A crop file (sfmeval.crop/1 JSON).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["crop_box", "crop_sphere"])]
    crop: Option<PathBuf>,
    /// Axis-aligned crop box: xmin,ymin,zmin,xmax,ymax,zmax (ground-truth frame).
    #[arg(
        long,
        value_name = "X0,Y0,Z0,X1,Y1,Z1",
        allow_hyphen_values = true,
        conflicts_with = "crop_sphere"
    )]
    crop_box: Option<String>,
    /// Crop sphere: cx,cy,cz,radius (ground-truth frame).
    #[arg(long, value_name = "CX,CY,CZ,R", allow_hyphen_values = true)]
    crop_sphere: Option<String>,
    /// Discard reconstructed points farther than D from the ground truth.
    #[arg(long, value_name = "D", allow_hyphen_values = true)]
    max_distance: Option<f64>,
    /// Thresholds in ground-truth units (comma-separated).
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    tau: Vec<f64>,
    /// Thresholds in percent of the ground-truth bounding-box diagonal (comma-separated).
    /// Default when no threshold is given: 0.5,1,2.
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    tau_relative: Vec<f64>,
    /// Completeness samples drawn on a ground-truth mesh.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_SAMPLES)]
    samples: usize,
    /// Seed of the surface sampler.
    #[arg(long, value_name = "S", default_value_t = 0)]
    seed: u64,
    /// Also report distances signed by the closest triangle's normal (as CloudCompare's C2M).
    #[arg(long)]
    signed: bool,
    /// Histogram bins.
    #[arg(long, value_name = "N", default_value_t = sfmeval::stats::DEFAULT_BINS)]
    bins: usize,
    /// Write the report (sfmeval.report/1 JSON) here.
    #[arg(long, value_name = "OUT.json")]
    report: Option<PathBuf>,
    /// Write the kept points coloured by error here (binary PLY).
    #[arg(long, value_name = "OUT.ply")]
    colored: Option<PathBuf>,
    /// Distance at which the colour map saturates (default: the accuracy p95).
    #[arg(long, value_name = "D")]
    color_clip: Option<f64>,
    /// Write per-point distances here (CSV).
    #[arg(long, value_name = "OUT.csv")]
    csv: Option<PathBuf>,
    /// Print the report JSON on stdout instead of the summary.
    #[arg(long)]
    json: bool,
    /// No progress bars and no summary.
    #[arg(long)]
    quiet: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Eval(args) => {
            if let Some(n) = args.threads {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n.max(1))
                    .build_global()
                    .ok();
            }
            eval(&args)
        }
        Command::Info { file } => info(&file),
        Command::Demo { json, report } => demo(json, report.as_deref()),
    }
}

/// Parses exactly `N` comma-separated numbers.
fn numbers<const N: usize>(flag: &str, text: &str) -> Result<[f64; N]> {
    let v: Vec<f64> = text
        .split(',')
        .map(|w| {
            w.trim()
                .parse::<f64>()
                .with_context(|| format!("{flag}: '{w}' is not a number"))
        })
        .collect::<Result<_>>()?;
    v.try_into().map_err(|v: Vec<f64>| {
        anyhow::anyhow!("{flag} needs {N} comma-separated numbers, got {}", v.len())
    })
}

fn crop_from_args(args: &EvalArgs) -> Result<Crop> {
    let mut crop = match &args.crop {
        Some(path) => {
            Crop::parse(&read(path)?).with_context(|| format!("crop file '{}'", path.display()))?
        }
        None => Crop::default(),
    };
    if let Some(b) = &args.crop_box {
        let b = numbers::<6>("--crop-box", b)?;
        crop.volume = Some(Volume::Box {
            min: [b[0], b[1], b[2]],
            max: [b[3], b[4], b[5]],
        });
    }
    if let Some(s) = &args.crop_sphere {
        let s = numbers::<4>("--crop-sphere", s)?;
        crop.volume = Some(Volume::Sphere {
            center: [s[0], s[1], s[2]],
            radius: s[3],
        });
    }
    if args.max_distance.is_some() {
        crop.max_distance = args.max_distance;
    }
    crop.validate()?;
    Ok(crop)
}

fn eval(args: &EvalArgs) -> Result<()> {
    let options = EvalOptions {
        tau: args.tau.clone(),
        tau_percent_of_diagonal: args.tau_relative.clone(),
        samples: args.samples,
        seed: args.seed,
        signed: args.signed,
        histogram_bins: args.bins,
        crop: crop_from_args(args)?,
    };
    options.validate()?;
    let alignment = match &args.transform {
        Some(path) => AlignmentInput::given(
            Similarity::parse(&read(path)?)
                .with_context(|| format!("transform file '{}'", path.display()))?,
        ),
        None => AlignmentInput::none(),
    };
    let gt_bytes = read(&args.gt)?;
    let external = gltf_neighbours(&args.gt, &gt_bytes);
    let gt = io::read_ground_truth(&name_of(&args.gt), &gt_bytes, &external)
        .with_context(|| format!("ground truth '{}'", args.gt.display()))?;
    drop(gt_bytes);
    let recon = io::read_point_cloud(&name_of(&args.recon), &read(&args.recon)?)
        .with_context(|| format!("reconstruction '{}'", args.recon.display()))?;
    let info = InputInfo {
        recon_name: name_of(&args.recon),
        recon_format: recon.format.name().into(),
        recon_images: 0,
        gt_name: name_of(&args.gt),
        gt_format: gt.format.name().into(),
        warnings: gt.warnings.iter().chain(&recon.warnings).cloned().collect(),
    };
    let bars = Bars::new(args.quiet);
    let prepared = PreparedGroundTruth::new(&gt.ground_truth, options.samples, options.seed, &bars)
        .with_context(|| format!("ground truth '{}'", args.gt.display()))?;
    let evaluation = evaluate(&prepared, &recon.cloud, &alignment, &options, &info, &bars)?;
    let report = &evaluation.report;
    let json = report.to_json();
    if let Some(path) = &args.report {
        write_atomic(path, json.as_bytes())?;
    }
    if let Some(path) = &args.colored {
        let clip = args
            .color_clip
            .unwrap_or(report.accuracy.stats.percentiles.p95);
        write_atomic(path, &io::write::colored_ply(&evaluation, clip))?;
    }
    if let Some(path) = &args.csv {
        write_atomic(path, io::write::distances_csv(&evaluation).as_bytes())?;
    }
    if args.json {
        print!("{json}");
    } else if !args.quiet {
        print!("{}", summary::render(report));
    }
    Ok(())
}

/// Files next to a `.gltf` that its buffers may refer to.
fn gltf_neighbours(path: &Path, bytes: &[u8]) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    if io::gltf::is_glb(bytes) || !name_of(path).to_ascii_lowercase().ends_with(".gltf") {
        return out;
    }
    let Ok(v) = serde_json::from_slice::<serde_json::Value>(bytes) else {
        return out;
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    for b in v
        .get("buffers")
        .and_then(|b| b.as_array())
        .into_iter()
        .flatten()
    {
        if let Some(uri) = b.get("uri").and_then(|u| u.as_str()) {
            if !uri.starts_with("data:") && !uri.contains("..") {
                if let Ok(data) = std::fs::read(dir.join(uri)) {
                    out.insert(uri.to_string(), data);
                }
            }
        }
    }
    out
}

fn info(path: &Path) -> Result<()> {
    let bytes = read(path)?;
    let name = name_of(path);
    let format = io::detect(&name, &bytes).with_context(|| format!("'{}'", path.display()))?;
    println!("file      {}", path.display());
    println!("format    {} ({} bytes)", format.name(), bytes.len());
    if format == io::Format::Ply {
        let p = io::ply::read_ply(&bytes).with_context(|| format!("'{}'", path.display()))?;
        println!("encoding  {:?}", p.encoding);
        println!("vertex properties  {}", p.vertex_properties.join(" "));
        for c in &p.comments {
            println!("comment   {c}");
        }
    }
    let external = gltf_neighbours(path, &bytes);
    let gt = io::read_ground_truth(&name, &bytes, &external)
        .with_context(|| format!("'{}'", path.display()))?;
    let (kind, pts, tris, area) = match &gt.ground_truth {
        GroundTruth::Mesh(m) => ("mesh", m.vertices.len(), m.triangles.len(), m.area()),
        GroundTruth::Cloud(c) => ("point cloud", c.points.len(), 0, 0.0),
    };
    println!("kind      {kind}");
    println!("points    {pts}");
    if kind == "mesh" {
        println!("triangles {tris}");
        println!("area      {area}");
    }
    if let Some(b) = Aabb::of(gt.ground_truth.points()) {
        println!("bounds    min {:?}", b.min);
        println!("          max {:?}", b.max);
        println!("diagonal  {}", b.diagonal());
    }
    for w in &gt.warnings {
        println!("warning   {w}");
    }
    Ok(())
}

const DEMO_GT: &[u8] = include_bytes!("../../../data/demo/ground_truth.glb");
const DEMO_RECON: &[u8] = include_bytes!("../../../data/demo/sparse.ply");
const DEMO_TRANSFORM: &[u8] = include_bytes!("../../../data/demo/gt_from_recon.txt");

fn demo(json: bool, report_path: Option<&Path>) -> Result<()> {
    let gt = io::read_ground_truth("ground_truth.glb", DEMO_GT, &BTreeMap::new())?;
    let recon = io::read_point_cloud("sparse.ply", DEMO_RECON)?;
    let options = EvalOptions::default();
    let alignment = AlignmentInput::given(Similarity::parse(DEMO_TRANSFORM)?);
    let info = InputInfo {
        recon_name: "sparse.ply".into(),
        recon_format: "ply".into(),
        recon_images: 0,
        gt_name: "ground_truth.glb".into(),
        gt_format: "glb".into(),
        warnings: Vec::new(),
    };
    let bars = Bars::new(false);
    let prepared =
        PreparedGroundTruth::new(&gt.ground_truth, options.samples, options.seed, &bars)?;
    let evaluation = evaluate(&prepared, &recon.cloud, &alignment, &options, &info, &bars)?;
    if let Some(p) = report_path {
        write_atomic(p, evaluation.report.to_json().as_bytes())?;
    }
    if json {
        print!("{}", evaluation.report.to_json());
    } else {
        print!("{}", summary::render(&evaluation.report));
    }
    if evaluation.report.accuracy.stats.count == 0 {
        bail!("the demo evaluated no point");
    }
    Ok(())
}
