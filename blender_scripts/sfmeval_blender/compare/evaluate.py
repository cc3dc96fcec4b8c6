"""The measurements, all through the ``sfmeval`` binary: the reconstruction's own points and
cameras (``sfmeval export``), alignment (``sfmeval align``, also ICP from a given start), the
evaluation of the points the user kept (``sfmeval eval --align given`` with the object's matrix,
the crop file and the cameras; the colours are the CLI's ``--colored`` PLY) and Table I
(``sfmeval table``). Nothing here computes a number, a colour or a table of its own."""

import csv
import json
import os
import shlex
import subprocess

import numpy as np

from . import plyio

# Every sfmeval command the add-on ran, as a shell line (the panel copies them into the text
# block "sfmeval commands": what a user types to get the same files).
COMMANDS = []


class CliError(RuntimeError):
    """The sfmeval binary failed; the message holds its stderr."""


def _run(argv, timeout=600):
    argv = [str(a) for a in argv]
    COMMANDS.append(" ".join(shlex.quote(a) for a in argv))
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        msg = (proc.stderr.strip() or proc.stdout.strip())[-800:]
        raise CliError("%s %s failed: %s" % (os.path.basename(argv[0]), argv[1], msg))
    return proc


def write_matrix_json(path, m):
    """`m` (4×4) as ``{"gt_from_recon": [[...], ...]}``, the JSON form ``--transform`` reads
    (Python's JSON numbers round-trip exactly)."""
    m = np.asarray(m, dtype=float).reshape(4, 4)
    with open(path, "w") as f:
        json.dump({"gt_from_recon": m.tolist()}, f)
        f.write("\n")


def export(sfmeval, recon, out, recon_cameras=None):
    """``sfmeval export``: the reconstruction's points (float64 PLY) and cameras (cameras.json)
    in its own frame, into `out`. Returns (points.ply, cameras.json or None)."""
    argv = [sfmeval, "export", recon, "--out", out]
    if recon_cameras:
        argv += ["--recon-cameras", recon_cameras]
    _run(argv)
    cams = os.path.join(out, "cameras.json")
    return os.path.join(out, "points.ply"), (cams if os.path.isfile(cams) else None)


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
    `start` (4×4) is the ICP start for mode "icp" (one call: the core's ICP runs to its fixed
    point)."""
    os.makedirs(work, exist_ok=True)
    out = os.path.join(work, "alignment.json")
    argv = [sfmeval, "align"] + inputs(dataset, recon, recon_cameras, gt) + ["--align", mode,
                                                                            "--out", out]
    if start is not None:
        tpath = os.path.join(work, "icp_start.json")
        write_matrix_json(tpath, start)
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
              csv_out=None, gt=None, colored=None):
    """The ``sfmeval eval`` command of the panel's numbers (also what a user types to get them)."""
    argv = [sfmeval, "eval"] + inputs(dataset, points, recon_cameras, gt) + [
        "--align", "given", "--transform", transform, "--report", report, "--quiet"]
    if crop:
        argv += ["--crop", crop]
    if csv_out:
        argv += ["--csv", csv_out]
    if colored:
        argv += ["--colored", colored]
    return argv


def evaluate(sfmeval, dataset, points, transform, report, recon_cameras=None, crop=None,
             csv_out=None, gt=None, colored=None):
    """Runs ``eval_argv``; returns (report dict, per-point distances, per-point status, the
    colours of the kept points in input order (N_kept, 3) uint8 from the ``--colored`` PLY)."""
    _run(eval_argv(sfmeval, dataset, points, transform, report, recon_cameras, crop, csv_out,
                   gt, colored))
    with open(report) as f:
        rep = json.load(f)
    dist, status, rgb = None, None, None
    if csv_out:
        dist, status = read_distances(csv_out)
    if colored:
        cols = plyio.read_columns(colored)
        rgb = np.stack([cols["red"], cols["green"], cols["blue"]], axis=1).astype(np.uint8)
    return rep, dist, status, rgb


def read_distances(path):
    """distance and status columns of ``sfmeval eval --csv`` (one row per input point)."""
    d, s = [], []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            d.append(float(row["distance"]))
            s.append(row["status"])
    return np.array(d), s


def table(sfmeval, dataset_name, reports, failed, out):
    """``sfmeval table`` of the reports ``[(pipeline, report path)]`` and the failed rows
    ``[(pipeline, reason)]``, every table file written into `out`; returns (table1.md,
    table1.csv) as the CLI wrote them (the runner's bytes)."""
    argv = [sfmeval, "table"] + ["%s=%s" % (p, r) for p, r in reports]
    for p, why in failed:
        argv += ["--failed", "%s=%s" % (p, why or "failed")]
    argv += ["--dataset", dataset_name, "--out", out]
    _run(argv)
    texts = []
    for name in ("table1.md", "table1.csv"):
        with open(os.path.join(out, name), encoding="utf-8", newline="") as f:
            texts.append(f.read())
    return tuple(texts)


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
    """The panel's numbers of a report (sfmeval.report/3), read from its fields: images
    registered / in the ground truth, points kept (after the crop), accuracy statistics,
    completeness (mean GT → reconstruction distance), F at 1 % of the diagonal, camera ATE (RMSE
    of the centres), and the notes as the core typed them (code, level, message)."""
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
        "notes": notes(report),
    }


# The levels the panel shows (docs/notes.md: info or warning); info notes stay in the report.
SHOWN_LEVELS = ("warning",)


def notes(report):
    """[{code, level, message}] of the report's notes whose level the panel shows, chosen by
    the typed `level` (never by the message's text), in the report's order."""
    return [{"code": n.get("code"), "level": n.get("level"), "message": n.get("message", "")}
            for n in report.get("notes") or [] if n.get("level") in SHOWN_LEVELS]
