"""`sfmeval export RECON --out DIR`: the reconstruction's points as a float64 PLY and its cameras
as cameras.json, in the reconstruction's own frame (what the Blender panel imports).

Checked against pycolmap reading the same COLMAP model (text and binary): the points (x, y, z
bit for bit, and colours) and every image's camera centre; a PLY's float32 points come back as
the same numbers in float64 (numpy reads the source); bad input is an error naming the file,
and nothing is written.
"""
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "tests" / "fixtures" / "models"


def read_ply(path):
    """(points (N,3) float64, colours (N,3) uint8 or None) of a binary little-endian PLY whose
    vertices have only scalar properties (numpy, independent of sfmeval's reader)."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert "format binary_little_endian 1.0" in header
    types = {"double": "<f8", "float": "<f4", "uchar": "u1"}
    n = next(int(ln.split()[2]) for ln in header if ln.startswith("element vertex"))
    props = [(ln.split()[2], types[ln.split()[1]]) for ln in header if ln.startswith("property")]
    rec = np.frombuffer(data[end:], dtype=np.dtype(props), count=n)
    pts = np.stack([rec["x"], rec["y"], rec["z"]], axis=1).astype(np.float64)
    names = [p for p, _ in props]
    cols = np.stack([rec["red"], rec["green"], rec["blue"]], axis=1) if "red" in names else None
    return pts, cols, props


def export(sfmeval_bin, recon, out, *extra):
    return subprocess.run([sfmeval_bin, "export", str(recon), "--out", str(out), *map(str, extra)],
                          capture_output=True, text=True)


@pytest.mark.parametrize("model", ["colmap_text", "colmap_bin"])
def test_export_equals_pycolmap(sfmeval_bin, tmp_path, model):
    pycolmap = pytest.importorskip("pycolmap")
    p = export(sfmeval_bin, MODELS / model, tmp_path)
    assert p.returncode == 0, p.stderr
    rec = pycolmap.Reconstruction(str(MODELS / model))
    pts, cols, props = read_ply(tmp_path / "points.ply")
    assert [t for _, t in props[:3]] == ["<f8"] * 3
    theirs = sorted((tuple(pt.xyz), tuple(int(c) for c in pt.color))
                    for pt in rec.points3D.values())
    mine = sorted((tuple(x), tuple(int(c) for c in col)) for x, col in zip(pts, cols))
    assert len(mine) == len(theirs) == 101
    assert mine == theirs  # every coordinate bit for bit, every colour
    cams = json.loads((tmp_path / "cameras.json").read_text())
    assert cams["frame"] == "reconstruction"
    centres = {}
    for im in cams["images"]:
        r = np.array(im["cam_from_world"]["rotation"], float)
        t = np.array(im["cam_from_world"]["translation"], float)
        centres[im["name"]] = -r.T @ t
    theirs = {im.name: np.asarray(im.projection_center()) for im in rec.images.values()
              if im.has_pose}
    assert set(centres) == set(theirs) and len(theirs) == 6
    for name, c in theirs.items():
        np.testing.assert_allclose(centres[name], c, rtol=0, atol=1e-12)
    by_id = {c.camera_id: c for c in rec.cameras.values()}
    for cam in cams["cameras"]:
        assert (cam["width"], cam["height"]) == (by_id[cam["id"]].width, by_id[cam["id"]].height)
        assert cam["fx"] == by_id[cam["id"]].focal_length_x


def test_export_reads_back_as_the_same_evaluation(sfmeval_bin, tmp_path):
    """The exported points and cameras evaluate exactly as the model itself: same report
    numbers (accuracy, cameras) with the demo's ground truth."""
    demo = ROOT / "data" / "demo"
    assert export(sfmeval_bin, demo / "sparse", tmp_path / "ex").returncode == 0
    reports = []
    for recon, cams in [(demo / "sparse", None), (tmp_path / "ex" / "points.ply",
                                                  tmp_path / "ex" / "cameras.json")]:
        out = tmp_path / ("r%d.json" % len(reports))
        argv = [sfmeval_bin, "eval", "--dataset", demo, "--recon", recon, "--name", "x",
                "--report", out, "--quiet", "--samples", "20000"]
        if cams:
            argv += ["--recon-cameras", cams]
        subprocess.run(list(map(str, argv)), check=True, capture_output=True)
        reports.append(json.loads(out.read_text()))
    a, b = reports
    assert a["accuracy"] == b["accuracy"]
    assert a["alignment"]["gt_from_recon"] == b["alignment"]["gt_from_recon"]
    assert a["cameras"]["ate_rmse"] == b["cameras"]["ate_rmse"]


