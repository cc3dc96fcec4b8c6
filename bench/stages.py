#!/usr/bin/env python3
"""Per-stage wall and CPU time of the 1M whole evaluation at 1 and 2 threads, and the part of
each stage that does not divide between threads.

Each stage is one `bench_op` operation (crates/sfmeval/examples/bench_op.rs) in its own process,
timed inside it (files read first, untimed, except `load`): wall seconds and the CPU seconds of
all the process's threads over the same span. The whole evaluation is `sfmeval eval` (1M
completeness samples, `--align none`), its process timed from outside (wall; CPU = user +
system from GNU time). Rounds alternate the thread counts; the table holds medians.

With T1 and T2 the wall times at 1 and 2 threads, a stage made of a serial part S and a part P
that divides evenly has T1 = S + P and T2 = S + P/2: the undivided part is S = 2·T2 − T1
(Amdahl's estimate; on a loaded machine a second thread may not be free, which inflates it:
quote the load).

  bench/stages.py [--data bench/data] [--mesh mesh_1m.ply] [--cloud cloud_1m.ply]
                  [--samples 1000000] [--rounds 3] [--markdown out.md]
  bench/stages.py --quick     (CI: the 50k mesh and the 100k cloud of generate.py --quick, written
                               into a temporary folder, 1 round)
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STAGES = [
    ("load", "reading the mesh and the cloud"),
    ("bvh", "BVH build"),
    ("kdtree", "k-d tree build (kiddo, the bench's)"),
    ("accuracy", "accuracy: BVH build + 1 query a point"),
    ("completeness", "completeness: sampling + k-d tree + 1 query a sample"),
]


def gnu_time():
    for t in ("/usr/bin/time", "gtime"):
        if Path(t).exists():
            return t
    raise SystemExit("bench stages: GNU time is needed (apt-get install time)")


def run_op(bench_op, op, mesh, cloud, samples, threads):
    out = subprocess.run([str(bench_op), op, "--mesh", str(mesh), "--cloud", str(cloud), "--samples",
                          str(samples), "--threads", str(threads)], capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"bench stages: bench_op {op} failed: {out.stderr[-800:]}")
    j = json.loads(out.stdout.strip().splitlines()[-1])
    if j.get("cpu_seconds") is None:
        raise SystemExit("bench stages: bench_op gave no CPU time (Linux's /proc is needed)")
    return j["seconds"], j["cpu_seconds"]


def run_eval(cli, mesh, cloud, samples, threads, report):
    with tempfile.NamedTemporaryFile("r") as tf:
        t0 = time.perf_counter()
        p = subprocess.run([gnu_time(), "-f", "%U %S", "-o", tf.name, str(cli), "eval", "--gt", str(mesh),
                            "--recon", str(cloud), "--samples", str(samples), "--threads", str(threads),
                            "--align", "none", "--quiet", "--report", str(report)], capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if p.returncode != 0:
            raise SystemExit(f"bench stages: sfmeval eval failed: {p.stderr[-800:]}")
        u, s = tf.read().split()[-2:]
    return wall, float(u) + float(s)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default=str(ROOT / "bench" / "data"))
    ap.add_argument("--mesh", default="mesh_1m.ply")
    ap.add_argument("--cloud", default="cloud_1m.ply")
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--markdown")
    args = ap.parse_args()
    quick_data = None
    if args.quick:
        args.mesh, args.cloud, args.samples, args.rounds = "mesh_50k.ply", "cloud_100k.ply", 100_000, 1
        quick_data = tempfile.TemporaryDirectory(prefix="sfmeval-stages-data-")
        args.data = quick_data.name
        subprocess.run([sys.executable, str(ROOT / "bench" / "generate.py"), "--quick", "--out", args.data],
                       check=True, capture_output=True)
    data = Path(args.data)
    mesh, cloud = data / args.mesh, data / args.cloud
    for f in (mesh, cloud):
        if not f.exists():
            raise SystemExit(f"bench stages: {f} is missing (bench/generate.py writes it)")
    release = ROOT / "target" / "release"
    bench_op, cli = release / "examples" / "bench_op", release / "sfmeval"
    for b in (bench_op, cli):
        if not b.exists():
            raise SystemExit(f"bench stages: {b} is missing (scripts/build-release.sh builds it)")

    times = {(name, t): [] for name, _ in STAGES + [("eval", "")] for t in (1, 2)}
    reports = {}
    with tempfile.TemporaryDirectory(prefix="sfmeval-stages-") as tmp:
        for _ in range(args.rounds):
            for threads in (1, 2):
                for name, _ in STAGES:
                    times[(name, threads)].append(run_op(bench_op, name, mesh, cloud, args.samples, threads))
                report = Path(tmp) / f"report-{threads}.json"
                times[("eval", threads)].append(run_eval(cli, mesh, cloud, args.samples, threads, report))
                reports[threads] = report.read_bytes()
    if reports[1] != reports[2]:
        raise SystemExit("bench stages: the reports at 1 and 2 threads differ")

    med = {k: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v)) for k, v in times.items()}
    load = os.getloadavg()
    rows = []
    for name, what in STAGES + [("eval", "whole `sfmeval eval` (process: reading, index, sampling, "
                                          "queries, statistics, report)")]:
        (w1, c1), (w2, c2) = med[(name, 1)], med[(name, 2)]
        undivided = max(0.0, 2 * w2 - w1)
        rows.append(f"| {what} | {w1:.3f} | {c1:.3f} | {w2:.3f} | {c2:.3f} | {w1 / w2:.2f}× | {undivided:.3f} |")
    text = (f"Stages of the whole evaluation: `{mesh.name}` against `{cloud.name}`, {args.samples} samples; "
            f"median of {args.rounds} round(s), thread counts alternated; load average at the end "
            f"{load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} on {os.cpu_count()} CPUs.\n\n"
            "| stage | wall, 1 thread (s) | CPU, 1 thread (s) | wall, 2 threads (s) | CPU, 2 threads (s) | "
            "speed-up | undivided 2·T₂ − T₁ (s) |\n|---|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n")
    print(text)
    if args.markdown:
        Path(args.markdown).write_text(text)


if __name__ == "__main__":
    sys.exit(main())
