#!/usr/bin/env python3
"""The Tanks and Temples protocol: `sfmeval tnt` against the benchmark's own toolbox
(tests/third_party/tanksandtemples_evaluation, run on the installed Open3D by
tests/python/tnt_toolbox.py) on the same scene, each in its own process, the median of several
rounds: the whole protocol (trajectory alignment, three ICP refinements, evaluation) and the
evaluation alone with the final transform fixed, on the dense cloud; the whole protocol on the
sparse SfM cloud too (the scene's recon/sparse.ply: the pycolmap run of data/demo, 2.5k points,
against the same ground truth, where the fixed costs around the ICP dominate). The two tools'
rounds alternate. Prints a markdown table with wall and CPU time and the ratios; exits 1 when the
numbers disagree (fixed transform: 1e-4; whole protocol: 0.5 points on the dense cloud, 1 point
on the sparse one (2 with --quick), where the toolbox's own runs differ by up to 0.57 points) or a tool fails.

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
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tests" / "python"))
from compare import GNU_TIME  # noqa: E402
import tnt_scene  # noqa: E402

TOOLBOX = ROOT / "tests" / "python" / "tnt_toolbox.py"


def run_timed(cmd):
    """Runs cmd under GNU time: (wall s, CPU s = user + sys, peak MiB, exit code, stdout, stderr)."""
    with tempfile.NamedTemporaryFile("r") as tf:
        t0 = time.perf_counter()
        p = subprocess.run([GNU_TIME, "-f", "%U %S %M", "-o", tf.name, *cmd], capture_output=True)
        wall = time.perf_counter() - t0
        fields = tf.read().split()[-3:]
    try:
        cpu, peak = float(fields[0]) + float(fields[1]), int(fields[2]) / 1024.0
    except (ValueError, IndexError):
        cpu, peak = float("nan"), float("nan")
    return wall, cpu, peak, p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")


def measure_pair(cmds, rounds):
    """Both commands of `cmds`, their rounds alternated: per command the median wall and CPU
    seconds, the max peak MiB and the last run's stdout."""
    runs = [[] for _ in cmds]
    for _ in range(rounds):
        for k, cmd in enumerate(cmds):
            wall, cpu, peak, rc, out, err = run_timed(cmd)
            if rc != 0:
                raise SystemExit(f"bench: {' '.join(map(str, cmd[:3]))} failed: {(out + err)[-800:]}")
            runs[k].append((wall, cpu, peak, out))
    return [(statistics.median(r[0] for r in rs), statistics.median(r[1] for r in rs), max(r[2] for r in rs),
             rs[-1][3]) for rs in runs]


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
    sparse = scene["recon"] / "sparse.ply"
    subprocess.run([cli, "log", "--model", str(ROOT / "data/demo/sparse"), "--images",
                    str(scene["recon"] / "images.txt"), "--out", str(log)], check=True, capture_output=True)
    transform = tmp / "gt_from_recon.txt"
    import numpy as np
    np.savetxt(transform, scene["gt_from_recon"])
    header = sparse.read_bytes().split(b"end_header")[0].decode(errors="replace")
    sparse_points = next(int(l.split()[2]) for l in header.splitlines() if l.startswith("element vertex"))

    def ours(out_dir):
        rep = json.loads((Path(out_dir) / "report.json").read_text())
        return {"precision": rep["precision"]["value"], "recall": rep["recall"]["value"], "f_score": rep["f_score"]}

    def theirs(stdout):
        return json.loads(stdout.strip().splitlines()[-1])

    def protocol(cloud, name):
        return ([cli, "tnt", "--scene", str(scene["scene"]), "--recon", str(cloud), "--trajectory", str(log),
                 "--tau", tau, "--out", str(tmp / f"ours_{name}"), "--quiet"],
                [sys.executable, str(TOOLBOX), "run", str(scene["scene"]), str(log), str(cloud), str(tmp / f"tb_{name}"),
                 tau])

    rows, failures = [], []
    for what, tol, (mine_cmd, their_cmd) in [
        # The toolbox's own runs differ by up to 5.7e-3 in F on the sparse cloud (its trajectory
        # RANSAC is not seeded, and 2.5k points leave its draws a trace): a wider bar there. On
        # --quick's 100k-point ground truth its precision spread over 0.8970-0.9108 in four runs
        # (1.4 points; sfmeval's is one value, 0.9112): twice that bar.
        (f"whole protocol, sparse cloud ({sparse_points} points)", 0.02 if args.quick else 0.01,
         protocol(sparse, "sparse")),
        (f"whole protocol, dense cloud ({args.dense_points + args.dense_points // 30} points)", 0.005,
         protocol(recon, "run")),
        ("evaluation, dense cloud, transform fixed", 1e-4,
         ([cli, "tnt", "--scene", str(scene["scene"]), "--recon", str(recon), "--transform", str(transform),
           "--tau", tau, "--out", str(tmp / "ours_histo"), "--quiet"],
          [sys.executable, str(TOOLBOX), "histo", str(scene["scene"]), str(recon), str(transform),
           str(tmp / "tb_histo"), tau])),
    ]:
        out_dir = mine_cmd[mine_cmd.index("--out") + 1]
        (w_ours, c_ours, p_ours, _), (w_tb, c_tb, p_tb, o_tb) = measure_pair([mine_cmd, their_cmd], args.rounds)
        r_ours, r_tb = ours(out_dir), theirs(o_tb)
        diff = max(abs(r_ours[k] - r_tb[k]) for k in ("precision", "recall", "f_score"))
        ok = diff <= tol
        if not ok:
            failures.append(f"{what}: P/R/F differ by {diff:.2e} > {tol}")
        fmt = lambda r: f"{r['precision']:.4f} / {r['recall']:.4f} / {r['f_score']:.4f}"
        rows.append(f"| {what} | sfmeval tnt | {w_ours:.2f} | {c_ours:.2f} | {p_ours:.0f} | **{w_tb / w_ours:.1f}×** "
                    f"(CPU {c_tb / c_ours:.1f}×) | {fmt(r_ours)} | {'✓' if ok else '✗'} max diff {diff:.1e} (bar {tol:g}) |")
        rows.append(f"| {what} | toolbox (Open3D, Python) | {w_tb:.2f} | {c_tb:.2f} | {p_tb:.0f} | 1× | {fmt(r_tb)} | "
                    "reference |")
    text = (f"Tanks and Temples protocol: scene `{scene['scene'].name}`, {args.gt_points} ground-truth points, "
            f"τ = {tau}; whole process (reading included), wall and CPU (user + system) seconds, median of "
            f"{args.rounds} round(s), the two tools' rounds alternated.\n\n"
            "| step | tool | wall s | CPU s | peak MiB | speed-up (wall; CPU) | P / R / F | agreement |\n"
            "|---|---|---|---|---|---|---|---|\n"
            + "\n".join(rows) + "\n")
    print(text)
    if args.markdown:
        Path(args.markdown).write_text(text)
    if failures:
        print("bench tnt: FAILED\n  " + "\n  ".join(failures), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