def test_export_of_a_ply_is_its_points_in_float64(sfmeval_bin, tmp_path):
    src = ROOT / "data" / "demo" / "sparse.ply"
    p = export(sfmeval_bin, src, tmp_path)
    assert p.returncode == 0, p.stderr
    theirs, their_cols, their_props = read_ply(src)
    assert [t for _, t in their_props[:3]] == ["<f4"] * 3
    mine, cols, _ = read_ply(tmp_path / "points.ply")
    assert np.array_equal(mine, theirs) and np.array_equal(cols, their_cols)
    assert not (tmp_path / "cameras.json").exists()
    assert "2529 points with colours, no cameras" in p.stdout


@pytest.mark.parametrize("name, content, message", [
    ("missing.nvm", None, "missing file"),
    ("bad.nvm", b"garbage\n", "expected NVM_V3"),
    ("bad.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 9\nproperty float x\n"
                b"property float y\nproperty float z\nend_header\n\0\0", None),
    ("sfm_data.json", b"{\"views\": 3}", None),
])
def test_export_bad_input_names_the_file(sfmeval_bin, tmp_path, name, content, message):
    src = tmp_path / name
    if content is not None:
        src.write_bytes(content)
    out = tmp_path / "out"
    p = export(sfmeval_bin, src, out)
    assert p.returncode == 1, p.stderr
    assert "panicked" not in p.stderr
    assert str(src) in p.stderr or name in p.stderr, p.stderr
    if message:
        assert message in p.stderr, p.stderr
    assert not out.exists()


def test_export_of_a_run_folder_is_what_the_runner_evaluates(sfmeval_bin, tmp_path):
    """A runner's run folder (run.json beside model/ and sparse.ply) exports by the run-folder
    layout of sfmeval-table, as the runner's report reads it: the model's float64 points and
    cameras when model/ holds one, else sparse.ply; not sparse.ply's float32 copy of them."""
    import shutil
    demo = ROOT / "data" / "demo"
    run = tmp_path / "copy"
    shutil.copytree(demo / "sparse", run / "model")
    shutil.copy(demo / "sparse.ply", run / "sparse.ply")
    (run / "run.json").write_text("{}")
    for recon, out in ((run, "run"), (demo / "sparse", "model")):
        p = export(sfmeval_bin, recon, tmp_path / out)
        assert p.returncode == 0, p.stderr
    for f in ("points.ply", "cameras.json"):
        assert (tmp_path / "run" / f).read_bytes() == (tmp_path / "model" / f).read_bytes(), f
    shutil.rmtree(run / "model")
    p = export(sfmeval_bin, run, tmp_path / "ply")
    assert p.returncode == 0, p.stderr
    assert not (tmp_path / "ply" / "cameras.json").exists()
    pts, _, _ = read_ply(tmp_path / "ply" / "points.ply")
    ply, _, _ = read_ply(demo / "sparse.ply")
    assert np.array_equal(pts, ply)
    (run / "sparse.ply").unlink()
    p = export(sfmeval_bin, run, tmp_path / "none")
    assert p.returncode == 1 and str(run) in p.stderr and "sparse.ply" in p.stderr, p.stderr
