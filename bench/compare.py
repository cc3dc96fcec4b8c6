#!/usr/bin/env python3
"""Side-by-side benchmark: sfmeval against every installed anchor (Open3D, trimesh+scipy,
point-cloud-utils, CloudCompare), operation by operation, on the same files, each run in its own
process, several rounds (a run over SLOW_S seconds is not repeated), median; prints one markdown
table per operation, ready for the README.

  scripts/bench.sh [options]            # from a fresh clone: installs the anchors, builds, generates data
  bench/compare.py [--quick] [--data DIR] [--rounds 3] [--sizes 10k,100k,1m] [--mesh 1m]
                   [--samples 1000000] [--align-size 100k] [--ops load,bvh,...] [--tools ...]
                   [--json out.json] [--markdown out.md]

Operations (same meaning for every tool, see bench/anchors/*.py and
crates/sfmeval/examples/bench_op.rs): load; bvh (mesh index build); kdtree (cloud index
build); accuracy (BVH build + exact distance of every point to the mesh); completeness (surface
samples + cloud index + nearest neighbour of every sample); c2c (cloud index + nearest neighbour
of a second, independently drawn cloud of the same size); align (scaled ICP from a perturbed
start, time and final error against the known transform); eval (the whole evaluation: the time
is the process's wall time, interpreter start-up included). "op s" is the time of the operation
measured inside the process, files already read (except load and eval); "peak MiB" the process's
peak resident memory. sfmeval runs with all cores and with one thread (the wasm comparison
base); anchors with all cores.

Agreement: sfmeval's numbers are the reference. Exact operations (accuracy, c2c) must agree
within ACC_TOL relative in the mean and 10 × ACC_TOL in the max (Open3D computes in float32),
completeness means (each tool draws its own samples) within COMP_TOL, load/index counts exactly;
align is judged by each tool's own error against the known transform (RMS displacement of the
ground truth's box corners, within ALIGN_OK of the diagonal: the clouds' noise level). A disagreeing tool is flagged and takes no part in
"fastest anchor"; the script exits 1 when any tool crashes or disagrees, or sfmeval's alignment
misses the truth by more than ALIGN_OK.

Dense rows (--dense, default 10m; `--dense 10m,100m` in the full run, `--dense ''` for none):
the whole eval only, on cloud_10m.ply / cloud_100m.ply (bench/generate.py --dense writes them
when missing), sfmeval with all threads against the --dense-tools anchors (default Open3D), one
round each, wall time and peak memory.

--quick (CI): 50k-triangle mesh and 10k points generated into a temporary directory, 10k
samples, one round, no CloudCompare ICP (a minute on its own), no dense rows.
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

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "bench" / "anchors"))
import cloudcompare  # noqa: E402
from generate import sample, write_ply  # noqa: E402

ACC_TOL = 1e-4       # relative, exact distances (float32 tools)
COMP_TOL = 0.03      # relative, completeness means from independent samplers
ALIGN_OK = 5e-3      # RMS displacement of the GT box corners after alignment / GT diagonal: the clouds' noise
GNU_TIME = "/usr/bin/time"  # Debian package `time`
SLOW_S = 60.0        # a run longer than this is not repeated (its row says "1 round")
OPS = ["load", "bvh", "kdtree", "accuracy", "completeness", "c2c", "align", "eval"]
SIZES = {"10k": 10_000, "100k": 100_000, "1m": 1_000_000, "10m": 10_000_000, "100m": 100_000_000}
DENSE = ("10m", "100m")  # eval-only sizes: no moved cloud, no c2c queries
PY_ANCHORS = {"Open3D": "open3d_ops.py", "trimesh+scipy": "trimesh_ops.py", "point-cloud-utils": "pcu_ops.py"}
ANCHORS = list(PY_ANCHORS) + ["CloudCompare"]
# The perturbed alignment start: the known gt_from_recon followed (in the ground-truth frame) by
# a 4° rotation about (1, 1, 1), a scale of 1.03 and a shift of 1 % of the diagonal along (1, -1, 0.5).
PERTURB_DEG, PERTURB_SCALE, PERTURB_SHIFT = 4.0, 1.03, 0.01

TITLES = {
    "load": "read and parse the mesh and the cloud",
    "bvh": "build the mesh's closest-point index",
    "kdtree": "build the cloud's nearest-neighbour index",
    "accuracy": "cloud → mesh, exact distance of every point (index build included)",
    "completeness": "mesh samples → cloud, nearest-neighbour distance (sampling and index build included)",
    "c2c": "cloud → cloud, nearest-neighbour distance of every query point (index build included)",
    "align": "scaled ICP from the perturbed start (final error against the known transform)",
    "eval": "whole evaluation (load, accuracy, completeness, statistics); time = process wall time",
}


def run_with_peak(cmd, env=None, cwd=None):
    """Runs cmd; returns (wall seconds, peak RSS MiB, exit code, stdout, stderr). The peak comes
    from GNU time (`/usr/bin/time -f %M`): a child forked from this Python process would inherit
    its resident size in ru_maxrss."""
    with tempfile.NamedTemporaryFile("r") as tf:
        t0 = time.perf_counter()
        p = subprocess.run([GNU_TIME, "-f", "%M", "-o", tf.name, *cmd], capture_output=True, env=env, cwd=cwd)
        wall = time.perf_counter() - t0
        lines = tf.read().split()
        peak = int(lines[-1]) / 1024.0 if lines and lines[-1].isdigit() else float("nan")
    return wall, peak, p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")


class Failed(Exception):
    pass


def last_json(stdout):
    lines = [l for l in stdout.splitlines() if l.startswith("{")]
    if not lines:
        raise Failed("no JSON on stdout: " + stdout[-500:])
    return json.loads(lines[-1])


def measure_cloudcompare(op, ctx, rounds):
    """CloudCompare's op: (op run − load-only run) of its own "Processed finished" times, then one
    untimed run that saves the distances. None when CloudCompare has no such op."""
    if op not in cloudcompare.OPS:
        return None
    f, cwd, env = ctx["files"], ctx["work"], cloudcompare.env()
    base, cmd, save = cloudcompare.commands(op, f, ctx["samples"])
    for old in list(Path(cwd).glob("*.asc")) + list(Path(cwd).glob("*_REGISTRATION_MATRIX.txt")):
        old.unlink()
    secs, walls, peaks = [], [], []
    for _ in range(rounds):
        base_s = 0.0
        if base:
            _, _, rc, out, err = run_with_peak(base, env, cwd)
            if rc != 0:
                raise Failed(f"load-only run exit {rc}: {(err or out)[-500:]}")
            base_s = cloudcompare.finished_seconds(out)
        w, peak, rc, out, err = run_with_peak(cmd, env, cwd)
        if rc != 0:
            raise Failed(f"exit {rc}: {(err or out)[-500:]}")
        secs.append(cloudcompare.finished_seconds(out) - base_s)
        walls.append(w), peaks.append(peak)
        if w > SLOW_S:
            break
    if op == "load":
        result = cloudcompare.load_result(out)
    else:
        if save:
            _, _, rc, out, err = run_with_peak(cmd + save, env, cwd)
            if rc != 0:
                raise Failed(f"saving run exit {rc}: {(err or out)[-500:]}")
        result = cloudcompare.result(op, f, Path(cwd))
    return dict(seconds=statistics.median(secs), wall=statistics.median(walls), peak=max(peaks), result=result,
                rounds=len(secs))


def measure(tool, op, ctx, rounds):
    """Runs one tool's op `rounds` times. Returns a row dict, or None when unsupported."""
    if tool == "CloudCompare":
        return measure_cloudcompare(op, ctx, rounds)
    f = ctx["files"]
    env = dict(os.environ)
    threads = ctx["threads"]
    if tool.startswith("sfmeval"):
        threads = 1 if tool.endswith("1 thread") else ctx["threads"]
        if op == "eval":
            report = Path(ctx["work"]) / f"report-{threads}.json"
            cmd = [ctx["cli"], "eval", "--gt", f["mesh"], "--recon", f["cloud"], "--samples", str(ctx["samples"]),
                   "--threads", str(threads), "--align", "none", "--quiet", "--report", str(report)]
        else:
            cmd = [ctx["bench_op"], op, "--mesh", f["mesh"], "--cloud", f["moved"] if op == "align" else f["cloud"],
                   "--queries", f["queries"], "--start", f["start"], "--samples", str(ctx["samples"]),
                   "--threads", str(threads)]
    else:
        env["OMP_NUM_THREADS"] = str(threads)
        cmd = [sys.executable, str(ROOT / "bench" / "anchors" / PY_ANCHORS[tool]), op, "--mesh", f["mesh"],
               "--cloud", f["moved"] if op == "align" else f["cloud"], "--queries", f["queries"], "--start", f["start"],
               "--samples", str(ctx["samples"]), "--threads", str(threads)]
    secs, walls, peaks = [], [], []
    for _ in range(rounds):
        w, peak, rc, out, err = run_with_peak(cmd, env, ctx["work"])
        if rc == 3:
            return None
        if rc != 0:
            raise Failed(f"exit {rc}: {(err or out)[-800:]}")
        if tool.startswith("sfmeval") and op == "eval":
            r = json.loads(report.read_text())
            result = {k: {"n": r[k]["count"], "mean": r[k]["mean"], "max": r[k]["max"]} for k in ("accuracy", "completeness")}
            secs.append(w)
        else:
            j = last_json(out)
            result = j["result"]
            secs.append(w if op == "eval" else j["seconds"])
        walls.append(w), peaks.append(peak)
        if w > SLOW_S:
            break
    return dict(seconds=statistics.median(secs), wall=statistics.median(walls), peak=max(peaks), result=result,
                rounds=len(secs))


