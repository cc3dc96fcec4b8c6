//! # sfmeval-wasm
//!
//! Thin wasm-bindgen bindings over the sfmeval core, for the npm package `sfmeval` and the
//! browser page. Bytes go in (`Uint8Array`), options go in as plain JS objects (deserialised with
//! serde-wasm-bindgen into the core's own option types), and the `sfmeval.report/3` JSON plus
//! typed arrays come out. Every number is computed by the core (`crates/sfmeval`) exactly as the
//! CLI computes it; errors become JS `Error`s carrying the core's message.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

use js_sys::{Float32Array, Float64Array, Function, Object, Uint8Array, Uint32Array};
use serde::Serialize as _;
use sfmeval::align::{AlignMode, AlignRequest, PointPair, parse_point_pairs};
use sfmeval::colormap::distance_colors;
use sfmeval::crop::Crop;
use sfmeval::dataset::Dataset;
use sfmeval::evaluate::EvalOptions;
use sfmeval::export;
use sfmeval::geometry::{Aabb, GroundTruth as CoreGroundTruth};
use sfmeval::gt_views::depth_stem;
use sfmeval::io;
use sfmeval::io::npy::DepthMap;
use sfmeval::pipeline::{self, EvalRequest, ReconInput};
use sfmeval::progress::{Progress, Stage};
use sfmeval::transform::Similarity;
use wasm_bindgen::prelude::*;

mod dtu;
mod eth3d;
mod pose_protocols;
mod poses;
mod stream;
mod table;
mod tnt;

pub use dtu::{DtuEvaluation, dtu_files, evaluate_dtu};
pub use eth3d::{Eth3dResult, eth3d_files, evaluate_eth3d};
pub use pose_protocols::{PosesEvaluation, evaluate_poses};
pub use poses::error_colors;
pub use stream::ReconstructionStream;
pub use table::{
    compare_table, comparison_tables, metric_catalogue, run_reconstruction_files, run_row,
};
pub use tnt::{TntResult, evaluate_tnt, tnt_files};
/// `initThreadPool(n)`: starts the pool of `n` Web Workers the threaded build's maps run on.
#[cfg(feature = "threads")]
pub use wasm_bindgen_rayon::init_thread_pool;

/// Whether a file can be part of an SfM model or a cloud, by its extension (the core's rule,
/// `sfmeval::files::is_model_file`): which files of a picked folder are reconstructions.
#[wasm_bindgen(js_name = isModelFile)]
pub fn is_model_file(path: &str) -> bool {
    sfmeval::files::is_model_file(path)
}

/// Threads the core's parallel maps use: the pool's size in the threaded build, 1 otherwise.
#[wasm_bindgen(js_name = threadCount)]
pub fn thread_count() -> usize {
    threads_in_pool()
}

#[cfg(feature = "threads")]
fn threads_in_pool() -> usize {
    rayon::current_num_threads()
}

#[cfg(not(feature = "threads"))]
fn threads_in_pool() -> usize {
    1
}

/// Installs the panic hook so that a Rust panic shows its message in the console.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

/// The version of the sfmeval core (the report's `tool.version`).
#[wasm_bindgen]
pub fn version() -> String {
    sfmeval::report::Tool::default().version
}

fn js_err(context: &str, e: impl std::fmt::Display) -> JsError {
    if context.is_empty() {
        JsError::new(&e.to_string())
    } else {
        JsError::new(&format!("{context}: {e}"))
    }
}

/// Reads a JS object `{name: Uint8Array, ...}` into named bytes.
fn files_of(files: &Object) -> Result<BTreeMap<String, Vec<u8>>, JsError> {
    let mut out = BTreeMap::new();
    for entry in Object::entries(files).iter() {
        let pair: js_sys::Array = entry.into();
        let name = pair
            .get(0)
            .as_string()
            .ok_or_else(|| JsError::new("file names must be strings"))?;
        let bytes = pair.get(1);
        if !bytes.is_instance_of::<Uint8Array>() {
            return Err(JsError::new(&format!("file '{name}' must be a Uint8Array")));
        }
        out.insert(name, Uint8Array::from(bytes).to_vec());
    }
    Ok(out)
}

fn points_f64(points: &[[f64; 3]]) -> Float64Array {
    Float64Array::from(points.as_flattened())
}

