"""sfmeval poses against the pose protocols' official code, same scene, same run.

A synthetic SfM result: N ground-truth cameras on a sphere looking at its centre (COLMAP text),
and an estimate of them in another gauge (a similarity applied) with rotation and position noise,
5 % of the images unregistered (COLMAP text). Each protocol runs as a whole process both ways:
`sfmeval poses --protocol P --json` and the vendored official code through
tests/python/pose_protocols_reference.py (COLMAP's benchmark utils, the Image Matching
Benchmark's mAA, VGGSfM's metric ported to numpy). The headline numbers must agree (1e-9 for
COLMAP and CO3D, 1e-6 for IMC's mAA, whose angles go through acos(1-2*loss)).

    .venv/bin/python bench/poses.py [--images N] [--rounds R] [--quick]
"""
import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tests" / "python"))
from timing import measure_cpu  # noqa: E402
import pose_protocols_reference as ref  # noqa: E402

CAMERA = {"id": 1, "width": 640, "height": 480, "fx": 500.0, "fy": 500.0, "cx": 320.0, "cy": 240.0}

# The official code as one process per protocol, printing the headline numbers as JSON.
REFERENCE = r"""
import json, sys, tempfile
sys.path.insert(0, sys.argv[1])
import numpy as np
import pose_protocols_reference as ref
protocol, gt, est = sys.argv[2], sys.argv[3], sys.argv[4]
gt_images = [(n, ref.qvec2rotmat(q), t) for n, q, t in ref.model_poses(gt)]
if protocol == "colmap":
    _, aucs, recalls = ref.colmap_reference(gt, est)
    out = {"auc": list(map(float, aucs)), "recall": list(map(float, recalls))}
elif protocol == "imc":
    with tempfile.TemporaryDirectory() as tmp:
        res, _ = ref.imc_reference(gt_images, est, tmp)
    out = {"maa_5": float(res["qt_auc_colmap_05"]), "maa_10": float(res["qt_auc_colmap_10"])}
else:
    est_by = {n: (ref.qvec2rotmat(q), t) for n, q, t in ref.model_poses(est)}
    m, _, _ = ref.co3d_reference(gt_images, est_by)
    out = {"rra": [float(m[f"Racc_{t}"]) for t in (5, 15, 30)],
           "rta": [float(m[f"Tacc_{t}"]) for t in (5, 15, 30)], "auc": float(m["Auc_30"])}
print(json.dumps(out))
"""


def look_at(center):
    """cam_from_world (R, t) of a camera at `center` looking at the origin (OpenCV axes)."""
    z = -center / np.linalg.norm(center)
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    r = np.stack([x, y, z])
    return r, -r @ center


def small_rotation(rng, sigma_rad):
    w = rng.normal(0.0, sigma_rad, 3)
    a = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / max(a, 1e-300)
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k


def make_scene(folder: Path, n: int, seed: int = 7):
    """GT and estimate folders (COLMAP text) of n images."""
    rng = np.random.default_rng(seed)
    gt, est = [], []
    # A similarity est_from_gt: the estimate lives in another gauge.
    s, r_g = 0.37, small_rotation(rng, 1.0)
    t_g = np.array([0.5, -1.2, 2.0])
    for k in range(n):
        phi = np.arccos(1 - 2 * (k + 0.5) / n)
        theta = np.pi * (1 + 5 ** 0.5) * k
        c = 3.0 * np.array([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)])
        c[2] = abs(c[2]) + 0.3
        r, t = look_at(c)
        name = f"{k:05d}.jpg"
        gt.append((name, r, t))
        if rng.random() < 0.05:
            continue
        c_noisy = c + rng.normal(0.0, 0.02, 3)
        r_noisy = small_rotation(rng, np.deg2rad(0.5)) @ r
        c_est = s * r_g @ c_noisy + t_g
        r_est = r_noisy @ r_g.T
        est.append((name, r_est, -r_est @ c_est))
    return (ref.write_colmap_text(gt, [CAMERA], folder / "gt"),
            ref.write_colmap_text(est, [CAMERA], folder / "est"))


def headline(protocol, rep):
    r = rep["result"]
    if protocol == "colmap":
        return {"auc": r["auc_percent"], "recall": r["recall_percent"]}
    if protocol == "imc":
        return {"maa_5": r["maa_5"], "maa_10": r["maa_10"]}
    return {"rra": r["rra_percent"], "rta": r["rta_percent"], "auc": r["auc_percent"]}


def agree(ours, official, tol):
    """Every headline number of `ours` within `tol` of the official code's (same keys)."""
    return ours.keys() == official.keys() and all(
        np.all(np.abs(np.atleast_1d(ours[k]) - np.atleast_1d(official[k])) <= tol) for k in ours)


def cpu_ratio(ours_s, theirs_s):
    """GNU time counts CPU in 10 ms ticks: below one tick the ratio is not measured."""
    return f"{theirs_s / ours_s:.1f}×" if ours_s >= 0.01 else "(under 10 ms)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--images", type=int, default=400)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="60 images, one round")
    a = ap.parse_args()
    if a.quick:
        a.images, a.rounds = 60, 1
    sfmeval = os.environ.get("SFMEVAL_BIN", str(ROOT / "target" / "release" / "sfmeval"))
    python = os.environ.get("SFMEVAL_PYTHON", sys.executable)
    with tempfile.TemporaryDirectory() as tmp:
        gt, est = make_scene(Path(tmp), a.images)
        n_est = len(ref.model_poses(est))
        print(f"poses: {a.images} ground-truth images, {n_est} registered, "
              f"{a.images * (a.images - 1) // 2} pairs; median of {a.rounds}")
        print("| protocol | sfmeval (wall, CPU, peak) | official code (wall, CPU, peak) | ratio (wall / CPU) | numbers |")
        print("|---|---|---|---|---|")
        failed = False
        for protocol, tol in (("colmap", 1e-9), ("imc", 1e-6), ("co3d", 1e-9)):
            ours = measure_cpu([sfmeval, "poses", "--gt-cameras", gt, "--recon", est,
                                "--protocol", protocol, "--json"], a.rounds,
                               lambda out, p=protocol: headline(p, json.loads(out)))
            theirs = measure_cpu([python, "-c", REFERENCE, str(ROOT / "tests" / "python"),
                                  protocol, gt, est], a.rounds,
                                 lambda out: json.loads(out.strip().splitlines()[-1]))
            ok = agree(ours[3], theirs[3], tol)
            failed |= not ok
            print(f"| {protocol} | {ours[0]:.3f} s, {ours[1]:.3f} s, {ours[2]:.0f} MiB "
                  f"| {theirs[0]:.3f} s, {theirs[1]:.3f} s, {theirs[2]:.0f} MiB "
                  f"| {theirs[0] / ours[0]:.1f}× / {cpu_ratio(ours[1], theirs[1])} "
                  f"| {'agree' if ok else 'DIFFER'} |")
            if not ok:
                print(f"  sfmeval {ours[3]}\n  official {theirs[3]}")
        if failed:
            raise SystemExit("bench poses: the numbers differ from the official code's")


if __name__ == "__main__":
    main()
