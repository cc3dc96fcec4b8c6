// Test data only: platform maths is fine here (reports use libm, see clippy.toml).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::disallowed_methods)]

use super::*;
use crate::model::cameras_json::read_cameras_json;
use crate::model::fuzz_tests::fixture;
use crate::model::{Image, Rigid, mat_vec};

fn gt() -> Reconstruction {
    read_cameras_json(&fixture("gt_cameras.json")).unwrap()
}

fn rot_axis_angle(axis: Point3, deg: f64) -> Mat3 {
    let n = norm(axis);
    let [x, y, z] = axis.map(|v| v / n);
    let (s, c) = deg.to_radians().sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// The GT cameras seen from a reconstruction frame with `X_gt = S·X_recon`.
fn in_recon_frame(gt: &Reconstruction, s: &Similarity) -> Reconstruction {
    let (scale, rs, ts) = (s.scale(), s.rotation(), s.translation());
    let mut est = gt.clone();
    est.format = "colmap";
    for im in &mut est.images {
        let p = im.cam_from_world;
        let r = mat_mul(&p.rotation, &rs);
        let rt = mat_vec(&p.rotation, ts);
        let t = [0, 1, 2].map(|k| (rt[k] + p.translation[k]) / scale);
        im.cam_from_world = Rigid {
            rotation: r,
            translation: t,
        };
        im.name = format!("images/{}", im.name.to_uppercase().replace(".PNG", ".png"));
    }
    est
}

fn similarity() -> Similarity {
    Similarity::from_parts(
        0.37,
        rot_axis_angle([0.3, -1.0, 0.5], 123.0),
        [4.0, -2.0, 7.5],
    )
}

#[test]
fn exact_estimate_has_zero_error() {
    let gt = gt();
    let s = similarity();
    let est = in_recon_frame(&gt, &s);
    let r = evaluate_cameras(&gt, &est, &s, &PoseOptions::default()).unwrap();
    assert_eq!(
        (r.ground_truth, r.registered, r.matched, r.models),
        (6, 6, 6, 1)
    );
    assert!(
        r.rotation_error_deg.max < 1e-9,
        "{}",
        r.rotation_error_deg.max
    );
    assert!(r.center_error.max < 1e-9);
    assert!(r.ate_rmse < 1e-9);
    assert_eq!(r.relative.pairs, 15);
    assert_eq!(r.relative.pairs_unregistered, 0);
    assert!(r.relative.rotation_error_deg.max < 1e-9);
    assert!(r.relative.translation_error_deg.max < 1e-6);
    assert!(
        r.relative
            .accuracy
            .iter()
            .all(|a| a.rra == 1.0 && a.rta == 1.0 && a.both == 1.0)
    );
    assert!((r.relative.auc - 1.0).abs() < 1e-12);
    assert_eq!(r.focal.len(), 1);
    assert_eq!(r.focal[0].error_percent, 0.0);
    assert!(r.notes.is_empty(), "{:?}", r.notes);
    // Scene radius: cameras on a 4.5 m arc.
    assert!(r.scene_radius > 0.5 && r.scene_radius < 4.5);
    // Identity alignment on the same data gives large errors (the check can fail).
    let bad = evaluate_cameras(&gt, &est, &Similarity::IDENTITY, &PoseOptions::default()).unwrap();
    assert!(bad.rotation_error_deg.min > 100.0);
    // …but relative errors do not depend on the alignment.
    assert!(bad.relative.rotation_error_deg.max < 1e-9);
    assert!(bad.relative.translation_error_deg.max < 1e-6);
}

#[test]
fn known_perturbations_give_known_errors() {
    let gt = gt();
    let s = similarity();
    let mut est = in_recon_frame(&gt, &s);
    // Rotate camera 2 by 10° about its own optical axis (centre unchanged) ...
    let c = est.images[2].center();
    let r = mat_mul(
        &rot_axis_angle([0.0, 0.0, 1.0], 10.0),
        &est.images[2].cam_from_world.rotation,
    );
    est.images[2].cam_from_world = Rigid::from_rotation_center(r, c);
    // ... shift camera 4 by 0.1 GT units (0.1 / scale in recon units) ...
    let c4 = est.images[4].center();
    let d = mat_vec(&transpose(&s.rotation()), [0.1 / s.scale(), 0.0, 0.0]);
    let moved = [c4[0] + d[0], c4[1] + d[1], c4[2] + d[2]];
    est.images[4].cam_from_world =
        Rigid::from_rotation_center(est.images[4].cam_from_world.rotation, moved);
    // ... drop image 5 and give the camera a 2 % longer focal at half the resolution.
    est.images.remove(5);
    est.cameras[0].width = 120;
    est.cameras[0].fx = 0.5 * 210.0 * 1.02;
    est.cameras[0].fy = 0.5 * 210.0 * 1.02;
    let r = evaluate_cameras(&gt, &est, &s, &PoseOptions::default()).unwrap();
    assert_eq!((r.matched, r.registered), (5, 5));
    let by_name = |n: &str| r.images.iter().find(|i| i.name == n).unwrap();
    assert!((by_name("0002.png").rotation_error_deg - 10.0).abs() < 1e-9);
    assert!(by_name("0002.png").center_error < 1e-9);
    assert!((by_name("0004.png").center_error - 0.1).abs() < 1e-9);
    assert!((by_name("0004.png").center_error_percent - 10.0 / r.scene_radius).abs() < 1e-6);
    assert!((r.ate_rmse - (0.01f64 / 5.0).sqrt()).abs() < 1e-9);
    // 5 of 15 pairs involve the dropped image.
    assert_eq!(r.relative.pairs_unregistered, 5);
    assert_eq!(r.relative.rotation_error_deg.max, 180.0);
    // Pairs with image 2 (4 registered partners) have exactly 10° relative rotation error.
    let ten = r
        .relative
        .rotation_error_deg
        .histogram
        .counts
        .iter()
        .sum::<u64>();
    assert_eq!(ten, 15);
    let a5 = &r.relative.accuracy[0];
    assert!((a5.rra - 6.0 / 15.0).abs() < 1e-12, "{}", a5.rra);
    let a15 = &r.relative.accuracy[2];
    assert!((a15.rra - 10.0 / 15.0).abs() < 1e-12);
    assert!((r.focal[0].error_percent - 2.0).abs() < 1e-9);
}

#[test]
fn auc_matches_hand_computation() {
    // errors 0.5 (bin 0), 2.5 (bin 2), 40 (outside): cumulative shares 1/3,1/3,2/3,... over 30 bins.
    let a = auc(&[0.5, 2.5, 40.0], 30.0);
    let want = (1.0 / 3.0 + 1.0 / 3.0 + 28.0 * 2.0 / 3.0) / 30.0;
    assert!((a - want).abs() < 1e-15);
    assert_eq!(auc(&[], 30.0), 0.0);
    assert_eq!(auc(&[180.0; 4], 30.0), 0.0);
}

#[test]
fn bad_inputs_are_errors_or_warnings() {
    let gt = gt();
    let s = similarity();
    let est = in_recon_frame(&gt, &s);
    let o = PoseOptions::default();
    // No name matches.
    let mut renamed = est.clone();
    for im in &mut renamed.images {
        im.name = format!("x_{}", im.name.replace("images/", ""));
    }
    let e = evaluate_cameras(&gt, &renamed, &s, &o).unwrap_err();
    assert!(matches!(e, Error::Empty { .. }));
    assert!(e.to_string().contains("x_0000.png"));
    // Empty model.
    let empty = Reconstruction::new("colmap");
    assert!(matches!(
        evaluate_cameras(&gt, &empty, &s, &o),
        Err(Error::Empty { .. })
    ));
    assert!(matches!(
        evaluate_cameras(&empty, &est, &s, &o),
        Err(Error::Empty { .. })
    ));
    // Fewer than 3 matched: a report with a warning.
    let mut two = est.clone();
    two.images.truncate(2);
    let r = evaluate_cameras(&gt, &two, &s, &o).unwrap();
    assert_eq!(r.matched, 2);
    assert!(r.notes.iter().any(|w| w.message.contains("only 2")));
    assert_eq!(r.relative.pairs_unregistered, 14);
    // One match: scene radius exists (GT), relative pairs all 180.
    let mut one = est.clone();
    one.images.truncate(1);
    let r = evaluate_cameras(&gt, &one, &s, &o).unwrap();
    assert_eq!(r.relative.auc, 0.0);
    // NaN pose: treated as unregistered with a warning.
    let mut nan = est.clone();
    nan.images[0].cam_from_world.translation[0] = f64::NAN;
    let r = evaluate_cameras(&gt, &nan, &s, &o).unwrap();
    assert_eq!(r.matched, 5);
    assert!(r.notes.iter().any(|w| w.message.contains("NaN")));
    assert!(r.rotation_error_deg.max.is_finite());
    // All NaN: no usable match.
    let mut all_nan = est.clone();
    for im in &mut all_nan.images {
        im.cam_from_world.rotation[0][0] = f64::NAN;
    }
    assert!(matches!(
        evaluate_cameras(&gt, &all_nan, &s, &o),
        Err(Error::Empty { .. })
    ));
    // Bad similarity.
    let mut m = s;
    m.matrix[0][0] = f64::NAN;
    assert!(matches!(
        evaluate_cameras(&gt, &est, &m, &o),
        Err(Error::InvalidContent(_))
    ));
    let zero = Similarity::from_parts(0.0, Similarity::IDENTITY.rotation(), [0.0; 3]);
    assert!(matches!(
        evaluate_cameras(&gt, &est, &zero, &o),
        Err(Error::InvalidContent(_))
    ));
    // A single GT camera: radius 0, a warning, no panic.
    let mut g1 = gt.clone();
    g1.images.truncate(1);
    let r = evaluate_cameras(&g1, &est, &s, &o).unwrap();
    assert_eq!(r.scene_radius, 0.0);
    assert_eq!(r.relative.pairs, 0);
    // Duplicate estimated name.
    let mut dup = est.clone();
    let extra = Image {
        ..dup.images[0].clone()
    };
    dup.images.push(extra);
    let r = evaluate_cameras(&gt, &dup, &s, &o).unwrap();
    assert!(r.notes.iter().any(|w| w.message.contains("repeat")));
}

#[test]
fn many_pairs_are_subsampled() {
    let gt = gt();
    let s = similarity();
    let est = in_recon_frame(&gt, &s);
    let o = PoseOptions {
        max_pairs: 4,
        ..PoseOptions::default()
    };
    let r = evaluate_cameras(&gt, &est, &s, &o).unwrap();
    assert_eq!(r.relative.pairs, 4);
    assert!(r.notes.iter().any(|w| w.message.contains("every 4-th")));
}

/// Umeyama similarity `dst ≈ s·R·src + t` (test-only; the alignment stages have their own).
fn umeyama(src: &[Point3], dst: &[Point3]) -> Similarity {
    use nalgebra::{Matrix3, Vector3};
    let n = src.len() as f64;
    let mean = |p: &[Point3]| {
        p.iter()
            .fold(Vector3::zeros(), |a, x| a + Vector3::from(*x))
            / n
    };
    let (ms, md) = (mean(src), mean(dst));
    let mut cov = Matrix3::zeros();
    let mut var = 0.0;
    for (a, b) in src.iter().zip(dst) {
        let (a, b) = (Vector3::from(*a) - ms, Vector3::from(*b) - md);
        cov += b * a.transpose();
        var += a.norm_squared();
    }
    cov /= n;
    var /= n;
    let svd = cov.svd(true, true);
    let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut d = Matrix3::identity();
    if (u * v_t).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let r = u * d * v_t;
    let scale = (svd.singular_values.component_mul(&d.diagonal())).sum() / var;
    let t = md - scale * r * ms;
    let rot = [0, 1, 2].map(|i| [0, 1, 2].map(|j| r[(i, j)]));
    Similarity::from_parts(scale, rot, [t[0], t[1], t[2]])
}

#[test]
fn real_tool_outputs_agree_with_ground_truth_after_alignment() {
    use crate::model::{bundler, colmap, matching, nvm};
    let gt = gt();
    let models: Vec<(&str, Reconstruction)> = vec![
        (
            "pycolmap",
            colmap::read_colmap_binary(
                &fixture("colmap_bin/cameras.bin"),
                &fixture("colmap_bin/images.bin"),
                Some(&fixture("colmap_bin/points3D.bin")),
            )
            .unwrap(),
        ),
        (
            "openmvg-rs",
            colmap::read_colmap_text(
                &fixture("openmvg_colmap/cameras.txt"),
                &fixture("openmvg_colmap/images.txt"),
                Some(&fixture("openmvg_colmap/points3D.txt")),
            )
            .unwrap(),
        ),
        (
            "openmvg json",
            crate::model::openmvg::read_openmvg_json(&fixture("openmvg_sfm_data.json")).unwrap(),
        ),
        (
            "colmap38 nvm",
            nvm::read_nvm(&fixture("colmap38.nvm")).unwrap(),
        ),
        ("theia nvm", nvm::read_nvm(&fixture("theia.nvm")).unwrap()),
        (
            "colmap38 bundler",
            bundler::read_bundler(
                &fixture("colmap38.bundle.out"),
                Some(&fixture("colmap38.list.txt")),
            )
            .unwrap(),
        ),
    ];
    for (label, est) in models {
        let m = matching::match_images(&gt, &est);
        let (g, e) = matching::matched_centers(&gt, &est, &m);
        let s = umeyama(&e, &g);
        let r = evaluate_cameras(&gt, &est, &s, &PoseOptions::default()).unwrap();
        eprintln!(
            "{label}: centre max {:.3} % of radius {:.3}, rotation max {:.3}°, rel rot max {:.3}°, rel trans max {:.3}°, auc {:.3}",
            r.center_error_percent.max,
            r.scene_radius,
            r.rotation_error_deg.max,
            r.relative.rotation_error_deg.max,
            r.relative.translation_error_deg.max,
            r.relative.auc
        );
        assert_eq!(r.matched, 6, "{label}");
        // A 70° arc of six 240×180 views with ~80 features each: centres within 3 % of the
        // scene radius (≈ 1 % of the 4.5 m orbit radius). An alignment from centres alone is
        // weakly conditioned on such an arc, so absolute rotations carry ~2° of alignment
        // error (numpy gives the same numbers); relative rotations, which do not depend on the
        // alignment, are within 1.5°.
        assert!(
            r.center_error_percent.max < 3.0,
            "{label}: {}",
            r.center_error_percent.max
        );
        assert!(
            r.rotation_error_deg.max < 3.0,
            "{label}: {}",
            r.rotation_error_deg.max
        );
        assert!(r.relative.rotation_error_deg.max < 1.5, "{label}");
        assert!(r.relative.accuracy[0].rra == 1.0, "{label}");
        assert!(r.relative.auc > 0.9, "{label}");
    }
}

/// Same models, same similarity, compared with the numpy/scipy implementation in
/// `tests/python/test_pose_metrics.py` (its output is committed as `pose_expected.json`).
#[test]
fn agrees_with_numpy_reference() {
    use crate::model::colmap;
    let expected: serde_json::Value =
        serde_json::from_slice(&fixture("pose_expected.json")).unwrap();
    let gt = gt();
    let read = |dir: &str| -> Reconstruction {
        if dir.ends_with("_bin") {
            let f = |n: &str| fixture(&format!("{dir}/{n}.bin"));
            colmap::read_colmap_binary(&f("cameras"), &f("images"), Some(&f("points3D"))).unwrap()
        } else {
            let f = |n: &str| fixture(&format!("{dir}/{n}.txt"));
            colmap::read_colmap_text(&f("cameras"), &f("images"), Some(&f("points3D"))).unwrap()
        }
    };
    let obj = expected.as_object().unwrap();
    assert_eq!(obj.len(), 4);
    for (dir, want) in obj {
        let est = read(dir);
        let m: Vec<f64> = want["gt_from_recon"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|r| r.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()))
            .collect();
        let mut mat = [[0.0; 4]; 4];
        for (i, v) in m.iter().enumerate() {
            mat[i / 4][i % 4] = *v;
        }
        let s = Similarity::from_matrix(mat).unwrap();
        let r = evaluate_cameras(&gt, &est, &s, &PoseOptions::default()).unwrap();
        let close = |a: f64, b: &serde_json::Value, tol: f64, what: &str| {
            let b = b.as_f64().unwrap();
            assert!((a - b).abs() <= tol, "{dir} {what}: sfmeval {a} numpy {b}");
        };
        assert_eq!(r.matched as u64, want["matched"].as_u64().unwrap());
        close(r.scene_radius, &want["scene_radius"], 1e-12, "scene radius");
        close(r.ate_rmse, &want["ate_rmse"], 1e-9, "ATE");
        for im in &r.images {
            let w = &want["images"][&im.name];
            close(
                im.rotation_error_deg,
                &w["rotation_error_deg"],
                1e-7,
                "rotation",
            );
            close(im.center_error, &w["center_error"], 1e-9, "centre");
        }
        // Pairs in the same (i < j) order.
        let rel_rot = want["relative_rotation_error_deg"].as_array().unwrap();
        let rel_tr = want["relative_translation_error_deg"].as_array().unwrap();
        assert_eq!(r.relative.pairs, rel_rot.len());
        let mean = |v: &[serde_json::Value]| {
            v.iter().map(|x| x.as_f64().unwrap()).sum::<f64>() / v.len() as f64
        };
        assert!(
            (r.relative.rotation_error_deg.mean - mean(rel_rot)).abs() < 1e-7,
            "{dir}"
        );
        assert!(
            (r.relative.translation_error_deg.mean - mean(rel_tr)).abs() < 1e-7,
            "{dir}"
        );
        let max =
            |v: &[serde_json::Value]| v.iter().map(|x| x.as_f64().unwrap()).fold(0.0, f64::max);
        assert!(
            (r.relative.rotation_error_deg.max - max(rel_rot)).abs() < 1e-7,
            "{dir}"
        );
        assert!(
            (r.relative.translation_error_deg.max - max(rel_tr)).abs() < 1e-7,
            "{dir}"
        );
        for (a, w) in r
            .relative
            .accuracy
            .iter()
            .zip(want["accuracy"].as_array().unwrap())
        {
            close(a.rra, &w["rra"], 1e-12, "RRA");
            close(a.rta, &w["rta"], 1e-12, "RTA");
        }
        close(r.relative.auc, &want["auc"], 1e-12, "AUC");
        close(
            r.focal[0].error_percent,
            &want["focal"][0]["error_percent"],
            1e-9,
            "focal",
        );
    }
}

