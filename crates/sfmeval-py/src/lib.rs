//! # sfmeval-py
//!
//! Thin PyO3 bindings over the sfmeval core for the Python package `sfmeval` (built by maturin,
//! `scripts/build-wheel.sh`). Paths go in and are read by `sfmeval-fs` exactly as the `sfmeval`
//! CLI reads them, arrays go in as the PLY file of the same numbers would be read; the request
//! is the core's [`EvalRequest`] and the evaluation is [`pipeline::run_owned`], so the report
//! JSON handed back is the CLI's `--report` file byte for byte. `read`, `align`, `cameras`,
//! `tnt`, `dtu` and `table` (`verbs.rs`) are the CLI's verbs of those names on the same
//! crates. The Python side (`python/sfmeval/__init__.py`) only wraps that JSON for attribute
//! access and the per-point arrays in numpy; it computes nothing.

mod arrays;
mod hooks;
mod verbs;

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use sfmeval::align::{AlignMode, AlignRequest, PointPair};
use sfmeval::crop::Crop;
use sfmeval::dataset::{Dataset, DatasetPaths, Part};
use sfmeval::evaluate::{EvalOptions, PointStatus};
use sfmeval::geometry::Positions;
use sfmeval::io::{self, ReadLimits, ply::PlyData};
use sfmeval::model;
use sfmeval::pipeline::{self, EvalRequest, ReconInput};
use sfmeval::pose::PoseOptions;
use sfmeval::progress::Progress;
use sfmeval::transform::Similarity;
use sfmeval_fs::{
    name_of, path_str, read, read_input_files, read_point_pairs, read_reconstruction_with_cameras,
    read_transform,
};

create_exception!(
    sfmeval,
    InputError,
    PyValueError,
    "An input the core cannot use: the message names the file (or option) and what is wrong."
);

/// What a call failed on: a path that does not exist (Python's `FileNotFoundError`), or
/// anything else the readers or the core reject (`InputError`, the CLI's message).
pub(crate) enum Failure {
    Missing(PathBuf),
    Input(anyhow::Error),
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Self {
        Failure::Input(e)
    }
}

impl From<sfmeval::Error> for Failure {
    fn from(e: sfmeval::Error) -> Self {
        Failure::Input(e.into())
    }
}

