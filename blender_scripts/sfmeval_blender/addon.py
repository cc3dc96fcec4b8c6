"""The Blender add-on: a panel in the 3D view sidebar (tab "sfmeval") with one button per step.

Every setting lives on the scene (``scene.sfmeval``) and can be changed between steps; each
button turns the settings into a config dict, validates it with the same code as the headless
generator (``config.resolve``) and runs the step from ``steps``.
"""

import os

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       FloatVectorProperty, IntProperty, PointerProperty, StringProperty)

from . import config as cfgmod
from . import steps
from .compare import panel as compare_panel

_BUILTINS = [(n, n.capitalize(), "built-in procedural %s" % n) for n in cfgmod.BUILTIN_OBJECTS]


def _presets(self, context):
    return [(n, n, "preset %s" % n) for n in cfgmod.preset_names()]


class SFMEVAL_PG_ring(bpy.types.PropertyGroup):
    elevation_deg: FloatProperty(name="Elevation", default=20.0, min=-90.0, max=90.0,
                                 description="Elevation of the ring above the target (degrees)")
    count: IntProperty(name="Views", default=18, min=0, max=10000)
    radius: FloatProperty(name="Radius", default=0.0, min=0.0, unit="LENGTH",
                          description="Orbit radius in metres; 0 = automatic (fit the object)")
    azimuth_offset_deg: FloatProperty(name="Azimuth offset", default=0.0)


class SFMEVAL_PG_settings(bpy.types.PropertyGroup):
    # dataset
    name: StringProperty(name="Name", default="dataset")
    seed: IntProperty(name="Seed", default=0, min=0)
    out_dir: StringProperty(name="Output folder", subtype="DIR_PATH", default="//sfmeval_dataset")
    preset: EnumProperty(name="Preset", items=_presets)
    # object
    source_kind: EnumProperty(name="Source", items=[("BUILTIN", "Built-in", "procedural object"),
                                                    ("FILE", "File", "a model file")])
    builtin: EnumProperty(name="Object", items=_BUILTINS, default="statue")
    filepath: StringProperty(name="Model file", subtype="FILE_PATH",
                             description="OBJ, PLY, STL, glTF/GLB, FBX or .blend")
    normalize: BoolProperty(name="Normalise size", default=True)
    size: FloatProperty(name="Size", default=1.0, min=1e-6, unit="LENGTH")
    center: BoolProperty(name="Centre", default=True)
    on_floor: BoolProperty(name="Stand on z = 0", default=False)
    subdivision: IntProperty(name="Subdivision", default=1, min=0, max=4)
    texture_scale: FloatProperty(name="Texture scale", default=1.0, min=0.01)
    # scene
    world_color: FloatVectorProperty(name="Background", subtype="COLOR", size=3, min=0.0, max=1.0,
                                     default=(0.5, 0.5, 0.5))
    world_strength: FloatProperty(name="Strength", default=1.0, min=0.0)
    floor: BoolProperty(name="Floor", default=False)
    walls: BoolProperty(name="Walls", default=False)
    keep_other_objects: BoolProperty(
        name="Keep other objects as context", default=False,
        description="Render the scene's objects that sfmeval did not make (e.g. the default Cube) "
                    "in the images. They never enter the masks, depth maps or ground truth (they "
                    "only hide the object behind them). Off: hidden while rendering")
    keep_other_lights: BoolProperty(
        name="Keep other lights", default=False,
        description="Let the scene's own lights (e.g. the default Light) light the images too. "
                    "Off: only sfmeval's lights")
    light_type: EnumProperty(name="Lights", items=[("area", "Area", ""), ("sun", "Sun", ""),
                                                   ("point", "Point", "")])
    key_energy: FloatProperty(name="Key", default=250.0, min=0.0)
    fill_energy: FloatProperty(name="Fill", default=120.0, min=0.0)
    samples: IntProperty(name="Samples", default=32, min=1)
    max_bounces: IntProperty(name="Bounces", default=4, min=0)
    denoise: EnumProperty(name="Denoise", items=[("auto", "Auto", "only where OpenImageDenoise exists"),
                                                 ("on", "On", ""), ("off", "Off", "")])
    # camera
    focal_mm: FloatProperty(name="Focal (mm)", default=35.0, min=0.1)
    sensor_w: FloatProperty(name="Sensor W (mm)", default=32.0, min=0.1)
    sensor_h: FloatProperty(name="Sensor H (mm)", default=18.0, min=0.1)
    res_x: IntProperty(name="Width", default=1920, min=1)
    res_y: IntProperty(name="Height", default=1080, min=1)
    shift_x: FloatProperty(name="Shift X", default=0.0)
    shift_y: FloatProperty(name="Shift Y", default=0.0)
    # views
    rings: CollectionProperty(type=SFMEVAL_PG_ring)
    fill: FloatProperty(name="Fill", default=0.85, min=0.05, max=1.5,
                        description="Automatic radius: object bounding sphere / half field of view")
    sphere_count: IntProperty(name="Sphere views", default=0, min=0)
    shell_count: IntProperty(name="Shell views", default=0, min=0)
    # outputs
    format: EnumProperty(name="Format", items=[("JPEG", "JPEG", ""), ("PNG", "PNG", "")])
    jpeg_quality: IntProperty(name="Quality", default=95, min=1, max=100)
    depth: BoolProperty(name="Depth maps", default=True)
    masks: BoolProperty(name="Masks", default=True)
    colmap_gt: BoolProperty(name="COLMAP GT model", default=True)


