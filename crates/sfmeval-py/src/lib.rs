//! # sfmeval-py
//!
//! Thin PyO3 bindings over the sfmeval core for the Python package `sfmeval` (built by maturin,
//! `scripts/build-wheel.sh`). Paths go in and are read by `sfmeval-fs` exactly as the `sfmeval`
//! CLI reads them; the request is the core's [`EvalRequest`] and the evaluation is
//! [`pipeline::run_owned`], so the report JSON handed back is the CLI's `--report` file byte for
//! byte. The Python side (`python/sfmeval/__init__.py`) only wraps that JSON for attribute
//! access and the per-point arrays in numpy; it computes nothing.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use sfmeval::align::{AlignMode, AlignRequest, PointPair};
use sfmeval::crop::Crop;
use sfmeval::dataset::{DatasetPaths, Part};
use sfmeval::evaluate::{EvalOptions, PointStatus};
use sfmeval::export;
use sfmeval::io::ReadLimits;
use sfmeval::pipeline::{self, EvalRequest, ReconInput};
use sfmeval::pose::PoseOptions;
use sfmeval::progress::NoProgress;
use sfmeval::transform::Similarity;
use sfmeval_fs::{
    name_of, path_str, read, read_point_pairs, read_reconstruction_with_cameras, read_transform,
};

create_exception!(
    sfmeval,
    InputError,
    PyValueError,
    "An input the core cannot use: the message names the file (or option) and what is wrong."
);

/// What `evaluate` failed on: a path that does not exist (Python's `FileNotFoundError`), or
/// anything else the readers or the core reject (`InputError`, the CLI's message).
enum Failure {
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
fn existing(path: &Path) -> Result<&Path, Failure> {
    if path.exists() {
        Ok(path)
    } else {
        Err(Failure::Missing(path.to_path_buf()))
    }
}

/// Everything `evaluate` takes, as the Python wrapper normalised it.
struct Inputs {
    gt: PathBuf,
    recon: PathBuf,
    recon_points: Option<Vec<[f64; 3]>>,
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

/// The ground truth's parts: a folder is a dataset (`ground_truth.glb`, `cameras.json` and
/// `depth/` when present, as `--dataset`), a file the geometry alone; `gt_cameras` overrides.
fn dataset_paths(inputs: &Inputs) -> Result<DatasetPaths, Failure> {
    let gt = existing(&inputs.gt)?;
    let mut paths = if gt.is_dir() {
        DatasetPaths::folder(path_str(gt)?)
    } else {
        DatasetPaths::ground_truth(path_str(gt)?)
    };
    if let Some(c) = &inputs.gt_cameras {
        paths.cameras = Part::Required(path_str(existing(c)?)?.to_string());
    }
    Ok(paths)
}

/// The reconstruction, read as `sfmeval eval --recon [--recon-cameras]` reads it.
fn read_recon(inputs: &Inputs) -> Result<ReconInput, Failure> {
    if let Some(points) = &inputs.recon_points {
        // an array from Python: the float64 PLY `sfmeval export` writes, read as that file is
        let name = inputs
            .name
            .clone()
            .unwrap_or_else(|| "points.ply".to_string());
        let files = [(name.clone(), export::points_ply_f64(points, None))].into();
        return Ok(pipeline::read_reconstruction(&name, &files)
            .with_context(|| format!("reconstruction '{name}' (an array of points)"))?);
    }
    let recon = existing(&inputs.recon)?;
    let name = inputs.name.clone().unwrap_or_else(|| name_of(recon));
    let cameras_path = inputs.recon_cameras.as_deref().map(existing).transpose()?;
    Ok(read_reconstruction_with_cameras(
        recon,
        cameras_path,
        &name,
    )?)
}

/// What one evaluation hands back to Python.
struct Outcome {
    report_json: String,
    distances: Vec<u8>,
    signed_distances: Option<Vec<u8>>,
    kept: Vec<u8>,
}

fn native_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_ne_bytes()).collect()
}

