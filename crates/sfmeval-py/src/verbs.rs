//! The CLI's other verbs for Python: `read` (what a file holds, as arrays), `cameras`
//! (`sfmeval cameras`), `tnt` (`sfmeval tnt`), `dtu` (`sfmeval dtu`), `eth3d` (`sfmeval eth3d`)
//! and `table` (`sfmeval table`), each reading its inputs as the CLI does (`dtu` and `eth3d`
//! through the same `sfmeval_fs::run_dtu` and `run_eth3d`) so that its JSON or text is the CLI's
//! byte for byte.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, anyhow};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use sfmeval::dataset::DatasetPaths;
use sfmeval::geometry::{GroundTruth, Positions};
use sfmeval::io::{LoadedCloud, ReadLimits};
use sfmeval::model;
use sfmeval::pipeline::{self, ReconInput};
use sfmeval::pose::{Protocol, ProtocolOptions};
use sfmeval::report::Report;
use sfmeval::transform::Similarity;
use sfmeval_dtu::{DtuMode, DtuOptions, Shuffle};
use sfmeval_eth3d::Eth3dOptions;
use sfmeval_fs::{
    Disk, DtuRun, Eth3dRun, cameras_on_files, name_of, named, path_str, pipeline_and_path,
    poses_on_files, read, read_transform, run_dtu, run_eth3d, write_atomic,
};
use sfmeval_table::{Row, failed_row, read_row_poses, report_row, summary_json, tables};
use sfmeval_tnt::{self as tnt, IcpCriteria, Registration, Scene, TntRequest};

use crate::{Failure, existing, hooks};

/// A file's contents for `sfmeval.read`.
enum Content {
    Mesh {
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
    },
    /// A cloud (`cameras` empty) or an SfM model's points with its cameras.json.
    Points {
        recon: Box<ReconInput>,
        cameras_json: Option<String>,
    },
}

/// What `read` found, with its name, format and notes.
struct Read {
    name: String,
    format: String,
    notes: String,
    content: Content,
}

/// Whether `path` is a geometry file (`.ply`, `.glb`, `.gltf`, `.obj`) rather than a model.
fn is_geometry(path: &Path) -> bool {
    path.is_file()
        && path.extension().is_some_and(|e| {
            ["ply", "glb", "gltf", "obj"]
                .iter()
                .any(|g| e.eq_ignore_ascii_case(g))
        })
}

/// Reads `path`: a geometry file as the ground-truth reader reads it (a mesh, or a cloud whose
/// camera-centre markers are removed as for `--recon`), anything else as `--recon` reads it.
fn read_path(path: &Path, limits: &ReadLimits) -> Result<Read, Failure> {
    let path = existing(path)?;
    let name = name_of(path);
    let recon = if is_geometry(path) {
        let dataset =
            sfmeval_fs::read_dataset(&DatasetPaths::ground_truth(path_str(path)?), limits)?;
        let loaded = dataset.loaded;
        match loaded.ground_truth {
            GroundTruth::Mesh(mesh) => {
                return Ok(Read {
                    name,
                    format: loaded.format.name().to_string(),
                    notes: serde_json::to_string(&loaded.notes)?,
                    content: Content::Mesh {
                        vertices: mesh.vertices,
                        triangles: mesh.triangles,
                    },
                });
            }
            GroundTruth::Cloud(cloud) => pipeline::reconstruction_from_cloud(
                &name,
                LoadedCloud {
                    cloud,
                    format: loaded.format,
                    notes: loaded.notes,
                },
            ),
        }
    } else {
        sfmeval_fs::read_reconstruction(path, &name)?
    };
    let cameras_json = recon
        .model
        .as_ref()
        .map(|m| model::cameras_json::write_cameras_json(m, "reconstruction"));
    Ok(Read {
        name,
        format: recon.format.clone(),
        notes: serde_json::to_string(&recon.notes)?,
        content: Content::Points {
            recon: Box::new(recon),
            cameras_json,
        },
    })
}

fn bytes_of<T: Copy, const N: usize>(rows: &[[T; N]], to: impl Fn(T) -> Vec<u8>) -> Vec<u8> {
    rows.iter().flatten().flat_map(|v| to(*v)).collect()
}

