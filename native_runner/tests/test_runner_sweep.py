"""`sfmeval-runner sweep` end to end, kept small for CI (45–125 s here): two values of the noise
factor on a 24-view 320x180 render of the statue (8 spp) with depth maps (--visibility),
pycolmap and a custom pipeline that always fails, 100k completeness samples. Checks the table
(including the visible-surface completeness and the track error), the charts and the page."""

import csv
import json
import math
import os
import subprocess
import xml.etree.ElementTree as ET

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))

VALUES = ["0", "8"]
PIPES = ["pycolmap", "broken"]
EXTRA_METRIC = "report.completeness.percentiles.p90"


def sweep_cmd(runner_bin, out, *extra):
    return [os.path.abspath(runner_bin), "sweep", "--factor", "noise=" + ",".join(VALUES),
            "--dataset-preset", "small",
            "--set", "render.samples=8", "--set", "camera.resolution=[320, 180]",
            "--set", "views.orbits=[{elevation_deg=25.0, count=24}]",
            "--pipelines", "pycolmap;broken", "--custom", "broken=false {out}",
            "--metric", EXTRA_METRIC + "=completeness p90 (m)",
            "--samples", "100000", "--timeout", "600", "--visibility", "--out", str(out)] + list(extra)


@pytest.fixture(scope="module")
def sweep(runner_bin, tmp_path_factory):
    pytest.importorskip("bpy")
    pytest.importorskip("pycolmap")
    out = tmp_path_factory.mktemp("sweep")
    # a relative --out (the generator runs in another folder: paths must not break)
    proc = subprocess.run(sweep_cmd(runner_bin, out.name), cwd=out.parent, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return out, proc


def rows_of(out):
    with open(os.path.join(out, "sweep.csv"), newline="") as f:
        return list(csv.DictReader(f))


def test_csv_has_a_row_per_value_and_pipeline(sweep):
    out, _ = sweep
    rows = rows_of(out)
    assert [(r["value"], r["pipeline"]) for r in rows] == [(v, p) for v in VALUES for p in PIPES]
    assert all(r["factor"] == "noise" and r["dataset"] == "noise-" + r["value"] for r in rows)
    cols = list(rows[0].keys())
    for needed in ("report.accuracy.mean", "report.accuracy.median", "report.thresholds[0].recall",
                   "report.thresholds[2].f_score", "run.registered_fraction",
                   "report.cameras.rotation_error_deg.median", "report.cameras.ate_rmse",
                   "run.wall_seconds", EXTRA_METRIC,
                   # --visibility: depth maps rendered, the visible-surface metrics plotted
                   "report.completeness_visible.visible_fraction",
                   "report.completeness_visible.thresholds[0].recall_visible",
                   "report.track_error.median"):
        assert needed in cols, cols
    metric_cols = cols[6:]
    for r in rows:
        if r["pipeline"] == "broken":
            assert r["status"] == "failed" and "exit status 1" in r["reason"]
            assert r["report.accuracy.mean"] == "" and r["report.thresholds[0].recall"] == ""
            continue
        assert r["status"] == "ok", r
        for c in metric_cols:
            assert r[c] != "", (r["value"], c)
            assert math.isfinite(float(r[c])), (r["value"], c, r[c])
        assert 0 < float(r["run.registered_fraction"]) <= 1
        assert 0 <= float(r["report.thresholds[0].recall"]) <= float(r["report.thresholds[2].recall"]) <= 1
        assert float(r["report.accuracy.mean"]) < 0.1  # metres, on a 1 m object
        # the statue's underside and hidden folds: most but not all of the surface is seen
        assert 0.5 < float(r["report.completeness_visible.visible_fraction"]) < 1
        assert float(r["report.completeness_visible.thresholds[0].recall_visible"]) >= \
            float(r["report.thresholds[0].recall"])


def test_variants_are_the_factor_values(sweep):
    out, _ = sweep
    doc = json.load(open(os.path.join(out, "sweep.json")))
    assert doc["factor"] == "noise" and doc["values"] == VALUES
    assert [v["overrides"] for v in doc["variants"]] == [["postprocess.noise_sigma=0.0"],
                                                          ["postprocess.noise_sigma=8.0"]]
    for v in VALUES:
        ds = json.load(open(os.path.join(out, "datasets", "noise-" + v, "dataset.json")))
        assert ds["settings"]["postprocess"]["noise_sigma"] == float(v)
        assert ds["images"] == 24 and ds["settings"]["camera"]["resolution"] == [320, 180]
    a = open(os.path.join(out, "datasets", "noise-0", "images", "0000.jpg"), "rb").read()
    b = open(os.path.join(out, "datasets", "noise-8", "images", "0000.jpg"), "rb").read()
    assert a != b


def test_charts_have_a_series_per_pipeline_and_failure_markers(sweep):
    out, _ = sweep
    doc = json.load(open(os.path.join(out, "sweep.json")))
    charts = [m["chart"] for m in doc["metrics"]]
    assert "report_accuracy_mean.svg" in charts and "run_wall_seconds.svg" in charts
    assert "report_completeness_percentiles_p90.svg" in charts
    ns = {"s": "http://www.w3.org/2000/svg"}
    for name in charts:
        root = ET.parse(os.path.join(out, "charts", name)).getroot()
        series = root.findall("s:g[@class='series']", ns)
        assert [g.get("data-series") for g in series] == PIPES, name
        py, broken = series
        # pycolmap: a line through both values, no failure marker
        assert len(py.findall("s:polyline", ns)) == 1, name
        assert len(py.findall("s:circle[@class='pt']", ns)) == 2, name
        assert not py.findall("s:g[@class='fail']", ns)
        # broken: no line, one red × per value, whose tooltip says why
        assert not broken.findall("s:polyline", ns)
        fails = broken.findall("s:g[@class='fail']", ns)
        assert len(fails) == 2, name
        assert all("exit status 1" in f.find("s:title", ns).text for f in fails)


def test_html_is_self_contained(sweep):
    out, _ = sweep
    html = open(os.path.join(out, "sweep.html")).read()
    n_metrics = len(json.load(open(os.path.join(out, "sweep.json")))["metrics"])
    assert html.count("<svg") == n_metrics
    assert html.count('<g class="series" data-series="pycolmap">') == n_metrics
    assert html.count('<g class="series" data-series="broken">') == n_metrics
    assert html.count('class="fail" data-series="broken"') == 2 * n_metrics
    for bad in ("http://", "https://", "<script", "src=", "<link", "@import", "url("):
        assert bad not in html, bad


def test_second_call_reuses_everything(sweep, runner_bin):
    out, _ = sweep
    before = rows_of(out)
    proc = subprocess.run(sweep_cmd(runner_bin, out.name), cwd=out.parent, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "sweep: rendering" not in proc.stderr
    assert proc.stderr.count("sweep: reusing") == 2
    assert "sweep: runs: 0 executed, 4 reused" in proc.stderr, proc.stderr[-2000:]
    after = rows_of(out)
    key = ["value", "pipeline", "status", "report.accuracy.mean", "run.wall_seconds"]
    assert [[r[k] for k in key] for r in after] == [[r[k] for k in key] for r in before]


@pytest.mark.parametrize("factor,msg", [
    ("colour=1,2", "unknown factor 'colour'"),
    ("views=0,8", "positive integer"),
    ("baseline=30", "more than a full circle"),
    ("noise=", "no values"),
])
def test_bad_factors_fail_before_rendering(runner_bin, tmp_path, factor, msg):
    proc = subprocess.run([runner_bin, "sweep", "--factor", factor, "--dataset-preset", "small",
                           "--pipelines", "pycolmap", "--out", str(tmp_path / "o")],
                          cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          timeout=120)
    assert proc.returncode != 0 and msg in proc.stderr, proc.stderr
    assert not os.path.exists(tmp_path / "o" / "datasets")


def test_a_variant_that_fails_to_render_is_recorded(runner_bin, tmp_path):
    """--dataset-config; the noise=4 variant is rejected by the generator (post-processing
    writes 8-bit images, the config asks for 16-bit PNG) while noise=0 renders: the sweep goes
    on and marks noise=4 as `generation failed` for every pipeline."""
    pytest.importorskip("bpy")
    cfg = tmp_path / "tiny.toml"
    cfg.write_text('preset = "small"\n[render]\nsamples = 2\nformat = "PNG"\npng_color_depth = 16\n'
                   '[camera]\nresolution = [160, 90]\n[views]\norbits = [{elevation_deg = 30.0, count = 3}]\n')
    out = tmp_path / "o"
    proc = subprocess.run([os.path.abspath(runner_bin), "sweep", "--factor", "noise=0,4",
                           "--dataset-config", str(cfg), "--pipelines", "broken",
                           "--custom", "broken=false {out}", "--samples", "10000", "--out", str(out)],
                          cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    rows = rows_of(out)
    assert [(r["value"], r["status"]) for r in rows] == [("0", "failed"), ("4", "generation failed")]
    assert "png_color_depth" in rows[1]["reason"], rows[1]["reason"]
    assert os.path.isfile(out / "datasets" / "noise-0" / "images" / "0000.png")
    assert not os.path.exists(out / "datasets" / "noise-4")
    svg = open(out / "charts" / "report_accuracy_mean.svg").read()
    assert svg.count('class="fail" data-series="broken"') == 2
    assert "generation failed" in svg
