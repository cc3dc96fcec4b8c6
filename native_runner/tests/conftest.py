"""sfmeval-runner test fixtures live in runner_testlib.py (unique module name)."""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from runner_testlib import batch, runner_bin, small_dataset  # noqa: E402,F401
