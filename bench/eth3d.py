#!/usr/bin/env python3
"""ETH3D's multi-view evaluation: `sfmeval eth3d` against the official C++ tool
(ETH3DMultiViewEvaluation, vendored in tests/third_party/eth3d_multi_view_evaluation/ and built
unchanged by scripts/build-eth3d-tool.sh) on the same scene, each in its own process with its
coloured clouds written, the median of several rounds, for a dense cloud and for a real sparse
SfM cloud. The tool runs with all cores (its completeness loop is OpenMP-parallel, its accuracy
loop serial), as sfmeval does. Wall and CPU (user + system) time: on a loaded machine the CPU
time is the fairer comparison. Prints a markdown table with the ratio; exits 1 when a number
disagrees (1e-6 relative) or a tool fails.

  bench/eth3d.py [--quick] [--rounds 3] [--scan-points 2000000] [--dense-points 2000000]
                 [--markdown out.md]

The scene is tests/python/eth3d_scene.py's (the demo statue scanned from two positions, in
ETH3D's layout). --quick (CI, about 20 s): 100k scan points, 100k reconstruction points, one round.
"""
import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tests" / "python"))
from timing import measure_cpu  # noqa: E402
import eth3d_scene  # noqa: E402
import eth3d_tool  # noqa: E402

TOLERANCES = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--scan-points", type=int, default=2_000_000)
    ap.add_argument("--dense-points", type=int, default=2_000_000)
    ap.add_argument("--markdown")
    args = ap.parse_args()
    if args.quick:
        args.rounds, args.scan_points, args.dense_points = 1, 100_000, 100_000
    cli = str(ROOT / "target" / "release" / "sfmeval")
    tool = str(eth3d_tool.build())
    tmp = Path(tempfile.mkdtemp(prefix="sfmeval-bench-eth3d-"))
    scene = eth3d_scene.build(tmp, cli, args.scan_points, args.dense_points)
    tol = ",".join(map(str, TOLERANCES))

    def ours(stdout):
        r = json.loads(stdout)["tolerances"]
        return [x[k] for k in ("accuracy", "completeness", "f1") for x in r]

    def theirs(stdout):
        got = {}
        for line in stdout.splitlines():
            key, _, values = line.partition(": ")
            got[key] = [float(v) for v in values.split()] if key in ("Accuracies", "Completenesses", "F1-scores") else None
        return got["Accuracies"] + got["Completenesses"] + got["F1-scores"]

    rows, failures = [], []
    for case in ("dense", "sparse"):
        recon = scene[case]
        mine = [cli, "eth3d", "--gt", str(scene["mlp"]), "--recon", str(recon), "--tolerances", tol,
                "--out", str(tmp / f"ours_{case}"), "--json"]
        official = [tool, "--reconstruction_ply_path", str(recon), "--ground_truth_mlp_path", str(scene["mlp"]),
                    "--tolerances", tol, "--completeness_cloud_output_path", str(tmp / f"tool_{case}" / "completeness"),
                    "--accuracy_cloud_output_path", str(tmp / f"tool_{case}" / "accuracy")]
        w_ours, c_ours, p_ours, r_ours = measure_cpu(mine, args.rounds, ours)
        w_tool, c_tool, p_tool, r_tool = measure_cpu(official, args.rounds, theirs)
        diff = max(abs(a - b) / max(abs(b), 1e-30) for a, b in zip(r_ours, r_tool))
        ok = diff <= 1e-6
        if not ok:
            failures.append(f"{case}: the numbers differ by {diff:.2e} relative")
        n = len(TOLERANCES)
        fmt = lambda r: f"{r[0]:.4f} / {r[n]:.4f} / {r[2 * n]:.4f}"
        rows.append(f"| {case} | sfmeval eth3d | {w_ours:.2f} | {c_ours:.2f} | {p_ours:.0f} | **{w_tool / w_ours:.1f}×** | "
                    f"{c_tool / c_ours:.1f}× | "
                    f"{fmt(r_ours)} | {'✓' if ok else '✗'} max rel. diff {diff:.1e} |")
        rows.append(f"| {case} | ETH3DMultiViewEvaluation | {w_tool:.2f} | {c_tool:.2f} | {p_tool:.0f} | 1× | 1× | "
                    f"{fmt(r_tool)} | reference |")
    text = (f"ETH3D evaluation: the demo statue scanned from two positions ({args.scan_points} scan points), "
            f"a dense cloud of {args.dense_points} surface samples with noise, a hole and outliers, and the demo's "
            f"real COLMAP cloud; tolerances {tol} m in one pass; wall time of the whole process (reading and the "
            f"{2 * len(TOLERANCES)} coloured clouds included), median of {args.rounds} round(s).\n\n"
            "| input | tool | wall s | CPU s | peak MiB | speed-up (wall) | CPU ratio | accuracy / completeness / F1 at 1 cm | agreement (all tolerances) |\n"
            "|---|---|---|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n")
    print(text)
    if args.markdown:
        Path(args.markdown).write_text(text)
    if failures:
        print("bench eth3d: FAILED\n  " + "\n  ".join(failures), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
