"""Runs the vendored official pose-protocol code (tests/third_party/{colmap_benchmark,
image_matching_benchmark,vggsfm_metric}) on SfM models, for tests/python/test_pose_protocols.py.

Inputs are what sfmeval reads: a ground truth as `cameras.json` or a COLMAP text folder, and an
estimate as a COLMAP model folder. The official functions run unchanged; this file only gives
them their inputs in the form each expects (pycolmap reconstructions for COLMAP's benchmark, the
`images.bin` records and calibration dictionaries for the Image Matching Benchmark, PyTorch3D-
convention SE(3) matrices for VGGSfM) and stands in for the file and configuration helpers that
the IMC functions call.
"""
import importlib.util
import json
import os
import sys
import types
from pathlib import Path

import numpy as np
import pycolmap

ROOT = Path(__file__).resolve().parents[2]
THIRD = ROOT / "tests" / "third_party"


def _load(path: Path, name: str, extra_path: Path | None = None, inject: dict | None = None):
    if extra_path is not None and str(extra_path) not in sys.path:
        sys.path.insert(0, str(extra_path))
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    for k, v in (inject or {}).items():
        setattr(mod, k, v)
    spec.loader.exec_module(mod)
    return mod


# numpy 1.26 (bpy needs numpy<2) has neither np.trapezoid nor np.acos, the numpy 2 names
# COLMAP's benchmark calls: the same functions under their numpy 1 names.
if not hasattr(np, "trapezoid"):
    np.trapezoid = np.trapz
if not hasattr(np, "acos"):
    np.acos = np.arccos


# ---------------------------------------------------------------- inputs
def qvec2rotmat(qvec):
    """COLMAP's scripts/python/read_write_model.py qvec2rotmat (w, x, y, z)."""
    return np.array([
        [1 - 2 * qvec[2]**2 - 2 * qvec[3]**2,
         2 * qvec[1] * qvec[2] - 2 * qvec[0] * qvec[3],
         2 * qvec[3] * qvec[1] + 2 * qvec[0] * qvec[2]],
        [2 * qvec[1] * qvec[2] + 2 * qvec[0] * qvec[3],
         1 - 2 * qvec[1]**2 - 2 * qvec[3]**2,
         2 * qvec[2] * qvec[3] - 2 * qvec[0] * qvec[1]],
        [2 * qvec[3] * qvec[1] - 2 * qvec[0] * qvec[2],
         2 * qvec[2] * qvec[3] + 2 * qvec[0] * qvec[1],
         1 - 2 * qvec[1]**2 - 2 * qvec[2]**2]])


def rotmat2qvec(R):
    """COLMAP's scripts/python/read_write_model.py rotmat2qvec (w, x, y, z)."""
    Rxx, Ryx, Rzx, Rxy, Ryy, Rzy, Rxz, Ryz, Rzz = np.asarray(R).flat
    K = np.array([
        [Rxx - Ryy - Rzz, 0, 0, 0],
        [Ryx + Rxy, Ryy - Rxx - Rzz, 0, 0],
        [Rzx + Rxz, Rzy + Ryz, Rzz - Rxx - Ryy, 0],
        [Ryz - Rzy, Rzx - Rxz, Rxy - Ryx, Rxx + Ryy + Rzz]]) / 3.0
    eigvals, eigvecs = np.linalg.eigh(K)
    qvec = eigvecs[[3, 0, 1, 2], np.argmax(eigvals)]
    if qvec[0] < 0:
        qvec *= -1
    return qvec


def read_cameras_json(path):
    """[(name, R, t)] of a cameras.json, in file order, and its cameras."""
    d = json.loads(Path(path).read_text())
    ims = [(i["name"], np.array(i["cam_from_world"]["rotation"], dtype=np.float64),
            np.array(i["cam_from_world"]["translation"], dtype=np.float64)) for i in d["images"]]
    return ims, d["cameras"]