# ---- agreement ------------------------------------------------------------------------------

def rel(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


def transform_error(m, truth, corners, diag):
    """(rotation error °, scale error, RMS displacement of the GT box corners / diagonal)."""
    e = np.asarray(m) @ np.linalg.inv(truth)
    a = e[:3, :3]
    s = np.cbrt(np.linalg.det(a))
    r = a / s
    angle = np.degrees(np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1)))
    moved = corners @ a.T + e[:3, 3]
    rms = np.sqrt(((moved - corners) ** 2).sum(1).mean()) / diag
    return float(angle), float(s - 1), float(rms)


def judge(op, row, ref, ctx):
    """(agrees: bool, text) of one row against sfmeval's."""
    res = row["result"]
    if op == "align":
        ang, ds, rms = transform_error(res["matrix"], ctx["truth"], ctx["corners"], ctx["diag"])
        row["error"] = dict(rotation_deg=ang, scale=ds, rms_of_diagonal=rms)
        ok = rms <= ALIGN_OK
        return ok, f"{ang:.3f}°, scale {ds * 100:+.3f} %, RMS {rms * 100:.4f} % of diag" + ("" if ok else " ✗ misaligned")
    if ref is None:
        return True, "reference"
    if op in ("load", "bvh", "kdtree"):
        diff = [k for k in res if k in ref and res[k] != ref[k]]
        return (not diff), ("✓ same counts" if not diff else "✗ " + ", ".join(f"{k} {res[k]} vs {ref[k]}" for k in diff))
    if op == "eval":
        a, c = rel(res["accuracy"]["mean"], ref["accuracy"]["mean"]), rel(res["completeness"]["mean"], ref["completeness"]["mean"])
        ok = a <= ACC_TOL and c <= COMP_TOL
        return ok, f"{'✓' if ok else '✗'} accuracy mean {a:.1e}, completeness mean {c * 100:.2f} %"
    m, x = rel(res["mean"], ref["mean"]), rel(res["max"], ref["max"])
    if op == "completeness":
        ok = m <= COMP_TOL
        return ok, f"{'✓' if ok else '✗'} mean {m * 100:.2f} %"
    ok = m <= ACC_TOL and x <= 10 * ACC_TOL
    return ok, f"{'✓' if ok else '✗'} mean {m:.1e}, max {x:.1e}"


