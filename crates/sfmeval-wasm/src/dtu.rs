//! The DTU MVS evaluation (`sfmeval-dtu`) on a scan's files as bytes: the `sfmeval.dtu/1` report
//! byte for byte what `sfmeval dtu --report` writes for the same files and options, the summary
//! lines `sfmeval dtu` prints, and the evaluator's coloured error clouds.

use std::collections::BTreeMap;

use js_sys::{Object, Uint8Array};
use serde::Deserialize;
use sfmeval_dtu::{self as dtu, DtuMode, DtuOptions, DtuReport, DtuScan, NamedBytes, Shuffle};
use wasm_bindgen::prelude::*;

use crate::{files_of, js_err};

/// The options of [`evaluate_dtu`], as `sfmeval dtu`'s flags (mm).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DtuJsOptions {
    /// `auto`, `mesh` or `pcd`.
    #[serde(default)]
    mode: Option<String>,
    #[serde(default)]
    downsample_density: Option<f64>,
    #[serde(default)]
    patch_size: Option<f64>,
    #[serde(default)]
    max_dist: Option<f64>,
    #[serde(default)]
    visualize_threshold: Option<f64>,
    #[serde(default)]
    seed: Option<u64>,
    #[serde(default)]
    no_shuffle: bool,
}

/// Which of `names` (a JSON array of file names or paths) are the DTU scan's files: `{scan,
/// stl, obs_mask, plane, reconstruction, missing: [sentence], problems: [sentence], ignored, inputs, summary}`
/// (`sfmeval_dtu::recognise`: `stl{NNN}_total.ply`, `ObsMask{N}_10.mat`, `Plane{N}.mat`, any
/// other `.ply` the reconstruction).
#[wasm_bindgen(js_name = dtuFiles)]
pub fn dtu_files(names_json: &str) -> Result<JsValue, JsError> {
    let names: Vec<String> =
        serde_json::from_str(names_json).map_err(|e| js_err("DTU file names", e))?;
    crate::table::to_js("DTU files", &dtu::recognise(&names))
}

/// One DTU evaluation: the report and the error clouds.
#[wasm_bindgen]
pub struct DtuEvaluation {
    report: DtuReport,
    d2s: Vec<u8>,
    s2d: Vec<u8>,
    scan: u32,
}

#[wasm_bindgen]
impl DtuEvaluation {
    /// The `sfmeval.dtu/1` JSON, byte for byte what `sfmeval dtu --report` writes.
    #[wasm_bindgen(getter, js_name = reportJson)]
    pub fn report_json(&self) -> String {
        self.report.to_json()
    }

    /// The summary `sfmeval dtu` prints: the counts line, then mean accuracy, mean
    /// completeness and overall (one line each).
    #[wasm_bindgen(getter)]
    pub fn summary(&self) -> String {
        self.report.summary()
    }

    /// The summary's first line: the scan, the input's kind and the point counts.
    #[wasm_bindgen(getter, js_name = countsLine)]
    pub fn counts_line(&self) -> String {
        self.report.counts_line()
    }

    /// The summary's lines for mean accuracy, mean completeness and overall, in that order.
    #[wasm_bindgen(getter, js_name = resultLines)]
    pub fn result_lines(&self) -> Vec<String> {
        vec![
            self.report.accuracy_line().trim().to_string(),
            self.report.completeness_line().trim().to_string(),
            self.report.overall_line().trim().to_string(),
        ]
    }

    /// The evaluator's accuracy error cloud, `vis_NNN_d2s.ply` (`sfmeval dtu --vis-out`).
    #[wasm_bindgen(js_name = d2sPly)]
    pub fn d2s_ply(&self) -> Uint8Array {
        Uint8Array::from(self.d2s.as_slice())
    }

    /// The evaluator's completeness error cloud, `vis_NNN_s2d.ply`.
    #[wasm_bindgen(js_name = s2dPly)]
    pub fn s2d_ply(&self) -> Uint8Array {
        Uint8Array::from(self.s2d.as_slice())
    }

