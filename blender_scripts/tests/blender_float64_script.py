"""Driven by test_blender_compare.py inside Blender (PyPI bpy or Debian's blender), on data/demo
(no rendering): a PLY (sparse.ply) and a COLMAP model (sparse/) imported as files, vertices of
both deleted in Edit Mode, Automatic and Refine on the selected one, Evaluate; then a real report
with its messages reworded, shown by the panel; then a vertex added in Edit Mode, which Evaluate
must report. What the test needs to redo it with the CLI is
dumped to JSON.

argv (after --): ZIP DATASET OUT_JSON SFMEVAL"""

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
zip_path, ds, out_json, sfmeval_bin = argv
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="sfmeval_blender")
bpy.context.preferences.addons["sfmeval_blender"].preferences.sfmeval_path = sfmeval_bin
from sfmeval_blender.compare import panel as cpanel  # noqa: E402
scene = bpy.context.scene
c = scene.sfmeval_compare
res = {"blender": bpy.app.version_string, "category": bpy.types.SFMEVAL_PT_compare.bl_category}
res["empty_labels"] = panel_labels(bpy.types.SFMEVAL_PT_compare, scene)
c.dataset_dir = ds


def commands():
    t = bpy.data.texts.get("sfmeval commands")
    return [ln[2:] for ln in t.as_string().splitlines() if ln.startswith("$ ")] if t else []


c.message = "a stale message"
for path in (os.path.join(ds, "sparse.ply"), os.path.join(ds, "sparse")):
    c.import_path = path
    assert bpy.ops.sfmeval.compare_import_file() == {"FINISHED"}, c.message
    res.setdefault("listed_after_import", []).append([r.name for r in c.recons])
res["message_after_import"] = c.message
names = [r.name for r in c.recons]
assert all(r.object for r in c.recons), [(r.name, r.message) for r in c.recons]
gt_coll = bpy.data.collections.get("sfmeval ground truth")
res["gt_collection"] = [o.type for o in gt_coll.objects] if gt_coll else None
res["import_commands"] = commands()

# Edit Mode deletions in both (the COLMAP one stays in Edit Mode: the evaluation must see it)
deleted = {}
for name, step in zip(names, (5, 3)):
    obj = c.recons[name].object
    for o in bpy.context.selected_objects:
        o.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    bm = bmesh.from_edit_mesh(obj.data)
    bm.verts.ensure_lookup_table()
    doomed = list(range(1, len(bm.verts), step))
    bmesh.ops.delete(bm, geom=[bm.verts[i] for i in doomed], context="VERTS")
    bmesh.update_edit_mesh(obj.data)
    deleted[name] = doomed
    if name == names[0]:
        bpy.ops.object.mode_set(mode="OBJECT")
res["deleted"] = deleted

# Automatic and Refine act on the selected row only
ply_name, colmap_name = names
before_ply = list(c.recons[ply_name].object["sfmeval_gt_from_recon"])
c.active_recon = names.index(colmap_name)
n0 = len(commands())
assert bpy.ops.sfmeval.compare_align(mode="auto") == {"FINISHED"}, c.message
res["auto_commands"] = commands()[n0:]
obj = c.recons[colmap_name].object
auto = np.array(list(obj["sfmeval_gt_from_recon"])).reshape(4, 4)
res["auto"] = auto.tolist()
a = math.radians(2.0)
P = np.eye(4)
P[:3, :3] = 1.01 * np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0],
                             [0, 0, 1]])
obj.matrix_basis = Matrix((P @ auto).tolist())
n0 = len(commands())
assert bpy.ops.sfmeval.compare_align(mode="icp") == {"FINISHED"}, c.message
res["refine_commands"] = commands()[n0:]
res["refined"] = list(obj["sfmeval_gt_from_recon"])
res["ply_untouched"] = list(c.recons[ply_name].object["sfmeval_gt_from_recon"]) == before_ply
work = os.path.join(ds, "compare", colmap_name)
with open(os.path.join(work, "icp_start.json")) as f:
    res["icp_start"] = json.load(f)["gt_from_recon"]
with open(os.path.join(work, "alignment.json")) as f:
    res["refine_alignment"] = json.load(f)

# Evaluate (no crop)
c.message = "a stale message"
assert bpy.ops.sfmeval.compare_evaluate() == {"FINISHED"}, c.message
res["message_after_eval"] = c.message
res["eval_commands"] = commands()
items = {}
for r in c.recons:
    assert r.status == "ok", (r.name, r.message)
    m = r.object.data
    idx = np.empty(len(m.vertices), np.int32)
    m.attributes["sfmeval_index"].data.foreach_get("value", idx)
    items[r.name] = {"report": r.report, "cameras_source": r.cameras_source,
                     "source": r.object["sfmeval_points"], "index": idx.tolist(),
                     "vertices": len(m.vertices), "summary": json.loads(r.summary),
                     "stored": list(r.object["sfmeval_gt_from_recon"])}
res["items"] = items
res["labels"] = panel_labels(bpy.types.SFMEVAL_PT_compare, scene, icons=True)
res["table_text"] = bpy.data.texts["sfmeval Table I"].as_string()

# A real report, its messages reworded: the panel shows the same notes (by level), new words
item = c.recons[ply_name]
with open(item.report) as f:
    rep = json.load(f)
for n in rep["notes"]:
    n["message"] = "REWORDED %s %s" % (n["level"], n["code"])
reworded = os.path.join(ds, "compare", "reworded.json")
with open(reworded, "w") as f:
    json.dump(rep, f)
cpanel.load_report(item, reworded)
res["reworded_labels"] = panel_labels(bpy.types.SFMEVAL_PT_compare, scene, icons=True)
res["notes"] = rep["notes"]

# Table I as Evaluate wrote it (the failed evaluation below rewrites it)
res["table_files"] = {n: open(os.path.join(ds, "compare", n), encoding="utf-8").read()
                      for n in ("table1.md", "table1.csv")}

# A vertex added in Edit Mode where vertex 0 was deleted: its index attribute is 0 (the
# default), a row no other vertex has now, but it has no source point; Evaluate must say so.
obj = c.recons[ply_name].object
for o in bpy.context.selected_objects:
    o.select_set(False)
bpy.context.view_layer.objects.active = obj
obj.select_set(True)
bpy.ops.object.mode_set(mode="EDIT")
bm = bmesh.from_edit_mesh(obj.data)
bm.verts.ensure_lookup_table()
bmesh.ops.delete(bm, geom=[bm.verts[0]], context="VERTS")
bm.verts.new((0.125, 0.25, 0.5))
bmesh.update_edit_mesh(obj.data)
bpy.ops.object.mode_set(mode="OBJECT")
c.active_recon = names.index(ply_name)
report_before = open(c.recons[ply_name].report, "rb").read()
c.message = ""
bpy.ops.sfmeval.compare_evaluate()
item = c.recons[ply_name]
res["added_vertex"] = {"status": item.status, "message": item.message, "panel": c.message,
                       "report_unchanged": open(item.report, "rb").read() == report_before
                       if item.report and os.path.isfile(item.report) else None}
with open(out_json, "w") as f:
    json.dump(res, f)
print("FLOAT64 DONE")
