"""Shared by the Python adapters of sfmeval-runner: arguments, image listing, focal from EXIF,
the tool-version record and a uniform exit on failure.

Every adapter is called as

    python ADAPTER.py --images DIR --out DIR [--known fx,fy,cx,cy] [--mode incremental|global]
                      [--option key=value ...] [--seed N]

and writes the final model as a COLMAP text model (cameras.txt, images.txt, points3D.txt) in
--out, plus --out/../tool.json with {"tool", "version", "registered", "points"}; an adapter may
also keep the tool's own exports in --out/../raw/ (the run folder's raw/).
`--known` gives the dataset's intrinsics in COLMAP's pixel convention (cx = W/2 for a centred
camera); without it the adapter uses the images' EXIF like a user would.
"""

import argparse
import json
import os
import sys

IMAGE_EXT = (".jpg", ".jpeg", ".png", ".tif", ".tiff")


def parse_args(description, modes=("incremental",)):
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--images", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--known", default=None, help="fx,fy,cx,cy in COLMAP's pixel convention")
    p.add_argument("--mode", default=modes[0], choices=modes)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--option", action="append", default=[], help="key=value")
    a = p.parse_args()
    opts = {}
    for kv in a.option:
        if "=" not in kv:
            p.error("--option needs key=value, got %r" % kv)
        k, v = kv.split("=", 1)
        opts[k.strip()] = v.strip()
    a.options = opts
    if a.known:
        try:
            a.known = [float(v) for v in a.known.split(",")]
        except ValueError:
            p.error("--known needs four numbers fx,fy,cx,cy")
        if len(a.known) != 4:
            p.error("--known needs four numbers fx,fy,cx,cy")
    os.makedirs(a.out, exist_ok=True)
    return a


def list_images(folder):
    names = sorted(n for n in os.listdir(folder) if n.lower().endswith(IMAGE_EXT))
    if not names:
        fail("no images in %s" % folder)
    return names


def exif_focal_px(path):
    """Focal length in pixels from EXIF (FocalLength × FocalPlaneXResolution per mm), or None.

    Falls back to FocalLengthIn35mmFilm (scaled by the longer image side / 36 mm)."""
    from PIL import Image

    with Image.open(path) as im:
        w, h = im.size
        exif = im.getexif()
        sub = exif.get_ifd(0x8769) if hasattr(exif, "get_ifd") else {}
    tags = dict(exif)
    tags.update(sub)
    focal = tags.get(0x920A)  # FocalLength
    xres = tags.get(0xA20E)  # FocalPlaneXResolution
    unit = tags.get(0xA210, 2)  # FocalPlaneResolutionUnit
    mm_per_unit = {2: 25.4, 3: 10.0, 4: 1.0, 5: 0.001}.get(int(unit) if unit else 2)
    try:
        if focal and xres and mm_per_unit:
            f = float(focal) * float(xres) / mm_per_unit
            if f > 0:
                return f, w, h
        f35 = tags.get(0xA405)
        if f35:
            return float(f35) / 36.0 * max(w, h), w, h
    except (TypeError, ValueError, ZeroDivisionError):
        pass
    return None, w, h


def run_subdir(out, name):
    """The run folder's sub-folder `name` (the folder holding --out: `scratch`, `raw`), created."""
    d = os.path.join(os.path.dirname(os.path.abspath(out)), name)
    os.makedirs(d, exist_ok=True)
    return d


def write_tool_json(out, tool, version, registered, points, extra=None):
    doc = {"tool": tool, "version": version, "registered": int(registered), "points": int(points)}
    doc.update(extra or {})
    with open(os.path.join(os.path.dirname(os.path.abspath(out)), "tool.json"), "w") as f:
        json.dump(doc, f, indent=1)


def fail(message, code=3):
    sys.stderr.write("adapter error: %s\n" % message)
    sys.exit(code)


def log(message):
    sys.stderr.write("[adapter] %s\n" % message)
    sys.stderr.flush()
