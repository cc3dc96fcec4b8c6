"""The runner's pose-protocol columns and ETH3D scenes.

Poses: a dataset made from data/demo (its ground truth, its ground-truth cameras.json and
images/ placeholders named as its images), run with a custom pipeline that "reconstructs" by
copying data/demo's real COLMAP model and one that fails. The report writes beside the run's
report the three `sfmeval.poses/1` reports, each `sfmeval poses --protocol P --json` on the
run's model byte for byte, and the tables' pose columns (runs.csv, summary.json, and
`sfmeval table` on the report) hold their numbers.

ETH3D: the small scene in ETH3D's layout of tests/fixtures/eth3d (the demo's statue as two
laser scans, in metres; tests/python/eth3d_scene.py) with images/ and the ground-truth cameras
(data/demo's cameras.json: the scene's frame is the demo's), run with the same pipelines. Each
run is aligned by its cameras and evaluated with ETH3D's protocol; its report equals `sfmeval
eth3d` on the points the runner wrote in the scene's frame, byte for byte, coloured clouds
included, and is close to `sfmeval eth3d` on the fixture's sparse.ply (the same points aligned
by `sfmeval align --align cameras`); its numbers are columns of the tables.
No rendering and no SfM tool: a few seconds."""

import csv
import io
import json
import os
import shutil
import subprocess

import pytest

from runner_testlib import REPO, load, run_cli

DEMO = os.path.join(REPO, "data", "demo")
ETH3D = os.path.join(REPO, "tests", "fixtures", "eth3d")
PIPES = ["--pipelines", "copy;bad",
         "--custom", "copy=cp %s {out}/" % " ".join(
             os.path.join(DEMO, "sparse", f) for f in ("cameras.txt", "images.txt",
                                                       "points3D.txt")),
         "--custom", "bad=no-such-sfm-tool {images} {out}"]
PROTOCOLS = ("colmap", "imc", "co3d")


@pytest.fixture(scope="module")
def sfmeval_cli():
    b = os.environ.get("SFMEVAL_BIN") or os.path.join(REPO, "target", "release", "sfmeval")
    assert os.path.isfile(b), b
    return b


def add_images_and_cameras(d):
    """images/ (placeholders named as the demo's images) and the demo's cameras.json."""
    cams = load(os.path.join(DEMO, "cameras.json"))
    (d / "images").mkdir(parents=True)
    for im in cams["images"]:
        (d / "images" / im["name"]).write_bytes(b"\xff\xd8 placeholder")
    shutil.copy(os.path.join(DEMO, "cameras.json"), d / "cameras.json")
    return len(cams["images"])


def csv_rows(path):
    return {r["pipeline"]: r for r in csv.DictReader(io.StringIO(path.read_text()))}


def pose_columns(report):
    """The wide table's pose columns of one protocol's report: header → value."""
    r = report["result"]
    if r["protocol"] == "colmap":
        return {f"COLMAP AUC@{t:g}° (%)": v for t, v in zip(r["thresholds_deg"], r["auc_percent"])}
    if r["protocol"] == "imc":
        return {"IMC mAA@10°": r["maa_10"]}
    cols = {}
    for what in ("rra", "rta"):
        for t, v in zip(r["thresholds_deg"], r[f"{what}_percent"]):
            cols[f"CO3D {what.upper()}@{t:g}° (%)"] = v
    cols[f"CO3D AUC@{r['auc_max_deg']:g}° (%)"] = r["auc_percent"]
    return cols


def check_poses(sfmeval_cli, ds, runs, table, name):
    """The run's pose reports are `sfmeval poses --json` on its model; the columns hold them."""
    rows = {r["pipeline"]: r for r in load(table / "summary.json")["rows"]}
    assert "poses" not in rows["bad"]
    wide = csv_rows(table / "runs.csv")
    assert all(wide["bad"][h] == "" for p in PROTOCOLS for h in
               pose_columns(load(table / "reports" / name / f"copy.poses-{p}.json")))
    for p in PROTOCOLS:
        path = table / "reports" / name / f"copy.poses-{p}.json"
        cli = subprocess.run([sfmeval_cli, "poses", "--gt-cameras", str(ds / "cameras.json"),
                              "--recon", str(runs / name / "copy" / "model"), "--protocol", p,
                              "--json"], capture_output=True, text=True)
        assert cli.returncode == 0, cli.stderr
        assert cli.stdout.encode() == path.read_bytes(), p
        report = json.loads(cli.stdout)
        assert report["matched"] > 10 and report["schema"] == "sfmeval.poses/1"
        result = {k: v for k, v in report["result"].items() if k != "protocol"}
        assert rows["copy"]["poses"][p] == result, p
        for header, value in pose_columns(report).items():
            assert float(wide["copy"][header]) == value, (header, wide["copy"][header], value)
    # the headline numbers say the demo's COLMAP cameras are good
    assert rows["copy"]["poses"]["colmap"]["auc_percent"][-1] > 50
    assert rows["copy"]["poses"]["co3d"]["rra_percent"][-1] == 100


