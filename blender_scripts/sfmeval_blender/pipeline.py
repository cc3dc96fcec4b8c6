"""Headless generation: every step in order, with progress on stdout."""

import os
import sys
import time

from . import config as cfgmod


def log(msg):
    sys.stdout.write("[sfmeval] %s\n" % msg)
    sys.stdout.flush()


def check_out_dir(out_dir, overwrite):
    if os.path.isfile(out_dir):
        raise cfgmod.ConfigError("--out %s is a file" % out_dir)
    if os.path.isdir(out_dir) and not overwrite:
        existing = [n for n in ("images", "cameras.json", "dataset.json", "ground_truth.glb")
                    if os.path.exists(os.path.join(out_dir, n))]
        if existing:
            raise cfgmod.ConfigError("--out %s already holds a dataset (%s): pass --overwrite or "
                                     "choose another folder" % (out_dir, ", ".join(existing)))


def clean_out_dir(out_dir):
    import shutil
    for sub in ("images", "depth", "masks", "sparse_gt"):
        p = os.path.join(out_dir, sub)
        if os.path.isdir(p):
            shutil.rmtree(p)
    for name in ("cameras.json", "dataset.json", "timing.json", "ground_truth.glb", "scene.blend"):
        p = os.path.join(out_dir, name)
        if os.path.exists(p):
            os.remove(p)
    remove_leftovers(out_dir)


def remove_leftovers(out_dir):
    """Temporary files of renders that were killed: the depth pass's ``.aux-<pid>.exr`` and the
    lossless ``images/*.render.png`` of a post-processed view."""
    import glob
    for p in glob.glob(os.path.join(out_dir, ".aux*.exr")) + glob.glob(
            os.path.join(out_dir, "images", "*.render.png")):
        os.remove(p)


def _build_scene(cfg):
    """Steps 1-4 on a fresh empty scene; returns the views."""
    from . import steps
    steps.reset_scene()
    log("import object: %s" % cfg["object"]["source"])
    steps.step_import_object(cfg)
    log("set up scene")
    steps.step_setup_scene(cfg)
    log("set up camera")
    steps.step_setup_camera(cfg)
    views = steps.step_animate(cfg)
    log("animate orbits: %d views" % len(views))
    return views


def _progress(what, k, n, secs):
    if secs is not None:
        log("%s %d/%d  %.2f s" % (what, k, n, secs))
    elif k == n or k % 10 == 0:
        log("%s %d/%d" % (what, k, n))


def _render(cfg, out_dir, frames=None):
    from . import steps
    info = steps.step_render(cfg, out_dir, _progress, frames=frames)
    mean = sum(info["seconds_per_frame"]) / max(1, len(info["seconds_per_frame"]))
    log("rendered %d images, %.2f s per frame" % (info["frames"], mean))
    for _, line in steps.other_objects_summary(info["other_objects"]):
        log(line)
    if info["views_without_object"]:
        log("warning: the object is seen in no pixel of %s"
            % ", ".join(info["views_without_object"]))
    return info


def generate(cfg, out_dir, render=True, overwrite=False):
    """Run the six steps headless on a fresh empty scene. Returns dataset.json's content."""
    from . import steps
    check_out_dir(out_dir, overwrite)
    t0 = time.perf_counter()
    _build_scene(cfg)
    # Everything that can fail on the input has been checked: now write.
    if overwrite:
        clean_out_dir(out_dir)
    os.makedirs(out_dir, exist_ok=True)
    if render:
        _render(cfg, out_dir)
    log("export ground truth")
    ds = steps.step_export(cfg, out_dir)
    log("done in %.1f s: %s" % (time.perf_counter() - t0, os.path.abspath(out_dir)))
    return ds


def check_not_finalized(out_dir):
    if os.path.exists(os.path.join(out_dir, "dataset.json")):
        raise cfgmod.ConfigError("--out %s is a finished dataset (dataset.json): its views are "
                                 "rendered already" % out_dir)


def render_part(cfg, out_dir, views_spec):
    """Render only the views of `views_spec` (``i/n`` or ``A:B``, :mod:`parts`) into `out_dir`
    (images/, depth/, masks/) and write the part's record ``.parts/<tag>.json``."""
    import socket

    import bpy

    from . import parts
    check_not_finalized(out_dir)
    parsed = parts.parse_views(views_spec)
    t0 = time.perf_counter()
    views = _build_scene(cfg)
    chosen = [views[k] for k in parts.select(parsed, len(views))]
    log("part %s: %d of %d views" % (parts.part_tag(parsed), len(chosen), len(views)))
    os.makedirs(out_dir, exist_ok=True)
    info = _render(cfg, out_dir, frames={m["frame"] for m in chosen}) if chosen else {
        "seconds_per_frame": [], "aux_seconds_total": 0.0, "denoise_used": None,
        "postprocess": None, "other_objects": None, "views_without_object": None}
    path = parts.write_part(out_dir, parsed, cfg, [m["name"] for m in chosen], info, {
        "host": socket.gethostname(), "threads": bpy.context.scene.render.threads,
        "wall_seconds": round(time.perf_counter() - t0, 3)})
    log("done in %.1f s: %s" % (time.perf_counter() - t0, path))
    return path


def finalize(cfg, out_dir):
    """After every part is rendered: check the parts (:func:`parts.merge`), write the ground
    truth, cameras.json, dataset.json and timing.json, and remove ``.parts/``."""
    import shutil

    import bpy

    from . import parts, steps
    check_not_finalized(out_dir)
    t0 = time.perf_counter()
    views = _build_scene(cfg)
    names = [m["name"] for m in views]

    def files(name):
        stem = os.path.splitext(name)[0]
        out = [os.path.join(out_dir, "images", name)]
        if cfg["outputs"]["depth"]:
            out.append(os.path.join(out_dir, "depth", stem + ".npy"))
        if cfg["outputs"]["masks"]:
            out.append(os.path.join(out_dir, "masks", stem + ".png"))
        return out

    remove_leftovers(out_dir)
    found = parts.read_parts(out_dir)
    info, timing_parts = parts.merge([p for p in found if p["images"]], cfg, names, files)
    steps.store(bpy.context.scene, "render_info", info)
    log("export ground truth (%d parts)" % len(found))
    ds = steps.step_export(cfg, out_dir, timing_parts=timing_parts)
    shutil.rmtree(os.path.join(out_dir, parts.PARTS_DIR))
    log("done in %.1f s: %s" % (time.perf_counter() - t0, os.path.abspath(out_dir)))
    return ds
