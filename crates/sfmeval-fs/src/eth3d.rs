//! ETH3D's multi-view evaluation ([`sfmeval_eth3d`]) of files on disk: the scene's MeshLab
//! project with its scan PLYs beside it, and a reconstruction PLY, so that the CLI's
//! `sfmeval eth3d`, the Python package's `sfmeval.eth3d` and the runner give the same report and
//! coloured clouds byte for byte.

use std::path::Path;

use anyhow::{Context as _, Result, bail};
use sfmeval_eth3d::{self as eth3d, Eth3dEvaluation, Eth3dOptions, Eth3dReport, Eth3dScene};

use crate::disk::read;

/// The scene of the MeshLab project `mlp` (`dslr_scan_eval/scan_alignment.mlp`) with the scan
/// PLYs it names; errors name the project or the scan.
pub fn read_eth3d_scene(mlp: &Path) -> Result<Eth3dScene> {
    let gt_name = mlp.display().to_string();
    let project = read(mlp)?;
    let entries = eth3d::mlp::read_mlp(&project)
        .map_err(|e| e.in_file("ground-truth project", gt_name.as_str()))?;
    // The scans' bytes live here while the scene is read.
    let mut files: Vec<(String, Vec<u8>)> = Vec::with_capacity(entries.len());
    for entry in &entries {
        let path = eth3d::mlp::scan_path(mlp, &entry.filename);
        let bytes = read(&path).with_context(|| {
            format!(
                "scan '{}' of the ground-truth project '{gt_name}'",
                entry.filename
            )
        })?;
        files.push((path.display().to_string(), bytes));
    }
    let mut next = files.iter();
    Ok(Eth3dScene::read(
        eth3d::NamedBytes {
            name: &gt_name,
            bytes: &project,
        },
        |_| {
            next.next()
                .map(|(name, bytes)| eth3d::NamedBytes { name, bytes })
                .ok_or_else(|| sfmeval::Error::InvalidContent("a scan is missing".into()))
        },
    )?)
}

/// One ETH3D evaluation's inputs: `sfmeval eth3d`'s flags.
#[derive(Debug, Clone, Copy)]
pub struct Eth3dRun<'a> {
    /// The scene's MeshLab project, its scan PLYs beside it (its path is its name in the report).
    pub gt: &'a Path,
    /// The reconstruction PLY, in the scene's frame and in metres (its path is its name).
    pub recon: &'a Path,
    /// The protocol's options.
    pub options: &'a Eth3dOptions,
}

/// What an ETH3D evaluation gives: the report, and what the coloured clouds are made from.
#[derive(Debug)]
pub struct Eth3dOutputs {
    /// The `sfmeval.eth3d/1` report.
    pub report: Eth3dReport,
    /// [`Eth3dReport::to_json`].
    pub json: String,
    evaluation: Eth3dEvaluation,
    recon: Vec<[f32; 3]>,
}

impl Eth3dOutputs {
    /// The tool's coloured clouds (`completeness.tolerance_T.ply`, `accuracy.tolerance_T.ply`)
    /// by file name, as `write` asks for them. Two writers take the tolerances in turn, each
    /// with its own copy of each kind's cloud, encoded once (15 bytes a point) and coloured
    /// again for each tolerance: one's write to disk overlaps the other's colouring and write.
    pub fn write_vis_files(&self, write: impl Fn(&str, &[u8]) -> Result<()> + Sync) -> Result<()> {
        let e = &self.evaluation;
        let writer = |first: usize| -> Result<()> {
            let mut completeness: Option<eth3d::vis::PclCloud> = None;
            let mut accuracy: Option<eth3d::vis::PclCloud> = None;
            for (t, &tolerance) in e.tolerances.iter().enumerate().skip(first).step_by(2) {
                let cloud =
                    completeness.get_or_insert_with(|| eth3d::vis::PclCloud::new(&e.scan_points));
                write(
                    &eth3d::vis::file_name("completeness", tolerance),
                    cloud.colour(eth3d::vis::completeness_colours(e, t)),
                )?;
                let cloud = accuracy.get_or_insert_with(|| eth3d::vis::PclCloud::new(&self.recon));
                write(
                    &eth3d::vis::file_name("accuracy", tolerance),
                    cloud.colour(eth3d::vis::accuracy_colours(e, t)),
                )?;
            }
            Ok(())
        };
        let (even, odd) = sfmeval::parallel::join(|| writer(0), || writer(1));
        even.and(odd)
    }
}

/// `sfmeval eth3d` on files: reads the scene and the reconstruction and evaluates.
pub fn run_eth3d(run: &Eth3dRun<'_>) -> Result<Eth3dOutputs> {
    let scene = read_eth3d_scene(run.gt)?;
    eth3d_on_scene(&scene, run)
}

/// `sfmeval eth3d` with the scene of `run.gt` already read ([`read_eth3d_scene`]): reads the
/// reconstruction and evaluates (a scene read once for many reconstructions).
pub fn eth3d_on_scene(scene: &Eth3dScene, run: &Eth3dRun<'_>) -> Result<Eth3dOutputs> {
    let gt_name = run.gt.display().to_string();
    let recon_name = run.recon.display().to_string();
    let recon = eth3d::scene::read_points_f32(&read(run.recon)?)
        .with_context(|| format!("reconstruction '{recon_name}'"))?;
    if recon.is_empty() {
        bail!("reconstruction '{recon_name}': the PLY has no vertices");
    }
    let evaluation = eth3d::evaluate(scene, &recon, run.options)?;
    let report = Eth3dReport::new(&evaluation, scene, &gt_name, &recon_name);
    let json = report.to_json();
    Ok(Eth3dOutputs {
        report,
        json,
        evaluation,
        recon,
    })
}
