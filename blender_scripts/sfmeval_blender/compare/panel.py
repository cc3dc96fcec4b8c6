"""The "Compare pipelines" panel (steps 7–11), its settings (``scene.sfmeval_compare``), its
operators and the add-on preferences (paths of ``sfmeval`` / ``sfmeval-runner``).

Every operator reports a failure in the panel (``message`` of the panel or of a row) instead of
raising: a missing binary, a failed run or a corrupt file leaves the other rows as they are.
"""

import json
import os
import time

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       IntProperty, PointerProperty, StringProperty)

from . import evaluate as ev
from . import run as runmod
from . import tools
from .blender import (align_item, crop_file, dataset_dir, gt_override, import_source,
                      measure_item, require_dataset, show_ground_truth, work_dir)

ADDON = __package__.split(".")[0]
LOG_TEXT = "sfmeval runs"
TABLE_TEXT = "sfmeval Table I"
COMMANDS_TEXT = "sfmeval commands"
CATEGORY = "sfmeval compare"  # its own sidebar tab
_STATE = {"cancel": False, "running": False}


class SFMEVAL_AP_preferences(bpy.types.AddonPreferences):
    bl_idname = ADDON
    sfmeval_path: StringProperty(name="sfmeval", subtype="FILE_PATH",
                                 description="The sfmeval binary (empty: PATH, then a "
                                             "repository's target/release)")
    runner_path: StringProperty(name="sfmeval-runner", subtype="FILE_PATH",
                                description="The sfmeval-runner binary (empty: PATH, then a "
                                            "repository's target/release)")

    def draw(self, context):
        self.layout.prop(self, "sfmeval_path")
        self.layout.prop(self, "runner_path")


def _prefs(context):
    addon = context.preferences.addons.get(ADDON)
    return addon.preferences if addon else None


def find_tool(context, name):
    """The binary's path (ToolMissing with what to build or set)."""
    p = _prefs(context)
    preferred = (p.sfmeval_path if name == "sfmeval" else p.runner_path) if p else ""
    extra = [os.path.dirname(bpy.data.filepath)] if bpy.data.filepath else []
    return tools.find(name, bpy.path.abspath(preferred) if preferred else "", extra)


class SFMEVAL_PG_pipeline(bpy.types.PropertyGroup):
    installed: BoolProperty()
    detail: StringProperty()
    selected: BoolProperty(name="", default=False)
    state: StringProperty(default="")
    elapsed: FloatProperty(default=0.0)
    message: StringProperty(default="")


class SFMEVAL_PG_recon(bpy.types.PropertyGroup):
    object: PointerProperty(type=bpy.types.Object)
    source: StringProperty()
    cameras_source: StringProperty()
    status: StringProperty(default="")
    message: StringProperty(default="")
    summary: StringProperty(default="")  # JSON of evaluate.summary(report)
    report: StringProperty(default="")


class SFMEVAL_PG_compare(bpy.types.PropertyGroup):
    dataset_dir: StringProperty(name="Dataset", subtype="DIR_PATH", default="",
                                description="Dataset folder (empty: the generator's output "
                                            "folder above)")
    runs_dir: StringProperty(name="Runs", subtype="DIR_PATH", default="",
                             description="Runner output folder (empty: <dataset>/runs)")
    pipelines: CollectionProperty(type=SFMEVAL_PG_pipeline)
    timeout: FloatProperty(name="Timeout (s)", default=1800.0, min=1.0)
    intrinsics: EnumProperty(name="Intrinsics", items=[
        ("exif", "EXIF", "the images' EXIF focal length"),
        ("known", "Known", "the dataset's cameras.json")])
    message: StringProperty(default="")
    recons: CollectionProperty(type=SFMEVAL_PG_recon)
    active_recon: IntProperty(name="Reconstruction", default=0,
                              description="The reconstruction Automatic and Refine align")
    import_path: StringProperty(name="File", subtype="FILE_PATH",
                                description="PLY, COLMAP folder/text/binary, NVM, Bundler .out, "
                                            "OpenMVG sfm_data.json")
    crop_object: PointerProperty(type=bpy.types.Object, name="Crop volume")
    use_max_distance: BoolProperty(name="Max distance", default=False)
    max_distance: FloatProperty(name="", default=0.05, min=0.0, unit="LENGTH")
    gt_source: EnumProperty(name="Ground truth", items=[
        ("DATASET", "Dataset", "the dataset's ground_truth.glb"),
        ("OBJECT", "Scene object", "a mesh of this scene, exported to compare/gt_scene.glb")])
    gt_object: PointerProperty(type=bpy.types.Object, name="GT object")


