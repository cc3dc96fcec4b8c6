//! OpenMVG `sfm_data.json` (cereal JSON, `research/formats.md`): `views`, `intrinsics`,
//! `extrinsics`, `structure`. Cereal maps are arrays of `{"key", "value"}`; polymorphic
//! intrinsics carry `polymorphic_name` only on the first of each type (later ones just the
//! numeric `polymorphic_id`), and a shared pointer's data only on its first occurrence.
//! Extrinsics give the rows of the world-to-camera rotation and the camera **centre**.
//! OpenMVG puts pixel centres on integer coordinates, so 0.5 is added to the principal point to
//! reach COLMAP's convention. Views without a pose are unregistered.

use std::collections::BTreeMap;

use serde_json::Value;

use super::{Camera, Image, Point3D, Reconstruction, Rigid};
use crate::error::{Error, Result};
use crate::geometry::{MAX_COORDINATE, show};
use crate::note::{Code, Note};

const FMT: &str = "OpenMVG sfm_data";

fn malformed(detail: impl Into<String>) -> Error {
    Error::malformed(FMT, detail)
}

fn num(v: &Value, what: &str) -> Result<f64> {
    let x = v
        .as_f64()
        .ok_or_else(|| malformed(format!("{what} is not a number")))?;
    if !x.is_finite() {
        return Err(Error::NonFinite {
            format: FMT,
            what: "value",
            count: 1,
            first_index: 0,
        });
    }
    Ok(x)
}

fn uint(v: &Value, what: &str) -> Result<u64> {
    v.as_u64()
        .ok_or_else(|| malformed(format!("{what} is not a non-negative integer")))
}

fn vec_n<const N: usize>(v: Option<&Value>, what: &str) -> Result<[f64; N]> {
    let a = v
        .and_then(Value::as_array)
        .filter(|a| a.len() == N)
        .ok_or_else(|| malformed(format!("{what} is not an array of {N} numbers")))?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = num(x, what)?;
    }
    Ok(out)
}

/// Entries of a cereal map (`[{"key": k, "value": v}, ...]`) as `(key, value)`.
fn cereal_map<'a>(root: &'a Value, field: &str) -> Result<Vec<(u64, &'a Value)>> {
    let Some(v) = root.get(field) else {
        return Ok(Vec::new());
    };
    let arr = v
        .as_array()
        .ok_or_else(|| malformed(format!("'{field}' is not an array")))?;
    arr.iter()
        .enumerate()
        .map(|(i, e)| {
            let key = e
                .get("key")
                .ok_or_else(|| malformed(format!("{field}[{i}] has no 'key'")))
                .and_then(|k| uint(k, &format!("{field}[{i}].key")))?;
            let value = e
                .get("value")
                .ok_or_else(|| malformed(format!("{field}[{i}] has no 'value'")))?;
            Ok((key, value))
        })
        .collect()
}

/// The data of a cereal (polymorphic) pointer, following cereal's shared-pointer ids: the
/// first occurrence of an id carries `data`, later ones only the id (`id & 0x7fffffff`).
fn pointer_data<'a>(
    value: &'a Value,
    seen: &mut BTreeMap<u64, &'a Value>,
    what: &str,
) -> Result<&'a Value> {
    let wrapper = value
        .get("ptr_wrapper")
        .ok_or_else(|| malformed(format!("{what} has no ptr_wrapper")))?;
    let id = wrapper.get("id").and_then(Value::as_u64);
    if let Some(data) = wrapper.get("data") {
        if let Some(id) = id {
            seen.insert(id & 0x7fff_ffff, data);
        }
        return Ok(data);
    }
    id.and_then(|id| seen.get(&(id & 0x7fff_ffff)).copied())
        .ok_or_else(|| {
            malformed(format!(
                "{what}: pointer without data refers to an unknown id"
            ))
        })
}

