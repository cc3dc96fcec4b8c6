"""Driven by test_blender_compare.py inside Blender (PyPI bpy or Debian's blender): the
"Compare pipelines" workflow as a user presses it, with the results dumped to JSON.

argv: ZIP DATASET MODE(run|premade) OUT_JSON SFMEVAL RUNNER"""

import json
import math
import os
import sys

import bpy  # noqa: I001 (bpy first: it makes bmesh and mathutils importable)
import bmesh
import numpy as np
from mathutils import Matrix

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from panel_probe import panel_labels  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
zip_path, ds, mode, out_json, sfmeval_bin, runner_bin = argv
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="sfmeval_blender")
assert hasattr(bpy.types, "SFMEVAL_PT_compare"), "compare panel not registered"
prefs = bpy.context.preferences.addons["sfmeval_blender"].preferences
scene = bpy.context.scene
c = scene.sfmeval_compare
c.dataset_dir = ds
res = {"blender": bpy.app.version_string}


def call(op, **kw):
    """An operator as a button press: an error report is a result, not an exception."""
    try:
        return sorted(op(**kw))
    except RuntimeError as exc:
        return str(exc)


def panel_draws():
    """The Compare panel's labels (its draw() runs without error)."""
    return panel_labels(bpy.types.SFMEVAL_PT_compare, scene)


# A missing binary: a message naming it and what to build; nothing else breaks.
prefs.sfmeval_path = "/nonexistent/sfmeval"
prefs.runner_path = "/nonexistent/sfmeval-runner"
res["missing_runner_result"] = call(bpy.ops.sfmeval.compare_pipelines)
res["missing_runner_msg"] = c.message
res["missing_sfmeval_result"] = call(bpy.ops.sfmeval.compare_evaluate)
res["missing_sfmeval_msg"] = c.message
res["missing_labels"] = panel_draws()
prefs.sfmeval_path = sfmeval_bin
prefs.runner_path = runner_bin

# 7. Run two pipelines through the operator (background mode: synchronous).
if mode == "run":
    assert call(bpy.ops.sfmeval.compare_pipelines) == ["FINISHED"], c.message
    res["pipelines"] = {p.name: p.installed for p in c.pipelines}
    for name in ("pycolmap", "pycolmap-global"):
        c.pipelines[name].selected = True
    c.intrinsics = "known"
    c.timeout = 600
    res["run_result"] = call(bpy.ops.sfmeval.compare_run)
    res["states"] = {p.name: [p.state, p.elapsed, p.message] for p in c.pipelines if p.selected}
    res["log"] = bpy.data.texts["sfmeval runs"].as_string()

# 8. Import every run (the test added a failed run and a corrupt one beside the real ones).
res["import_result"] = call(bpy.ops.sfmeval.compare_import_runs)
res["rows"] = {r.name: [r.status, r.message] for r in c.recons}
ok = [r.name for r in c.recons if r.object]
res["ok"] = ok
res["imported_vertices"] = {n: len(c.recons[n].object.data.vertices) for n in ok}
res["display"] = {n: [c.recons[n].object.get("sfmeval_display"),
                      [m.type for m in c.recons[n].object.modifiers]] for n in ok}
res["cameras"] = {n: len([o for o in c.recons[n].object.children if o.type == "CAMERA"])
                  for n in ok}
res["first_eval"] = call(bpy.ops.sfmeval.compare_evaluate)
res["first_reports"] = {n: json.load(open(c.recons[n].report)) for n in ok}

# 8b. Any file the CLI reads: the first run's COLMAP text model, imported as a file.
c.import_path = os.path.join(ds, "runs", os.path.basename(ds), ok[0], "model")
res["file_import"] = call(bpy.ops.sfmeval.compare_import_file)
fitem = c.recons[ok[0] + "-model"]
res["file_row"] = [fitem.status, fitem.message]
if fitem.object:
    res["file_co"] = [v.co[:] for v in fitem.object.data.vertices]
    res["file_stored"] = list(fitem.object["sfmeval_gt_from_recon"])

# 11b. The ground truth as a scene object: the dataset's GLB imported, then exported by the
# add-on (no crop this time).
before_objs = set(bpy.data.objects)
if not hasattr(np, "bool"):  # Debian's Blender 3.4 glTF importer uses np.bool (numpy < 1.24)
    np.bool = bool
