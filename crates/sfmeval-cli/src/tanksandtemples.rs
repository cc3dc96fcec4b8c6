//! `sfmeval tnt` (the Tanks and Temples protocol on a scene folder) and `sfmeval log` (a
//! model's cameras as the benchmark's `.log` trajectory).

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use clap::Args;
use sfmeval_fs::{Disk, image_names, name_of, path_str, read, read_input_files, write_atomic};
use sfmeval_tnt::{
    self as tnt, IcpCriteria, Registration, Scene, TntRequest, TrajectoryAlignmentOptions,
};

use crate::concurrent::side_by_side;
use crate::progress::Bars;

/// `sfmeval tnt`'s flags.
#[derive(Args, Debug)]
pub struct TntArgs {
    /// The scene folder as the benchmark ships it: SCENE.ply, SCENE.json (crop),
    /// SCENE_trans.txt, SCENE_COLMAP_SfM.log and, for video trajectories,
    /// SCENE_mapping_reference.txt. The folder's name is the scene's.
    #[arg(long, value_name = "DIR")]
    scene: PathBuf,
    /// The files' stem when it is not the folder's name.
    #[arg(long, value_name = "NAME")]
    scene_name: Option<String>,
    /// The reconstruction: a PLY point cloud (usually the dense one), or any SfM model sfmeval
    /// reads (COLMAP folder, .nvm, Bundler .out, sfm_data.json), whose points are measured.
    #[arg(long, value_name = "PATH")]
    recon: PathBuf,
    /// The reconstruction's camera trajectory (.log, one frame per input image; `sfmeval log`
    /// writes it from an SfM model).
    #[arg(long, value_name = "FILE", required_unless_present = "transform")]
    trajectory: Option<PathBuf>,
    /// Skip the registration: use this gt_from_recon (16 numbers, row-major 4×4).
    #[arg(long, value_name = "FILE", conflicts_with = "trajectory")]
    transform: Option<PathBuf>,
    /// τ in ground-truth units (default: the scene's, from the benchmark's table).
    #[arg(long, value_name = "T")]
    tau: Option<f64>,
    /// Seed of the trajectory alignment's RANSAC.
    #[arg(long, value_name = "S", default_value_t = 0)]
    seed: u64,
    /// Output folder for report.json, SCENE.precision.ply / .recall.ply (coloured by
    /// distance) and the toolbox's .precision.txt, .recall.txt and .prf_tau_plotstr.txt
    /// (default: an `evaluation` folder beside the reconstruction, as the toolbox does).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Print the report JSON instead of the summary.
    #[arg(long)]
    json: bool,
    /// No progress bars, no summary.
    #[arg(long)]
    quiet: bool,
}

/// `sfmeval log`'s flags.
#[derive(Args, Debug)]
pub struct LogArgs {
    /// The SfM model: a COLMAP folder, .nvm, Bundler .out, OpenMVG sfm_data.json, cameras.json.
    #[arg(long, value_name = "PATH")]
    model: PathBuf,
    /// The input images: their folder (one frame per image file in it, sorted by name, as the
    /// benchmark's converter lists them) or a text file of image names, one per line, in frame
    /// order.
    #[arg(long, value_name = "DIR|FILE")]
    images: PathBuf,
    /// Where to write the .log.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

/// Runs `sfmeval tnt`.
pub fn tnt_cmd(args: &TntArgs) -> Result<()> {
    // The scene (its ground truth is the larger file) and the reconstruction are read at the
    // same time; the scene's error comes first when both fail.
    let (recon, scene) = side_by_side(
        || sfmeval_fs::read_reconstruction(&args.recon, &name_of(&args.recon)),
        || -> Result<Scene> {
            Ok(Scene::read(
                &Disk,
                path_str(&args.scene)?,
                args.scene_name.as_deref(),
            )?)
        },
    );
    let (scene, recon) = (scene?, recon?);
    let registration = match (&args.transform, &args.trajectory) {
        (Some(t), _) => Registration::Given(
            tnt::matrix::parse(&read(t)?, "transform")
                .with_context(|| format!("transform '{}'", t.display()))?,
        ),
        (None, Some(log)) => Registration::Protocol {
            trajectory: tnt::read_log(&read(log)?)
                .with_context(|| format!("trajectory '{}'", log.display()))?,
            trajectory_name: name_of(log),
            options: TrajectoryAlignmentOptions {
                seed: args.seed,
                ..Default::default()
            },
        },
        (None, None) => {
            bail!("give --trajectory FILE.log (or --transform FILE to skip the registration)")
        }
    };
    let request = TntRequest {
        tau: args.tau,
        registration,
        icp: IcpCriteria::TOOLBOX,
    };
    let bars = Bars::new(args.quiet || args.json);
    let evaluation = tnt::evaluate(
        &scene,
        &name_of(&args.recon),
        &recon.cloud.points.as_f64(),
        &request,
        &bars,
    )?;
    let out = match &args.out {
        Some(o) => o.clone(),
        None => args
            .recon
            .parent()
            .unwrap_or(Path::new("."))
            .join("evaluation"),
    };
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create '{}'", out.display()))?;
    let mut evaluation = evaluation;
    evaluation.report.notes.splice(0..0, recon.notes);
    let report = &evaluation.report;
    let json = evaluation.report_json();
    // The plot renders while the report, the clouds and the texts are encoded and written.
    let write_all = |files: Vec<(String, Vec<u8>)>| -> Result<()> {
        for (name, bytes) in files {
            write_atomic(&out.join(name), &bytes)?;
        }
        Ok(())
    };
    let (written, plots) = sfmeval::parallel::join(
        || {
            write_atomic(&out.join("report.json"), json.as_bytes())?;
            write_all(evaluation.data_files())
        },
        || evaluation.plot_files(),
    );
    written?;
    write_all(plots)?;
    if args.json {
        print!("{json}");
    } else if !args.quiet {
        print!("{}", summary(report, &out));
    }
    Ok(())
}

fn summary(r: &tnt::TntReport, out: &Path) -> String {
    format!("{}  written to {}\n", r.summary(), out.display())
}

/// Runs `sfmeval log`.
pub fn log_cmd(args: &LogArgs) -> Result<()> {
    let model = sfmeval::model::read_model_files(&read_input_files(&args.model)?)
        .with_context(|| format!("model '{}'", args.model.display()))?;
    let names = if args.images.is_dir() {
        image_names(&args.images)?
    } else {
        let text = String::from_utf8(read(&args.images)?)
            .with_context(|| format!("image list '{}' is not UTF-8 text", args.images.display()))?;
        text.lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .map(String::from)
            .collect()
    };
    if names.is_empty() {
        bail!("'{}' names no image", args.images.display());
    }
    let (frames, registered) = tnt::log_from_model(&model, &names);
    write_atomic(&args.out, tnt::write_log(&frames).as_bytes())?;
    println!(
        "{}: {} frames, {registered} registered, {} missing (identity)",
        args.out.display(),
        frames.len(),
        frames.len() - registered
    );
    Ok(())
}
