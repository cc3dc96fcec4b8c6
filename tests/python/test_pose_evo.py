"""Camera-pose errors of `sfmeval cameras` against evo (https://github.com/MichaelGrupp/evo).

evo is an independent trajectory-evaluation tool. For every SfM fixture model that sfmeval reads
(tests/fixtures/models) against `gt_cameras.json`, this test

1. reads the estimate independently of sfmeval (pycolmap for COLMAP folders, small parsers here
   for NVM, Bundler and OpenMVG `sfm_data.json`) and builds evo `PoseTrajectory3D`s of
   world_from_cam poses (position = camera centre, quaternion wxyz of R_world_from_cam),
   matched by image name, timestamps = index in sorted name order;
2. aligns the estimate with evo's own Sim(3) Umeyama (`align(ref, correct_scale=True)`), takes
   evo's APE (translation part, rotation angle in degrees) per image and evo's RPE rotation angle
   over all image pairs (evo's `all_pairs=True` means every pair (i, i+delta), so all pairs are
   the union over delta = 1..n-1);
3. runs `sfmeval cameras` on the same files, once aligning the camera centres itself (its LO-RANSAC
   refits Umeyama on the inliers, so with all cameras inliers it must find evo's similarity) and
   once with `--transform` = evo's similarity, and compares the similarity, per-image centre and
   rotation errors, ATE RMSE, and the relative rotation (and translation-direction) error
   statistics / RRA / RTA the report exposes.

A harder case moves one camera of colmap_bin far away: sfmeval's RANSAC must drop it, and its
similarity must equal evo's Umeyama on the other five.

A third case removes one image of colmap_bin (deregistered): evo sees five poses, and sfmeval's
pairs with the missing image count 180°, as documented.

Tolerances (measured differences are ~1e-13 degrees; see the constants) are far below anything a
wrong formula, frame, inverse or alignment would give (the errors themselves are 0.02–3 degrees
and up to a few % of the scene radius).
"""
import copy
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

# Plain imports, no importorskip: evo (and pycolmap, imported where used as in the other tests)
# are in requirements/models.txt, and this test must run, not skip, wherever the suite runs.
from evo.core import lie_algebra as lie
from evo.core import metrics as evo_metrics
from evo.core.trajectory import PoseTrajectory3D

ROOT = Path(__file__).resolve().parents[2]
FIX = ROOT / "tests" / "fixtures" / "models"
GT = FIX / "gt_cameras.json"

# Measured on the fixtures (numpy 1.26.4 / evo 1.38.1 vs sfmeval, x86-64): per-image and
# relative angles differ by at most 4e-13 degrees, lengths by 1.5e-15 of the scene radius, the
# similarities (nalgebra's SVD vs numpy's) by 4e-13 degrees, 7e-16 in scale and 1.6e-15 of the
# radius in translation: only rounding, as both compute the same closed forms in double
# precision. The tolerances leave 250x (angles) to 1000x (lengths) of margin for other BLAS /
# CPUs, and are still about 1e-8 of the smallest errors they compare (a centre error of 7.5e-5
# of the radius, rotation errors of 0.02 degrees and more).
TOL_DEG = 1e-10  # angles in degrees
TOL_LEN_REL = 1e-12  # lengths, relative to the GT scene radius
TOL_SIM_DEG = 1e-10  # rotation of the similarity
TOL_SIM_SCALE_REL = 1e-12
TOL_SIM_T_REL = 1e-12  # translation, relative to the scene radius


# --- independent readers: name -> (R cam_from_world, camera centre) --------------------------

def quat_wxyz_to_matrix(q):
    from scipy.spatial.transform import Rotation

    w, x, y, z = q
    return Rotation.from_quat([x, y, z, w]).as_matrix()  # scipy normalises


