"""Evaluates two reconstructions of the demo (the COLMAP model and its PLY points), prints the
comparison table and saves the accuracy histograms with matplotlib (an optional dependency:
``pip install matplotlib``; without it the table is printed and no figure saved). Every number
comes from the core: the table is ``sfmeval table``'s text, the bars are the report's own
histogram (``accuracy.histogram``: edges and counts).

Run from the repository root:
``python crates/sfmeval-py/examples/compare_and_plot.py . histogram.png``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path
from typing import Dict

import sfmeval


def evaluate_runs(root: Path, runs: Path) -> Dict[str, sfmeval.Report]:
    """One report per pipeline, written as ``runs/PIPELINE/report.json``."""
    demo = root / "data" / "demo"
    reports = {
        "colmap": sfmeval.evaluate(demo, demo / "sparse", samples=200_000),
        "colmap-points": sfmeval.evaluate(demo, demo / "sparse.ply", align="global",
                                          samples=200_000),
    }
    for pipeline, report in reports.items():
        (runs / pipeline).mkdir(parents=True, exist_ok=True)
        (runs / pipeline / "report.json").write_text(report.to_json(), encoding="utf-8")
    return reports


def save_histograms(reports: Dict[str, sfmeval.Report], path: Path) -> bool:
    """The reports' accuracy histograms in one figure; False without matplotlib."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    fig, ax = plt.subplots(figsize=(7, 4))
    for pipeline, report in reports.items():
        h = report.accuracy.histogram
        edges = [float(e) for e in h.edges]
        counts = [int(c) for c in h.counts]
        ax.stairs(counts, edges, label=f"{pipeline} (mean {float(report.accuracy.mean):.4f})")
    ax.set_xlabel("distance to the ground truth (m)")
    ax.set_ylabel("points")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True


def main(root: Path, figure: Path) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        try:
            reports = evaluate_runs(root, Path(tmp))
            tables = sfmeval.table(tmp, dataset="demo")
        except (FileNotFoundError, sfmeval.InputError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 1
    print(tables.table1_md)
    if save_histograms(reports, figure):
        print(f"histograms saved to {figure}")
    else:
        print("matplotlib is not installed: no histogram saved")
    return 0


if __name__ == "__main__":
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    figure = Path(sys.argv[2]) if len(sys.argv) > 2 else Path("histogram.png")
    sys.exit(main(root, figure))
