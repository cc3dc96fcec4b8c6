"""Config, presets, camera sampling and conventions: pure Python, no Blender."""

import json
import math
import os

import numpy as np
import pytest

from sfmeval_blender import config, geometry, tomlmini

SEED_COUNTS = {"statue": 121, "vase": 86, "bicycle": 86, "hydrant": 66, "vehicle": 141, "small": 36}


@pytest.mark.parametrize("name,count", sorted(SEED_COUNTS.items()))
def test_presets_view_counts(name, count):
    cfg = config.resolve(preset=name)
    assert config.count_views(cfg) == count
    if name != "small":
        assert cfg["camera"]["resolution"] == [1920, 1080]
        assert cfg["object"]["source"] == "builtin:" + name
    else:
        assert cfg["camera"]["resolution"] == [640, 360]


def test_defaults_are_the_seed_camera():
    cfg = config.resolve({})
    k = geometry.intrinsics(cfg["camera"])
    assert cfg["camera"]["focal_mm"] == 35.0 and cfg["camera"]["sensor_mm"] == [32.0, 18.0]
    assert (k["width"], k["height"]) == (1920, 1080)
    assert k["fx"] == pytest.approx(2100.0) and k["cx"] == 960.0 and k["cy"] == 540.0
    assert cfg["camera"]["exif_35mm_equivalent"] is False


def test_unknown_option_is_named_with_a_suggestion():
    with pytest.raises(config.ConfigError, match=r"render\.sampels.*did you mean 'samples'"):
        config.resolve({"render": {"sampels": 4}})
    with pytest.raises(config.ConfigError, match=r"unknown option 'views\.orbits\[0\]\.elevation'"):
        config.resolve({"views": {"orbits": [{"elevation": 4}]}})
    with pytest.raises(config.ConfigError, match="unknown option 'bogus'"):
        config.resolve({}, overrides=["bogus.x=1"])


def test_zero_views_is_an_error():
    with pytest.raises(config.ConfigError, match="zero views"):
        config.resolve({"views": {"orbits": []}})
    with pytest.raises(config.ConfigError, match="zero views"):
        config.resolve({"views": {"orbits": [{"count": 0}]}})


def test_bad_values():
    with pytest.raises(config.ConfigError, match="render.format must be one of"):
        config.resolve({"render": {"format": "GIF"}})
    with pytest.raises(config.ConfigError, match="render.samples must be of type int"):
        config.resolve({"render": {"samples": "many"}})
    with pytest.raises(config.ConfigError, match="aspect"):
        config.resolve({"camera": {"resolution": [640, 480]}})
    with pytest.raises(config.ConfigError, match="unknown built-in object"):
        config.resolve({"object": {"source": "builtin:teapot"}})


def test_missing_and_unreadable_model_files(tmp_path):
    with pytest.raises(config.ConfigError, match="model file not found"):
        config.resolve({"object": {"source": str(tmp_path / "nope.obj")}})
    empty = tmp_path / "empty.ply"
    empty.write_bytes(b"")
    with pytest.raises(config.ConfigError, match="empty"):
        config.resolve({"object": {"source": str(empty)}})
    bad = tmp_path / "bad.glb"
    bad.write_bytes(b"this is not a binary glTF")
    with pytest.raises(config.ConfigError, match="does not look like"):
        config.resolve({"object": {"source": str(bad)}})
    weird = tmp_path / "model.xyz"
    weird.write_text("1 2 3")
    with pytest.raises(config.ConfigError, match="unsupported model format"):
        config.resolve({"object": {"source": str(weird)}})


