"""Shared fixture: the small dataset is rendered ONCE per test session (PyPI bpy) and reused.

Set SFMEVAL_TEST_DATASET=/path/to/existing/small/dataset to reuse a dataset rendered earlier
(e.g. while iterating on the tests); the fixture then only checks it exists.
"""

import json
import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from blender_testlib import have_bpy, run_generate  # noqa: E402


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
    with open(os.path.join(out, "timing.json")) as f:
        timing = json.load(f)
    sys.stderr.write("\n[small dataset] %d images, %.2f s/frame, wall %.1f s\n"
                     % (ds["images"], timing["render_seconds_mean"], proc.seconds))
    return out
