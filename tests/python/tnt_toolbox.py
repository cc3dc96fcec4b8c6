"""Runs the Tanks and Temples evaluation toolbox (tests/third_party/tanksandtemples_evaluation,
vendored unmodified) on the installed Open3D, adapting only the three call sites whose API moved
since Open3D 0.9 (see that folder's README), and prints its numbers as JSON on the last line.

  python tnt_toolbox.py run   SCENE_DIR TRAJ.log RECON.ply OUT_DIR TAU
  python tnt_toolbox.py histo SCENE_DIR RECON.ply TRANSFORM.txt OUT_DIR TAU

`run` is the toolbox's whole `run_evaluation`; `histo` its `EvaluateHisto` with the final
transform fixed. TAU is added to the toolbox's τ table under the scene's folder name.
"""
import json
import os
import sys
import time
import types
from pathlib import Path

import numpy as np
import open3d as o3d

TOOLBOX = Path(__file__).resolve().parents[1] / "third_party" / "tanksandtemples_evaluation"
_reg = o3d.pipelines.registration


class _RansacCriteria:
    """The 0.9 criteria object the toolbox fills (max_iteration, max_validation)."""

    def __init__(self):
        self.max_iteration = 100000
        self.max_validation = 100000


def _ransac_on_correspondence(source, target, corres, distance, estimation, ransac_n, criteria):
    """0.9's positional order (criteria after ransac_n) onto the current signature. 0.9 drew
    all `max_iteration` samples (`max_validation` only capped the validations); the current
    criteria stop early once a sample reaches `confidence`, 0.999 by default, which is not the
    toolbox's algorithm: confidence 1.0 never stops early (log(1 - 1) makes the estimate NaN or
    infinite), so every sample is drawn as in 0.9."""
    return _reg.registration_ransac_based_on_correspondence(
        source, target, corres, distance, estimation, ransac_n, [],
        _reg.RANSACConvergenceCriteria(criteria.max_iteration, 1.0))


_shim = types.SimpleNamespace(**{k: getattr(_reg, k) for k in dir(_reg) if not k.startswith("_")})
_shim.RANSACConvergenceCriteria = _RansacCriteria
_shim.registration_ransac_based_on_correspondence = _ransac_on_correspondence
o3d.registration = _shim
sys.path.insert(0, str(TOOLBOX))

import config  # noqa: E402
import evaluation  # noqa: E402
import run  # noqa: E402


def main():
    mode, scene_dir = sys.argv[1], sys.argv[2]
    scene = os.path.basename(os.path.normpath(scene_dir))
    tau = float(sys.argv[-1])
    config.scenes_tau_dict[scene] = tau
    t0 = time.perf_counter()
    if mode == "run":
        _, _, _, traj, ply, out, _ = sys.argv
        run.run_evaluation(dataset_dir=scene_dir, traj_path=traj, ply_path=ply, out_dir=out)
    elif mode == "histo":
        _, _, _, ply, transform, out, _ = sys.argv
        os.makedirs(out, exist_ok=True)
        pcd = o3d.io.read_point_cloud(ply)
        gt = o3d.io.read_point_cloud(os.path.join(scene_dir, scene + ".ply"))
        vol = o3d.visualization.read_selection_polygon_volume(os.path.join(scene_dir, scene + ".json"))
        evaluation.EvaluateHisto(pcd, gt, np.loadtxt(transform), vol, tau / 2.0, tau, out, 5, scene)
    else:
        raise SystemExit(f"unknown mode {mode}")
    seconds = time.perf_counter() - t0
    p, r, f, _, _ = np.loadtxt(os.path.join(out, scene + ".prf_tau_plotstr.txt"))
    print(json.dumps({"precision": p, "recall": r, "f_score": f, "seconds": seconds}))


if __name__ == "__main__":
    main()
