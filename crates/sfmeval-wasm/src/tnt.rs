//! The Tanks and Temples protocol (`sfmeval-tnt`) on a scene's files as bytes: the
//! `sfmeval.tanksandtemples/2` report byte for byte what `sfmeval tnt --json` prints for the same
//! files (the CLI given the scene folder by its name, `--scene SCENE`), its summary, and the files
//! the CLI writes beside it (the coloured clouds, the toolbox's texts, the precision/recall plot
//! as SVG; no PNG here).

use std::cell::RefCell;
use std::collections::BTreeMap;

use js_sys::{Object, Uint8Array};
use serde::Deserialize;
use sfmeval::files::FileSource;
use sfmeval::pipeline;
use sfmeval_tnt::{
    self as tnt, IcpCriteria, Registration, Scene, TntEvaluation, TntRequest,
    TrajectoryAlignmentOptions,
};
use wasm_bindgen::prelude::*;

use crate::{files_of, js_err};

/// The scene's files, each handed over (moved, not copied) the one time the scene's reader asks
/// for it: a ground truth of millions of points is in memory as bytes once.
struct TakeOnRead(RefCell<BTreeMap<String, Vec<u8>>>);

impl FileSource for TakeOnRead {
    fn read(&self, path: &str) -> sfmeval::Result<Option<Vec<u8>>> {
        Ok(self.0.borrow_mut().remove(path))
    }

    fn list(&self, dir: &str) -> sfmeval::Result<Vec<String>> {
        self.0.borrow().list(dir)
    }

    fn is_dir(&self, path: &str) -> bool {
        self.0.borrow().is_dir(path)
    }
}

/// The options of [`evaluate_tnt`], as `sfmeval tnt`'s flags.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TntJsOptions {
    /// τ in ground-truth units (default: the scene's, from the benchmark's table).
    #[serde(default)]
    tau: Option<f64>,
    /// The trajectory alignment's RANSAC seed.
    #[serde(default)]
    seed: Option<u64>,
}

/// Which of `names` (a JSON array of file names or paths) are the scene's files: `{scene,
/// ground_truth, crop, alignment, reference_trajectory, mapping, trajectory, reconstruction,
/// missing, problems, ignored, inputs, summary}` (`sfmeval_tnt::recognise`).
#[wasm_bindgen(js_name = tntFiles)]
pub fn tnt_files(names_json: &str) -> Result<JsValue, JsError> {
    let names: Vec<String> =
        serde_json::from_str(names_json).map_err(|e| js_err("Tanks and Temples file names", e))?;
    crate::table::to_js("Tanks and Temples files", &tnt::recognise(&names))
}

/// One Tanks and Temples evaluation: the report and what its files are made from.
#[wasm_bindgen]
pub struct TntResult {
    evaluation: TntEvaluation,
}

#[wasm_bindgen]
impl TntResult {
    /// The `sfmeval.tanksandtemples/2` JSON, byte for byte what `sfmeval tnt --json` prints.
    #[wasm_bindgen(getter, js_name = reportJson)]
    pub fn report_json(&self) -> String {
        self.evaluation.report_json()
    }

    /// The summary `sfmeval tnt` prints, without its last line (where the files went).
    #[wasm_bindgen(getter)]
    pub fn summary(&self) -> String {
        self.evaluation.report.summary()
    }

    /// The summary's lines (scene and τ, registration, precision / recall / F-score, notes).
    #[wasm_bindgen(getter, js_name = summaryLines)]
    pub fn summary_lines(&self) -> Vec<String> {
        self.evaluation.report.summary_lines()
    }

    /// The precision/recall plot (SVG text), as `sfmeval tnt` writes it.
    #[wasm_bindgen(getter, js_name = plotSvg)]
    pub fn plot_svg(&self) -> String {
        tnt::pr_svg(&self.evaluation.report)
    }

    /// The names of the files `sfmeval tnt` writes beside the report (no PNG): the coloured
    /// clouds, the toolbox's texts and the plot's SVG.
    #[wasm_bindgen(js_name = fileNames)]
    pub fn file_names(&self) -> Vec<String> {
        let r = &self.evaluation.report;
        let name = &r.protocol.scene;
        let mut out = vec![
            format!("{name}.precision.ply"),
            format!("{name}.recall.ply"),
        ];
        for (suffix, _) in self.evaluation.toolbox_texts() {
            out.push(format!("{name}{suffix}"));
        }
        out.push(format!("{}.svg", tnt::plot_stem(name, r.protocol.tau)));
        out
    }

