//! ETH3D's multi-view evaluation (`sfmeval-eth3d`) on a scene's files as bytes: the
//! `sfmeval.eth3d/1` report byte for byte what `sfmeval eth3d --json` prints for the same files
//! and options (the CLI run in the project's folder, which names the scans as the project
//! writes them), its summary and per-tolerance table, and the tool's coloured clouds.

use std::collections::BTreeMap;

use js_sys::{Object, Uint8Array};
use serde::Deserialize;
use sfmeval_eth3d::{
    self as eth3d, Eth3dEvaluation, Eth3dOptions, Eth3dReport, Eth3dScene, NamedBytes,
};
use wasm_bindgen::prelude::*;

use crate::{files_of, js_err};

/// The options of [`evaluate_eth3d`], as `sfmeval eth3d`'s flags (m, degrees).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Eth3dJsOptions {
    #[serde(default)]
    tolerances: Option<Vec<f64>>,
    #[serde(default)]
    voxel_size: Option<f32>,
    #[serde(default)]
    beam_start_radius: Option<f32>,
    #[serde(default)]
    beam_divergence_halfangle_deg: Option<f32>,
}

/// Which of `names` (a JSON array of file names or paths) are the scene's files: `{project,
/// scans: [{filename, file}], reconstruction, missing, problems, ignored, inputs, summary: {line, status, complete, problem}}`
/// (`sfmeval_eth3d::recognise`); `project` the project's bytes once it is known (the scans are
/// matched to the names it gives them).
#[wasm_bindgen(js_name = eth3dFiles)]
pub fn eth3d_files(names_json: &str, project: Option<Uint8Array>) -> Result<JsValue, JsError> {
    let names: Vec<String> =
        serde_json::from_str(names_json).map_err(|e| js_err("ETH3D file names", e))?;
    let bytes = project.map(|p| p.to_vec());
    crate::table::to_js("ETH3D files", &eth3d::recognise(&names, bytes.as_deref()))
}

/// One ETH3D evaluation: the report and what its coloured clouds are made from.
#[wasm_bindgen]
pub struct Eth3dResult {
    report: Eth3dReport,
    evaluation: Eth3dEvaluation,
    reconstruction: Vec<[f32; 3]>,
}

#[wasm_bindgen]
impl Eth3dResult {
    /// The `sfmeval.eth3d/1` JSON, byte for byte what `sfmeval eth3d --json` prints.
    #[wasm_bindgen(getter, js_name = reportJson)]
    pub fn report_json(&self) -> String {
        self.report.to_json()
    }

    /// The summary `sfmeval eth3d` prints (without `--out`).
    #[wasm_bindgen(getter)]
    pub fn summary(&self) -> String {
        self.report.summary()
    }

    /// The summary's first line (points, scans, voxel size).
    #[wasm_bindgen(getter)]
    pub fn headline(&self) -> String {
        self.report.headline()
    }

    /// The per-tolerance table, `{columns, rows}` (cell texts from the core).
    #[wasm_bindgen(getter)]
    pub fn table(&self) -> Result<JsValue, JsError> {
        crate::table::to_js("ETH3D table", &self.report.table())
    }

    /// The tolerances, smallest first (the index of [`Self::accuracy_ply`]).
    #[wasm_bindgen(getter)]
    pub fn tolerances(&self) -> Vec<f32> {
        self.evaluation.tolerances.clone()
    }

    /// The names the tool gives tolerance `t`'s clouds, `[accuracy, completeness]`
    /// (`accuracy.tolerance_T.ply`, `completeness.tolerance_T.ply`).
    #[wasm_bindgen(js_name = cloudNames)]
    pub fn cloud_names(&self, t: usize) -> Vec<String> {
        let tol = self.evaluation.tolerances.get(t).copied().unwrap_or(0.0);
        vec![
            eth3d::vis::file_name("accuracy", tol),
            eth3d::vis::file_name("completeness", tol),
        ]
    }

    /// Tolerance `t`'s accuracy cloud, the reconstruction coloured as the tool colours it.
    #[wasm_bindgen(js_name = accuracyPly)]
    pub fn accuracy_ply(&self, t: usize) -> Result<Uint8Array, JsError> {
        self.check(t)?;
        let bytes = eth3d::vis::accuracy_ply(&self.evaluation, &self.reconstruction, t);
        Ok(Uint8Array::from(bytes.as_slice()))
    }

