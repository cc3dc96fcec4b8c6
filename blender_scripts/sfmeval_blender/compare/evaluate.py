"""The measurements, all through the ``sfmeval`` binary: alignment (``sfmeval align``, also ICP
from a given start), evaluation of the points the user kept (``sfmeval eval --align given``
with the object's matrix, the crop file, the run's model for the cameras), viridis colours with
the CLI's clip rule, and Table I in the runner's format (native_runner/src/table/mod.rs)."""

import csv
import decimal
import json
import os
import subprocess

import numpy as np

# crates/sfmeval/src/colormap.rs
VIRIDIS = np.array([[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
                    [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]], dtype=float)


def viridis(t):
    """Colours (N, 3) uint8 of t in [0, 1] (clamped, NaN → top), as colormap.rs computes them."""
    t = np.asarray(t, dtype=float)
    t = np.where(np.isnan(t), 1.0, np.clip(t, 0.0, 1.0))
    x = t * (len(VIRIDIS) - 1)
    i = np.minimum(np.floor(x).astype(int), len(VIRIDIS) - 2)
    f = (x - i)[..., None]
    c = VIRIDIS[i] + (VIRIDIS[i + 1] - VIRIDIS[i]) * f
    # Rust's f64::round rounds half away from zero; the values are ≥ 0.
    return np.floor(c + 0.5).astype(np.uint8)


def distance_colors(d, clip):
    """colormap.rs `distance_color`: viridis(d / clip), the top colour when clip ≤ 0."""
    d = np.asarray(d, dtype=float)
    if clip > 0:
        return viridis(d / clip)
    return viridis(np.ones_like(d))


def color_clip(report):
    """The CLI's default clip (`--color-clip`): the accuracy p95."""
    return report["accuracy"]["percentiles"]["p95"]


class CliError(RuntimeError):
    """The sfmeval binary failed; the message holds its stderr."""


def _run(argv, timeout=600):
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        msg = (proc.stderr.strip() or proc.stdout.strip())[-800:]
        raise CliError("%s %s failed: %s" % (os.path.basename(argv[0]), argv[1], msg))
    return proc


def write_transform(path, m):
    """A gt_from_recon file: 16 numbers, row-major, exact (as ``sfmeval align --out`` writes)."""
    m = np.asarray(m, dtype=float).reshape(4, 4)
    text = "# gt_from_recon (Blender object matrix)\n" + "".join(
        " ".join("%.17e" % v for v in row) + "\n" for row in m)
    with open(path, "w") as f:
        f.write(text)


def inputs(dataset, recon, recon_cameras=None, gt=None):
    """The input flags of align/eval."""
    args = ["--dataset", dataset, "--recon", recon]
    if recon_cameras:
        args += ["--recon-cameras", recon_cameras]
    if gt:
        args += ["--gt", gt]
    return args


def align(sfmeval, dataset, recon, work, mode="auto", start=None, recon_cameras=None, gt=None):
    """``sfmeval align``: the alignment section (dict with gt_from_recon, method, scale, ...).
    `start` (4×4) is the ICP start for mode "icp"."""
    os.makedirs(work, exist_ok=True)
    out = os.path.join(work, "alignment.json")
    argv = [sfmeval, "align"] + inputs(dataset, recon, recon_cameras, gt) + ["--align", mode,
                                                                            "--out", out]
    if start is not None:
        tpath = os.path.join(work, "icp_start.txt")
        write_transform(tpath, start)
        argv += ["--transform", tpath]
    _run(argv)
    with open(out) as f:
        return json.load(f)


def rotation_scale_change(a, b):
    """(degrees, relative scale change) from similarity `a` to `b` (4×4)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    sa, sb = np.cbrt(np.linalg.det(a[:3, :3])), np.cbrt(np.linalg.det(b[:3, :3]))
    r = (a[:3, :3] / sa).T @ (b[:3, :3] / sb)
    c = min(1.0, max(-1.0, (np.trace(r) - 1) / 2))
    return float(np.degrees(np.arccos(c))), float(sb / sa - 1)


def eval_argv(sfmeval, dataset, points, transform, report, recon_cameras=None, crop=None,
              csv_out=None, gt=None):
    """The ``sfmeval eval`` command of the panel's numbers (also what a user types to get them)."""
    argv = [sfmeval, "eval"] + inputs(dataset, points, recon_cameras, gt) + [
        "--align", "given", "--transform", transform, "--report", report, "--quiet"]
    if crop:
        argv += ["--crop", crop]
    if csv_out:
        argv += ["--csv", csv_out]
    return argv


def evaluate(sfmeval, dataset, points, transform, report, recon_cameras=None, crop=None,
             csv_out=None, gt=None):
    """Runs ``eval_argv``; returns (report dict, per-point distances, per-point status)."""
    _run(eval_argv(sfmeval, dataset, points, transform, report, recon_cameras, crop, csv_out, gt))
    with open(report) as f:
        rep = json.load(f)
    dist, status = None, None
    if csv_out:
        dist, status = read_distances(csv_out)
    return rep, dist, status


def read_distances(path):
    """distance and status columns of ``sfmeval eval --csv`` (one row per input point)."""
    d, s = [], []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            d.append(float(row["distance"]))
            s.append(row["status"])
    return np.array(d), s


def points_in_gt(path):
    """x, y, z (GT frame) of ``sfmeval eval --csv``."""
    with open(path, newline="") as f:
        return np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in csv.DictReader(f)])


