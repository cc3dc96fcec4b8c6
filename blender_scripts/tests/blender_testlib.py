"""Utilities of the blender_scripts tests (a unique module name: the repository runs several
test folders in one pytest session, so no `conftest`/`helpers` imports across folders)."""

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
BLENDER_SCRIPTS = os.path.dirname(HERE)
GENERATE = os.path.join(BLENDER_SCRIPTS, "generate.py")
REPO = os.path.dirname(BLENDER_SCRIPTS)
if BLENDER_SCRIPTS not in sys.path:
    sys.path.insert(0, BLENDER_SCRIPTS)


def have_bpy():
    return importlib.util.find_spec("bpy") is not None


def run_generate(args, python=None, timeout=900):
    """Run the headless generator with the PyPI bpy module (this interpreter by default)."""
    cmd = [python or sys.executable, GENERATE] + list(args)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          timeout=timeout)
    proc.seconds = time.perf_counter() - t0
    return proc


def _release_bin(env, name, package):
    b = os.environ.get(env)
    if b:
        assert os.path.isfile(b), b
        return b
    # (every binary, as the other tests build them: no crate compiled twice)
    subprocess.run([os.path.join(REPO, "scripts", "build-release.sh")], cwd=REPO, check=True)
    return os.path.join(REPO, "target", "release", name)


def release_bins():
    """{"sfmeval", "runner"}: $SFMEVAL_BIN / $SFMEVAL_RUNNER_BIN, else built in target/release."""
    return {"sfmeval": _release_bin("SFMEVAL_BIN", "sfmeval", "sfmeval-cli"),
            "runner": _release_bin("SFMEVAL_RUNNER_BIN", "sfmeval-runner", "sfmeval-runner")}


def run_blender(args, timeout=900):
    """Run the headless generator inside Debian's `blender` executable."""
    exe = shutil.which("blender")
    cmd = [exe, "-b", "--factory-startup", "-noaudio", "-P", GENERATE, "--"] + list(args)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          timeout=timeout)
    proc.seconds = time.perf_counter() - t0
    return proc


requires_bpy = pytest.mark.skipif(not have_bpy(), reason="PyPI bpy is not installed in this Python "
                                  "(pip install -r requirements/blender.txt)")


def load_json(path):
    with open(path) as f:
        return json.load(f)


def camera_matrices(cams):
    cam = cams["cameras"][0]
    K = np.array([[cam["fx"], 0, cam["cx"]], [0, cam["fy"], cam["cy"]], [0, 0, 1.0]])
    poses = {}
    for im in cams["images"]:
        R = np.array(im["cam_from_world"]["rotation"], dtype=float)
        t = np.array(im["cam_from_world"]["translation"], dtype=float)
        poses[im["name"]] = (R, t)
    return cam, K, poses


def project(K, R, t, X):
    """World points (N,3) → pixel coordinates (N,2) in the COLMAP convention, and depth z."""
    Xc = X @ R.T + t
    z = Xc[:, 2]
    uv = (Xc[:, :2] / z[:, None]) * np.array([K[0, 0], K[1, 1]]) + np.array([K[0, 2], K[1, 2]])
    return uv, z


def glb_vertices(path):
    """World-space vertices of every mesh in a GLB, node transforms applied (trimesh)."""
    import trimesh
    scene = trimesh.load(path, force="scene")
    meshes = []
    for node in scene.graph.nodes_geometry:
        transform, geom_name = scene.graph[node]
        g = scene.geometry[geom_name]
        meshes.append(trimesh.transformations.transform_points(g.vertices, transform))
    return np.vstack(meshes), scene


