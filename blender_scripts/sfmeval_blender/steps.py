"""The six steps of dataset generation, on the current Blender scene.

Shared by the add-on (one button per step) and the headless generator (all steps in order).
Objects the steps create carry a custom property ``sfmeval_role`` so a later step (or a re-run
of a step) finds them again; the configuration used by each step is stored on the scene.
"""

import contextlib
import hashlib
import json
import math
import os
import sys
import time

import bpy
from mathutils import Matrix, Vector

from . import __version__, compat, config as cfgmod, exif, geometry, postprocess, shapes

ROLE = "sfmeval_role"


class GenerationError(RuntimeError):
    """A failure during generation, worded for a person."""


# -- helpers ---------------------------------------------------------------------------------
def objects_with_role(role):
    return [o for o in bpy.data.objects if o.get(ROLE) == role]


def remove_role(role):
    """Delete the objects a previous run of a step made (and their now unused data)."""
    for o in objects_with_role(role):
        data = o.data
        bpy.data.objects.remove(o, do_unlink=True)
        if data is None or data.users:
            continue
        coll = {"MESH": bpy.data.meshes, "LIGHT": bpy.data.lights,
                "CAMERA": bpy.data.cameras}.get(getattr(data, "id_type", ""))
        if coll is not None:
            coll.remove(data)


def link(obj, role):
    obj[ROLE] = role
    bpy.context.scene.collection.objects.link(obj)
    return obj


def get_object():
    objs = objects_with_role("object")
    if not objs:
        raise GenerationError("no object: run the 'import object' step first")
    return objs[0]


def get_camera():
    objs = objects_with_role("camera")
    if not objs:
        raise GenerationError("no camera: run the 'set up camera' step first")
    return objs[0]


def store(scene, key, value):
    scene["sfmeval_" + key] = json.dumps(value)


def load(scene, key, default=None):
    raw = scene.get("sfmeval_" + key)
    return json.loads(raw) if raw else default


def evaluated_world_vertices(obj):
    """World-space vertices (Blender frame) of the object with modifiers applied, and the
    triangle count."""
    dg = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg)
    me = ev.to_mesh()
    try:
        mw = obj.matrix_world
        verts = [tuple(mw @ v.co) for v in me.vertices]
        me.calc_loop_triangles()
        ntri = len(me.loop_triangles)
    finally:
        ev.to_mesh_clear()
    return verts, ntri


def bbox(verts):
    lo = [min(v[i] for v in verts) for i in range(3)]
    hi = [max(v[i] for v in verts) for i in range(3)]
    return lo, hi


