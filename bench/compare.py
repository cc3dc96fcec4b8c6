#!/usr/bin/env python3
"""Times `sfmeval eval` against Open3D and trimesh on the same files, each run in its own
process, several rounds, and prints the median wall time, peak memory and the speed-up of
sfmeval over the fastest anchor. Also checks that the tools agree on the mean distances.

  bench/compare.py [--data bench/data] [--rounds 3] [--sizes 10k,100k,1m] [--mesh 1m] [--threads N]

The whole `eval` is compared with the same work in each anchor: load both files, accuracy
(every point → exact closest point on the mesh), completeness (S area-uniform samples on the mesh →
nearest reconstructed point), and the statistics. Run bench/generate.py first.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

OPEN3D = r"""
import sys, json, numpy as np, open3d as o3d
mesh_path, cloud_path, samples, threads = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
mesh = o3d.io.read_triangle_mesh(mesh_path)
pts = np.asarray(o3d.io.read_point_cloud(cloud_path).points)
scene = o3d.t.geometry.RaycastingScene(nthreads=threads)
scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
acc = scene.compute_distance(o3d.core.Tensor(pts.astype(np.float32)), nthreads=threads).numpy().astype(np.float64)
samp = mesh.sample_points_uniformly(samples)
cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
comp = np.asarray(samp.compute_point_cloud_distance(cloud))
out = {}
for k, d in (("accuracy", acc), ("completeness", comp)):
    out[k] = dict(mean=float(d.mean()), median=float(np.median(d)), std=float(d.std()), max=float(d.max()),
                  rms=float(np.sqrt((d ** 2).mean())), p90=float(np.percentile(d, 90)))
print(json.dumps(out))
"""

TRIMESH = r"""
import sys, json, numpy as np, trimesh
from scipy.spatial import cKDTree
mesh_path, cloud_path, samples = sys.argv[1], sys.argv[2], int(sys.argv[3])
mesh = trimesh.load(mesh_path, process=False, force="mesh")
pts = np.asarray(trimesh.load(cloud_path).vertices, dtype=np.float64)
_, acc, _ = trimesh.proximity.closest_point(mesh, pts)
samp, _ = trimesh.sample.sample_surface(mesh, samples, seed=0)
comp, _ = cKDTree(pts).query(samp, workers=-1)
out = {}
for k, d in (("accuracy", acc), ("completeness", comp)):
    out[k] = dict(mean=float(d.mean()), median=float(np.median(d)), std=float(d.std()), max=float(d.max()),
                  rms=float(np.sqrt((d ** 2).mean())), p90=float(np.percentile(d, 90)))
print(json.dumps(out))
"""


def run_measured(cmd, env=None):
    """Runs cmd, returns (wall seconds, peak RSS MiB, stdout)."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    out = p.stdout.read()
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd[:2]))[:200]} exited with {os.waitstatus_to_exitcode(status)}: {err.decode()[-2000:]}")
    return wall, usage.ru_maxrss / 1024.0, out.decode()


def median_run(cmd, rounds, env=None):
    runs = [run_measured(cmd, env) for _ in range(rounds)]
    walls = [r[0] for r in runs]
    return statistics.median(walls), max(r[1] for r in runs), runs[-1][2]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=str(ROOT / "bench" / "data"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--sizes", default="10k,100k,1m")
    ap.add_argument("--mesh", default="1m")
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--trimesh-max", type=int, default=10_000, help="skip trimesh above this many points (it is very slow)")
    ap.add_argument("--sfmeval", default=str(ROOT / "target" / "release" / "sfmeval"))
    args = ap.parse_args()
    data = Path(args.data)
    mesh = data / f"mesh_{args.mesh}.ply"
    py = sys.executable
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for size in args.sizes.split(","):
            cloud = data / f"cloud_{size}.ply"
            n = {"10k": 10_000, "100k": 100_000, "1m": 1_000_000}.get(size, 0)
            rep = Path(tmp) / "r.json"
            ours = median_run([args.sfmeval, "eval", "--gt", str(mesh), "--recon", str(cloud), "--samples", str(args.samples),
                               "--threads", str(args.threads), "--align", "none", "--quiet", "--report", str(rep)], args.rounds)
            report = json.loads(rep.read_text())
            o3d = median_run([py, "-c", OPEN3D, str(mesh), str(cloud), str(args.samples), str(args.threads)], args.rounds)
            anchors = {"Open3D": o3d}
            if n <= args.trimesh_max:
                anchors["trimesh+scipy"] = median_run([py, "-c", TRIMESH, str(mesh), str(cloud), str(args.samples)], max(1, args.rounds // 2))
            fastest = min(anchors, key=lambda k: anchors[k][0])
            o3d_stats = json.loads(o3d[2])
            agree = abs(report["accuracy"]["mean"] - o3d_stats["accuracy"]["mean"]) / o3d_stats["accuracy"]["mean"]
            agree_c = abs(report["completeness"]["mean"] - o3d_stats["completeness"]["mean"]) / o3d_stats["completeness"]["mean"]
            rows.append((size, ours, anchors, fastest, agree, agree_c))
    print(f"\nwhole eval, {mesh.name} ({args.samples} completeness samples), {args.threads} threads, median of {args.rounds}\n")
    print("| points | sfmeval | Open3D | trimesh+scipy | speed-up vs fastest anchor | mean accuracy / completeness vs Open3D |")
    print("|---|---|---|---|---|---|")
    for size, ours, anchors, fastest, agree, agree_c in rows:
        cell = lambda r: f"{r[0]:.2f} s, {r[1]:.0f} MiB" if r else "—"
        print(f"| {size} | {cell(ours)} | {cell(anchors.get('Open3D'))} | {cell(anchors.get('trimesh+scipy'))} | "
              f"{anchors[fastest][0] / ours[0]:.2f}× ({fastest}) | {agree * 100:.3f} % / {agree_c * 100:.2f} % |")


if __name__ == "__main__":
    main()