/// `x0 y0 z0 x1 ...` float64 in native order (a C-contiguous `(N, 3)` numpy array's bytes).
fn points_of(bytes: &[u8]) -> PyResult<Vec<[f64; 3]>> {
    if !bytes.len().is_multiple_of(24) {
        return Err(InputError::new_err(format!(
            "recon: {} bytes are not whole points of three float64",
            bytes.len()
        )));
    }
    Ok(bytes
        .chunks_exact(24)
        .map(|p| {
            let mut xyz = [0.0; 3];
            for (v, b) in xyz.iter_mut().zip(p.chunks_exact(8)) {
                let mut word = [0u8; 8];
                word.copy_from_slice(b);
                *v = f64::from_ne_bytes(word);
            }
            xyz
        })
        .collect())
}

/// The whole evaluation, without the GIL: the CLI's `eval` on the same inputs.
fn evaluate_inputs(inputs: &Inputs) -> Result<Outcome, Failure> {
    let eval = EvalOptions {
        tau: inputs.tau.clone(),
        tau_percent_of_diagonal: inputs.tau_percent.clone(),
        samples: inputs.samples,
        seed: inputs.seed,
        signed: inputs.signed,
        crop: crop_of(inputs)?,
        ..EvalOptions::default()
    };
    eval.validate()?;
    let request = EvalRequest {
        align: align_of(inputs)?,
        eval,
        pose: PoseOptions::default(),
    };
    let paths = dataset_paths(inputs)?;
    let limits = ReadLimits::triangles(inputs.max_triangles);
    let mut dataset = sfmeval_fs::read_dataset(&paths, &limits)?;
    let recon = read_recon(inputs)?;
    let what = match &inputs.recon_points {
        Some(_) => recon.name.clone(),
        None => inputs.recon.display().to_string(),
    };
    let evaluation =
        pipeline::run_owned(&mut dataset, recon, &request, &NoProgress).map_err(|e| {
            match (&inputs.pairs, e.concerns_point_pairs()) {
                (Some(p), true) => {
                    anyhow::Error::new(e).context(format!("point pairs '{}'", p.display()))
                }
                _ => anyhow::Error::new(e).context(format!("evaluating '{what}'")),
            }
        })?;
    Ok(Outcome {
        report_json: evaluation.report.to_json(),
        distances: native_bytes(&evaluation.distances),
        signed_distances: evaluation.signed_distances.as_deref().map(native_bytes),
        kept: evaluation
            .status
            .iter()
            .map(|s| u8::from(*s == PointStatus::Kept))
            .collect(),
    })
}

/// What `_evaluate` returns to the wrapper: the report JSON, the distances, the signed ones and
/// the kept flags.
type Returned<'py> = (
    String,
    Bound<'py, PyBytes>,
    Option<Bound<'py, PyBytes>>,
    Bound<'py, PyBytes>,
);

/// `_evaluate(...)`: the report JSON (`sfmeval eval --report`'s bytes), the unsigned
/// distances (float64, native order, one per input point), the signed ones (or `None`) and a
/// kept flag per point (uint8). Arguments are the wrapper's normalised ones
/// (`python/sfmeval/__init__.py`).
#[pyfunction]
#[pyo3(signature = (gt, recon, *, recon_points=None, name=None, gt_cameras=None, recon_cameras=None, align=None,
    transform_path=None, transform_json=None, pairs=None, crop_path=None, crop_json=None,
    max_distance=None, tau=Vec::new(), tau_percent=Vec::new(),
    samples=sfmeval::evaluate::DEFAULT_SAMPLES, seed=0, signed=false,
    max_triangles=ReadLimits::DEFAULT_MAX_TRIANGLES))]
#[allow(clippy::too_many_arguments)]
fn _evaluate<'py>(
    py: Python<'py>,
    gt: PathBuf,
    recon: PathBuf,
    recon_points: Option<Vec<u8>>,
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
) -> PyResult<Returned<'py>> {
    let recon_points = recon_points.map(|bytes| points_of(&bytes)).transpose()?;
    let inputs = Inputs {
        gt,
        recon,
        recon_points,
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
    let outcome = py.detach(|| evaluate_inputs(&inputs))?;
    Ok((
        outcome.report_json,
        PyBytes::new(py, &outcome.distances),
        outcome
            .signed_distances
            .as_deref()
            .map(|b| PyBytes::new(py, b)),
        PyBytes::new(py, &outcome.kept),
    ))
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
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(align_modes, m)?)?;
    Ok(())
}