def bilinear(img, u, v):
    """Sample img (H,W) at continuous pixel coords in the COLMAP convention (pixel centres at
    +0.5). Returns values and a validity flag (all four neighbours inside and non-zero)."""
    h, w = img.shape
    x = u - 0.5
    y = v - 0.5
    x0 = np.floor(x).astype(int)
    y0 = np.floor(y).astype(int)
    ok = (x0 >= 0) & (y0 >= 0) & (x0 + 1 < w) & (y0 + 1 < h)
    x0c = np.clip(x0, 0, w - 2)
    y0c = np.clip(y0, 0, h - 2)
    fx = x - x0c
    fy = y - y0c
    a = img[y0c, x0c]
    b = img[y0c, x0c + 1]
    c = img[y0c + 1, x0c]
    d = img[y0c + 1, x0c + 1]
    ok &= (a > 0) & (b > 0) & (c > 0) & (d > 0)
    val = a * (1 - fx) * (1 - fy) + b * fx * (1 - fy) + c * (1 - fx) * fy + d * fx * fy
    return val, ok


def umeyama(src, dst, with_scale=True):
    """Similarity (s, R, t) minimising ||dst − (s R src + t)||² (Umeyama 1991)."""
    src = np.asarray(src, float)
    dst = np.asarray(dst, float)
    mu_s, mu_d = src.mean(0), dst.mean(0)
    xs, xd = src - mu_s, dst - mu_d
    cov = xd.T @ xs / len(src)
    U, S, Vt = np.linalg.svd(cov)
    D = np.eye(3)
    if np.linalg.det(U) * np.linalg.det(Vt) < 0:
        D[2, 2] = -1
    R = U @ D @ Vt
    var_s = (xs ** 2).sum() / len(src)
    s = np.trace(np.diag(S) @ D) / var_s if with_scale else 1.0
    t = mu_d - s * R @ mu_s
    return s, R, t


def shift_principal_point(cams, px):
    """A copy of cameras.json `cams` with every camera's principal point moved by `px` pixels in
    x and y (what a half-pixel convention error does)."""
    out = json.loads(json.dumps(cams))
    for cam in out["cameras"]:
        cam["cx"] += px
        cam["cy"] += px
    return out


def _triangulate(rays_and_poses):
    """Linear (DLT) triangulation from normalised image points and 3x4 cam_from_world poses."""
    A = []
    for xy, P in rays_and_poses:
        A += [xy[0] * P[2] - P[0], xy[1] * P[2] - P[1]]
    X = np.linalg.svd(np.array(A))[2][-1]
    return X[:3] / X[3]


def track_reprojection(rec, cams):
    """Reprojection errors (px) of a pycolmap reconstruction's tracks (≥ 3 views) two ways,
    with every point re-triangulated by the same linear DLT: from the tool's own cameras, and
    from the ground-truth cameras of `cams` (cameras.json). Only the poses and intrinsics differ
    between the two, not how the points are found (a tool's own points come from its bundle
    adjustment, robust or not, and would not compare like with like).

    If the GT poses are exact, they explain the tool's own feature tracks as well as the tool's
    optimised poses do; a wrong axis, a half-pixel shift or a bad focal shows at once."""
    _, K, poses = camera_matrices(cams)
    K_inv = np.linalg.inv(K)
    gt_pose = {n: np.hstack([R, t[:, None]]) for n, (R, t) in poses.items()}
    own, gt = [], []
    for p in rec.points3D.values():
        obs = [(rec.images[e.image_id], rec.images[e.image_id].points2D[e.point2D_idx].xy)
               for e in p.track.elements]
        if len(obs) < 3:
            continue
        own_views = [(np.asarray(rec.cameras[im.camera_id].cam_from_img(xy)),
                      im.cam_from_world().matrix()) for im, xy in obs]
        gt_views = [((K_inv @ np.array([xy[0], xy[1], 1.0]))[:2], gt_pose[im.name])
                    for im, xy in obs]
        X_own, X_gt = _triangulate(own_views), _triangulate(gt_views)
        for (im, xy), (_, P_own), (_, P_gt) in zip(obs, own_views, gt_views):
            uv = rec.cameras[im.camera_id].img_from_cam(P_own[:, :3] @ X_own + P_own[:, 3])
            own.append(np.linalg.norm(np.asarray(uv) - xy))
            q = K @ (P_gt[:, :3] @ X_gt + P_gt[:, 3])
            gt.append(np.linalg.norm(q[:2] / q[2] - xy))
    return np.array(own), np.array(gt)
