//! `sfmeval dtu`: the DTU MVS evaluation of a reconstruction on a scan, as the benchmark's
//! Python port (DTUeval-python) computes it.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use clap::{Args, ValueEnum};
use sfmeval_dtu::{self as dtu, DtuMode, DtuOptions, DtuReport, Shuffle};
use sfmeval_fs::{DtuRun, run_dtu, write_atomic};

use crate::progress::Bars;

/// How a reconstruction with faces is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DtuModeArg {
    /// A mesh when the reconstruction has faces, points otherwise.
    Auto,
    /// A mesh, sampled as the evaluator samples it (its vertices and a grid in each triangle).
    Mesh,
    /// The vertices or points only (faces ignored).
    Pcd,
}

/// `sfmeval dtu`'s flags.
#[derive(Args, Debug)]
pub struct DtuArgs {
    /// The ground-truth folder as the benchmark ships it: Points/stl/stlNNN_total.ply,
    /// ObsMask/ObsMaskN_10.mat and ObsMask/PlaneN.mat.
    #[arg(long, value_name = "DIR")]
    dataset: PathBuf,
    /// The scan number (24, 37, ...).
    #[arg(long, value_name = "N")]
    scan: u32,
    /// The reconstruction, in the scan's frame and in mm: a PLY point cloud or mesh, an OBJ or
    /// glTF mesh, or an SfM model (COLMAP, NVM, Bundler, OpenMVG, cameras.json) whose 3D points
    /// are evaluated, read as `sfmeval eval --recon` reads it.
    #[arg(long, value_name = "FILE")]
    recon: PathBuf,
    /// Whether the reconstruction is a mesh to sample or points.
    #[arg(long, value_enum, default_value_t = DtuModeArg::Auto)]
    mode: DtuModeArg,
    /// Down-sampling density (mm).
    #[arg(long, value_name = "MM", default_value_t = dtu::DOWNSAMPLE_DENSITY)]
    downsample_density: f64,
    /// The bounding box is widened by this much (mm; twice as much above).
    #[arg(long, value_name = "MM", default_value_t = dtu::PATCH_SIZE)]
    patch_size: f64,
    /// Distances from this on are left out of the means (mm).
    #[arg(long, value_name = "MM", default_value_t = dtu::MAX_DIST)]
    max_dist: f64,
    /// Distance at which the error clouds are fully red (mm).
    #[arg(long, value_name = "MM", default_value_t = dtu::VISUALIZE_THRESHOLD)]
    visualize_threshold: f64,
    /// Seed of the shuffle before down-sampling (the evaluator shuffles at random).
    #[arg(long, value_name = "S", default_value_t = 0)]
    seed: u64,
    /// Down-sample in the input's order (a mesh's vertices, then its samples) instead.
    #[arg(long, conflicts_with = "seed")]
    no_shuffle: bool,
    /// Write the evaluator's coloured error clouds vis_NNN_d2s.ply and vis_NNN_s2d.ply here.
    #[arg(long, value_name = "DIR")]
    vis_out: Option<PathBuf>,
    /// Write the sfmeval.dtu/1 report here.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
    /// Print the report JSON instead of the summary.
    #[arg(long)]
    json: bool,
}

/// Runs `sfmeval dtu`.
pub fn dtu_cmd(args: &DtuArgs) -> Result<()> {
    let options = DtuOptions {
        downsample_density: args.downsample_density,
        patch_size: args.patch_size,
        max_dist: args.max_dist,
        visualize_threshold: args.visualize_threshold,
        shuffle: if args.no_shuffle {
            Shuffle::None
        } else {
            Shuffle::Seeded(args.seed)
        },
    };
    let run = DtuRun {
        dataset: &args.dataset,
        scan: args.scan,
        recon: &args.recon,
        mode: match args.mode {
            DtuModeArg::Auto => DtuMode::Auto,
            DtuModeArg::Mesh => DtuMode::Mesh,
            DtuModeArg::Pcd => DtuMode::Pcd,
        },
        options,
    };
    let outputs = run_dtu(&run, &Bars::new(args.json))?;
    if let Some(path) = &args.report {
        write_atomic(path, outputs.json.as_bytes())?;
    }
    if let Some(dir) = &args.vis_out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create '{}'", dir.display()))?;
        for (name, bytes) in outputs.vis_files() {
            write_atomic(&dir.join(name), &bytes)?;
        }
    }
    if args.json {
        print!("{}", outputs.json);
    } else {
        print!("{}", summary(&outputs.report, args.vis_out.as_deref()));
    }
    Ok(())
}

fn summary(r: &DtuReport, vis: Option<&Path>) -> String {
    let mut s = r.summary();
    if let Some(dir) = vis {
        s += &format!("  error clouds written to {}\n", dir.display());
    }
    s
}
