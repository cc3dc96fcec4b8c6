"""`sfmeval table`: Table I and the wide table of evaluation reports, checked against the reports'
own numbers and against an independent Python writer of the runner's Table I format."""
import csv
import io
import json
import subprocess
from pathlib import Path

import jsonschema

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "data" / "demo"
MODELS = ROOT / "tests" / "fixtures" / "models"


def evaluate(sfmeval_bin, recon, report, *extra):
    report.parent.mkdir(parents=True, exist_ok=True)
    cmd = [sfmeval_bin, "eval", "--quiet", "--gt", str(DEMO / "ground_truth.glb"),
           "--gt-cameras", str(DEMO / "cameras.json"), "--recon", str(recon),
           "--report", str(report), *map(str, extra)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return json.loads(report.read_text())


def table(sfmeval_bin, *args):
    p = subprocess.run([sfmeval_bin, "table", *map(str, args)], capture_output=True, text=True)
    return p


def python_table1(dataset, rows, caption):
    """Table I in the runner's format, written independently: rows are (pipeline, mean, points,
    status, reason), in column order."""
    head = "| dataset |" + "".join(f" {p} |" for p, *_ in rows) + "\n|---|" + "---:|" * len(rows) + "\n"
    cells = []
    for _, mean, points, status, reason in rows:
        if mean is not None:
            cells.append(f"{mean:.6f} ({points})")
        else:
            why = reason.replace("|", " ").replace("\n", " ")
            cells.append(why if why.startswith(status) else f"{status}: {why}")
    body = f"| {dataset} |" + "".join(f" {c} |" for c in cells) + "\n"
    return ("# Table I: mean distance to the ground truth (m) and number of points\n\nEach cell: "
            f"mean reconstruction → ground-truth distance in metres (after {caption}), and in "
            "parentheses the number of points; failed runs show why.\n\n" + head + body)


def test_table_of_reports_equals_their_numbers(sfmeval_bin, tmp_path):
    # two reconstructions of the demo (a COLMAP model and its PLY) and a failed run
    auto = evaluate(sfmeval_bin, DEMO / "sparse", tmp_path / "colmap" / "report.json")
    mine = evaluate(sfmeval_bin, DEMO / "sparse.ply", tmp_path / "mine.json", "--align", "auto")
    p = table(sfmeval_bin, tmp_path / "colmap" / "report.json", f"zeta={tmp_path / 'mine.json'}",
              "--failed", "theia=failed: no model | written", "--dataset", "statue",
              "--out", tmp_path / "tables")
    assert p.returncode == 0, p.stderr
    rows = [("colmap", auto["accuracy"]["mean"], auto["inputs"]["reconstruction"]["points"], "ok", ""),
            ("theia", None, 0, "failed", "failed: no model | written"),
            ("zeta", mine["accuracy"]["mean"], mine["inputs"]["reconstruction"]["points"], "ok", "")]
    want = python_table1("statue", rows, "`auto` alignment")
    assert p.stdout == want, p.stdout
    assert (tmp_path / "tables" / "table1.md").read_text() == want
    # the CSV gives the numbers in full, as Python's repr reads them back
    recs = list(csv.reader(io.StringIO((tmp_path / "tables" / "table1.csv").read_text())))
    assert recs[0][:4] == ["dataset", "colmap.mean_m", "colmap.points", "colmap.status"]
    assert float(recs[1][1]) == auto["accuracy"]["mean"] and recs[1][3] == "ok"
    assert recs[1][4:7] == ["", "", "failed"]
    # the wide table carries each row's F-scores and camera errors from its report
    summary = json.loads((tmp_path / "tables" / "summary.json").read_text())
    assert summary["pipelines"] == ["colmap", "theia", "zeta"]
    colmap = next(r for r in summary["rows"] if r["pipeline"] == "colmap")
    assert [t["f_score"] for t in colmap["thresholds"]] == [t["f_score"] for t in auto["thresholds"]]
    assert colmap["rotation_median_deg"] == auto["cameras"]["rotation_error_deg"]["median"]
    assert colmap["alignment"] == "auto"


def test_the_caption_names_the_alignment_used(sfmeval_bin, tmp_path):
    t = tmp_path / "t.txt"
    t.write_text("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    evaluate(sfmeval_bin, DEMO / "sparse", tmp_path / "a" / "report.json", "--align", "given", "--transform", t)
    given = table(sfmeval_bin, tmp_path / "a" / "report.json")
    assert given.returncode == 0, given.stderr
    assert "(after `given` alignment)" in given.stdout
    # the dataset name defaults to the ground truth's file stem
    assert "\n| ground_truth |" in given.stdout
    evaluate(sfmeval_bin, DEMO / "sparse", tmp_path / "b" / "report.json")
    mixed = table(sfmeval_bin, tmp_path / "a" / "report.json", tmp_path / "b" / "report.json")
    assert "(after each run's own alignment: `auto` alignment or `given` alignment)" in mixed.stdout


def test_bad_table_arguments_say_what_is_wrong(sfmeval_bin, tmp_path):
    p = table(sfmeval_bin, tmp_path / "missing" / "report.json")
    assert p.returncode != 0 and "missing" in p.stderr and "panicked" not in p.stderr
    bad = tmp_path / "x" / "report.json"
    bad.parent.mkdir()
    bad.write_text('{"schema": "something else"}')
    p = table(sfmeval_bin, bad)
    assert p.returncode != 0 and "sfmeval.report/3" in p.stderr and str(bad) in p.stderr, p.stderr
    evaluate(sfmeval_bin, DEMO / "sparse.ply", tmp_path / "c" / "report.json")
    p = table(sfmeval_bin, tmp_path / "c" / "report.json", f"c={tmp_path / 'c' / 'report.json'}")
    assert p.returncode != 0 and "given twice" in p.stderr
    p = table(sfmeval_bin, tmp_path / "c" / "report.json", "--failed", "nobody")
    assert p.returncode != 0 and "PIPELINE=REASON" in p.stderr


def test_reports_validate_against_the_schema(sfmeval_bin, tmp_path):
    schema = json.loads((ROOT / "schemas" / "report.schema.json").read_text())
    rep = evaluate(sfmeval_bin, DEMO / "sparse", tmp_path / "r.json")
    jsonschema.validate(rep, schema)
    assert rep["schema"] == "sfmeval.report/3"
    assert all({"code", "level", "message"} <= set(n) for n in rep["notes"])