/// `_read(path, max_triangles)`: a dict with `kind` (`mesh`, `cloud`, `model`), `name`,
/// `format`, `notes` (JSON), `points` (bytes, `dtype` `float32`/`float64`, as stored),
/// `triangles` (uint32 bytes, meshes), `colors` (uint8 bytes or `None`) and `cameras`
/// (cameras.json text, models).
#[pyfunction]
#[pyo3(signature = (path, max_triangles=ReadLimits::DEFAULT_MAX_TRIANGLES))]
pub(crate) fn _read<'py>(
    py: Python<'py>,
    path: PathBuf,
    max_triangles: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let limits = ReadLimits::triangles(max_triangles);
    let read = hooks::run(py, None, None, |_| read_path(&path, &limits))?;
    let out = PyDict::new(py);
    out.set_item("name", &read.name)?;
    out.set_item("format", &read.format)?;
    out.set_item("notes", &read.notes)?;
    match read.content {
        Content::Mesh {
            vertices,
            triangles,
        } => {
            out.set_item("kind", "mesh")?;
            out.set_item("dtype", "float64")?;
            out.set_item(
                "points",
                PyBytes::new(py, &bytes_of(&vertices, |v| v.to_ne_bytes().to_vec())),
            )?;
            out.set_item(
                "triangles",
                PyBytes::new(py, &bytes_of(&triangles, |v| v.to_ne_bytes().to_vec())),
            )?;
            out.set_item("colors", py.None())?;
            out.set_item("cameras", py.None())?;
        }
        Content::Points {
            recon,
            cameras_json,
        } => {
            out.set_item(
                "kind",
                if recon.model.is_some() {
                    "model"
                } else {
                    "cloud"
                },
            )?;
            let (dtype, bytes) = match &recon.cloud.points {
                Positions::F64(p) => ("float64", bytes_of(p, |v| v.to_ne_bytes().to_vec())),
                Positions::F32(p) => ("float32", bytes_of(p, |v| v.to_ne_bytes().to_vec())),
            };
            out.set_item("dtype", dtype)?;
            out.set_item("points", PyBytes::new(py, &bytes))?;
            out.set_item("triangles", py.None())?;
            match &recon.cloud.colors {
                Some(c) => out.set_item("colors", PyBytes::new(py, &bytes_of(c, |v| vec![v])))?,
                None => out.set_item("colors", py.None())?,
            }
            out.set_item("cameras", cameras_json)?;
        }
    }
    Ok(out)
}

/// `sfmeval cameras --gt-cameras G --recon R [--transform T] --report OUT`: the file's text.
fn cameras_of(
    gt_cameras: &Path,
    recon: &Path,
    transform_path: Option<&Path>,
    transform_json: Option<&str>,
) -> Result<String, Failure> {
    let (gt_cameras, recon) = (existing(gt_cameras)?, existing(recon)?);
    let given = match (transform_path, transform_json) {
        (Some(p), _) => Some(read_transform(existing(p)?)?),
        (None, Some(text)) => Some(Similarity::parse(text.as_bytes()).context("transform")?),
        (None, None) => None,
    };
    Ok(cameras_on_files(gt_cameras, recon, given)?.to_json()?)
}

/// `_cameras(gt_cameras, recon, transform_path=None, transform_json=None)`: the JSON
/// `sfmeval cameras --report` writes.
#[pyfunction]
#[pyo3(signature = (gt_cameras, recon, transform_path=None, transform_json=None))]
pub(crate) fn _cameras(
    py: Python<'_>,
    gt_cameras: PathBuf,
    recon: PathBuf,
    transform_path: Option<PathBuf>,
    transform_json: Option<String>,
) -> PyResult<String> {
    hooks::run(py, None, None, |_| {
        cameras_of(
            &gt_cameras,
            &recon,
            transform_path.as_deref(),
            transform_json.as_deref(),
        )
    })
}

/// `sfmeval poses --gt-cameras G --recon R --protocol P [--position-accuracy D] --report OUT`:
/// the file's text.
fn poses_of(
    gt_cameras: &Path,
    recon: &Path,
    protocol: &str,
    position_accuracy: f64,
) -> Result<String, Failure> {
    let protocol = Protocol::parse(protocol)?;
    let options = ProtocolOptions {
        colmap_position_accuracy: position_accuracy,
        ..ProtocolOptions::default()
    };
    let (_, poses) = poses_on_files(existing(gt_cameras)?, existing(recon)?, protocol, &options)?;
    Ok(poses.to_json())
}

