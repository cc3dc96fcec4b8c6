"""The bpy side of steps 8–11: reconstructions as objects, their measurement, the crop file.

A dataset's ground-truth frame is glTF's (Y up, docs/dataset.md); Blender's world is Z up. Every
imported reconstruction is parented to one empty, "sfmeval GT frame", whose matrix is
blender_from_gltf, so a points object's own matrix (``matrix_basis``) IS the alignment
gt_from_recon and its mesh holds the points in the reconstruction's frame, as the file has them.
Moving, rotating or scaling the object changes the alignment; deleting vertices in Edit Mode
removes points from the evaluation.

The mesh's vertices are float32 (Blender's), so they are only what is shown: every vertex
carries the integer attribute ``sfmeval_index``, its row in the float64 source that ``sfmeval
export`` wrote (``compare/NAME/source/points.ply``), and what is measured are the source's rows
of the vertices still there.
"""

import json
import os

import bpy
import numpy as np
from mathutils import Matrix

from . import crop as cropmod
from . import evaluate as ev
from . import plyio

GT_FRAME = "sfmeval GT frame"
# glTF = (x, z, -y) of Blender (geometry.blender_to_gltf)
GLTF_FROM_BLENDER = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], float)
PROP_T = "sfmeval_gt_from_recon"
INDEX = "sfmeval_index"
SOURCE = "sfmeval_points"  # the object's float64 source PLY (sfmeval export)
GT_COLLECTION = "sfmeval ground truth"


def dataset_dir(context):
    """The dataset folder: the one set in the Compare panel, else the generator's output."""
    c = context.scene.sfmeval_compare
    d = c.dataset_dir or context.scene.sfmeval.out_dir
    # absolute: the runner is given absolute folders
    return os.path.abspath(bpy.path.abspath(d)) if d else ""


def work_dir(context, name=None):
    """``<dataset>/compare[/<name>]``: everything the add-on writes (points, reports, crop)."""
    d = os.path.join(dataset_dir(context), "compare")
    return os.path.join(d, name) if name else d


def require_dataset(context):
    d = dataset_dir(context)
    if not d or not os.path.isfile(os.path.join(d, "cameras.json")):
        raise ValueError("no dataset at '%s' (no cameras.json): generate one (steps 1–6) or set "
                         "the dataset folder in Compare pipelines" % d)
    return d


def gt_frame(context):
    """The empty carrying blender_from_gltf (made once, in the scene's main collection)."""
    obj = bpy.data.objects.get(GT_FRAME)
    if obj is None:
        obj = bpy.data.objects.new(GT_FRAME, None)
        obj.empty_display_size = 0.1
        context.scene.collection.objects.link(obj)
    obj.matrix_world = Matrix(np.linalg.inv(GLTF_FROM_BLENDER).tolist())
    return obj


def _collection(context, name):
    coll = bpy.data.collections.get(name)
    if coll is None:
        coll = bpy.data.collections.new(name)
        context.scene.collection.children.link(coll)
    return coll


def gt_from_recon(obj):
    """The object's alignment (float64 4×4): the exact one stored at the last alignment while
    the object's matrix still holds it (Blender keeps the matrix as float32 location, rotation
    and scale: ~1e-6 off; a move smaller than 0.001°, 1e-5 in scale and
    translation is taken as no move), else the matrix the user gave it by moving the object."""
    m = np.array(obj.matrix_basis, dtype=float)
    stored = obj.get(PROP_T)
    if stored is not None:
        s = np.array(list(stored), dtype=float).reshape(4, 4)
        deg, dscale = ev.rotation_scale_change(s, m)
        dt = np.linalg.norm(s[:3, 3] - m[:3, 3])
        if deg < 1e-3 and abs(dscale) < 1e-5 and dt < 1e-5 * max(1.0, np.linalg.norm(s[:3, 3])):
            return s
    return m


def set_gt_from_recon(obj, m):
    m = np.asarray(m, dtype=float).reshape(4, 4)
    obj.matrix_basis = Matrix(m.tolist())
    obj[PROP_T] = m.reshape(-1).tolist()