    /// The error clouds' file names, `[d2s, s2d]`, as `sfmeval dtu --vis-out` names them.
    #[wasm_bindgen(js_name = visNames)]
    pub fn vis_names(&self) -> Vec<String> {
        let (a, b) = dtu::vis::vis_names(self.scan);
        vec![a, b]
    }
}

/// The DTU evaluation of a scan's files, as `sfmeval dtu`: `files` is `{name: Uint8Array}` with
/// the STL points (`stl{NNN}_total.ply`), the observation mask (`ObsMask{N}_10.mat`), the
/// ground plane (`Plane{N}.mat`) and the reconstruction (any other `.ply`), recognised by
/// [`dtu_files`]; the scan number comes from their names and the report names the
/// reconstruction as given. `options`: `mode` (`auto`, `mesh`, `pcd`), `downsample_density`,
/// `patch_size`, `max_dist`, `visualize_threshold` (mm), `seed`, `no_shuffle`.
#[wasm_bindgen(js_name = evaluateDtu)]
pub fn evaluate_dtu(files: &Object, options: JsValue) -> Result<DtuEvaluation, JsError> {
    let files: BTreeMap<String, Vec<u8>> = files_of(files)?;
    let o: DtuJsOptions = if options.is_undefined() || options.is_null() {
        serde_json::from_str("{}").map_err(|e| js_err("options", e))?
    } else {
        serde_wasm_bindgen::from_value(options).map_err(|e| js_err("options", e.to_string()))?
    };
    let mode = match o.mode.as_deref() {
        None => DtuMode::Auto,
        Some(m) => m.parse().map_err(|e| js_err("options.mode", e))?,
    };
    let names: Vec<&String> = files.keys().collect();
    let found = dtu::recognise(&names);
    if !found.complete() {
        let mut why = found.problems.clone();
        if !found.missing.is_empty() {
            why.push(format!("missing {}", found.missing.join("; ")));
        }
        return Err(JsError::new(&format!("DTU files: {}", why.join("; "))));
    }
    let (Some(scan), Some(stl), Some(obs), Some(plane), Some(recon)) = (
        found.scan,
        found.stl.as_ref(),
        found.obs_mask.as_ref(),
        found.plane.as_ref(),
        found.reconstruction.as_ref(),
    ) else {
        return Err(JsError::new("DTU files: incomplete"));
    };
    let scan_files = DtuScan::read(named(&files, stl), named(&files, obs), named(&files, plane))
        .map_err(|e| js_err("", e))?;
    let (input, mesh) = dtu::read_reconstruction(named(&files, recon).bytes, mode)
        .map_err(|e| js_err(&format!("reconstruction '{recon}'"), e))?;
    let defaults = DtuOptions::default();
    let options = DtuOptions {
        downsample_density: o.downsample_density.unwrap_or(defaults.downsample_density),
        patch_size: o.patch_size.unwrap_or(defaults.patch_size),
        max_dist: o.max_dist.unwrap_or(defaults.max_dist),
        visualize_threshold: o
            .visualize_threshold
            .unwrap_or(defaults.visualize_threshold),
        shuffle: if o.no_shuffle {
            Shuffle::None
        } else {
            Shuffle::Seeded(o.seed.unwrap_or(0))
        },
    };
    let evaluation = dtu::evaluate(&scan_files, input, &options, &sfmeval::progress::NoProgress)
        .map_err(|e| js_err(&format!("reconstruction '{recon}'"), e))?;
    let report = DtuReport::new(&evaluation, scan, recon, mesh);
    Ok(DtuEvaluation {
        d2s: dtu::vis::d2s_ply(&evaluation),
        s2d: dtu::vis::s2d_ply(&evaluation, &scan_files.stl),
        report,
        scan,
    })
}

/// The bytes of file `name` of `files`, named.
fn named<'a>(files: &'a BTreeMap<String, Vec<u8>>, name: &'a str) -> NamedBytes<'a> {
    NamedBytes {
        name,
        bytes: files.get(name).map(Vec::as_slice).unwrap_or_default(),
    }
}