/// `_poses(gt_cameras, recon, protocol, position_accuracy=0.0)`: the JSON `sfmeval poses
/// --report` writes.
#[pyfunction]
#[pyo3(signature = (gt_cameras, recon, protocol, position_accuracy=0.0))]
pub(crate) fn _poses(
    py: Python<'_>,
    gt_cameras: PathBuf,
    recon: PathBuf,
    protocol: String,
    position_accuracy: f64,
) -> PyResult<String> {
    hooks::run(py, None, None, |_| {
        poses_of(&gt_cameras, &recon, &protocol, position_accuracy)
    })
}

/// `sfmeval tnt`'s inputs.
struct TntInputs {
    scene: PathBuf,
    scene_name: Option<String>,
    recon: PathBuf,
    trajectory: Option<PathBuf>,
    transform_path: Option<PathBuf>,
    transform_text: Option<String>,
    tau: Option<f64>,
    seed: u64,
    out: Option<PathBuf>,
}

/// `sfmeval tnt` on the same inputs: its `report.json`, and its output files in `out` when
/// given.
fn tnt_of(t: &TntInputs, progress: &dyn sfmeval::progress::Progress) -> Result<String, Failure> {
    let scene_dir = existing(&t.scene)?;
    let recon_path = existing(&t.recon)?;
    let scene = Scene::read(&Disk, path_str(scene_dir)?, t.scene_name.as_deref())?;
    let recon = sfmeval_fs::read_reconstruction(recon_path, &name_of(recon_path))?;
    let registration = match (&t.transform_path, &t.transform_text, &t.trajectory) {
        (Some(p), _, _) => Registration::Given(
            tnt::matrix::parse(&read(existing(p)?)?, "transform")
                .with_context(|| format!("transform '{}'", p.display()))?,
        ),
        (None, Some(text), _) => Registration::Given(
            tnt::matrix::parse(text.as_bytes(), "transform").context("transform")?,
        ),
        (None, None, Some(log)) => Registration::Protocol {
            trajectory: tnt::read_log(&read(existing(log)?)?)
                .with_context(|| format!("trajectory '{}'", log.display()))?,
            trajectory_name: name_of(log),
            options: tnt::TrajectoryAlignmentOptions {
                seed: t.seed,
                ..Default::default()
            },
        },
        (None, None, None) => Err(anyhow!(
            "give trajectory= (a .log), or transform= to skip the registration"
        ))?,
    };
    let request = TntRequest {
        tau: t.tau,
        registration,
        icp: IcpCriteria::TOOLBOX,
    };
    let mut evaluation = tnt::evaluate(
        &scene,
        &name_of(recon_path),
        &recon.cloud.points.as_f64(),
        &request,
        progress,
    )?;
    evaluation.report.notes.splice(0..0, recon.notes);
    let json = evaluation.report_json();
    if let Some(out) = &t.out {
        std::fs::create_dir_all(out)
            .with_context(|| format!("cannot create '{}'", out.display()))?;
        write_atomic(&out.join("report.json"), json.as_bytes())?;
        for (name, bytes) in evaluation.output_files() {
            write_atomic(&out.join(name), &bytes)?;
        }
    }
    Ok(json)
}

/// `_tnt(scene, recon, ...)`: the `report.json` of `sfmeval tnt` on the same inputs (written
/// with the other output files into `out` when given).
#[pyfunction]
#[pyo3(signature = (scene, recon, *, scene_name=None, trajectory=None, transform_path=None,
    transform_text=None, tau=None, seed=0, out=None, threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _tnt(
    py: Python<'_>,
    scene: PathBuf,
    recon: PathBuf,
    scene_name: Option<String>,
    trajectory: Option<PathBuf>,
    transform_path: Option<PathBuf>,
    transform_text: Option<String>,
    tau: Option<f64>,
    seed: u64,
    out: Option<PathBuf>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let inputs = TntInputs {
        scene,
        scene_name,
        recon,
        trajectory,
        transform_path,
        transform_text,
        tau,
        seed,
        out,
    };
    hooks::run(py, threads, progress, |p| tnt_of(&inputs, p))
}

