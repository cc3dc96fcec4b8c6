//! The camera-pose benchmark protocols (`sfmeval poses --protocol colmap|imc|co3d`) on the
//! ground-truth cameras' and the estimated model's files as bytes: the `sfmeval.poses/1` report
//! byte for byte what `sfmeval poses --json` prints for the same files and options, the summary
//! it prints otherwise (also as rows for the page's table) and the `--pairs` CSV.

use std::collections::BTreeMap;

use js_sys::Object;
use serde::Deserialize;
use sfmeval::pipeline;
use sfmeval::pose::{PosesReport, Protocol, ProtocolOptions, evaluate_protocol};
use wasm_bindgen::prelude::*;

use crate::{files_of, js_err};

/// The options of [`evaluate_poses`], as `sfmeval poses`' flags.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PosesJsOptions {
    /// `colmap`, `imc` or `co3d`.
    protocol: String,
    /// COLMAP: the ground truth's position accuracy (GT units), `--position-accuracy`.
    #[serde(default)]
    position_accuracy: Option<f64>,
}

/// One protocol's evaluation: the report, its summary and the scored pairs.
#[wasm_bindgen]
pub struct PosesEvaluation {
    report: PosesReport,
    pairs_csv: String,
}

#[wasm_bindgen]
impl PosesEvaluation {
    /// The `sfmeval.poses/1` JSON, byte for byte what `sfmeval poses --json` prints.
    #[wasm_bindgen(getter, js_name = reportJson)]
    pub fn report_json(&self) -> String {
        self.report.to_json()
    }

    /// The summary `sfmeval poses` prints (one line per row of [`Self::summary_rows`]).
    #[wasm_bindgen(getter)]
    pub fn summary(&self) -> String {
        self.report.summary()
    }

    /// The summary as rows `[{label, text}]`: counts, the protocol's numbers, the convention
    /// and the notes, worded by the core.
    #[wasm_bindgen(getter, js_name = summaryRows)]
    pub fn summary_rows(&self) -> Result<JsValue, JsError> {
        crate::table::to_js("summary", &self.report.summary_rows())
    }

    /// Every scored ground-truth pair's errors, the CSV `sfmeval poses --pairs` writes.
    #[wasm_bindgen(getter, js_name = pairsCsv)]
    pub fn pairs_csv(&self) -> String {
        self.pairs_csv.clone()
    }
}

/// The name a set of files goes by in messages: the one file's name, else the names joined.
fn files_name(files: &BTreeMap<String, Vec<u8>>) -> String {
    files.keys().cloned().collect::<Vec<_>>().join(", ")
}

/// One pose protocol, as `sfmeval poses`: `gt_files` (`{name: Uint8Array}`) the ground-truth
/// cameras (a dataset's `cameras.json` or any model the core reads), `recon_files` the estimated
/// model's files (COLMAP `cameras/images/points3D` `.bin`/`.txt`, `.nvm`, Bundler `.out` +
/// `list.txt`, `sfm_data.json`, `cameras.json`); `options`: `{protocol, position_accuracy}`.
#[wasm_bindgen(js_name = evaluatePoses)]
pub fn evaluate_poses(
    gt_files: &Object,
    recon_files: &Object,
    options: JsValue,
) -> Result<PosesEvaluation, JsError> {
    let o: PosesJsOptions =
        serde_wasm_bindgen::from_value(options).map_err(|e| js_err("options", e.to_string()))?;
    let protocol = Protocol::parse(&o.protocol).map_err(|e| js_err("options.protocol", e))?;
    let gt_files = files_of(gt_files)?;
    let recon_files = files_of(recon_files)?;
    let gt_name = files_name(&gt_files);
    let recon_name = files_name(&recon_files);
    let gt = sfmeval::model::read_model_files(&gt_files)
        .map_err(|e| js_err(&format!("ground-truth cameras '{gt_name}'"), e))?;
    let est = pipeline::read_reconstruction(&recon_name, &recon_files)
        .map_err(|e| js_err(&format!("reconstruction '{recon_name}'"), e))?;
    let est = est.model.ok_or_else(|| {
        JsError::new(&format!(
            "reconstruction '{recon_name}' has no cameras (a bare point cloud)"
        ))
    })?;
    let options = ProtocolOptions {
        colmap_position_accuracy: o.position_accuracy.unwrap_or(0.0),
        ..ProtocolOptions::default()
    };
    let report = evaluate_protocol(&gt, &est, protocol, &options)
        .map_err(|e| js_err(&format!("poses of '{recon_name}' against '{gt_name}'"), e))?;
    Ok(PosesEvaluation {
        pairs_csv: report.pairs_csv(&gt),
        report,
    })
}
