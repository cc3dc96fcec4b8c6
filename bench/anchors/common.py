"""Shared command line and output of the anchor scripts (one per tool, each run in its own process
by bench/compare.py):

  python bench/anchors/TOOL_ops.py OP --mesh MESH --cloud CLOUD [--queries CLOUD2] [--samples N]
                                      [--start START.txt] [--threads N] [--gate F]

Each prints one JSON line {"op", "seconds", "result": {...}} like sfmeval's
`crates/sfmeval/examples/bench_op.rs`, with the same op names and meanings: `seconds` covers the
operation only (files are read first, untimed, except for `load` and `eval`). A tool without an
equivalent of an op exits with UNSUPPORTED (3).
"""
import argparse
import json
import sys
import time

import numpy as np

UNSUPPORTED = 3


def parse(ops):
    ap = argparse.ArgumentParser()
    ap.add_argument("op", choices=ops)
    ap.add_argument("--mesh")
    ap.add_argument("--cloud")
    ap.add_argument("--queries")
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--start", help="row-major 4x4 start similarity (align)")
    ap.add_argument("--gate", type=float, default=0.05, help="ICP correspondence gate, fraction of the mesh diagonal")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--seed", type=int, default=1)
    return ap.parse_args()


def unsupported(op):
    print(json.dumps({"op": op, "unsupported": True}))
    sys.exit(UNSUPPORTED)


def summary(d):
    d = np.asarray(d, dtype=np.float64)
    return {"n": int(d.size), "mean": float(d.mean()), "max": float(d.max())}


def read_matrix(path):
    return np.loadtxt(path, comments="#").reshape(4, 4)


class Timer:
    """`with Timer() as t: ...` then t.seconds."""

    def __enter__(self):
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.t0


def emit(op, seconds, result):
    print(json.dumps({"op": op, "seconds": seconds, "result": result}))