bpy.ops.import_scene.gltf(filepath=os.path.join(ds, "ground_truth.glb"))
gt_obj = [o for o in bpy.data.objects if o not in before_objs and o.type == "MESH"][0]
c.gt_source, c.gt_object = "OBJECT", gt_obj
c.crop_object, c.use_max_distance = None, False
res["gt_object_eval"] = call(bpy.ops.sfmeval.compare_evaluate)
res["gt_object_reports"] = {n: json.load(open(c.recons[n].report)) for n in ok}
c.gt_source = "DATASET"
res["gt_dataset_eval"] = call(bpy.ops.sfmeval.compare_evaluate)
res["gt_dataset_reports"] = {n: json.load(open(c.recons[n].report)) for n in ok}

# 9a. Delete every 7th point of the first reconstruction in Edit Mode (bmesh, as a user would).
first = ok[0]
obj = c.recons[first].object
bpy.context.view_layer.objects.active = obj
obj.select_set(True)
before = np.array([v.co[:] for v in obj.data.vertices])
bpy.ops.object.mode_set(mode="EDIT")
bm = bmesh.from_edit_mesh(obj.data)
bm.verts.ensure_lookup_table()
doomed = list(range(0, len(bm.verts), 7))
bmesh.ops.delete(bm, geom=[bm.verts[i] for i in doomed], context="VERTS")
bmesh.update_edit_mesh(obj.data)
res["deleted"] = len(doomed)
res["kept_expected"] = np.delete(before, doomed, axis=0).tolist()
# (stays in Edit Mode: the evaluation must see the edit)

# 9b. A crop box, moved, rotated and scaled; and a max distance.
assert call(bpy.ops.sfmeval.compare_add_crop, kind="CUBE") == ["FINISHED"]
crop = c.crop_object
crop.location = (0.02, -0.01, 0.05)
crop.rotation_euler = (0.0, 0.0, math.radians(20))
crop.scale = (0.45, 0.4, 0.42)
c.use_max_distance = True
c.max_distance = 0.05
bpy.context.view_layer.update()
res["crop_matrix"] = [list(r) for r in crop.matrix_world]

# 10. Automatic alignment of the kept points, then Refine (ICP) from a start moved by 3° and 2 %.
c.active_recon = c.recons.find(first)  # the row Automatic and Refine act on
res["align_auto"] = call(bpy.ops.sfmeval.compare_align, mode="auto")
auto = np.array(list(obj["sfmeval_gt_from_recon"])).reshape(4, 4)
res["auto"] = auto.tolist()
axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
a = math.radians(3)
P = np.eye(4)
P[:3, :3] = 1.02 * (np.eye(3) + math.sin(a) * K + (1 - math.cos(a)) * K @ K)
obj.matrix_basis = Matrix((P @ auto).tolist())
res["start"] = (P @ auto).tolist()
from sfmeval_blender.compare.blender import gt_from_recon  # noqa: E402
res["start_seen"] = gt_from_recon(obj).tolist()  # what Refine starts from: the moved object
res["align_refine"] = call(bpy.ops.sfmeval.compare_align, mode="icp")
res["refined"] = np.array(list(obj["sfmeval_gt_from_recon"])).reshape(4, 4).tolist()

# 11. Evaluate and compare.
res["eval_result"] = call(bpy.ops.sfmeval.compare_evaluate)
res["rows_after"] = {r.name: [r.status, r.message] for r in c.recons}
items = {}
for n in ok:
    r = c.recons[n]
    o = r.object
    if o.mode == "EDIT":
        o.update_from_editmode()
    m = o.data
    dist = np.empty(len(m.vertices), np.float32)
    m.attributes["distance"].data.foreach_get("value", dist)
    col = np.empty(len(m.vertices) * 4, np.float32)
    m.color_attributes["sfmeval_color"].data.foreach_get("color", col)
    items[n] = {
        "vertices": len(m.vertices),
        "co": [v.co[:] for v in m.vertices] if n == first else None,
        "matrix_basis": [list(row) for row in o.matrix_basis],
        "matrix_world": [list(row) for row in o.matrix_world],
        "stored": list(o["sfmeval_gt_from_recon"]),
        "distance": dist.tolist(), "color": col.reshape(-1, 4).tolist(),
        "summary": json.loads(r.summary), "report": r.report,
        "cameras_source": r.cameras_source,
    }
res["items"] = items
res["table_text"] = bpy.data.texts["sfmeval Table I"].as_string()
res["labels"] = panel_draws()
with open(out_json, "w") as f:
    json.dump(res, f)
print("COMPARE DONE")
