"""Headless dataset generator.

    blender -b --factory-startup -P blender_scripts/generate.py -- --config D.toml --out DIR
    python blender_scripts/generate.py --config D.toml --out DIR      (PyPI bpy)
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from sfmeval_blender.cli import main  # noqa: E402


def _argv():
    if "--" in sys.argv:                      # blender ... -P generate.py -- ARGS
        return sys.argv[sys.argv.index("--") + 1:]
    return sys.argv[1:]


if __name__ == "__main__":
    code = main(_argv())
    sys.stdout.flush()
    sys.stderr.flush()
    if code:
        # Inside Blender a plain SystemExit would be caught: leave with the code directly.
        os._exit(code)
