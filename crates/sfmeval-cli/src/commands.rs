//! Command-line interface definitions and their implementations.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use clap::builder::PossibleValuesParser;
use clap::{Args, Parser, Subcommand};
use sfmeval::AlignInputProblem;
use sfmeval::align::{AlignMode, AlignRequest, PointPair};
use sfmeval::crop::{Crop, Volume};
use sfmeval::dataset::{Dataset, DatasetPaths, Part};
use sfmeval::evaluate::{DEFAULT_SAMPLES, EvalOptions};
use sfmeval::export;
use sfmeval::geometry::{Aabb, GroundTruth};
use sfmeval::io::{self, ReadLimits};
use sfmeval::model;
use sfmeval::pipeline::{self, EvalRequest, ReconInput, read_reconstruction};
use sfmeval::pose::{PoseOptions, Protocol, ProtocolOptions};
use sfmeval_fs::{
    Disk, cameras_on_files, name_of, path_str, poses_on_files, read, read_point_pairs,
    read_reconstruction_with_cameras, read_transform, write_atomic,
};

use crate::concurrent::side_by_side;
use crate::progress::Bars;
use crate::summary;
use crate::table::{TableArgs, table_cmd};
use crate::tanksandtemples::{LogArgs, TntArgs, log_cmd, tnt_cmd};

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
    Eval(Box<EvalArgs>),
    /// Align a reconstruction to the ground truth and print (or save) gt_from_recon.
    Align {
        #[command(flatten)]
        input: InputArgs,
        /// Write the 4×4 here (JSON with the alignment section when the name ends in .json,
        /// else 16 numbers as text).
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Seed of the randomised stages and of the surface sampler.
        #[arg(long, value_name = "S", default_value_t = 0)]
        seed: u64,
        /// Ground-truth surface samples the `global` search measures against (as `eval
        /// --samples`: with the same value and seed, `align` finds `eval`'s alignment).
        #[arg(long, value_name = "N", default_value_t = DEFAULT_SAMPLES)]
        samples: usize,
    },
    /// Camera-pose errors of a reconstruction's cameras against the ground-truth cameras.
    Cameras {
        /// Ground-truth cameras (a dataset's cameras.json, or any model in the GT frame).
        #[arg(long, value_name = "FILE")]
        gt_cameras: PathBuf,
        /// The reconstruction: a COLMAP model folder, .nvm, Bundler .out, sfm_data.json, cameras.json.
        #[arg(long, value_name = "PATH")]
        recon: PathBuf,
        /// Use this gt_from_recon instead of aligning the camera centres.
        #[arg(long, value_name = "FILE")]
        transform: Option<PathBuf>,
        /// Write the cameras section (JSON) here.
        #[arg(long, value_name = "OUT.json")]
        report: Option<PathBuf>,
        /// Print the JSON instead of the summary.
        #[arg(long)]
        json: bool,
    },
    /// A camera-pose benchmark's numbers (COLMAP's benchmark, IMC mAA, CO3D RRA/RTA/AUC), as
    /// its official code computes them, from relative poses (no alignment).
    Poses {
        /// Ground-truth cameras (a dataset's cameras.json, or any model: COLMAP, NVM, ...).
        #[arg(long, value_name = "FILE")]
        gt_cameras: PathBuf,
        /// The reconstruction: a COLMAP model folder, .nvm, Bundler .out, sfm_data.json, cameras.json.
        #[arg(long, value_name = "PATH")]
        recon: PathBuf,
        /// The protocol (docs/poses.md).
        #[arg(long, value_parser = PossibleValuesParser::new(["colmap", "imc", "co3d"]))]
        protocol: String,
        /// COLMAP: the dataset's ground-truth position accuracy (GT units): shorter GT
        /// baselines get translation error 0, and it is the AUC's min_error (0: off).
        #[arg(long, value_name = "D", default_value_t = 0.0)]
        position_accuracy: f64,
        /// Write every scored ground-truth pair's errors here (CSV).
        #[arg(long, value_name = "OUT.csv")]
        pairs: Option<PathBuf>,
        /// Write the report (sfmeval.poses/1 JSON) here.
        #[arg(long, value_name = "OUT.json")]
        report: Option<PathBuf>,
        /// Print the JSON instead of the summary.
        #[arg(long)]
        json: bool,
    },
    /// Show what a file holds: format, counts, bounds.
    Info {
        /// A PLY, GLB, glTF or OBJ file.
        file: PathBuf,
        /// Refuse a glTF mesh with more triangles than this once every node instance is expanded
        /// (PLY and OBJ meshes are read whatever their size).
        #[arg(long, value_name = "N", default_value_t = ReadLimits::DEFAULT_MAX_TRIANGLES)]
        max_triangles: u64,
    },
    /// The Tanks and Temples protocol on a scene folder: trajectory alignment, three ICP
    /// refinements, crop, voxel down-sampling, precision / recall / F at the scene's τ, as the
    /// benchmark's own evaluation toolbox computes them.
    #[command(alias = "tanksandtemples")]
    Tnt(Box<TntArgs>),
    /// The DTU MVS evaluation on a scan (STL points, observation mask, ground plane):
    /// mean accuracy, mean completeness and overall in mm, as the benchmark's Python port
    /// computes them.
    Dtu(Box<crate::dtu::DtuArgs>),
    /// ETH3D's multi-view evaluation on a scene's laser scans (a MeshLab project): accuracy,
    /// completeness and F1 per tolerance, as the benchmark's official tool computes them.
    Eth3d(Box<crate::eth3d::Eth3dArgs>),
    /// Write a model's cameras as a Tanks and Temples .log trajectory (one frame per image).
    Log(LogArgs),
    /// Table I and the comparison table of evaluation reports, as `sfmeval-runner report`
    /// writes them for its runs.
    Table(TableArgs),
    /// Write a reconstruction's points (binary PLY, double x y z, with its colours) and its
    /// cameras (cameras.json) in the reconstruction's own frame: any format --recon reads.
    Export(ExportArgs),
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

