//! `cameras.json` (`sfmeval.cameras/1`, `docs/cameras-json.md`): the ground-truth cameras of a
//! dataset and the estimated cameras of a run, read by one reader. When a run's file holds
//! several sub-models (`model_index`), the largest is used and the others are listed.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::{Camera, Image, Reconstruction, Rigid};
use crate::error::{Error, Result};
use crate::note::{Code, Note};

const FMT: &str = "cameras.json";

/// The schema id this reader accepts.
pub(crate) const SCHEMA: &str = "sfmeval.cameras/1";

/// Where the expected format is described, appended to the schema errors.
const EXPECTED: &str = " (the expected format, with its cameras and images, is documented in \
                        docs/cameras-json.md)";

/// The top-level `schema` field alone (any JSON type), read before the rest.
#[derive(Deserialize)]
struct SchemaProbe {
    #[serde(default)]
    schema: Option<serde_json::Value>,
}

/// The rest of the file (its `schema` checked by [`SchemaProbe`]).
#[derive(Deserialize)]
struct File {
    #[serde(default)]
    frame: Option<String>,
    #[serde(default)]
    pixel_convention: Option<String>,
    cameras: Vec<JsonCamera>,
    images: Vec<JsonImage>,
}

#[derive(Deserialize)]
struct JsonCamera {
    id: u64,
    model: String,
    width: u64,
    height: u64,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    #[serde(default)]
    params: Vec<f64>,
}

#[derive(Deserialize)]
struct JsonImage {
    name: String,
    camera_id: u64,
    cam_from_world: JsonPose,
    #[serde(default)]
    model_index: Option<u64>,
}

#[derive(Deserialize)]
struct JsonPose {
    rotation: [[f64; 3]; 3],
    translation: [f64; 3],
}

/// Reads a `cameras.json`. The result's [`Reconstruction::notes`] mention a `frame` other
/// than `gltf` or `reconstruction`; rotations are checked to be rotations (orthonormal,
/// determinant +1, within a tolerance of 1e-4) and cameras and poses for sense
/// ([`Reconstruction::validate`]).
pub fn read_cameras_json(bytes: &[u8]) -> Result<Reconstruction> {
    let json_error = |e: serde_json::Error| {
        if e.is_eof() {
            Error::truncated(FMT, e.to_string())
        } else {
            Error::malformed(FMT, e.to_string())
        }
    };
    // The schema first, so that a JSON file of another kind (another tool's cameras, a report)
    // is told what is expected instead of the first field it lacks.
    let probe: SchemaProbe = serde_json::from_slice(bytes).map_err(json_error)?;
    match probe.schema {
        Some(serde_json::Value::String(s)) if s == SCHEMA => {}
        Some(serde_json::Value::String(s)) => {
            return Err(Error::unsupported(
                FMT,
                format!(
                    "schema '{}' is not '{SCHEMA}'{EXPECTED}",
                    super::text::clip(&s)
                ),
            ));
        }
        _ => {
            return Err(Error::unsupported(
                FMT,
                format!("not an sfmeval cameras file: no \"schema\": \"{SCHEMA}\"{EXPECTED}"),
            ));
        }
    }
    let file: File = serde_json::from_slice(bytes).map_err(json_error)?;
    if let Some(pc) = file.pixel_convention.as_ref().filter(|pc| *pc != "colmap") {
        return Err(Error::unsupported(
            FMT,
            format!(
                "pixel_convention '{}' (version 1 allows only 'colmap')",
                super::text::clip(pc)
            ),
        ));
    }
    let mut cameras = Vec::with_capacity(file.cameras.len());
    for c in file.cameras {
        if cameras.iter().any(|o: &Camera| o.id == c.id) {
            return Err(Error::malformed(
                FMT,
                format!("camera id {} appears twice", c.id),
            ));
        }
        // Full COLMAP parameter list when the model is a COLMAP one.
        let mut params = match super::colmap::camera_model_by_name(&c.model).map(|m| m.focal) {
            Some(super::colmap::FocalLayout::Single) => vec![c.fx, c.cx, c.cy],
            Some(super::colmap::FocalLayout::None) => Vec::new(),
            _ => vec![c.fx, c.fy, c.cx, c.cy],
        };
        params.extend(&c.params);
        if params.iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                format: FMT,
                what: "camera parameter",
                count: 1,
                first_index: cameras.len(),
            });
        }
        cameras.push(Camera {
            id: c.id,
            model: c.model,
            width: c.width,
            height: c.height,
            fx: c.fx,
            fy: c.fy,
            cx: c.cx,
            cy: c.cy,
            params,
        });
    }
    // Group images by model_index (absent = 0).
    let mut groups: BTreeMap<u64, Vec<Image>> = BTreeMap::new();
    for (i, im) in file.images.into_iter().enumerate() {
        if im.name.is_empty() {
            return Err(Error::malformed(
                FMT,
                format!("image #{i} has an empty name"),
            ));
        }
        if !cameras.iter().any(|c| c.id == im.camera_id) {
            return Err(Error::malformed(
                FMT,
                format!(
                    "image '{}' uses camera {} which is not listed",
                    super::text::clip(&im.name),
                    im.camera_id
                ),
            ));
        }
        let pose = Rigid {
            rotation: im.cam_from_world.rotation,
            translation: im.cam_from_world.translation,
        };
        if !pose.is_finite() {
            return Err(Error::NonFinite {
                format: FMT,
                what: "image pose",
                count: 1,
                first_index: i,
            });
        }
        if let Some(dev) = super::rotation_defect(&pose.rotation) {
            return Err(Error::out_of_range(
                FMT,
                format!("image '{}'", super::text::clip(&im.name)),
                "cam_from_world.rotation",
                dev,
            ));
        }
        let group = groups.entry(im.model_index.unwrap_or(0)).or_default();
        group.push(Image {
            id: i as u64,
            name: im.name,
            camera_id: im.camera_id,
            cam_from_world: pose,
            observations: Vec::new(),
        });
    }
    let frame_note = file.frame.filter(|f| f != "gltf" && f != "reconstruction");
    let models: Vec<(String, Reconstruction)> = if groups.is_empty() {
        vec![(String::from("model 0"), Reconstruction::new("cameras_json"))]
    } else {
        groups
            .into_iter()
            .map(|(k, images)| {
                let mut r = Reconstruction::new("cameras_json");
                r.images = images;
                (format!("model {k}"), r)
            })
            .collect()
    };
    let mut rec = super::choose_largest(models)?;
    rec.cameras = cameras;
    rec.validate(FMT, true)?;
    if let Some(f) = frame_note {
        rec.notes.push(
            Note::new(
                Code::UnknownCameraFrame,
                format!(
                    "cameras.json frame is '{}', not 'gltf' or 'reconstruction'",
                    super::text::clip(&f)
                ),
            )
            .with("frame", f.as_str()),
        );
    }
    Ok(rec)
}

