"""`sfmeval dtu` against the DTU evaluation's Python port (DTUeval-python's eval.py, vendored in
tests/reference/dtueval_python/ and run unchanged by dtu_port.py with its shuffle kept in the
input's order) on a small scan in DTU's layout made from the demo dataset, in mm (dtu_scene.py):
a real sparse SfM cloud, a dense noisy cloud with a hole and outliers (the down-sampling and the
box matter), and a mesh the evaluator samples.

Mean accuracy, mean completeness and overall must agree to 1e-6 relative, and the coloured
error clouds (vis_001_d2s.ply, vis_001_s2d.ply) byte for byte after their headers.
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import pytest

import dtu_scene

HERE = Path(__file__).resolve().parent
PORT = HERE / "dtu_port.py"
PYTHON = os.environ.get("SFMEVAL_PYTHON", sys.executable)
SCHEMA = json.loads((HERE.parents[1] / "schemas" / "dtu.schema.json").read_text())


@pytest.fixture(scope="module")
def scene(tmp_path_factory, sfmeval_bin):
    return dtu_scene.build(tmp_path_factory.mktemp("dtu"), sfmeval_bin)


def run_port(scene, recon, mode, vis_dir):
    vis_dir.mkdir(parents=True, exist_ok=True)
    p = subprocess.run([PYTHON, str(PORT), "--data", str(recon), "--scan", str(scene["scan"]),
                        "--mode", mode, "--dataset_dir", str(scene["dataset"]),
                        "--vis_out_dir", str(vis_dir)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr[-3000:]
    return [float(v) for v in p.stdout.strip().splitlines()[-1].split()]


def run_sfmeval(sfmeval_bin, scene, recon, mode, vis_dir, *extra):
    p = subprocess.run([sfmeval_bin, "dtu", "--dataset", str(scene["dataset"]),
                        "--scan", str(scene["scan"]), "--recon", str(recon), "--mode", mode,
                        "--vis-out", str(vis_dir), "--json", *extra],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    rep = json.loads(p.stdout)
    jsonschema.validate(rep, SCHEMA)
    return rep


def body(path):
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    return data[:end], data[end:]


@pytest.mark.parametrize("case, mode", [("sparse", "pcd"), ("dense", "pcd"), ("mesh", "mesh")])
def test_equals_the_python_port(sfmeval_bin, scene, tmp_path, case, mode):
    port = run_port(scene, scene[case], mode, tmp_path / "port")
    rep = run_sfmeval(sfmeval_bin, scene, scene[case], mode, tmp_path / "ours", "--no-shuffle")
    ours = [rep["mean_accuracy"], rep["mean_completeness"], rep["overall"]]
    assert ours == pytest.approx(port, rel=1e-6, abs=0), (case, ours, port)
    c = rep["counts"]
    # The scene is built so that every filter has work to do.
    assert c["downsampled"] <= c["points"]
    assert c["observed"] < c["in_bounding_box"]
    assert c["stl_above_plane"] < c["stl_points"]
    if case == "dense":
        assert c["in_bounding_box"] < c["downsampled"]
        assert c["accuracy_below_max_dist"] < c["observed"]
        assert c["downsampled"] < 0.9 * c["points"]
    for name in ("vis_001_d2s.ply", "vis_001_s2d.ply"):
        head_port, body_port = body(tmp_path / "port" / name)
        head_ours, body_ours = body(tmp_path / "ours" / name)
        assert head_ours == head_port.replace(b"Open3D", b"sfmeval"), name
        assert body_ours == body_port, name
    # All four colours appear in the d2s cloud of the dense case.
    if case == "dense":
        _, d2s = body(tmp_path / "ours" / "vis_001_d2s.ply")
        rgb = np.frombuffer(d2s, dtype=[("p", "<f8", 3), ("c", "u1", 3)])["c"]
        assert {(0, 0, 255), (0, 255, 0), (255, 0, 0), (255, 255, 255)} <= set(map(tuple, rgb.tolist()))


def test_the_shuffle_is_seeded_and_changes_little(sfmeval_bin, scene, tmp_path):
    """The evaluator shuffles at random: a seed gives the same numbers every run, another seed
    numbers within the port's own run-to-run spread (its README: about 0.01 %)."""
    a = run_sfmeval(sfmeval_bin, scene, scene["mesh"], "mesh", tmp_path / "a", "--seed", "1")
    b = run_sfmeval(sfmeval_bin, scene, scene["mesh"], "mesh", tmp_path / "b", "--seed", "1")
    c = run_sfmeval(sfmeval_bin, scene, scene["mesh"], "mesh", tmp_path / "c", "--seed", "2")
    assert a == b
    assert a["counts"]["downsampled"] != c["counts"]["downsampled"]
    assert c["overall"] == pytest.approx(a["overall"], rel=2e-3)


def test_missing_and_wrong_files_are_named(sfmeval_bin, scene, tmp_path):
    p = subprocess.run([sfmeval_bin, "dtu", "--dataset", str(scene["dataset"]), "--scan", "2",
                        "--recon", str(scene["sparse"])], capture_output=True, text=True)
    assert p.returncode == 1 and "stl002_total.ply" in p.stderr, p.stderr
    far = tmp_path / "far.ply"
    dtu_scene.write_ply(far, np.full((10, 3), 1e4))
    p = subprocess.run([sfmeval_bin, "dtu", "--dataset", str(scene["dataset"]), "--scan", "1",
                        "--recon", str(far)], capture_output=True, text=True)
    assert p.returncode == 1 and "far.ply" in p.stderr and "bounding box" in p.stderr, p.stderr
