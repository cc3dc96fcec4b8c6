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
    for name in ("cameras.json", "dataset.json", "ground_truth.glb", "scene.blend", ".aux.exr"):
        p = os.path.join(out_dir, name)
        if os.path.exists(p):
            os.remove(p)


def generate(cfg, out_dir, render=True, overwrite=False):
    """Run the six steps headless on a fresh empty scene. Returns dataset.json's content."""
    from . import steps
    check_out_dir(out_dir, overwrite)
    t0 = time.perf_counter()
    steps.reset_scene()
    log("import object: %s" % cfg["object"]["source"])
    obj = steps.step_import_object(cfg)
    log("set up scene")
    steps.step_setup_scene(cfg)
    log("set up camera")
    steps.step_setup_camera(cfg)
    views = steps.step_animate(cfg)
    log("animate orbits: %d views" % len(views))
    # Everything that can fail on the input has been checked: now write.
    if overwrite:
        clean_out_dir(out_dir)
    os.makedirs(out_dir, exist_ok=True)
    if render:
        def progress(what, k, n, secs):
            if secs is not None:
                log("%s %d/%d  %.2f s" % (what, k, n, secs))
            elif k == n or k % 10 == 0:
                log("%s %d/%d" % (what, k, n))
        info = steps.step_render(cfg, out_dir, progress)
        mean = sum(info["seconds_per_frame"]) / max(1, len(info["seconds_per_frame"]))
        log("rendered %d images, %.2f s per frame" % (info["frames"], mean))
        for _, line in steps.other_objects_summary(info["other_objects"]):
            log(line)
        if info["views_without_object"]:
            log("warning: the object is seen in no pixel of %s"
                % ", ".join(info["views_without_object"]))
    log("export ground truth")
    ds = steps.step_export(cfg, out_dir)
    log("done in %.1f s: %s" % (time.perf_counter() - t0, os.path.abspath(out_dir)))
    return ds
