"""How the package runs the core, with the built wheel installed: the `threads=` pool, the
progress callback, Ctrl-C, two evaluations in two Python threads at once, and the memory of a
10M-point array against the CLI's on the same points.

SFMEVAL_BIN: the CLI (default target/release/sfmeval).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import sfmeval

ROOT = Path(__file__).resolve().parents[3]
BIN = Path(os.environ.get("SFMEVAL_BIN", ROOT / "target/release/sfmeval"))
DEMO = ROOT / "data/demo"
DEMO_ARGS = dict(gt=DEMO / "ground_truth.glb", recon=DEMO / "sparse",
                 gt_cameras=DEMO / "cameras.json")


def test_threads_give_the_same_report_and_zero_is_refused():
    one = sfmeval.evaluate(**DEMO_ARGS, samples=200_000, threads=1)
    two = sfmeval.evaluate(**DEMO_ARGS, samples=200_000, threads=2)
    every = sfmeval.evaluate(**DEMO_ARGS, samples=200_000)
    assert one.to_json() == two.to_json() == every.to_json()
    with pytest.raises(sfmeval.InputError, match="threads"):
        sfmeval.evaluate(**DEMO_ARGS, threads=0)


def test_threads_is_the_size_of_the_calls_pool():
    # the hooks run on the threads of the call's pool (install runs the call on one of them)
    def callers(threads):
        ids = set()
        sfmeval.evaluate(**DEMO_ARGS, threads=threads,
                         progress=lambda s, f: ids.add(threading.get_native_id()))
        return ids
    assert threading.get_native_id() not in callers(1)
    assert len(callers(1)) == 1
    assert len(callers(2)) == 2


def test_one_thread_is_slower_than_two():
    # the pool of the call is the call's: one worker takes longer than two (2 cores here)
    def timed(threads):
        t = time.perf_counter()
        sfmeval.evaluate(**DEMO_ARGS, threads=threads)
        return time.perf_counter() - t
    timed(2)
    one, two = min(timed(1) for _ in range(2)), min(timed(2) for _ in range(2))
    assert two < 0.9 * one, (one, two)


def test_two_evaluations_in_two_python_threads_overlap():
    # one worker each: with the GIL released, two run at once on the two cores. Timed up to
    # three times (a machine shared with other work can stall one measurement); one pair of
    # measurements under 0.9 passes
    def one():
        r = sfmeval.evaluate(**DEMO_ARGS, threads=1)
        assert r.accuracy.count == 2529

    def measure():
        start = time.perf_counter()
        one()
        one()
        serial = time.perf_counter() - start
        pair = [threading.Thread(target=one) for _ in range(2)]
        start = time.perf_counter()
        for t in pair:
            t.start()
        for t in pair:
            t.join()
        return serial, time.perf_counter() - start

    one()
    tries = []
    for _ in range(3):
        serial, concurrent = measure()
        tries.append((round(serial, 2), round(concurrent, 2)))
        print(f"serial {serial:.2f} s, two threads {concurrent:.2f} s ({concurrent / serial:.2f})")
        if concurrent < 0.9 * serial:
            break
    assert concurrent < 0.9 * serial, tries


def test_progress_reports_every_stage_from_start_to_end():
    calls = []
    r = sfmeval.evaluate(**DEMO_ARGS, progress=lambda stage, f: calls.append((stage, f)))
    stages = list(dict.fromkeys(s for s, _ in calls))
    # the CLI's bar labels, in the pipeline's order
    assert stages[:2] == ["indexing ground truth", "sampling GT surface"]
    assert "aligning" in stages and "completeness (GT → recon)" in stages
    for stage in stages:
        fractions = [f for s, f in calls if s == stage]
        assert fractions[0] == 0.0 and fractions[-1] == 1.0, (stage, fractions)
        assert all(0.0 <= f <= 1.0 for f in fractions)
    # 1 % steps in the long stages, not a call per point
    assert 10 < len([f for s, f in calls if s.startswith("completeness")]) <= 102
    assert r.to_json() == sfmeval.evaluate(**DEMO_ARGS).to_json()


def test_an_exception_in_the_progress_callback_stops_the_evaluation():
    class Stop(Exception):
        pass

    seen = []

    def progress(stage, fraction):
        seen.append(stage)
        if stage == "aligning":
            raise Stop(stage)

    with pytest.raises(Stop, match="aligning"):
        sfmeval.evaluate(**DEMO_ARGS, progress=progress)
    assert seen[-1] == "aligning" and "completeness (GT → recon)" not in seen
    # and the package goes on working
    assert sfmeval.evaluate(**DEMO_ARGS, samples=10_000).accuracy.count == 2529


def test_dtu_has_the_threads_and_progress_of_the_other_verbs():
    dtu = ROOT / "tests/fixtures/dtu"
    args = (dtu, 1, dtu / "mesh.ply")
    calls = []
    r = sfmeval.dtu(*args, threads=1, progress=lambda stage, f: calls.append((stage, f)))
    stages = list(dict.fromkeys(s for s, _ in calls))
    assert stages == ["indexing ground truth", "accuracy (recon → GT)",
                      "indexing reconstruction", "completeness (GT → recon)"], stages
    for stage in stages:
        fractions = [f for s, f in calls if s == stage]
        assert fractions[0] == 0.0 and fractions[-1] == 1.0, (stage, fractions)
    assert len([f for s, f in calls if s.startswith("accuracy")]) > 10
    assert r.to_json() == sfmeval.dtu(*args, threads=2).to_json()

    class Stop(Exception):
        pass

    def stop(stage, fraction):
        if stage.startswith("accuracy"):
            raise Stop(stage)

    with pytest.raises(Stop):
        sfmeval.dtu(*args, progress=stop)
    with pytest.raises(sfmeval.InputError, match="threads"):
        sfmeval.dtu(*args, threads=0)


CHILD = """
import signal, sys, time, sfmeval
# Python's own Ctrl-C handler even where the parent left SIGINT ignored (a shell's background
# job inherits SIG_IGN, and Python then installs no handler)
signal.signal(signal.SIGINT, signal.default_int_handler)
args = dict(gt=sys.argv[1], recon=sys.argv[2], gt_cameras=sys.argv[3], samples=3_000_000,
            threads=1)