def write_colmap_text(images, cameras, folder):
    """A COLMAP text model of [(name, R or qvec, t)] (no points)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / "cameras.txt", "w") as f:
        for c in cameras:
            f.write(f"{c['id']} PINHOLE {c['width']} {c['height']} {c['fx']!r} {c['fy']!r} "
                    f"{c['cx']!r} {c['cy']!r}\n")
    with open(folder / "images.txt", "w") as f:
        for k, (name, r, t) in enumerate(images):
            q = rotmat2qvec(r) if np.shape(r) == (3, 3) else np.asarray(r)
            vals = " ".join(repr(float(v)) for v in [*q, *t])
            f.write(f"{k + 1} {vals} {cameras[0]['id']} {name}\n\n")
    (folder / "points3D.txt").write_text("")
    return folder


def model_poses(folder):
    """[(name, qvec (w,x,y,z), tvec)] of a COLMAP text model's images.txt, in id order, parsed as
    COLMAP's read_write_model.read_images_text does (so a `nan` reads as NaN, which pycolmap
    refuses)."""
    lines = [x for x in (Path(folder) / "images.txt").read_text().splitlines()
             if x.strip() and not x.startswith("#")]
    out = {}
    k = 0
    while k < len(lines):
        f = lines[k].split()
        # A line of observations follows each image line (possibly empty, then skipped above).
        if len(f) >= 10 and f[-1].lower().endswith((".png", ".jpg", ".jpeg")):
            out[int(f[0])] = (f[9], np.array(list(map(float, f[1:5]))),
                              np.array(list(map(float, f[5:8]))))
        k += 1
    return [out[i] for i in sorted(out)]


# ---------------------------------------------------------------- COLMAP's benchmark
def colmap_reference(gt_folder, est_folder, thresholds=(0.5, 1, 5, 10), position_accuracy=0.0):
    """COLMAP's relative metric: (errors, aucs, recalls) as the benchmark computes them for one
    scene with one GT component and the estimate as its only sub-model."""
    mod = _load(THIRD / "colmap_benchmark" / "utils.py", "colmap_benchmark_utils",
                THIRD / "colmap_benchmark")
    sparse_gt = pycolmap.Reconstruction(str(gt_folder))
    est = pycolmap.Reconstruction(str(est_folder))
    # process_scene's default: every sparse_gt image in component 0.
    image_name_to_component = {image.name: 0 for image in sparse_gt.images.values()}
    errors = mod.compute_grouped_rel_errors(sparse_gt=sparse_gt, sub_models=[est],
                                            image_name_to_component=image_name_to_component,
                                            min_proj_center_dist=position_accuracy)
    th = np.array(thresholds, dtype=np.float64)
    aucs = mod.compute_auc(errors, th, min_error=position_accuracy)
    recalls = mod.compute_recall(errors, th)
    return errors, aucs, recalls


# ---------------------------------------------------------------- Image Matching Benchmark
class _ImageRecord(types.SimpleNamespace):
    pass


def imc_reference(gt_images, est_folder, tmp):
    """The Image Matching Benchmark's multiview pose error and mAA for one bag whose images are
    the ground truth's, with `est_folder` as COLMAP's only model (`0`)."""
    tmp = Path(tmp)
    out_path = tmp / "colmap"
    (out_path / "0").mkdir(parents=True, exist_ok=True)
    for f in Path(est_folder).iterdir():
        (out_path / "0" / f.name).write_bytes(f.read_bytes())
    store = {}

    def read_images_binary(path):
        recs = {}
        for k, (name, q, t) in enumerate(model_poses(Path(path).parent)):
            recs[k + 1] = _ImageRecord(name=name, qvec=q, tvec=t)
        return recs

    names = [n for n, _, _ in gt_images]
    calib = {n: {"R": r, "T": t} for n, r, t in gt_images}

    def delayed(f):
        return lambda *a, **k: (f, a, k)

    def parallel(n_jobs=None):
        return lambda jobs: [f(*a, **k) for f, a, k in jobs]

    inject = {
        "read_images_binary": read_images_binary,
        "qvec2rotmat": qvec2rotmat,
        "get_colmap_pose_file": lambda cfg: str(tmp / "colmap_pose_errors.h5"),
        "get_colmap_output_path": lambda cfg: str(out_path),
        "get_colmap_image_path_list": lambda cfg: list(names),
        "get_colmap_image_subset_index": lambda cfg, lst: list(range(len(lst))),
        "get_item_name_list": lambda lst: list(lst),
        "get_data_path": lambda cfg: str(tmp),
        "get_fullpath_list": lambda data_dir, key: [],
        "load_calib": lambda calib_list, subset_index: calib,
        "Parallel": parallel,
        "delayed": delayed,
        "tqdm": lambda x: x,
        "save_h5": lambda d, path: store.__setitem__(path, dict(d)),
        "load_h5_valid_image": lambda path, deprecated: store[path],
        "get_num_in_bag": lambda cfg: 1,
        "valid_bag": lambda cfg, deprecated: True,
    }
    mod = _load(THIRD / "image_matching_benchmark" / "imc_eval.py", "imc_eval", inject=inject)
    for k, v in inject.items():
        setattr(mod, k, v)
    cfg = types.SimpleNamespace(bag_id=0)
    mod.compute_pose_error(cfg)
    res = {}
    mod.compute_qt_auc_colmap(res, [], cfg)
    return res, store[str(tmp / "colmap_pose_errors.h5")]


# ---------------------------------------------------------------- VGGSfM / CO3D
_F = np.diag([-1.0, -1.0, 1.0])


def pt3d_se3(R, t):
    """The PyTorch3D world-to-view matrix (row vectors: X_view = X_world R + T) of an OpenCV
    cam_from_world (R, t): R_pt3d = (F R)ᵀ, T = F t with F = diag(-1, -1, 1), as VGGT's and
    CO3D's loaders convert."""
    m = np.eye(4)
    m[:3, :3] = (_F @ R).T
    m[3, :3] = _F @ t
    return m


def co3d_reference(gt_images, est_by_name):
    """VGGSfM's camera_to_rel_deg on all pairs of the ground-truth images and PoseDiffusion's
    RRA / RTA / AUC@30; a pair with an image missing from `est_by_name` gets 180° for both
    errors (sfmeval's stated convention: the official code has no unregistered frames)."""
    sys.path.insert(0, str(THIRD / "vggsfm_metric"))
    import metric_numpy
    import posediffusion_test_excerpt
    n = len(gt_images)
    gt = np.stack([pt3d_se3(r, t) for _, r, t in gt_images])
    pred = np.stack([pt3d_se3(*est_by_name[name]) if name in est_by_name else np.eye(4)
                     for name, _, _ in gt_images])
    r_err, t_err = metric_numpy.camera_to_rel_deg(gt, pred, 1)
    i1, i2 = metric_numpy.batched_all_pairs(1, n)
    for k, (a, b) in enumerate(zip(i1, i2)):
        if gt_images[a][0] not in est_by_name or gt_images[b][0] not in est_by_name:
            r_err[k] = 180.0
            t_err[k] = 180.0
    return posediffusion_test_excerpt.co3d_metrics(r_err, t_err), r_err, t_err