def props_to_config(p):
    """The add-on settings as a config dict (validated: raises ConfigError)."""
    src = "builtin:" + p.builtin if p.source_kind == "BUILTIN" else bpy.path.abspath(p.filepath)
    rings = [{"elevation_deg": r.elevation_deg, "count": r.count,
              "radius": r.radius if r.radius > 0 else "auto",
              "azimuth_offset_deg": r.azimuth_offset_deg} for r in p.rings]
    lights = [dict(cfgmod.LIGHT_DEFAULTS, type=p.light_type, energy=p.key_energy,
                   azimuth_deg=45.0, elevation_deg=50.0, size=2.0),
              dict(cfgmod.LIGHT_DEFAULTS, type=p.light_type, energy=p.fill_energy,
                   azimuth_deg=-135.0, elevation_deg=25.0, size=2.0)]
    if p.light_type == "sun":
        for li in lights:
            li["energy"] = li["energy"] / 100.0
            li["size"] = 2.0
    user = {
        "dataset": {"name": p.name, "seed": p.seed},
        "object": {"source": src, "normalize": p.normalize, "size": p.size, "center": p.center,
                   "on_floor": p.on_floor, "subdivision": p.subdivision,
                   "texture_scale": p.texture_scale},
        "lights": lights,
        "background": {"world_color": list(p.world_color), "world_strength": p.world_strength,
                       "floor": p.floor, "walls": p.walls,
                       "keep_other_objects": p.keep_other_objects,
                       "keep_other_lights": p.keep_other_lights},
        "render": {"samples": p.samples, "max_bounces": p.max_bounces,
                   "denoise": {"auto": "auto", "on": True, "off": False}[p.denoise],
                   "format": p.format, "jpeg_quality": p.jpeg_quality},
        "camera": {"focal_mm": p.focal_mm, "sensor_mm": [p.sensor_w, p.sensor_h],
                   "resolution": [p.res_x, p.res_y], "shift": [p.shift_x, p.shift_y]},
        "views": {"orbits": rings, "fill": p.fill, "sphere": {"count": p.sphere_count},
                  "shell": {"count": p.shell_count}},
        "outputs": {"depth": p.depth, "masks": p.masks, "colmap_gt": p.colmap_gt},
    }
    return cfgmod.resolve(user)