/// The same as 32-bit floats (WebGL buffers).
fn points_f32(points: &[[f64; 3]]) -> Float32Array {
    let flat: Vec<f32> = points.iter().flatten().map(|&v| v as f32).collect();
    Float32Array::from(flat.as_slice())
}

/// A ground truth read from bytes (GLB, glTF with its external buffers, OBJ, PLY mesh or cloud).
/// Its BVH and completeness samples are prepared on the first evaluation and reused while the
/// sample count and seed stay the same.
#[wasm_bindgen]
pub struct GroundTruth {
    dataset: Dataset,
}

#[wasm_bindgen]
impl GroundTruth {
    /// Reads `bytes` named `name`; `external` is an optional object `{uri: Uint8Array}` with the
    /// external buffers of a `.gltf`; `max_triangles` (default 10 M) refuses a glTF mesh with
    /// more triangles once every node instance is expanded, before anything is allocated (a
    /// PLY's or OBJ's triangles are in the file and are not held to it).
    #[wasm_bindgen(constructor)]
    pub fn new(
        name: &str,
        bytes: &Uint8Array,
        external: Option<Object>,
        max_triangles: Option<f64>,
    ) -> Result<GroundTruth, JsError> {
        let external = match external {
            Some(o) => files_of(&o)?,
            None => BTreeMap::new(),
        };
        let limits = match max_triangles {
            Some(n) if n.is_finite() && n >= 1.0 => io::ReadLimits::triangles(n as u64),
            Some(n) => {
                return Err(JsError::new(&format!(
                    "maxTriangles must be a number ≥ 1, got {n}"
                )));
            }
            None => io::ReadLimits::default(),
        };
        let loaded = io::read_ground_truth_with_limits(name, &bytes.to_vec(), &external, &limits)
            .map_err(|e| js_err(&format!("ground truth '{name}'"), e))?;
        Ok(GroundTruth {
            dataset: Dataset::new(name, loaded),
        })
    }

    /// File name given when reading.
    #[wasm_bindgen(getter)]
    pub fn name(&self) -> String {
        self.dataset.name.clone()
    }

    /// Format read (`glb`, `gltf`, `obj`, `ply`).
    #[wasm_bindgen(getter)]
    pub fn format(&self) -> String {
        self.dataset.loaded.format.name().to_string()
    }

    /// Whether the ground truth is a triangle mesh (else a point cloud).
    #[wasm_bindgen(getter, js_name = isMesh)]
    pub fn is_mesh(&self) -> bool {
        matches!(self.dataset.loaded.ground_truth, CoreGroundTruth::Mesh(_))
    }

    /// Vertices (or cloud points), `x0, y0, z0, x1, ...`, in the ground-truth frame.
    pub fn vertices(&self) -> Float64Array {
        points_f64(&self.dataset.loaded.ground_truth.points())
    }

    /// Triangle vertex indices (empty for a cloud).
    pub fn triangles(&self) -> Uint32Array {
        match &self.dataset.loaded.ground_truth {
            CoreGroundTruth::Mesh(m) => {
                let flat: Vec<u32> = m.triangles.iter().flatten().copied().collect();
                Uint32Array::from(flat.as_slice())
            }
            CoreGroundTruth::Cloud(_) => Uint32Array::new_with_length(0),
        }
    }

    /// Bounding box `[xmin, ymin, zmin, xmax, ymax, zmax]`.
    pub fn bounds(&self) -> Vec<f64> {
        Aabb::of(&self.dataset.loaded.ground_truth.points())
            .map(|b| b.min.iter().chain(&b.max).copied().collect())
            .unwrap_or_default()
    }

    /// The messages of the notes from reading (the report lists them typed, in `notes`).
    #[wasm_bindgen(getter)]
    pub fn warnings(&self) -> Vec<String> {
        messages(&self.dataset.loaded.notes)
    }

    /// Attaches the ground-truth cameras used by later evaluations (camera alignment and pose
    /// metrics). Takes ownership: the `Cameras` object cannot be used afterwards.
    #[wasm_bindgen(js_name = setCameras)]
    pub fn set_cameras(&mut self, cameras: Cameras) {
        self.dataset.set_cameras(Some(cameras.model));
    }