/// The inputs shared by `eval` and `align`.
#[derive(Args, Debug)]
struct InputArgs {
    /// A dataset folder (docs/dataset.md): its ground_truth.glb is the ground truth, its
    /// cameras.json the ground-truth cameras, and its depth/ (when present) the depth maps
    /// (`eval` only). --gt, --gt-cameras and --depth override the parts.
    #[arg(long, value_name = "DIR")]
    dataset: Option<PathBuf>,
    /// Ground truth: GLB, glTF, OBJ or PLY (mesh, or a dense cloud).
    #[arg(long, value_name = "FILE", required_unless_present = "dataset")]
    gt: Option<PathBuf>,
    /// Reconstruction: a PLY point cloud, a COLMAP model folder (sparse/ with sub-models is
    /// fine), an .nvm, a Bundler .out, an OpenMVG sfm_data.json, or a cameras.json.
    #[arg(long, value_name = "PATH")]
    recon: PathBuf,
    /// The reconstruction's name in the report and its notes (default: the file or folder
    /// name). `sfmeval-runner report` and the page's Compare name a run `DATASET/PIPELINE`:
    /// with that name the report is theirs byte for byte.
    #[arg(long, value_name = "NAME")]
    name: Option<String>,
    /// The SfM model (any format --recon takes) whose cameras go with a PLY --recon in the same
    /// frame: the PLY's points at the model's camera centres are removed (whatever their
    /// colour), and the model's cameras serve the camera alignment and the pose metrics. A
    /// --recon folder holding one PLY beside a model does the same by itself.
    #[arg(long, value_name = "PATH")]
    recon_cameras: Option<PathBuf>,
    /// Ground-truth cameras (the dataset's cameras.json): camera alignment and pose metrics.
    #[arg(long, value_name = "FILE")]
    gt_cameras: Option<PathBuf>,
    /// Alignment: auto (cameras, else points, else global; then icp), cameras, points, global
    /// (alone, or refined: cameras+icp, points+icp, global+icp), icp (from --transform or the
    /// identity), given (needs --transform) or none. Default: given with --transform, else auto.
    #[arg(long, value_name = "METHOD", value_parser = PossibleValuesParser::new(AlignMode::names()))]
    align: Option<String>,
    /// A 4×4 row-major similarity gt_from_recon (JSON or 16 numbers as text): used as is with
    /// `--align given`, as the start of `--align icp`.
    #[arg(long, value_name = "FILE")]
    transform: Option<PathBuf>,
    /// Point pairs for `--align points`: `{"pairs": [{"recon": [x,y,z], "gt": [x,y,z]}, ...]}`.
    #[arg(long, value_name = "FILE")]
    pairs: Option<PathBuf>,
    /// Refuse a glTF ground truth with more triangles than this once every node instance is
    /// expanded (checked before anything is allocated; raise it for a trusted large file). PLY
    /// and OBJ meshes are read whatever their size: their triangles are in the file.
    #[arg(long, value_name = "N", default_value_t = ReadLimits::DEFAULT_MAX_TRIANGLES)]
    max_triangles: u64,
}

