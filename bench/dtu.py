#!/usr/bin/env python3
"""The DTU evaluation: `sfmeval dtu` against the Python port of the benchmark's evaluation
(DTUeval-python's eval.py, vendored in tests/reference/dtueval_python/, run unchanged by
tests/python/dtu_port.py with the shuffle in the input's order) on the same scan, each in its own
process, the median of several rounds, for a dense point cloud and for a mesh the evaluator
samples. Prints a markdown table with the ratio; exits 1 when the numbers disagree (1e-6
relative) or a tool fails.

  bench/dtu.py [--quick] [--rounds 3] [--stl-points 2000000] [--dense-points 2000000]
               [--markdown out.md]

The scan is tests/python/dtu_scene.py's (the demo statue as a 100 mm figurine in DTU's layout).
--quick (CI, about 30 s): 100k STL points, 100k reconstruction points, one round.
"""
import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tests" / "python"))
from timing import measure  # noqa: E402
import dtu_scene  # noqa: E402

PORT = ROOT / "tests" / "python" / "dtu_port.py"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--stl-points", type=int, default=2_000_000)
    ap.add_argument("--dense-points", type=int, default=2_000_000)
    ap.add_argument("--markdown")
    args = ap.parse_args()
    if args.quick:
        args.rounds, args.stl_points, args.dense_points = 1, 100_000, 100_000
    cli = str(ROOT / "target" / "release" / "sfmeval")
    tmp = Path(tempfile.mkdtemp(prefix="sfmeval-bench-dtu-"))
    scene = dtu_scene.build(tmp, cli, args.stl_points, args.dense_points)

    def ours(stdout):
        r = json.loads(stdout)
        return [r["mean_accuracy"], r["mean_completeness"], r["overall"]]

    def theirs(stdout):
        return [float(v) for v in stdout.strip().splitlines()[-1].split()]

    rows, failures = [], []
    for case, mode in [("dense", "pcd"), ("mesh", "mesh")]:
        recon = scene[case]
        mine = [cli, "dtu", "--dataset", str(tmp), "--scan", "1", "--recon", str(recon), "--mode", mode,
                "--no-shuffle", "--vis-out", str(tmp / f"ours_{case}"), "--json"]
        port = [sys.executable, str(PORT), "--data", str(recon), "--scan", "1", "--mode", mode,
                "--dataset_dir", str(tmp), "--vis_out_dir", str(tmp / f"port_{case}")]
        (tmp / f"port_{case}").mkdir()
        w_ours, p_ours, r_ours = measure(mine, args.rounds, ours)
        w_port, p_port, r_port = measure(port, args.rounds, theirs)
        diff = max(abs(a - b) / abs(b) for a, b in zip(r_ours, r_port))
        ok = diff <= 1e-6
        if not ok:
            failures.append(f"{case}: the numbers differ by {diff:.2e} relative")
        fmt = lambda r: " / ".join(f"{v:.6f}" for v in r)
        rows.append(f"| {case} ({mode}) | sfmeval dtu | {w_ours:.2f} | {p_ours:.0f} | **{w_port / w_ours:.1f}×** | "
                    f"{fmt(r_ours)} | {'✓' if ok else '✗'} max rel. diff {diff:.1e} |")
        rows.append(f"| {case} ({mode}) | DTUeval-python | {w_port:.2f} | {p_port:.0f} | 1× | {fmt(r_port)} | reference |")
    text = (f"DTU evaluation: the demo statue as a 100 mm scan, {args.stl_points} STL points, a dense cloud of "
            f"{args.dense_points} surface samples with noise and outliers, and the statue's mesh (sampled at 0.2 mm); "
            f"wall time of the whole process (reading and the error clouds included), median of {args.rounds} round(s).\n\n"
            "| input | tool | wall s | peak MiB | speed-up | accuracy / completeness / overall (mm) | agreement |\n"
            "|---|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n")
    print(text)
    if args.markdown:
        Path(args.markdown).write_text(text)
    if failures:
        print("bench dtu: FAILED\n  " + "\n  ".join(failures), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