    /// Removes the attached ground-truth cameras (and the depth maps, which need them).
    #[wasm_bindgen(js_name = clearCameras)]
    pub fn clear_cameras(&mut self) {
        self.dataset.set_cameras(None);
    }

    /// Attaches the dataset's depth maps (`depth/<image stem>.npy`, one per ground-truth image,
    /// given as `{name: Uint8Array}`; folders in the names are ignored) for visibility-aware
    /// completeness and the track-based error, as `sfmeval eval --depth`. Needs the cameras.
    #[wasm_bindgen(js_name = setDepthMaps)]
    pub fn set_depth_maps(&mut self, files: Object) -> Result<(), JsError> {
        if self.dataset.cameras().is_none() {
            return Err(JsError::new(
                "depth maps need the ground-truth cameras (cameras.json) first",
            ));
        }
        let mut maps = BTreeMap::new();
        for (name, bytes) in files_of(&files)? {
            let map = DepthMap::from_npy(&bytes)
                .map_err(|e| js_err(&format!("depth map '{name}'"), e))?;
            maps.insert(depth_stem(&name), map);
        }
        self.dataset
            .set_depth_maps(&maps)
            .map_err(|e| js_err("depth maps", e))
    }

    /// Removes the attached depth maps.
    #[wasm_bindgen(js_name = clearDepthMaps)]
    pub fn clear_depth_maps(&mut self) {
        self.dataset.clear_depth_maps();
    }

    /// Whether depth maps are attached.
    #[wasm_bindgen(getter, js_name = hasDepthMaps)]
    pub fn has_depth_maps(&self) -> bool {
        self.dataset.views().is_some()
    }

    /// Whether ground-truth cameras are attached.
    #[wasm_bindgen(getter, js_name = hasCameras)]
    pub fn has_cameras(&self) -> bool {
        self.dataset.cameras().is_some()
    }
}

/// A reconstruction read from its files: a PLY cloud, or an SfM model's files (COLMAP
/// `cameras/images/points3D` `.bin`/`.txt`, `.nvm`, Bundler `.out` + `list.txt`,
/// `sfm_data.json`, `cameras.json`).
#[wasm_bindgen]
pub struct Reconstruction {
    input: ReconInput,
}

#[wasm_bindgen]
impl Reconstruction {
    /// Reads `files` (`{relativePath: Uint8Array}`); `name` is shown in the report.
    #[wasm_bindgen(constructor)]
    pub fn new(name: &str, files: &Object) -> Result<Reconstruction, JsError> {
        let files = files_of(files)?;
        let input = pipeline::read_reconstruction(name, &files)
            .map_err(|e| js_err(&format!("reconstruction '{name}'"), e))?;
        Ok(Reconstruction { input })
    }

    /// Name shown in the report.
    #[wasm_bindgen(getter)]
    pub fn name(&self) -> String {
        self.input.name.clone()
    }

    /// Format read (`ply`, `colmap`, `nvm`, ...).
    #[wasm_bindgen(getter)]
    pub fn format(&self) -> String {
        self.input.format.clone()
    }

    /// Number of points.
    #[wasm_bindgen(getter, js_name = pointCount)]
    pub fn point_count(&self) -> usize {
        self.input.cloud.points.len()
    }

    /// Registered images (0 for a bare cloud).
    #[wasm_bindgen(getter)]
    pub fn images(&self) -> usize {
        self.input.model.as_ref().map_or(0, |m| m.images.len())
    }

    /// Points in the reconstruction's own frame, `x0, y0, z0, x1, ...`.
    pub fn positions(&self) -> Float64Array {
        points_f64(&self.input.cloud.points.as_f64())
    }

    /// Whether the points are stored as 32-bit floats (a binary PLY with `float` x y z), so
    /// [`Self::positions_f32`] gives them exactly.
    #[wasm_bindgen(getter, js_name = positionsAreF32)]
    pub fn positions_are_f32(&self) -> bool {
        matches!(
            self.input.cloud.points,
            sfmeval::geometry::Positions::F32(_)
        )
    }

    /// The same as 32-bit floats (WebGL buffers), without a 64-bit copy of a dense cloud.
    #[wasm_bindgen(js_name = positionsF32)]
    pub fn positions_f32(&self) -> Float32Array {
        match &self.input.cloud.points {
            sfmeval::geometry::Positions::F32(v) => Float32Array::from(v.as_flattened()),
            sfmeval::geometry::Positions::F64(v) => points_f32(v),
        }
    }

