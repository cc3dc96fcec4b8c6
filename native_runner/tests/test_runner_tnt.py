"""`sfmeval-runner report` on a Tanks and Temples scene: the batch's runs of the small dataset,
with that dataset laid out as the benchmark ships a scene (images/ plus <scene>.ply, .json,
_trans.txt, _COLMAP_SfM.log; no cameras.json), are evaluated with the benchmark's protocol: each
run's .log trajectory is written, the numbers equal `sfmeval tnt` on the same files, and the
tables get the scene's row with its F at τ."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from runner_testlib import REPO, load, run_cli

sys.path.insert(0, os.path.join(REPO, "tests", "python"))
import tnt_scene  # noqa: E402


@pytest.fixture(scope="module")
def scene_report(runner_bin, batch, tmp_path_factory):
    root = tmp_path_factory.mktemp("tnt-runner")
    name = batch["name"]
    scene_dir = root / name
    _, _, tau, names, _ = tnt_scene.write_scene(
        scene_dir, name, os.path.join(batch["dataset"], "ground_truth.glb"),
        os.path.join(batch["dataset"], "cameras.json"), 100_000)
    os.symlink(os.path.join(batch["dataset"], "images"), scene_dir / "images")
    table = root / "table"
    proc = run_cli(runner_bin, "report", batch["runs"], "--datasets", scene_dir, "--out", table,
                   "--tau", tau)
    return {"dir": scene_dir, "table": table, "tau": tau, "names": names, "stderr": proc.stderr}


def test_runs_are_evaluated_with_the_protocol(scene_report, batch):
    table = scene_report["table"]
    rows = {r["pipeline"]: r for r in load(table / "summary.json")["rows"]} \
        if (table / "summary.json").exists() else None
    assert rows, scene_report["stderr"]
    ok = [p for p, r in rows.items() if r["status"] == "ok"]
    assert "pycolmap" in ok and "colmap" in ok, rows
    for p in ok:
        rep = load(table / "reports" / batch["name"] / f"{p}.json")
        assert rep["schema"] == "sfmeval.tanksandtemples/2"
        assert rep["protocol"]["tau"] == scene_report["tau"]
        assert rep["registration"]["mode"] == "protocol"
        assert rep["registration"]["trajectory_alignment"]["fitness"] > 0.9, p
        files = table / "reports" / batch["name"] / p
        for f in ["trajectory.log", f"{batch['name']}.precision.ply", f"{batch['name']}.recall.ply",
                  f"{batch['name']}.prf_tau_plotstr.txt"]:
            assert (files / f).is_file(), (p, f)
        log = (files / "trajectory.log").read_text().splitlines()
        assert len(log) == 5 * len(scene_report["names"]) == 5 * 36
        row = rows[p]
        assert row["thresholds"][0]["f_score"] == rep["f_score"]
        assert 0.0 < rep["precision"]["value"] <= 1.0 and rep["recall"]["value"] > 0.0
    # Runs that did not end ok keep their rows.
    assert rows["bad"]["status"] == "failed" and rows["slow"]["status"] == "timeout"
    md = (table / "table1.md").read_text()
    assert "pycolmap" in md


def test_runner_equals_the_cli(scene_report, batch, sfmeval_cli):
    """The runner's report is `sfmeval tnt` on the run's model and its written trajectory."""
    p = "pycolmap"
    files = scene_report["table"] / "reports" / batch["name"] / p
    out = scene_report["table"].parent / "cli"
    proc = subprocess.run([sfmeval_cli, "tnt", "--scene", str(scene_report["dir"]),
                           "--recon", str(batch["runs"] / batch["name"] / p / "model"),
                           "--trajectory", str(files / "trajectory.log"), "--tau", str(scene_report["tau"]),
                           "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    cli = load(out / "report.json")
    runner = load(scene_report["table"] / "reports" / batch["name"] / f"{p}.json")
    for key in ["precision", "recall", "registration", "curves"]:
        assert cli[key] == runner[key], key
    assert cli["f_score"] == runner["f_score"]
    assert np.loadtxt(out / f"{batch['name']}.prf_tau_plotstr.txt").tolist() == \
        np.loadtxt(files / f"{batch['name']}.prf_tau_plotstr.txt").tolist()


@pytest.fixture(scope="module")
def sfmeval_cli():
    b = os.environ.get("SFMEVAL_BIN") or os.path.join(REPO, "target", "release", "sfmeval")
    if not os.path.isfile(b):
        subprocess.run([os.path.join(REPO, "scripts", "build-release.sh")], cwd=REPO, check=True)
    return b
