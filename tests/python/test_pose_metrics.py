"""Camera-pose metrics: an independent numpy/scipy implementation on the committed SfM fixtures.

`tests/fixtures/models/pose_expected.json` holds what this file computes (the similarity used,
per-image rotation/centre errors, relative-pose errors, RRA/RTA, AUC, focal errors). The Rust
test `pose::tests::agrees_with_numpy_reference` evaluates the same models with the same
similarity and must reproduce these numbers; the test here checks that the committed file is what
numpy gives today. Regenerate with:

    .venv/bin/python tests/python/test_pose_metrics.py --write

Models are read with pycolmap (COLMAP text/binary), independently of sfmeval's readers.
"""
import json
import sys
from itertools import combinations
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
FIX = ROOT / "tests" / "fixtures" / "models"
EXPECTED = FIX / "pose_expected.json"
MODELS = ["colmap_bin", "colmap_text", "openmvg_colmap", "theia_colmap"]


def rot_angle_deg(r):
    from scipy.spatial.transform import Rotation

    return float(np.degrees(Rotation.from_matrix(r).magnitude()))


def vec_angle_deg(a, b):
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0 and nb == 0:
        return 0.0
    if na == 0 or nb == 0:
        return 180.0
    return float(np.degrees(np.arccos(np.clip(a @ b / (na * nb), -1.0, 1.0))))


def umeyama(src, dst):
    ms, md = src.mean(0), dst.mean(0)
    a, b = src - ms, dst - md
    u, s, vt = np.linalg.svd(b.T @ a / len(src))
    d = np.eye(3)
    if np.linalg.det(u @ vt) < 0:
        d[2, 2] = -1
    r = u @ d @ vt
    scale = np.trace(np.diag(s) @ d) / (a ** 2).sum(1).mean()
    m = np.eye(4)
    m[:3, :3] = scale * r
    m[:3, 3] = md - scale * r @ ms
    return m


def load_gt():
    gt = json.loads((FIX / "gt_cameras.json").read_text())
    cams = {c["id"]: c for c in gt["cameras"]}
    images = [(im["name"], np.array(im["cam_from_world"]["rotation"]),
               np.array(im["cam_from_world"]["translation"]), cams[im["camera_id"]])
              for im in gt["images"]]
    return images


def load_est(name):
    import pycolmap

    rec = pycolmap.Reconstruction(str(FIX / name))
    out = {}
    for im in rec.images.values():
        pose = im.cam_from_world() if callable(im.cam_from_world) else im.cam_from_world
        m = np.asarray(pose.matrix())
        # pycolmap does not normalise a quaternion read from text (Theia prints 6 digits), and
        # Eigen's matrix of an unnormalised quaternion is not a rotation: rebuild it from the
        # normalised quaternion (scipy normalises; pycolmap's quat is x, y, z, w).
        from scipy.spatial.transform import Rotation

        m[:, :3] = Rotation.from_quat(np.asarray(pose.rotation.quat)).as_matrix()
        cam = rec.cameras[im.camera_id]
        f = float(np.mean([cam.params[i] for i in cam.focal_length_idxs()]))
        out[im.name] = (m[:, :3], m[:, 3], f, cam.width, im.camera_id)
    return out


