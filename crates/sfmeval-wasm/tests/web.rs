//! Tests of the bindings, run by wasm-bindgen-test-runner in Node and in headless Chromium.
#![cfg(target_arch = "wasm32")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use js_sys::{Object, Reflect, Uint8Array};
use sfmeval_wasm::{GroundTruth, Reconstruction, evaluate, parse_crop, parse_transform_text};
use wasm_bindgen::JsValue;
use wasm_bindgen_test::*;

/// A unit tetrahedron as an ASCII PLY mesh.
const GT: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
/// Points near its faces, in a frame scaled by 2 (so `TRANSFORM` maps them back).
const RECON: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nend_header\n0.4 0.4 0.02\n0.6 0 0.6\n0 0.5 0.5\n0.2 0.2 0.2\n0.7 0.6 0.6\n";
const TRANSFORM: &str = "0.5 0 0 0\n0 0.5 0 0\n0 0 0.5 0\n0 0 0 1\n";

fn files(name: &str, bytes: &[u8]) -> Object {
    let o = Object::new();
    Reflect::set(&o, &name.into(), &Uint8Array::from(bytes)).unwrap();
    o
}

fn options(json: &str) -> JsValue {
    js_sys::JSON::parse(json).unwrap()
}

#[wasm_bindgen_test]
fn evaluates_the_demo_with_its_transform() {
    let mut gt = GroundTruth::new("tetra.ply", &Uint8Array::from(GT), None, None).unwrap();
    assert!(gt.is_mesh());
    assert_eq!(gt.vertices().length() % 3, 0);
    let recon = Reconstruction::new("cloud.ply", &files("cloud.ply", RECON)).unwrap();
    assert_eq!(recon.format(), "ply");
    let opts = Object::new();
    Reflect::set(&opts, &"transform".into(), &TRANSFORM.into()).unwrap();
    Reflect::set(&opts, &"samples".into(), &20_000.into()).unwrap();
    Reflect::set(&opts, &"crop".into(), &options(r#"{"max_distance": 0.2}"#)).unwrap();
    let calls = std::rc::Rc::new(std::cell::Cell::new(0u32));
    let c = calls.clone();
    let cb = wasm_bindgen::closure::Closure::<dyn FnMut(String, f64, f64)>::new(
        move |_: String, _: f64, _: f64| c.set(c.get() + 1),
    );
    let e = evaluate(
        &mut gt,
        &recon,
        opts.into(),
        Some(cb.as_ref().unchecked_ref::<js_sys::Function>().clone()),
    )
    .unwrap();
    let report: serde_json::Value = serde_json::from_str(&e.report_json()).unwrap();
    assert_eq!(report["schema"], "sfmeval.report/3");
    assert_eq!(report["alignment"]["method"], "given");
    assert_eq!(report["options"]["samples"], 20_000);
    let n = recon.point_count() as u32;
    assert_eq!(e.distances().length(), n);
    assert_eq!(e.status().length(), n);
    assert_eq!(e.colors(0.01).length(), 3 * n);
    assert_eq!(report["inputs"]["ground_truth"]["triangles"], 4);
    assert_eq!(report["crop"]["kind"], "max_distance");
    // (0.2, 0.2, 0.2) is in the tetrahedron's interior, 0.1 from the face x=0 after scaling.
    assert!((e.distances().get_index(3) - 0.1).abs() < 1e-6);
    assert_eq!(e.gt_from_recon()[0], 0.5);
    assert!(calls.get() > 0, "progress was reported");
    assert!(e.colored_ply(0.01).to_vec().starts_with(b"ply\n"));
    assert!(e.csv().starts_with("index,x,y,z,distance"));
}

use wasm_bindgen::JsCast as _;

#[wasm_bindgen_test]
fn errors_carry_the_core_message() {
    let err = GroundTruth::new(
        "broken.glb",
        &Uint8Array::from(&b"glTF\x02\0\0\0junk"[..]),
        None,
        None,
    )
    .err()
    .expect("a broken GLB is an error");
    let v: JsValue = err.into();
    let msg = Reflect::get(&v, &"message".into())
        .unwrap()
        .as_string()
        .unwrap();
    assert!(msg.starts_with("ground truth 'broken.glb'"), "{msg}");
    let err = Reconstruction::new(
        "x.ply",
        &files("x.ply", b"ply\nformat ascii 1.0\nelement vertex 5\n"),
    )
    .err()
    .expect("a truncated PLY is an error");
    let v: JsValue = err.into();
    assert!(v.is_instance_of::<js_sys::Error>());
    assert!(parse_crop(r#"{"max_distance": -1}"#).is_err());
    assert!(parse_crop(r#"{"schema":"sfmeval.crop/1","max_distance": 0.1}"#).is_ok());
    assert_eq!(parse_transform_text(TRANSFORM).unwrap().len(), 16);
    let mut gt = GroundTruth::new("tetra.ply", &Uint8Array::from(GT), None, None).unwrap();
    let recon = Reconstruction::new("cloud.ply", &files("cloud.ply", RECON)).unwrap();
    assert!(evaluate(&mut gt, &recon, options(r#"{"samples": 0}"#), None).is_err());
    assert!(evaluate(&mut gt, &recon, options(r#"{"bogus": 1}"#), None).is_err());
    assert!(evaluate(&mut gt, &recon, options(r#"{"align": "given"}"#), None).is_err());
    // The triangle limit guards glTF instancing only: a PLY's triangles are in the file, so the
    // tetrahedron's 4 pass a limit of 3; a limit below 1 is refused.
    assert!(GroundTruth::new("tetra.ply", &Uint8Array::from(GT), None, Some(3.0)).is_ok());
    assert!(GroundTruth::new("tetra.ply", &Uint8Array::from(GT), None, Some(0.0)).is_err());
}

const RUN_JSON: &str = r#"{"schema":"sfmeval.run/1","dataset":"tetra","dataset_dir":"/d","pipeline":"colmap","kind":"colmap","tool":"colmap","version":"3.9","status":"ok","reason":null,"command":[],"options":{},"wall_seconds":1.5,"cpu_seconds":2.0,"peak_memory_bytes":2500000,"exit_status":0,"images_total":36,"images_registered":30,"points":5,"models":1,"started_unix":0,"finished_unix":1,"log":"log.txt","steps":[],"warnings":[]}"#;

#[wasm_bindgen_test]
fn builds_the_runner_rows_and_tables() {
    let mut gt = GroundTruth::new("tetra.ply", &Uint8Array::from(GT), None, None).unwrap();
    let recon = Reconstruction::new("tetra/colmap", &files("cloud.ply", RECON)).unwrap();
    let opts = Object::new();
    Reflect::set(&opts, &"transform".into(), &TRANSFORM.into()).unwrap();
    Reflect::set(&opts, &"samples".into(), &2_000.into()).unwrap();
    let e = evaluate(&mut gt, &recon, opts.into(), None).unwrap();
    let row: serde_json::Value = serde_json::from_str(&e.run_row(RUN_JSON).unwrap()).unwrap();
    assert_eq!(row["pipeline"], "colmap");
    assert_eq!(row["points"], 5);
    assert_eq!(row["peak_memory_mb"], 2.5);
    assert_eq!(row["report"], "reports/tetra/colmap.json");
    assert_eq!(row["cdf"].as_array().unwrap().len(), 201);
    assert_eq!(row["thresholds"].as_array().unwrap().len(), 3);
    // a failed run: the row from run.json alone
    let failed = sfmeval_wasm::run_row(&RUN_JSON.replace("\"ok\"", "\"timeout\"")).unwrap();
    let failed: serde_json::Value = serde_json::from_str(&failed).unwrap();
    assert_eq!(failed["status"], "timeout");
    assert!(failed["mean"].is_null());
    // a broken run.json names the file
    let err = sfmeval_wasm::run_row("{}").err().unwrap();
    let msg = js_sys::Error::from(JsValue::from(err)).message();
    assert!(String::from(msg).starts_with("run.json: missing field"));
    let rows = format!("[{row},{failed}]");
    let t = sfmeval_wasm::comparison_tables(&rows).unwrap();
    let md = Reflect::get(&t, &"table1_md".into())
        .unwrap()
        .as_string()
        .unwrap();
    assert!(md.contains("| dataset | colmap |\n"), "{md}");
    let csv = Reflect::get(&t, &"runs_csv".into())
        .unwrap()
        .as_string()
        .unwrap();
    assert!(csv.starts_with("dataset,pipeline,status,points,registered,"));
}

#[wasm_bindgen_test]
fn camera_poses_for_the_frusta() {
    let cams = include_bytes!("../../../data/demo/cameras.json");
    let r = Reconstruction::new("cams", &files("cameras.json", cams)).unwrap();
    let poses = r.camera_poses().to_vec();
    assert_eq!(poses.len(), 36 * 14);
    assert_eq!(r.camera_names().len(), 36);
    // the first image's centre as the file gives it, and the PINHOLE 640×360, f 700 frustum
    let c = [2.058960199356, 0.749400258064, 1.4901e-08];
    for k in 0..3 {
        assert!((poses[k] - c[k]).abs() < 1e-6, "{poses:?}");
    }
    assert!((poses[12] - 320.0 / 700.0).abs() < 1e-12 && (poses[13] - 180.0 / 700.0).abs() < 1e-12);
    // a bare cloud has no cameras
    let cloud = Reconstruction::new("cloud.ply", &files("cloud.ply", RECON)).unwrap();
    assert_eq!(cloud.camera_poses().length(), 0);
    let colors = sfmeval_wasm::error_colors(&[0.0, 1.0, f64::NAN], 1.0).to_vec();
    assert_eq!(colors.len(), 9);
    assert_eq!(&colors[6..], &[128, 128, 128]);
    assert_ne!(&colors[0..3], &colors[3..6]);
}
