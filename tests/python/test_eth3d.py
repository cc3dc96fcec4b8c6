"""`sfmeval eth3d` against ETH3D's official multi-view evaluation tool (the C++ program, vendored
in tests/third_party/eth3d_multi_view_evaluation/ and built from Debian's PCL by
scripts/build-eth3d-tool.sh, printing 9 significant digits) on a small scene in ETH3D's layout made
from the demo dataset (eth3d_scene.py): a real sparse SfM cloud, and a dense noisy cloud with a
hole, outliers seen through (inaccurate) and hidden (unobserved).

Every tolerance's accuracy, completeness and F1 must agree to 1e-6 relative (they are the
tool's floats: equal in fact), and the coloured clouds byte for byte.
"""
import json
import subprocess
from pathlib import Path

import jsonschema
import numpy as np
import pytest

import eth3d_scene
import eth3d_tool

HERE = Path(__file__).resolve().parent
SCHEMA = json.loads((HERE.parents[1] / "schemas" / "eth3d.schema.json").read_text())
TOLERANCES = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5]


@pytest.fixture(scope="module")
def tool():
    return eth3d_tool.build()


@pytest.fixture(scope="module")
def scene(tmp_path_factory, sfmeval_bin):
    return eth3d_scene.build(tmp_path_factory.mktemp("eth3d"), sfmeval_bin)


def run_sfmeval(sfmeval_bin, scene, recon, out_dir, *extra):
    p = subprocess.run([sfmeval_bin, "eth3d", "--gt", str(scene["mlp"]), "--recon", str(recon),
                        "--out", str(out_dir), "--json", *extra], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    rep = json.loads(p.stdout)
    jsonschema.validate(rep, SCHEMA)
    assert json.loads((Path(out_dir) / "eth3d.json").read_text()) == rep
    return rep


@pytest.mark.parametrize("case", ["sparse", "dense"])
def test_equals_the_official_tool(sfmeval_bin, tool, scene, tmp_path, case):
    official = eth3d_tool.run(tool, scene["mlp"], scene[case], TOLERANCES, tmp_path / "tool")
    rep = run_sfmeval(sfmeval_bin, scene, scene[case], tmp_path / "ours")
    t = rep["tolerances"]
    assert [x["tolerance"] for x in t] == pytest.approx(official["Tolerances"], rel=1e-7)
    for key, name in (("accuracy", "Accuracies"), ("completeness", "Completenesses"),
                      ("f1", "F1-scores")):
        ours = [x[key] for x in t]
        assert ours == pytest.approx(official[name], rel=1e-6, abs=1e-12), (case, key)
    # The scene gives every class work at the small tolerances, and the numbers move.
    assert t[0]["inaccurate_points"] > 0 and t[0]["unobserved_points"] > 0
    assert 0 < t[0]["accuracy"] < t[-1]["accuracy"] and 0 < t[0]["completeness"] < 1
    tool_files = sorted(p.name for p in (tmp_path / "tool").iterdir())
    ours_files = sorted(p.name for p in (tmp_path / "ours").iterdir() if p.suffix == ".ply")
    assert ours_files == tool_files and len(tool_files) == 2 * len(TOLERANCES)
    for name in tool_files:
        assert (tmp_path / "ours" / name).read_bytes() == (tmp_path / "tool" / name).read_bytes(), name
    # All three classes are coloured in the smallest tolerance's accuracy cloud of the dense case.
    if case == "dense":
        data = (tmp_path / "ours" / "accuracy.tolerance_0.01.ply").read_bytes()
        start = data.index(b"end_header\n") + len(b"end_header\n")
        n = rep["reconstruction_points"]
        rgb = np.frombuffer(data[start:start + 15 * n], dtype=[("p", "<f4", 3), ("c", "u1", 3)])["c"]
        assert {(0, 255, 0), (255, 0, 0), (0, 0, 255)} == set(map(tuple, rgb.tolist()))


def test_threads_of_the_tool_change_no_number(tool, scene):
    """The tool's completeness loop is OpenMP-parallel: its numbers do not depend on it."""
    one = eth3d_tool.run(tool, scene["mlp"], scene["dense"], TOLERANCES, threads=1)
    two = eth3d_tool.run(tool, scene["mlp"], scene["dense"], TOLERANCES, threads=2)
    assert one == two


def test_double_precision_reconstruction_is_read_as_floats(sfmeval_bin, scene, tmp_path):
    """A PLY of doubles gives the numbers of the same points stored as floats (the tool's PCL
    1.13 reads such a file as all zeros; sfmeval rounds to float as the tool's points are)."""
    pts = np.asarray(eth3d_scene.read_ply_f32(scene["dense"]), dtype=np.float64)
    doubles = tmp_path / "dense64.ply"
    eth3d_scene.write_ply(doubles, pts)
    a = run_sfmeval(sfmeval_bin, scene, scene["dense"], tmp_path / "a")
    b = run_sfmeval(sfmeval_bin, scene, doubles, tmp_path / "b")
    assert a["tolerances"] == b["tolerances"]


def test_options_and_unsorted_tolerances(sfmeval_bin, tool, scene, tmp_path):
    """Another voxel size and beam, the tolerances unsorted: still the tool's numbers."""
    tols = [0.05, 0.005, 0.03]
    extra = ["--voxel_size", "0.03", "--beam_start_radius_meters", "0.004",
             "--beam_divergence_halfangle_deg", "0.05"]
    cmd = [str(tool), "--reconstruction_ply_path", str(scene["dense"]), "--ground_truth_mlp_path",
           str(scene["mlp"]), "--tolerances", ",".join(map(str, tols)), *extra]
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    official = {ln.split(": ")[0]: [float(v) for v in ln.split(": ")[1].split()]
                for ln in p.stdout.splitlines() if ln.split(": ")[0] in ("Accuracies", "Completenesses")}
    rep = run_sfmeval(sfmeval_bin, scene, scene["dense"], tmp_path / "ours", "--tolerances",
                      ",".join(map(str, tols)), "--voxel-size", "0.03", "--beam-start-radius",
                      "0.004", "--beam-divergence-halfangle-deg", "0.05")
    assert [x["tolerance"] for x in rep["tolerances"]] == pytest.approx(sorted(tols), rel=1e-7)
    assert [x["accuracy"] for x in rep["tolerances"]] == pytest.approx(official["Accuracies"], rel=1e-6)
    assert [x["completeness"] for x in rep["tolerances"]] == pytest.approx(official["Completenesses"], rel=1e-6)


def test_missing_scan_and_bad_reconstruction_are_named(sfmeval_bin, scene, tmp_path):
    mlp = tmp_path / "scan_alignment.mlp"
    mlp.write_text(Path(scene["mlp"]).read_text().replace('filename="scan2.ply"',
                                                           'filename="gone.ply"'))
    (tmp_path / "scan1.ply").write_bytes((Path(scene["mlp"]).parent / "scan1.ply").read_bytes())
    p = subprocess.run([sfmeval_bin, "eth3d", "--gt", str(mlp), "--recon", str(scene["dense"])],
                       capture_output=True, text=True)
    assert p.returncode == 1 and "gone.ply" in p.stderr, p.stderr
    bad = tmp_path / "bad.ply"
    bad.write_bytes(Path(scene["dense"]).read_bytes()[:500])
    p = subprocess.run([sfmeval_bin, "eth3d", "--gt", str(scene["mlp"]), "--recon", str(bad)],
                       capture_output=True, text=True)
    assert p.returncode == 1 and "bad.ply" in p.stderr and "panicked" not in p.stderr, p.stderr
