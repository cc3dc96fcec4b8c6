"""Rendering a dataset in parts (`generate.py --views i/n` / `A:B`, then `--finalize`) gives the
folder a one-shot render gives, byte for byte: images (with EXIF and seeded noise), depth
maps, masks, ground truth, cameras, sparse_gt and dataset.json. Only timing.json differs: it
holds the measured render times (and, for parts, where each part ran). A tiny dataset: 8 views
at 160x90, 4 spp, ~2 s per render."""

import os

import pytest

from blender_testlib import load_json, requires_bpy, run_generate

pytestmark = requires_bpy

ARGS = ["--preset", "statue", "--set", "camera.resolution=[160, 90]",
        "--set", "render.samples=4", "--set", "postprocess.noise_sigma=4",
        "--set", "views.orbits=[{elevation_deg=20.0, count=4}, "
                 "{elevation_deg=45.0, count=4, azimuth_offset_deg=15.0}]",
        "--set", "views.sphere.count=0"]


def gen(*args):
    proc = run_generate(ARGS + list(args), timeout=300)
    return proc


def files(root):
    out = {}
    for d, _, names in os.walk(root):
        for n in names:
            p = os.path.join(d, n)
            with open(p, "rb") as f:
                out[os.path.relpath(p, root)] = f.read()
    return out


@pytest.fixture(scope="module")
def one_shot(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("parts") / "one")
    proc = gen("--out", out)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return out


def test_shards_and_finalize_equal_a_one_shot_render(one_shot, tmp_path):
    out = str(tmp_path / "split")
    for views in ["1/2", "0/2"]:  # any order
        proc = gen("--views", views, "--out", out)
        assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
        assert not os.path.exists(os.path.join(out, "dataset.json"))
    assert sorted(os.listdir(os.path.join(out, ".parts"))) == ["views-0-of-2.json",
                                                               "views-1-of-2.json"]
    proc = gen("--finalize", "--out", out)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    a, b = files(one_shot), files(out)
    assert sorted(a) == sorted(b)  # no .parts/ left, nothing missing
    assert len([k for k in a if k.startswith("images/")]) == 8
    assert {"depth/0007.npy", "masks/0007.png", "ground_truth.glb", "cameras.json",
            "dataset.json", "sparse_gt/images.txt"} <= set(a)
    differ = [k for k in a if a[k] != b[k]]
    assert differ == ["timing.json"], differ
    t1, t2 = load_json(os.path.join(one_shot, "timing.json")), load_json(os.path.join(out, "timing.json"))
    assert t1["parts"] is None and len(t1["render_seconds_per_frame"]) == 8
    assert [p["views"] for p in t2["parts"]] == ["shard 0 2", "shard 1 2"]
    assert t2["parts"][0]["images"] == ["0000.jpg", "0002.jpg", "0004.jpg", "0006.jpg"]
    assert len(t2["render_seconds_per_frame"]) == 8
    assert all(t > 0 for t in t2["render_seconds_per_frame"])
    # a finished dataset refuses more parts
    proc = gen("--views", "0/2", "--out", out)
    assert proc.returncode == 2 and "finished dataset" in proc.stderr


def test_ranges_must_cover_every_view_once(one_shot, tmp_path):
    out = str(tmp_path / "ranges")
    for views in ["0:3", "3:6"]:
        assert gen("--views", views, "--out", out).returncode == 0
    proc = gen("--finalize", "--out", out)
    assert proc.returncode == 1 and "2 of 8 views are not rendered yet: 0006.jpg, 0007.jpg" \
        in proc.stderr, proc.stderr
    assert not os.path.exists(os.path.join(out, "dataset.json"))
    assert gen("--views", "2:4", "--out", out).returncode == 0  # overlaps both
    proc = gen("--finalize", "--out", out)
    assert proc.returncode == 1 and "is in two parts" in proc.stderr, proc.stderr
    os.remove(os.path.join(out, ".parts", "views-2-to-4.json"))
    assert gen("--views", "6:100", "--out", out).returncode == 0  # clipped to the last view
    proc = gen("--finalize", "--out", out)
    assert proc.returncode == 0, proc.stderr
    a, b = files(one_shot), files(out)
    assert sorted(a) == sorted(b)
    assert [k for k in a if a[k] != b[k]] == ["timing.json"]
    # a part rendered from another configuration is refused
    other = str(tmp_path / "mixed")
    assert gen("--views", "0/2", "--out", other).returncode == 0
    proc = run_generate(ARGS + ["--set", "render.samples=2", "--views", "1/2", "--out", other])
    assert proc.returncode == 0
    proc = gen("--finalize", "--out", other)
    assert proc.returncode == 1 and "another configuration" in proc.stderr, proc.stderr
    proc = gen("--views", "2/2", "--out", other)
    assert proc.returncode == 2 and "0 <= i < n" in proc.stderr