impl From<serde_json::Error> for Failure {
    fn from(e: serde_json::Error) -> Self {
        Failure::Input(e.into())
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> PyErr {
        match f {
            Failure::Missing(p) => PyFileNotFoundError::new_err((
                2_i32,
                "No such file or directory".to_string(),
                p.display().to_string(),
            )),
            Failure::Input(e) => InputError::new_err(format!("{e:#}")),
        }
    }
}

/// Fails with `FileNotFoundError` when `path` names nothing.
pub(crate) fn existing(path: &Path) -> Result<&Path, Failure> {
    if path.exists() {
        Ok(path)
    } else {
        Err(Failure::Missing(path.to_path_buf()))
    }
}

/// The ground truth as given: a path (file or dataset folder), or geometry from arrays.
pub(crate) enum GtSource {
    Path(PathBuf),
    /// Vertices (or a cloud's points) and, for a mesh, triangles: read as the binary PLY of
    /// them, named `name` in the report.
    Arrays {
        vertices: Positions,
        triangles: Option<Vec<[u32; 3]>>,
        name: String,
    },
}

/// The reconstruction as given: a path, or an array of points.
pub(crate) enum ReconSource {
    Path(PathBuf),
    Points(Positions),
}

/// Everything `evaluate` and `align` take, as the Python wrapper normalised it.
pub(crate) struct Inputs {
    gt: GtSource,
    recon: ReconSource,
    name: Option<String>,
    gt_cameras: Option<PathBuf>,
    recon_cameras: Option<PathBuf>,
    align: Option<String>,
    transform_path: Option<PathBuf>,
    transform_json: Option<String>,
    pairs: Option<PathBuf>,
    crop_path: Option<PathBuf>,
    crop_json: Option<String>,
    max_distance: Option<f64>,
    tau: Vec<f64>,
    tau_percent: Vec<f64>,
    samples: usize,
    seed: u64,
    signed: bool,
    max_triangles: u64,
}

/// The crop as `sfmeval eval --crop FILE --max-distance D` builds it (the JSON of a crop given
/// from Python goes through the same parser).
fn crop_of(inputs: &Inputs) -> Result<Crop, Failure> {
    let mut crop = match (&inputs.crop_path, &inputs.crop_json) {
        (Some(path), _) => Crop::parse(&read(existing(path)?)?)
            .with_context(|| format!("crop file '{}'", path.display()))?,
        (None, Some(text)) => Crop::parse(text.as_bytes()).context("crop")?,
        (None, None) => Crop::default(),
    };
    if inputs.max_distance.is_some() {
        crop.max_distance = inputs.max_distance;
    }
    crop.validate().context("crop")?;
    Ok(crop)
}

/// The alignment request of `align`, `transform` and `pairs`, as the CLI's `--align`,
/// `--transform` and `--pairs` (the mode's default is the core's: `given` with a transform,
/// else `auto`).
fn align_of(inputs: &Inputs) -> Result<AlignRequest, Failure> {
    let transform = match (&inputs.transform_path, &inputs.transform_json) {
        (Some(path), _) => Some(read_transform(existing(path)?)?),
        (None, Some(text)) => Some(Similarity::parse(text.as_bytes()).context("transform")?),
        (None, None) => None,
    };
    let pairs: Vec<PointPair> = match &inputs.pairs {
        Some(p) => read_point_pairs(existing(p)?)?,
        None => Vec::new(),
    };
    let mode = inputs
        .align
        .as_deref()
        .map(AlignMode::parse)
        .transpose()
        .context("align")?;
    Ok(AlignRequest::new(mode, transform, pairs).context("align")?)
}

/// The ground truth: a folder is a dataset (`ground_truth.glb`, `cameras.json` and `depth/`
/// when present, as `--dataset`; no depth maps for `align`, as the CLI's), a file the geometry
/// alone, arrays the PLY of them; `gt_cameras` overrides (as `--gt-cameras`).
fn read_ground_truth(inputs: &mut Inputs, with_depth: bool) -> Result<Dataset, Failure> {
    let limits = ReadLimits::triangles(inputs.max_triangles);
    let cameras = match &inputs.gt_cameras {
        Some(c) => Some(path_str(existing(c)?)?.to_string()),
        None => None,
    };
    let source = std::mem::replace(&mut inputs.gt, GtSource::Path(PathBuf::new()));
    match source {
        GtSource::Path(gt) => {
            let gt = existing(&gt)?;
            let mut paths = if gt.is_dir() {
                DatasetPaths::folder(path_str(gt)?)
            } else {
                DatasetPaths::ground_truth(path_str(gt)?)
            };
            if let Some(c) = cameras {
                paths.cameras = Part::Required(c);
            }
            if !with_depth {
                paths.depth = Part::Off;
            }
            Ok(sfmeval_fs::read_dataset(&paths, &limits)?)
        }
        GtSource::Arrays {
            vertices,
            triangles,
            name,
        } => {
            let what = || format!("ground truth '{name}' (arrays)");
            let loaded = PlyData::from_memory(vertices, triangles)
                .and_then(io::ground_truth_from_ply)
                .map_err(anyhow::Error::new)
                .with_context(what)?;
            let mut dataset = Dataset::new(&name, loaded);
            if let Some(c) = cameras {
                let model = model::read_model_files(&read_input_files(Path::new(&c))?)
                    .map_err(|e| e.in_file("ground-truth cameras", c.clone()))?;
                dataset.set_cameras(Some(model));
            }
            Ok(dataset)
        }
    }
}

/// The reconstruction, read as `sfmeval eval --recon [--recon-cameras]` reads it; an array is
/// read as the binary PLY of its points (`float` or `double` as its dtype) would be.
fn read_recon(inputs: &mut Inputs) -> Result<ReconInput, Failure> {
    let source = std::mem::replace(&mut inputs.recon, ReconSource::Path(PathBuf::new()));
    match source {
        ReconSource::Points(_) if inputs.recon_cameras.is_some() => {
            Err(Failure::Input(anyhow::anyhow!(
                "recon_cameras: the cameras go with a PLY file given as recon, not with an array"
            )))
        }
        ReconSource::Points(points) => {
            let name = inputs
                .name
                .clone()
                .unwrap_or_else(|| "points.ply".to_string());
            let loaded = PlyData::from_memory(points, None)
                .and_then(|p| io::point_cloud_from_ply(&name, p))
                .map_err(anyhow::Error::new)
                .with_context(|| format!("reconstruction '{name}' (an array of points)"))?;
            Ok(pipeline::reconstruction_from_cloud(&name, loaded))
        }
        ReconSource::Path(recon) => {
            let recon = existing(&recon)?;
            let name = inputs.name.clone().unwrap_or_else(|| name_of(recon));
            let cameras_path = inputs.recon_cameras.as_deref().map(existing).transpose()?;
            Ok(read_reconstruction_with_cameras(
                recon,
                cameras_path,
                &name,
            )?)
        }
    }
}

/// What the CLI's errors of an evaluation name: the pairs file for the point pairs' errors,
/// else the reconstruction.
fn run_error(e: sfmeval::Error, inputs: &Inputs, what: &str) -> Failure {
    Failure::Input(match (&inputs.pairs, e.concerns_point_pairs()) {
        (Some(p), true) => anyhow::Error::new(e).context(format!("point pairs '{}'", p.display())),
        _ => anyhow::Error::new(e).context(format!("evaluating '{what}'")),
    })
}

/// How the reconstruction is named in the errors of an evaluation (its path, as the CLI's).
fn recon_label(inputs: &Inputs) -> String {
    match (&inputs.recon, &inputs.name) {
        (ReconSource::Path(p), _) => p.display().to_string(),
        (ReconSource::Points(_), Some(n)) => n.clone(),
        (ReconSource::Points(_), None) => "points.ply".to_string(),
    }
}

/// What one evaluation hands back to Python (the rest of the evaluation is dropped before).
struct Outcome {
    report_json: String,
    distances: Vec<f64>,
    signed_distances: Option<Vec<f64>>,
    kept: Vec<u8>,
    completeness_points: Vec<[f64; 3]>,
    completeness_distances: Vec<f64>,
}

/// `values` as a Python `bytes` of float64 in native order, written in place (no second copy
/// beside the vector).
fn native_bytes<'py>(py: Python<'py>, values: &[f64]) -> PyResult<Bound<'py, PyBytes>> {
    PyBytes::new_with(py, values.len() * 8, |buf| {
        for (chunk, v) in buf.chunks_exact_mut(8).zip(values) {
            chunk.copy_from_slice(&v.to_ne_bytes());
        }
        Ok(())
    })
}

