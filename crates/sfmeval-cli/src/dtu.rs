//! `sfmeval dtu`: the DTU MVS evaluation of a reconstruction on a scan, as the benchmark's
//! Python port (DTUeval-python) computes it.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use clap::{Args, ValueEnum};
use sfmeval_dtu::{self as dtu, DtuOptions, DtuReport, DtuScan, NamedBytes, ReconMode, Shuffle};
use sfmeval_fs::{read, write_atomic};

/// How the reconstruction is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DtuMode {
    /// A mesh when the PLY has faces, points otherwise.
    Auto,
    /// A mesh, sampled as the evaluator samples it (its vertices and a grid in each triangle).
    Mesh,
    /// The PLY's vertices as points (faces ignored).
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
    /// The reconstruction, in the scan's frame and in mm: a PLY point cloud or mesh.
    #[arg(long, value_name = "FILE")]
    recon: PathBuf,
    /// Whether the reconstruction is a mesh to sample or points.
    #[arg(long, value_enum, default_value_t = DtuMode::Auto)]
    mode: DtuMode,
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
    let files = [
        dtu::scan::stl_path(args.scan),
        dtu::scan::obs_mask_path(args.scan),
        dtu::scan::plane_path(args.scan),
    ]
    .map(|rel| args.dataset.join(rel));
    let [stl, obs, plane] = files.each_ref().map(|p| p.display().to_string());
    let bytes = files
        .iter()
        .map(|p| read(p))
        .collect::<Result<Vec<Vec<u8>>>>()?;
    let scan = DtuScan::read(
        NamedBytes {
            name: &stl,
            bytes: &bytes[0],
        },
        NamedBytes {
            name: &obs,
            bytes: &bytes[1],
        },
        NamedBytes {
            name: &plane,
            bytes: &bytes[2],
        },
    )?;
    drop(bytes);
    let recon_name = args.recon.display().to_string();
    let mode = match args.mode {
        DtuMode::Auto => ReconMode::Auto,
        DtuMode::Mesh => ReconMode::Mesh,
        DtuMode::Pcd => ReconMode::Pcd,
    };
    let (input, mesh) = dtu::read_reconstruction(&read(&args.recon)?, mode)
        .with_context(|| format!("reconstruction '{recon_name}'"))?;
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
    let evaluation = dtu::evaluate(&scan, input, &options)
        .with_context(|| format!("reconstruction '{recon_name}'"))?;
    let report = DtuReport::new(&evaluation, args.scan, &recon_name, mesh);
    let json = report.to_json();
    if let Some(path) = &args.report {
        write_atomic(path, json.as_bytes())?;
    }
    if let Some(dir) = &args.vis_out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create '{}'", dir.display()))?;
        let (d2s, s2d) = dtu::vis::vis_names(args.scan);
        write_atomic(&dir.join(d2s), &dtu::vis::d2s_ply(&evaluation))?;
        write_atomic(&dir.join(s2d), &dtu::vis::s2d_ply(&evaluation, &scan.stl))?;
    }
    if args.json {
        print!("{json}");
    } else {
        print!("{}", summary(&report, args.vis_out.as_deref()));
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