def metrics(gt, est):
    names = [g[0] for g in gt]
    matched = [n for n in names if n in est]
    cg = {n: -r.T @ t for n, r, t, _ in gt}
    ce = {n: -e[0].T @ e[1] for n, e in est.items()}
    sim = umeyama(np.array([ce[n] for n in matched]), np.array([cg[n] for n in matched]))
    scale = np.cbrt(np.linalg.det(sim[:3, :3]))
    rs = sim[:3, :3] / scale
    centres = np.array([cg[n] for n in names])
    radius = float(np.linalg.norm(centres - centres.mean(0), axis=1).mean())
    per_image = {}
    in_gt = {}
    for n, rg, tg, _ in gt:
        if n not in est:
            continue
        re, te = est[n][0], est[n][1]
        r_in_gt = re @ rs.T
        c_in_gt = sim[:3, :3] @ ce[n] + sim[:3, 3]
        in_gt[n] = (r_in_gt, -r_in_gt @ c_in_gt)
        per_image[n] = {"rotation_error_deg": rot_angle_deg(rg @ r_in_gt.T),
                        "center_error": float(np.linalg.norm(c_in_gt - cg[n]))}
    rot_rel, trans_rel = [], []
    gtd = {n: (r, t) for n, r, t, _ in gt}
    for a, b in combinations(names, 2):
        if a not in in_gt or b not in in_gt:
            rot_rel.append(180.0)
            trans_rel.append(180.0)
            continue
        def rel(p, q):
            r = q[0] @ p[0].T
            return r, q[1] - r @ p[1]
        rg, tg = rel(gtd[a], gtd[b])
        re, te = rel(in_gt[a], in_gt[b])
        rot_rel.append(rot_angle_deg(rg.T @ re))
        trans_rel.append(vec_angle_deg(tg, te))
    rot_rel, trans_rel = np.array(rot_rel), np.array(trans_rel)
    worst = np.maximum(rot_rel, trans_rel)
    hist, _ = np.histogram(worst, bins=np.arange(31))
    auc = float(np.mean(np.cumsum(hist) / len(worst)))
    center_errors = np.array([v["center_error"] for v in per_image.values()])
    gcam = gt[0][3]
    focal = []
    for cam_id in sorted({e[4] for e in est.values()}):
        f, w = next((e[2], e[3]) for e in est.values() if e[4] == cam_id)
        fg = 0.5 * (gcam["fx"] + gcam["fy"])
        f = f * gcam["width"] / w
        focal.append({"camera_id": int(cam_id), "error_percent": 100.0 * (f - fg) / fg})
    return {
        "gt_from_recon": sim.tolist(),
        "matched": len(matched),
        "scene_radius": radius,
        "ate_rmse": float(np.sqrt(np.mean(center_errors ** 2))),
        "images": per_image,
        "relative_rotation_error_deg": rot_rel.tolist(),
        "relative_translation_error_deg": trans_rel.tolist(),
        "accuracy": [{"threshold_deg": t, "rra": float(np.mean(rot_rel < t)),
                      "rta": float(np.mean(trans_rel < t))} for t in (5.0, 10.0, 15.0)],
        "auc": auc,
        "focal": focal,
    }


def compute_all():
    gt = load_gt()
    return {name: metrics(gt, load_est(name)) for name in MODELS}


def test_committed_reference_is_what_numpy_computes():
    pytest.importorskip("pycolmap")
    pytest.importorskip("scipy")
    want = json.loads(EXPECTED.read_text())
    got = compute_all()
    assert set(want) == set(got)
    for name in got:
        g, w = got[name], want[name]
        np.testing.assert_allclose(g["gt_from_recon"], w["gt_from_recon"], rtol=0, atol=1e-9)
        for n, v in g["images"].items():
            for k in v:
                assert abs(v[k] - w["images"][n][k]) < 1e-9, (name, n, k)
        np.testing.assert_allclose(g["relative_rotation_error_deg"],
                                   w["relative_rotation_error_deg"], atol=1e-7)
        np.testing.assert_allclose(g["relative_translation_error_deg"],
                                   w["relative_translation_error_deg"], atol=1e-7)
        assert abs(g["auc"] - w["auc"]) < 1e-12
        assert abs(g["ate_rmse"] - w["ate_rmse"]) < 1e-9


def test_numpy_reference_is_sane():
    """The reference itself on the fixtures: every tool within 3 % of the scene radius."""
    pytest.importorskip("pycolmap")
    for name, m in json.loads(EXPECTED.read_text()).items():
        assert m["matched"] == 6
        worst = max(v["center_error"] for v in m["images"].values())
        assert 100 * worst / m["scene_radius"] < 3.0, name


if __name__ == "__main__":
    if "--write" in sys.argv:
        EXPECTED.write_text(json.dumps(compute_all(), indent=1) + "\n")
        print("wrote", EXPECTED)