def runs_dir(context):
    c = context.scene.sfmeval_compare
    if c.runs_dir:
        return os.path.abspath(bpy.path.abspath(c.runs_dir))
    return os.path.join(dataset_dir(context), "runs")


def _fail(op, context, msg, target=None):
    (target or context.scene.sfmeval_compare).message = msg
    op.report({"ERROR"}, msg)
    return {"CANCELLED"}


def _text(name, clear=False):
    t = bpy.data.texts.get(name) or bpy.data.texts.new(name)
    if clear:
        t.clear()
    return t


def _log_commands():
    """The sfmeval commands run since the last call, appended to the text block "sfmeval
    commands" (what a user types to get the same files)."""
    if ev.COMMANDS:
        t = _text(COMMANDS_TEXT)
        for line in ev.COMMANDS:
            t.write("$ %s\n" % line)
        del ev.COMMANDS[:]


def _redraw(context):
    for area in (context.screen.areas if getattr(context, "screen", None) else ()):
        area.tag_redraw()


class SFMEVAL_OT_compare_pipelines(bpy.types.Operator):
    """Ask sfmeval-runner which pipelines are installed here"""
    bl_idname = "sfmeval.compare_pipelines"
    bl_label = "List pipelines"

    def execute(self, context):
        c = context.scene.sfmeval_compare
        try:
            listed = runmod.list_pipelines(find_tool(context, "sfmeval-runner"))
        except (tools.ToolMissing, RuntimeError, OSError) as exc:
            return _fail(self, context, str(exc))
        old = {p.name: p.selected for p in c.pipelines}
        c.pipelines.clear()
        for p in listed:
            item = c.pipelines.add()
            item.name, item.installed, item.detail = p["name"], p["installed"], p["detail"]
            item.selected = old.get(p["name"], False) and p["installed"]
        c.message = ""
        return {"FINISHED"}