/// The whole evaluation, without the GIL: the CLI's `eval` on the same inputs.
fn evaluate_inputs(mut inputs: Inputs, progress: &dyn Progress) -> Result<Outcome, Failure> {
    let eval = EvalOptions {
        tau: inputs.tau.clone(),
        tau_percent_of_diagonal: inputs.tau_percent.clone(),
        samples: inputs.samples,
        seed: inputs.seed,
        signed: inputs.signed,
        crop: crop_of(&inputs)?,
        ..EvalOptions::default()
    };
    eval.validate()?;
    let request = EvalRequest {
        align: align_of(&inputs)?,
        eval,
        pose: PoseOptions::default(),
    };
    let what = recon_label(&inputs);
    let mut dataset = read_ground_truth(&mut inputs, true)?;
    let recon = read_recon(&mut inputs)?;
    let evaluation = pipeline::run_owned(&mut dataset, recon, &request, progress)
        .map_err(|e| run_error(e, &inputs, &what))?;
    let kept = evaluation
        .status
        .iter()
        .map(|s| u8::from(*s == PointStatus::Kept))
        .collect();
    Ok(Outcome {
        report_json: evaluation.report.to_json(),
        distances: evaluation.distances,
        signed_distances: evaluation.signed_distances,
        kept,
        completeness_points: evaluation.completeness_points,
        completeness_distances: evaluation.completeness_distances,
    })
}