    /// Per-point RGB colours (`r0, g0, b0, ...`), when the file has them.
    pub fn colors(&self) -> Option<Uint8Array> {
        self.input.cloud.colors.as_ref().map(|c| {
            let flat: Vec<u8> = c.iter().flatten().copied().collect();
            Uint8Array::from(flat.as_slice())
        })
    }

    /// The messages of the notes from reading (the report lists them typed, in `notes`).
    #[wasm_bindgen(getter)]
    pub fn warnings(&self) -> Vec<String> {
        messages(&self.input.notes)
    }
}

/// Ground-truth cameras (a dataset's `cameras.json`, or any SfM model in the ground-truth
/// frame), for camera alignment and pose metrics.
#[wasm_bindgen]
pub struct Cameras {
    model: sfmeval::model::Reconstruction,
}

#[wasm_bindgen]
impl Cameras {
    /// Reads `files` (`{name: Uint8Array}`).
    #[wasm_bindgen(constructor)]
    pub fn new(files: &Object) -> Result<Cameras, JsError> {
        let files = files_of(files)?;
        let model = sfmeval::model::read_model_files(&files)
            .map_err(|e| js_err("ground-truth cameras", e))?;
        Ok(Cameras { model })
    }

    /// Number of images.
    #[wasm_bindgen(getter)]
    pub fn images(&self) -> usize {
        self.model.images.len()
    }
}

/// Forwards the core's progress to a JS callback `(stage, done, total)` from the calling
/// thread, and keeps it in [`PROGRESS`] for the threads that cannot call JS.
struct JsProgress;

/// The running call's progress: the stage (an index into [`progress_stages`]), done and
/// total. Every thread writes it; in the threaded build the memory is shared, so the page's
/// main thread reads it while the worker that called is blocked in the call (the pool's
/// threads cannot call back into JavaScript).
static PROGRESS: [AtomicU64; 3] = [const { AtomicU64::new(0) }; 3];

/// Byte address of the progress counters in the module's memory: three `u64` (stage index,
/// done, total), to read with `Atomics.load` on a `BigUint64Array` over the shared memory.
#[wasm_bindgen(js_name = progressCounters)]
pub fn progress_counters() -> usize {
    PROGRESS.as_ptr() as usize
}

/// The stage labels the progress counters' stage index points into.
#[wasm_bindgen(js_name = progressStages)]
pub fn progress_stages() -> Vec<String> {
    STAGES.iter().map(|s| s.label().to_string()).collect()
}

const STAGES: [Stage; 8] = [
    Stage::IndexGroundTruth,
    Stage::Accuracy,
    Stage::Sampling,
    Stage::IndexReconstruction,
    Stage::Completeness,
    Stage::Alignment,
    Stage::Visibility,
    Stage::TrackError,
];

thread_local! {
    static CALLBACK: std::cell::RefCell<Option<Function>> = const { std::cell::RefCell::new(None) };
}

impl JsProgress {
    fn emit(&self) {
        let [stage, done, total] = PROGRESS.each_ref().map(|c| c.load(Ordering::Relaxed));
        let label = STAGES.get(stage as usize).map_or("", |s| s.label());
        CALLBACK.with(|c| {
            if let Some(f) = c.borrow().as_ref() {
                let _ = f.call3(
                    &JsValue::NULL,
                    &JsValue::from_str(label),
                    &JsValue::from_f64(done as f64),
                    &JsValue::from_f64(total as f64),
                );
            }
        });
    }
}

impl Progress for JsProgress {
    fn start(&self, stage: Stage, total: u64) {
        let i = STAGES.iter().position(|s| *s == stage).unwrap_or(0);
        let [s, d, t] = &PROGRESS;
        s.store(i as u64, Ordering::Relaxed);
        d.store(0, Ordering::Relaxed);
        t.store(total, Ordering::Relaxed);
        self.emit();
    }
    fn advance(&self, n: u64) {
        PROGRESS[1].fetch_add(n, Ordering::Relaxed);
        self.emit();
    }
    fn finish(&self) {
        let [_, d, t] = &PROGRESS;
        d.store(t.load(Ordering::Relaxed), Ordering::Relaxed);
        self.emit();
    }
}