def show_ground_truth(context, dataset):
    """The dataset's ground_truth.glb in the scene, in its own collection "sfmeval ground truth"
    (once; display only: the evaluation reads the file). Returns an error text, or ""."""
    coll = _collection(context, GT_COLLECTION)
    if len(coll.objects):
        return ""
    path = os.path.join(dataset, "ground_truth.glb")
    if not os.path.isfile(path):
        return "no ground_truth.glb in %s" % dataset
    if not hasattr(np, "bool"):  # Blender 3.4's glTF importer uses np.bool (numpy < 1.24)
        np.bool = bool
    before = set(bpy.data.objects)
    layer = context.view_layer
    selected, active = list(context.selected_objects), layer.objects.active
    try:
        bpy.ops.import_scene.gltf(filepath=path)
    except Exception as exc:  # display only: never fail the import for it
        return "ground truth display: %s" % exc
    for obj in set(bpy.data.objects) - before:
        for other in list(obj.users_collection):
            other.objects.unlink(obj)
        coll.objects.link(obj)
        obj.select_set(False)  # the importer selects what it made: the user's selection stays
    for obj in selected:
        if obj.name in layer.objects:
            obj.select_set(True)
    layer.objects.active = active
    return ""


def new_points_object(context, name, points, cameras_json=None):
    """A collection `name` with the points object `name` (mesh of loose vertices in the
    reconstruction's frame, each with its source row in ``sfmeval_index``) under the GT frame,
    and the estimated cameras as its children."""
    coll = _collection(context, "sfmeval " + name)
    old = bpy.data.objects.get(name)
    if old is not None:
        for child in list(old.children):
            bpy.data.objects.remove(child, do_unlink=True)
        bpy.data.objects.remove(old, do_unlink=True)
    mesh = bpy.data.meshes.new(name)
    pts = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    mesh.vertices.add(len(pts))
    mesh.vertices.foreach_set("co", pts.ravel())
    index = mesh.attributes.new(INDEX, "INT", "POINT")
    index.data.foreach_set("value", np.arange(len(pts), dtype=np.int32))
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    coll.objects.link(obj)
    obj.parent = gt_frame(context)
    obj.matrix_parent_inverse.identity()
    if len(pts):
        # the cloud's extent without its few far outliers (which would make the points huge)
        lo, hi = np.percentile(pts, [2, 98], axis=0)
        size = float(np.linalg.norm(hi - lo))
        obj["sfmeval_display"] = show_as_points(obj, max(size, 1e-9) * 0.004)
    if cameras_json and os.path.isfile(cameras_json):
        add_cameras(coll, obj, cameras_json)
    return obj