/// The flags of `sfmeval export`.
#[derive(Args, Debug)]
struct ExportArgs {
    /// The reconstruction: a PLY point cloud, a COLMAP model folder, an .nvm, a Bundler .out, an
    /// OpenMVG sfm_data.json or a cameras.json (what `eval --recon` reads), or a run folder of
    /// `sfmeval-runner` (its run.json beside model/ or sparse.ply: the reconstruction the
    /// runner's report evaluates, by the run-folder layout of sfmeval-table: the model, else
    /// sparse.ply).
    #[arg(value_name = "RECON")]
    recon: PathBuf,
    /// The SfM model whose cameras go with a PLY RECON (as `eval --recon-cameras`: the PLY's
    /// points at the model's camera centres are removed).
    #[arg(long, value_name = "PATH")]
    recon_cameras: Option<PathBuf>,
    /// The folder to write points.ply and cameras.json into (made when missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct EvalArgs {
    #[command(flatten)]
    input: InputArgs,
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
        allow_hyphen_values = true,
        alias = "tau-relative"
    )]
    tau_percent: Vec<f64>,
    /// Completeness samples drawn on a ground-truth mesh.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_SAMPLES)]
    samples: usize,
    /// Seed of the surface sampler and the randomised alignment stages.
    #[arg(long, value_name = "S", default_value_t = 0)]
    seed: u64,
    /// Also report distances signed by the closest triangle's normal (as CloudCompare's C2M).
    #[arg(long)]
    signed: bool,
    /// Histogram bins.
    #[arg(long, value_name = "N", default_value_t = sfmeval::stats::DEFAULT_BINS)]
    bins: usize,
    /// Write the report (sfmeval.report/3 JSON) here.
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
    /// Ground-truth depth maps (a dataset's depth/ folder: <image stem>.npy for every image of
    /// the ground-truth cameras; needs --gt-cameras or --dataset): adds completeness over the
    /// visible surface and, for models with tracks, the track-based error.
    #[arg(long, value_name = "DIR")]
    depth: Option<PathBuf>,
    /// Images a surface sample must be seen in to count as visible (with depth maps).
    #[arg(long, value_name = "K", default_value_t = sfmeval::visibility::DEFAULT_MIN_VIEWS)]
    min_views: u32,
    /// Write the completeness samples here (CSV: position, distance, views, label).
    #[arg(long, value_name = "OUT.csv")]
    samples_csv: Option<PathBuf>,
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
        Command::Align {
            input,
            out,
            seed,
            samples,
        } => align_cmd(&input, out.as_deref(), seed, samples),
        Command::Poses {
            gt_cameras,
            recon,
            protocol,
            position_accuracy,
            pairs,
            report,
            json,
        } => poses_cmd(
            &gt_cameras,
            &recon,
            &protocol,
            position_accuracy,
            pairs.as_deref(),
            report.as_deref(),
            json,
        ),
        Command::Cameras {
            gt_cameras,
            recon,
            transform,
            report,
            json,
        } => cameras_cmd(
            &gt_cameras,
            &recon,
            transform.as_deref(),
            report.as_deref(),
            json,
        ),
        Command::Info {
            file,
            max_triangles,
        } => info(&file, &ReadLimits::triangles(max_triangles)),
        Command::Tnt(args) => tnt_cmd(&args),
        Command::Dtu(args) => crate::dtu::dtu_cmd(&args),
        Command::Eth3d(args) => crate::eth3d::eth3d_cmd(&args),
        Command::Log(args) => log_cmd(&args),
        Command::Table(args) => table_cmd(&args),
        Command::Export(args) => export_cmd(&args),
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

/// The alignment request of `--align`, `--transform` and `--pairs`.
fn align_request(input: &InputArgs) -> Result<AlignRequest> {
    let transform = input.transform.as_deref().map(read_transform).transpose()?;
    let pairs: Vec<PointPair> = match &input.pairs {
        Some(p) => read_point_pairs(p)?,
        None => Vec::new(),
    };
    let mode = input.align.as_deref().map(AlignMode::parse).transpose()?;
    AlignRequest::new(mode, transform, pairs).map_err(|e| match e {
        sfmeval::Error::AlignInput { mode, problem } => {
            anyhow::anyhow!("--align {mode} {}", flag_problem(problem))
        }
        e => e.into(),
    })
}

