//! `sfmeval eth3d`: ETH3D's multi-view evaluation of a reconstruction on a scene's laser scans,
//! as the benchmark's official tool (ETH3DMultiViewEvaluation) computes it.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use clap::Args;
use sfmeval_eth3d::{self as eth3d, Eth3dOptions, Eth3dReport};
use sfmeval_fs::{Eth3dRun, run_eth3d, write_atomic};

/// `sfmeval eth3d`'s flags.
#[derive(Args, Debug)]
pub struct Eth3dArgs {
    /// The ground truth: the scene's MeshLab project (dslr_scan_eval/scan_alignment.mlp), its
    /// scan PLYs beside it.
    #[arg(long, value_name = "MLP")]
    gt: PathBuf,
    /// The reconstruction, in the scene's frame and in metres: a PLY (its vertices; faces are
    /// ignored, as the tool ignores them).
    #[arg(long, value_name = "PLY")]
    recon: PathBuf,
    /// Evaluation tolerances (m), comma-separated; the benchmark's list by default.
    #[arg(
        long,
        value_name = "T,T,...",
        default_value = "0.01,0.02,0.05,0.1,0.2,0.5"
    )]
    tolerances: String,
    /// Voxel size of the normalisation (m).
    #[arg(long, value_name = "M", default_value_t = eth3d::VOXEL_SIZE)]
    voxel_size: f32,
    /// Laser beam radius at the scanner (m).
    #[arg(long, value_name = "M", default_value_t = eth3d::BEAM_START_RADIUS)]
    beam_start_radius: f32,
    /// Laser beam divergence half-angle (degrees).
    #[arg(long, value_name = "DEG", default_value_t = eth3d::BEAM_DIVERGENCE_HALFANGLE_DEG)]
    beam_divergence_halfangle_deg: f32,
    /// Write the sfmeval.eth3d/1 report (eth3d.json) and the tool's coloured clouds
    /// (accuracy.tolerance_T.ply, completeness.tolerance_T.ply) here.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Print the report JSON instead of the summary.
    #[arg(long)]
    json: bool,
}

/// The tolerances as the tool parses them (`atof`, then rounded to `float`).
fn parse_tolerances(list: &str) -> Result<Vec<f32>> {
    let mut out = Vec::new();
    for w in list.split(',') {
        let v: f64 = w
            .trim()
            .parse()
            .with_context(|| format!("--tolerances: '{w}' is not a number"))?;
        out.push(v as f32);
    }
    Ok(out)
}

/// Runs `sfmeval eth3d`.
pub fn eth3d_cmd(args: &Eth3dArgs) -> Result<()> {
    let options = Eth3dOptions {
        tolerances: parse_tolerances(&args.tolerances)?,
        voxel_size: args.voxel_size,
        beam_start_radius: args.beam_start_radius,
        beam_divergence_halfangle_deg: args.beam_divergence_halfangle_deg,
    };
    let outputs = run_eth3d(&Eth3dRun {
        gt: &args.gt,
        recon: &args.recon,
        options: &options,
    })?;
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create '{}'", dir.display()))?;
        write_atomic(&dir.join("eth3d.json"), outputs.json.as_bytes())?;
        outputs.write_vis_files(|name, bytes| write_atomic(&dir.join(name), bytes))?;
    }
    let json = &outputs.json;
    let report = &outputs.report;
    if args.json {
        print!("{json}");
    } else {
        print!("{}", summary(report, args.out.as_deref()));
    }
    Ok(())
}

fn summary(r: &Eth3dReport, out: Option<&Path>) -> String {
    let mut s = r.summary();
    if let Some(dir) = out {
        s += &format!(
            "  report and coloured clouds written to {}\n",
            dir.display()
        );
    }
    s
}