#[test]
fn protocols_are_gauge_free_and_exact_on_the_ground_truth_in_another_frame() {
    let gt = gt();
    let s = Similarity::from_parts(
        2.5,
        rot_axis_angle([0.3, -1.0, 0.4], 40.0),
        [1.0, -2.0, 0.5],
    );
    let est = in_recon_frame(&gt, &s);
    let opts = ProtocolOptions::default();
    let rep = evaluate_protocol(&gt, &est, Protocol::Colmap, &opts).unwrap();
    let ProtocolResult::Colmap(c) = &rep.result else {
        panic!("not colmap")
    };
    assert_eq!(c.pairs, 30);
    assert_eq!(c.recall_percent, vec![100.0; 4]);
    // acos of a rounded 1 leaves ~1e-6 degrees: the AUC at 0.5° is 100 to ~1e-3 %.
    assert!(
        c.auc_percent.iter().all(|a| (a - 100.0).abs() < 1e-3),
        "{c:?}"
    );
    let rep = evaluate_protocol(&gt, &est, Protocol::Imc, &opts).unwrap();
    let ProtocolResult::Imc(i) = &rep.result else {
        panic!("not imc")
    };
    assert_eq!((i.pairs, i.maa_5, i.maa_10), (15, 1.0, 1.0));
    let rep = evaluate_protocol(&gt, &est, Protocol::Co3d, &opts).unwrap();
    let ProtocolResult::Co3d(c) = &rep.result else {
        panic!("not co3d")
    };
    assert_eq!(c.rra_percent, vec![100.0; 3]);
    assert_eq!(c.auc_percent, 100.0);
    assert_eq!(rep.pair_rows.len(), 15);
    // The eps floor of acos(1 - 2 max(1e-15, loss)): 6.3e-8 rad, never 0.
    assert!(
        rep.pair_rows
            .iter()
            .all(|r| r.rotation_deg > 3e-6 && r.rotation_deg < 1e-5)
    );
}

