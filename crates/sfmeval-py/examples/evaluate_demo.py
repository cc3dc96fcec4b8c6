"""Evaluates the demo pair and prints the numbers a paper's table quotes; checked by
``mypy --strict`` against the installed package's types (scripts/check-python-package.sh).

Run from the repository root: ``python crates/sfmeval-py/examples/evaluate_demo.py``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import sfmeval


def summary(report: sfmeval.Report) -> str:
    lines = [
        f"accuracy mean {float(report.accuracy.mean):.6f} over {int(report.accuracy.count)} points",
        f"alignment {str(report.alignment.method)}, scale {float(report.alignment.scale):.6f}",
    ]
    for t in report.thresholds:
        lines.append(f"tau {float(t.tau):.6f}: F {float(t.f_score):.4f}")
    for note in report.notes:
        lines.append(f"{note.level} [{note.code}] {note.message}")
    return "\n".join(lines)


def main(root: Path) -> int:
    demo = root / "data" / "demo"
    try:
        report = sfmeval.evaluate(
            demo / "ground_truth.glb", demo / "sparse", gt_cameras=demo / "cameras.json"
        )
    except (FileNotFoundError, sfmeval.InputError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    gt_from_recon: np.ndarray = report.alignment.gt_from_recon
    kept: np.ndarray = report.kept
    print(summary(report))
    print("gt_from_recon\n", gt_from_recon)
    print("p95 of the kept points' distances", float(np.percentile(report.distances[kept], 95)))
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")))