/// An alignment request's problem in the flags the user types.
fn flag_problem(problem: AlignInputProblem) -> &'static str {
    match problem {
        AlignInputProblem::MissingTransform => "needs --transform FILE",
        AlignInputProblem::MissingPairs => "needs --pairs FILE",
        AlignInputProblem::TransformIgnoredUseGiven => {
            "ignores --transform (use --align given, the default with --transform)"
        }
        AlignInputProblem::TransformIgnored => {
            "ignores --transform (it is used by --align given and as the start of --align icp)"
        }
    }
}

/// Where the ground truth's parts are: `--dataset` gives the folder layout, `--gt`,
/// `--gt-cameras` and `--depth` override a part.
fn dataset_paths(
    input: &InputArgs,
    depth: Option<&Path>,
    with_depth: bool,
) -> Result<DatasetPaths> {
    let mut paths = match &input.dataset {
        Some(d) => DatasetPaths::folder(path_str(d)?),
        None => {
            let gt = input
                .gt
                .as_deref()
                .ok_or_else(|| anyhow::anyhow!("--gt FILE or --dataset DIR is required"))?;
            DatasetPaths::ground_truth(path_str(gt)?)
        }
    };
    if let Some(gt) = &input.gt {
        paths.ground_truth = path_str(gt)?.to_string();
    }
    if let Some(c) = &input.gt_cameras {
        paths.cameras = Part::Required(path_str(c)?.to_string());
    }
    paths.depth = match (with_depth, depth) {
        (false, _) => Part::Off,
        (true, Some(d)) => Part::Required(path_str(d)?.to_string()),
        (true, None) => paths.depth,
    };
    Ok(paths)
}

/// An evaluation's error, naming the file it is about: the pairs file for the point pairs'
/// errors, else the reconstruction.
fn run_error(e: sfmeval::Error, input: &InputArgs) -> anyhow::Error {
    match (&input.pairs, e.concerns_point_pairs()) {
        (Some(p), true) => anyhow::Error::new(e).context(format!("point pairs '{}'", p.display())),
        _ => anyhow::Error::new(e).context(format!("evaluating '{}'", input.recon.display())),
    }
}

/// Reads the reconstruction of `--recon` (with `--recon-cameras`). A binary PLY cloud is read
/// in pieces, so a dense cloud is never in memory twice (file bytes and points).
fn read_recon(input: &InputArgs) -> Result<ReconInput> {
    let name = input.name.clone().unwrap_or_else(|| name_of(&input.recon));
    read_reconstruction_with_cameras(&input.recon, input.recon_cameras.as_deref(), &name)
}

