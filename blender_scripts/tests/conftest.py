"""Shared fixtures: the small dataset is rendered ONCE per test session (PyPI bpy) and reused.

Set SFMEVAL_TEST_DATASET=/path/to/existing/small/dataset to reuse a dataset rendered earlier
(e.g. while iterating on the tests); the fixture then only checks it exists.
"""

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import time

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
BLENDER_SCRIPTS = os.path.dirname(HERE)
GENERATE = os.path.join(BLENDER_SCRIPTS, "generate.py")
REPO = os.path.dirname(BLENDER_SCRIPTS)
sys.path.insert(0, BLENDER_SCRIPTS)


def have_bpy():
    return importlib.util.find_spec("bpy") is not None


def run_generate(args, python=None, timeout=900):
    """Run the headless generator with the PyPI bpy module (this interpreter by default)."""
    cmd = [python or sys.executable, GENERATE] + list(args)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          timeout=timeout)
    proc.seconds = time.perf_counter() - t0
    return proc


def run_blender(args, timeout=900):
    """Run the headless generator inside Debian's `blender` executable."""
    exe = shutil.which("blender")
    cmd = [exe, "-b", "--factory-startup", "-noaudio", "-P", GENERATE, "--"] + list(args)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          timeout=timeout)
    proc.seconds = time.perf_counter() - t0
    return proc


requires_bpy = pytest.mark.skipif(not have_bpy(), reason="PyPI bpy is not installed in this Python "
                                  "(pip install -r requirements/blender.txt)")


@pytest.fixture(scope="session")
def small_dataset(tmp_path_factory):
    """The `small` preset (36 views, 640×360, 16 spp), with scene.blend saved for checks."""
    given = os.environ.get("SFMEVAL_TEST_DATASET")
    if given:
        assert os.path.isfile(os.path.join(given, "cameras.json")), given
        return given
    if not have_bpy():
        pytest.skip("PyPI bpy is not installed: cannot render the test dataset")
    out = str(tmp_path_factory.mktemp("small") / "dataset")
    proc = run_generate(["--preset", "small", "--set", "outputs.save_blend=true", "--out", out])
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    with open(os.path.join(out, "dataset.json")) as f:
        ds = json.load(f)
    sys.stderr.write("\n[small dataset] %d images, %.2f s/frame, wall %.1f s\n"
                     % (ds["images"], ds["timing"]["render_seconds_mean"], proc.seconds))
    return out


def load_json(path):
    with open(path) as f:
        return json.load(f)
