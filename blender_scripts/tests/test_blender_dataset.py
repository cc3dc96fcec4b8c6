"""The small dataset rendered once with PyPI bpy (session fixture): contracts and conventions."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from blender_testlib import REPO, load_json, requires_bpy, run_generate
from blender_testlib import bilinear, camera_matrices, glb_vertices, project

pytestmark = requires_bpy


def _mask(ds, name):
    return np.array(Image.open(os.path.join(ds, "masks", os.path.splitext(name)[0] + ".png"))) > 127


def _depth(ds, name):
    return np.load(os.path.join(ds, "depth", os.path.splitext(name)[0] + ".npy"))


def test_files_and_schemas(small_dataset):
    import jsonschema
    ds = small_dataset
    cams = load_json(os.path.join(ds, "cameras.json"))
    with open(os.path.join(REPO, "schemas", "cameras.schema.json")) as f:
        jsonschema.validate(cams, json.load(f))
    assert cams["schema"] == "sfmeval.cameras/1" and cams["frame"] == "gltf"
    assert cams["pixel_convention"] == "colmap"
    cam = cams["cameras"][0]
    assert (cam["width"], cam["height"], cam["fx"], cam["fy"], cam["cx"], cam["cy"]) == \
        (640, 360, 700.0, 700.0, 320.0, 180.0)
    names = sorted(os.listdir(os.path.join(ds, "images")))
    assert names == ["%04d.jpg" % i for i in range(36)]
    assert [im["name"] for im in cams["images"]] == names
    for sub, ext in (("depth", ".npy"), ("masks", ".png")):
        assert sorted(os.listdir(os.path.join(ds, sub))) == [n[:-4] + ext for n in names]
    meta = load_json(os.path.join(ds, "dataset.json"))
    assert meta["schema"] == "sfmeval.dataset/1"
    assert meta["blender"]["version"].startswith("5.")
    assert meta["seed"] == 0 and meta["images"] == 36
    assert meta["source"] == {"kind": "builtin", "name": "statue", "seed": 0}
    assert meta["settings"]["render"]["samples"] == 16
    assert "timing" not in meta and "created_utc" not in meta  # measured: in timing.json
    timing = load_json(os.path.join(ds, "timing.json"))
    assert timing["schema"] == "sfmeval.timing/1" and timing["parts"] is None
    assert len(timing["render_seconds_per_frame"]) == 36
    assert all(t > 0 for t in timing["render_seconds_per_frame"])
    assert meta["render"]["denoise_used"] is False
    # The headless generator starts from an empty scene: nothing of the user's to hide.
    assert meta["other_objects"] == {"keep_other_objects": False, "keep_other_lights": False,
                                     "objects": []}
    assert meta["render"]["views_without_object"] == []
    for im in cams["images"]:
        R = np.array(im["cam_from_world"]["rotation"])
        assert np.allclose(R @ R.T, np.eye(3), atol=1e-6) and np.linalg.det(R) > 0
        C = -R.T @ np.array(im["cam_from_world"]["translation"])
        assert np.allclose(C, im["center"], atol=1e-6)


def test_depth_and_mask_formats(small_dataset):
    d = _depth(small_dataset, "0000.jpg")
    m = np.array(Image.open(os.path.join(small_dataset, "masks", "0000.png")))
    assert d.dtype == np.float32 and d.shape == (360, 640)
    assert m.dtype == np.uint8 and m.shape == (360, 640) and set(np.unique(m)) == {0, 255}
    assert np.array_equal(d > 0, m == 255)


def test_gt_vertices_project_onto_masks_and_depth(small_dataset):
    """Every GLB vertex projects into the object's mask (within the 1-px boundary
    quantisation), and visible vertices agree with the depth map at sub-pixel precision —
    a wrong axis, sign, handedness or half-pixel offset fails here."""
    ds = small_dataset
    cams = load_json(os.path.join(ds, "cameras.json"))
    cam, K, poses = camera_matrices(cams)
    X, _ = glb_vertices(os.path.join(ds, "ground_truth.glb"))
    from scipy import ndimage
    worst_outside = 0.0
    errs = {0.0: [], 0.5: [], -0.5: []}
    for name, (R, t) in poses.items():
        uv, z = project(K, R, t, X)
        assert (z > 0).all()
        mask = _mask(ds, name)
        iu = np.floor(uv[:, 0]).astype(int)
        iv = np.floor(uv[:, 1]).astype(int)
        assert ((iu >= 0) & (iv >= 0) & (iu < cam["width"]) & (iv < cam["height"])).all(), name
        dist = ndimage.distance_transform_edt(~mask)[iv, iu]
        worst_outside = max(worst_outside, dist.max())
        assert (dist == 0).mean() > 0.9, name
        depth = _depth(ds, name)
        for du in errs:
            for (su, sv) in ((du, 0.0), (0.0, du)):
                val, ok = bilinear(depth, uv[:, 0] + su, uv[:, 1] + sv)
                vis = ok & (np.abs(val - z) < 0.01 * z)
                assert vis.sum() > 0.25 * len(z), name
                errs[du].append(np.median(np.abs(val - z)[vis] / z[vis]))
    assert worst_outside <= 1.5, "a vertex projects %.2f px outside the mask" % worst_outside
    right = float(np.median(errs[0.0]))
    shifted = min(float(np.median(errs[0.5])), float(np.median(errs[-0.5])))
    sys.stderr.write("\n[projection] median relative depth error %.2e (half-pixel shift: %.2e)\n"
                     % (right, shifted))
    assert right < 3e-4
    assert right < 0.6 * shifted


def test_mask_agrees_with_rendered_image(small_dataset):
    """The separate depth/mask pass lines up with the RGB render: background outside, object in."""
    from scipy import ndimage
    ds = small_dataset
    meta = load_json(os.path.join(ds, "dataset.json"))
    bg_lin = meta["settings"]["background"]["world_color"][0]
    bg = 255 * (1.055 * bg_lin ** (1 / 2.4) - 0.055)          # sRGB of the world colour
    for name in ("0000.jpg", "0009.jpg", "0020.jpg"):
        img = np.asarray(Image.open(os.path.join(ds, "images", name)).convert("RGB"), float)
        mask = _mask(ds, name)
        outside = ~ndimage.binary_dilation(mask, iterations=3)
        inside = ndimage.binary_erosion(mask, iterations=3)
        diff = np.abs(img - bg).max(axis=2)
        assert np.median(diff[outside]) < 3, name
        assert (diff[outside] > 12).mean() < 0.002, name
        assert (diff[inside] > 12).mean() > 0.8, name


def test_glb_matches_blender_world_vertices(small_dataset, tmp_path):
    """ground_truth.glb (read by trimesh) = the object's evaluated world-space vertices in
    Blender (read from scene.blend by bpy), converted (x, y, z) → (x, z, −y)."""
    ds = small_dataset
    script = tmp_path / "dump.py"
    script.write_text(
        "import bpy, numpy as np, sys\n"
        "bpy.ops.wm.open_mainfile(filepath=sys.argv[1])\n"
        "o = [o for o in bpy.data.objects if o.get('sfmeval_role') == 'object'][0]\n"
        "dg = bpy.context.evaluated_depsgraph_get(); ev = o.evaluated_get(dg); me = ev.to_mesh()\n"
        "mw = np.array(o.matrix_world)\n"
        "v = np.array([tuple(x.co) for x in me.vertices])\n"
        "np.save(sys.argv[2], v @ mw[:3, :3].T + mw[:3, 3])\n")
    out = tmp_path / "v.npy"
    proc = subprocess.run([sys.executable, str(script), os.path.join(ds, "scene.blend"), str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    vb = np.load(out)
    vg = np.stack([vb[:, 0], vb[:, 2], -vb[:, 1]], axis=1)
    X, scene = glb_vertices(os.path.join(ds, "ground_truth.glb"))
    from scipy.spatial import cKDTree
    d1, _ = cKDTree(vg).query(X)
    d2, _ = cKDTree(X).query(vg)
    assert max(d1.max(), d2.max()) < 1e-5
    meta = load_json(os.path.join(ds, "dataset.json"))
    assert meta["object"]["vertices"] == len(vg)
    assert np.allclose(X.min(0), meta["object"]["bbox_min_gltf"], atol=1e-5)
    assert np.allclose(X.max(0), meta["object"]["bbox_max_gltf"], atol=1e-5)
    # normalised: largest edge 1 m, centred at the origin
    ext = X.max(0) - X.min(0)
    assert ext.max() == pytest.approx(1.0, abs=1e-5)
    assert np.allclose((X.max(0) + X.min(0)) / 2, 0, atol=1e-5)


def test_exif_gives_the_focal_in_pixels(small_dataset):
    cams = load_json(os.path.join(small_dataset, "cameras.json"))
    fx = cams["cameras"][0]["fx"]
    for im in cams["images"][:5]:
        e = Image.open(os.path.join(small_dataset, "images", im["name"])).getexif()
        ie = e.get_ifd(0x8769)
        assert ie[0xA210] == 2                                   # inches
        assert float(ie[0x920A]) * float(ie[0xA20E]) / 25.4 == pytest.approx(fx, abs=1e-9)
        assert (ie[0xA002], ie[0xA003]) == (640, 360)
        assert 0xA405 not in ie
        assert e[0x010F] == "sfmeval"


def test_colmap_gt_model_matches_cameras_json(small_dataset):
    pycolmap = pytest.importorskip("pycolmap")
    rec = pycolmap.Reconstruction(os.path.join(small_dataset, "sparse_gt"))
    cams = load_json(os.path.join(small_dataset, "cameras.json"))
    assert rec.num_images() == 36
    by_name = {im.name: im for im in rec.images.values()}
    cam = list(rec.cameras.values())[0]
    assert list(cam.params) == pytest.approx([700.0, 700.0, 320.0, 180.0])
    for im in cams["images"]:
        p = by_name[im["name"]].cam_from_world
        p = p() if callable(p) else p
        assert np.allclose(p.rotation.matrix(), im["cam_from_world"]["rotation"], atol=1e-6)
        assert np.allclose(p.translation, im["cam_from_world"]["translation"], atol=1e-6)


def test_same_config_same_cameras_and_geometry(small_dataset, tmp_path):
    """Reproducible: regenerating (without rendering) gives identical cameras and GLB geometry."""
    out = str(tmp_path / "again")
    proc = run_generate(["--preset", "small", "--no-render", "--out", out])
    assert proc.returncode == 0, proc.stderr[-2000:]
    a = load_json(os.path.join(small_dataset, "cameras.json"))
    b = load_json(os.path.join(out, "cameras.json"))
    assert a == b
    va, _ = glb_vertices(os.path.join(small_dataset, "ground_truth.glb"))
    vb, _ = glb_vertices(os.path.join(out, "ground_truth.glb"))
    assert np.array_equal(va, vb)
    assert not os.path.exists(os.path.join(out, "images"))