def config_to_props(cfg, p):
    src = cfg["object"]["source"]
    if src.startswith("builtin:"):
        p.source_kind, p.builtin = "BUILTIN", src[len("builtin:"):]
    else:
        p.source_kind, p.filepath = "FILE", src
    o, b, r, c, v = cfg["object"], cfg["background"], cfg["render"], cfg["camera"], cfg["views"]
    p.name, p.seed = cfg["dataset"]["name"], cfg["dataset"]["seed"]
    p.normalize, p.size, p.center, p.on_floor = o["normalize"], o["size"], o["center"], o["on_floor"]
    p.subdivision, p.texture_scale = o["subdivision"], o["texture_scale"]
    p.world_color, p.world_strength = b["world_color"], b["world_strength"]
    p.floor, p.walls = b["floor"], b["walls"]
    p.keep_other_objects, p.keep_other_lights = b["keep_other_objects"], b["keep_other_lights"]
    if cfg["lights"]:
        p.light_type = cfg["lights"][0]["type"]
        p.key_energy = cfg["lights"][0]["energy"]
        p.fill_energy = cfg["lights"][1]["energy"] if len(cfg["lights"]) > 1 else 0.0
    p.samples, p.max_bounces = r["samples"], r["max_bounces"]
    p.denoise = {"auto": "auto", True: "on", False: "off"}[r["denoise"]]
    p.format, p.jpeg_quality = r["format"], r["jpeg_quality"]
    p.focal_mm = c["focal_mm"]
    p.sensor_w, p.sensor_h = c["sensor_mm"]
    p.res_x, p.res_y = c["resolution"]
    p.shift_x, p.shift_y = c["shift"]
    p.rings.clear()
    for ring in v["orbits"]:
        it = p.rings.add()
        it.elevation_deg, it.count = ring["elevation_deg"], ring["count"]
        it.radius = 0.0 if ring["radius"] == "auto" else ring["radius"]
        it.azimuth_offset_deg = ring["azimuth_offset_deg"]
    p.fill, p.sphere_count, p.shell_count = v["fill"], v["sphere"]["count"], v["shell"]["count"]
    out = cfg["outputs"]
    p.depth, p.masks, p.colmap_gt = out["depth"], out["masks"], out["colmap_gt"]


def other_objects_lines(scene):
    """What the panel says about the objects sfmeval did not make, as the render step will
    treat them now: [(treatment, "Hidden while rendering: Cube, Light"), …]."""
    p = scene.sfmeval
    cfg = {"background": {"keep_other_objects": p.keep_other_objects,
                          "keep_other_lights": p.keep_other_lights}}
    return steps.other_objects_summary(steps.other_objects_record(scene, cfg))


