"""The Compare pipelines panel in a real Blender window (manual check and the README picture):
the run operator runs modally (timers keep firing while the pipelines run), then import, crop,
evaluate, Table I (the text block the panel writes) in a text editor below the 3D view, and a
screenshot of the window.

    xvfb-run -s "-screen 0 1600x1500x24" blender --factory-startup -noaudio \\
        --window-geometry 0 0 1600 1500 EMPTY.blend -P blender_scripts/compare_ui_demo.py -- \\
        ZIP DATASET SFMEVAL RUNNER OUT.png

EMPTY.blend: any saved startup file (a file on the command line skips the splash screen).
DATASET is a rendered dataset; pycolmap-global is run on it (into DATASET/runs/) and every run
folder there is imported. Prints "UI ticks during the run: N" (N > 0: Blender stayed usable).

The README picture (docs/blender-compare-panel.jpg): the `small` preset rendered without depth
and masks; in DATASET/runs/ `sfmeval-runner run` made pycolmap, a bare cloud (`--custom
cloud-only=cp OPENMVG_RUN/sparse.ply {out}/`) and a failing custom run (`zz-failed`); window
1600x2300, the screenshot cut above the timeline (1600x2098) and saved as JPEG quality 80.
"""

import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
zip_path, ds, sfmeval_bin, runner_bin, png = argv
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="sfmeval_blender")
prefs = bpy.context.preferences.addons["sfmeval_blender"].preferences
prefs.sfmeval_path, prefs.runner_path = sfmeval_bin, runner_bin
from sfmeval_blender.compare import panel as cpanel  # noqa: E402

# the dataset panel (tab "sfmeval") out of the picture: the sidebar shows the comparison's own
# tab, "sfmeval compare" (Blender 3.4 cannot switch tabs from Python)
bpy.utils.unregister_class(bpy.types.SFMEVAL_PT_panel)
ticks = []
state = {"phase": "start", "t0": 0.0}


def view3d():
    win = bpy.context.window_manager.windows[0]
    area = max((a for a in win.screen.areas if a.type == "VIEW_3D"), key=lambda a: a.height)
    region = next(r for r in area.regions if r.type == "WINDOW")
    return win, area, region


def show_table_below(win, area):
    """A text editor below the 3D view showing the text block Table I is written into."""
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.screen.area_split(direction="HORIZONTAL", factor=0.13)
    below = min((a for a in win.screen.areas if a.type == "VIEW_3D"), key=lambda a: a.height)
    below.type = "TEXT_EDITOR"
    space = below.spaces.active
    space.text = bpy.data.texts[cpanel.TABLE_TEXT]
    space.show_word_wrap = True
    space.show_line_numbers = False
    space.show_syntax_highlight = False
    space.top = 0


def tick():
    try:
        return _tick()
    except Exception:
        import traceback
        traceback.print_exc()
        bpy.ops.wm.quit_blender()


def _tick():
    scene = bpy.context.scene
    c = scene.sfmeval_compare
    win, area, region = view3d()
    with bpy.context.temp_override(window=win, area=area, region=region, scene=scene):
        if state["phase"] == "start":
            for name in ("Cube", "Light"):
                if name in bpy.data.objects:
                    bpy.data.objects.remove(bpy.data.objects[name])
            c.dataset_dir = ds
            area.spaces.active.show_region_ui = True
            # the sidebar's sfmeval tab: the other tabs' panels are unregistered for the picture
            for cls in list(bpy.types.Panel.__subclasses__()):
                if (getattr(cls, "bl_space_type", "") == "VIEW_3D"
                        and getattr(cls, "bl_region_type", "") == "UI"
                        and getattr(cls, "bl_category", "") != "sfmeval"
                        and not cls.__name__.startswith("SFMEVAL")):
                    try:
                        bpy.utils.unregister_class(cls)
                    except RuntimeError:
                        pass
            bpy.ops.sfmeval.compare_pipelines()
            c.pipelines["pycolmap-global"].selected = True
            c.intrinsics = "known"
            bpy.ops.sfmeval.compare_run("INVOKE_DEFAULT")
            state.update(phase="running", t0=time.monotonic())
            return 0.5
        if state["phase"] == "running":
            if cpanel._STATE["running"]:
                ticks.append(c.pipelines["pycolmap-global"].elapsed)
                return 0.5
            print("UI ticks during the run: %d, state %s, %.1f s" % (
                len(ticks), c.pipelines["pycolmap-global"].state,
                c.pipelines["pycolmap-global"].elapsed))
            bpy.ops.sfmeval.compare_import_runs()
            bpy.ops.sfmeval.compare_add_crop(kind="CUBE")
            c.crop_object.scale = (0.45, 0.45, 0.5)
            c.use_max_distance, c.max_distance = True, 0.05
            bpy.ops.sfmeval.compare_evaluate()
            state["phase"] = "table"
            return 0.5
        if state["phase"] == "table":
            show_table_below(win, area)
            state["phase"] = "frame"
            return 0.5
        if state["phase"] == "frame":
            shading = area.spaces.active.shading
            shading.type, shading.color_type = "SOLID", "VERTEX"
            for o in bpy.context.view_layer.objects:
                o.select_set(o.name in ("pycolmap", "pycolmap-global"))
            bpy.ops.view3d.view_selected()
            for o in bpy.context.view_layer.objects:
                o.select_set(False)
            state["phase"] = "shoot"
            return 3.0
        bpy.ops.screen.screenshot(filepath=png)
        print("screenshot", png)
        bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(tick, first_interval=2.0)