#[test]
fn a_non_finite_pose_is_unregistered_and_invalidates_the_imc_model() {
    let gt = gt();
    let mut est = in_recon_frame(&gt, &Similarity::default());
    est.images[3].cam_from_world.translation[1] = f64::NAN;
    let opts = ProtocolOptions::default();
    let rep = evaluate_protocol(&gt, &est, Protocol::Imc, &opts).unwrap();
    let ProtocolResult::Imc(i) = &rep.result else {
        panic!("not imc")
    };
    assert!(!i.model_valid);
    assert_eq!((i.pairs_unregistered, i.maa_10), (15, 0.0));
    assert_eq!(rep.non_finite, 1);
    assert!(rep.notes.iter().any(|n| n.code == Code::NonFinitePoses));
    let rep = evaluate_protocol(&gt, &est, Protocol::Colmap, &opts).unwrap();
    let ProtocolResult::Colmap(c) = &rep.result else {
        panic!("not colmap")
    };
    assert_eq!(
        (c.pairs, c.pairs_unregistered, c.pairs_outside_gt),
        (30, 10, 0)
    );
    let rep = evaluate_protocol(&gt, &est, Protocol::Co3d, &opts).unwrap();
    let ProtocolResult::Co3d(c) = &rep.result else {
        panic!("not co3d")
    };
    assert_eq!(c.pairs_unregistered, 5);
    // 10 of 15 pairs are perfect, 5 fail every threshold.
    assert!(
        c.rra_percent
            .iter()
            .all(|r| (r - 200.0 / 3.0).abs() < 1e-12)
    );
}

