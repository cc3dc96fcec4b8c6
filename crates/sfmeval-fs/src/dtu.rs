//! The DTU evaluation ([`sfmeval_dtu`]) of files on disk: the scan's files in the benchmark's
//! layout, and any reconstruction `sfmeval eval` reads (a PLY cloud or mesh, an OBJ or glTF
//! mesh, an SfM model's points), so that the CLI's `sfmeval dtu`, the Python package's
//! `sfmeval.dtu` and the runner give the same report and error clouds byte for byte.

use std::path::Path;

use anyhow::{Context as _, Result};
use sfmeval::dataset::DatasetPaths;
use sfmeval::geometry::{GroundTruth, Point3};
use sfmeval::io::{self, ReadLimits};
use sfmeval::progress::Progress;
use sfmeval_dtu::{
    self as dtu, DtuEvaluation, DtuInput, DtuMode, DtuOptions, DtuReport, DtuScan, NamedBytes,
};

use crate::disk::{path_str, read, read_dataset};
use crate::stream::read_reconstruction;

/// The scan `scan`'s files under `dataset` (`Points/stl/stlNNN_total.ply`,
/// `ObsMask/ObsMaskN_10.mat`, `ObsMask/PlaneN.mat`); errors name the file.
pub fn read_dtu_scan(dataset: &Path, scan: u32) -> Result<DtuScan> {
    let files = [
        dtu::scan::stl_path(scan),
        dtu::scan::obs_mask_path(scan),
        dtu::scan::plane_path(scan),
    ]
    .map(|rel| dataset.join(rel));
    let [stl, obs, plane] = files.each_ref().map(|p| p.display().to_string());
    let bytes = files.iter().map(|p| read(p)).collect::<Result<Vec<_>>>()?;
    Ok(DtuScan::read(
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
    )?)
}

/// A reconstruction as the DTU evaluation takes it.
#[derive(Debug, Clone, PartialEq)]
pub struct DtuRecon {
    /// Points, or a mesh to sample.
    pub input: DtuInput,
    /// Whether `input` is a mesh (the report's `mode`).
    pub mesh: bool,
}

/// Whether `path` is a geometry file (`.ply`, `.obj`, `.glb`, `.gltf`) rather than a model.
fn geometry_format(path: &Path) -> Option<&'static str> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    let format = ["ply", "obj", "glb", "gltf"]
        .into_iter()
        .find(|g| *g == ext)?;
    path.is_file().then_some(format)
}

/// The reconstruction at `path`, read as `sfmeval eval` reads it: a PLY's vertices (and faces),
/// an OBJ or glTF mesh (as the ground-truth reader reads it: the glTF's scene transforms
/// applied), or the 3D points of an SfM model (a COLMAP, NVM, Bundler, OpenMVG or cameras.json
/// folder or file). `mode` picks mesh or points for a file with faces. Errors name the path.
pub fn read_dtu_recon(path: &Path, mode: DtuMode) -> Result<DtuRecon> {
    let name = path.display().to_string();
    let context = || format!("reconstruction '{name}'");
    let (vertices, triangles) = match geometry_format(path) {
        Some("ply") => {
            let ply = io::ply::read_ply(&read(path)?).with_context(context)?;
            (ply.vertices.into_f64(), ply.triangles)
        }
        Some(_) => {
            let dataset = read_dataset(
                &DatasetPaths::ground_truth(path_str(path)?),
                &ReadLimits::default(),
            )
            .with_context(context)?;
            match dataset.loaded.ground_truth {
                GroundTruth::Mesh(m) => (m.vertices, m.triangles),
                GroundTruth::Cloud(c) => (c.points.into_f64(), Vec::new()),
            }
        }
        None => {
            let recon = read_reconstruction(path, &name)?;
            (recon.cloud.points.into_f64(), Vec::new())
        }
    };
    let what = match geometry_format(path) {
        Some(f) => format!("the {} file", f.to_ascii_uppercase()),
        None => "an SfM model's points".to_string(),
    };
    let (input, mesh) = mode
        .input(vertices, triangles, &what)
        .with_context(context)?;
    Ok(DtuRecon { input, mesh })
}

/// One DTU evaluation's inputs: `sfmeval dtu`'s flags.
#[derive(Debug, Clone, Copy)]
pub struct DtuRun<'a> {
    /// The ground-truth folder in the benchmark's layout.
    pub dataset: &'a Path,
    /// The scan number.
    pub scan: u32,
    /// The reconstruction (its path is its name in the report).
    pub recon: &'a Path,
    /// Mesh or points.
    pub mode: DtuMode,
    /// The protocol's options.
    pub options: DtuOptions,
}

/// What a DTU evaluation gives: the report, and what the error clouds are made from.
#[derive(Debug)]
pub struct DtuOutputs {
    /// The `sfmeval.dtu/1` report.
    pub report: DtuReport,
    /// [`DtuReport::to_json`].
    pub json: String,
    evaluation: DtuEvaluation,
    stl: Vec<Point3>,
}

impl DtuOutputs {
    /// The coloured error clouds (`vis_NNN_d2s.ply`, `vis_NNN_s2d.ply`) by file name.
    pub fn vis_files(&self) -> [(String, Vec<u8>); 2] {
        dtu::vis::output_files(&self.evaluation, self.report.scan, &self.stl)
    }
}

/// `sfmeval dtu` on files: reads the scan and the reconstruction and evaluates.
pub fn run_dtu(run: &DtuRun<'_>, progress: &dyn Progress) -> Result<DtuOutputs> {
    let scan = read_dtu_scan(run.dataset, run.scan)?;
    let recon_name = run.recon.display().to_string();
    let recon = read_dtu_recon(run.recon, run.mode)?;
    let evaluation = dtu::evaluate(&scan, recon.input, &run.options, progress)
        .with_context(|| format!("reconstruction '{recon_name}'"))?;
    let report = DtuReport::new(&evaluation, run.scan, &recon_name, recon.mesh);
    let json = report.to_json();
    Ok(DtuOutputs {
        report,
        json,
        evaluation,
        stl: scan.stl,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometry_files_are_told_from_models_by_extension() {
        let dir = std::env::temp_dir().join(format!("sfmeval-fs-dtu-{}", std::process::id()));
        std::fs::create_dir_all(&dir).ok();
        let obj = dir.join("m.OBJ");
        std::fs::write(&obj, b"v 0 0 0\n").ok();
        assert_eq!(geometry_format(&obj), Some("obj"));
        assert_eq!(geometry_format(&dir), None);
        assert_eq!(geometry_format(&dir.join("missing.ply")), None);
        std::fs::remove_dir_all(&dir).ok();
    }
}
