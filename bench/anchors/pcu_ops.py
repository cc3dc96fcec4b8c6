#!/usr/bin/env python3
"""point-cloud-utils 0.34 anchor. Usage: see common.py. No separate index build or ICP (exits 3).

  load          load_mesh_vf + load_mesh_v (float64)
  accuracy      closest_points_on_mesh of every point (exact, libigl AABB tree)
  completeness  sample_mesh_random(samples) + k_nearest_neighbors(k=1) to the cloud
  c2c           k_nearest_neighbors(k=1) of --queries in the cloud
  eval          load + accuracy + completeness
"""
import numpy as np
import point_cloud_utils as pcu

from common import Timer, emit, parse, summary, unsupported

OPS = ["load", "bvh", "kdtree", "accuracy", "completeness", "c2c", "align", "eval"]


def completeness(v, f, pts, samples, seed):
    fid, bc = pcu.sample_mesh_random(v, f, samples, random_seed=seed)
    samp = pcu.interpolate_barycentric_coords(f, fid, bc, v)
    return pcu.k_nearest_neighbors(samp, pts, k=1)[0]


def main():
    a = parse(OPS)
    read_mesh = lambda: pcu.load_mesh_vf(a.mesh, dtype=np.float64)
    read_cloud = lambda p=a.cloud: pcu.load_mesh_v(p, dtype=np.float64)
    if a.op in ("bvh", "kdtree", "align"):
        unsupported(a.op)
    if a.op == "load":
        with Timer() as t:
            (v, f), pts = read_mesh(), read_cloud()
        emit(a.op, t.seconds, {"vertices": len(v), "triangles": len(f), "points": len(pts)})
    elif a.op == "accuracy":
        (v, f), pts = read_mesh(), read_cloud()
        with Timer() as t:
            d = pcu.closest_points_on_mesh(pts, v, f)[0]
        emit(a.op, t.seconds, summary(d))
    elif a.op == "completeness":
        (v, f), pts = read_mesh(), read_cloud()
        with Timer() as t:
            d = completeness(v, f, pts, a.samples, a.seed)
        emit(a.op, t.seconds, summary(d))
    elif a.op == "c2c":
        pts, q = read_cloud(), read_cloud(a.queries)
        with Timer() as t:
            d = pcu.k_nearest_neighbors(q, pts, k=1)[0]
        emit(a.op, t.seconds, summary(d))
    elif a.op == "eval":
        with Timer() as t:
            (v, f), pts = read_mesh(), read_cloud()
            acc = pcu.closest_points_on_mesh(pts, v, f)[0]
            comp = completeness(v, f, pts, a.samples, a.seed)
        emit(a.op, t.seconds, {"accuracy": summary(acc), "completeness": summary(comp)})


if __name__ == "__main__":
    main()