def result_text(op, res):
    if op == "eval":
        return f"{res['accuracy']['mean']:.6g} / {res['completeness']['mean']:.6g}"
    if op in ("accuracy", "completeness", "c2c"):
        return f"{res['mean']:.6g} / {res['max']:.6g}"
    if op == "load":
        return f"{res.get('triangles')} triangles, {res.get('points')} points"
    if op == "bvh":
        return f"{res.get('triangles')} triangles"
    if op == "kdtree":
        return f"{res.get('points')} points"
    return ""


# ---- workload -------------------------------------------------------------------------------

def rotation(axis, deg):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    a = np.radians(deg)
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k


def prepare(data, mesh_name, size, work, ctx):
    """Symlinks the inputs into `work` (CloudCompare writes next to its inputs), draws the query
    cloud of c2c and writes the perturbed start."""
    import trimesh
    work.mkdir(parents=True, exist_ok=True)
    files = {"mesh": f"mesh_{mesh_name}.ply", "cloud": f"cloud_{size}.ply", "moved": f"cloud_{size}_moved.ply",
             "queries": f"queries_{size}.ply", "start": "start.txt"}
    dense = size in DENSE
    if dense and not (data / files["cloud"]).exists():
        subprocess.run([sys.executable, str(ROOT / "bench" / "generate.py"), "--out", str(data), "--dense", size],
                       check=True, stdout=subprocess.DEVNULL)
    for k in ("mesh", "cloud") if dense else ("mesh", "cloud", "moved"):
        link = work / files[k]
        if not link.exists():
            link.symlink_to((data / files[k]).resolve())
    if "mesh" not in ctx:
        m = trimesh.load(data / files["mesh"], process=False, force="mesh")
        v = np.asarray(m.vertices, np.float64)
        lo, hi = v.min(0), v.max(0)
        ctx["mesh"] = (v, np.asarray(m.faces))
        ctx["diag"] = float(np.linalg.norm(hi - lo))
        ctx["corners"] = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        ctx["truth"] = np.loadtxt(data / "gt_from_recon.txt", comments="#").reshape(4, 4)
    v, fa = ctx["mesh"]
    if not dense and not (work / files["queries"]).exists():
        rng = np.random.default_rng(7)
        n = SIZES.get(size) or len(trimesh.load(data / files["cloud"]).vertices)
        q = sample(v, fa, n, rng) + rng.normal(scale=0.005 * ctx["diag"], size=(n, 3))
        write_ply(work / files["queries"], q)
    p = np.eye(4)
    p[:3, :3] = PERTURB_SCALE * rotation([1, 1, 1], PERTURB_DEG)
    p[:3, 3] = PERTURB_SHIFT * ctx["diag"] * np.array([1, -1, 0.5]) / np.linalg.norm([1, -1, 0.5])
    np.savetxt(work / files["start"], p @ ctx["truth"], fmt="%.17g")
    ctx["files"] = files  # names inside `work`, every tool runs there
    ctx["work"] = str(work)


