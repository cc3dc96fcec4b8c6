//! Camera poses for the viewer's frusta: per registered image its centre, orientation and
//! field of view as numbers (the page draws them), and the error colours of the points' map.

use js_sys::{Float64Array, Uint8Array};
use sfmeval::colormap::distance_color;
use sfmeval::model::Reconstruction as Model;
use wasm_bindgen::prelude::*;

use crate::{Evaluation, GroundTruth, Reconstruction};

/// Numbers per camera in [`poses`].
pub const POSE_STRIDE: usize = 14;

/// Per image of `model`, 14 numbers: the centre (3), the rotation `world_from_cam` row-major (9;
/// OpenCV axes: x right, y down, z forward) and the tangents of the half field of view along x
/// and y (0 when the camera's size or focal length is unknown), in the model's frame.
fn poses(model: &Model) -> Float64Array {
    let mut out = Vec::with_capacity(model.images.len() * POSE_STRIDE);
    for im in &model.images {
        out.extend(im.center());
        let r = im.cam_from_world.rotation;
        for i in 0..3 {
            for row in &r {
                out.push(row[i]);
            }
        }
        let cam = model.cameras.iter().find(|c| c.id == im.camera_id);
        let tan = |size: u64, f: f64| {
            if size > 0 && f > 0.0 {
                size as f64 / 2.0 / f
            } else {
                0.0
            }
        };
        out.push(cam.map_or(0.0, |c| tan(c.width, c.fx)));
        out.push(cam.map_or(0.0, |c| tan(c.height, c.fy)));
    }
    Float64Array::from(out.as_slice())
}

fn names(model: &Model) -> Vec<String> {
    model.images.iter().map(|i| i.name.clone()).collect()
}

#[wasm_bindgen]
impl GroundTruth {
    /// The ground-truth cameras' poses (14 numbers each: centre, `world_from_cam` row-major,
    /// tangents of the half field of view in x and y), empty without cameras.
    #[wasm_bindgen(js_name = cameraPoses)]
    pub fn camera_poses(&self) -> Float64Array {
        self.dataset
            .cameras()
            .map_or_else(|| Float64Array::new_with_length(0), poses)
    }

    /// The ground-truth images' names, in the order of `cameraPoses()`.
    #[wasm_bindgen(js_name = cameraNames)]
    pub fn camera_names(&self) -> Vec<String> {
        self.dataset.cameras().map(names).unwrap_or_default()
    }
}

#[wasm_bindgen]
impl Reconstruction {
    /// The registered images' poses in the reconstruction's own frame (14 numbers each, as
    /// `GroundTruth.cameraPoses()`), empty for a bare cloud.
    #[wasm_bindgen(js_name = cameraPoses)]
    pub fn camera_poses(&self) -> Float64Array {
        self.input
            .model
            .as_ref()
            .map_or_else(|| Float64Array::new_with_length(0), poses)
    }

    /// The registered images' names, in the order of `cameraPoses()`.
    #[wasm_bindgen(js_name = cameraNames)]
    pub fn camera_names(&self) -> Vec<String> {
        self.input.model.as_ref().map(names).unwrap_or_default()
    }
}

/// The viewer's colours (`r0, g0, b0, ...`, viridis saturating at `clip`, as the points' map)
/// of any values, e.g. the cameras' centre errors; NaN values are grey.
#[wasm_bindgen(js_name = errorColors)]
pub fn error_colors(values: &[f64], clip: f64) -> Uint8Array {
    let flat: Vec<u8> = values
        .iter()
        .flat_map(|&v| {
            if v.is_nan() {
                [128, 128, 128]
            } else {
                distance_color(v, clip)
            }
        })
        .collect();
    Uint8Array::from(flat.as_slice())
}

/// The clip of the estimated frusta's colours: the camera-centre errors' 95th percentile, as the
/// points' map clips at the accuracy's (`Evaluation.defaultClip()`).
fn camera_clip(cams: &sfmeval::report::CamerasSection) -> f64 {
    cams.errors.center_error.percentiles.p95
}

#[wasm_bindgen]
impl Evaluation {
    /// The colour clip of the estimated cameras (the centre errors' 95th percentile, GT units),
    /// `undefined` without pose errors.
    #[wasm_bindgen(js_name = cameraClip)]
    pub fn camera_clip(&self) -> Option<f64> {
        self.inner.report.cameras.as_ref().map(camera_clip)
    }

    /// Per registered image of `recon` (the order of its `cameraPoses()`), its camera-centre
    /// error (NaN when no ground-truth image has its name), as the report lists them.
    #[wasm_bindgen(js_name = cameraErrors)]
    pub fn camera_errors(&self, recon: &Reconstruction) -> Float64Array {
        Float64Array::from(self.errors_of(recon).as_slice())
    }

    /// The estimated frusta's colours (`r0, g0, b0, ...`, the order of `recon.cameraPoses()`):
    /// the centre error in the points' colour map clipped at [`Self::camera_clip`], grey where no
    /// ground-truth image has the name; empty without pose errors.
    #[wasm_bindgen(js_name = cameraColors)]
    pub fn camera_colors(&self, recon: &Reconstruction) -> Uint8Array {
        match self.inner.report.cameras.as_ref() {
            Some(cams) => error_colors(&self.errors_of(recon), camera_clip(cams)),
            None => Uint8Array::new_with_length(0),
        }
    }
}

impl Evaluation {
    fn errors_of(&self, recon: &Reconstruction) -> Vec<f64> {
        let Some(cams) = self.inner.report.cameras.as_ref() else {
            return Vec::new();
        };
        let by_name: std::collections::HashMap<&str, f64> = cams
            .errors
            .images
            .iter()
            .map(|im| (im.estimated_name.as_str(), im.center_error))
            .collect();
        recon
            .input
            .model
            .as_ref()
            .map(|m| {
                m.images
                    .iter()
                    .map(|im| by_name.get(im.name.as_str()).copied().unwrap_or(f64::NAN))
                    .collect()
            })
            .unwrap_or_default()
    }
}