class _Step(bpy.types.Operator):
    bl_options = {"REGISTER", "UNDO"}

    def run(self, context, cfg):  # pragma: no cover - overridden
        raise NotImplementedError

    def execute(self, context):
        p = context.scene.sfmeval
        try:
            cfg = props_to_config(p)
            msg = self.run(context, cfg)
        except (cfgmod.ConfigError, steps.GenerationError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        level, msg = msg if isinstance(msg, tuple) else ("INFO", msg)
        if msg:
            self.report({level}, msg)
        return {"FINISHED"}


def _out_dir(context):
    path = bpy.path.abspath(context.scene.sfmeval.out_dir)
    if not path:
        raise steps.GenerationError("set an output folder")
    return path


class SFMEVAL_OT_import_object(_Step):
    """Import or build the main object (replaces a previous one)"""
    bl_idname = "sfmeval.import_object"
    bl_label = "1. Import object"

    def run(self, context, cfg):
        obj = steps.step_import_object(cfg)
        return "object %s: %d vertices" % (obj.name, len(obj.data.vertices))


class SFMEVAL_OT_setup_scene(_Step):
    """World background, lights, floor/walls and Cycles settings"""
    bl_idname = "sfmeval.setup_scene"
    bl_label = "2. Set up scene"

    def run(self, context, cfg):
        steps.step_setup_scene(cfg)


class SFMEVAL_OT_setup_camera(_Step):
    """Create the camera with the configured intrinsics"""
    bl_idname = "sfmeval.setup_camera"
    bl_label = "3. Set up camera"

    def run(self, context, cfg):
        steps.step_setup_camera(cfg)


class SFMEVAL_OT_animate_orbits(_Step):
    """Key the camera through every view of the orbits (frame 1 + i = view i)"""
    bl_idname = "sfmeval.animate_orbits"
    bl_label = "4. Animate orbits"

    def run(self, context, cfg):
        return "%d views keyed" % len(steps.step_animate(cfg))


class SFMEVAL_OT_render(_Step):
    """Render every view with EXIF (and depth maps / masks) into the output folder"""
    bl_idname = "sfmeval.render"
    bl_label = "5. Render"

    def run(self, context, cfg):
        wm = context.window_manager
        n = len(steps.load(context.scene, "views") or [])
        wm.progress_begin(0, max(1, n))
        try:
            info = steps.step_render(cfg, _out_dir(context),
                                     progress=lambda what, k, total, s: wm.progress_update(k))
        finally:
            wm.progress_end()
        return steps.render_report(info)


class SFMEVAL_OT_export_gt(_Step):
    """Write ground_truth.glb, cameras.json, dataset.json (and sparse_gt/)"""
    bl_idname = "sfmeval.export_gt"
    bl_label = "6. Export ground truth"

    def run(self, context, cfg):
        steps.step_export(cfg, _out_dir(context))
        return "ground truth written to %s" % _out_dir(context)


class SFMEVAL_OT_generate_all(_Step):
    """Run all six steps"""
    bl_idname = "sfmeval.generate_all"
    bl_label = "Run all steps"

    def run(self, context, cfg):
        out = _out_dir(context)
        steps.step_import_object(cfg)
        steps.step_setup_scene(cfg)
        steps.step_setup_camera(cfg)
        steps.step_animate(cfg)
        level, msg = steps.render_report(steps.step_render(cfg, out))
        steps.step_export(cfg, out)
        return level, "dataset written to %s; %s" % (out, msg)


class SFMEVAL_OT_load_preset(bpy.types.Operator):
    """Load a preset into the settings"""
    bl_idname = "sfmeval.load_preset"
    bl_label = "Load preset"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        p = context.scene.sfmeval
        config_to_props(cfgmod.resolve(preset=p.preset), p)
        return {"FINISHED"}


class SFMEVAL_OT_load_config(bpy.types.Operator):
    """Load a dataset config file (TOML or JSON) into the settings"""
    bl_idname = "sfmeval.load_config"
    bl_label = "Load config file"
    filepath: StringProperty(subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.toml;*.json", options={"HIDDEN"})

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        try:
            cfg = cfgmod.resolve(cfgmod.load_file(self.filepath))
        except cfgmod.ConfigError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        config_to_props(cfg, context.scene.sfmeval)
        return {"FINISHED"}


class SFMEVAL_OT_ring_add(bpy.types.Operator):
    """Add an orbit ring"""
    bl_idname = "sfmeval.ring_add"
    bl_label = "Add ring"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        context.scene.sfmeval.rings.add()
        return {"FINISHED"}


class SFMEVAL_OT_ring_remove(bpy.types.Operator):
    """Remove an orbit ring"""
    bl_idname = "sfmeval.ring_remove"
    bl_label = "Remove ring"
    bl_options = {"REGISTER", "UNDO"}
    index: IntProperty()

    def execute(self, context):
        context.scene.sfmeval.rings.remove(self.index)
        return {"FINISHED"}


class SFMEVAL_PT_panel(bpy.types.Panel):
    bl_label = "sfmeval dataset"
    bl_idname = "SFMEVAL_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "sfmeval"

    def draw(self, context):
        p = context.scene.sfmeval
        lay = self.layout
        row = lay.row(align=True)
        row.prop(p, "preset", text="")
        row.operator("sfmeval.load_preset", text="Load")
        lay.operator("sfmeval.load_config", icon="FILE")
        lay.prop(p, "name")
        lay.prop(p, "seed")
        lay.prop(p, "out_dir")

        box = lay.box()
        box.label(text="Object", icon="MESH_MONKEY")
        box.prop(p, "source_kind", expand=True)
        box.prop(p, "builtin" if p.source_kind == "BUILTIN" else "filepath")
        row = box.row()
        row.prop(p, "normalize")
        row.prop(p, "center")
        box.prop(p, "size")
        box.prop(p, "on_floor")
        if p.source_kind == "BUILTIN":
            box.prop(p, "subdivision")
            box.prop(p, "texture_scale")
        box.operator("sfmeval.import_object", icon="IMPORT")

        box = lay.box()
        box.label(text="Scene", icon="WORLD")
        box.prop(p, "world_color")
        box.prop(p, "world_strength")
        row = box.row()
        row.prop(p, "floor")
        row.prop(p, "walls")
        box.prop(p, "light_type")
        row = box.row()
        row.prop(p, "key_energy")
        row.prop(p, "fill_energy")
        row = box.row()
        row.prop(p, "samples")
        row.prop(p, "max_bounces")
        box.prop(p, "denoise")
        box.operator("sfmeval.setup_scene", icon="SCENE_DATA")

        box = lay.box()
        box.label(text="Camera", icon="CAMERA_DATA")
        box.prop(p, "focal_mm")
        row = box.row()
        row.prop(p, "sensor_w")
        row.prop(p, "sensor_h")
        row = box.row()
        row.prop(p, "res_x")
        row.prop(p, "res_y")
        row = box.row()
        row.prop(p, "shift_x")
        row.prop(p, "shift_y")
        box.operator("sfmeval.setup_camera", icon="OUTLINER_OB_CAMERA")

        box = lay.box()
        box.label(text="Orbits", icon="ORIENTATION_GIMBAL")
        if len(p.rings) == 0:
            box.label(text="No rings yet: load a preset or add a ring", icon="INFO")
        for i, ring in enumerate(p.rings):
            row = box.row(align=True)
            row.prop(ring, "elevation_deg", text="El")
            row.prop(ring, "count", text="N")
            row.prop(ring, "radius", text="R")
            row.operator("sfmeval.ring_remove", text="", icon="X").index = i
        box.operator("sfmeval.ring_add", icon="ADD")
        box.prop(p, "fill")
        row = box.row()
        row.prop(p, "sphere_count")
        row.prop(p, "shell_count")
        box.operator("sfmeval.animate_orbits", icon="ANIM")

        box = lay.box()
        box.label(text="Render & export", icon="RENDER_STILL")
        row = box.row()
        row.prop(p, "format")
        if p.format == "JPEG":
            row.prop(p, "jpeg_quality")
        row = box.row()
        row.prop(p, "depth")
        row.prop(p, "masks")
        box.prop(p, "colmap_gt")
        sub = box.box()
        sub.label(text="Objects sfmeval did not make", icon="OUTLINER_COLLECTION")
        sub.prop(p, "keep_other_objects")
        sub.prop(p, "keep_other_lights")
        for treatment, line in other_objects_lines(context.scene):
            sub.label(text=line, icon="HIDE_ON" if treatment == "hidden" else "HIDE_OFF")
        box.operator("sfmeval.render", icon="RENDER_ANIMATION")
        box.operator("sfmeval.export_gt", icon="EXPORT")
        lay.separator()
        lay.operator("sfmeval.generate_all", icon="PLAY")


CLASSES = (SFMEVAL_PG_ring, SFMEVAL_PG_settings, SFMEVAL_OT_import_object, SFMEVAL_OT_setup_scene,
           SFMEVAL_OT_setup_camera, SFMEVAL_OT_animate_orbits, SFMEVAL_OT_render,
           SFMEVAL_OT_export_gt, SFMEVAL_OT_generate_all, SFMEVAL_OT_load_preset,
           SFMEVAL_OT_load_config, SFMEVAL_OT_ring_add, SFMEVAL_OT_ring_remove, SFMEVAL_PT_panel)


@bpy.app.handlers.persistent
def _init_defaults(*_args):
    """Fill a scene's empty settings with the default config (rings etc.)."""
    try:
        for scene in bpy.data.scenes:
            if len(scene.sfmeval.rings) == 0:
                config_to_props(cfgmod.resolve({}), scene.sfmeval)
    except Exception:  # pragma: no cover - restricted context while loading
        pass
    return None


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.sfmeval = PointerProperty(type=SFMEVAL_PG_settings)
    if _init_defaults not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(_init_defaults)
    bpy.app.timers.register(_init_defaults, first_interval=0.2)
    compare_panel.register()


def unregister():
    if _init_defaults in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_init_defaults)
    compare_panel.unregister()
    del bpy.types.Scene.sfmeval
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
