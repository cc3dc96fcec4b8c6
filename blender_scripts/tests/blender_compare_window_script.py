"""Driven by test_blender_compare_window.py inside Debian's Blender with a real window (under
xvfb-run): the Compare panel's run operator runs modally; a timer (a stand-in for the user)
presses the buttons, records what it sees and dumps it to JSON, then quits.

1. Run `fast` (a custom pipeline: a short sleep, then a copy of a COLMAP model): the timer keeps
   ticking while it runs, and it ends ok.
2. Run `slow` (a custom pipeline sleeping a minute); once its tool is up, press Cancel: the
   runner and the tool's process group must go, the row say cancelled, the timer keep ticking.
3. Import the runs (`fast`), evaluate them, frame the points in Solid shading and take a
   screenshot of the window (OUT_PNG: the points in their viridis colours, the add-on set Color:
   Attribute), then one with Color: Single (OUT_PNG with "-single" before ".png").

argv (after --): ZIP DATASET SFMEVAL RUNNER PIDFILE SLEEP_ARG OUT_JSON OUT_PNG
RUNNER is a wrapper of sfmeval-runner adding the two `--custom` pipelines; for `run` it appends
its pid (the runner's, it execs) to PIDFILE. SLEEP_ARG is the slow tool's unique `sleep` argument.
"""

import json
import os
import sys
import time
import traceback

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from panel_probe import panel_labels  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
zip_path, ds, sfmeval_bin, runner_bin, pidfile, sleep_arg, out_json, png = argv
bpy.context.preferences.view.show_splash = False
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="sfmeval_blender")
prefs = bpy.context.preferences.addons["sfmeval_blender"].preferences
prefs.sfmeval_path, prefs.runner_path = sfmeval_bin, runner_bin
from sfmeval_blender.compare import panel as cpanel  # noqa: E402

TICK = 0.25
res = {"blender": bpy.app.version_string, "ticks": [], "phases": {}}
state = {"phase": "start", "t0": time.monotonic(), "since": time.monotonic()}


def now():
    return time.monotonic() - state["t0"]


def goto(phase):
    res["phases"][phase] = now()
    state.update(phase=phase, since=time.monotonic())


