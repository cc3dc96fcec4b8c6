"""The runner on a DTU scan: a tiny scan in DTU's layout (tests/python/dtu_scene.py: the demo's
statue in mm with the benchmark's STL points, observation mask and plane) with images/ and the
ground-truth cameras (data/demo's cameras.json in mm), run with a custom pipeline that
"reconstructs" by copying data/demo's real COLMAP model and one that fails. Each run is aligned
by its cameras and evaluated with the DTU protocol; its report equals `sfmeval dtu` on the
points the runner wrote in the scan's frame, byte for byte; the DTU numbers are columns of the
tables. The same batch through the local executor (run, then report) and through Slurm (its
collect stage evaluates) gives the same reports and Table I byte for byte.
No rendering and no SfM tool."""

import json
import os
import subprocess
import sys

import pytest

import slurm_testlib
from runner_testlib import REPO, load, run_cli

sys.path.insert(0, os.path.join(REPO, "tests", "python"))
import dtu_scene  # noqa: E402

DEMO = os.path.join(REPO, "data", "demo")
PIPES = ["--pipelines", "copy;bad",
         "--custom", "copy=cp %s {out}/" % " ".join(
             os.path.join(DEMO, "sparse", f) for f in ("cameras.txt", "images.txt",
                                                       "points3D.txt")),
         "--custom", "bad=no-such-sfm-tool {images} {out}"]
SLURM = ["--executor", "slurm", "--stage", "run:cpus=1,mem=500M,time=10",
         "--stage", "collect:cpus=1,mem=1G"]


@pytest.fixture(scope="module")
def sfmeval_cli():
    b = os.environ.get("SFMEVAL_BIN") or os.path.join(REPO, "target", "release", "sfmeval")
    assert os.path.isfile(b), b
    return b


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = slurm_testlib.start(str(tmp_path_factory.mktemp("slurm-cluster")))
    yield c
    c.stop()


def dtu_dataset(root, sfmeval_cli):
    """scan1/ in DTU's layout, with images/ (placeholders named as the demo's) and cameras.json
    (the demo's cameras in the scan's frame: × dtu_scene.SCALE, in mm)."""
    d = root / "scan1"
    scene = dtu_scene.build(d, sfmeval_cli, stl_points=20_000, dense_points=1000)
    cams = json.load(open(os.path.join(DEMO, "cameras.json")))
    (d / "images").mkdir()
    for im in cams["images"]:
        (d / "images" / im["name"]).write_bytes(b"\xff\xd8 placeholder")
        im["center"] = [c * dtu_scene.SCALE for c in im["center"]]
        t = im["cam_from_world"]["translation"]
        im["cam_from_world"]["translation"] = [c * dtu_scene.SCALE for c in t]
    (d / "cameras.json").write_text(json.dumps(cams, indent=1))
    return d, scene


def test_dtu_scan_through_both_executors(runner_bin, sfmeval_cli, cluster, tmp_path):
    scan, scene = dtu_dataset(tmp_path / "data", sfmeval_cli)
    grid = ["--datasets", scan] + PIPES
    local = tmp_path / "local"
    run_cli(runner_bin, "run", *grid, "--out", local)
    table = tmp_path / "local-table"
    run_cli(runner_bin, "report", local, "--out", table)

    rows = {r["pipeline"]: r for r in load(table / "summary.json")["rows"]}
    assert rows["bad"]["status"] == "failed" and "dtu" not in rows["bad"]
    row = rows["copy"]
    assert row["status"] == "ok" and row["alignment"] == "cameras", row
    rep_path = table / "reports" / "scan1" / "copy.json"
    rep = load(rep_path)
    assert rep["schema"] == "sfmeval.dtu/1" and rep["scan"] == 1 and rep["mode"] == "pcd"
    assert row["dtu"] == {"scan": 1, "mean_accuracy": rep["mean_accuracy"],
                          "mean_completeness": rep["mean_completeness"],
                          "overall": rep["overall"]}
    files = table / "reports" / "scan1" / "copy"
    for f in ("recon_in_scan_frame.ply", "alignment.json", "vis_001_d2s.ply",
              "vis_001_s2d.ply"):
        assert (files / f).is_file(), f
    assert load(files / "alignment.json")["method"] == "cameras"

    # The runner's report is `sfmeval dtu` on the points it wrote, byte for byte, error
    # clouds included.
    recon = files / "recon_in_scan_frame.ply"
    vis = tmp_path / "cli-vis"
    p = subprocess.run([sfmeval_cli, "dtu", "--dataset", str(scan), "--scan", "1", "--recon",
                        str(recon), "--json", "--vis-out", str(vis)],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert p.stdout.encode() == rep_path.read_bytes()
    for f in ("vis_001_d2s.ply", "vis_001_s2d.ply"):
        assert (vis / f).read_bytes() == (files / f).read_bytes(), f
    # ... and close to the demo's points brought into the scan by `sfmeval align --align
    # cameras` (dtu_scene's sparse.ply): the same alignment, there before the scaling to mm.
    p = subprocess.run([sfmeval_cli, "dtu", "--dataset", str(scan), "--scan", "1", "--recon",
                        str(scene["sparse"]), "--json"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    ref = json.loads(p.stdout)
    assert rep["counts"]["points"] == ref["counts"]["points"]
    for k in ("mean_accuracy", "mean_completeness", "overall"):
        assert rep[k] == pytest.approx(ref[k], rel=1e-4), k
    assert 0 < rep["overall"] < 10.0

    # The DTU columns in the tables, Table I's cell the overall.
    head = (table / "runs.csv").read_text().splitlines()[0]
    assert "DTU accuracy (mm),DTU completeness (mm),DTU overall (mm)" in head
    t1 = (table / "table1.md").read_text()
    assert f"{rep['overall']:.3f} mm DTU overall ({rep['counts']['points']})" in t1

    # The same batch on Slurm: its collect gives the same Table I and report.
    slurm = tmp_path / "slurm"
    run_cli(runner_bin, "run", *grid, "--out", slurm, *SLURM, env={"SLURM_CONF": cluster.conf})
    cluster.wait_idle(240)
    for f in ("table1.md", "table1.csv"):
        assert (slurm / "table" / f).read_bytes() == (table / f).read_bytes(), f
    theirs = slurm / "table" / "reports" / "scan1"
    mine = load(rep_path)
    other = load(theirs / "copy.json")
    # the report names the PLY it measured, each in its own table folder
    assert other["reconstruction"] == str(theirs / "copy" / "recon_in_scan_frame.ply")
    assert {**other, "reconstruction": mine["reconstruction"]} == mine
    for f in ("recon_in_scan_frame.ply", "alignment.json", "vis_001_d2s.ply",
              "vis_001_s2d.ply"):
        assert (theirs / "copy" / f).read_bytes() == (files / f).read_bytes(), f
