#!/usr/bin/env python3
"""Open3D anchor (open3d-cpu 0.19). Usage: see common.py. OpenMP threads: OMP_NUM_THREADS.

  load          read_triangle_mesh + read_point_cloud
  bvh           RaycastingScene.add_triangles + one query (Embree builds its BVH on the first query)
  kdtree        KDTreeFlann of the cloud
  accuracy      RaycastingScene build + compute_distance of every point (float32, Embree)
  completeness  sample_points_uniformly(samples) + compute_point_cloud_distance to the cloud
  c2c           compute_point_cloud_distance of --queries to the cloud
  align         registration_icp, TransformationEstimationPointToPoint(with_scaling=True), from
                --start, target = the mesh vertices, gate = --gate x mesh diagonal, 100 iterations
  eval          load + accuracy + completeness (the driver times the whole process)
"""
import numpy as np
import open3d as o3d

from common import Timer, emit, parse, read_matrix, summary

OPS = ["load", "bvh", "kdtree", "accuracy", "completeness", "c2c", "align", "eval"]


def scene_of(mesh, threads):
    scene = o3d.t.geometry.RaycastingScene(nthreads=threads)
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    return scene


def accuracy(mesh, pts, threads):
    scene = scene_of(mesh, threads)
    return scene.compute_distance(o3d.core.Tensor(pts.astype(np.float32)), nthreads=threads).numpy()


def completeness(mesh, pcd, samples):
    return np.asarray(mesh.sample_points_uniformly(samples).compute_point_cloud_distance(pcd))


def main():
    a = parse(OPS)
    read_mesh = lambda: o3d.io.read_triangle_mesh(a.mesh)
    read_cloud = lambda p=a.cloud: o3d.io.read_point_cloud(p)
    if a.op == "load":
        with Timer() as t:
            mesh, pcd = read_mesh(), read_cloud()
        emit(a.op, t.seconds, {"vertices": len(mesh.vertices), "triangles": len(mesh.triangles), "points": len(pcd.points)})
    elif a.op == "bvh":
        mesh = read_mesh()
        with Timer() as t:
            scene = scene_of(mesh, a.threads)
            scene.compute_distance(o3d.core.Tensor(np.zeros((1, 3), np.float32)))
        emit(a.op, t.seconds, {"triangles": len(mesh.triangles)})
    elif a.op == "kdtree":
        pcd = read_cloud()
        with Timer() as t:
            o3d.geometry.KDTreeFlann(pcd)
        emit(a.op, t.seconds, {"points": len(pcd.points)})
    elif a.op == "accuracy":
        mesh, pts = read_mesh(), np.asarray(read_cloud().points)
        with Timer() as t:
            d = accuracy(mesh, pts, a.threads)
        emit(a.op, t.seconds, summary(d))
    elif a.op == "completeness":
        mesh, pcd = read_mesh(), read_cloud()
        with Timer() as t:
            d = completeness(mesh, pcd, a.samples)
        emit(a.op, t.seconds, summary(d))
    elif a.op == "c2c":
        pcd, q = read_cloud(), read_cloud(a.queries)
        with Timer() as t:
            d = np.asarray(q.compute_point_cloud_distance(pcd))
        emit(a.op, t.seconds, summary(d))
    elif a.op == "align":
        mesh, pcd, start = read_mesh(), read_cloud(), read_matrix(a.start)
        v = np.asarray(mesh.vertices)
        gate = a.gate * np.linalg.norm(v.max(0) - v.min(0))
        with Timer() as t:
            target = o3d.geometry.PointCloud(mesh.vertices)
            r = o3d.pipelines.registration.registration_icp(
                pcd, target, gate, start,
                o3d.pipelines.registration.TransformationEstimationPointToPoint(with_scaling=True),
                o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=100))
        emit(a.op, t.seconds, {"matrix": np.asarray(r.transformation).tolist(), "fitness": r.fitness})
    elif a.op == "eval":
        with Timer() as t:
            mesh, pcd = read_mesh(), read_cloud()
            acc = accuracy(mesh, np.asarray(pcd.points), a.threads)
            comp = completeness(mesh, pcd, a.samples)
        emit(a.op, t.seconds, {"accuracy": summary(acc), "completeness": summary(comp)})


if __name__ == "__main__":
    main()