/// Sets the callback for the duration of one call and removes it afterwards.
struct CallbackGuard;

impl CallbackGuard {
    fn set(f: Option<Function>) -> CallbackGuard {
        CALLBACK.with(|c| *c.borrow_mut() = f);
        CallbackGuard
    }
}

impl Drop for CallbackGuard {
    fn drop(&mut self) {
        CALLBACK.with(|c| *c.borrow_mut() = None);
    }
}

/// The alignment part of the options, as the CLI's `--align`, `--transform` and `--pairs`.
#[derive(serde::Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct AlignOptions {
    /// One of [`AlignMode::names`] (see `alignModes()`).
    align: Option<String>,
    /// A row-major 4×4 `gt_from_recon`, or the text of a transform file.
    transform: Option<serde_json::Value>,
    /// Point pairs for the `points` stages.
    pairs: Option<Vec<PointPair>>,
}

/// Splits the JS options object into the core's [`EvalOptions`] and the alignment request.
fn parse_options(options: JsValue) -> Result<(EvalOptions, AlignOptions), JsError> {
    if options.is_undefined() || options.is_null() {
        return Ok((EvalOptions::default(), AlignOptions::default()));
    }
    let mut value: serde_json::Value =
        serde_wasm_bindgen::from_value(options).map_err(|e| js_err("options", e.to_string()))?;
    let map = value
        .as_object_mut()
        .ok_or_else(|| JsError::new("options must be an object"))?;
    let mut align = serde_json::Map::new();
    for key in ["align", "transform", "pairs"] {
        if let Some(v) = map.remove(key).filter(|v| !v.is_null()) {
            align.insert(key.into(), v);
        }
    }
    let eval: EvalOptions =
        serde_json::from_value(value).map_err(|e| js_err("options", e.to_string()))?;
    let align: AlignOptions = serde_json::from_value(serde_json::Value::Object(align))
        .map_err(|e| js_err("options", e.to_string()))?;
    Ok((eval, align))
}

fn parse_transform(v: &serde_json::Value) -> Result<Similarity, JsError> {
    let text = match v {
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    };
    Similarity::parse(text.as_bytes()).map_err(|e| js_err("transform", e))
}

/// Builds the alignment request: the core's [`AlignRequest::new`], as the CLI's.
fn align_request(a: AlignOptions) -> Result<AlignRequest, JsError> {
    let transform = a.transform.as_ref().map(parse_transform).transpose()?;
    let mode = a
        .align
        .as_deref()
        .map(AlignMode::parse)
        .transpose()
        .map_err(|e| js_err("options", e))?;
    AlignRequest::new(mode, transform, a.pairs.unwrap_or_default())
        .map_err(|e| js_err("options", e))
}

/// Every alignment mode, as `[{name, description, needsTransform, needsPairs, needsCameras}]`,
/// in the order menus list them.
#[wasm_bindgen(js_name = alignModes)]
pub fn align_modes() -> Result<JsValue, JsError> {
    let modes: Vec<serde_json::Value> = AlignMode::ALL
        .iter()
        .map(|m| {
            serde_json::json!({
                "name": m.name(),
                "description": m.description(),
                "needsTransform": m.needs_transform(),
                "needsPairs": m.needs_pairs(),
                "needsCameras": m.needs_cameras(),
            })
        })
        .collect();
    modes
        .serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| js_err("alignment modes", e.to_string()))
}

/// The result of [`evaluate`]: the report and per-point arrays for the viewer and exports.
#[wasm_bindgen]
pub struct Evaluation {
    inner: sfmeval::evaluate::Evaluation,
    /// The pose protocols' numbers (`sfmeval poses`) when the ground truth and the
    /// reconstruction both have cameras, for the run's row (`runRow`).
    poses: Option<sfmeval_table::RowPoses>,
}

#[wasm_bindgen]
impl Evaluation {
    /// The `sfmeval.report/3` JSON, byte for byte what `sfmeval eval --report` writes.
    #[wasm_bindgen(js_name = reportJson)]
    pub fn report_json(&self) -> String {
        self.inner.report.to_json()
    }