def _points_material():
    """Material showing the ``sfmeval_color`` attribute (Material Preview / Rendered)."""
    mat = bpy.data.materials.get("sfmeval points")
    if mat is not None:
        return mat
    mat = bpy.data.materials.new("sfmeval points")
    mat.use_nodes = True
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "sfmeval_color"
    nt.links.new(attr.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


# Point clouds: Solid shading never colours them and EEVEE draws them only from 4.2 on (EEVEE
# Next; Debian's 3.4 shows them grey, Blender 5 in colour). Before 4.2 the points are tiny ico
# spheres instead: real faces carrying ``sfmeval_color`` (and the active colour attribute).
POINTS_AS_SPHERES = bpy.app.version < (4, 2, 0)


def show_as_points(obj, radius):
    """A geometry-nodes modifier drawing the loose vertices as points of `radius` (the mesh,
    which the evaluation reads, is unchanged): a point cloud in Blender 4.2+, else a low-poly
    sphere on every vertex (realized, so ``sfmeval_color`` reaches Solid shading's Attribute
    colour). Returns an error text, or "" when done."""
    try:
        ng = bpy.data.node_groups.new("sfmeval points", "GeometryNodeTree")
        if hasattr(ng, "interface"):  # Blender 4+
            ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
            ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
        else:  # Blender 3.x
            ng.inputs.new("NodeSocketGeometry", "Geometry")
            ng.outputs.new("NodeSocketGeometry", "Geometry")
        gi = ng.nodes.new("NodeGroupInput")
        go = ng.nodes.new("NodeGroupOutput")
        sm = ng.nodes.new("GeometryNodeSetMaterial")
        sm.inputs["Material"].default_value = _points_material()
        if POINTS_AS_SPHERES:
            ico = ng.nodes.new("GeometryNodeMeshIcoSphere")
            ico.inputs["Radius"].default_value = radius
            ico.inputs["Subdivisions"].default_value = 1
            iop = ng.nodes.new("GeometryNodeInstanceOnPoints")
            real = ng.nodes.new("GeometryNodeRealizeInstances")
            ng.links.new(gi.outputs[0], iop.inputs["Points"])
            ng.links.new(ico.outputs["Mesh"], iop.inputs["Instance"])
            ng.links.new(iop.outputs["Instances"], real.inputs["Geometry"])
            ng.links.new(real.outputs["Geometry"], sm.inputs["Geometry"])
        else:
            m2p = ng.nodes.new("GeometryNodeMeshToPoints")
            m2p.inputs["Radius"].default_value = radius
            ng.links.new(gi.outputs[0], m2p.inputs["Mesh"])
            ng.links.new(m2p.outputs["Points"], sm.inputs["Geometry"])
        ng.links.new(sm.outputs["Geometry"], go.inputs[0])
        mod = obj.modifiers.new("sfmeval points", "NODES")
        mod.node_group = ng
        return ""
    except Exception as exc:  # display only: never fail the import for it
        return "points display: %s" % exc


def show_colors(context):
    """Solid shading coloured by the active colour attribute (``sfmeval_color``: Color:
    Attribute, enum VERTEX) in the 3D views of the window, if there is one."""
    screen = getattr(context, "screen", None)
    for area in (screen.areas if screen else ()):
        if area.type == "VIEW_3D":
            for space in area.spaces:
                if space.type == "VIEW_3D":
                    space.shading.color_type = "VERTEX"  # shown as "Attribute"


def add_cameras(coll, parent, path):
    """The cameras of an ``sfmeval.cameras/1`` file as camera objects parented to `parent`
    (poses in the reconstruction's frame: they follow the alignment)."""
    with open(path) as f:
        doc = json.load(f)
    cams = {c.get("id", i): c for i, c in enumerate(doc.get("cameras", []))}
    flip = np.diag([1.0, -1.0, -1.0])  # COLMAP camera (z forward, y down) → Blender's
    for im in doc.get("images", []):
        pose = im.get("cam_from_world")
        if not pose:
            continue
        R = np.array(pose["rotation"], float)
        t = np.array(pose["translation"], float)
        m = np.eye(4)
        m[:3, :3] = R.T @ flip
        m[:3, 3] = -R.T @ t
        cam = cams.get(im.get("camera_id"), next(iter(cams.values()), None))
        data = bpy.data.cameras.new("%s %s" % (parent.name, im.get("name", "")))
        if cam and cam.get("width"):
            data.sensor_fit = "HORIZONTAL"
            data.sensor_width = 36.0
            data.lens = cam["fx"] * 36.0 / cam["width"]
        data.display_size = 0.05
        obj = bpy.data.objects.new(data.name, data)
        coll.objects.link(obj)
        obj.parent = parent
        obj.matrix_parent_inverse.identity()
        obj.matrix_basis = Matrix(m.tolist())


def leave_edit_mode(obj):
    """Back to Object Mode (the Edit Mode deletions are applied to the mesh)."""
    if obj.mode == "EDIT":
        bpy.context.view_layer.objects.active = obj
        bpy.ops.object.mode_set(mode="OBJECT")


def kept_indices(obj):
    """The source rows (``sfmeval_index``) of the vertices left in the object's mesh, Edit Mode
    deletions included (the object leaves Edit Mode)."""
    leave_edit_mode(obj)
    mesh = obj.data
    attr = mesh.attributes.get(INDEX)
    if attr is None or attr.data_type != "INT" or attr.domain != "POINT":
        raise ValueError("%s has no integer point attribute '%s': import it again" %
                         (obj.name, INDEX))
    idx = np.empty(len(mesh.vertices), dtype=np.int32)
    attr.data.foreach_get("value", idx)
    return idx


_SOURCES = {}


def source_points(obj):
    """The object's float64 source points (``sfmeval export``'s PLY; read once per file)."""
    path = obj.get(SOURCE)
    if not path or not os.path.isfile(path):
        raise ValueError("%s: its source points (%s) are gone: import it again" % (obj.name, path))
    key = (path, os.path.getmtime(path))
    if key not in _SOURCES:
        _SOURCES.clear()
        _SOURCES[key] = plyio.read_vertices(path)
    return _SOURCES[key]


def kept_points(obj):
    """The float64 source points of the vertices left in the object's mesh (recon frame), Edit
    Mode deletions included. A vertex added (its index attribute 0, or a copy's), duplicated or
    moved in Edit Mode has no source point of its own: each is an error naming how many, never
    a point dropped or measured at another's position. A vertex still has its source row when
    its index is in range, used once, and its position is that row's float32 value (as the
    import wrote it)."""
    idx = kept_indices(obj)
    src = source_points(obj)
    if not len(idx):
        return src[idx]
    co = np.empty(3 * len(idx), dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    in_range = (idx >= 0) & (idx < len(src))
    same = np.zeros(len(idx), dtype=bool)
    same[in_range] = np.all(co[in_range] == src[idx[in_range]].astype(np.float32), axis=1)
    _, first = np.unique(idx, return_index=True)
    once = np.zeros(len(idx), dtype=bool)
    once[first] = True
    orphans = int(np.count_nonzero(~(same & once)))
    if orphans:
        raise ValueError("%s: %d of its %d vertices were added, duplicated or moved in Edit Mode "
                         "and have no source point (only deleting points is measured): undo "
                         "that, or import it again" % (obj.name, orphans, len(idx)))
    return src[idx]


def crop_file(context):
    """Writes ``<dataset>/compare/crop.json`` from the crop object and the max distance; returns
    its path, or None (and removes a stale file) when there is no crop."""
    c = context.scene.sfmeval_compare
    path = os.path.join(work_dir(context), "crop.json")
    volume = None
    obj = c.crop_object
    if obj is not None:
        if obj.type == "EMPTY":
            kind = "sphere" if obj.empty_display_type == "SPHERE" else "box"
            s = obj.empty_display_size
            lo, hi = (-s, -s, -s), (s, s, s)
        elif obj.type == "MESH":
            kind = "sphere" if obj.get("sfmeval_crop") == "sphere" else "box"
            bb = np.array([list(v) for v in obj.bound_box])
            lo, hi = bb.min(0), bb.max(0)
        else:
            raise ValueError("crop object '%s' is a %s: use an empty (cube or sphere) or a mesh"
                             % (obj.name, obj.type))
        m = GLTF_FROM_BLENDER @ np.array(obj.matrix_world, dtype=float)
        volume = cropmod.volume_from_matrix(kind, m, lo, hi)
    # the value as typed (the property is float32: 0.05 would be 0.05000000074505806)
    maxd = float("%.7g" % c.max_distance) if c.use_max_distance else None
    if volume is None and maxd is None:
        if os.path.exists(path):
            os.remove(path)
        return None
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(cropmod.crop_json(volume, maxd))
    return path


def gt_override(context):
    """``--gt`` when the ground truth is a scene object: exported to ``compare/gt_scene.glb`` in
    the dataset's frame (glTF, Y up), as steps.export_gt does."""
    c = context.scene.sfmeval_compare
    if c.gt_source != "OBJECT":
        return None
    obj = c.gt_object
    if obj is None or obj.type != "MESH":
        raise ValueError("ground truth 'scene object' needs a mesh object chosen in the panel")
    path = os.path.join(work_dir(context), "gt_scene.glb")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    from .. import compat
    prev = list(context.selected_objects)
    for o in prev:
        o.select_set(False)
    obj.select_set(True)
    op = bpy.ops.export_scene.gltf
    op(**compat.op_kwargs(op, filepath=path, export_format="GLB", use_selection=True,
                          export_apply=True, export_yup=True, export_materials="NONE",
                          export_cameras=False, export_lights=False, export_animations=False))
    obj.select_set(False)
    for o in prev:
        o.select_set(True)
    return path


def paint(obj, distances, status, kept_rgb):
    """`distance` point attribute and the colours of ``sfmeval eval --colored`` (``sfmeval_color``,
    float RGBA = the CLI's bytes / 255, its rows are the kept points in input order; points the
    crop drops are grey)."""
    mesh = obj.data
    n = len(mesh.vertices)
    for name in ("distance", "sfmeval_color"):
        a = mesh.attributes.get(name)
        if a is not None:
            mesh.attributes.remove(a)
    d = mesh.attributes.new("distance", "FLOAT", "POINT")
    d.data.foreach_set("value", np.asarray(distances, dtype=np.float32))
    kept = np.array([s == "kept" for s in status], dtype=bool)
    if int(kept.sum()) != len(kept_rgb):
        raise ev.CliError("%s: the coloured PLY has %d points, the evaluation kept %d"
                          % (obj.name, len(kept_rgb), int(kept.sum())))
    rgb = np.full((n, 3), 0.5, np.float32)
    rgb[kept] = np.asarray(kept_rgb, np.float32) / 255.0
    rgba = np.concatenate([rgb, np.ones((n, 1), np.float32)], axis=1)
    if hasattr(mesh, "color_attributes"):
        col = mesh.color_attributes.new("sfmeval_color", "FLOAT_COLOR", "POINT")
    else:  # pragma: no cover
        col = mesh.attributes.new("sfmeval_color", "FLOAT_COLOR", "POINT")
    col.data.foreach_set("color", rgba.ravel())
    # Solid shading's Color: Attribute draws the active one (the spheres of show_as_points keep
    # it through Realize Instances in Blender 3.4); the render one too, for the exporters
    if hasattr(mesh.color_attributes, "active_color"):
        mesh.color_attributes.active_color = col
    if hasattr(mesh.color_attributes, "render_color_index"):
        mesh.color_attributes.render_color_index = [a.name for a in mesh.color_attributes].index(
            "sfmeval_color")
    mesh.update()
    show_colors(bpy.context)


def write_kept_points(context, item):
    """Writes the object's kept points (Edit Mode deletions applied, reconstruction frame) to
    compare/<name>/points.ply. Returns (dataset folder, work folder, the PLY's path)."""
    ds = require_dataset(context)
    work = work_dir(context, item.name)
    os.makedirs(work, exist_ok=True)
    pts = os.path.join(work, "points.ply")
    plyio.write_points(pts, kept_points(item.object))
    return ds, work, pts


def align_item(context, sfmeval, item, mode):
    """Aligns a reconstruction's kept points: `mode` "auto" (cameras / global, then ICP) or
    "icp" from the object's current matrix (Refine). Sets the object's matrix."""
    obj = item.object
    ds, work, pts = write_kept_points(context, item)
    gt = gt_override(context)
    cams = item.cameras_source or None
    if mode != "icp":
        a = ev.align(sfmeval, ds, pts, work, mode=mode, recon_cameras=cams, gt=gt)
    else:
        # one call: the core's ICP runs to its fixed point (restarts included)
        a = ev.align(sfmeval, ds, pts, work, mode="icp", start=gt_from_recon(obj),
                     recon_cameras=cams, gt=gt)
    set_gt_from_recon(obj, a["gt_from_recon"])
    return a


def measure_item(context, sfmeval, item, crop=None, gt=None):
    """Evaluates the object's kept points with its matrix as the alignment (``sfmeval eval
    --align given``), the crop file and the run's cameras; paints the points; returns the
    report. Files: compare/<name>/{points.ply, gt_from_recon.json, report.json, distances.csv,
    colored.ply}."""
    obj = item.object
    ds, work, pts = write_kept_points(context, item)
    tpath = os.path.join(work, "gt_from_recon.json")
    ev.write_matrix_json(tpath, gt_from_recon(obj))
    rep, dist, status, rgb = ev.evaluate(
        sfmeval, ds, pts, tpath, os.path.join(work, "report.json"),
        recon_cameras=item.cameras_source or None, crop=crop,
        csv_out=os.path.join(work, "distances.csv"), gt=gt,
        colored=os.path.join(work, "colored.ply"))
    if len(dist) != len(obj.data.vertices):
        raise ev.CliError("%s: the CLI measured %d points of %d (camera-centre points removed?)"
                          % (pts, len(dist), len(obj.data.vertices)))
    paint(obj, dist, status, rgb)
    return rep


def import_source(context, sfmeval, name, source, run_dir=None):
    """Imports a reconstruction: a run folder (read by ``sfmeval export RUN_FOLDER`` with the
    run-folder layout of sfmeval-table: its model/, else its sparse.ply, exactly what the
    runner's report evaluates) or any file or folder the CLI reads, through ``sfmeval export``
    (its points as float64 and its cameras, in its own frame, into compare/NAME/source/).
    Aligns it automatically; returns (the points object, the cameras file evaluations use or
    None)."""
    ds = require_dataset(context)
    work = work_dir(context, name)
    os.makedirs(work, exist_ok=True)
    recon = run_dir or source
    if not os.path.exists(recon):
        raise ValueError("%s does not exist" % recon)
    points_ply, cameras_json = ev.export(sfmeval, recon, os.path.join(work, "source"))
    gt = gt_override(context)
    a = ev.align(sfmeval, ds, points_ply, work, recon_cameras=cameras_json, gt=gt)
    obj = new_points_object(context, name, plyio.read_vertices(points_ply), cameras_json)
    obj[SOURCE] = points_ply
    set_gt_from_recon(obj, a["gt_from_recon"])
    obj["sfmeval_source"] = recon
    return obj, cameras_json