def read_colmap(path):
    import pycolmap

    rec = pycolmap.Reconstruction(str(path))
    out = {}
    for im in rec.images.values():
        if not im.has_pose:
            continue
        pose = im.cam_from_world() if callable(im.cam_from_world) else im.cam_from_world
        x, y, z, w = np.asarray(pose.rotation.quat)  # pycolmap: x, y, z, w (not normalised
        r = quat_wxyz_to_matrix([w, x, y, z])  # when read from Theia's 6-digit text)
        out[im.name] = (r, -r.T @ np.asarray(pose.translation))
    return out


def read_nvm(path):
    lines = [ln.split() for ln in path.read_text().splitlines()]
    lines = [ln for ln in lines if ln]
    assert lines[0][0] == "NVM_V3"
    n = int(lines[1][0])
    out = {}
    for ln in lines[2:2 + n]:
        # name f qw qx qy qz cx cy cz radial 0
        out[ln[0]] = (quat_wxyz_to_matrix([float(v) for v in ln[2:6]]),
                      np.array([float(v) for v in ln[6:9]]))
    return out


def read_bundler(path, list_path):
    names = [ln.split()[0] for ln in list_path.read_text().splitlines() if ln.strip()]
    vals = [ln.split() for ln in path.read_text().splitlines() if not ln.startswith("#")]
    n = int(vals[0][0])
    flip = np.diag([1.0, -1.0, -1.0])  # Bundler looks down -z with +y up
    out = {}
    for k in range(n):
        block = np.array(vals[1 + 5 * k:6 + 5 * k], dtype=float)
        r, t = flip @ block[1:4], flip @ block[4]
        if not np.any(r):
            continue  # unregistered camera
        out[names[k]] = (r, -r.T @ t)
    return out


def read_sfm_data(path):
    d = json.loads(path.read_text())
    poses = {e["key"]: e["value"] for e in d["extrinsics"]}
    out = {}
    for v in d["views"]:
        data = v["value"]["ptr_wrapper"]["data"]
        p = poses.get(data["id_pose"])
        if p is not None:
            out[data["filename"]] = (np.array(p["rotation"]), np.array(p["center"]))
    return out


MODELS = {
    "colmap_bin": lambda: read_colmap(FIX / "colmap_bin"),
    "colmap_text": lambda: read_colmap(FIX / "colmap_text"),
    "openmvg_colmap": lambda: read_colmap(FIX / "openmvg_colmap"),
    "theia_colmap": lambda: read_colmap(FIX / "theia_colmap"),
    "colmap38.nvm": lambda: read_nvm(FIX / "colmap38.nvm"),
    "theia.nvm": lambda: read_nvm(FIX / "theia.nvm"),
    "colmap38.bundle.out": lambda: read_bundler(FIX / "colmap38.bundle.out",
                                                FIX / "colmap38.list.txt"),
    "openmvg_sfm_data.json": lambda: read_sfm_data(FIX / "openmvg_sfm_data.json"),
}


def read_gt():
    gt = json.loads(GT.read_text())
    out = {}
    for im in gt["images"]:
        r = np.array(im["cam_from_world"]["rotation"])
        out[im["name"]] = (r, -r.T @ np.array(im["cam_from_world"]["translation"]))
    return out, [im["name"] for im in gt["images"]]


# --- evo ------------------------------------------------------------------------------------

def trajectory(poses, names):
    """world_from_cam poses of `names` as an evo trajectory (timestamps = index)."""
    from scipy.spatial.transform import Rotation

    xyz = np.array([poses[n][1] for n in names])
    q = Rotation.from_matrix(np.array([poses[n][0].T for n in names])).as_quat()  # x, y, z, w
    return PoseTrajectory3D(positions_xyz=xyz, orientations_quat_wxyz=q[:, [3, 0, 1, 2]],
                            timestamps=np.arange(len(names), dtype=float))