    /// Every reconstructed point in the ground-truth frame (`x0, y0, z0, ...`), input order.
    #[wasm_bindgen(js_name = pointsInGt)]
    pub fn points_in_gt(&self) -> Float64Array {
        points_f64(&self.inner.points_in_gt())
    }

    /// The same points as 32-bit floats (for WebGL buffers).
    #[wasm_bindgen(js_name = pointsInGtF32)]
    pub fn points_in_gt_f32(&self) -> Float32Array {
        points_f32(&self.inner.points_in_gt())
    }

    /// Unsigned distance of every point to the ground truth.
    pub fn distances(&self) -> Float64Array {
        Float64Array::from(self.inner.distances.as_slice())
    }

    /// Signed distances, when the options asked for them (mesh ground truth).
    #[wasm_bindgen(js_name = signedDistances)]
    pub fn signed_distances(&self) -> Option<Float64Array> {
        self.inner
            .signed_distances
            .as_ref()
            .map(|d| Float64Array::from(d.as_slice()))
    }

    /// Per-point status: 0 kept, 1 outside the crop volume, 2 farther than the max distance.
    pub fn status(&self) -> Uint8Array {
        let s: Vec<u8> = self.inner.status.iter().map(|s| *s as u8).collect();
        Uint8Array::from(s.as_slice())
    }

    /// Distances of the completeness samples (inside the crop volume) to the kept points.
    #[wasm_bindgen(js_name = completenessDistances)]
    pub fn completeness_distances(&self) -> Float64Array {
        Float64Array::from(self.inner.completeness_distances.as_slice())
    }

    /// The kept points' distances, ascending (NaN last), sorted in the core: what the page's
    /// precision curve and τ slider read.
    #[wasm_bindgen(js_name = sortedKeptDistances)]
    pub fn sorted_kept_distances(&self) -> Float64Array {
        Float64Array::from(self.inner.sorted_kept_distances().as_slice())
    }

    /// The completeness distances, ascending (NaN last).
    #[wasm_bindgen(js_name = sortedCompletenessDistances)]
    pub fn sorted_completeness_distances(&self) -> Float64Array {
        Float64Array::from(self.inner.sorted_completeness_distances().as_slice())
    }

    /// Heat-map colours (`r0, g0, b0, ...`, viridis) of every point, saturating at `clip`
    /// (the colours of the coloured PLY).
    pub fn colors(&self, clip: f64) -> Uint8Array {
        Uint8Array::from(distance_colors(&self.inner.distances, clip).as_flattened())
    }

    /// The kept points coloured by error as binary PLY, as `sfmeval eval --colored`.
    #[wasm_bindgen(js_name = coloredPly)]
    pub fn colored_ply(&self, clip: f64) -> Uint8Array {
        Uint8Array::from(export::colored_ply(&self.inner, clip).as_slice())
    }

    /// Per-point distances as CSV, as `sfmeval eval --csv`.
    pub fn csv(&self) -> String {
        export::distances_csv(&self.inner)
    }

    /// The completeness samples used (inside the crop volume), `x0, y0, z0, ...`, as 32-bit
    /// floats (WebGL), in the order of `completenessDistances()`.
    #[wasm_bindgen(js_name = completenessPointsF32)]
    pub fn completeness_points_f32(&self) -> Float32Array {
        points_f32(&self.inner.completeness_points)
    }

    /// Per completeness sample: 0 covered, 1 missed (visible, not reconstructed within the
    /// report's `completeness_visible.labels_tau`), 2 unseen; `undefined` without depth maps.
    #[wasm_bindgen(js_name = sampleLabels)]
    pub fn sample_labels(&self) -> Option<Uint8Array> {
        self.inner.sample_labels.as_ref().map(|l| {
            let flat: Vec<u8> = l.iter().map(|&x| x as u8).collect();
            Uint8Array::from(flat.as_slice())
        })
    }

    /// Per reconstructed point, its track-based true error (NaN where not measured);
    /// `undefined` without depth maps or tracks.
    #[wasm_bindgen(js_name = trackErrors)]
    pub fn track_errors(&self) -> Option<Float64Array> {
        self.inner.track_errors.as_ref().map(|t| {
            let flat: Vec<f64> = t.iter().map(|e| e.unwrap_or(f64::NAN)).collect();
            Float64Array::from(flat.as_slice())
        })
    }