    /// Tolerance `t`'s completeness cloud, the scan points coloured as the tool colours them.
    #[wasm_bindgen(js_name = completenessPly)]
    pub fn completeness_ply(&self, t: usize) -> Result<Uint8Array, JsError> {
        self.check(t)?;
        let bytes = eth3d::vis::completeness_ply(&self.evaluation, t);
        Ok(Uint8Array::from(bytes.as_slice()))
    }
}

impl Eth3dResult {
    fn check(&self, t: usize) -> Result<(), JsError> {
        if t < self.evaluation.tolerances.len() {
            Ok(())
        } else {
            Err(JsError::new(&format!(
                "tolerance index {t} out of range: {} tolerances",
                self.evaluation.tolerances.len()
            )))
        }
    }
}

/// ETH3D's evaluation of a scene's files, as `sfmeval eth3d`: `files` is `{name: Uint8Array}`
/// with the MeshLab project (`.mlp`), the scan PLYs it names and the reconstruction PLY (any
/// other `.ply`), recognised by [`eth3d_files`]; the report names the project and the
/// reconstruction as given and the scans as the project writes them. `options`: `tolerances`
/// (m), `voxel_size`, `beam_start_radius` (m), `beam_divergence_halfangle_deg`.
#[wasm_bindgen(js_name = evaluateEth3d)]
pub fn evaluate_eth3d(files: &Object, options: JsValue) -> Result<Eth3dResult, JsError> {
    let files: BTreeMap<String, Vec<u8>> = files_of(files)?;
    let o: Eth3dJsOptions = if options.is_undefined() || options.is_null() {
        serde_json::from_str("{}").map_err(|e| js_err("options", e))?
    } else {
        serde_wasm_bindgen::from_value(options).map_err(|e| js_err("options", e.to_string()))?
    };
    let names: Vec<&String> = files.keys().collect();
    let project_bytes = names
        .iter()
        .find(|n| eth3d::recognise(&[n.as_str()], None).project.is_some())
        .and_then(|n| files.get(n.as_str()));
    let found = eth3d::recognise(&names, project_bytes.map(Vec::as_slice));
    if !found.complete() {
        let mut why = found.problems.clone();
        if !found.missing.is_empty() {
            why.push(format!("missing {}", found.missing.join("; ")));
        }
        return Err(JsError::new(&format!("ETH3D files: {}", why.join("; "))));
    }
    let (Some(project), Some(recon)) = (found.project.as_ref(), found.reconstruction.as_ref())
    else {
        return Err(JsError::new("ETH3D files: incomplete"));
    };
    let bytes = |name: &str| files.get(name).map(Vec::as_slice).unwrap_or_default();
    let mut scans = found.scans.iter();
    let scene = Eth3dScene::read(
        NamedBytes {
            name: project,
            bytes: bytes(project),
        },
        |_| {
            scans
                .next()
                .map(|s| NamedBytes {
                    name: &s.filename,
                    bytes: bytes(&s.file),
                })
                .ok_or_else(|| sfmeval::Error::InvalidContent("a scan is missing".into()))
        },
    )
    .map_err(|e| js_err("", e))?;
    let reconstruction = eth3d::scene::read_points_f32(bytes(recon))
        .map_err(|e| js_err(&format!("reconstruction '{recon}'"), e))?;
    if reconstruction.is_empty() {
        return Err(JsError::new(&format!(
            "reconstruction '{recon}': the PLY has no vertices"
        )));
    }
    let options = Eth3dOptions {
        tolerances: o.tolerances.map_or_else(
            || eth3d::DEFAULT_TOLERANCES.to_vec(),
            |v| v.iter().map(|&t| t as f32).collect(),
        ),
        voxel_size: o.voxel_size.unwrap_or(eth3d::VOXEL_SIZE),
        beam_start_radius: o.beam_start_radius.unwrap_or(eth3d::BEAM_START_RADIUS),
        beam_divergence_halfangle_deg: o
            .beam_divergence_halfangle_deg
            .unwrap_or(eth3d::BEAM_DIVERGENCE_HALFANGLE_DEG),
    };
    let evaluation = eth3d::evaluate(&scene, &reconstruction, &options)
        .map_err(|e| js_err(&format!("reconstruction '{recon}'"), e))?;
    let report = Eth3dReport::new(&evaluation, &scene, project, recon);
    Ok(Eth3dResult {
        report,
        evaluation,
        reconstruction,
    })
}
