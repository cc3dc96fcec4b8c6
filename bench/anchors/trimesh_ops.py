#!/usr/bin/env python3
"""trimesh 4.8 + scipy anchor. Usage: see common.py. scipy queries use every core (workers=-1).

  load          trimesh.load of the mesh (process=False) and the cloud
  bvh           mesh.triangles_tree (rtree R-tree of the triangles' boxes)
  kdtree        scipy.spatial.cKDTree of the cloud
  accuracy      trimesh.proximity.closest_point of every point (exact, float64; slow)
  completeness  trimesh.sample.sample_surface(samples) + cKDTree of the cloud + query
  c2c           cKDTree of the cloud + query of --queries
  align         trimesh.registration.icp(scale=True) from --start onto the mesh vertices
                (no correspondence gate), 100 iterations
  eval          load + accuracy + completeness
"""
import numpy as np
import trimesh
from scipy.spatial import cKDTree

from common import Timer, emit, parse, read_matrix, summary

OPS = ["load", "bvh", "kdtree", "accuracy", "completeness", "c2c", "align", "eval"]


def completeness(mesh, pts, samples, seed):
    samp, _ = trimesh.sample.sample_surface(mesh, samples, seed=seed)
    return cKDTree(pts).query(samp, workers=-1)[0]


def main():
    a = parse(OPS)
    read_mesh = lambda: trimesh.load(a.mesh, process=False, force="mesh")
    read_cloud = lambda p=a.cloud: np.asarray(trimesh.load(p).vertices, dtype=np.float64)
    if a.op == "load":
        with Timer() as t:
            mesh, pts = read_mesh(), read_cloud()
        emit(a.op, t.seconds, {"vertices": len(mesh.vertices), "triangles": len(mesh.faces), "points": len(pts)})
    elif a.op == "bvh":
        mesh = read_mesh()
        with Timer() as t:
            mesh.triangles_tree
        emit(a.op, t.seconds, {"triangles": len(mesh.faces)})
    elif a.op == "kdtree":
        pts = read_cloud()
        with Timer() as t:
            cKDTree(pts)
        emit(a.op, t.seconds, {"points": len(pts)})
    elif a.op == "accuracy":
        mesh, pts = read_mesh(), read_cloud()
        with Timer() as t:
            d = trimesh.proximity.closest_point(mesh, pts)[1]
        emit(a.op, t.seconds, summary(d))
    elif a.op == "completeness":
        mesh, pts = read_mesh(), read_cloud()
        with Timer() as t:
            d = completeness(mesh, pts, a.samples, a.seed)
        emit(a.op, t.seconds, summary(d))
    elif a.op == "c2c":
        pts, q = read_cloud(), read_cloud(a.queries)
        with Timer() as t:
            d = cKDTree(pts).query(q, workers=-1)[0]
        emit(a.op, t.seconds, summary(d))
    elif a.op == "align":
        mesh, pts, start = read_mesh(), read_cloud(), read_matrix(a.start)
        with Timer() as t:
            m, _, _ = trimesh.registration.icp(pts, np.asarray(mesh.vertices), initial=start, threshold=1e-7,
                                               max_iterations=100, reflection=False, translation=True, scale=True)
        emit(a.op, t.seconds, {"matrix": np.asarray(m).tolist()})
    elif a.op == "eval":
        with Timer() as t:
            mesh, pts = read_mesh(), read_cloud()
            acc = trimesh.proximity.closest_point(mesh, pts)[1]
            comp = completeness(mesh, pts, a.samples, a.seed)
        emit(a.op, t.seconds, {"accuracy": summary(acc), "completeness": summary(comp)})


if __name__ == "__main__":
    main()