/// `sfmeval export`: the points `eval` would evaluate (camera-centre points removed, in the
/// file's order) as a float64 PLY, and the model's cameras as cameras.json, both in the
/// reconstruction's frame. Without cameras, a cameras.json left in DIR by an earlier export is
/// removed (the folder never mixes two reconstructions).
fn export_cmd(args: &ExportArgs) -> Result<()> {
    let run_folder = args.recon.join(sfmeval_table::layout::RUN_JSON).is_file();
    let recon = if run_folder && args.recon_cameras.is_none() {
        // a runner's run folder: its reconstruction as the runner's report reads it
        let files = sfmeval_table::layout::read_run_reconstruction(&Disk, path_str(&args.recon)?)?;
        // errors name the part of the run folder they are about: model/ or sparse.ply
        let part = if files.contains_key(sfmeval_table::layout::SPARSE_PLY) {
            sfmeval_table::layout::SPARSE_PLY
        } else {
            sfmeval_table::layout::MODEL_DIR
        };
        read_reconstruction(&name_of(&args.recon), &files)
            .with_context(|| format!("reconstruction '{}'", args.recon.join(part).display()))?
    } else {
        read_reconstruction_with_cameras(
            &args.recon,
            args.recon_cameras.as_deref(),
            &name_of(&args.recon),
        )?
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating the folder '{}'", args.out.display()))?;
    let points = recon.cloud.points.as_f64();
    let colors = recon.cloud.colors.as_deref();
    write_atomic(
        &args.out.join("points.ply"),
        &export::points_ply_f64(&points, colors),
    )?;
    let cameras_path = args.out.join("cameras.json");
    let images = match &recon.model {
        Some(m) => {
            let text = model::cameras_json::write_cameras_json(m, "reconstruction");
            write_atomic(&cameras_path, text.as_bytes())?;
            Some(m.images.len())
        }
        None => {
            if cameras_path.exists() {
                std::fs::remove_file(&cameras_path)
                    .with_context(|| format!("removing the stale '{}'", cameras_path.display()))?;
            }
            None
        }
    };
    for n in &recon.notes {
        eprintln!("{}: {}", n.level.as_str(), n.message);
    }
    println!(
        "{}: {} points{}, {} -> {}",
        args.recon.display(),
        points.len(),
        if colors.is_some() {
            " with colours"
        } else {
            ""
        },
        images.map_or("no cameras".to_string(), |n| format!("{n} images")),
        args.out.display()
    );
    Ok(())
}

/// The ground truth (as [`dataset_paths`] finds it) and the reconstruction, read at the same
/// time: two files, two parsers (the ground truth's error first when both fail).
fn read_inputs(
    input: &InputArgs,
    depth: Option<&Path>,
    with_depth: bool,
) -> Result<(Dataset, ReconInput)> {
    let paths = dataset_paths(input, depth, with_depth)?;
    let limits = ReadLimits::triangles(input.max_triangles);
    let (recon, dataset) = side_by_side(
        || read_recon(input),
        || sfmeval_fs::read_dataset(&paths, &limits),
    );
    Ok((dataset?, recon?))
}

fn eval(args: &EvalArgs) -> Result<()> {
    let eval = EvalOptions {
        tau: args.tau.clone(),
        tau_percent_of_diagonal: args.tau_percent.clone(),
        samples: args.samples,
        seed: args.seed,
        signed: args.signed,
        histogram_bins: args.bins,
        crop: crop_from_args(args)?,
        min_views: args.min_views,
    };
    eval.validate()?;
    let request = EvalRequest {
        align: align_request(&args.input)?,
        eval,
        pose: PoseOptions::default(),
    };
    let bars = Bars::new(args.quiet);
    let (mut dataset, recon) = read_inputs(&args.input, args.depth.as_deref(), true)?;
    let evaluation = pipeline::run_owned(&mut dataset, recon, &request, &bars)
        .map_err(|e| run_error(e, &args.input))?;
    if let Some(path) = &args.samples_csv {
        write_atomic(path, export::samples_csv(&evaluation).as_bytes())?;
    }
    let report = &evaluation.report;
    let json = report.to_json();
    if let Some(path) = &args.report {
        write_atomic(path, json.as_bytes())?;
    }
    if let Some(path) = &args.colored {
        let clip = args
            .color_clip
            .unwrap_or(report.accuracy.stats.percentiles.p95);
        write_atomic(path, &export::colored_ply(&evaluation, clip))?;
    }
    if let Some(path) = &args.csv {
        write_atomic(path, export::distances_csv(&evaluation).as_bytes())?;
    }
    if args.json {
        print!("{json}");
    } else if !args.quiet {
        print!("{}", summary::render(report));
    }
    Ok(())
}

fn align_cmd(input: &InputArgs, out: Option<&Path>, seed: u64, samples: usize) -> Result<()> {
    // The ground truth is sampled as `eval` samples it: the global search measures against
    // those samples (one sample, as this once drew, is a ground truth of zero extent).
    let request = EvalRequest {
        align: align_request(input)?,
        eval: EvalOptions {
            samples,
            seed,
            ..EvalOptions::default()
        },
        pose: PoseOptions::default(),
    };
    let bars = Bars::new(false);
    let (mut dataset, recon) = read_inputs(input, None, false)?;
    let evaluation =
        pipeline::run(&mut dataset, &recon, &request, &bars).map_err(|e| run_error(e, input))?;
    let a = &evaluation.report.alignment;
    let text: String = a
        .gt_from_recon
        .iter()
        .map(|r| {
            r.iter()
                .map(|v| format!("{v:.17e}"))
                .collect::<Vec<_>>()
                .join(" ")
                + "\n"
        })
        .collect();
    if let Some(p) = out {
        if name_of(p).to_ascii_lowercase().ends_with(".json") {
            let mut s = serde_json::to_string_pretty(a)?;
            s.push('\n');
            write_atomic(p, s.as_bytes())?;
        } else {
            write_atomic(
                p,
                format!("# gt_from_recon ({}), scale {}\n{text}", a.method, a.scale).as_bytes(),
            )?;
        }
    }
    println!(
        "# gt_from_recon by {} (scale {}, rmse {:?}, converged {})",
        a.method, a.scale, a.rmse, a.converged
    );
    print!("{text}");
    for n in &evaluation.report.notes {
        eprintln!("{}: {}", n.level.as_str(), n.message);
    }
    Ok(())
}

fn cameras_cmd(
    gt_cameras: &Path,
    recon: &Path,
    transform: Option<&Path>,
    report: Option<&Path>,
    json: bool,
) -> Result<()> {
    let given = transform.map(read_transform).transpose()?;
    let outputs = cameras_on_files(gt_cameras, recon, given)?;
    let s = outputs.to_json()?;
    if let Some(p) = report {
        write_atomic(p, s.as_bytes())?;
    }
    if json {
        print!("{s}");
    } else {
        print!(
            "{}",
            summary::render_cameras(
                &outputs.cameras,
                &outputs.alignment.method,
                outputs.alignment.scale
            )
        );
    }
    Ok(())
}

fn poses_cmd(
    gt_cameras: &Path,
    recon: &Path,
    protocol: &str,
    position_accuracy: f64,
    pairs: Option<&Path>,
    report: Option<&Path>,
    json: bool,
) -> Result<()> {
    let protocol = Protocol::parse(protocol)?;
    let options = ProtocolOptions {
        colmap_position_accuracy: position_accuracy,
        ..ProtocolOptions::default()
    };
    let (gt, poses) = poses_on_files(gt_cameras, recon, protocol, &options)?;
    let s = poses.to_json();
    if let Some(p) = report {
        write_atomic(p, s.as_bytes())?;
    }
    if let Some(p) = pairs {
        write_atomic(p, poses.pairs_csv(&gt).as_bytes())?;
    }
    if json {
        print!("{s}");
    } else {
        print!("{}", poses.summary());
    }
    Ok(())
}

fn info(path: &Path, limits: &ReadLimits) -> Result<()> {
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
    let dataset =
        Dataset::read_with_limits(&Disk, &DatasetPaths::ground_truth(path_str(path)?), limits)?;
    let gt = &dataset.loaded;
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
    if let Some(b) = Aabb::of(&gt.ground_truth.points()) {
        println!("bounds    min {:?}", b.min);
        println!("          max {:?}", b.max);
        println!("diagonal  {}", b.diagonal());
    }
    for n in &gt.notes {
        println!("{:<9} {}", n.level.as_str(), n.message);
    }
    Ok(())
}

const DEMO_GT: &[u8] = include_bytes!("../../../data/demo/ground_truth.glb");
const DEMO_CAMERAS: &[u8] = include_bytes!("../../../data/demo/cameras.json");
const DEMO_MODEL: [(&str, &[u8]); 3] = [
    (
        "sparse/cameras.txt",
        include_bytes!("../../../data/demo/sparse/cameras.txt"),
    ),
    (
        "sparse/images.txt",
        include_bytes!("../../../data/demo/sparse/images.txt"),
    ),
    (
        "sparse/points3D.txt",
        include_bytes!("../../../data/demo/sparse/points3D.txt"),
    ),
];

/// The demo: 36 rendered views of the built-in statue (Blender), reconstructed by pycolmap,
/// evaluated with `auto` alignment (camera centres, then ICP) and camera-pose metrics.
fn demo(json: bool, report_path: Option<&Path>) -> Result<()> {
    let mut files: BTreeMap<String, Vec<u8>> = DEMO_MODEL
        .iter()
        .map(|(n, b)| (format!("demo/{n}"), b.to_vec()))
        .collect();
    files.insert("demo/ground_truth.glb".into(), DEMO_GT.to_vec());
    files.insert("demo/cameras.json".into(), DEMO_CAMERAS.to_vec());
    let mut dataset = Dataset::read(&files, &DatasetPaths::folder("demo"))?;
    let recon = read_reconstruction(
        "sparse",
        &sfmeval::files::read_input_files(&files, "demo/sparse")?,
    )?;
    let bars = Bars::new(false);
    let evaluation = pipeline::run(&mut dataset, &recon, &EvalRequest::default(), &bars)?;
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