def installed_anchors(wanted):
    """The wanted anchors that are installed; each one that is not is named on stderr as
    "skipped: ..." (scripts/test.sh counts those lines as skipped tests)."""
    out = []
    for name, script in PY_ANCHORS.items():
        mod = {"Open3D": "open3d", "trimesh+scipy": "trimesh", "point-cloud-utils": "point_cloud_utils"}[name]
        if name not in wanted:
            continue
        if subprocess.run([sys.executable, "-c", f"import {mod}"], capture_output=True).returncode == 0:
            out.append(name)
        else:
            print(f"skipped: anchor {name}: Python module {mod} not importable", file=sys.stderr)
    if "CloudCompare" in wanted:
        if cloudcompare.available():
            out.append("CloudCompare")
        else:
            print(f"skipped: anchor CloudCompare: {cloudcompare.BINARY} not on PATH", file=sys.stderr)
    return out


def build(skip):
    if skip:
        return
    # bench_op and the CLI, with the features every other release build of the tests resolves
    subprocess.run([str(ROOT / "scripts" / "build-release.sh")], cwd=ROOT, check=True)


# ---- main -----------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="CI mode: tiny generated data, one round")
    ap.add_argument("--data", default=str(ROOT / "bench" / "data"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--sizes", default="10k,100k,1m")
    ap.add_argument("--mesh", default="1m")
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--align-size", default="100k")
    ap.add_argument("--ops", default=",".join(OPS))
    ap.add_argument("--tools", default=",".join(ANCHORS), help="anchors to run when installed")
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--dense", default="10m", help="eval-only dense rows: 10m, 100m (comma-separated, '' for none)")
    ap.add_argument("--dense-tools", default="Open3D", help="anchors that run the dense rows")
    ap.add_argument("--slow-max", type=int, default=10_000,
                    help="trimesh accuracy/eval only up to this many points (closest_point is very slow)")
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--json", help="write every measurement here")
    ap.add_argument("--markdown", help="also write the tables here")
    args = ap.parse_args()

    tmp = tempfile.TemporaryDirectory(prefix="sfmeval-bench-")
    data = Path(args.data)
    if args.quick:
        data = Path(tmp.name) / "data"
        subprocess.run([sys.executable, str(ROOT / "bench" / "generate.py"), "--quick", "--out", str(data)],
                       check=True, stdout=subprocess.DEVNULL)
        args.rounds, args.sizes, args.mesh, args.samples, args.align_size = 1, "10k", "50k", 10_000, "10k"
        args.dense = ""
    build(args.no_build)
    anchors = installed_anchors(args.tools.split(","))
    tools = ["sfmeval", "sfmeval 1 thread"] + anchors
    ctx = {"threads": args.threads, "samples": args.samples,
           "bench_op": str(ROOT / "target" / "release" / "examples" / "bench_op"),
           "cli": str(ROOT / "target" / "release" / "sfmeval")}
    ops = args.ops.split(",")
    sizes = args.sizes.split(",")
    plan = []  # (op, size)
    for op in ops:
        if op == "bvh":
            plan.append((op, sizes[-1]))
        elif op == "align":
            plan.append((op, args.align_size))
        else:
            plan += [(op, s) for s in sizes]
    dense = [d for d in args.dense.split(",") if d]
    if "eval" in ops:
        plan += [("eval", d) for d in dense]

    print(f"bench: tools {', '.join(tools)}; {args.threads} threads; {args.rounds} round(s); data {data}", file=sys.stderr)
    failures, sections, records = [], [], []
    for op, size in plan:
        prepare(data, args.mesh, size, Path(tmp.name) / size, ctx)
        n = SIZES.get(size, size)
        rows = {}
        for tool in tools:
            if tool == "trimesh+scipy" and op in ("accuracy", "eval") and isinstance(n, int) and n > args.slow_max:
                continue
            if size in DENSE and (tool == "sfmeval 1 thread" or
                                  (not tool.startswith("sfmeval") and tool not in args.dense_tools.split(","))):
                continue
            if tool == "CloudCompare" and op == "align" and args.quick:
                continue  # ~100 C2M passes: a minute even on the quick data
            print(f"bench: {op} {size} {tool} ...", file=sys.stderr, flush=True)
            try:
                row = measure(tool, op, ctx, 1 if size in DENSE else args.rounds)
            except Exception as e:  # noqa: BLE001 - a crashing tool is a row, not the end of the run
                row = {"crash": str(e)[:300]}
                failures.append(f"{op} {size} {tool}: crashed: {str(e)[:300]}")
            if row is not None:
                rows[tool] = row
        ref = rows.get("sfmeval", {}).get("result")
        for tool, row in rows.items():
            if "crash" in row:
                continue
            ok, text = judge(op, row, ref if tool != "sfmeval" else None, ctx)
            row["agrees"], row["agreement"] = ok, text
            if not ok and (op != "align" or tool.startswith("sfmeval")):
                failures.append(f"{op} {size} {tool}: {text}")
        # sfmeval is only trusted when some anchor agrees with it
        agreeing = [t for t in anchors if rows.get(t, {}).get("agrees")]
        if op not in ("align",) and "sfmeval" in rows and "crash" not in rows["sfmeval"] and anchors and not agreeing \
                and any(t in rows for t in anchors):
            rows["sfmeval"]["agreement"] = "✗ no anchor agrees"
            failures.append(f"{op} {size}: no anchor agrees with sfmeval")
        fastest = min((rows[t]["seconds"] for t in agreeing), default=None)
        if op == "align":
            good = [t for t in anchors if t in rows and rows[t].get("agrees")]
            fastest = min((rows[t]["seconds"] for t in good), default=None)
        sections.append(table(op, size, n, rows, fastest, ctx, args))
        records.append({"op": op, "size": size, "rows": rows})
    if "accuracy" in ops:
        sections.append(physical_limit(ctx, sizes[-1], args, data, tmp))

    text = header(args, tools) + "\n\n".join(sections) + "\n"
    print(text)
    if args.markdown:
        Path(args.markdown).write_text(text)
    if args.json:
        Path(args.json).write_text(json.dumps({"args": vars(args), "tools": tools, "results": records}, indent=1, default=str))
    if failures:
        print("bench: FAILED\n  " + "\n  ".join(failures), file=sys.stderr)
        sys.exit(1)
    print("bench: every tool ran and agreed", file=sys.stderr)


def header(args, tools):
    return (f"Mesh `mesh_{args.mesh}`, {args.samples} completeness samples, {args.threads} threads "
            f"(sfmeval also with 1), median of {args.rounds} round(s), each in its own process. "
            f"Tools: {', '.join(tools)}.\n\n")


def table(op, size, n, rows, fastest, ctx, args):
    files = ctx["files"]
    what = {"bvh": files["mesh"], "align": f"{files['moved']} → {files['mesh']}"}.get(op, f"{files['cloud']} vs {files['mesh']}")
    if op == "c2c":
        what = f"{files['queries']} → {files['cloud']}"
    head = f"#### {op}: {TITLES[op]}\n\n`{what}`\n\n"
    res_col = {"align": "final error vs known transform", "eval": "accuracy / completeness mean",
               "accuracy": "mean / max", "completeness": "mean / max", "c2c": "mean / max"}.get(op, "result")
    lines = [f"| tool | {'wall s' if op == 'eval' else 'op s'} | process s | peak MiB | ÷ fastest anchor | {res_col} | agreement |",
             "|---|---|---|---|---|---|---|"]
    for tool, r in rows.items():
        if "crash" in r:
            lines.append(f"| {tool} | crashed | | | | | ✗ {r['crash'][:120]} |")
            continue
        ratio = f"{r['seconds'] / fastest:.2f}×" if fastest else "—"
        res = r["agreement"] if op == "align" else result_text(op, r["result"])
        agree = ("✓" if r["agrees"] else "✗") if op == "align" else r["agreement"]
        once = " (1 round)" if r["rounds"] < args.rounds else ""
        lines.append(f"| {tool} | {r['seconds']:.3f}{once} | {r['wall']:.2f} | {r['peak']:.0f} | {ratio} | {res} | {agree} |")
    return head + "\n".join(lines)


def physical_limit(ctx, size, args, data, tmp):
    """sfmeval's accuracy against (triangle tests per query × cost per test) + streaming."""
    prepare(data, args.mesh, size, Path(tmp.name) / size, ctx)
    f = ctx["files"]
    _, _, rc, out, err = run_with_peak([ctx["bench_op"], "cost", "--mesh", f["mesh"], "--cloud", f["cloud"], "--threads", "1"],
                                       None, ctx["work"])
    if rc != 0:
        return f"(physical-limit estimate unavailable: {err[-200:]})"
    c = last_json(out)["result"]
    n = SIZES.get(size) or 0
    est = n * (c["triangle_tests_per_query_lower_bound"] * c["seconds_per_triangle_test"] + c["seconds_per_streamed_point"])
    return (f"Physical-limit estimate for accuracy, {size} points, one thread: {n} queries × "
            f"{c['triangle_tests_per_query_lower_bound']:.1f} point-triangle tests (lower bound: triangles whose box is "
            f"nearer than the answer) × {c['seconds_per_triangle_test'] * 1e9:.1f} ns + streaming "
            f"{c['seconds_per_streamed_point'] * 1e9:.2f} ns/point ≈ {est:.3f} s "
            f"(÷ {args.threads} threads ≈ {est / args.threads:.3f} s) for the queries; the index build is the bvh table.")


if __name__ == "__main__":
    main()
