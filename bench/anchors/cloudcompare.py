"""CloudCompare anchor (Debian `cloudcompare` 2.11.3, command line, headless).

CloudCompare is one process per command line, so it cannot time one operation from inside a
script: `bench/compare.py` runs each op's command line and a baseline command line that only
loads the same files, and takes the op's seconds as the difference of CloudCompare's own
"Processed finished in X s" lines (both exclude Qt start-up and plugin loading). The numbers
come from one extra, untimed run that also saves the clouds as ASCII.

Headless quirks handled here: QT_QPA_PLATFORM=offscreen (no X server), -SILENT (no console
window), -AUTO_SAVE OFF (every command would otherwise write its result next to the input),
-NO_TIMESTAMP (predictable output names), output files land next to the *input path*, so the
driver gives symlinks inside a scratch directory (never the data directory), and C2M distances
are signed (the absolute value is compared). Wrong answers seen: on bench/data's 1M-triangle
mesh, C2M overestimates the distance of points near the two poles, where 1000 sliver triangles
meet (cloud_10k: 96 points off by more than 1e-4 relative, some 0.0005 → 0.018; the mean is
0.1 % high), so compare.py flags its accuracy there; on the 50k mesh it agrees to 1e-10. Its
ICP runs one C2M pass per iteration: minutes on 100k points. No separate index build (its octree is internal)
and no whole-`eval` equivalent in one command line.

  load          -O mesh -O cloud
  accuracy      -c2m_dist (exact point-to-triangle distance, octree-accelerated)
  completeness  -SAMPLE_MESH POINTS samples, then -c2c_dist of the samples to the cloud
  c2c           -c2c_dist of the queries to the cloud (exact nearest neighbour)
  align         -APPLY_TRANS start, then -ICP -ADJUST_SCALE (the mesh is the reference),
                -OVERLAP 95, at most 100 iterations, -MIN_ERROR_DIFF 1e-5 (its default)
"""
import os
import re
import shutil
from pathlib import Path

import numpy as np

BINARY = "CloudCompare"
OPS = ("load", "accuracy", "completeness", "c2c", "align")
BASE = [BINARY, "-SILENT", "-NO_TIMESTAMP", "-AUTO_SAVE", "OFF"]
SAVE = ["-C_EXPORT_FMT", "ASC", "-SAVE_CLOUDS"]


def available():
    return shutil.which(BINARY) is not None


def env():
    return dict(os.environ, QT_QPA_PLATFORM="offscreen")


def commands(op, f, samples):
    """(baseline or None, op command, extra arguments of the untimed check run) for op.
    `f` maps mesh/cloud/queries/moved/start to file names inside the scratch directory."""
    if op == "load":
        return None, BASE + ["-O", f["mesh"], "-O", f["cloud"]], []
    if op == "accuracy":
        load = ["-O", f["cloud"], "-O", f["mesh"]]
        return BASE + load, BASE + load + ["-c2m_dist"], SAVE
    if op == "completeness":
        return (BASE + ["-O", f["mesh"], "-O", f["cloud"]],
                BASE + ["-O", f["mesh"], "-SAMPLE_MESH", "POINTS", str(samples), "-O", f["cloud"], "-c2c_dist"], SAVE)
    if op == "c2c":
        load = ["-O", f["queries"], "-O", f["cloud"]]
        return BASE + load, BASE + load + ["-c2c_dist"], SAVE
    if op == "align":
        load = ["-O", f["moved"], "-APPLY_TRANS", f["start"], "-O", f["mesh"]]
        icp = ["-ICP", "-ADJUST_SCALE", "-ITER", "100", "-MIN_ERROR_DIFF", "1e-5", "-OVERLAP", "95"]
        return BASE + load, BASE + load + icp, []
    raise ValueError(op)


def finished_seconds(stdout):
    m = re.findall(r"Processed finished in ([0-9.]+) s", stdout)
    if not m:
        raise RuntimeError("CloudCompare printed no 'Processed finished' line:\n" + stdout[-2000:])
    return float(m[-1])


def _distances(path):
    d = np.abs(np.loadtxt(path, usecols=3, ndmin=1))
    return {"n": int(d.size), "mean": float(d.mean()), "max": float(d.max())}


def result(op, f, work: Path):
    """The op's numbers from the files CloudCompare wrote into `work`."""
    stem = lambda k: Path(f[k]).stem
    if op == "accuracy":
        return _distances(work / f"{stem('cloud')}_C2M_DIST.asc")
    if op == "completeness":
        return _distances(work / f"{stem('mesh')}_SAMPLED_POINTS_C2C_DIST.asc")
    if op == "c2c":
        return _distances(work / f"{stem('queries')}_C2C_DIST.asc")
    if op == "align":
        icp = np.loadtxt(work / f"{stem('moved')}_REGISTRATION_MATRIX.txt").reshape(4, 4)
        start = np.loadtxt(work / f["start"], comments="#").reshape(4, 4)
        return {"matrix": (icp @ start).tolist()}
    return {}


def load_result(stdout):
    """Triangle and point counts from the load log."""
    tri = re.search(r"Found one mesh with (\d+) faces and (\d+) vertices", stdout)
    pts = re.search(r"Found one cloud with (\d+) points", stdout)
    return {"vertices": int(tri.group(2)) if tri else None, "triangles": int(tri.group(1)) if tri else None,
            "points": int(pts.group(1)) if pts else None}
