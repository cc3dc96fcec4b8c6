"""pycolmap on the rendered images: the EXIF focal is read right, every image registers, and
the camera centres agree with cameras.json after a similarity (< 0.5 % of the orbit radius)."""

import os
import sys

import numpy as np
import pytest

from blender_testlib import load_json, requires_bpy
from blender_testlib import umeyama

pytestmark = requires_bpy


def test_pycolmap_registers_all_and_matches_ground_truth(small_dataset, tmp_path):
    pycolmap = pytest.importorskip("pycolmap")
    images = os.path.join(small_dataset, "images")
    db = str(tmp_path / "db.db")
    dev = pycolmap.Device.cpu
    pycolmap.extract_features(db, images, camera_mode=pycolmap.CameraMode.SINGLE, device=dev)
    # the prior focal comes from our EXIF alone
    database = pycolmap.Database.open(db) if hasattr(pycolmap.Database, "open") else pycolmap.Database(db)
    cams_db = database.read_all_cameras()
    database.close()
    assert len(cams_db) == 1
    assert cams_db[0].focal_length == pytest.approx(700.0, abs=1e-6)
    assert cams_db[0].has_prior_focal_length
    pycolmap.match_exhaustive(db, device=dev)
    out = tmp_path / "sparse"
    out.mkdir()
    recs = pycolmap.incremental_mapping(db, images, str(out))
    assert recs, "pycolmap produced no model"
    rec = max(recs.values(), key=lambda r: r.num_reg_images())
    gt = load_json(os.path.join(small_dataset, "cameras.json"))
    assert rec.num_reg_images() == len(gt["images"])
    est = {im.name: np.array(im.projection_center()) for im in rec.images.values()}
    names = [im["name"] for im in gt["images"]]
    dst = np.array([im["center"] for im in gt["images"]])
    src = np.array([est[n] for n in names])
    s, R, t = umeyama(src, dst)
    aligned = (s * (R @ src.T)).T + t
    err = np.linalg.norm(aligned - dst, axis=1)
    meta = load_json(os.path.join(small_dataset, "dataset.json"))
    radius = float(np.median([v["radius"] for v in meta["views"]]))
    rel = err / radius
    sys.stderr.write("\n[pycolmap] %d/%d registered, %d points, centre error after Sim(3): "
                     "median %.3f %%, RMS %.3f %%, max %.3f %% of orbit radius %.3f m\n"
                     % (rec.num_reg_images(), len(names), rec.num_points3D(),
                        100 * np.median(rel), 100 * np.sqrt(np.mean(rel ** 2)), 100 * rel.max(),
                        radius))
    # RMS (and so median) over the cameras below 0.5 % of the orbit radius, no camera above
    # 1.5 %. Measured on the small preset: median 0.16-0.24 %, RMS 0.21-0.34 %, worst camera
    # 0.45-0.9 % — the worst camera depends on tiny changes of the images, and stays there even
    # with the exact intrinsics given to pycolmap, while the GT itself is consistent with the
    # images to ~1e-4 (test_dataset), so it is SIFT localisation noise at 640×360 / 16 spp.
    assert np.sqrt(np.mean(rel ** 2)) < 0.005
    assert rel.max() < 0.015