def evo_all_pairs(ref, est, relation):
    """evo RPE over every pair i < j: {(i, j): error}."""
    out = {}
    n = ref.num_poses
    for delta in range(1, n):
        rpe = evo_metrics.RPE(relation, delta=delta, delta_unit=evo_metrics.Unit.frames,
                              all_pairs=True)
        rpe.process_data((ref, est))
        starts = [i for i in range(n) if i + delta < n]
        assert rpe.delta_ids == [i + delta for i in starts]
        out.update({(i, i + delta): float(e) for i, e in zip(starts, rpe.error)})
    assert len(out) == n * (n - 1) // 2
    return out


def evo_eval(gt, est, fit_names=None):
    """evo's alignment and errors of the images both have; the similarity is fitted on
    `fit_names` (default all matched) and applied to every matched image."""
    names = sorted(set(gt) & set(est))
    ref, raw = trajectory(gt, names), trajectory(est, names)
    fit = names if fit_names is None else sorted(fit_names)
    sub = trajectory(est, fit)
    r, t, s = sub.align(trajectory(gt, fit), correct_scale=True)
    aligned = copy.deepcopy(raw)
    aligned.scale(s)
    aligned.transform(lie.se3(r, t))
    ape_t = evo_metrics.APE(evo_metrics.PoseRelation.translation_part)
    ape_t.process_data((ref, aligned))
    ape_r = evo_metrics.APE(evo_metrics.PoseRelation.rotation_angle_deg)
    ape_r.process_data((ref, aligned))
    rel_rot = evo_all_pairs(ref, aligned, evo_metrics.PoseRelation.rotation_angle_deg)
    # Translation direction of cam_j_from_cam_i (sfmeval's convention) from evo's SE(3) algebra.
    rel_dir = {}
    for (i, j) in rel_rot:
        tg = lie.relative_se3(ref.poses_se3[j], ref.poses_se3[i])[:3, 3]
        te = lie.relative_se3(aligned.poses_se3[j], aligned.poses_se3[i])[:3, 3]
        c = np.linalg.norm(np.cross(tg, te))
        rel_dir[(i, j)] = float(np.degrees(np.arctan2(c, tg @ te)))
    sim = np.eye(4)
    sim[:3, :3], sim[:3, 3] = s * r, t
    return {
        "names": names, "sim": sim, "r": r, "s": s, "t": t,
        "center": dict(zip(names, ape_t.error)), "rotation": dict(zip(names, ape_r.error)),
        "ate_rmse": ape_t.get_statistic(evo_metrics.StatisticsType.rmse),
        "rel_rot": {(names[i], names[j]): e for (i, j), e in rel_rot.items()},
        "rel_dir": {(names[i], names[j]): e for (i, j), e in rel_dir.items()},
    }


# --- sfmeval --------------------------------------------------------------------------------