    /// The accuracy 95th percentile: the default colour clip of the CLI.
    #[wasm_bindgen(js_name = defaultClip)]
    pub fn default_clip(&self) -> f64 {
        self.inner.report.accuracy.stats.percentiles.p95
    }

    /// `gt_from_recon`, row-major, 16 numbers.
    #[wasm_bindgen(js_name = gtFromRecon)]
    pub fn gt_from_recon(&self) -> Vec<f64> {
        self.inner
            .report
            .alignment
            .gt_from_recon
            .iter()
            .flatten()
            .copied()
            .collect()
    }
}

/// Aligns and measures `recon` against `gt` (with its cameras when attached), as
/// `sfmeval eval`. `options` holds the core's
/// `EvalOptions` fields (`tau`, `tau_percent_of_diagonal`, `samples`, `seed`, `signed`,
/// `histogram_bins`, `crop`) plus `align`, `transform` and `pairs` (as the CLI's flags).
/// `progress(stage, done, total)` is called during the long steps.
#[wasm_bindgen]
pub fn evaluate(
    gt: &mut GroundTruth,
    recon: &Reconstruction,
    options: JsValue,
    progress: Option<Function>,
) -> Result<Evaluation, JsError> {
    let (eval, align) = parse_options(options)?;
    eval.validate().map_err(|e| js_err("options", e))?;
    let request = EvalRequest {
        align: align_request(align)?,
        eval,
        ..EvalRequest::default()
    };
    let _guard = CallbackGuard::set(progress);
    let bar = JsProgress;
    let inner = pipeline::run(&mut gt.dataset, &recon.input, &request, &bar).map_err(|e| {
        if e.concerns_point_pairs() {
            js_err("options.pairs", e)
        } else {
            js_err(&format!("evaluating '{}'", recon.input.name), e)
        }
    })?;
    // as the runner's report: every protocol with its defaults, none when one cannot score
    let poses = match (gt.dataset.cameras(), &recon.input.model) {
        (Some(g), Some(e)) => sfmeval_table::PoseReports::evaluate(g, e)
            .ok()
            .and_then(|p| p.row_poses()),
        _ => None,
    };
    Ok(Evaluation { inner, poses })
}

/// Parses and validates a crop file (`sfmeval.crop/1`) and returns it as a plain object.
#[wasm_bindgen(js_name = parseCrop)]
pub fn parse_crop(text: &str) -> Result<JsValue, JsError> {
    let crop = Crop::parse(text.as_bytes()).map_err(|e| js_err("", e))?;
    crop.serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| js_err("crop", e.to_string()))
}

/// Validates a crop object and returns the text of its crop file, as the CLI reads it.
#[wasm_bindgen(js_name = cropFile)]
pub fn crop_file(crop: JsValue) -> Result<String, JsError> {
    let crop: Crop = serde_wasm_bindgen::from_value(crop).map_err(|e| js_err("crop", e))?;
    crop.validate().map_err(|e| js_err("", e))?;
    Ok(crop.to_file_json() + "\n")
}

/// Parses a transform (16 numbers as text, or JSON) into a row-major 4×4 similarity.
#[wasm_bindgen(js_name = parseTransform)]
pub fn parse_transform_text(text: &str) -> Result<Vec<f64>, JsError> {
    let t = Similarity::parse(text.as_bytes()).map_err(|e| js_err("transform", e))?;
    Ok(t.matrix.iter().flatten().copied().collect())
}

/// Parses a point-pairs file (`{"pairs": [{"recon": [x,y,z], "gt": [x,y,z]}, ...]}`).
#[wasm_bindgen(js_name = parsePointPairs)]
pub fn parse_point_pairs_text(text: &str) -> Result<JsValue, JsError> {
    let pairs = parse_point_pairs(text.as_bytes()).map_err(|e| js_err("", e))?;
    pairs
        .serialize(&serde_wasm_bindgen::Serializer::json_compatible())
        .map_err(|e| js_err("point pairs", e.to_string()))
}

/// The messages of notes, for a loader's line in the page.
fn messages(notes: &[sfmeval::note::Note]) -> Vec<String> {
    notes.iter().map(|n| n.message.clone()).collect()
}
