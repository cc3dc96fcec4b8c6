"""Fixtures and helpers of the sfmeval-runner tests (imported by conftest.py; a unique module
name so that one pytest session can hold every test folder).

- `runner_bin`: $SFMEVAL_RUNNER_BIN, else built by `scripts/build-release.sh`.
- `small_dataset`: the generator's `small` preset (36 views, 640×360; no depth/mask pass),
  rendered once with PyPI bpy into target/test-data/small-<key>/, where <key> hashes the full
  resolved generator config (`generate.py --print-config`) and the generator's source, and
  reused while both are unchanged. $SFMEVAL_RUNNER_TEST_DATASET points at an existing dataset
  instead.
- `batch`: ONE run of the seven built-in pipelines that install from registries (+ visualsfm
  absent, a failing and a timing-out custom command) on that dataset, and its report; shared by
  the tests.
"""

import hashlib
import json
import os
import shutil
import subprocess
import sys
import time

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
GENERATE = os.path.join(REPO, "blender_scripts", "generate.py")
CACHE = os.path.join(REPO, "target", "test-data")
DATASET_ARGS = ["--preset", "small", "--set", "outputs.depth=false",
                "--set", "outputs.masks=false"]

# The pipelines of the end-to-end batch. COLMAP's sequential matcher (window 12: both rings'
# neighbours) instead of exhaustive keeps the COLMAP CLI within the CI budget (exhaustive
# matching alone took 96 s of its 136 s here). max_features=2048 only caps the SIFT count; the
# 640x360 images give ~850 features each, so it changes nothing today. Known intrinsics from
# cameras.json make the camera-pose check independent of the tools' focal refinement (with
# EXIF, pycolmap's refined focal was once 1.6 % off, giving 1.4 % median centre error). Theia
# with its default squared loss is not deterministic and its worst camera reached 1.08 % of the
# radius once in CI (0.55-0.78 % over 12 runs here); a 2 px Cauchy loss gave 0.25-0.50 %.
# theia-incremental and openmvg-global run with the images' EXIF (`intrinsics=exif`), so the
# Theia adapter's EXIF focal reading and openmvg-rs's own are exercised too (they add ~25 s and
# ~8 s of run time).
THEIA = "max_features=2000,loss=cauchy,loss_width=2"
PIPELINES = ("colmap:matcher=sequential,overlap=12,max_features=2048;"
             "pycolmap:max_features=2048;pycolmap-global:max_features=2048;"
             "theia:%s;theia-incremental:%s,intrinsics=exif;"
             "openmvg;openmvg-global:intrinsics=exif;visualsfm;bad;slow:timeout=3"
             % (THEIA, THEIA))
REAL = ["colmap", "pycolmap", "pycolmap-global", "theia", "theia-incremental", "openmvg",
        "openmvg-global"]
# The intrinsics each real pipeline of the batch gets (the batch's default: known).
INTRINSICS = {p: "known" for p in REAL}
INTRINSICS.update({"theia-incremental": "exif", "openmvg-global": "exif"})
CUSTOMS = ["--custom", "bad=no-such-sfm-tool {images} {out}",
           "--custom", "slow=sleep 60; echo {out}"]


def _key(args):
    """Hash of the resolved generator config and of the generator's own source (a change to a
    built-in object's shape or texture must re-render too)."""
    out = subprocess.run([sys.executable, GENERATE] + args + ["--print-config"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, check=True)
    cfg = json.loads(out.stdout)
    h = hashlib.sha256(json.dumps(cfg, sort_keys=True).encode())
    pkg = os.path.join(REPO, "blender_scripts", "sfmeval_blender")
    for root, dirs, files in os.walk(pkg):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(files):
            if name.endswith((".py", ".toml")):
                with open(os.path.join(root, name), "rb") as f:
                    h.update(name.encode() + b"\0" + f.read())
    return h.hexdigest()[:16]


@pytest.fixture(scope="session")
def runner_bin():
    b = os.environ.get("SFMEVAL_RUNNER_BIN")
    if b:
        assert os.path.isfile(b), b
        return b
    subprocess.run([os.path.join(REPO, "scripts", "build-release.sh")], cwd=REPO, check=True)
    return os.path.join(REPO, "target", "release", "sfmeval-runner")


@pytest.fixture(scope="session")
def small_dataset():
    given = os.environ.get("SFMEVAL_RUNNER_TEST_DATASET")
    if given:
        assert os.path.isfile(os.path.join(given, "cameras.json")), given
        return given
    pytest.importorskip("bpy")
    dest = os.path.join(CACHE, "small-" + _key(DATASET_ARGS))
    if os.path.isfile(os.path.join(dest, "dataset.json")):
        return dest
    os.makedirs(CACHE, exist_ok=True)
    tmp = dest + ".partial-%d" % os.getpid()
    shutil.rmtree(tmp, ignore_errors=True)
    t0 = time.time()
    proc = subprocess.run([sys.executable, GENERATE] + DATASET_ARGS + ["--out", tmp],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    os.rename(tmp, dest)
    sys.stderr.write("\n[runner tests] rendered %s in %.0f s\n" % (dest, time.time() - t0))
    return dest


def run_cli(runner_bin, *args, check=True, env=None):
    e = dict(os.environ)
    e.update(env or {})
    e.setdefault("SFMEVAL_PYTHON", sys.executable)
    proc = subprocess.run([runner_bin] + [str(a) for a in args], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, env=e, cwd=REPO)
    if check:
        assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return proc


@pytest.fixture(scope="session")
def batch(runner_bin, small_dataset, tmp_path_factory):
    root = tmp_path_factory.mktemp("batch")
    runs, table = root / "runs", root / "table"
    t0 = time.time()
    proc = run_cli(runner_bin, "run", "--datasets", small_dataset, "--pipelines", PIPELINES,
                   *CUSTOMS, "--intrinsics", "known", "--jobs", "2", "--out", runs)
    run_seconds = time.time() - t0
    t0 = time.time()
    rep = run_cli(runner_bin, "report", runs, "--out", table)
    sys.stderr.write("\n[runner tests] batch %.0f s, report %.0f s\n%s\n"
                     % (run_seconds, time.time() - t0, proc.stderr))
    name = os.path.basename(small_dataset)
    return {"root": root, "runs": runs, "table": table, "dataset": small_dataset, "name": name,
            "stderr": proc.stderr + rep.stderr}


def load(path):
    with open(path) as f:
        return json.load(f)