fn read_report(path: &Path) -> Result<Report, Failure> {
    let text = read(existing(path)?)?;
    let text = std::str::from_utf8(&text)
        .with_context(|| format!("report '{}' is not UTF-8 text", path.display()))?;
    Ok(serde_json::from_str(text).with_context(|| {
        format!(
            "'{}' is not an sfmeval.report/3 (sfmeval eval --report) file",
            path.display()
        )
    })?)
}

/// The rows of `sfmeval table REPORT... [--dataset D] [--failed P=R...]`.
fn table_rows(
    reports: &[String],
    dataset: Option<&str>,
    failed: &[String],
) -> Result<Vec<Row>, Failure> {
    let mut read = Vec::new();
    for arg in reports {
        let (pipeline, path) = pipeline_and_path(arg)?;
        let report = read_report(&path)?;
        read.push((pipeline, path, report));
    }
    let dataset = match (dataset, read.first()) {
        (Some(d), _) => d.to_string(),
        (None, Some((_, _, r))) => {
            let name = &r.inputs.ground_truth.name;
            Path::new(name)
                .file_stem()
                .map_or_else(|| name.clone(), |s| s.to_string_lossy().into_owned())
        }
        (None, None) => Err(anyhow!("no report given"))?,
    };
    let mut rows = Vec::new();
    for (pipeline, path, report) in &read {
        let file = path_str(path)?;
        let mut row = report_row(&dataset, pipeline, report, file);
        // the pose protocols' reports beside it (sfmeval poses --json), when there
        row.poses = read_row_poses(&Disk, file)?;
        rows.push(row);
    }
    for f in failed {
        let Some((pipeline, reason)) = named(f) else {
            Err(anyhow!("failed '{f}': expected PIPELINE=REASON"))?
        };
        rows.push(failed_row(&dataset, pipeline, "failed", reason));
    }
    let mut seen = std::collections::BTreeSet::new();
    for r in &rows {
        if !seen.insert(r.pipeline.as_str()) {
            Err(anyhow!(
                "pipeline '{}' is given twice: name each report PIPELINE=REPORT",
                r.pipeline
            ))?;
        }
    }
    Ok(rows)
}

/// `_table(reports, dataset=None, failed=[])`: the texts `sfmeval table` prints and writes
/// (`table1.md`, `table1.csv`, `table.md`, `runs.csv`, `summary.json`) as a dict by file name.
#[pyfunction]
#[pyo3(signature = (reports, dataset=None, failed=Vec::new()))]
pub(crate) fn _table<'py>(
    py: Python<'py>,
    reports: Vec<String>,
    dataset: Option<String>,
    failed: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let texts = hooks::run(py, None, None, |_| {
        let rows = table_rows(&reports, dataset.as_deref(), &failed)?;
        let t = tables(&rows);
        Ok([
            ("table1.md", t.table1_md),
            ("table1.csv", t.table1_csv),
            ("table.md", t.table_md),
            ("runs.csv", t.runs_csv),
            ("summary.json", summary_json(&rows)?),
        ])
    })?;
    let out = PyDict::new(py);
    for (name, text) in texts {
        out.set_item(name, text)?;
    }
    Ok(out)
}

/// `sfmeval dtu`'s inputs.
pub(crate) struct DtuInputs {
    dataset: PathBuf,
    scan: u32,
    recon: PathBuf,
    mode: DtuMode,
    options: DtuOptions,
    vis_out: Option<PathBuf>,
    report: Option<PathBuf>,
}

/// `sfmeval dtu` on the same inputs: its report JSON, written to `report` and with the error
/// clouds into `vis_out` when given, as the CLI writes them.
fn dtu_of(d: &DtuInputs, progress: &dyn sfmeval::progress::Progress) -> Result<String, Failure> {
    let run = DtuRun {
        dataset: existing(&d.dataset)?,
        scan: d.scan,
        recon: existing(&d.recon)?,
        mode: d.mode,
        options: d.options,
    };
    let outputs = run_dtu(&run, progress)?;
    if let Some(path) = &d.report {
        write_atomic(path, outputs.json.as_bytes())?;
    }
    if let Some(dir) = &d.vis_out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create '{}'", dir.display()))?;
        for (name, bytes) in outputs.vis_files() {
            write_atomic(&dir.join(name), &bytes)?;
        }
    }
    Ok(outputs.json)
}

