//! `sfmeval eth3d`: ETH3D's multi-view evaluation of a reconstruction on a scene's laser scans,
//! as the benchmark's official tool (ETH3DMultiViewEvaluation) computes it.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use clap::Args;
use sfmeval_eth3d::{self as eth3d, Eth3dOptions, Eth3dReport, Eth3dScene, NamedBytes};
use sfmeval_fs::{read, write_atomic};

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
    let gt_name = args.gt.display().to_string();
    let mlp = read(&args.gt)?;
    // The scans' bytes live here while the scene is read.
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    let mut read_error = None;
    let scene = {
        let entries = eth3d::mlp::read_mlp(&mlp)
            .map_err(|e| e.in_file("ground-truth project", gt_name.as_str()))?;
        for entry in &entries {
            let path = eth3d::mlp::scan_path(&args.gt, &entry.filename);
            match read(&path) {
                Ok(b) => files.push((path.display().to_string(), b)),
                Err(e) => {
                    read_error = Some(e.context(format!(
                        "scan '{}' of the ground-truth project '{gt_name}'",
                        entry.filename
                    )));
                    break;
                }
            }
        }
        if let Some(e) = read_error {
            return Err(e);
        }
        let mut next = files.iter();
        Eth3dScene::read(
            NamedBytes {
                name: &gt_name,
                bytes: &mlp,
            },
            |_| {
                next.next()
                    .map(|(name, bytes)| NamedBytes { name, bytes })
                    .ok_or_else(|| sfmeval::Error::InvalidContent("a scan is missing".into()))
            },
        )?
    };
    drop(files);
    let recon_name = args.recon.display().to_string();
    let recon = eth3d::scene::read_points_f32(&read(&args.recon)?)
        .with_context(|| format!("reconstruction '{recon_name}'"))?;
    if recon.is_empty() {
        bail!("reconstruction '{recon_name}': the PLY has no vertices");
    }
    let evaluation = eth3d::evaluate(&scene, &recon, &options)?;
    let report = Eth3dReport::new(&evaluation, &scene, &gt_name, &recon_name);
    let json = report.to_json();
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create '{}'", dir.display()))?;
        write_atomic(&dir.join("eth3d.json"), json.as_bytes())?;
        // One cloud in memory at a time (each is 15 bytes a point).
        for (t, &tolerance) in evaluation.tolerances.iter().enumerate() {
            let name = eth3d::vis::file_name("completeness", tolerance);
            write_atomic(
                &dir.join(name),
                &eth3d::vis::completeness_ply(&evaluation, t),
            )?;
            let name = eth3d::vis::file_name("accuracy", tolerance);
            write_atomic(
                &dir.join(name),
                &eth3d::vis::accuracy_ply(&evaluation, &recon, t),
            )?;
        }
    }
    if args.json {
        print!("{json}");
    } else {
        print!("{}", summary(&report, args.out.as_deref()));
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