/// Reads an OpenMVG `sfm_data.json`.
pub fn read_openmvg_json(bytes: &[u8]) -> Result<Reconstruction> {
    let root: Value = serde_json::from_slice(bytes).map_err(|e| {
        if e.is_eof() {
            Error::truncated(FMT, e.to_string())
        } else {
            malformed(e.to_string())
        }
    })?;
    if !root.is_object() || root.get("views").is_none() {
        return Err(malformed("not an sfm_data file (no 'views')"));
    }
    let mut rec = Reconstruction::new("openmvg");
    let mut seen = BTreeMap::new();

    // Intrinsics: polymorphic_id → type name, learnt from the first of each type.
    let mut type_names: BTreeMap<u64, String> = BTreeMap::new();
    for (key, value) in cereal_map(&root, "intrinsics")? {
        let pid = value.get("polymorphic_id").and_then(Value::as_u64);
        let name = match value.get("polymorphic_name").and_then(Value::as_str) {
            Some(n) => {
                if let Some(pid) = pid {
                    type_names.insert(pid & 0x7fff_ffff, n.to_string());
                }
                n.to_string()
            }
            None => pid
                .and_then(|p| type_names.get(&(p & 0x7fff_ffff)).cloned())
                .ok_or_else(|| malformed(format!("intrinsic {key}: unknown polymorphic type")))?,
        };
        if rec.cameras.iter().any(|c| c.id == key) {
            return Err(malformed(format!("intrinsic key {key} appears twice")));
        }
        let data = pointer_data(value, &mut seen, &format!("intrinsic {key}"))?;
        let width = data
            .get("width")
            .map(|w| uint(w, "width"))
            .transpose()?
            .unwrap_or(0);
        let height = data
            .get("height")
            .map(|h| uint(h, "height"))
            .transpose()?
            .unwrap_or(0);
        let (f, cx, cy) = if name == "spherical" {
            (0.0, width as f64 / 2.0, height as f64 / 2.0)
        } else {
            let f = num(
                data.get("focal_length")
                    .ok_or_else(|| malformed(format!("intrinsic {key} has no focal_length")))?,
                "focal_length",
            )?;
            let [px, py] = vec_n::<2>(data.get("principal_point"), "principal_point")?;
            (f, px + 0.5, py + 0.5)
        };
        let mut params = vec![f, cx, cy];
        for d in ["disto_k1", "disto_k3", "disto_t2", "fisheye"] {
            if let Some(a) = data.get(d).and_then(Value::as_array) {
                for x in a {
                    params.push(num(x, d)?);
                }
            }
        }
        rec.cameras.push(Camera {
            id: key,
            model: name,
            width,
            height,
            fx: f,
            fy: f,
            cx,
            cy,
            params,
        });
    }

    // Extrinsics: pose id → rotation rows + centre.
    let mut poses: BTreeMap<u64, Rigid> = BTreeMap::new();
    for (key, value) in cereal_map(&root, "extrinsics")? {
        let rows = value
            .get("rotation")
            .and_then(Value::as_array)
            .filter(|a| a.len() == 3)
            .ok_or_else(|| malformed(format!("extrinsic {key}: rotation is not 3 rows")))?;
        let mut r = [[0.0; 3]; 3];
        for (i, row) in rows.iter().enumerate() {
            if let Some(dst) = r.get_mut(i) {
                *dst = vec_n::<3>(Some(row), "rotation row")?;
            }
        }
        let c = vec_n::<3>(value.get("center"), "center")?;
        if let Some(k) = (0..3).find(|&k| !(c[k].abs() <= MAX_COORDINATE)) {
            return Err(Error::out_of_range(
                FMT,
                format!("extrinsic {key}"),
                format!("center {}", ["x", "y", "z"][k]),
                format!("is {}, beyond ±{}", show(c[k]), show(MAX_COORDINATE)),
            ));
        }
        if poses
            .insert(key, Rigid::from_rotation_center(r, c))
            .is_some()
        {
            return Err(malformed(format!("extrinsic key {key} appears twice")));
        }
    }

    // Views.
    let mut image_of_view: BTreeMap<u64, usize> = BTreeMap::new();
    let mut missing_intrinsic = 0usize;
    for (key, value) in cereal_map(&root, "views")? {
        let data = pointer_data(value, &mut seen, &format!("view {key}"))?;
        let name = data
            .get("filename")
            .and_then(Value::as_str)
            .ok_or_else(|| malformed(format!("view {key} has no filename")))?
            .to_string();
        let id_view = data.get("id_view").and_then(Value::as_u64).unwrap_or(key);
        let id_intrinsic = data.get("id_intrinsic").and_then(Value::as_u64);
        let id_pose = data.get("id_pose").and_then(Value::as_u64);
        let pose = id_pose.and_then(|p| poses.get(&p)).copied();
        let camera_id = id_intrinsic.filter(|i| rec.cameras.iter().any(|c| c.id == *i));
        match (pose, camera_id) {
            (Some(pose), Some(camera_id)) => {
                if image_of_view.insert(id_view, rec.images.len()).is_some() {
                    return Err(malformed(format!(
                        "view id {id_view} appears twice (view {key})"
                    )));
                }
                rec.images.push(Image {
                    id: id_view,
                    name,
                    camera_id,
                    cam_from_world: pose,
                    observations: Vec::new(),
                });
            }
            (Some(_), None) => {
                missing_intrinsic += 1;
                rec.unregistered.push(name);
            }
            (None, _) => rec.unregistered.push(name),
        }
    }

    // Structure.
    let mut bad_refs = 0usize;
    for (key, value) in cereal_map(&root, "structure")? {
        let xyz = vec_n::<3>(value.get("X"), &format!("landmark {key} X"))?;
        let point_index = rec.points.len();
        let mut track = Vec::new();
        for (view, obs) in cereal_map(value, "observations")? {
            let feat = obs.get("id_feat").and_then(Value::as_u64).unwrap_or(0);
            let xy = vec_n::<2>(obs.get("x"), "observation x")?;
            match image_of_view.get(&view).copied() {
                Some(i) => {
                    rec.observe(&mut track, i, feat, [xy[0] + 0.5, xy[1] + 0.5], point_index)
                }
                None => bad_refs += 1,
            }
        }
        rec.points.push(Point3D {
            xyz,
            color: None,
            error: None,
            track,
        });
    }
    rec.validate(FMT, true)?;
    if missing_intrinsic > 0 {
        rec.notes.push(
            Note::new(
                Code::MissingIntrinsics,
                format!(
                    "{missing_intrinsic} posed view(s) have no valid intrinsic; counted as unregistered"
                ),
            )
            .with("count", missing_intrinsic),
        );
    }
    if bad_refs > 0 {
        rec.notes.push(
            Note::new(
                Code::DanglingReferences,
                format!(
                    "{bad_refs} landmark observation(s) refer to views without a pose; dropped"
                ),
            )
            .with("count", bad_refs),
        );
    }
    rec.note_unregistered("view(s) have no pose (unregistered)");
    Ok(rec)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::model::colmap::read_colmap_text;
    use crate::model::fuzz_tests::fixture;

    #[test]
    fn fixture_matches_the_openmvg_rs_colmap_export() {
        let j = read_openmvg_json(&fixture("openmvg_sfm_data.json")).unwrap();
        let c = read_colmap_text(
            &fixture("openmvg_colmap/cameras.txt"),
            &fixture("openmvg_colmap/images.txt"),
            Some(&fixture("openmvg_colmap/points3D.txt")),
        )
        .unwrap();
        // One unregistered view was added by hand; the rest agree with the COLMAP export.
        assert_eq!(j.unregistered, vec!["extra_unposed.png".to_string()]);
        assert_eq!(j.images.len(), c.images.len());
        for im in &c.images {
            let o = j.images.iter().find(|o| o.name == im.name).unwrap();
            let (a, b) = (im.center(), o.center());
            assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-6), "{}", im.name);
            let r = crate::model::mat_mul(
                &im.cam_from_world.rotation,
                &crate::model::transpose(&o.cam_from_world.rotation),
            );
            assert!(crate::model::rotation_angle_deg(&r) < 1e-5);
        }
        // Cameras: the second intrinsic has no polymorphic_name (cereal writes it once).
        assert_eq!(j.cameras.len(), 2);
        assert_eq!(j.cameras[1].model, j.cameras[0].model);
        assert_eq!(
            (j.cameras[0].fx, j.cameras[0].cx, j.cameras[0].cy),
            (210.0, 120.0, 90.0)
        );
        assert!(!j.points.is_empty());
        assert!(j.points.iter().all(|p| p.track.len() >= 2));
    }

    #[test]
    fn bad_inputs() {
        assert!(matches!(
            read_openmvg_json(b"{\"views\": ["),
            Err(Error::Truncated { .. })
        ));
        assert!(matches!(
            read_openmvg_json(b"[]"),
            Err(Error::Malformed { .. })
        ));
        assert!(matches!(
            read_openmvg_json(b"{\"views\": 3}"),
            Err(Error::Malformed { .. })
        ));
        let r = read_openmvg_json(b"{\"views\": []}").unwrap();
        assert!(r.images.is_empty());
        let bad_rot = br#"{"views": [], "extrinsics": [{"key": 0, "value": {"rotation": [[1,0,0],[0,1,0]], "center": [0,0,0]}}]}"#;
        assert!(matches!(
            read_openmvg_json(bad_rot),
            Err(Error::Malformed { .. })
        ));
        let unknown_type = br#"{"views": [], "intrinsics": [{"key": 0, "value": {"polymorphic_id": 5, "ptr_wrapper": {"id": 1, "data": {}}}}]}"#;
        assert!(matches!(
            read_openmvg_json(unknown_type),
            Err(Error::Malformed { .. })
        ));
    }
}
