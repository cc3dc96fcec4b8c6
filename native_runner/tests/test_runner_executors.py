"""One batch plan, two executors: the same `run` batch (two tiny datasets made of data/demo:
its ground truth, its cameras and placeholder images, × a custom pipeline that "reconstructs"
by copying data/demo's sparse.ply and one that fails) run by the local executor and by the
real one-node Slurm that slurm_testlib starts. Their summaries (`batch.json`, one type) have
the same keys and the same values but for where they ran and the measured times; the Slurm
batch's Table I and reports (its collect evaluates) equal a local `report` of the local runs
byte for byte.
No rendering and no SfM tool: ~28 s here (2 loaded cores), half of it the cluster's start."""

import json
import os
import shutil

import pytest

import slurm_testlib
from runner_testlib import REPO, load, run_cli

DEMO = os.path.join(REPO, "data", "demo")
PIPES = ["--pipelines", "copy;bad",
         "--custom", "copy=cp %s {out}/" % os.path.join(DEMO, "sparse.ply"),
         "--custom", "bad=no-such-sfm-tool {images} {out}"]
SLURM = ["--executor", "slurm", "--stage", "run:cpus=1,mem=500M,time=10",
         "--stage", "collect:cpus=1,mem=1G"]
# where and when it ran: the rest of a summary is the batch's
MEASURED = ("executor", "timing")


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = slurm_testlib.start(str(tmp_path_factory.mktemp("slurm-cluster")))
    yield c
    c.stop()


def demo_dataset(root, name):
    d = root / name
    (d / "images").mkdir(parents=True)
    for f in ("cameras.json", "ground_truth.glb"):
        shutil.copy(os.path.join(DEMO, f), d / f)
    for im in json.load(open(os.path.join(DEMO, "cameras.json")))["images"][:3]:
        (d / "images" / im["name"]).write_bytes(b"\xff\xd8 placeholder")
    return d


def test_one_run_plan_through_both_executors_gives_the_same_summary(runner_bin, cluster,
                                                                    tmp_path):
    data = tmp_path / "data"
    grid = ["--datasets", demo_dataset(data, "demo-b"), demo_dataset(data, "demo-a")] + PIPES
    local = tmp_path / "local"
    run_cli(runner_bin, "run", *grid, "--out", local)
    slurm = tmp_path / "slurm"
    run_cli(runner_bin, "run", *grid, "--out", slurm, *SLURM, env={"SLURM_CONF": cluster.conf})
    cluster.wait_idle(240)

    mine, theirs = load(local / "batch.json"), load(slurm / "batch.json")
    assert (mine["executor"], theirs["executor"]) == ("local", "slurm")
    assert sorted(mine) == sorted(theirs) and sorted(mine["timing"]) == sorted(theirs["timing"])
    for k in mine:
        if k not in MEASURED:
            assert mine[k] == theirs[k], (k, mine[k], theirs[k])
    # the batch itself, as planned: both datasets in the order given, both pipelines run
    assert mine["datasets"] == [str(data / "demo-b"), str(data / "demo-a")]
    assert mine["pipelines"] == ["copy", "bad"]
    assert mine["runs_executed"] == {"failed": 2, "ok": 2} and mine["runs_reused"] == 0
    assert mine["tasks_without_result"] == []
    # a local run does not evaluate; the Slurm batch's collect does
    assert mine["timing"]["report_seconds"] is None
    assert theirs["timing"]["report_seconds"] > 0
    for t in (mine, theirs):
        assert t["timing"]["total_seconds"] >= t["timing"]["runs_seconds"] >= 0

    # The same runs: the Slurm tables equal a local `report` of the local runs.
    # (table1.md, table1.csv and the reports; table.md and runs.csv hold the measured times)
    table = tmp_path / "local-table"
    run_cli(runner_bin, "report", local, "--out", table)
    for f in ("table1.md", "table1.csv"):
        assert (slurm / "table" / f).read_bytes() == (table / f).read_bytes(), f
    for ds in ("demo-a", "demo-b"):
        rel = os.path.join("reports", ds, "copy.json")
        assert (slurm / "table" / rel).read_bytes() == (table / rel).read_bytes(), rel
    for ds in ("demo-a", "demo-b"):
        assert load(local / ds / "copy" / "run.json")["status"] == "ok"
        assert load(slurm / "runs" / ds / "copy" / "run.json")["status"] == "ok"
        assert load(slurm / "runs" / ds / "bad" / "run.json")["status"] == "failed"

    # Resumed locally, nothing is run again, and the summary says so.
    run_cli(runner_bin, "run", *grid, "--out", local, "--resume")
    again = load(local / "batch.json")
    assert again["runs_executed"] == {} and again["runs_reused"] == 4


