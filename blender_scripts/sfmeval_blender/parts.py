"""Rendering a dataset in parts: which views a part renders, the record a part leaves behind,
and merging the records when the dataset is finalized.

``generate.py --views i/n`` renders the views k with k % n == i (``--views A:B``: views A to
B − 1) into the dataset folder and writes ``.parts/<tag>.json``; ``generate.py --finalize``
checks that the parts cover every view exactly once, all rendered from the same configuration,
with every file present, then writes what needs every view (``ground_truth.glb``,
``cameras.json``, ``sparse_gt/``, ``dataset.json``, ``timing.json``) and removes ``.parts/``.
The images of a view do not depend on which other views were rendered, so the folder is the
one a one-shot render writes, byte for byte; only ``timing.json`` holds measured times.

Pure Python (no bpy).
"""

import hashlib
import json
import os

from .config import ConfigError

PARTS_DIR = ".parts"
PART_SCHEMA = "sfmeval.render-part/1"


class PartsError(ConfigError):
    """A views spec that does not parse, or parts that do not make a whole dataset."""


def parse_views(spec):
    """``"i/n"`` → ("shard", i, n); ``"A:B"`` → ("range", A, B) (0-based, B excluded)."""
    text = spec.strip()
    try:
        if "/" in text:
            i, n = (int(x) for x in text.split("/", 1))
            if n < 1 or not 0 <= i < n:
                raise PartsError("--views i/n needs 0 <= i < n, got %s" % spec)
            return ("shard", i, n)
        if ":" in text:
            a, b = (int(x) for x in text.split(":", 1))
            if a < 0 or b <= a:
                raise PartsError("--views A:B needs 0 <= A < B, got %s" % spec)
            return ("range", a, b)
    except ValueError as exc:
        if isinstance(exc, PartsError):
            raise
        raise PartsError("--views wants i/n or A:B (integers), got %r" % spec) from None
    raise PartsError("--views wants i/n (every n-th view from i) or A:B (views A..B-1), got %r"
                     % spec)


def part_tag(parsed):
    """File-name tag of a part: ``views-1-of-4`` or ``views-10-to-20``."""
    kind, a, b = parsed
    return "views-%d-of-%d" % (a, b) if kind == "shard" else "views-%d-to-%d" % (a, b)


def select(parsed, count):
    """Indices (0-based) of the views of `count` that the part renders."""
    kind, a, b = parsed
    if kind == "shard":
        return [k for k in range(count) if k % b == a]
    if a >= count:
        raise PartsError("--views %d:%d starts past the last view (%d views)" % (a, b, count))
    return list(range(a, min(b, count)))


def config_digest(cfg):
    """SHA-256 of the resolved configuration: every part of a dataset must share it."""
    return hashlib.sha256(json.dumps(cfg, sort_keys=True).encode()).hexdigest()


def write_json_atomic(path, doc):
    tmp = "%s.tmp-%d" % (path, os.getpid())
    with open(tmp, "w") as f:
        f.write(json.dumps(doc, indent=1) + "\n")
    os.replace(tmp, path)


def write_part(out_dir, parsed, cfg, names, info, extra):
    """The record of one rendered part (atomically: a part without it is not rendered)."""
    folder = os.path.join(out_dir, PARTS_DIR)
    os.makedirs(folder, exist_ok=True)
    doc = {"schema": PART_SCHEMA, "views": parsed[0] + " %d %d" % parsed[1:],
           "config_sha256": config_digest(cfg), "images": names,
           "seconds_per_frame": [round(t, 3) for t in info["seconds_per_frame"]],
           "aux_seconds_total": info["aux_seconds_total"],
           "denoise_used": info["denoise_used"], "postprocess": info["postprocess"],
           "other_objects": info["other_objects"],
           "views_without_object": info["views_without_object"]}
    doc.update(extra)
    path = os.path.join(folder, part_tag(parsed) + ".json")
    write_json_atomic(path, doc)
    return path


def read_parts(out_dir):
    """Every part record of a dataset folder, sorted by file name."""
    folder = os.path.join(out_dir, PARTS_DIR)
    if not os.path.isdir(folder):
        return []
    parts = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".json"):
            continue
        with open(os.path.join(folder, name)) as f:
            doc = json.load(f)
        if doc.get("schema") != PART_SCHEMA:
            raise PartsError("%s/%s is not a render part record" % (folder, name))
        doc["file"] = name
        parts.append(doc)
    return parts


def merge(parts, cfg, view_names, expected_files):
    """The render info of the whole dataset from its parts, in view order, after checking that
    they were made from `cfg`, cover `view_names` exactly once, agree on everything that is not
    a time, and that every file of `expected_files(name)` exists. Returns (info, timing)."""
    if not parts:
        raise PartsError("no rendered parts (.parts/*.json): render the views first "
                         "(generate.py --views i/n)")
    digest = config_digest(cfg)
    seen = {}
    for p in parts:
        if p["config_sha256"] != digest:
            raise PartsError("part %s was rendered from another configuration" % p["file"])
        for name in p["images"]:
            if name in seen:
                raise PartsError("view %s is in two parts (%s and %s)" % (name, seen[name], p["file"]))
            seen[name] = p["file"]
    missing = [n for n in view_names if n not in seen]
    if missing:
        raise PartsError("%d of %d views are not rendered yet: %s%s" % (
            len(missing), len(view_names), ", ".join(missing[:6]),
            " …" if len(missing) > 6 else ""))
    extra = sorted(set(seen) - set(view_names))
    if extra:
        raise PartsError("parts hold views this configuration does not have: %s" % ", ".join(extra))
    absent = [f for n in view_names for f in expected_files(n) if not os.path.isfile(f)]
    if absent:
        raise PartsError("rendered files are missing: %s" % ", ".join(absent[:6]))
    for key in ("denoise_used", "postprocess", "other_objects"):
        values = {json.dumps(p[key], sort_keys=True) for p in parts}
        if len(values) > 1:
            raise PartsError("the parts disagree on %s" % key)
    first = parts[0]
    seconds = {}
    without = set()
    has_aux = first["views_without_object"] is not None
    for p in parts:
        seconds.update(zip(p["images"], p["seconds_per_frame"]))
        without.update(p["views_without_object"] or [])
    info = {"seconds_per_frame": [seconds[n] for n in view_names],
            "aux_seconds_total": sum(p["aux_seconds_total"] for p in parts),
            "denoise_used": first["denoise_used"], "postprocess": first["postprocess"],
            "other_objects": first["other_objects"], "frames": len(view_names),
            "views_without_object": [n for n in view_names if n in without] if has_aux else None}
    timing_parts = [{k: p[k] for k in ("file", "views", "images", "seconds_per_frame",
                                        "aux_seconds_total", "host", "threads", "wall_seconds")
                     if k in p} for p in parts]
    return info, timing_parts
