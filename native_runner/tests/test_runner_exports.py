"""The tools' own exports kept in the run folders, other model formats through `run` + `report`,
and a stand-in VisualSFM, all on the shared `batch` (see runner_testlib.py).

- Raw exports: each is evaluated by the real `sfmeval eval` CLI as a user would (it never sees
  the runner's converted files) and must agree with the runner's report of the same run.
- Custom pipelines writing NVM, Bundler and PLY: COLMAP 3.8's own `model_converter` writes them
  from the batch's pycolmap model; the runner's numbers must agree with that run's.
- VisualSFM cannot be installed from any registry, so a stand-in on PATH checks its command line
  and writes an NVM (see test_visualsfm_stand_in).
"""

import glob
import os
import re
import shutil
import stat
import subprocess
import sys

import numpy as np
import pytest

from runner_testlib import REPO, load, run_cli

SCHEMA = os.path.join(REPO, "schemas", "report.schema.json")
MARKERS = re.compile(r"removed (\d+) point\(s\) in camera-marker colours")


def run_dir(batch, pipeline):
    return batch["runs"] / batch["name"] / pipeline


def report_of(table, name, pipeline):
    return load(table / "reports" / name / (pipeline + ".json"))


def orbit_radius(dataset):
    ds = load(os.path.join(dataset, "dataset.json"))
    radii = [v["radius"] for v in ds["views"]]
    return sum(radii) / len(radii)


@pytest.fixture(scope="session")
def sfmeval_bin():
    b = os.environ.get("SFMEVAL_BIN")
    if b:
        assert os.path.isfile(b), b
        return os.path.abspath(b)
    b = os.path.join(REPO, "target", "release", "sfmeval")
    if not os.path.isfile(b):
        subprocess.run([os.path.join(REPO, "scripts", "build-release.sh")], cwd=REPO, check=True)
    return b


# (pipeline, export inside its run folder, kind). theia: Theia's WriteNVMFile and WritePlyFile
# (camera centres appended in red); openmvg: openmvg-rs's write_ply (green centres); colmap: the
# COLMAP CLI mapper's binary sub-model; pycolmap: its own text export (`model/` is copied
# verbatim from Reconstruction.write_text).
RAW = [("theia", "raw/reconstruction.nvm", "model"), ("theia", "raw/points.ply", "ply"),
       ("openmvg", "raw/scene.ply", "ply"), ("colmap", "raw/sparse/*", "model"),
       ("pycolmap", "model", "model")]


@pytest.mark.parametrize("pipeline,export,kind", RAW,
                         ids=["%s:%s" % (p, e.replace("/*", "")) for p, e, _ in RAW])
