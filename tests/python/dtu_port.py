"""Runs the vendored DTUeval-python `eval.py` (tests/reference/dtueval_python/) unchanged, with
its one random step made deterministic: the port shuffles the points with an unseeded
`np.random.default_rng().shuffle` before down-sampling; here `default_rng` returns a generator
whose `shuffle` keeps the order, so the port down-samples in the input's order, as
`sfmeval dtu --no-shuffle` does (the tests shuffle the input file themselves instead).

  python dtu_port.py [eval.py's arguments]

prints what eval.py prints: `mean_d2s mean_s2d overall` on its last line.
"""
import runpy
import sys
from pathlib import Path

import numpy as np

EVAL = Path(__file__).resolve().parents[1] / "reference" / "dtueval_python" / "eval.py"


_default_rng = np.random.default_rng


class _KeepOrder:
    """A numpy Generator whose shuffle keeps the order (everything else delegated: scipy and
    scikit-learn draw from default_rng when they are imported)."""

    def __init__(self, *args, **kwargs):
        self._rng = _default_rng(*args, **kwargs)

    def shuffle(self, x, axis=0):
        pass

    def __getattr__(self, name):
        return getattr(self._rng, name)


def main():
    np.random.default_rng = _KeepOrder
    sys.argv = [str(EVAL), *sys.argv[1:]]
    # run_path makes the script __main__ while it runs, so the mesh mode's worker processes
    # (forked) find sample_single_tri there.
    runpy.run_path(str(EVAL), run_name="__main__")


if __name__ == "__main__":
    main()
