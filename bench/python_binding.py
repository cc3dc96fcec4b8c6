#!/usr/bin/env python3
"""sfmeval's Python package inside Python against Open3D's in-process cloud-to-mesh evaluation,
and the binding's overhead against the CLI, on the same files in one process.

  python bench/python_binding.py --mesh bench/data/mesh_1m.ply --cloud bench/data/cloud_1m.ply

Needs the wheel (`pip install target/wheels/sfmeval-*.whl`) and Open3D (requirements/bench.txt)
in the interpreter that runs it, and the release CLI (--bin, default target/release/sfmeval).
Rounds alternate the four runs (median of --rounds):

  cli          `sfmeval eval --gt MESH --recon CLOUD --align none`, the process's wall time
  py fresh     `sfmeval.evaluate(MESH, CLOUD, align="none")`, the first call of a new Python
               process (timed inside it: the CLI's work from a cold process, without the
               interpreter's start and imports)
  py path      the same call again and again in this process (reading included; a warm process
               reuses the memory it freed, which a new CLI process has to fault in)
  py array     `sfmeval.evaluate(MESH, points, align="none")`, the cloud already a numpy array
  open3d       read_triangle_mesh + read_point_cloud, RaycastingScene.compute_distance of every
               point (accuracy) and sample_points_uniformly + compute_point_cloud_distance
               (completeness): bench/anchors/open3d_ops.py's `eval`, in this process

The binding overhead is `py fresh` against `cli` (the same work, files to report, each from a
cold process; the CLI's figure also holds its process start, about 1 ms); the report
of `py path` must be the CLI's byte for byte and its accuracy mean Open3D's to 1e-4 (float32).
Prints one markdown table.
"""
import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import open3d as o3d

sys.path.insert(0, str(Path(__file__).resolve().parent / "anchors"))
from open3d_ops import accuracy, completeness  # noqa: E402

import sfmeval  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mesh", required=True)
    ap.add_argument("--cloud", required=True)
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--bin", default=str(ROOT / "target/release/sfmeval"))
    a = ap.parse_args()
    times = {"cli": [], "py fresh": [], "py path": [], "py array": [], "open3d": []}
    fresh = ("import sys, time, sfmeval; t = time.perf_counter(); "
             "sfmeval.evaluate(sys.argv[1], sys.argv[2], align='none', samples=int(sys.argv[3]));"
             " print(time.perf_counter() - t)")
    points = sfmeval.read(a.cloud).points
    with tempfile.TemporaryDirectory() as tmp:
        cli_report = Path(tmp) / "report.json"
        for _ in range(a.rounds):
            t = time.perf_counter()
            subprocess.run([a.bin, "eval", "--gt", a.mesh, "--recon", a.cloud, "--align", "none",
                            "--samples", str(a.samples), "--quiet", "--report", str(cli_report)],
                           check=True)
            times["cli"].append(time.perf_counter() - t)
            p = subprocess.run([sys.executable, "-c", fresh, a.mesh, a.cloud, str(a.samples)],
                               check=True, capture_output=True, text=True)
            times["py fresh"].append(float(p.stdout))
            t = time.perf_counter()
            by_path = sfmeval.evaluate(a.mesh, a.cloud, align="none", samples=a.samples)
            times["py path"].append(time.perf_counter() - t)
            t = time.perf_counter()
            by_array = sfmeval.evaluate(a.mesh, points, align="none", samples=a.samples,
                                        name=Path(a.cloud).name)
            times["py array"].append(time.perf_counter() - t)
            t = time.perf_counter()
            mesh, pcd = o3d.io.read_triangle_mesh(a.mesh), o3d.io.read_point_cloud(a.cloud)
            acc = accuracy(mesh, np.asarray(pcd.points), 0)
            completeness(mesh, pcd, a.samples)
            times["open3d"].append(time.perf_counter() - t)
        assert by_path.to_json().encode() == cli_report.read_bytes(), "py path != the CLI's report"
        assert by_array.to_json() == by_path.to_json(), "py array != py path"
    mean, o3d_mean = by_path.accuracy.mean, float(np.mean(acc))
    assert abs(mean - o3d_mean) <= 1e-4 * abs(o3d_mean), (mean, o3d_mean)
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"| {len(points):,} points, {a.samples:,} samples, {a.rounds} rounds (median) | seconds "
          "| Open3D in-process ÷ this |")
    print("|---|---|---|")
    for k, v in med.items():
        print(f"| {k} | {v:.2f} | {med['open3d'] / v:.2f}× |")
    print(f"\nbinding overhead (py fresh ÷ cli − 1): {100 * (med['py fresh'] / med['cli'] - 1):+.1f} %;"
          f" accuracy mean {mean:.9g} (Open3D {o3d_mean:.9g}); all rounds: {json.dumps(times)}")


if __name__ == "__main__":
    main()
