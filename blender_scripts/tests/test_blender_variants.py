"""Less common settings rendered for real on a tiny dataset (PyPI bpy, a few seconds): lens
shift (principal point off centre), PNG output, floor + walls, sphere and shell views.
The GT must still project exactly onto the masks and depth maps."""


import numpy as np
import pytest
from PIL import Image

from blender_testlib import load_json, requires_bpy, run_generate
from blender_testlib import bilinear, camera_matrices, glb_vertices, project

pytestmark = requires_bpy

CFG = '''preset = "small"
[object]
source = "builtin:statue"
[render]
samples = 4
format = "PNG"
[camera]
resolution = [320, 180]
shift = [0.06, -0.04]
[background]
floor = true
walls = true
[views]
orbits = [{elevation_deg = 30.0, count = 2}]
sphere = {count = 2}
shell = {count = 2}
'''


def test_shift_png_room_sphere_shell(tmp_path):
    cfg = tmp_path / "v.toml"
    cfg.write_text(CFG)
    out = tmp_path / "out"
    proc = run_generate(["--config", str(cfg), "--out", str(out)], timeout=600)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    cams = load_json(out / "cameras.json")
    cam, K, poses = camera_matrices(cams)
    assert cam["cx"] == pytest.approx(320 / 2 - 0.06 * 320)
    assert cam["cy"] == pytest.approx(180 / 2 - 0.04 * 320)
    assert [im["name"] for im in cams["images"]] == ["%04d.png" % i for i in range(6)]
    meta = load_json(out / "dataset.json")
    assert [v["group"] for v in meta["views"]] == ["orbit0"] * 2 + ["sphere"] * 2 + ["shell"] * 2
    X, _ = glb_vertices(str(out / "ground_truth.glb"))
    from scipy import ndimage
    errs, shifted = [], []
    for name, (R, t) in poses.items():
        uv, z = project(K, R, t, X)
        stem = name[:-4]
        mask = np.array(Image.open(out / "masks" / (stem + ".png"))) > 127
        depth = np.load(out / "depth" / (stem + ".npy"))
        inside = ((uv[:, 0] >= 0) & (uv[:, 1] >= 0) & (uv[:, 0] < 320) & (uv[:, 1] < 180))
        iu = np.floor(uv[inside, 0]).astype(int)
        iv = np.floor(uv[inside, 1]).astype(int)
        assert ndimage.distance_transform_edt(~mask)[iv, iu].max() <= 1.5, name
        # the floor and walls are background in the mask, but present in the image
        img = np.asarray(Image.open(out / "images" / name).convert("RGB"), float)
        assert img.shape == (180, 320, 3)
        assert mask.mean() < 0.6
        ie = Image.open(out / "images" / name).getexif().get_ifd(0x8769)
        assert float(ie[0x920A]) * float(ie[0xA20E]) / 25.4 == pytest.approx(cam["fx"], abs=1e-9)
        for du, acc in ((0.0, errs), (0.5, shifted)):
            val, ok = bilinear(depth, uv[:, 0] + du, uv[:, 1] + du)
            vis = ok & (np.abs(val - z) < 0.01 * z)
            if vis.sum() > 20:
                acc.append(np.median(np.abs(val - z)[vis] / z[vis]))
    assert len(errs) == 6
    assert np.median(errs) < 5e-4 and np.median(errs) < 0.7 * np.median(shifted)


def test_same_seed_same_images(tmp_path):
    """Within one Blender version the same config and seed give the same pixels."""
    cfg = tmp_path / "t.toml"
    cfg.write_text('preset = "small"\n[render]\nsamples = 4\n[camera]\nresolution = [160, 90]\n'
                   '[views]\norbits = [{elevation_deg = 20.0, count = 2}]\n'
                   '[outputs]\ndepth = false\nmasks = false\n')
    outs = []
    for k in range(2):
        out = tmp_path / ("o%d" % k)
        proc = run_generate(["--config", str(cfg), "--out", str(out)], timeout=300)
        assert proc.returncode == 0, proc.stderr[-2000:]
        outs.append(out)
    for name in ("0000.jpg", "0001.jpg"):
        assert (outs[0] / "images" / name).read_bytes() == (outs[1] / "images" / name).read_bytes()
    assert not (outs[0] / "depth").exists() and not (outs[0] / "masks").exists()
    assert load_json(outs[0] / "cameras.json") == load_json(outs[1] / "cameras.json")