# A tiny table1: one preset, 8 views at 160x90, 2 samples per pixel, in 2 render shards; the
# "pipeline" copies data/demo's sparse.ply (no SfM tool: the renders are what is compared).
TABLE1 = ["table1", "--quick", "--presets", "statue", "--render-shards", "2",
          "--pipelines", "copy", "--custom", PIPES[3], "--samples", "20000",
          "--set", "camera.resolution=[160, 90]", "--set", "render.samples=2",
          "--set", "views.orbits=[{elevation_deg=20.0, count=8}]"]
TABLE1_SLURM = ["--executor", "slurm", "--stage", "render:cpus=1,mem=1G",
                "--stage", "finalize:cpus=1,mem=1G", "--stage", "run:cpus=1,mem=500M",
                "--stage", "collect:cpus=1,mem=1G"]
NAME = "statue-quick"


def tree(root):
    """{relative path: bytes} of every file under root."""
    out = {}
    for d, _, names in os.walk(root):
        for n in names:
            p = os.path.join(d, n)
            out[os.path.relpath(p, root)] = open(p, "rb").read()
    return out


def test_render_shards_through_both_executors_give_the_same_dataset(runner_bin, cluster,
                                                                    tmp_path):
    """The local executor runs the plan's render tasks and finalize as the Slurm jobs do: with
    --render-shards 2 both make the same dataset byte for byte (the 8 images, cameras.json,
    dataset.json, ground_truth.glb and sparse_gt/'s COLMAP text model; timing.json holds the
    measured times and where each part ran) and a table1.json of the same keys."""
    pytest.importorskip("bpy")
    local = tmp_path / "local"
    p = run_cli(runner_bin, *TABLE1, "--out", local)
    # two render tasks and the finalize, each one generator call logged in datasets/NAME.log
    log = (local / "datasets" / (NAME + ".log")).read_text()
    assert [l.split("# ")[-1] for l in log.splitlines() if l.startswith("$ ")] == \
        ["generate %s --views 0/2" % NAME, "generate %s --views 1/2" % NAME,
         "generate %s --finalize" % NAME], log[-3000:]
    assert "in 2 shard(s)" in p.stderr, p.stderr
    slurm = tmp_path / "slurm"
    p = run_cli(runner_bin, *TABLE1, "--out", slurm, *TABLE1_SLURM,
                env={"SLURM_CONF": cluster.conf})
    assert "submitted render 2/2, finalize 1/1, run 1/1, collect 1/1" in p.stderr, p.stderr
    cluster.wait_idle(300)

    a, b = tree(local / "datasets" / NAME), tree(slurm / "datasets" / NAME)
    assert sorted(a) == sorted(b)
    images = [f for f in a if f.startswith("images" + os.sep)]
    assert len(images) == 8
    gt = [os.path.join("sparse_gt", f) for f in ("cameras.txt", "images.txt", "points3D.txt")]
    assert sorted(f for f in a if f not in images) == \
        ["cameras.json", "dataset.json", "ground_truth.glb"] + gt + ["timing.json"], sorted(a)
    assert [f for f in sorted(a) if a[f] != b[f]] == ["timing.json"]
    for t in (local, slurm):
        parts = load(t / "datasets" / NAME / "timing.json")["parts"]
        assert [x["views"] for x in parts] == ["shard 0 2", "shard 1 2"], parts

    mine, theirs = load(local / "table1.json"), load(slurm / "table1.json")
    assert (mine["executor"], theirs["executor"]) == ("local", "slurm")
    assert sorted(mine) == sorted(theirs) and sorted(mine["timing"]) == sorted(theirs["timing"])
    for k in mine:
        if k not in MEASURED:
            assert mine[k] == theirs[k], (k, mine[k], theirs[k])
    assert mine["presets"] == ["statue"] and mine["pipelines"] == ["copy"]
    for t in (mine, theirs):
        assert t["timing"]["render_seconds"][NAME] > 0

    # A complete dataset is reused: the local command again renders nothing.
    p = run_cli(runner_bin, *TABLE1, "--out", local)
    assert "table1: reusing" in p.stderr and log == \
        (local / "datasets" / (NAME + ".log")).read_text()
    assert load(local / "table1.json")["timing"]["render_seconds"] == {}