def alive(pid):
    """The process exists and is not a zombie."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(") ", 1)[1][0] != "Z"
    except (OSError, IndexError):
        return False


def group_alive(pgid):
    """Some live process is in process group `pgid`."""
    for e in os.listdir("/proc"):
        if e.isdigit():
            try:
                with open("/proc/%s/stat" % e) as f:
                    fields = f.read().rsplit(") ", 1)[1].split()
            except (OSError, IndexError):
                continue
            if fields[0] != "Z" and int(fields[2]) == pgid:
                return True
    return False


def find_sleeper():
    for e in os.listdir("/proc"):
        if e.isdigit():
            try:
                with open("/proc/%s/cmdline" % e, "rb") as f:
                    if f.read().split(b"\0")[:2] == [b"sleep", sleep_arg.encode()]:
                        return int(e)
            except OSError:
                pass
    return None


def finish(error=None):
    res["error"] = error
    with open(out_json, "w") as f:
        json.dump(res, f, indent=1)
    bpy.ops.wm.quit_blender()


def tick():
    try:
        return _tick()
    except Exception:
        finish(traceback.format_exc())
        return None


def _tick():
    scene = bpy.context.scene
    c = scene.sfmeval_compare
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    res["ticks"].append([now(), state["phase"], cpanel._STATE["running"]])
    if time.monotonic() - state["since"] > 40:
        finish("phase %s took over 40 s" % state["phase"])
        return None
    with bpy.context.temp_override(window=win, area=area, region=region, scene=scene):
        phase = state["phase"]
        if phase == "start":
            area.spaces.active.show_region_ui = True
            # for the screenshot: the panel on top of the sidebar's default tab (Blender 3.4
            # cannot switch tabs from Python)
            pt = bpy.types.SFMEVAL_PT_compare
            bpy.utils.unregister_class(pt)
            pt.bl_category, pt.bl_order = "Item", -1
            bpy.utils.register_class(pt)
            c.dataset_dir = ds
            assert bpy.ops.sfmeval.compare_pipelines() == {"FINISHED"}, c.message
            res["listed"] = {p.name: p.installed for p in c.pipelines}
            c.pipelines["fast"].selected = True
            res["fast_invoke"] = sorted(bpy.ops.sfmeval.compare_run("INVOKE_DEFAULT"))
            goto("fast")
        elif phase == "fast":
            if not cpanel._STATE["running"]:
                p = c.pipelines["fast"]
                res["fast"] = [p.state, p.elapsed, p.message]
                c.pipelines["fast"].selected = False
                c.pipelines["slow"].selected = True
                res["slow_invoke"] = sorted(bpy.ops.sfmeval.compare_run("INVOKE_DEFAULT"))
                goto("slow")
        elif phase == "slow":
            sleeper = find_sleeper()
            if sleeper is not None:
                with open(pidfile) as f:
                    res["runner_pid"] = int(f.read().split()[-1])
                res["sleeper_pid"], res["tool_pgid"] = sleeper, os.getpgid(sleeper)
                res["before_cancel"] = [alive(res["runner_pid"]), group_alive(res["tool_pgid"]),
                                        c.pipelines["slow"].state]
                res["cancel_result"] = sorted(bpy.ops.sfmeval.compare_cancel())
                goto("cancelled")
        elif phase == "cancelled":
            if "gone" not in res and not alive(res["runner_pid"]) \
                    and not group_alive(res["tool_pgid"]):
                res["gone"] = now()
            # a second after the modal run ended: the timer still ticks (Blender responsive)
            if "gone" in res and not cpanel._STATE["running"] \
                    and time.monotonic() - state["since"] > 1.0:
                p = c.pipelines["slow"]
                res["slow"] = [p.state, p.elapsed, p.message]
                res["labels"] = panel_labels(bpy.types.SFMEVAL_PT_compare, scene)
                res["log"] = bpy.data.texts["sfmeval runs"].as_string()
                shading = area.spaces.active.shading
                shading.type = "SOLID"
                res["color_type_before"] = shading.color_type
                assert bpy.ops.sfmeval.compare_import_runs() == {"FINISHED"}, c.message
                assert bpy.ops.sfmeval.compare_evaluate() == {"FINISHED"}, c.message
                obj = c.recons["fast"].object
                res["fast_status"] = [c.recons["fast"].status, c.recons["fast"].message]
                res["color_type"] = shading.color_type
                me = obj.data
                res["active_color"] = (me.color_attributes.active_color.name
                                       if me.color_attributes.active_color else None)
                res["vertices"] = len(me.vertices)
                # the points framed (the startup cube, which would hide them, removed; the
                # ground-truth mesh the import shows, in its own collection, hidden)
                if "Cube" in bpy.data.objects:
                    bpy.data.objects.remove(bpy.data.objects["Cube"])
                gt_layer = bpy.context.view_layer.layer_collection.children.get(
                    "sfmeval ground truth")
                res["gt_shown"] = bool(gt_layer and len(gt_layer.collection.objects))
                if gt_layer:
                    gt_layer.hide_viewport = True
                co = np.array([obj.matrix_world @ v.co for v in me.vertices])
                lo, hi = np.percentile(co, [10, 90], axis=0)  # (outliers far off)
                r3d = area.spaces.active.region_3d
                r3d.view_location = ((lo + hi) / 2).tolist()
                r3d.view_distance = 1.5 * float(np.linalg.norm(hi - lo))
                # the 3D view's drawing region in the window (origin bottom left) left of the
                # sidebar, which overlaps it
                ui = next(r for r in area.regions if r.type == "UI")
                res["view_region"] = [region.x - win.x, region.y - win.y,
                                      min(region.width, ui.x - region.x), region.height]
                goto("shoot")
                return 3.0
        elif phase == "shoot":
            bpy.ops.screen.screenshot(filepath=png)
            area.spaces.active.shading.color_type = "SINGLE"
            goto("shoot_single")
            return 3.0
        elif phase == "shoot_single":
            bpy.ops.screen.screenshot(filepath=png[:-len(".png")] + "-single.png")
            finish()
            return None
    return TICK


bpy.app.timers.register(tick, first_interval=1.0)