class SFMEVAL_OT_compare_run(bpy.types.Operator):
    """Run the ticked pipelines on the dataset with sfmeval-runner, one after the other, into
    <runs>/<dataset>/<pipeline>/ (Blender stays usable; in background mode it waits)"""
    bl_idname = "sfmeval.compare_run"
    bl_label = "Run pipelines"

    def execute(self, context):
        c = context.scene.sfmeval_compare
        if _STATE["running"]:
            return _fail(self, context, "pipelines are already running")
        try:
            self._runner = find_tool(context, "sfmeval-runner")
            self._dataset = require_dataset(context)
        except (tools.ToolMissing, ValueError) as exc:
            return _fail(self, context, str(exc))
        self._queue = [p.name for p in c.pipelines if p.selected and p.installed]
        if not self._queue:
            return _fail(self, context, "no installed pipeline ticked (List pipelines first)")
        for p in c.pipelines:
            if p.name in self._queue:
                p.state, p.elapsed, p.message = "queued", 0.0, ""
        self._out = runs_dir(context)
        self._job, self._name = None, None
        self._log = _text(LOG_TEXT, clear=True)
        c.message = ""
        _STATE.update(cancel=False, running=True)
        if bpy.app.background or context.window is None:
            while self._step(context):
                time.sleep(0.2)
            return {"FINISHED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.5, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _step(self, context):
        """One poll; False when every queued run has ended. An unexpected error ends the
        batch with a message (and the runner), never a stuck "running" state."""
        try:
            return self._poll(context)
        except Exception as exc:
            if self._job is not None:
                self._job.cancel()
            context.scene.sfmeval_compare.message = "run stopped: %s" % exc
            _STATE["running"] = False
            return False

    def _poll(self, context):
        c = context.scene.sfmeval_compare
        if self._job is None:
            if not self._queue:
                _STATE["running"] = False
                return False
            self._name = self._queue.pop(0)
            c.pipelines[self._name].state = "running"
            argv = runmod.run_command(self._runner, self._dataset, self._out, self._name,
                                      c.timeout, c.intrinsics)
            self._log.write("$ %s\n" % " ".join(argv))
            try:
                self._job = runmod.Job(argv)
            except OSError as exc:
                c.pipelines[self._name].state = "failed"
                c.pipelines[self._name].message = str(exc)
                return True
        item = c.pipelines[self._name]
        lines, rc = self._job.poll()
        for line in lines:
            self._log.write(line + "\n")
        item.elapsed = self._job.elapsed()
        if _STATE["cancel"] and rc is None:
            self._job.cancel()
            item.state, item.message = "cancelled", "cancelled by the user"
            for name in self._queue:
                c.pipelines[name].state = "cancelled"
            self._queue, self._job = [], None
            self._log.write("# cancelled\n")
            _STATE["running"] = False
            return False
        if rc is not None:
            status, reason = runmod.run_status(
                runmod.run_folder(self._dataset, self._out, self._name))
            if rc != 0 and status == "ok":
                status, reason = "failed", "sfmeval-runner exited with %d (see the log)" % rc
            item.state, item.message = status, reason
            self._job = None
        return True

    def modal(self, context, event):
        if event.type == "TIMER":
            running = self._step(context)
            for area in context.screen.areas if context.screen else []:
                area.tag_redraw()
            if not running:
                context.window_manager.event_timer_remove(self._timer)
                return {"FINISHED"}
        return {"PASS_THROUGH"}


class SFMEVAL_OT_compare_cancel(bpy.types.Operator):
    """End the running pipeline (its whole process tree) and skip the queued ones"""
    bl_idname = "sfmeval.compare_cancel"
    bl_label = "Cancel"

    def execute(self, context):
        _STATE["cancel"] = True
        return {"FINISHED"}


def _row(context, name):
    c = context.scene.sfmeval_compare
    item = c.recons.get(name)
    if item is None:
        item = c.recons.add()
        item.name = name
    item.status = item.message = item.summary = ""
    return item


class SFMEVAL_OT_compare_import_runs(bpy.types.Operator):
    """Import every run of the dataset (<runs>/<dataset>/*/): one collection per pipeline,
    aligned automatically; failed runs get a row saying why"""
    bl_idname = "sfmeval.compare_import_runs"
    bl_label = "Import runs"

    def execute(self, context):
        c = context.scene.sfmeval_compare
        try:
            sfmeval = find_tool(context, "sfmeval")
            ds = require_dataset(context)
        except (tools.ToolMissing, ValueError) as exc:
            return _fail(self, context, str(exc))
        base = os.path.join(runs_dir(context), os.path.basename(ds))
        if not os.path.isdir(base):
            return _fail(self, context, "no runs in %s: run pipelines first" % base)
        c.message = ""
        show_ground_truth(context, ds)
        todo = []
        for name in sorted(os.listdir(base)):  # every row listed first, then imported
            folder = os.path.join(base, name)
            if not os.path.isfile(os.path.join(folder, "run.json")):
                continue
            item = _row(context, name)
            item.source = folder
            status, reason = runmod.run_status(folder)
            if status != "ok":
                item.status, item.message = status, reason or status
                continue
            item.status = "importing"
            todo.append((name, folder))
        _redraw(context)
        for name, folder in todo:
            _import(context, sfmeval, c.recons[name], folder, run_dir=folder)
        active = c.recons[c.active_recon] if 0 <= c.active_recon < len(c.recons) else None
        if active is None or active.object is None:  # select the first imported row
            c.active_recon = next((i for i, r in enumerate(c.recons) if r.object), 0)
        _log_commands()
        _redraw(context)
        return {"FINISHED"}


def _import(context, sfmeval, item, source, run_dir=None):
    try:
        obj, cams = import_source(context, sfmeval, item.name, source, run_dir)
        item.object, item.cameras_source = obj, cams or ""
        item.status = "imported"
    except (ev.CliError, ValueError, OSError) as exc:
        item.status, item.message = "failed", str(exc)


class SFMEVAL_OT_compare_import_file(bpy.types.Operator):
    """Import one reconstruction file or model folder (any format the CLI reads)"""
    bl_idname = "sfmeval.compare_import_file"
    bl_label = "Import file"

    def execute(self, context):
        c = context.scene.sfmeval_compare
        try:
            sfmeval = find_tool(context, "sfmeval")
            require_dataset(context)
        except (tools.ToolMissing, ValueError) as exc:
            return _fail(self, context, str(exc))
        path = os.path.normpath(bpy.path.abspath(c.import_path))
        name = os.path.splitext(os.path.basename(path))[0] or "recon"
        if os.path.isdir(path):  # run/model, sparse/0: the parent names it
            name = "%s-%s" % (os.path.basename(os.path.dirname(path)), name)
        c.message = ""
        show_ground_truth(context, dataset_dir(context))
        item = _row(context, name)
        item.source = path
        _import(context, sfmeval, item, path)
        c.active_recon = c.recons.find(name)
        _log_commands()
        _redraw(context)
        return {"FINISHED"}


class SFMEVAL_OT_compare_add_crop(bpy.types.Operator):
    """Add a crop volume (an empty the user moves, rotates and scales) around the object"""
    bl_idname = "sfmeval.compare_add_crop"
    bl_label = "Add crop volume"
    kind: EnumProperty(items=[("CUBE", "Box", ""), ("SPHERE", "Sphere", "")])

    def execute(self, context):
        c = context.scene.sfmeval_compare
        c.message = ""
        obj = bpy.data.objects.new("sfmeval crop", None)
        obj.empty_display_type = self.kind
        obj.empty_display_size = 1.0
        context.scene.collection.objects.link(obj)
        c.crop_object = obj
        return {"FINISHED"}


class SFMEVAL_OT_compare_align(bpy.types.Operator):
    """Align the selected reconstruction's kept points: automatic (cameras or global, then
    ICP), or Refine: one ICP from where the object is now, run by the core to its fixed point"""
    bl_idname = "sfmeval.compare_align"
    bl_label = "Align"
    mode: EnumProperty(items=[("auto", "Automatic", ""), ("icp", "Refine (ICP)", "")])
    index: IntProperty(default=-1, description="The row to align (-1: the panel's selected one)")

    def execute(self, context):
        c = context.scene.sfmeval_compare
        c.message = ""
        try:
            sfmeval = find_tool(context, "sfmeval")
        except tools.ToolMissing as exc:
            return _fail(self, context, str(exc))
        index = self.index if self.index >= 0 else c.active_recon
        if not 0 <= index < len(c.recons) or c.recons[index].object is None:
            return _fail(self, context, "select an imported reconstruction in the list first")
        item = c.recons[index]
        try:
            align_item(context, sfmeval, item, self.mode)
            item.status, item.message = "aligned (%s)" % self.mode, ""
        except (ev.CliError, ValueError, OSError) as exc:
            item.status, item.message = "failed", str(exc)
        _log_commands()
        return {"FINISHED"}


class SFMEVAL_OT_compare_evaluate(bpy.types.Operator):
    """Evaluate every imported reconstruction with sfmeval (the points kept, the object's
    matrix as the alignment, the crop), recolour the points and write Table I"""
    bl_idname = "sfmeval.compare_evaluate"
    bl_label = "Evaluate and compare"

    def execute(self, context):
        c = context.scene.sfmeval_compare
        try:
            sfmeval = find_tool(context, "sfmeval")
            ds = require_dataset(context)
            crop = crop_file(context)
            gt = gt_override(context)
        except (tools.ToolMissing, ValueError) as exc:
            return _fail(self, context, str(exc))
        c.message = ""
        reports, failed = [], []
        for item in c.recons:
            if item.object is None:
                failed.append((item.name, item.message or item.status or "not imported"))
                continue
            try:
                measure_item(context, sfmeval, item, crop=crop, gt=gt)
            except (ev.CliError, ValueError, OSError) as exc:
                item.status, item.message, item.summary = "failed", str(exc), ""
                failed.append((item.name, str(exc)))
                continue
            load_report(item, os.path.join(work_dir(context, item.name), "report.json"))
            reports.append((item.name, item.report))
        if reports:
            try:
                md, csv_text = ev.table(sfmeval, os.path.basename(ds), reports, failed,
                                        work_dir(context))
                _text(TABLE_TEXT, clear=True).write(md + "\n" + csv_text)
            except (ev.CliError, OSError) as exc:
                c.message = "Table I: %s" % exc
        _log_commands()
        _redraw(context)
        return {"FINISHED"}


def load_report(item, path):
    """Shows the report at `path` in the row `item`: its numbers and its warnings (by level),
    read from the report's fields."""
    with open(path) as f:
        rep = json.load(f)
    item.summary, item.status, item.message = json.dumps(ev.summary(rep)), "ok", ""
    item.report = path


def _fmt(v, digits=4):
    """A number for a narrow sidebar: 4 significant digits (0.003172, 1.2e-05), an integer as is."""
    if v is None:
        return "—"
    if isinstance(v, float):
        return "%.*g" % (digits, v)
    return str(v)


def _value_rows(col, pairs):
    """One row per value, the name left and the number right (readable at the sidebar's
    default width, where "mean 0.003172  median 0.002811" is cut)."""
    for name, value in pairs:
        row = col.row(align=True)
        row.label(text=name)
        row.label(text=value)


LEVEL_ICONS = {"warning": "ERROR", "info": "INFO"}


class SFMEVAL_UL_recons(bpy.types.UIList):
    """The imported reconstructions: the selected one is what Automatic and Refine align."""
    bl_idname = "SFMEVAL_UL_recons"

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname,
                  index=0):
        row = layout.row()
        row.label(text=item.name, icon="OUTLINER_OB_POINTCLOUD" if item.object else "CANCEL")
        row.label(text=item.status or "")