def test_raw_exports_evaluate_like_the_run(sfmeval_bin, batch, tmp_path, pipeline, export, kind):
    """0.2-0.3 s each (100k completeness samples; the accuracy does not depend on them).

    Models (NVM, COLMAP binary/text): `auto` alignment (GT cameras + ICP); every camera within
    1 % of the orbit radius, the same registered images and points as the run, and the same
    accuracy (the same points aligned by the same cameras: measured ratio 1 - 2e-8 for Theia's
    6-digit NVM). PLYs: no cameras, so the marker-colour path must strip exactly one point per
    registered image (the warning says how many), leaving the run's points, and `auto` aligns
    them by `global` + ICP alone: the mean must match the camera-aligned run's report (measured
    ratios 1 - 3e-5 to 1 + 1.1e-4; before the box-normalised global starts these landed in wrong
    poses, mean 0.033-0.037 m against 0.0013-0.0047 m)."""
    jsonschema = pytest.importorskip("jsonschema")
    d = run_dir(batch, pipeline)
    found = glob.glob(str(d / export))
    assert len(found) == 1, (export, found)
    out = tmp_path / "r.json"
    ds = batch["dataset"]
    own = report_of(batch["table"], batch["name"], pipeline)
    proc = subprocess.run([sfmeval_bin, "eval", "--gt", os.path.join(ds, "ground_truth.glb"),
                           "--gt-cameras", os.path.join(ds, "cameras.json"), "--recon", found[0],
                           "--samples", "100000", "--quiet", "--report", str(out)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    rep = load(out)
    jsonschema.validate(rep, load(SCHEMA))
    rec = load(d / "run.json")
    mean, own_mean = rep["accuracy"]["mean"], own["accuracy"]["mean"]
    sys.stderr.write("%s %s: mean %.6f m (run's report %.6f, ratio %.5f), %d points, "
                     "alignment %s\n" % (pipeline, export, mean, own_mean, mean / own_mean,
                                         rep["inputs"]["reconstruction"]["points"],
                                         rep["alignment"]["method"]))
    assert rep["inputs"]["reconstruction"]["points"] == rec["points"]
    if kind == "ply":
        removed = [int(n) for w in [n["message"] for n in rep["notes"]] for n in MARKERS.findall(w)]
        assert removed == [rec["images_registered"]], [n["message"] for n in rep["notes"]]
        assert rep["alignment"]["method"] == "global+icp"
        assert abs(mean - own_mean) < 2e-3 * own_mean
    else:
        assert rep["alignment"]["method"] == own["alignment"]["method"] == "cameras+icp"
        cams = rep["cameras"]
        assert cams["registered"] == rec["images_registered"] == own["cameras"]["registered"]
        radius = orbit_radius(ds)
        assert cams["center_error"]["max"] < 0.01 * radius, cams["center_error"]["max"] / radius
        assert abs(mean - own_mean) < 1e-3 * own_mean


def ply_points(path):
    """xyz of a binary little-endian PLY with float x, y, z and uchar colours (sparse.ply)."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    n = int(re.search(rb"element vertex (\d+)", data[:end]).group(1))
    assert b"property float x" in data[:end] and b"binary_little_endian" in data[:end]
    rec = np.frombuffer(data[end:end + 15 * n], dtype=[("xyz", "<f4", 3), ("rgb", "u1", 3)])
    return rec["xyz"].astype(np.float64)


def custom_exports(batch):
    """Custom pipelines whose command converts the batch's pycolmap model with COLMAP 3.8's own
    writers (model_converter): NVM, Bundler (.bundle.out + .list.txt) and PLY."""
    src = run_dir(batch, "pycolmap") / "model"
    conv = "colmap model_converter --input_path %s --output_type %s --output_path {out}/%s"
    return {"as-nvm": conv % (src, "NVM", "model.nvm"),
            "as-bundler": conv % (src, "Bundler", "bundle"),
            "as-ply": conv % (src, "PLY", "points.ply")}


def test_custom_nvm_bundler_and_ply_outputs(runner_bin, batch, tmp_path):
    """1.5 s (three instant conversions, then the report of three runs). The NVM and Bundler
    runs hold the source's cameras and points: same registered images, points and (same cameras
    aligning the same points) accuracy and centre errors as the pycolmap run's report. The PLY
    run has only the points: its sparse.ply must hold exactly the source's points (COLMAP writes
    float32, so compared to 1e-6 m), and `auto` aligns it by global + ICP to the accuracy of
    the camera-aligned source (see test_raw_exports_evaluate_like_the_run)."""
    if shutil.which("colmap") is None:
        pytest.skip("the COLMAP CLI is not installed")
    customs = custom_exports(batch)
    args = []
    for name, cmd in customs.items():
        args += ["--custom", "%s=%s" % (name, cmd)]
    runs, table = tmp_path / "runs", tmp_path / "table"
    run_cli(runner_bin, "run", "--datasets", batch["dataset"], "--pipelines", ",".join(customs),
            *args, "--out", runs)
    run_cli(runner_bin, "report", runs, "--out", table, "--samples", "100000")
    src_rec = load(run_dir(batch, "pycolmap") / "run.json")
    src_rep = report_of(batch["table"], batch["name"], "pycolmap")
    for name in customs:
        rec = load(runs / batch["name"] / name / "run.json")
        assert rec["status"] == "ok", (name, rec["reason"])
        assert rec["points"] == src_rec["points"], name
        rep = report_of(table, batch["name"], name)
        mean, src_mean = rep["accuracy"]["mean"], src_rep["accuracy"]["mean"]
        sys.stderr.write("%s: %d images, %d points, mean %.6f m (pycolmap %.6f, ratio %.5f)\n"
                         % (name, rec["images_registered"], rec["points"], mean, src_mean,
                            mean / src_mean))
        if name == "as-ply":
            assert rec["images_registered"] == 0 and rep["inputs"]["reconstruction"]["images"] == 0
            assert any("no cameras" in w for w in [n["message"] for n in rep["notes"]]), [n["message"] for n in rep["notes"]]
            got = ply_points(runs / batch["name"] / name / "sparse.ply")
            want = ply_points(run_dir(batch, "pycolmap") / "sparse.ply")
            assert got.shape == want.shape
            rows = lambda a: a[np.lexsort(a.T[::-1])]  # noqa: E731 - points in any order
            assert np.abs(rows(got) - rows(want)).max() < 1e-6
            assert rep["alignment"]["method"] == "global+icp"
            assert abs(mean - src_mean) < 2e-3 * src_mean, name
        else:
            assert rec["images_registered"] == src_rec["images_registered"], name
            assert rep["cameras"]["registered"] == src_rep["cameras"]["registered"], name
            assert abs(mean - src_mean) < 1e-3 * src_mean, name
            c, s = rep["cameras"]["center_error"], src_rep["cameras"]["center_error"]
            assert abs(c["median"] - s["median"]) < 0.01 * s["median"] + 1e-6, (name, c, s)


STAND_IN = r'''#!%(python)s
"""Stand-in for VisualSFM (tests only): checks the command line, writes a prepared NVM."""
import shutil, sys
expected = %(expected)r
args = sys.argv[1:]
if len(args) != 3 or args[0] not in expected or not args[2].endswith(".nvm"):
    sys.stderr.write("stand-in VisualSFM: unexpected arguments %%r\n" %% (args,))
    sys.exit(2)
if args[1] != %(images)r:
    sys.stderr.write("stand-in VisualSFM: image folder %%r\n" %% args[1])
    sys.exit(2)
print("stand-in VisualSFM:", " ".join(args))
shutil.copy(%(nvm)r, args[2])
'''


def test_visualsfm_stand_in(runner_bin, batch, tmp_path):
    """VisualSFM cannot be installed from a registry, so this uses a stand-in `VisualSFM` first
    on PATH: a Python script that accepts only the command line the adapter documents
    (`sfm+shared+k=fx,cx,fy,cy <images> <out>.nvm` with known intrinsics, `sfm+shared ...` with
    EXIF) and copies an NVM written by a real NVM writer (COLMAP 3.8's model_converter, from the
    batch's pycolmap model) to the requested path. It proves the adapter's command line, its
    availability check via PATH and the NVM pickup through run + report; it says nothing about
    VisualSFM's own reconstructions. 0.4 s."""
    if shutil.which("colmap") is None:
        pytest.skip("the COLMAP CLI is not installed")
    nvm = tmp_path / "prepared.nvm"
    subprocess.run(["colmap", "model_converter", "--input_path",
                    str(run_dir(batch, "pycolmap") / "model"), "--output_path", str(nvm),
                    "--output_type", "NVM"], check=True, stdout=subprocess.DEVNULL)
    cams = load(os.path.join(batch["dataset"], "cameras.json"))["cameras"][0]
    k = "sfm+shared+k=%s,%s,%s,%s" % tuple(
        "%s" % (int(v) if float(v).is_integer() else v)
        for v in (cams["fx"], cams["cx"], cams["fy"], cams["cy"]))
    bindir = tmp_path / "bin"
    bindir.mkdir()
    exe = bindir / "VisualSFM"
    exe.write_text(STAND_IN % {"python": sys.executable, "expected": [k, "sfm+shared"],
                               "images": os.path.join(batch["dataset"], "images"),
                               "nvm": str(nvm)})
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    env = {"PATH": str(bindir) + os.pathsep + os.environ.get("PATH", "")}
    runs, table = tmp_path / "runs", tmp_path / "table"
    run_cli(runner_bin, "run", "--datasets", batch["dataset"], "--pipelines",
            "visualsfm;visualsfm:intrinsics=exif,name=visualsfm-exif", "--intrinsics", "known",
            "--out", runs, env=env)
    run_cli(runner_bin, "report", runs, "--out", table, "--samples", "100000", env=env)
    src = load(run_dir(batch, "pycolmap") / "run.json")
    radius = orbit_radius(batch["dataset"])
    for name, mode in [("visualsfm", k), ("visualsfm-exif", "sfm+shared")]:
        d = runs / batch["name"] / name
        rec = load(d / "run.json")
        assert rec["status"] == "ok", (name, rec["reason"])
        assert rec["command"][0].split()[1] == mode, rec["command"]
        assert rec["images_registered"] == src["images_registered"]
        assert rec["points"] == src["points"]
        assert "stand-in VisualSFM: " + mode in (d / "log.txt").read_text()
        rep = report_of(table, batch["name"], name)
        assert rep["cameras"]["registered"] == src["images_registered"]
        assert rep["cameras"]["center_error"]["max"] < 0.01 * radius
