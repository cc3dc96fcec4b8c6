#!/usr/bin/env python3
"""The Tanks and Temples protocol: `sfmeval tnt` against the benchmark's own toolbox
(tests/third_party/tanksandtemples_evaluation, run on the installed Open3D by
tests/python/tnt_toolbox.py) on the same scene, each in its own process, the median of several
rounds: the whole protocol (trajectory alignment, three ICP refinements, evaluation) and the
evaluation alone with the final transform fixed. Prints a markdown table with the ratio; exits 1
when the numbers disagree (fixed transform: 1e-4; whole protocol: 0.5 points) or a tool fails.

  bench/tanksandtemples.py [--quick] [--rounds 3] [--gt-points 2000000] [--dense-points 1000000]
                           [--markdown out.md]

The scene is tests/python/tnt_scene.py's (the demo statue in the benchmark's layout, the .log of
its real pycolmap run, a dense cloud with noise and outliers). --quick (CI): 100k ground-truth
points, 50k reconstruction points, one round.
"""
import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tests" / "python"))
from compare import run_with_peak  # noqa: E402
import tnt_scene  # noqa: E402

TOOLBOX = ROOT / "tests" / "python" / "tnt_toolbox.py"


def measure(cmd, rounds, result):
    """Median wall seconds, max peak MiB, and result() of the last run's stdout."""
    walls, peaks, out = [], [], ""
    for _ in range(rounds):
        wall, peak, rc, out, err = run_with_peak(cmd)
        if rc != 0:
            raise SystemExit(f"bench: {' '.join(map(str, cmd[:3]))} failed: {(out + err)[-800:]}")
        walls.append(wall)
        peaks.append(peak)
    return statistics.median(walls), max(peaks), result(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--gt-points", type=int, default=2_000_000)
    ap.add_argument("--dense-points", type=int, default=1_000_000)
    ap.add_argument("--markdown")
    args = ap.parse_args()
    if args.quick:
        args.rounds, args.gt_points, args.dense_points = 1, 100_000, 50_000
    cli = str(ROOT / "target" / "release" / "sfmeval")
    tmp = Path(tempfile.mkdtemp(prefix="sfmeval-bench-tnt-"))
    scene = tnt_scene.build(tmp, args.gt_points, args.dense_points)
    recon, log, tau = scene["recon"] / "dense.ply", scene["recon"] / "recon.log", str(scene["tau"])
    subprocess.run([cli, "log", "--model", str(ROOT / "data/demo/sparse"), "--images",
                    str(scene["recon"] / "images.txt"), "--out", str(log)], check=True, capture_output=True)
    transform = tmp / "gt_from_recon.txt"
    import numpy as np
    np.savetxt(transform, scene["gt_from_recon"])

    def ours(out):
        rep = json.loads((Path(out) / "report.json").read_text())
        return {"precision": rep["precision"]["value"], "recall": rep["recall"]["value"], "f_score": rep["f_score"]}

    def theirs(stdout):
        return json.loads(stdout.strip().splitlines()[-1])

    rows, failures = [], []
    for what, tol, mine_cmd, their_cmd in [
        ("whole protocol", 0.005,
         [cli, "tnt", "--scene", str(scene["scene"]), "--recon", str(recon), "--trajectory", str(log),
          "--tau", tau, "--out", str(tmp / "ours_run"), "--quiet"],
         [sys.executable, str(TOOLBOX), "run", str(scene["scene"]), str(log), str(recon), str(tmp / "tb_run"), tau]),
        ("evaluation, transform fixed", 1e-4,
         [cli, "tnt", "--scene", str(scene["scene"]), "--recon", str(recon), "--transform", str(transform),
          "--tau", tau, "--out", str(tmp / "ours_histo"), "--quiet"],
         [sys.executable, str(TOOLBOX), "histo", str(scene["scene"]), str(recon), str(transform), str(tmp / "tb_histo"), tau]),
    ]:
        out_dir = mine_cmd[mine_cmd.index("--out") + 1]
        w_ours, p_ours, r_ours = measure(mine_cmd, args.rounds, lambda _o, d=out_dir: ours(d))
        w_tb, p_tb, r_tb = measure(their_cmd, args.rounds, theirs)
        diff = max(abs(r_ours[k] - r_tb[k]) for k in ("precision", "recall", "f_score"))
        ok = diff <= tol
        if not ok:
            failures.append(f"{what}: P/R/F differ by {diff:.2e} > {tol}")
        fmt = lambda r: f"{r['precision']:.4f} / {r['recall']:.4f} / {r['f_score']:.4f}"
        rows.append(f"| {what} | sfmeval tnt | {w_ours:.2f} | {p_ours:.0f} | **{w_tb / w_ours:.1f}×** | {fmt(r_ours)} | "
                    f"{'✓' if ok else '✗'} max diff {diff:.1e} (bar {tol:g}) |")
        rows.append(f"| {what} | toolbox (Open3D, Python) | {w_tb:.2f} | {p_tb:.0f} | 1× | {fmt(r_tb)} | reference |")
    text = (f"Tanks and Temples protocol: scene `{scene['scene'].name}`, {args.gt_points} ground-truth points, "
            f"{args.dense_points + args.dense_points // 30} reconstruction points, τ = {tau}; wall time of the whole "
            f"process (reading included), median of {args.rounds} round(s).\n\n"
            "| step | tool | wall s | peak MiB | speed-up | P / R / F | agreement |\n|---|---|---|---|---|---|---|\n"
            + "\n".join(rows) + "\n")
    print(text)
    if args.markdown:
        Path(args.markdown).write_text(text)
    if failures:
        print("bench tnt: FAILED\n  " + "\n  ".join(failures), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