    /// The bytes of one of [`Self::file_names`], made when asked for.
    pub fn file(&self, file_name: &str) -> Result<Uint8Array, JsError> {
        let r = &self.evaluation.report;
        let name = &r.protocol.scene;
        let bytes = if file_name == format!("{name}.precision.ply") {
            self.evaluation.precision_ply()
        } else if file_name == format!("{name}.recall.ply") {
            self.evaluation.recall_ply()
        } else if file_name == format!("{}.svg", tnt::plot_stem(name, r.protocol.tau)) {
            tnt::pr_svg(r).into_bytes()
        } else {
            self.evaluation
                .toolbox_texts()
                .into_iter()
                .find(|(suffix, _)| file_name == format!("{name}{suffix}"))
                .map(|(_, text)| text.into_bytes())
                .ok_or_else(|| JsError::new(&format!("no output file '{file_name}'")))?
        };
        Ok(Uint8Array::from(bytes.as_slice()))
    }
}

/// The Tanks and Temples protocol on a scene's files, as `sfmeval tnt --scene SCENE`: `files`
/// is `{name: Uint8Array}` with `SCENE.ply`, `SCENE.json`, `SCENE_trans.txt`,
/// `SCENE_COLMAP_SfM.log` (and `SCENE_mapping_reference.txt` for a video scene), the
/// reconstruction's trajectory (any other `.log`) and the reconstruction (any other `.ply`),
/// recognised by [`tnt_files`]. `options`: `tau`, `seed`.
#[wasm_bindgen(js_name = evaluateTnt)]
pub fn evaluate_tnt(files: &Object, options: JsValue) -> Result<TntResult, JsError> {
    let mut files: BTreeMap<String, Vec<u8>> = files_of(files)?;
    let o: TntJsOptions = if options.is_undefined() || options.is_null() {
        serde_json::from_str("{}").map_err(|e| js_err("options", e))?
    } else {
        serde_wasm_bindgen::from_value(options).map_err(|e| js_err("options", e.to_string()))?
    };
    let names: Vec<&String> = files.keys().collect();
    let found = tnt::recognise(&names);
    if !found.complete() {
        let mut why = found.problems.clone();
        if !found.missing.is_empty() {
            why.push(format!("missing {}", found.missing.join("; ")));
        }
        return Err(JsError::new(&format!(
            "Tanks and Temples files: {}",
            why.join("; ")
        )));
    }
    let (Some(scene_name), Some(recon), Some(log)) = (
        found.scene.clone(),
        found.reconstruction.clone(),
        found.trajectory.clone(),
    ) else {
        return Err(JsError::new("Tanks and Temples files: incomplete"));
    };
    // the scene's files in a folder named after the scene, as the CLI reads `--scene SCENE`
    let mut scene_files = BTreeMap::new();
    for part in [
        &found.ground_truth,
        &found.crop,
        &found.alignment,
        &found.reference_trajectory,
        &found.mapping,
    ]
    .into_iter()
    .flatten()
    {
        if let Some(bytes) = files.remove(part) {
            let base = part.rsplit(['/', '\\']).next().unwrap_or(part);
            scene_files.insert(format!("{scene_name}/{base}"), bytes);
        }
    }
    let scene = Scene::read(&TakeOnRead(RefCell::new(scene_files)), &scene_name, None)
        .map_err(|e| js_err("", e))?;
    let trajectory = tnt::read_log(files.get(&log).map(Vec::as_slice).unwrap_or_default())
        .map_err(|e| js_err(&format!("trajectory '{log}'"), e))?;
    let recon_base = recon
        .rsplit(['/', '\\'])
        .next()
        .unwrap_or(&recon)
        .to_string();
    let recon_bytes = files.remove(&recon).unwrap_or_default();
    let input = pipeline::read_reconstruction(
        &recon_base,
        &BTreeMap::from([(recon_base.clone(), recon_bytes)]),
    )
    .map_err(|e| js_err(&format!("reconstruction '{recon}'"), e))?;
    let request = TntRequest {
        tau: o.tau,
        registration: Registration::Protocol {
            trajectory,
            trajectory_name: log.rsplit(['/', '\\']).next().unwrap_or(&log).to_string(),
            options: TrajectoryAlignmentOptions {
                seed: o.seed.unwrap_or(0),
                ..Default::default()
            },
        },
        icp: IcpCriteria::TOOLBOX,
    };
    let mut evaluation = tnt::evaluate(
        &scene,
        &recon_base,
        &input.cloud.points.as_f64(),
        &request,
        &sfmeval::progress::NoProgress,
    )
    .map_err(|e| js_err(&format!("reconstruction '{recon}'"), e))?;
    evaluation.report.notes.splice(0..0, input.notes);
    Ok(TntResult { evaluation })
}