/// The `frame` field of a `cameras.json` (`gltf` for ground truth, `reconstruction` for a run),
/// `None` when absent or unreadable.
#[cfg(test)]
pub(crate) fn frame_of(bytes: &[u8]) -> Option<String> {
    let v: serde_json::Value = serde_json::from_slice(bytes).ok()?;
    v.get("frame")?.as_str().map(str::to_string)
}

/// Writes a reconstruction's cameras and poses as `cameras.json` (`frame` = `reconstruction`
/// unless given). Sub-model images are not included (only this model's, `model_index` 0).
pub fn write_cameras_json(rec: &Reconstruction, frame: &str) -> String {
    let cameras: Vec<serde_json::Value> = rec
        .cameras
        .iter()
        .map(|c| {
            let mut v = serde_json::json!({
                "id": c.id, "model": c.model, "width": c.width, "height": c.height,
                "fx": c.fx, "fy": c.fy, "cx": c.cx, "cy": c.cy,
            });
            let skip = match super::colmap::camera_model_by_name(&c.model).map(|m| m.focal) {
                Some(super::colmap::FocalLayout::Single) => 3,
                Some(super::colmap::FocalLayout::Double) => 4,
                Some(super::colmap::FocalLayout::None) => 0,
                None => usize::MAX,
            };
            let extra: Vec<f64> = c.params.iter().skip(skip).copied().collect();
            if !extra.is_empty() {
                v["params"] = serde_json::json!(extra);
            }
            v
        })
        .collect();
    let images: Vec<serde_json::Value> = rec
        .images
        .iter()
        .map(|im| {
            serde_json::json!({
                "name": im.name, "camera_id": im.camera_id,
                "cam_from_world": {"rotation": im.cam_from_world.rotation, "translation": im.cam_from_world.translation},
                "center": im.center(),
            })
        })
        .collect();
    let doc = serde_json::json!({
        "schema": SCHEMA, "frame": frame, "pixel_convention": "colmap",
        "cameras": cameras, "images": images,
    });
    serde_json::to_string_pretty(&doc).unwrap_or_default()
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::model::fuzz_tests::fixture;

    #[test]
    fn ground_truth_fixture() {
        let r = read_cameras_json(&fixture("gt_cameras.json")).unwrap();
        assert_eq!(r.images.len(), 6);
        assert_eq!(r.cameras[0].fx, 210.0);
        assert_eq!(r.images[0].name, "0000.png");
        assert_eq!(
            frame_of(&fixture("gt_cameras.json")).as_deref(),
            Some("gltf")
        );
        // Camera 0 sits at 4.5 m from the z axis.
        let c = r.images[0].center();
        assert!(((c[0] * c[0] + c[1] * c[1]).sqrt() - 4.5).abs() < 1e-9);
    }

    #[test]
    fn round_trip_and_sub_models() {
        let r = read_cameras_json(&fixture("gt_cameras.json")).unwrap();
        let text = write_cameras_json(&r, "reconstruction");
        let back = read_cameras_json(text.as_bytes()).unwrap();
        assert_eq!(back.images.len(), r.images.len());
        for (a, b) in back.images.iter().zip(&r.images) {
            assert_eq!(a.name, b.name);
            for k in 0..3 {
                assert!(
                    (a.cam_from_world.translation[k] - b.cam_from_world.translation[k]).abs()
                        < 1e-15
                );
                for j in 0..3 {
                    assert!(
                        (a.cam_from_world.rotation[k][j] - b.cam_from_world.rotation[k][j]).abs()
                            < 1e-15
                    );
                }
            }
        }
        assert_eq!(back.cameras, r.cameras);
        // model_index: two sub-models, the larger wins.
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let imgs = v["images"].as_array_mut().unwrap();
        imgs[0]["model_index"] = 1.into();
        let r2 = read_cameras_json(v.to_string().as_bytes()).unwrap();
        assert_eq!(r2.images.len(), 5);
        assert_eq!(r2.num_models(), 2);
        assert_eq!(r2.sub_models[0].images, 1);
    }

    #[test]
    fn bad_inputs() {
        let ok = r#"{"schema":"sfmeval.cameras/1","cameras":[{"id":1,"model":"PINHOLE","width":4,"height":3,"fx":1,"fy":1,"cx":2,"cy":1.5}],"images":[IMG]}"#;
        let with = |img: &str| ok.replace("IMG", img);
        let pose =
            r#""cam_from_world":{"rotation":[[1,0,0],[0,1,0],[0,0,1]],"translation":[0,0,0]}"#;
        assert!(
            read_cameras_json(
                with(&format!(r#"{{"name":"a.jpg","camera_id":1,{pose}}}"#)).as_bytes()
            )
            .is_ok()
        );
        assert!(matches!(
            read_cameras_json(
                with(&format!(r#"{{"name":"a.jpg","camera_id":2,{pose}}}"#)).as_bytes()
            ),
            Err(Error::Malformed { .. })
        ));
        let mirrored = pose.replace("[0,0,1]]", "[0,0,-1]]");
        let e = read_cameras_json(
            with(&format!(r#"{{"name":"a.jpg","camera_id":1,{mirrored}}}"#)).as_bytes(),
        )
        .unwrap_err();
        assert_eq!(e.kind(), "out_of_range");
        let msg = e.to_string();
        assert!(
            msg.contains("image 'a.jpg'") && msg.contains("rotation") && msg.contains("reflection"),
            "{msg}"
        );
        // Finite but absurd values: each refused naming the image or camera and the field.
        let cases = [
            (
                with(&format!(
                    r#"{{"name":"a.jpg","camera_id":1,{}}}"#,
                    pose.replace("[0,0,0]", "[1e150,0,0]")
                )),
                "translation x",
            ),
            (
                with(&format!(
                    r#"{{"name":"a.jpg","camera_id":1,{}}}"#,
                    pose.replace("[1,0,0]", "[1e308,0,0]")
                )),
                "rotation",
            ),
            (
                with(&format!(
                    r#"{{"name":"a.jpg","camera_id":1,{}}}"#,
                    pose.replace("[1,0,0]", "[0.9,0,0]")
                )),
                "rotation",
            ),
            (
                with(&format!(r#"{{"name":"a.jpg","camera_id":1,{pose}}}"#))
                    .replace(r#""width":4"#, r#""width":18446744073709551615"#),
                "width",
            ),
            (
                with(&format!(r#"{{"name":"a.jpg","camera_id":1,{pose}}}"#))
                    .replace(r#""height":3"#, r#""height":0"#),
                "height",
            ),
            (
                with(&format!(r#"{{"name":"a.jpg","camera_id":1,{pose}}}"#))
                    .replace(r#""fx":1"#, r#""fx":-1"#),
                "focal length fx",
            ),
            (
                with(&format!(r#"{{"name":"a.jpg","camera_id":1,{pose}}}"#))
                    .replace(r#""fy":1"#, r#""fy":1e308"#),
                "focal length fy",
            ),
            (
                with(&format!(r#"{{"name":"a.jpg","camera_id":1,{pose}}}"#))
                    .replace(r#""cx":2"#, r#""cx":1e300"#),
                "principal point cx",
            ),
        ];
        for (text, field) in cases {
            let e = read_cameras_json(text.as_bytes()).unwrap_err();
            assert_eq!(e.kind(), "out_of_range", "{field}: {e}");
            let msg = e.to_string();
            assert!(msg.contains(field), "{field}: {msg}");
            assert!(
                msg.contains("image 'a.jpg'") || msg.contains("camera 1"),
                "{msg}"
            );
        }
        // Both sizes 0 (unknown) and a principal point outside the image: warnings.
        let unknown = with(&format!(r#"{{"name":"a.jpg","camera_id":1,{pose}}}"#))
            .replace(r#""width":4,"height":3"#, r#""width":0,"height":0"#);
        let r = read_cameras_json(unknown.as_bytes()).unwrap();
        assert!(
            r.notes
                .iter()
                .any(|w| w.message.contains("camera 1") && w.message.contains("unknown")),
            "{:?}",
            r.notes
        );
        let outside = with(&format!(r#"{{"name":"a.jpg","camera_id":1,{pose}}}"#))
            .replace(r#""cx":2"#, r#""cx":-50"#);
        let r = read_cameras_json(outside.as_bytes()).unwrap();
        assert!(
            r.notes.iter().any(|w| w
                .message
                .contains("camera 1: the principal point lies outside")),
            "{:?}",
            r.notes
        );
        // JSON has no NaN literal: a NaN pose is a parse error, never a panic.
        let nan = pose.replace("[0,0,0]", "[NaN,0,0]");
        assert!(
            read_cameras_json(
                with(&format!(r#"{{"name":"a.jpg","camera_id":1,{nan}}}"#)).as_bytes()
            )
            .is_err()
        );
        let huge = pose.replace("[0,0,0]", "[1e999,0,0]");
        assert!(
            read_cameras_json(
                with(&format!(r#"{{"name":"a.jpg","camera_id":1,{huge}}}"#)).as_bytes()
            )
            .is_err()
        );
        assert!(matches!(
            read_cameras_json(&ok.as_bytes()[..40]),
            Err(Error::Truncated { .. })
        ));
        assert!(matches!(
            read_cameras_json(
                ok.replace("cameras/1", "cameras/2")
                    .replace("IMG", "")
                    .as_bytes()
            ),
            Err(Error::Unsupported { .. })
        ));
        // A JSON file of another kind names the expected schema and its documentation, not the
        // first field it lacks (was: "missing field `schema` at line 2428").
        for other in [
            r#"{"frames":[{"file_path":"0000.jpg","transform_matrix":[]}],"camera_angle_x":0.7}"#,
            r#"{"schema":7,"cameras":[]}"#,
            r#"{"schema":"nerfstudio","cameras":[],"images":[]}"#,
        ] {
            let e = read_cameras_json(other.as_bytes()).unwrap_err();
            assert_eq!(e.kind(), "unsupported", "{e}");
            let msg = e.to_string();
            assert!(
                msg.starts_with("cameras.json: ")
                    && (msg.contains("'sfmeval.cameras/1'")
                        || msg.contains("\"sfmeval.cameras/1\""))
                    && msg.contains("docs/cameras-json.md")
                    && !msg.contains("missing field"),
                "{msg}"
            );
        }
        let empty = read_cameras_json(ok.replace("IMG", "").as_bytes()).unwrap();
        assert!(empty.images.is_empty());
    }
}
