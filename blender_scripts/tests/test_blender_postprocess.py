"""Image post-processes (blur, noise) and partial-arc orbits (azimuth_step_deg): the NumPy
arithmetic, the config checks, and one tiny real render that applies them before EXIF."""

import math
import os

import numpy as np
import pytest
from PIL import Image

from blender_testlib import load_json, requires_bpy, run_generate
from sfmeval_blender import config, geometry, postprocess


def _cfg(**pp):
    return config.resolve({"postprocess": pp}, preset="small")


def test_defaults_are_off_and_recorded():
    cfg = config.resolve(preset="small")
    assert cfg["postprocess"] == {"blur_sigma": 0.0, "noise_sigma": 0.0, "seed": -1}
    assert not postprocess.active(cfg)
    img = (np.arange(60, dtype=np.uint8).reshape(4, 5, 3))
    assert np.array_equal(postprocess.apply(img, cfg, 0), img)


def test_kernel_and_blur():
    k = postprocess.gaussian_kernel(1.5)
    assert len(k) == 2 * 5 + 1 and abs(k.sum() - 1) < 1e-12 and k.argmax() == 5
    # std of the discrete kernel ≈ sigma
    x = np.arange(-5, 6)
    assert abs(math.sqrt((k * x * x).sum()) - 1.5) < 0.02
    rng = np.random.default_rng(0)
    img = rng.uniform(0, 255, size=(40, 50, 3))
    out = postprocess.blur(img, 2.0)
    assert out.shape == img.shape
    assert abs(out.mean() - img.mean()) < 1.0         # mass preserved (reflect edges)
    assert out.std() < 0.3 * img.std()                # white noise is smoothed away
    # a constant image is unchanged; an impulse spreads into the kernel (separable: outer product)
    assert np.allclose(postprocess.blur(np.full((9, 9, 1), 7.0), 1.0), 7.0)
    imp = np.zeros((21, 21, 1))
    imp[10, 10, 0] = 1.0
    k1 = postprocess.gaussian_kernel(1.0)
    got = postprocess.blur(imp, 1.0)[7:14, 7:14, 0]
    assert np.allclose(got, np.outer(k1, k1), atol=1e-12)


def test_noise_is_seeded_and_has_sigma():
    cfg = _cfg(noise_sigma=8.0)
    img = np.full((120, 160, 3), 128, np.uint8)
    a = postprocess.apply(img, cfg, 3)
    b = postprocess.apply(img, cfg, 3)
    c = postprocess.apply(img, cfg, 4)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    d = a.astype(float) - 128
    assert abs(d.mean()) < 0.2 and abs(d.std() - 8.0) < 0.2
    other = postprocess.apply(img, config.resolve({"postprocess": {"noise_sigma": 8.0, "seed": 5}},
                                                  preset="small"), 3)
    assert not np.array_equal(a, other)
    # clipped to the 8-bit range
    dark = postprocess.apply(np.zeros((50, 50, 3), np.uint8), cfg, 0)
    assert dark.dtype == np.uint8 and dark.min() == 0


def test_config_checks():
    with pytest.raises(config.ConfigError, match="noise_sigma"):
        _cfg(noise_sigma=-1.0)
    with pytest.raises(config.ConfigError, match="blur_sigma"):
        _cfg(blur_sigma=-0.5)
    with pytest.raises(config.ConfigError, match="png_color_depth"):
        config.resolve({"postprocess": {"blur_sigma": 1.0},
                        "render": {"format": "PNG", "png_color_depth": 16}}, preset="small")
    with pytest.raises(config.ConfigError, match="full circle"):
        config.resolve(preset="small", overrides=["views.orbits=[{count=18, azimuth_step_deg=30.0}]"])
    with pytest.raises(config.ConfigError, match="azimuth_step_deg"):
        config.resolve(preset="small", overrides=["views.orbits=[{count=3, azimuth_step_deg=-1.0}]"])


def test_azimuth_step_makes_a_partial_arc():
    cfg = config.resolve(preset="small", overrides=[
        "views.orbits=[{elevation_deg=20.0, count=5, azimuth_step_deg=7.5, azimuth_offset_deg=10.0}]"])
    views = geometry.camera_positions(cfg["views"], [0, 0, 0], 3.0, 0)
    az = [v["azimuth_deg"] for v in views]
    assert np.allclose(az, [10.0, 17.5, 25.0, 32.5, 40.0])
    # step 0 keeps the full evenly spaced ring (the previous behaviour, bit for bit)
    full = geometry.camera_positions(config.resolve(preset="small")["views"], [0, 0, 0], 3.0, 0)
    assert np.allclose([v["azimuth_deg"] for v in full[:18]], np.arange(18) * 20.0)


@requires_bpy
def test_render_with_blur_and_noise(tmp_path):
    """4 views at 160×90: blur + noise applied, EXIF still written, settings in dataset.json,
    and the same config renders the same bytes."""
    base = ["--preset", "small", "--set", "render.samples=2", "--set", "camera.resolution=[160, 90]",
            "--set", "views.orbits=[{elevation_deg=30.0, count=2}]", "--set", "outputs.depth=false",
            "--set", "outputs.masks=false"]
    pp = ["--set", "postprocess.blur_sigma=1.5", "--set", "postprocess.noise_sigma=6.0"]
    outs = {}
    for name, extra in (("plain", []), ("pp", pp), ("pp2", pp)):
        out = tmp_path / name
        proc = run_generate(base + extra + ["--out", str(out)], timeout=600)
        assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
        outs[name] = out
    ds = load_json(outs["pp"] / "dataset.json")
    assert ds["settings"]["postprocess"]["blur_sigma"] == 1.5
    assert ds["settings"]["postprocess"]["noise_sigma"] == 6.0
    assert ds["render"]["postprocess"]["applied"] is True
    assert load_json(outs["plain"] / "dataset.json")["render"]["postprocess"]["applied"] is False
    for name in ("0000.jpg", "0001.jpg"):
        a = outs["plain"] / "images" / name
        b = outs["pp"] / "images" / name
        assert a.read_bytes() != b.read_bytes()
        assert b.read_bytes() == (outs["pp2"] / "images" / name).read_bytes()
        assert not os.path.exists(str(b) + ".render.png")
        with Image.open(b) as im:
            assert im.size == (160, 90) and im.format == "JPEG"
            assert im.getexif().get_ifd(0x8769).get(0x920A) is not None  # FocalLength
            pix = np.asarray(im.convert("L"), float)
        with Image.open(a) as im:
            ref = np.asarray(im.convert("L"), float)
        # noise adds high-frequency energy that the plain render does not have
        hf = lambda x: np.abs(np.diff(x, axis=1)).mean()  # noqa: E731
        assert hf(pix) > hf(ref)