def test_pose_protocols_are_columns_of_the_tables(runner_bin, sfmeval_cli, tmp_path):
    ds = tmp_path / "data" / "statue"
    add_images_and_cameras(ds)
    shutil.copy(os.path.join(DEMO, "ground_truth.glb"), ds / "ground_truth.glb")
    runs, table = tmp_path / "runs", tmp_path / "table"
    run_cli(runner_bin, "run", "--datasets", ds, *PIPES, "--out", runs)
    run_cli(runner_bin, "report", runs, "--out", table)
    check_poses(sfmeval_cli, ds, runs, table, "statue")
    head = (table / "runs.csv").read_text().splitlines()[0].split(",")
    # after the camera columns, before the resources
    assert head.index("COLMAP AUC@0.5° (%)") == head.index("centre max (% radius)") + 1
    assert head.index("CO3D AUC@30° (%)") + 1 == head.index("wall (s)")
    assert "| COLMAP AUC@0.5° (%) |" in (table / "table.md").read_text()

    # `sfmeval table` on the report (its pose reports beside it) shows the same columns
    out = tmp_path / "cli-table"
    rep = table / "reports" / "statue" / "copy.json"
    p = subprocess.run([sfmeval_cli, "table", f"copy={rep}", "--dataset", "statue", "--out",
                        str(out), "--format", "wide-csv"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    mine = csv_rows(table / "runs.csv")["copy"]
    theirs = csv_rows(out / "runs.csv")["copy"]
    for header in mine:
        if "AUC" in header or "mAA" in header or "RRA" in header or "RTA" in header:
            assert theirs[header] == mine[header], header
    # a pose report that is not one is named
    (table / "reports" / "statue" / "copy.poses-imc.json").write_text("{}")
    p = subprocess.run([sfmeval_cli, "table", f"copy={rep}"], capture_output=True, text=True)
    assert p.returncode == 1 and "copy.poses-imc.json" in p.stderr, p.stderr


def test_eth3d_scene(runner_bin, sfmeval_cli, tmp_path):
    scene = tmp_path / "data" / "terrace"
    shutil.copytree(os.path.join(ETH3D, "dslr_scan_eval"), scene / "dslr_scan_eval")
    add_images_and_cameras(scene)
    runs, table = tmp_path / "runs", tmp_path / "table"
    run_cli(runner_bin, "run", "--datasets", scene, *PIPES, "--out", runs)
    run_cli(runner_bin, "report", runs, "--out", table)

    rows = {r["pipeline"]: r for r in load(table / "summary.json")["rows"]}
    assert rows["bad"]["status"] == "failed" and "eth3d" not in rows["bad"]
    row = rows["copy"]
    assert row["status"] == "ok" and row["alignment"] == "cameras", row
    rep_path = table / "reports" / "terrace" / "copy.json"
    rep = load(rep_path)
    assert rep["schema"] == "sfmeval.eth3d/1"
    assert row["eth3d"]["tolerances"] == [
        {k: t[k] for k in ("tolerance", "accuracy", "completeness", "f1")}
        for t in rep["tolerances"]]
    files = table / "reports" / "terrace" / "copy"
    assert load(files / "alignment.json")["method"] == "cameras"

    # The runner's report is `sfmeval eth3d` on the points it wrote, byte for byte, coloured
    # clouds included.
    mlp = scene / "dslr_scan_eval" / "scan_alignment.mlp"
    recon = files / "recon_in_scene_frame.ply"
    cli_out = tmp_path / "cli"
    p = subprocess.run([sfmeval_cli, "eth3d", "--gt", str(mlp), "--recon", str(recon), "--json",
                        "--out", str(cli_out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert p.stdout.encode() == rep_path.read_bytes()
    clouds = sorted(f.name for f in cli_out.iterdir() if f.suffix == ".ply")
    assert len(clouds) == 12
    for f in clouds:
        assert (cli_out / f).read_bytes() == (files / f).read_bytes(), f
    # ... and close to the fixture's sparse.ply: the demo's points aligned by `sfmeval align
    # --align cameras`, the same alignment
    p = subprocess.run([sfmeval_cli, "eth3d", "--gt", str(mlp), "--recon",
                        os.path.join(ETH3D, "sparse.ply"), "--json"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    ref = json.loads(p.stdout)
    assert rep["reconstruction_points"] == ref["reconstruction_points"]
    for mine, theirs in zip(rep["tolerances"], ref["tolerances"]):
        for k in ("accuracy", "completeness", "f1"):
            assert mine[k] == pytest.approx(theirs[k], abs=0.01), (mine["tolerance"], k)
    assert rep["tolerances"][-1]["f1"] > 0.1

    # ETH3D's columns in the tables, Table I's cell the F1 at 2 cm; the pose protocols too
    wide = csv_rows(table / "runs.csv")
    for k, t in enumerate(rep["tolerances"]):
        for field, what in (("accuracy", "accuracy"), ("completeness", "completeness"),
                            ("f1", "F1")):
            header = f"ETH3D {what}@{t['tolerance']:g}m"
            assert float(wide["copy"][header]) == t[field], header
            assert wide["bad"][header] == ""
    f1 = next(t["f1"] for t in rep["tolerances"] if t["tolerance"] == 0.02)
    t1 = (table / "table1.md").read_text()
    assert f"{f1:.3f} ETH3D F1 at 0.02 m ({rep['reconstruction_points']})" in t1
    assert "ETH3D's F1 score at 0.02 m" in t1
    check_poses(sfmeval_cli, scene, runs, table, "terrace")


def test_eth3d_scene_without_cameras_is_named(runner_bin, tmp_path):
    scene = tmp_path / "data" / "terrace"
    shutil.copytree(os.path.join(ETH3D, "dslr_scan_eval"), scene / "dslr_scan_eval")
    add_images_and_cameras(scene)
    (scene / "cameras.json").unlink()
    runs, table = tmp_path / "runs", tmp_path / "table"
    run_cli(runner_bin, "run", "--datasets", scene, "--pipelines", "copy", "--custom", PIPES[3],
            "--out", runs)
    run_cli(runner_bin, "report", runs, "--out", table)
    row = load(table / "summary.json")["rows"][0]
    assert row["status"] == "evaluation failed"
    assert "cameras.json" in row["reason"] and str(scene) in row["reason"], row["reason"]