/// `_dtu(dataset, scan, recon, ...)`: the report `sfmeval dtu --json` prints (written to
/// `report`, and the error clouds into `vis_out`, when given). An option left `None` is the
/// CLI's default; `shuffle=False` is `--no-shuffle`.
#[pyfunction]
#[pyo3(signature = (dataset, scan, recon, *, mode="auto", downsample_density=None,
    patch_size=None, max_dist=None, visualize_threshold=None, seed=0, shuffle=true, vis_out=None,
    report=None, threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _dtu(
    py: Python<'_>,
    dataset: PathBuf,
    scan: u32,
    recon: PathBuf,
    mode: &str,
    downsample_density: Option<f64>,
    patch_size: Option<f64>,
    max_dist: Option<f64>,
    visualize_threshold: Option<f64>,
    seed: u64,
    shuffle: bool,
    vis_out: Option<PathBuf>,
    report: Option<PathBuf>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let mode: DtuMode = mode.parse().map_err(|e: sfmeval::Error| Failure::from(e))?;
    let inputs = DtuInputs {
        dataset,
        scan,
        recon,
        mode,
        options: DtuOptions {
            downsample_density: downsample_density.unwrap_or(sfmeval_dtu::DOWNSAMPLE_DENSITY),
            patch_size: patch_size.unwrap_or(sfmeval_dtu::PATCH_SIZE),
            max_dist: max_dist.unwrap_or(sfmeval_dtu::MAX_DIST),
            visualize_threshold: visualize_threshold.unwrap_or(sfmeval_dtu::VISUALIZE_THRESHOLD),
            shuffle: if shuffle {
                Shuffle::Seeded(seed)
            } else {
                Shuffle::None
            },
        },
        vis_out,
        report,
    };
    hooks::run(py, threads, progress, |p| dtu_of(&inputs, p))
}

/// `sfmeval eth3d`'s inputs.
struct Eth3dInputs {
    gt: PathBuf,
    recon: PathBuf,
    options: Eth3dOptions,
    out: Option<PathBuf>,
}

/// `sfmeval eth3d` on the same inputs: its report JSON, written with the coloured clouds into
/// `out` when given, as the CLI writes them.
fn eth3d_of(e: &Eth3dInputs) -> Result<String, Failure> {
    let outputs = run_eth3d(&Eth3dRun {
        gt: existing(&e.gt)?,
        recon: existing(&e.recon)?,
        options: &e.options,
    })?;
    if let Some(dir) = &e.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create '{}'", dir.display()))?;
        write_atomic(&dir.join("eth3d.json"), outputs.json.as_bytes())?;
        outputs.write_vis_files(|name, bytes| write_atomic(&dir.join(name), bytes))?;
    }
    Ok(outputs.json)
}

/// `_eth3d(gt, recon, ...)`: the report `sfmeval eth3d --json` prints (written with the
/// coloured clouds into `out` when given). An option left `None` is the CLI's default; the
/// tolerances are the CLI's, each parsed as a double and rounded to `float` as the tool does.
#[pyfunction]
#[pyo3(signature = (gt, recon, *, tolerances=None, voxel_size=None, beam_start_radius=None,
    beam_divergence_halfangle_deg=None, out=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _eth3d(
    py: Python<'_>,
    gt: PathBuf,
    recon: PathBuf,
    tolerances: Option<Vec<f64>>,
    voxel_size: Option<f64>,
    beam_start_radius: Option<f64>,
    beam_divergence_halfangle_deg: Option<f64>,
    out: Option<PathBuf>,
    threads: Option<usize>,
) -> PyResult<String> {
    let defaults = Eth3dOptions::default();
    let inputs = Eth3dInputs {
        gt,
        recon,
        options: Eth3dOptions {
            tolerances: tolerances.map_or(defaults.tolerances, |t| {
                t.into_iter().map(|v| v as f32).collect()
            }),
            voxel_size: voxel_size.map_or(defaults.voxel_size, |v| v as f32),
            beam_start_radius: beam_start_radius.map_or(defaults.beam_start_radius, |v| v as f32),
            beam_divergence_halfangle_deg: beam_divergence_halfangle_deg
                .map_or(defaults.beam_divergence_halfangle_deg, |v| v as f32),
        },
        out,
    };
    hooks::run(py, threads, None, |_| eth3d_of(&inputs))
}
