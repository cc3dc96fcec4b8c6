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