def _get(d, *keys):
    for k in keys:
        if not isinstance(d, dict) or d.get(k) is None:
            return None
        d = d[k]
    return d


def f_at(report, percent=1.0):
    """F-score at the threshold of `percent` % of the diagonal (None when not measured)."""
    for t in report.get("thresholds") or []:
        rel = t.get("tau_percent_of_diagonal")
        if rel is not None and abs(float(rel) - percent) < 1e-9:
            return t.get("f_score")
    return None


def summary(report):
    """The panel's row of a report (sfmeval.report/2): images registered / in the ground truth,
    points kept (after the crop), accuracy statistics, completeness (mean GT → reconstruction
    distance), F at 1 % of the diagonal, camera ATE (RMSE of the centres)."""
    acc = report.get("accuracy") or {}
    return {
        "registered": _get(report, "cameras", "registered"),
        "images": _get(report, "cameras", "ground_truth"),
        "input_points": _get(report, "inputs", "reconstruction", "points"),
        "points": _get(report, "crop", "kept"),
        "min": acc.get("min"), "max": acc.get("max"), "mean": acc.get("mean"),
        "median": acc.get("median"), "std": acc.get("std"),
        "completeness": _get(report, "completeness", "mean"),
        "f1": f_at(report, 1.0),
        "ate": _get(report, "cameras", "ate_rmse"),
    }


def rust_num(x):
    """A float as Rust's `{}` Display prints it (shortest round trip, never an exponent)."""
    if x is None:
        return ""
    r = repr(float(x))
    if "e" in r or "E" in r:
        r = format(decimal.Decimal(r), "f")
    if r.endswith(".0"):
        r = r[:-2]
    return r


def _csv_field(s):
    return '"%s"' % s.replace('"', '""') if any(c in s for c in ',"\n') else s


def table_order(rows, builtin):
    """The runner's column order (table/order.rs): the built-in pipelines in their order, then
    the others by name."""
    known = [r for b in builtin for r in rows if r[0] == b]
    return known + sorted((r for r in rows if r[0] not in builtin), key=lambda r: r[0])


def table1(dataset_name, rows, alignment="`auto` alignment"):
    """(markdown, csv) of Table I for one dataset, byte-for-byte in the runner's format
    (native_runner/src/table/mod.rs `write_tables`).

    `rows`: [(pipeline, mean or None, points, status, reason)] in column order; `alignment`
    names the alignment in the caption (the runner's: "`auto` alignment")."""
    head = "| dataset |" + "".join(" %s |" % p for p, *_ in rows)
    head += "\n|---|" + "---:|" * len(rows) + "\n"
    cells = []
    for _, mean, points, status, reason in rows:
        if mean is not None:
            cells.append("%.6f (%d)" % (mean, points))
        else:
            why = (reason or "").replace("|", " ").replace("\n", " ")
            why = why if len(why) <= 120 else why[:120] + "…"
            cells.append(why if why.startswith(status) else "%s: %s" % (status, why))
    body = "| %s |" % dataset_name + "".join(" %s |" % c for c in cells) + "\n"
    md = ("# Table I: mean distance to the ground truth (m) and number of points\n\nEach cell: "
          "mean reconstruction → ground-truth distance in metres (after %s), and "
          "in parentheses the number of points; failed runs show why.\n\n" % alignment
          + head + body)
    header = ["dataset"]
    for p, *_ in rows:
        header += ["%s.mean_m" % p, "%s.points" % p, "%s.status" % p]
    rec = [dataset_name]
    for _, mean, points, status, _ in rows:
        rec += [rust_num(mean), str(points) if mean is not None else "", status]
    csv_text = ",".join(map(_csv_field, header)) + "\n" + ",".join(map(_csv_field, rec)) + "\n"
    return md, csv_text
