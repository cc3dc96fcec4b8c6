"""A Tanks and Temples scene in the benchmark's folder layout, made from sfmeval's demo dataset
(data/demo: a rendered statue, its ground-truth cameras and a real pycolmap reconstruction of its
36 images), for the cross-checks of `sfmeval tnt` against the benchmark's toolbox and for the
benchmark:

  SCENE/SCENE.ply                 ground truth: points sampled on the mesh (trimesh), written by Open3D
  SCENE/SCENE.json                crop: an Open3D SelectionPolygonVolume across y (the glTF up axis)
  SCENE/SCENE_trans.txt           a known similarity: reference SfM frame -> ground-truth frame
  SCENE/SCENE_COLMAP_SfM.log      the ground-truth cameras in that reference frame (toolbox's writer)
  recon/sparse.ply                the pycolmap run's sparse cloud (COLMAP's PLY export)
  recon/dense.ply                 a dense-like cloud in the pycolmap frame: surface samples with
                                  noise and outliers (Open3D's writer)
  recon/images.txt                the image names in frame order
  recon/gt_from_recon.txt         the pycolmap frame -> ground truth, from the camera centres

  python tests/python/tnt_scene.py OUT [--gt-points N] [--dense-points N]
"""
import argparse
import json
import shutil
import sys
from pathlib import Path

import numpy as np
import open3d as o3d
import trimesh

sys.path.insert(0, str(Path(__file__).resolve().parent))
from numpy_ref import apply, quat_to_rot, similarity, umeyama_np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "data" / "demo"
TOOLBOX = ROOT / "tests" / "third_party" / "tanksandtemples_evaluation"
SCENE = "Synth"


def _write_cloud(path, points):
    pcd = o3d.geometry.PointCloud()
    pcd.points = o3d.utility.Vector3dVector(points)
    assert o3d.io.write_point_cloud(str(path), pcd, write_ascii=False)


def _colmap_images(sparse_dir):
    """name -> world_from_cam (4x4) of the demo's COLMAP text model, parsed here."""
    poses = {}
    lines = [l for l in (sparse_dir / "images.txt").read_text().splitlines() if l and not l.startswith("#")]
    for line in lines:
        f = line.split()
        if len(f) < 10:
            continue
        q, t = np.array(f[1:5], float), np.array(f[5:8], float)
        r = quat_to_rot(q)
        m = np.eye(4)
        m[:3, :3] = r.T
        m[:3, 3] = -r.T @ t
        poses[f[9]] = m
    return poses


def write_scene(scene_dir, name, glb, cameras_json, gt_points, seed=0):
    """Writes NAME.ply, NAME.json, NAME_trans.txt and NAME_COLMAP_SfM.log into SCENE_DIR from a
    ground-truth mesh and its cameras.json; returns (mesh, ground-truth points, τ, names)."""
    scene_dir = Path(scene_dir)
    scene_dir.mkdir(parents=True, exist_ok=True)
    mesh = trimesh.load(glb, force="mesh")
    gt, _ = trimesh.sample.sample_surface(mesh, gt_points, seed=seed)
    _write_cloud(scene_dir / f"{name}.ply", gt)
    lo, hi = gt.min(0), gt.max(0)
    diag = float(np.linalg.norm(hi - lo))
    tau = float(f"{0.004 * diag:.3g}")

    # Reference frame: the ground truth under a known similarity.
    gt_from_ref = similarity(1.3, quat_to_rot([0.9, 0.1, 0.35, -0.2]), np.array([0.5, -0.2, 1.0]))
    np.savetxt(scene_dir / f"{name}_trans.txt", gt_from_ref)
    ref_from_gt = np.linalg.inv(gt_from_ref)
    cams = json.loads(Path(cameras_json).read_text())
    names = sorted(im["name"] for im in cams["images"])
    by_name = {im["name"]: im["cam_from_world"] for im in cams["images"]}
    sys.path.insert(0, str(TOOLBOX))
    import trajectory_io

    ref_rot = quat_to_rot([0.9, 0.1, 0.35, -0.2]).T
    traj = []
    for k, n in enumerate(names):
        r = np.array(by_name[n]["rotation"], float)
        t = np.array(by_name[n]["translation"], float)
        pose = np.eye(4)
        pose[:3, :3] = ref_rot @ r.T
        pose[:3, 3] = apply(ref_from_gt, -r.T @ t)
        traj.append(trajectory_io.CameraPose([k, k, 0], pose))
    trajectory_io.write_trajectory(traj, str(scene_dir / f"{name}_COLMAP_SfM.log"))

    # Crop: an irregular polygon in x-z (cuts a side and the corners) across y, without the base.
    (x0, y0, z0), (x1, y1, z1) = lo - 0.02 * (hi - lo), hi + 0.02 * (hi - lo)
    w, d = x1 - x0, z1 - z0
    polygon = [[x0 + 0.2 * w, 0, z0], [x0 + 0.85 * w, 0, z0], [x0 + 0.85 * w, 0, z1 - 0.3 * d],
               [x0 + 0.6 * w, 0, z1], [x0, 0, z1], [x0, 0, z0 + 0.25 * d]]
    crop = {"class_name": "SelectionPolygonVolume", "version_major": 1, "version_minor": 0,
            "orthogonal_axis": "Y", "axis_min": float(lo[1] + 0.05 * (hi[1] - lo[1])),
            "axis_max": float(y1), "bounding_polygon": polygon}
    (scene_dir / f"{name}.json").write_text(json.dumps(crop, indent=1))
    return mesh, gt, tau, names, by_name


def build(out, gt_points=500_000, dense_points=200_000, seed=0):
    """Writes the scene under OUT and returns its paths and τ."""
    out = Path(out)
    scene_dir, recon = out / SCENE, out / "recon"
    recon.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    mesh, gt, tau, names, by_name = write_scene(scene_dir, SCENE, DEMO / "ground_truth.glb",
                                                DEMO / "cameras.json", gt_points, seed)
    lo, hi = gt.min(0), gt.max(0)

    # The reconstruction: the pycolmap run, its frame found from the camera centres.
    poses = _colmap_images(DEMO / "sparse")
    gt_centres = {n: -np.array(by_name[n]["rotation"]).T @ np.array(by_name[n]["translation"]) for n in names}
    common = [n for n in names if n in poses]
    gt_from_recon = umeyama_np([poses[n][:3, 3] for n in common], [gt_centres[n] for n in common])
    np.savetxt(recon / "gt_from_recon.txt", gt_from_recon)
    shutil.copy(DEMO / "sparse.ply", recon / "sparse.ply")
    dense, _ = trimesh.sample.sample_surface(mesh, dense_points, seed=seed + 1)
    dense = dense + rng.normal(scale=0.3 * tau, size=dense.shape)
    outliers = rng.uniform(lo, hi, size=(dense_points // 30, 3))
    dense = np.vstack([dense, outliers])
    _write_cloud(recon / "dense.ply", apply(np.linalg.inv(gt_from_recon), dense))
    (recon / "images.txt").write_text("".join(n + "\n" for n in names))
    return {"scene": scene_dir, "tau": tau, "recon": recon, "names": names,
            "gt_from_recon": gt_from_recon, "registered": common}


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--gt-points", type=int, default=500_000)
    ap.add_argument("--dense-points", type=int, default=200_000)
    a = ap.parse_args()
    info = build(a.out, a.gt_points, a.dense_points)
    print(f"scene {info['scene']} tau {info['tau']}")