#[test]
fn colmap_auc_is_the_trapezoid_of_the_recall_curve() {
    // Recall 0 at 0, 0.5 at 1, 1 at 2: area 0.25 + 0.75 over 2 = 50 %; at 1: 0.25 / 1.
    let aucs = super::colmap_benchmark::compute_auc(&[1.0, 2.0], &[2.0, 1.0, 4.0], 0.0);
    assert_eq!(aucs, vec![50.0, 25.0, 75.0]);
    // min_error 1.5: recall 0.5 from 0 to 1.5, then 1 at 2: (0.75 + 0.375) / 2.
    let aucs = super::colmap_benchmark::compute_auc(&[1.0, 2.0], &[2.0], 1.5);
    assert_eq!(aucs, vec![56.25]);
}

#[test]
fn pytorch3d_quaternion_equals_the_unit_quaternion_of_a_rotation() {
    for (axis, deg) in [
        ([1.0, 2.0, 3.0], 10.0),
        ([0.0, 0.0, 1.0], 179.0),
        ([1.0, -1.0, 0.2], 95.0),
    ] {
        let r = rot_axis_angle(axis, deg);
        let (a, b) = (
            super::protocol::quaternion(&r),
            super::protocol::quaternion_pytorch3d(&r),
        );
        for k in 0..4 {
            assert!((a[k] - b[k]).abs() < 1e-15, "{a:?} {b:?}");
        }
    }
}

#[test]
fn unknown_protocols_and_bad_options_are_errors() {
    assert!(matches!(
        Protocol::parse("eth3d"),
        Err(Error::InvalidOption(_))
    ));
    let gt = gt();
    let opts = ProtocolOptions {
        colmap_thresholds_deg: vec![0.0],
        ..ProtocolOptions::default()
    };
    assert!(evaluate_protocol(&gt, &gt, Protocol::Colmap, &opts).is_err());
    let mut renamed = gt.clone();
    for im in &mut renamed.images {
        im.name = format!("x_{}", im.name);
    }
    let err = evaluate_protocol(&gt, &renamed, Protocol::Imc, &ProtocolOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("none of the 6 estimated image(s)"), "{err}");
}