def test_toml_fallback_parser_matches_tomllib():
    import tomllib
    for name in config.preset_names():
        with open(os.path.join(config.PRESET_DIR, name + ".toml"), "rb") as f:
            text = f.read().decode()
        assert tomlmini.loads(text, force_fallback=True) == tomllib.loads(text), name
    text = ('a = 1\nb = "x\\ty"\nc = [1.5, -2e3, true]\n[t.u]\nv = {w = [1, 2], \'q\' = \'lit\'}\n'
            '[[arr]]\nx = 1\n[[arr]]\nx = 2 # comment\ny = [\n  1,\n  2,\n]\n')
    assert tomlmini.loads(text, force_fallback=True) == tomllib.loads(text)
    with pytest.raises(tomlmini.TomlError, match="line 2"):
        tomlmini.loads("a = 1\nb = \n", force_fallback=True)


def test_json_and_toml_configs_are_equivalent(tmp_path):
    toml = tmp_path / "d.toml"
    toml.write_text('preset = "small"\n[render]\nsamples = 7\n[[views.orbits]]\ncount = 5\n')
    js = tmp_path / "d.json"
    js.write_text(json.dumps({"preset": "small", "render": {"samples": 7},
                              "views": {"orbits": [{"count": 5}]}}))
    a = config.resolve(config.load_file(str(toml)))
    b = config.resolve(config.load_file(str(js)))
    assert a == b and a["render"]["samples"] == 7 and config.count_views(a) == 5


def test_relative_model_path_is_relative_to_the_config(tmp_path):
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "d.toml").write_text('[object]\nsource = "m.obj"\n')
    cfg = config.resolve(config.load_file(str(tmp_path / "d.toml")))
    assert cfg["object"]["source"] == str(tmp_path / "m.obj")


def test_cameras_look_at_the_target_and_are_reproducible():
    cfg = config.resolve({"views": {"sphere": {"count": 10}, "shell": {"count": 10}}}, preset="small")
    target = [0.1, -0.2, 0.3]
    a = geometry.camera_positions(cfg["views"], target, 2.5, seed=3)
    b = geometry.camera_positions(cfg["views"], target, 2.5, seed=3)
    c = geometry.camera_positions(cfg["views"], target, 2.5, seed=4)
    assert a == b and len(a) == 56
    assert a[-1]["eye"] != c[-1]["eye"]                  # the shell depends on the seed
    for v in a:
        rot = np.array(geometry.look_at_rotation(v["eye"], target))
        assert np.allclose(rot.T @ rot, np.eye(3), atol=1e-12) and np.linalg.det(rot) > 0
        forward = -rot[:, 2]                             # Blender camera looks along -Z
        to_target = np.array(target) - np.array(v["eye"])
        assert np.allclose(forward, to_target / np.linalg.norm(to_target), atol=1e-12)
        assert rot[2, 1] >= 0                            # image up points to world +Z
    ring = [v for v in a if v["group"] == "orbit0"]
    assert all(math.isclose(v["eye"][2] - target[2], 2.5 * math.sin(math.radians(20)), abs_tol=1e-12)
               for v in ring)


def test_opencv_pose_in_gltf_frame():
    # A Blender camera at (0, -5, 0) looking at the origin (towards +Y), image up = +Z.
    rot = geometry.look_at_rotation([0, -5, 0], [0, 0, 0])
    R, t, c = geometry.opencv_pose_gltf(rot, [0, -5, 0])
    R = np.array(R)
    assert np.allclose(c, [0, 0, 5])                      # (x, y, z)_b → (x, z, −y)_gltf
    # glTF origin is 5 m in front of the camera; glTF +Y (up) is image −y (up), +X is right.
    assert np.allclose(R @ [0, 0, 0] + t, [0, 0, 5])
    assert np.allclose(R @ [0, 1, 0], [0, -1, 0])
    assert np.allclose(R @ [1, 0, 0], [1, 0, 0])
    q = geometry.rotation_to_quaternion(R.tolist())
    w, x, y, z = q
    Rq = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                   [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                   [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    assert np.allclose(Rq, R)


def test_principal_point_from_shift():
    k = geometry.intrinsics({"resolution": [640, 360], "focal_mm": 35, "sensor_mm": [32, 18],
                             "shift": [0.1, -0.05]})
    assert k["cx"] == pytest.approx(320 - 64) and k["cy"] == pytest.approx(180 - 32)