/// The ground truth and reconstruction arguments of `_evaluate` and `_align`, as sources.
fn sources(
    gt: Option<PathBuf>,
    gt_vertices: Option<&Bound<'_, PyAny>>,
    gt_triangles: Option<&Bound<'_, PyAny>>,
    gt_name: Option<String>,
    recon: Option<PathBuf>,
    recon_points: Option<&Bound<'_, PyAny>>,
) -> PyResult<(GtSource, ReconSource)> {
    let gt = match (gt, gt_vertices) {
        (_, Some(v)) => GtSource::Arrays {
            vertices: arrays::positions(v, "gt vertices")?,
            triangles: gt_triangles
                .map(|t| arrays::rows_u32(t, "gt triangles"))
                .transpose()?,
            name: gt_name.unwrap_or_else(|| "ground_truth.ply".to_string()),
        },
        (Some(p), None) => GtSource::Path(p),
        (None, None) => return Err(InputError::new_err("gt: a path or arrays are needed")),
    };
    let recon = match (recon, recon_points) {
        (_, Some(a)) => ReconSource::Points(arrays::positions(a, "recon")?),
        (Some(p), None) => ReconSource::Path(p),
        (None, None) => return Err(InputError::new_err("recon: a path or an array is needed")),
    };
    Ok((gt, recon))
}

/// What `_evaluate` returns to the wrapper: the report JSON, the distances, the signed ones, the
/// kept flags, and the completeness samples (x y z) with their distances.
type Returned<'py> = (
    String,
    Bound<'py, PyBytes>,
    Option<Bound<'py, PyBytes>>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
);

/// `_evaluate(...)`: the report JSON (`sfmeval eval --report`'s bytes), the unsigned
/// distances (float64, native order, one per input point), the signed ones (or `None`), a
/// kept flag per point (uint8), and the completeness samples (x y z float64, ground-truth frame)
/// and their distances to the reconstruction (float64), as `--samples-csv` writes them. Arguments are the wrapper's normalised ones
/// (`python/sfmeval/__init__.py`): arrays C-contiguous, float32/float64 (uint32 triangles).
#[pyfunction]
#[pyo3(signature = (gt=None, recon=None, *, gt_vertices=None, gt_triangles=None, gt_name=None,
    recon_points=None, name=None, gt_cameras=None, recon_cameras=None, align=None,
    transform_path=None, transform_json=None, pairs=None, crop_path=None, crop_json=None,
    max_distance=None, tau=Vec::new(), tau_percent=Vec::new(),
    samples=sfmeval::evaluate::DEFAULT_SAMPLES, seed=0, signed=false,
    max_triangles=ReadLimits::DEFAULT_MAX_TRIANGLES, threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn _evaluate<'py>(
    py: Python<'py>,
    gt: Option<PathBuf>,
    recon: Option<PathBuf>,
    gt_vertices: Option<Bound<'py, PyAny>>,
    gt_triangles: Option<Bound<'py, PyAny>>,
    gt_name: Option<String>,
    recon_points: Option<Bound<'py, PyAny>>,
    name: Option<String>,
    gt_cameras: Option<PathBuf>,
    recon_cameras: Option<PathBuf>,
    align: Option<String>,
    transform_path: Option<PathBuf>,
    transform_json: Option<String>,
    pairs: Option<PathBuf>,
    crop_path: Option<PathBuf>,
    crop_json: Option<String>,
    max_distance: Option<f64>,
    tau: Vec<f64>,
    tau_percent: Vec<f64>,
    samples: usize,
    seed: u64,
    signed: bool,
    max_triangles: u64,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Returned<'py>> {
    let (gt, recon) = sources(
        gt,
        gt_vertices.as_ref(),
        gt_triangles.as_ref(),
        gt_name,
        recon,
        recon_points.as_ref(),
    )?;
    let inputs = Inputs {
        gt,
        recon,
        name,
        gt_cameras,
        recon_cameras,
        align,
        transform_path,
        transform_json,
        pairs,
        crop_path,
        crop_json,
        max_distance,
        tau,
        tau_percent,
        samples,
        seed,
        signed,
        max_triangles,
    };
    let outcome = hooks::run(py, threads, progress, |p| evaluate_inputs(inputs, p))?;
    let distances = native_bytes(py, &outcome.distances)?;
    drop(outcome.distances);
    let signed = outcome
        .signed_distances
        .as_deref()
        .map(|d| native_bytes(py, d))
        .transpose()?;
    let sample_coordinates: Vec<f64> = outcome
        .completeness_points
        .iter()
        .flatten()
        .copied()
        .collect();
    Ok((
        outcome.report_json,
        distances,
        signed,
        PyBytes::new(py, &outcome.kept),
        native_bytes(py, &sample_coordinates)?,
        native_bytes(py, &outcome.completeness_distances)?,
    ))
}