stages = []
if sys.argv[4] == "full":
    t = time.perf_counter()
    sfmeval.evaluate(**args)
    print("finished", time.perf_counter() - t, flush=True)
    sys.exit(0)
print("go", flush=True)
t = time.perf_counter()
try:
    sfmeval.evaluate(**args, progress=lambda s, f: stages.append(s))
    print("finished", time.perf_counter() - t, flush=True)
except KeyboardInterrupt:
    print("interrupted", time.perf_counter() - t, stages[-1], flush=True)
    print("again", sfmeval.evaluate(**{**args, "samples": 10_000}).accuracy.count, flush=True)
"""


def test_ctrl_c_stops_a_long_evaluation():
    argv = [sys.executable, "-c", CHILD, str(DEMO / "ground_truth.glb"), str(DEMO / "sparse"),
            str(DEMO / "cameras.json")]
    full = subprocess.run(argv + ["full"], capture_output=True, text=True, check=True)
    full_s = float(full.stdout.split()[1])
    child = subprocess.Popen(argv + ["interrupt"], stdout=subprocess.PIPE, text=True)
    assert child.stdout is not None
    assert child.stdout.readline().strip() == "go"
    time.sleep(0.5)
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=60)
    waited = time.perf_counter() - sent
    lines = out.splitlines()
    print(f"full evaluation {full_s:.2f} s; interrupted after {lines[0]}, {waited:.2f} s after Ctrl-C")
    assert lines[0].startswith("interrupted"), out
    assert float(lines[0].split()[1]) < 0.5 * full_s, (full_s, out)
    # at the core's next hook: at most 1 % of a stage (sampling reports at its end), so a
    # fraction of the whole
    assert waited < 0.3 * full_s, (full_s, waited)
    assert lines[1] == "again 2529"


MEMORY_CHILD = """
import sys, numpy as np, sfmeval
def status(key):  # KiB; VmHWM is this process's own peak (ru_maxrss can start at the parent's)
    with open("/proc/self/status") as f:
        return next(int(l.split()[1]) for l in f if l.startswith(key + ":"))
points = np.load(sys.argv[2])
before = status("VmRSS")  # the array's pages in
r = sfmeval.evaluate(sys.argv[1], points, align="none", samples=100_000, name="points.ply")
print(before, status("VmHWM"), r.accuracy.count)
"""

CLI_CHILD = """
import resource, subprocess, sys
subprocess.run(sys.argv[1:], check=True)
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)  # the CLI's peak (KiB)
"""


def test_a_10m_point_array_costs_the_memory_of_the_clis_evaluation(tmp_path):
    n = 10_000_000
    rng = np.random.default_rng(1)
    mesh = sfmeval.read(DEMO / "ground_truth.glb")
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    points = lo + rng.random((n, 3)) * (hi - lo)
    np.save(tmp_path / "points.npy", points)
    ply = tmp_path / "points.ply"
    with open(ply, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty double x\n"
                f"property double y\nproperty double z\nend_header\n".encode())
        f.write(points.astype("<f8").tobytes())
    del points
    report = tmp_path / "cli.json"
    cli = subprocess.run([sys.executable, "-c", CLI_CHILD, str(BIN), "eval", "--gt",
                          str(DEMO / "ground_truth.glb"), "--recon", str(ply), "--align", "none",
                          "--samples", "100000", "--quiet", "--report", str(report)],
                         capture_output=True, text=True, check=True)
    cli_kib = int(cli.stdout.split()[-1])
    py = subprocess.run([sys.executable, "-c", MEMORY_CHILD, str(DEMO / "ground_truth.glb"),
                         str(tmp_path / "points.npy")], capture_output=True, text=True, check=True)
    before_kib, peak_kib, count = map(int, py.stdout.split())
    assert count == json.loads(report.read_text())["accuracy"]["count"] == n
    # the array (240 MB) is the caller's, before the call; the call's own growth is the CLI's
    # whole evaluation: reading the points into the core's storage once, then the core
    growth = peak_kib - before_kib
    assert peak_kib > before_kib
    print(f"CLI peak {cli_kib / 1024:.0f} MiB; Python: {before_kib / 1024:.0f} MiB with the "
          f"array, peak {peak_kib / 1024:.0f} MiB, growth {growth / 1024:.0f} MiB "
          f"({growth / cli_kib:.3f} of the CLI's)")
    assert growth < 1.10 * cli_kib, (cli_kib, before_kib, peak_kib)