class SFMEVAL_PT_compare(bpy.types.Panel):
    bl_label = "Compare pipelines"
    bl_idname = "SFMEVAL_PT_compare"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = CATEGORY

    def draw(self, context):
        c = context.scene.sfmeval_compare
        lay = self.layout
        lay.prop(c, "dataset_dir")
        if not c.dataset_dir:
            d = dataset_dir(context)
            if not d or not os.path.isfile(os.path.join(d, "cameras.json")):
                lay.label(text="Choose a dataset folder (one with cameras.json and "
                               "ground_truth.glb)", icon="INFO")
                lay.label(text="or make one with steps 1–6 (into the output folder)")
            else:
                lay.label(text="Using the generator's output: %s" % d, icon="INFO")
        lay.prop(c, "runs_dir")
        for name in ("sfmeval", "sfmeval-runner"):
            try:
                find_tool(context, name)
            except tools.ToolMissing as exc:
                lay.label(text=str(exc), icon="ERROR")
        if c.message:
            lay.label(text=c.message, icon="ERROR")
        box = lay.box()
        box.label(text="7. Run pipelines")
        box.operator("sfmeval.compare_pipelines")
        for p in c.pipelines:
            row = box.row()
            row.enabled = p.installed
            row.prop(p, "selected", text=p.name)
            state = p.state or ("" if p.installed else "missing")
            if p.state in ("running", "ok", "failed", "timeout", "cancelled"):
                state = "%s %.0f s" % (p.state, p.elapsed)
            row.label(text=state)
            if p.message:
                box.label(text=p.message[:200], icon="ERROR")
        row = box.row()
        row.prop(c, "timeout")
        row.prop(c, "intrinsics")
        row = box.row()
        row.operator("sfmeval.compare_run")
        row.operator("sfmeval.compare_cancel")
        box = lay.box()
        box.label(text="8. Import reconstructions")
        box.operator("sfmeval.compare_import_runs")
        row = box.row()
        row.prop(c, "import_path")
        row.operator("sfmeval.compare_import_file", text="Import")
        if len(c.recons):
            box.template_list("SFMEVAL_UL_recons", "", c, "recons", c, "active_recon", rows=3)
        for r in c.recons:
            if r.message:
                box.label(text="%s: %s" % (r.name, r.message[:200]), icon="ERROR")
        box = lay.box()
        box.label(text="9. Cut away (delete points in Edit Mode, or crop)")
        row = box.row()
        row.operator("sfmeval.compare_add_crop", text="Box").kind = "CUBE"
        row.operator("sfmeval.compare_add_crop", text="Sphere").kind = "SPHERE"
        box.prop(c, "crop_object")
        row = box.row()
        row.prop(c, "use_max_distance")
        row.prop(c, "max_distance")
        box = lay.box()
        active = c.recons[c.active_recon] if 0 <= c.active_recon < len(c.recons) else None
        box.label(text="10. Align %s" % (active.name if active else "(select a reconstruction)"))
        row = box.row()
        row.enabled = active is not None and active.object is not None
        op = row.operator("sfmeval.compare_align", text="Automatic")
        op.mode, op.index = "auto", c.active_recon
        op = row.operator("sfmeval.compare_align", text="Refine (ICP)")
        op.mode, op.index = "icp", c.active_recon
        box = lay.box()
        box.label(text="11. Evaluate and compare")
        box.prop(c, "gt_source")
        if c.gt_source == "OBJECT":
            box.prop(c, "gt_object")
        box.operator("sfmeval.compare_evaluate")
        # one small block per reconstruction, one value a row (a grid does not fit the sidebar)
        for r in c.recons:
            s = json.loads(r.summary) if r.summary else {}
            if not s:
                continue
            col = box.box().column(align=True)
            col.label(text=r.name)
            _value_rows(col, [
                ("images", "%s / %s" % (_fmt(s["registered"]), _fmt(s["images"]))),
                ("points", _fmt(s["points"])),
                ("min", _fmt(s["min"])), ("max", _fmt(s["max"])),
                ("mean", _fmt(s["mean"])), ("median", _fmt(s["median"])),
                ("std", _fmt(s["std"])), ("completeness", _fmt(s["completeness"])),
                ("F@1%", _fmt(s["f1"])), ("ATE", _fmt(s["ate"]))])
            for n in s.get("notes", []):
                col.label(text=n["message"], icon=LEVEL_ICONS.get(n["level"], "ERROR"))


CLASSES = (SFMEVAL_AP_preferences, SFMEVAL_PG_pipeline, SFMEVAL_PG_recon, SFMEVAL_PG_compare,
           SFMEVAL_OT_compare_pipelines, SFMEVAL_OT_compare_run, SFMEVAL_OT_compare_cancel,
           SFMEVAL_OT_compare_import_runs, SFMEVAL_OT_compare_import_file,
           SFMEVAL_OT_compare_add_crop, SFMEVAL_OT_compare_align, SFMEVAL_OT_compare_evaluate,
           SFMEVAL_UL_recons, SFMEVAL_PT_compare)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.sfmeval_compare = PointerProperty(type=SFMEVAL_PG_compare)


def unregister():
    del bpy.types.Scene.sfmeval_compare
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
