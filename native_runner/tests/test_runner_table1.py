"""`sfmeval-runner table1 --quick` end to end, made cheap with generator overrides: two presets
(statue, vehicle) at 320x180, 24 views on two rings, 4 spp; openmvg only; 100k completeness
samples. Measured on 2 vCPUs at load 2-3: 10-21 s for
the first call (rendering 2 x 24 frames, two openmvg runs, report), 0.2 s for the second."""

import csv
import json
import os
import subprocess

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))

PRESETS = ["statue", "vehicle"]
PIPES = ["openmvg"]
# --set comes after --quick's own overrides, so these win.
SETS = ["camera.resolution=[320, 180]", "render.samples=4",
        "views.orbits=[{elevation_deg=20.0, count=12}, "
        "{elevation_deg=45.0, count=12, azimuth_offset_deg=15.0}]"]


def table1_cmd(runner_bin, out):
    cmd = [os.path.abspath(runner_bin), "table1", "--quick", "--presets", *PRESETS,
           "--pipelines", *PIPES, "--samples", "100000", "--out", str(out)]
    for s in SETS:
        cmd += ["--set", s]
    return cmd


def run(cmd, timeout):
    proc = subprocess.run(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True, timeout=timeout)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return proc


@pytest.fixture(scope="module")
def table1(runner_bin, tmp_path_factory):
    pytest.importorskip("bpy")
    pytest.importorskip("openmvg_rs")
    out = tmp_path_factory.mktemp("table1")
    return out, run(table1_cmd(runner_bin, out), 900)


def md_rows(path):
    lines = [l for l in open(path).read().splitlines() if l.startswith("|")]
    cells = [[c.strip() for c in l.strip().strip("|").split("|")] for l in lines]
    header = cells[0]
    return header, [r for r in cells[1:] if not set(r[0]) <= {"-", ":"}]


def test_table_has_a_row_per_preset_and_a_column_per_pipeline(table1):
    out, _ = table1
    names = ["%s-quick" % p for p in PRESETS]
    header, rows = md_rows(out / "table" / "table1.md")
    assert header == ["dataset"] + PIPES
    assert sorted(r[0] for r in rows) == names
    with open(out / "table" / "table1.csv", newline="") as f:
        csv_rows = list(csv.DictReader(f))
    assert sorted(r["dataset"] for r in csv_rows) == names
    summary = json.load(open(out / "table" / "summary.json"))
    for name in names:
        ds = json.load(open(out / "datasets" / name / "dataset.json"))
        assert ds["images"] == 24 and ds["settings"]["camera"]["resolution"] == [320, 180]
        for p in PIPES:
            rec = json.load(open(out / "runs" / name / p / "run.json"))
            row = next(r for r in csv_rows if r["dataset"] == name)
            md = next(r for r in rows if r[0] == name)[1 + PIPES.index(p)]
            if rec["status"] == "ok":
                rep = json.load(open(out / "table" / "reports" / name / (p + ".json")))
                mean = rep["accuracy"]["mean"]
                assert float(row[p + ".mean_m"]) == mean
                assert md == "%.6f (%d)" % (mean, rep["inputs"]["reconstruction"]["points"])
            else:  # a failure is shown with its reason, not dropped
                assert md.startswith("failed"), md
        assert any(r["dataset"] == name for r in summary["rows"])
    # the numbers were checked for at least one run (both registered here: 20 and 86 points)
    assert any(c != "" and not c.startswith("failed") for r in rows for c in r[1:])


def test_table1_json_has_the_timings(table1):
    out, proc = table1
    doc = json.load(open(out / "table1.json"))
    assert doc["quick"] is True and doc["presets"] == PRESETS and doc["pipelines"] == PIPES
    assert sum(doc["runs_executed"].values()) == len(PRESETS) * len(PIPES)
    assert doc["runs_reused"] == 0
    assert doc["executor"] == "local" and doc["tasks_without_result"] == []
    t = doc["timing"]
    assert sorted(t["render_seconds_per_view"]) == sorted(t["render_seconds"])
    assert all(0 < v < t["render_seconds"][k] for k, v in t["render_seconds_per_view"].items())
    assert sorted(t["render_seconds"]) == ["%s-quick" % p for p in PRESETS]
    assert all(v > 0 for v in t["render_seconds"].values())
    for k in ["datasets_seconds", "runs_seconds", "report_seconds", "total_seconds"]:
        assert t[k] > 0, k
    assert t["total_seconds"] >= t["datasets_seconds"] + t["runs_seconds"] + t["report_seconds"]
    assert t["datasets_seconds"] >= sum(t["render_seconds"].values())
    assert "table1: rendering" in proc.stderr


def test_second_call_reuses_datasets_and_runs(table1, runner_bin):
    out, _ = table1
    before = (out / "table" / "table1.md").read_text()
    runs = {p: open(out / "runs" / ("%s-quick" % p) / "openmvg" / "run.json").read()
            for p in PRESETS}
    proc = run(table1_cmd(runner_bin, out), 300)
    assert "table1: rendering" not in proc.stderr
    assert proc.stderr.count("table1: reusing") == len(PRESETS)
    doc = json.load(open(out / "table1.json"))
    assert doc["runs_executed"] == {} and doc["runs_reused"] == len(PRESETS) * len(PIPES)
    assert doc["timing"]["render_seconds"] == {} == doc["timing"]["render_seconds_per_view"]
    for p in PRESETS:  # the runs were not redone
        assert open(out / "runs" / ("%s-quick" % p) / "openmvg" / "run.json").read() == runs[p]
    assert (out / "table" / "table1.md").read_text() == before
