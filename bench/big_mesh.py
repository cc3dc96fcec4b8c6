#!/usr/bin/env python3
"""Big ground-truth mesh: `sfmeval eval` against Open3D's cloud-to-mesh distance, in one run.

  .venv/bin/python bench/big_mesh.py [--data DIR] [--rounds 2] [--cli target/release/sfmeval]

On bench/generate.py --big-mesh's workload (written into DIR when missing): the 10M-triangle
height field mesh_height_10m.ply (5.0M vertices, 190 MB) and cloud_height_1m.ply (1M noisy points
on it). Each round runs, alternately, each in its own process under GNU time:
  sfmeval  `sfmeval eval --align none --samples 1000000` (read, BVH, accuracy, 1M completeness
           samples, report): the whole evaluation;
  Open3D   bench/anchors/open3d_ops.py accuracy (read_triangle_mesh, RaycastingScene build and
           compute_distance of every point): the cloud-to-mesh distance alone.
Prints each round's wall time and peak RSS, the medians (wall) and maxima (peak), and the ratios
(Open3D / sfmeval wall: the speed-up; sfmeval / Open3D peak: the memory ratio, ≤ 1 is the aim).
The accuracy means must agree within compare.py's ACC_TOL (Open3D computes in float32); exits 1
when they do not or a tool fails.
"""
import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
from compare import ACC_TOL, last_json, rel, run_with_peak  # noqa: E402

MESH, CLOUD = "mesh_height_10m.ply", "cloud_height_1m.ply"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=str(ROOT / "bench" / "data"))
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--cli", default=str(ROOT / "target" / "release" / "sfmeval"))
    ap.add_argument("--samples", type=int, default=1_000_000)
    args = ap.parse_args()
    data = Path(args.data)
    mesh, cloud = data / MESH, data / CLOUD
    if not (mesh.exists() and cloud.exists()):
        subprocess.run([sys.executable, str(ROOT / "bench" / "generate.py"), "--out", str(data), "--big-mesh"],
                       check=True)
    with tempfile.TemporaryDirectory() as work:
        report = Path(work) / "report.json"
        tools = {
            "sfmeval": [args.cli, "eval", "--gt", str(mesh), "--recon", str(cloud), "--samples",
                        str(args.samples), "--align", "none", "--quiet", "--report", str(report)],
            "Open3D": [sys.executable, str(ROOT / "bench" / "anchors" / "open3d_ops.py"), "accuracy",
                       "--mesh", str(mesh), "--cloud", str(cloud)],
        }
        walls = {t: [] for t in tools}
        peaks = {t: [] for t in tools}
        means = {}
        for r in range(args.rounds):
            order = list(tools) if r % 2 == 0 else list(reversed(tools))
            for tool in order:
                wall, peak, rc, out, err = run_with_peak(tools[tool])
                if rc != 0:
                    print(f"{tool} failed (exit {rc}): {(err or out)[-800:]}")
                    return 1
                means[tool] = (json.loads(report.read_text())["accuracy"]["mean"] if tool == "sfmeval"
                               else last_json(out)["result"]["mean"])
                walls[tool].append(wall)
                peaks[tool].append(peak)
                print(f"round {r + 1} {tool:8s} {wall:7.2f} s {peak:8.0f} MiB")
    wall = {t: statistics.median(v) for t, v in walls.items()}
    peak = {t: max(v) for t, v in peaks.items()}
    print()
    print("| | wall (median) | peak RSS (max) |")
    print("|---|---|---|")
    for t in tools:
        print(f"| {t} | {wall[t]:.2f} s | {peak[t]:.0f} MiB |")
    print(f"\nspeed-up (Open3D wall / sfmeval wall): {wall['Open3D'] / wall['sfmeval']:.2f}x; "
          f"memory (sfmeval peak / Open3D peak): {peak['sfmeval'] / peak['Open3D']:.3f}")
    agree = rel(means["Open3D"], means["sfmeval"]) <= ACC_TOL
    print(f"accuracy mean: sfmeval {means['sfmeval']:.9g}, Open3D {means['Open3D']:.9g} "
          f"({'agree' if agree else 'DISAGREE'} within {ACC_TOL:g})")
    return 0 if agree else 1


if __name__ == "__main__":
    sys.exit(main())
