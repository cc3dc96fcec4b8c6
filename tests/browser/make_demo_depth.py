#!/usr/bin/env python3
"""Depth maps of the demo's ground truth for every camera of data/demo/cameras.json, in the
dataset contract (docs/dataset.md: float32 (H, W), row 0 on top, metres along the OpenCV camera
z through each pixel centre (u + 0.5, v + 0.5) in COLMAP pixels, 0 where no object), made by
Open3D's ray casting: an independent renderer, so the browser tests can drop depth maps into the
page and the npm package without shipping 33 MB of them.

  make_demo_depth.py OUT_DIR      # writes OUT_DIR/<image stem>.npy
"""
import json
import sys
from pathlib import Path

import numpy as np
import open3d as o3d
import trimesh

ROOT = Path(__file__).resolve().parents[2]


def main():
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    demo = ROOT / "data" / "demo"
    mesh = trimesh.load(demo / "ground_truth.glb", force="mesh", process=False)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(np.asarray(mesh.vertices, np.float32)),
                        o3d.core.Tensor(np.asarray(mesh.faces, np.uint32)))
    cams = json.loads((demo / "cameras.json").read_text())
    by_id = {c["id"]: c for c in cams["cameras"]}
    for im in cams["images"]:
        c = by_id[im["camera_id"]]
        w, h = c["width"], c["height"]
        r = np.array(im["cam_from_world"]["rotation"], float)
        t = np.array(im["cam_from_world"]["translation"], float)
        centre = -r.T @ t
        u, v = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
        d_cam = np.stack([(u - c["cx"]) / c["fx"], (v - c["cy"]) / c["fy"], np.ones_like(u)], -1)
        d_world = d_cam @ r  # rows: R^T d
        rays = np.concatenate([np.broadcast_to(centre, d_world.shape), d_world], -1)
        hit = scene.cast_rays(o3d.core.Tensor(rays.reshape(-1, 6).astype(np.float32)))
        t_hit = hit["t_hit"].numpy().reshape(h, w)
        # the direction's camera z is 1, so the ray parameter is the depth along the optical axis
        depth = np.where(np.isfinite(t_hit), t_hit, 0.0).astype(np.float32)
        np.save(out / (Path(im["name"]).stem + ".npy"), depth)
    print(f"{len(cams['images'])} depth maps in {out}")


if __name__ == "__main__":
    main()