def reset_scene():
    """Empty scene for the headless generator (never used by the add-on)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)


# -- objects sfmeval did not make ------------------------------------------------------------
# Types that never put a pixel in a Cycles render (an empty only when it instances nothing).
_NOT_RENDERED_TYPES = {"CAMERA", "ARMATURE", "LATTICE", "SPEAKER", "LIGHT_PROBE", "EMPTY"}


def _rendered_collections(view_layer):
    """Collections whose objects a render of `view_layer` includes (not excluded from the view
    layer, not disabled for rendering, nor any of their parents)."""
    out = set()

    def walk(lc):
        if lc.exclude or lc.collection.hide_render:
            return
        out.add(lc.collection)
        for child in lc.children:
            walk(child)

    walk(view_layer.layer_collection)
    return out


def other_objects(scene, cfg, view_layer=None):
    """Every object of `scene` that sfmeval did not make (no ``sfmeval_role``: the default Cube,
    Light and Camera, the user's own objects), sorted by name, as (object, treatment):

    - ``"hidden"``: it would render, so it is hidden from rendering while sfmeval renders
      (images, depth, masks) — the default;
    - ``"context"``: kept in the images (``background.keep_other_objects``, or
      ``background.keep_other_lights`` for lights); never in masks, depth or the ground truth;
    - ``"not rendered"``: cameras, armatures, plain empties…, and objects the user already left
      out of renders (``hide_render``, a collection disabled or excluded): left alone.
    """
    vl = view_layer or bpy.context.view_layer
    rendered = _rendered_collections(vl)
    bg = cfg["background"]
    out = []
    for o in sorted(scene.objects, key=lambda o: o.name):
        if o.get(ROLE):
            continue
        inert = o.type in _NOT_RENDERED_TYPES and not (
            o.type == "EMPTY" and o.instance_type != "NONE")
        if inert or o.hide_render or not any(c in rendered for c in o.users_collection):
            treatment = "not rendered"
        elif o.type == "LIGHT":
            treatment = "context" if bg["keep_other_lights"] else "hidden"
        else:
            treatment = "context" if bg["keep_other_objects"] else "hidden"
        out.append((o, treatment))
    return out


def other_objects_record(scene, cfg):
    """The dataset.json field ``other_objects`` (docs/dataset.md)."""
    return {"keep_other_objects": cfg["background"]["keep_other_objects"],
            "keep_other_lights": cfg["background"]["keep_other_lights"],
            "objects": [{"name": o.name, "type": o.type, "treatment": t}
                        for o, t in other_objects(scene, cfg)]}


def _names(names, limit=8):
    names = list(names)
    more = len(names) - limit
    return ", ".join(names[:limit]) + (" and %d more" % more if more > 0 else "")


def other_objects_summary(record):
    """One line per treatment for the panel and the reports: ``("hidden", "Hidden while
    rendering: Cube, Light")``, ``("context", "Kept as context: Table")``."""
    lines = []
    for treatment, head in (("hidden", "Hidden while rendering"), ("context", "Kept as context")):
        names = [o["name"] for o in record["objects"] if o["treatment"] == treatment]
        if names:
            lines.append((treatment, "%s: %s" % (head, _names(names))))
    return lines


def render_report(info):
    """(level, message) for the render step: "WARNING" when objects were hidden (the images do
    not show the scene as the viewport does) or some views show no object at all."""
    times = info["seconds_per_frame"]
    parts = ["rendered %d images (%.2f s per frame)" % (len(times), sum(times) / max(1, len(times)))]
    level = "INFO"
    record = info["other_objects"]
    for treatment, line in other_objects_summary(record):
        if treatment == "hidden":
            level = "WARNING"
            types = {o["type"] == "LIGHT" for o in record["objects"] if o["treatment"] == "hidden"}
            toggles = " or ".join(name for is_light, name in (
                (False, "'Keep other objects as context'"), (True, "'Keep other lights'"))
                if is_light in types)
            line += " (not made by sfmeval; %s renders them)" % toggles
        else:
            line += " (in the images; not in masks, depth or ground truth)"
        parts.append(line)
    missing = info.get("views_without_object") or []
    if missing:
        level = "WARNING"
        parts.append("the object is seen in no pixel of %d of %d views (hidden behind context "
                     "objects or out of frame): %s" % (len(missing), info["frames"], _names(missing, 4)))
    return level, "; ".join(parts)


class _Hiding:
    """What :func:`other_objects_hidden` yields: the ``other_objects`` record, and ``check()``
    to call after every frame change."""

    def __init__(self, record, hidden):
        self.record, self.hidden = record, hidden

    def check(self):
        """A keyframe or driver on an object's render visibility overrides the hiding at each
        frame change (and in the render itself): fail then rather than render it."""
        for o in self.hidden:
            if not o.hide_render:
                raise GenerationError(
                    "the render visibility of %r is animated (keyframes or a driver on 'Disable "
                    "in Renders'), so sfmeval cannot hide it: remove them, delete the object or "
                    "keep other objects as context" % o.name)


@contextlib.contextmanager
def other_objects_hidden(scene, cfg):
    """Hide the objects sfmeval did not make from rendering (``hide_render``) for the duration
    of the block, unless they are kept as context; every object's own ``hide_render`` is
    restored afterwards, also when rendering fails. Yields a :class:`_Hiding`."""
    hiding = _Hiding(other_objects_record(scene, cfg), [])
    try:
        for o, t in other_objects(scene, cfg):
            if t != "hidden":
                continue
            try:
                o.hide_render = True
            except (AttributeError, TypeError, RuntimeError):
                raise GenerationError(
                    "cannot hide %r from rendering (linked from a library?): make it local, "
                    "delete it or keep other objects as context" % o.name) from None
            hiding.hidden.append(o)
        yield hiding
    finally:
        for o in hiding.hidden:
            o.hide_render = False


# -- step 1: import object --------------------------------------------------------------------
def _ramp(nodes, links, fac, positions, colors):
    ramp = nodes.new("ShaderNodeValToRGB")
    els = ramp.color_ramp.elements
    els[0].position, els[1].position = positions
    els[0].color = list(colors[0]) + [1.0]
    els[1].color = list(colors[1]) + [1.0]
    links.new(fac, ramp.inputs["Fac"])
    return ramp.outputs["Color"]


def _math(nodes, links, op, a, b=None, c=None):
    n = nodes.new("ShaderNodeMath")
    n.operation = op
    for i, v in enumerate((a, b, c)):
        if v is None:
            continue
        if isinstance(v, (int, float)):
            n.inputs[i].default_value = v
        else:
            links.new(v, n.inputs[i])
    return n.outputs[0]


def _material_from_desc(desc, cfg_obj):
    """A Principled material whose colour is a procedural texture of *object* coordinates, so
    the texture sticks to the surface in every view (no UVs needed).

    colour = ramp(coarse pattern → colour_a/colour_b) × ramp(fine noise → grey/white)
    """
    mat = bpy.data.materials.new(desc["name"])
    compat.use_nodes(mat)
    nt = mat.node_tree
    nodes, links = nt.nodes, nt.links
    bsdf = nodes.get("Principled BSDF") or nodes.new("ShaderNodeBsdfPrincipled")
    texco = nodes.new("ShaderNodeTexCoord")
    s = desc["scale"] * cfg_obj["texture_scale"]
    vec = texco.outputs["Object"]
    contrast = desc["contrast"] if cfg_obj["texture_contrast"] < 0 else cfg_obj["texture_contrast"]

    def noise(scale, detail):
        n = nodes.new("ShaderNodeTexNoise")
        compat.set_input(n, ["Scale"], scale)
        compat.set_input(n, ["Detail"], detail)
        compat.set_input(n, ["Roughness"], 0.6)
        links.new(vec, n.inputs["Vector"])
        return n.outputs["Fac"]

    pattern = desc["pattern"]
    if pattern == "voronoi":
        vor = nodes.new("ShaderNodeTexVoronoi")
        compat.set_input(vor, ["Scale"], s)
        links.new(vec, vor.inputs["Vector"])
        fac = _math(nodes, links, "MULTIPLY_ADD", vor.outputs["Distance"], 1.2, noise(3 * s, 4))
        fac = _math(nodes, links, "SUBTRACT", fac, 0.45)
        positions = (0.25, 0.6)
    elif pattern in ("bands", "marble"):
        sep = nodes.new("ShaderNodeSeparateXYZ")
        links.new(vec, sep.inputs[0])
        axis = sep.outputs[2] if pattern == "bands" else sep.outputs[0]
        warp = _math(nodes, links, "MULTIPLY", noise(0.6 * s, 6), 7.0 if pattern == "bands" else 12.0)
        arg = _math(nodes, links, "MULTIPLY_ADD", axis, 2.0 * s, warp)
        fac = _math(nodes, links, "MULTIPLY_ADD", _math(nodes, links, "SINE", arg), 0.5, 0.5)
        positions = (0.3, 0.7)
    else:
        fac = noise(s, 8)
        positions = (0.44, 0.56)
    a, b = desc["color_a"], desc["color_b"]
    mid = [(a[i] + b[i]) / 2 for i in range(3)]
    ca = [mid[i] + (a[i] - mid[i]) * contrast for i in range(3)]
    cb = [mid[i] + (b[i] - mid[i]) * contrast for i in range(3)]
    coarse = _ramp(nodes, links, fac, positions, (ca, cb))
    lo = 1.0 - 0.55 * contrast
    fine = _ramp(nodes, links, noise(5.0 * s, 6), (0.4, 0.6), ((lo, lo, lo), (1.0, 1.0, 1.0)))
    mix, mfac, ma, mb, mout = compat.new_mix_node(nodes)
    mix.blend_type = "MULTIPLY"
    mfac.default_value = 1.0
    links.new(coarse, ma)
    links.new(fine, mb)
    links.new(mout, bsdf.inputs["Base Color"])
    compat.set_input(bsdf, ["Roughness"], desc["roughness"])
    compat.set_input(bsdf, ["Metallic"], desc["metallic"])
    compat.set_input(bsdf, ["Specular IOR Level", "Specular"], 0.3)
    return mat


def _build_builtin(name, cfg):
    mesh_data, mats, smooth = shapes.build(name, cfg["dataset"]["seed"])
    me = bpy.data.meshes.new("sfmeval_" + name)
    me.from_pydata(mesh_data.verts, [], mesh_data.faces)
    me.polygons.foreach_set("material_index", mesh_data.face_mat)
    compat.set_smooth(me, mesh_data.face_smooth)
    me.validate()
    me.update()
    for desc in mats:
        me.materials.append(_material_from_desc(desc, cfg["object"]))
    obj = bpy.data.objects.new("sfmeval_object", me)
    link(obj, "object")
    levels = int(cfg["object"]["subdivision"])
    if smooth and levels > 0:
        mod = obj.modifiers.new("Subdivision", "SUBSURF")
        mod.levels = levels
        mod.render_levels = levels
    return obj


def _import_file(path):
    """Import a model file; returns the new mesh objects (any hierarchy flattened)."""
    ext = os.path.splitext(path)[1].lower()
    before = set(bpy.data.objects)
    try:
        if ext == ".obj":
            if compat.op_exists("wm", "obj_import"):
                bpy.ops.wm.obj_import(filepath=path)
            else:
                bpy.ops.import_scene.obj(filepath=path)
        elif ext == ".ply":
            if compat.op_exists("wm", "ply_import"):
                bpy.ops.wm.ply_import(filepath=path)
            else:
                bpy.ops.import_mesh.ply(filepath=path)
        elif ext == ".stl":
            if compat.op_exists("wm", "stl_import"):
                bpy.ops.wm.stl_import(filepath=path)
            else:
                bpy.ops.import_mesh.stl(filepath=path)
        elif ext in (".gltf", ".glb"):
            bpy.ops.import_scene.gltf(filepath=path)
        elif ext == ".fbx":
            bpy.ops.import_scene.fbx(filepath=path)
        elif ext == ".blend":
            with bpy.data.libraries.load(path, link=False) as (src, dst):
                dst.objects = list(src.objects)
            for o in dst.objects:
                if o is not None and o.type == "MESH":
                    bpy.context.scene.collection.objects.link(o)
        else:
            raise GenerationError("unsupported model format %r" % ext)
    except GenerationError:
        raise
    except Exception as exc:
        raise GenerationError("cannot import %s: %s" % (path, str(exc).strip().splitlines()[-1]
                                                        if str(exc).strip() else exc)) from None
    new = [o for o in bpy.data.objects if o not in before]
    meshes = [o for o in new if o.type == "MESH" and o.data is not None and len(o.data.vertices) > 0]
    if not meshes:
        for o in new:
            bpy.data.objects.remove(o, do_unlink=True)
        raise GenerationError("cannot import %s: the file holds no mesh with vertices" % path)
    return new, meshes


def _join(new, meshes):
    """One object from all imported meshes: modifiers and world transforms baked into the mesh."""
    dg = bpy.context.evaluated_depsgraph_get()
    baked = []
    for o in meshes:
        me = bpy.data.meshes.new_from_object(o.evaluated_get(dg))
        me.transform(o.matrix_world)
        baked.append(me)
    for o in new:
        bpy.data.objects.remove(o, do_unlink=True)
    main = baked[0]
    if len(baked) > 1:
        import bmesh
        bm = bmesh.new()
        bm.from_mesh(main)
        for me in baked[1:]:
            offset = len(main.materials)
            for m in me.materials:
                main.materials.append(m)
            nfaces = len(bm.faces)
            bm.from_mesh(me)
            bm.faces.ensure_lookup_table()
            for f in bm.faces[nfaces:]:
                f.material_index += offset
            bpy.data.meshes.remove(me)
        bm.to_mesh(main)
        bm.free()
    main.name = "sfmeval_object"
    obj = bpy.data.objects.new("sfmeval_object", main)
    return link(obj, "object")


def _default_material(cfg):
    desc = shapes.material("sfmeval_default", (0.7, 0.62, 0.5), (0.2, 0.18, 0.2), "marble", 5.0, 0.6)
    return _material_from_desc(desc, cfg["object"])


def step_import_object(cfg):
    """Import (or build) the main object, optionally normalised in size and centred."""
    scene = bpy.context.scene
    remove_role("object")
    src = cfg["object"]["source"]
    if src.startswith("builtin:"):
        obj = _build_builtin(src[len("builtin:"):], cfg)
        source = {"kind": "builtin", "name": src[len("builtin:"):], "seed": cfg["dataset"]["seed"]}
    else:
        cfgmod.check_model_file(src)
        new, meshes = _import_file(src)
        obj = _join(new, meshes)
        if not any(m is not None for m in obj.data.materials):
            obj.data.materials.clear()
            obj.data.materials.append(_default_material(cfg))
        with open(src, "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
        source = {"kind": "file", "name": os.path.basename(src), "path": os.path.abspath(src),
                  "format": os.path.splitext(src)[1].lower().lstrip("."), "sha256": digest}
    bpy.context.view_layer.update()
    verts, _ = evaluated_world_vertices(obj)
    lo, hi = bbox(verts)
    o = cfg["object"]
    s = 1.0
    if o["normalize"]:
        extent = max(hi[i] - lo[i] for i in range(3))
        if extent <= 0:
            raise GenerationError("the object has zero size")
        s = o["size"] / extent
    centre = [(lo[i] + hi[i]) / 2 for i in range(3)]
    shift = [0.0, 0.0, 0.0]
    if o["center"]:
        shift = [-centre[i] * s for i in range(3)]
    if o["on_floor"]:
        shift[2] = -lo[2] * s
    obj.matrix_world = Matrix.Translation(Vector(shift)) @ Matrix.Scale(s, 4) @ obj.matrix_world
    bpy.context.view_layer.update()
    store(scene, "source", source)
    store(scene, "config", cfg)
    return obj


# -- step 2: scene ----------------------------------------------------------------------------
def object_frame(cfg):
    """(target, bounding radius around the target) in the Blender frame."""
    obj = get_object()
    verts, _ = evaluated_world_vertices(obj)
    lo, hi = bbox(verts)
    t = cfg["views"]["target"]
    target = [(lo[i] + hi[i]) / 2 for i in range(3)] if t == "object" else [float(x) for x in t]
    radius = max(math.sqrt(sum((v[i] - target[i]) ** 2 for i in range(3))) for v in verts)
    return target, radius


def _plane(name, verts, mat):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], [(0, 1, 2, 3)])
    me.materials.append(mat)
    obj = bpy.data.objects.new(name, me)
    return link(obj, "room")


def step_setup_scene(cfg):
    """World background, lights, optional floor/walls, Cycles and colour-management settings."""
    scene = bpy.context.scene
    target, brad = object_frame(cfg)
    bg = cfg["background"]
    world = bpy.data.worlds.get("sfmeval_world") or bpy.data.worlds.new("sfmeval_world")
    compat.use_nodes(world)
    node = world.node_tree.nodes.get("Background") or world.node_tree.nodes.new("ShaderNodeBackground")
    out = world.node_tree.nodes.get("World Output") or world.node_tree.nodes.new("ShaderNodeOutputWorld")
    if not node.outputs[0].links:
        world.node_tree.links.new(node.outputs[0], out.inputs["Surface"])
    node.inputs["Color"].default_value = list(bg["world_color"]) + [1.0]
    node.inputs["Strength"].default_value = bg["world_strength"]
    scene.world = world

    remove_role("light")
    for i, spec in enumerate(cfg["lights"]):
        ld = bpy.data.lights.new("sfmeval_light_%d" % i, spec["type"].upper())
        ld.energy = spec["energy"]
        ld.color = spec["color"]
        if spec["type"] == "area":
            ld.size = spec["size"]
        elif spec["type"] == "point":
            ld.shadow_soft_size = spec["size"]
        elif spec["type"] == "sun":
            ld.angle = math.radians(spec["size"])
        lo = bpy.data.objects.new("sfmeval_light_%d" % i, ld)
        eye = geometry._point(target, spec["distance"], math.radians(spec["azimuth_deg"]),
                              math.radians(spec["elevation_deg"]))
        rot = geometry.look_at_rotation(eye, target)
        lo.matrix_world = Matrix([rot[0] + [eye[0]], rot[1] + [eye[1]], rot[2] + [eye[2]],
                                  [0, 0, 0, 1]])
        link(lo, "light")

    remove_role("room")
    if bg["floor"] or bg["walls"]:
        mat = bpy.data.materials.get("sfmeval_room") or bpy.data.materials.new("sfmeval_room")
        compat.use_nodes(mat)
        bsdf = mat.node_tree.nodes.get("Principled BSDF")
        if bsdf is not None:
            bsdf.inputs["Base Color"].default_value = list(bg["wall_color"]) + [1.0]
            compat.set_input(bsdf, ["Roughness"], 0.9)
        h = bg["room_size"] / 2.0
        obj = get_object()
        zmin = bbox(evaluated_world_vertices(obj)[0])[0][2]
        z1 = zmin + 2 * h
        if bg["floor"]:
            _plane("sfmeval_floor", [(-h, -h, zmin), (h, -h, zmin), (h, h, zmin), (-h, h, zmin)], mat)
        if bg["walls"]:
            corners = [(-h, -h), (h, -h), (h, h), (-h, h)]
            for k in range(4):
                (xa, ya), (xb, yb) = corners[k], corners[(k + 1) % 4]
                _plane("sfmeval_wall_%d" % k, [(xa, ya, zmin), (xa, ya, z1), (xb, yb, z1),
                                               (xb, yb, zmin)], mat)
            _plane("sfmeval_ceiling", [(-h, -h, z1), (-h, h, z1), (h, h, z1), (h, -h, z1)], mat)

    configure_render(scene, cfg)
    store(scene, "config", cfg)


def configure_render(scene, cfg):
    r = cfg["render"]
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = r["samples"]
    cy.use_adaptive_sampling = r["adaptive_sampling"]
    cy.max_bounces = r["max_bounces"]
    cy.diffuse_bounces = r["diffuse_bounces"]
    cy.glossy_bounces = r["glossy_bounces"]
    cy.transmission_bounces = r["transmission_bounces"]
    cy.volume_bounces = 0
    cy.seed = cfg["dataset"]["seed"] if r["seed"] < 0 else r["seed"]
    cy.use_animated_seed = False
    cy.filter_width = r["filter_width"]
    want = r["denoise"]
    available = compat.oidn_available()
    if want is True and not available:
        raise GenerationError("render.denoise = true, but this Blender has no OpenImageDenoise "
                              "(Debian's build lacks it): use \"auto\" or false")
    use = available if want == "auto" else bool(want)
    cy.use_denoising = use
    if use and "denoiser" in cy.bl_rna.properties:
        cy.denoiser = "OPENIMAGEDENOISE"
    scene.render.film_transparent = False
    scene.render.use_persistent_data = True
    # No Blender metadata in the image files (it holds render times and paths, so the same
    # config would give different bytes); the EXIF we write is the only metadata.
    for prop in scene.render.bl_rna.properties.keys():
        if prop.startswith("use_stamp"):
            setattr(scene.render, prop, False)
    if r["threads"] > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = r["threads"]
    else:
        scene.render.threads_mode = "AUTO"
    vs = scene.view_settings
    scene.display_settings.display_device = "sRGB"
    vs.view_transform = r["view_transform"]
    vs.look = "None"
    vs.exposure = 0.0
    vs.gamma = 1.0
    vs.use_curve_mapping = False
    return use


# -- step 3: camera ---------------------------------------------------------------------------
def step_setup_camera(cfg):
    scene = bpy.context.scene
    c = cfg["camera"]
    remove_role("camera")
    cd = bpy.data.cameras.new("sfmeval_camera")
    cd.type = "PERSP"
    cd.lens_unit = "MILLIMETERS"
    cd.lens = c["focal_mm"]
    cd.sensor_fit = "HORIZONTAL"
    cd.sensor_width = c["sensor_mm"][0]
    cd.sensor_height = c["sensor_mm"][1]
    cd.shift_x, cd.shift_y = c["shift"]
    cd.clip_start = c["clip_start"]
    cd.clip_end = c["clip_end"]
    cam = link(bpy.data.objects.new("sfmeval_camera", cd), "camera")
    cam.rotation_mode = "QUATERNION"
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = c["resolution"]
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.use_border = False
    store(scene, "config", cfg)
    return cam


def camera_intrinsics(scene, cam):
    """Intrinsics in pixels from the Blender camera actually used (COLMAP convention)."""
    cd = cam.data
    if cd.sensor_fit != "HORIZONTAL":
        raise GenerationError("camera sensor_fit must be HORIZONTAL")
    w, h = scene.render.resolution_x, scene.render.resolution_y
    k = geometry.intrinsics({"resolution": [w, h], "focal_mm": cd.lens,
                             "sensor_mm": [cd.sensor_width, cd.sensor_height],
                             "shift": [cd.shift_x, cd.shift_y]})
    return k


# -- step 4: orbits ---------------------------------------------------------------------------
def step_animate(cfg):
    """Key the camera through every view: frame 1 + i is view i (constant interpolation)."""
    scene = bpy.context.scene
    cam = get_camera()
    target, brad = object_frame(cfg)
    auto = geometry.auto_radius(brad, cfg["camera"], cfg["views"]["fill"])
    views = geometry.camera_positions(cfg["views"], target, auto, cfg["dataset"]["seed"])
    if not views:
        raise GenerationError("zero views: configure views.orbits / views.sphere / views.shell")
    if cam.animation_data:
        cam.animation_data_clear()
    prefs = bpy.context.preferences.edit
    old_interp = prefs.keyframe_new_interpolation_type
    prefs.keyframe_new_interpolation_type = "CONSTANT"
    try:
        for i, v in enumerate(views):
            rot = geometry.look_at_rotation(v["eye"], target)
            m = Matrix([rot[0] + [v["eye"][0]], rot[1] + [v["eye"][1]], rot[2] + [v["eye"][2]],
                        [0, 0, 0, 1]])
            cam.matrix_world = m
            frame = i + 1
            cam.keyframe_insert("location", frame=frame)
            cam.keyframe_insert("rotation_quaternion", frame=frame)
    finally:
        prefs.keyframe_new_interpolation_type = old_interp
    scene.frame_start = 1
    scene.frame_end = len(views)
    scene.frame_set(1)
    fmt = cfg["outputs"]["name_format"]
    ext = ".jpg" if cfg["render"]["format"] == "JPEG" else ".png"
    meta = [{"name": fmt.format(i) + ext, "frame": i + 1, "group": v["group"],
             "azimuth_deg": v["azimuth_deg"], "elevation_deg": v["elevation_deg"],
             "radius": v["radius"]} for i, v in enumerate(views)]
    store(scene, "views", meta)
    store(scene, "target", {"target": target, "bounding_radius": brad, "auto_radius": auto})
    store(scene, "config", cfg)
    return meta


# -- step 5: render ---------------------------------------------------------------------------
def _set_output(scene, fmt, cfg):
    im = scene.render.image_settings
    if fmt == "JPEG":
        im.file_format = "JPEG"
        im.color_mode = "RGB"
        im.quality = cfg["render"]["jpeg_quality"]
    elif fmt == "PNG":
        im.file_format = "PNG"
        im.color_mode = "RGB"
        im.color_depth = str(cfg["render"]["png_color_depth"])
        im.compression = 15
    elif fmt == "EXR":
        im.file_format = "OPEN_EXR"
        im.color_mode = "RGBA"
        im.color_depth = "32"
        im.exr_codec = "ZIP"
    scene.render.use_file_extension = False


def _render_to(scene, path):
    scene.render.filepath = path
    try:
        bpy.ops.render.render(write_still=True)
    except RuntimeError as exc:
        raise GenerationError("rendering %s failed: %s" % (
            path, str(exc).strip().replace("Error: ", "", 1))) from None
    if not os.path.isfile(path):
        raise GenerationError("Blender did not write %s" % path)


def step_render(cfg, out_dir, progress=None, frames=None):
    """Render every view to images/, write EXIF, then (optionally) depth and masks."""
    scene = bpy.context.scene
    cam = get_camera()
    meta = load(scene, "views")
    if not meta:
        raise GenerationError("no views: run the 'animate orbits' step first")
    if frames is not None:
        meta = [m for m in meta if m["frame"] in frames]
    img_dir = os.path.join(out_dir, "images")
    os.makedirs(img_dir, exist_ok=True)
    denoise_used = configure_render(scene, cfg)
    pp_on = postprocess.active(cfg)
    if pp_on:
        try:
            postprocess.check_available()
        except ImportError as exc:
            raise GenerationError(str(exc)) from None
    _set_output(scene, "PNG" if pp_on else cfg["render"]["format"], cfg)
    if pp_on:
        scene.render.image_settings.color_depth = "8"
    c = cfg["camera"]
    w, h = scene.render.resolution_x, scene.render.resolution_y
    times = []
    aux_time = 0.0
    without_object = None                     # unknown without a depth/mask pass
    # Objects sfmeval did not make stay out of every render unless kept as context.
    with other_objects_hidden(scene, cfg) as hiding:
        for k, m in enumerate(meta):
            scene.frame_set(m["frame"])
            hiding.check()
            path = os.path.join(img_dir, m["name"])
            t0 = time.perf_counter()
            if pp_on:  # render losslessly, then blur/noise into the configured format
                tmp = path + ".render.png"
                _render_to(scene, tmp)
                postprocess.process_file(tmp, path, cfg, m["frame"] - 1)
                os.remove(tmp)
            else:
                _render_to(scene, path)
            times.append(time.perf_counter() - t0)
            if c["exif"]:
                exif.write_exif(path, width=w, height=h, focal_mm=cam.data.lens,
                                sensor_mm=[cam.data.sensor_width, cam.data.sensor_height],
                                make=c["make"], model=c["model"],
                                software="sfmeval_blender %s / Blender %s" % (__version__, bpy.app.version_string),
                                unit=c["exif_focal_plane_unit"], write_35mm=c["exif_35mm_equivalent"])
            if progress:
                progress("render", k + 1, len(meta), times[-1])
        if cfg["outputs"]["depth"] or cfg["outputs"]["masks"]:
            t0 = time.perf_counter()
            without_object = render_aux(cfg, out_dir, meta, progress, hiding.check)
            aux_time = time.perf_counter() - t0
    info = {"postprocess": {"applied": pp_on, "blur_sigma": cfg["postprocess"]["blur_sigma"],
                            "noise_sigma": cfg["postprocess"]["noise_sigma"],
                            "seed": postprocess.seed_of(cfg),
                            "order": "blur, then noise, on the 8-bit render, before EXIF"},
            "seconds_per_frame": times, "aux_seconds_total": aux_time, "denoise_used": denoise_used,
            "denoise_available": compat.oidn_available(), "frames": len(meta),
            "other_objects": hiding.record, "views_without_object": without_object}
    store(scene, "render_info", info)
    return info


def _aux_material():
    mat = bpy.data.materials.get("sfmeval_depth") or bpy.data.materials.new("sfmeval_depth")
    compat.use_nodes(mat)
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    camdata = nt.nodes.new("ShaderNodeCameraData")
    em = nt.nodes.new("ShaderNodeEmission")
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    em.inputs["Strength"].default_value = 1.0
    nt.links.new(camdata.outputs["View Z Depth"], em.inputs["Color"])
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    return mat


def render_aux(cfg, out_dir, meta, progress=None, after_frame=None):
    """Depth (float32 .npy, metres along the optical axis, 0 = no object) and masks (PNG).

    One extra Cycles pass per view: every surface replaced by an emission of its camera-space Z
    depth, 1 sample through a 0.01-pixel box filter (so each pixel sees exactly the ray through
    its centre), transparent film (alpha = object coverage), walls, floor and lights hidden.
    Other objects kept as context are holdouts: they hide the object behind them (depth 0,
    mask 0, as in the images) but are never object themselves.

    `after_frame()` runs after every frame change. Returns the names of the views in which no
    pixel shows the object."""
    import numpy as np
    scene = bpy.context.scene
    vl = bpy.context.view_layer
    r = scene.render
    saved = {
        "samples": scene.cycles.samples, "filter_type": scene.cycles.pixel_filter_type,
        "filter_width": scene.cycles.filter_width, "film": r.film_transparent,
        "denoise": scene.cycles.use_denoising, "bounces": scene.cycles.max_bounces,
        "override": vl.material_override, "vt": scene.view_settings.view_transform,
        "adaptive": scene.cycles.use_adaptive_sampling,
    }
    hidden = [o for o in scene.objects if not o.hide_render
              and (o.get(ROLE) == "room" or o.type == "LIGHT")]
    holdouts = [o for o, t in other_objects(scene, cfg) if t == "context"
                and o.type != "LIGHT" and not o.is_holdout]
    without_object = []
    try:
        scene.cycles.samples = 1
        scene.cycles.use_adaptive_sampling = False
        scene.cycles.pixel_filter_type = "BOX"
        scene.cycles.filter_width = 0.01
        scene.cycles.use_denoising = False
        scene.cycles.max_bounces = 0
        r.film_transparent = True
        vl.material_override = _aux_material()
        if "Raw" in compat.enum_items(scene.view_settings, "view_transform"):
            scene.view_settings.view_transform = "Raw"
        for o in hidden:
            o.hide_render = True
        for o in holdouts:
            o.is_holdout = True
        _set_output(scene, "EXR", cfg)
        # one name per process: parts of a dataset may render into the same folder at once
        tmp = os.path.join(out_dir, ".aux-%d.exr" % os.getpid())
        depth_dir = os.path.join(out_dir, "depth")
        mask_dir = os.path.join(out_dir, "masks")
        if cfg["outputs"]["depth"]:
            os.makedirs(depth_dir, exist_ok=True)
        if cfg["outputs"]["masks"]:
            os.makedirs(mask_dir, exist_ok=True)
        w, h = r.resolution_x, r.resolution_y
        for k, m in enumerate(meta):
            scene.frame_set(m["frame"])
            if after_frame:
                after_frame()
            _render_to(scene, tmp)
            img = bpy.data.images.load(tmp, check_existing=False)
            try:
                img.colorspace_settings.name = "Non-Color"
                buf = np.empty(w * h * 4, dtype=np.float32)
                img.pixels.foreach_get(buf)
            finally:
                bpy.data.images.remove(img)
            rgba = buf.reshape(h, w, 4)[::-1]             # Blender stores rows bottom-up
            cover = rgba[:, :, 3] > 0.5
            if not cover.any():
                without_object.append(m["name"])
            stem = os.path.splitext(m["name"])[0]
            if cfg["outputs"]["depth"]:
                depth = np.where(cover, rgba[:, :, 0], 0.0).astype(np.float32)
                np.save(os.path.join(depth_dir, stem + ".npy"), depth)
            if cfg["outputs"]["masks"]:
                mask = (cover * 255).astype(np.uint8)
                exif.write_png_gray(os.path.join(mask_dir, stem + ".png"), mask.tobytes(), w, h)
            if progress:
                progress("depth/masks", k + 1, len(meta), None)
        if os.path.exists(tmp):
            os.remove(tmp)
    finally:
        scene.cycles.samples = saved["samples"]
        scene.cycles.pixel_filter_type = saved["filter_type"]
        scene.cycles.filter_width = saved["filter_width"]
        scene.cycles.use_denoising = saved["denoise"]
        scene.cycles.max_bounces = saved["bounces"]
        scene.cycles.use_adaptive_sampling = saved["adaptive"]
        r.film_transparent = saved["film"]
        vl.material_override = saved["override"]
        scene.view_settings.view_transform = saved["vt"]
        for o in hidden:
            o.hide_render = False
        for o in holdouts:
            o.is_holdout = False
        _set_output(scene, cfg["render"]["format"], cfg)
    return without_object


# -- step 6: ground truth ---------------------------------------------------------------------
def _r(x, nd=12):
    return round(float(x), nd)


def dump_json(obj, path):
    """JSON with one line per small numeric array (rotation rows, vectors)."""
    import re
    text = json.dumps(obj, indent=1)
    text = re.sub(r"\[\s*([-0-9.eE+,\s]+?)\s*\]",
                  lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text)
    with open(path, "w") as f:
        f.write(text + "\n")


def gt_cameras(scene):
    cam = get_camera()
    meta = load(scene, "views") or []
    k = camera_intrinsics(scene, cam)
    images = []
    current = scene.frame_current
    for m in meta:
        scene.frame_set(m["frame"])
        mw = cam.matrix_world
        # Blender keeps the pose in float32: take its unit quaternion and build the rotation in
        # double precision, so that the written matrix is orthonormal to ~1e-16.
        q = mw.to_quaternion()
        rot = geometry.quaternion_to_rotation([q.w, q.x, q.y, q.z])
        centre = [mw[0][3], mw[1][3], mw[2][3]]
        R, t, c = geometry.opencv_pose_gltf(rot, centre)
        images.append({"name": m["name"], "camera_id": 1,
                       "cam_from_world": {"rotation": [[_r(x) for x in row] for row in R],
                                          "translation": [_r(x) for x in t]},
                       "center": [_r(x) for x in c]})
    scene.frame_set(current)
    cd = cam.data
    camera = {"id": 1, "model": "PINHOLE", "width": k["width"], "height": k["height"],
              "fx": _r(k["fx"]), "fy": _r(k["fy"]), "cx": _r(k["cx"]), "cy": _r(k["cy"]),
              "focal_mm": _r(cd.lens, 9), "sensor_mm": [_r(cd.sensor_width, 9), _r(cd.sensor_height, 9)]}
    return {"schema": "sfmeval.cameras/1", "frame": "gltf", "pixel_convention": "colmap",
            "cameras": [camera], "images": images}


def write_colmap_text(cams, folder):
    os.makedirs(folder, exist_ok=True)
    c = cams["cameras"][0]
    with open(os.path.join(folder, "cameras.txt"), "w") as f:
        f.write("# Camera list with one line of data per camera:\n")
        f.write("#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n")
        f.write("# Number of cameras: 1\n")
        f.write("%d PINHOLE %d %d %r %r %r %r\n" % (c["id"], c["width"], c["height"],
                                                   c["fx"], c["fy"], c["cx"], c["cy"]))
    with open(os.path.join(folder, "images.txt"), "w") as f:
        f.write("# Image list with two lines of data per image:\n")
        f.write("#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n")
        f.write("#   POINTS2D[] as (X, Y, POINT3D_ID)\n")
        f.write("# Number of images: %d, mean observations per image: 0\n" % len(cams["images"]))
        for i, im in enumerate(cams["images"]):
            q = geometry.rotation_to_quaternion(im["cam_from_world"]["rotation"])
            t = im["cam_from_world"]["translation"]
            f.write("%d %s %s %d %s\n\n" % (i + 1, " ".join(repr(x) for x in q),
                                            " ".join(repr(x) for x in t), im["camera_id"], im["name"]))
    with open(os.path.join(folder, "points3D.txt"), "w") as f:
        f.write("# 3D point list with one line of data per point:\n")
        f.write("#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n")
        f.write("# Number of points: 0, mean track length: 0\n")


def export_glb(obj, path):
    """The object alone (selection-only export); the user's selection and active object are
    restored afterwards."""
    vl = bpy.context.view_layer
    selected = [o for o in vl.objects if o.select_get()]
    active = vl.objects.active
    try:
        _export_selected_glb(obj, path)
    finally:
        for o in vl.objects:
            o.select_set(o in selected)
        vl.objects.active = active


def _export_selected_glb(obj, path):
    vl = bpy.context.view_layer
    for o in vl.objects:
        o.select_set(False)
    obj.select_set(True)
    vl.objects.active = obj
    op = bpy.ops.export_scene.gltf
    kwargs = compat.op_kwargs(op, filepath=path, export_format="GLB", use_selection=True,
                              export_apply=True, export_yup=True, export_materials="NONE",
                              export_cameras=False, export_lights=False, export_animations=False,
                              export_extras=False, export_texcoords=True, export_normals=True,
                              export_skins=False, export_morph=False, will_save_settings=False)
    try:
        res = op(**kwargs)
    except Exception as exc:
        raise GenerationError("glTF export failed: %s (the exporter needs numpy: on Debian "
                              "`apt-get install python3-numpy`)" % exc) from None
    if "FINISHED" not in res or not os.path.isfile(path):
        raise GenerationError("glTF export did not write %s" % path)


def step_export(cfg, out_dir, timing_parts=None):
    """ground_truth.glb, cameras.json, dataset.json, timing.json, sparse_gt/ (and scene.blend on
    request). `timing_parts`: the measured times of each rendered part (finalize)."""
    scene = bpy.context.scene
    obj = get_object()
    os.makedirs(out_dir, exist_ok=True)
    export_glb(obj, os.path.join(out_dir, "ground_truth.glb"))
    cams = gt_cameras(scene)
    dump_json(cams, os.path.join(out_dir, "cameras.json"))
    if cfg["outputs"]["colmap_gt"]:
        write_colmap_text(cams, os.path.join(out_dir, "sparse_gt"))
    verts, ntri = evaluated_world_vertices(obj)
    gv = [geometry.blender_to_gltf(v) for v in verts]
    lo, hi = bbox(gv)
    tgt = load(scene, "target", {})
    info = load(scene, "render_info", {}) or {}
    times = info.get("seconds_per_frame", [])
    views = load(scene, "views", [])
    ds = {
        "schema": "sfmeval.dataset/1",
        "name": cfg["dataset"]["name"],
        "description": cfg["dataset"]["description"],
        "generator": {"name": "sfmeval_blender", "version": __version__},
        "blender": {"version": bpy.app.version_string,
                    "build_hash": bpy.app.build_hash.decode() if isinstance(bpy.app.build_hash, bytes) else str(bpy.app.build_hash),
                    "as_python_module": bool(getattr(bpy.app, "binary_path", "") == ""),
                    "python": sys.version.split()[0]},
        "seed": cfg["dataset"]["seed"],
        "source": load(scene, "source", {}),
        "object": {"vertices": len(verts), "triangles": ntri, "bbox_min_gltf": lo, "bbox_max_gltf": hi,
                   "target_gltf": geometry.blender_to_gltf(tgt["target"]) if tgt else None,
                   "bounding_radius": tgt.get("bounding_radius"), "auto_orbit_radius": tgt.get("auto_radius")},
        "settings": cfg,
        "render": {"engine": "CYCLES", "device": "CPU", "samples": scene.cycles.samples,
                   "denoise_used": info.get("denoise_used"), "denoise_available": compat.oidn_available(),
                   "threads": scene.render.threads, "view_transform": scene.view_settings.view_transform,
                   "postprocess": info.get("postprocess"),
                   "views_without_object": info.get("views_without_object")},
        "other_objects": info.get("other_objects") or other_objects_record(scene, cfg),
        "images": len(views),
        "views": views,
        "files": {"images": "images/", "ground_truth": "ground_truth.glb", "cameras": "cameras.json",
                  "sparse_gt": "sparse_gt/" if cfg["outputs"]["colmap_gt"] else None,
                  "depth": "depth/<image stem>.npy" if cfg["outputs"]["depth"] else None,
                  "masks": "masks/<image stem>.png" if cfg["outputs"]["masks"] else None,
                  "blend": "scene.blend" if cfg["outputs"]["save_blend"] else None},
    }
    dump_json(ds, os.path.join(out_dir, "dataset.json"))
    # What was measured goes beside it: dataset.json is the same bytes for the same config
    # (and Blender), however and wherever the views were rendered.
    timing = {"schema": "sfmeval.timing/1",
              "render_seconds_per_frame": [round(t, 3) for t in times],
              "render_seconds_mean": round(sum(times) / len(times), 3) if times else None,
              "render_seconds_total": round(sum(times), 3),
              "depth_mask_seconds_total": round(info.get("aux_seconds_total", 0.0), 3),
              "parts": timing_parts,
              "created_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    dump_json(timing, os.path.join(out_dir, "timing.json"))
    if cfg["outputs"]["save_blend"]:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(os.path.join(out_dir, "scene.blend")),
                                    copy=True)
    return ds