def run_cameras(sfmeval_bin, recon, tmp_path, transform=None):
    out = tmp_path / "cams.json"
    cmd = [sfmeval_bin, "cameras", "--gt-cameras", str(GT), "--recon", str(recon),
           "--report", str(out)]
    if transform is not None:
        tf = tmp_path / "gt_from_recon.txt"
        tf.write_text("\n".join(" ".join(repr(float(v)) for v in row) for row in transform) + "\n")
        cmd += ["--transform", str(tf)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return json.loads(out.read_text())


def rotation_angle_deg(r):
    from scipy.spatial.transform import Rotation

    return float(np.degrees(Rotation.from_matrix(r).magnitude()))


def compare_similarity(rep, ev, radius):
    a = rep["alignment"]
    m = np.array(a["gt_from_recon"])
    s = np.cbrt(np.linalg.det(m[:3, :3]))
    d_rot = rotation_angle_deg((m[:3, :3] / s) @ ev["r"].T)
    d_scale = abs(s / ev["s"] - 1)
    d_t = np.linalg.norm(m[:3, 3] - ev["t"]) / radius
    assert d_rot < TOL_SIM_DEG, d_rot
    assert d_scale < TOL_SIM_SCALE_REL, d_scale
    assert d_t < TOL_SIM_T_REL, d_t


def compare_errors(rep, ev, gt_order, radius):
    """Per-image and relative errors of a `cameras` report against evo's."""
    c = rep["cameras"]
    assert c["matched"] == len(ev["names"])
    per = {im["name"]: im for im in c["images"]}
    assert sorted(per) == ev["names"]

    for n in ev["names"]:
        dc = abs(per[n]["center_error"] - ev["center"][n]) / radius
        dr = abs(per[n]["rotation_error_deg"] - ev["rotation"][n])
        assert dc < TOL_LEN_REL, (n, per[n]["center_error"], ev["center"][n])
        assert dr < TOL_DEG, (n, per[n]["rotation_error_deg"], ev["rotation"][n])
    d_ate = abs(c["ate_rmse"] - ev["ate_rmse"]) / radius
    assert d_ate < TOL_LEN_REL, (c["ate_rmse"], ev["ate_rmse"])

    # Relative errors over all GT pairs; a pair with an image the estimate lacks is 180°
    # (sfmeval's documented convention; evo only sees matched poses).
    rel = c["relative"]
    pairs = [(a, b) for k, a in enumerate(gt_order) for b in gt_order[k + 1:]]
    assert rel["pairs"] == len(pairs)
    missing = [p for p in pairs if not (p[0] in ev["center"] and p[1] in ev["center"])]
    assert rel["pairs_unregistered"] == len(missing)
    for key, evo_key in (("rotation_error_deg", "rel_rot"),
                         ("translation_error_deg", "rel_dir")):
        want = np.array([180.0 if p in missing else ev[evo_key][tuple(sorted(p))]
                         for p in pairs])
        st = rel[key]
        got = {"min": st["min"], "max": st["max"], "mean": st["mean"], "median": st["median"],
               "std": st["std"], "rms": st["rms"]}
        ref = {"min": want.min(), "max": want.max(), "mean": want.mean(),
               "median": float(np.median(want)), "std": want.std(),
               "rms": float(np.sqrt(np.mean(want ** 2)))}
        for k in got:
            d = abs(got[k] - ref[k])
            assert d < TOL_DEG, (key, k, got[k], ref[k])
        assert st["count"] == len(pairs)
        acc_key = "rra" if key.startswith("rotation") else "rta"
        for acc in rel["accuracy"]:
            assert acc[acc_key] == pytest.approx(np.mean(want < acc["threshold_deg"]), abs=1e-12)


@pytest.mark.parametrize("model", list(MODELS))
def test_pose_errors_agree_with_evo(model, sfmeval_bin, tmp_path):
    gt, gt_order = read_gt()
    est = MODELS[model]()
    ev = evo_eval(gt, est)
    assert len(ev["names"]) >= 5, model
    centres = np.array([gt[n][1] for n in gt_order])
    radius = float(np.linalg.norm(centres - centres.mean(0), axis=1).mean())
    recon = FIX / model

    # sfmeval's own camera alignment: all cameras must be inliers, then its LO-RANSAC ends with
    # Umeyama on all centres, which is evo's alignment.
    rep = run_cameras(sfmeval_bin, recon, tmp_path)
    assert rep["alignment"]["method"] == "cameras"
    assert rep["alignment"]["inlier_ratio"] == 1.0, rep["alignment"]
    compare_similarity(rep, ev, radius)
    compare_errors(rep, ev, gt_order, radius)

    # The identical similarity: evo's, given to sfmeval.
    rep = run_cameras(sfmeval_bin, recon, tmp_path, transform=ev["sim"])
    assert np.allclose(rep["alignment"]["gt_from_recon"], ev["sim"], rtol=0, atol=0)
    compare_errors(rep, ev, gt_order, radius)

    # The errors are real (not all ~0): the comparison above had something to compare.
    assert max(ev["rotation"].values()) > 1e-3 and max(ev["center"].values()) > 1e-6 * radius


def test_outlier_camera_is_dropped_like_evo_on_the_inliers(sfmeval_bin, tmp_path):
    """colmap_bin with one camera moved far away: sfmeval keeps 5 of 6 cameras, and its
    similarity is evo's Umeyama on those 5; every error (the outlier's too) agrees with evo's
    under that similarity."""
    import pycolmap

    gt, gt_order = read_gt()
    rec = pycolmap.Reconstruction(str(FIX / "colmap_bin"))
    est = read_colmap(FIX / "colmap_bin")
    spread = np.linalg.norm(np.array([c for _, c in est.values()]) - np.mean(
        [c for _, c in est.values()], axis=0), axis=1).mean()
    victim = sorted(est)[2]
    image = next(im for im in rec.images.values() if im.name == victim)
    # Move its centre by the spread of the estimated centres: t' = t - R·Δc.
    r, c = est[victim]
    dc = np.array([1.0, 0.5, -0.3]) * spread
    frame = rec.frames[image.frame_id] if hasattr(image, "frame_id") else None
    if frame is not None and hasattr(frame, "rig_from_world"):
        pose = frame.rig_from_world
        pose.translation = np.asarray(pose.translation) - r @ dc
        frame.rig_from_world = pose
    else:
        pose = image.cam_from_world
        pose.translation = np.asarray(pose.translation) - r @ dc
        image.cam_from_world = pose
    out = tmp_path / "outlier_model"
    out.mkdir()
    rec.write_text(str(out))
    est2 = read_colmap(out)
    assert np.allclose(est2[victim][1], c + dc, atol=1e-6 * spread)
    assert all(np.allclose(est2[n][1], est[n][1]) for n in est if n != victim)

    inliers = [n for n in est2 if n != victim]
    ev = evo_eval(gt, est2, fit_names=inliers)
    centres = np.array([gt[n][1] for n in gt_order])
    radius = float(np.linalg.norm(centres - centres.mean(0), axis=1).mean())
    assert ev["center"][victim] > 0.3 * radius  # a real outlier under evo's inlier fit

    rep = run_cameras(sfmeval_bin, out, tmp_path)
    assert rep["alignment"]["inlier_ratio"] == pytest.approx(5 / 6), rep["alignment"]
    compare_similarity(rep, ev, radius)
    compare_errors(rep, ev, gt_order, radius)
    # evo's Umeyama on all six (outlier included) is far from it: the test sees the difference.
    ev_all = evo_eval(gt, est2)
    assert rotation_angle_deg(ev_all["r"] @ ev["r"].T) > 10 * TOL_SIM_DEG


def test_unregistered_image_counts_180(sfmeval_bin, tmp_path):
    """colmap_bin without one image: evo aligns and measures the five others; sfmeval agrees on
    them and counts the 5 pairs with the missing image as 180° in the relative statistics,
    RRA and RTA."""
    import pycolmap

    gt, gt_order = read_gt()
    rec = pycolmap.Reconstruction(str(FIX / "colmap_bin"))
    victim = sorted(im.name for im in rec.images.values())[3]
    rec.deregister_frame(next(im.frame_id for im in rec.images.values() if im.name == victim))
    out = tmp_path / "dropped_model"
    out.mkdir()
    rec.write_text(str(out))
    est = read_colmap(out)
    assert sorted(est) == sorted(n for n in gt if n != victim)
    ev = evo_eval(gt, est)
    centres = np.array([gt[n][1] for n in gt_order])
    radius = float(np.linalg.norm(centres - centres.mean(0), axis=1).mean())
    rep = run_cameras(sfmeval_bin, out, tmp_path)
    assert rep["alignment"]["inlier_ratio"] == 1.0
    assert rep["cameras"]["relative"]["pairs_unregistered"] == len(gt_order) - 1
    compare_similarity(rep, ev, radius)
    compare_errors(rep, ev, gt_order, radius)