/// `sfmeval align` on the same inputs, without the GIL: the alignment section as `--out
/// X.json` writes it and the report's notes (JSON), which the CLI prints.
fn align_inputs(mut inputs: Inputs, progress: &dyn Progress) -> Result<(String, String), Failure> {
    let request = EvalRequest {
        align: align_of(&inputs)?,
        eval: EvalOptions {
            samples: inputs.samples,
            seed: inputs.seed,
            ..EvalOptions::default()
        },
        pose: PoseOptions::default(),
    };
    let what = recon_label(&inputs);
    let mut dataset = read_ground_truth(&mut inputs, false)?;
    let recon = read_recon(&mut inputs)?;
    let evaluation = pipeline::run_owned(&mut dataset, recon, &request, progress)
        .map_err(|e| run_error(e, &inputs, &what))?;
    let mut alignment = serde_json::to_string_pretty(&evaluation.report.alignment)?;
    alignment.push('\n');
    Ok((alignment, serde_json::to_string(&evaluation.report.notes)?))
}

/// `_align(...)`: `sfmeval align`'s alignment section (the bytes `--out X.json` writes) and the
/// notes as JSON.
#[pyfunction]
#[pyo3(signature = (gt=None, recon=None, *, gt_vertices=None, gt_triangles=None, gt_name=None,
    recon_points=None, name=None, gt_cameras=None, recon_cameras=None, align=None,
    transform_path=None, transform_json=None, pairs=None,
    samples=sfmeval::evaluate::DEFAULT_SAMPLES, seed=0,
    max_triangles=ReadLimits::DEFAULT_MAX_TRIANGLES, threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn _align<'py>(
    py: Python<'py>,
    gt: Option<PathBuf>,
    recon: Option<PathBuf>,
    gt_vertices: Option<Bound<'py, PyAny>>,
    gt_triangles: Option<Bound<'py, PyAny>>,
    gt_name: Option<String>,
    recon_points: Option<Bound<'py, PyAny>>,
    name: Option<String>,
    gt_cameras: Option<PathBuf>,
    recon_cameras: Option<PathBuf>,
    align: Option<String>,
    transform_path: Option<PathBuf>,
    transform_json: Option<String>,
    pairs: Option<PathBuf>,
    samples: usize,
    seed: u64,
    max_triangles: u64,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, String)> {
    let (gt, recon) = sources(
        gt,
        gt_vertices.as_ref(),
        gt_triangles.as_ref(),
        gt_name,
        recon,
        recon_points.as_ref(),
    )?;
    let inputs = Inputs {
        gt,
        recon,
        name,
        gt_cameras,
        recon_cameras,
        align,
        transform_path,
        transform_json,
        pairs,
        crop_path: None,
        crop_json: None,
        max_distance: None,
        tau: Vec::new(),
        tau_percent: Vec::new(),
        samples,
        seed,
        signed: false,
        max_triangles,
    };
    hooks::run(py, threads, progress, |p| align_inputs(inputs, p))
}

/// The version of the sfmeval core (the report's `tool.version`).
#[pyfunction]
fn version() -> String {
    sfmeval::report::Tool::default().version
}

/// The alignment modes `align=` takes, in the core's order.
#[pyfunction]
fn align_modes() -> Vec<&'static str> {
    AlignMode::names().to_vec()
}

/// The native module `sfmeval._sfmeval`.
#[pymodule]
fn _sfmeval(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add_function(wrap_pyfunction!(_evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(_align, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::_read, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::_cameras, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::_poses, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::_tnt, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::_dtu, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::_eth3d, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::_table, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(align_modes, m)?)?;
    Ok(())
}
