"""Driven by test_blender_compare.py inside Debian's Blender (headless): data/demo's COLMAP
model imported as a file, a crop *sphere* (moved, uniformly scaled) and a max distance, then
Evaluate; what the test needs to redo it with the CLI is dumped to JSON.

argv (after --): ZIP DATASET OUT_JSON SFMEVAL"""

import json
import os
import sys

import bpy

zip_path, ds, out_json, sfmeval_bin = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="sfmeval_blender")
bpy.context.preferences.addons["sfmeval_blender"].preferences.sfmeval_path = sfmeval_bin
c = bpy.context.scene.sfmeval_compare
c.dataset_dir = ds
c.import_path = os.path.join(ds, "sparse")
assert bpy.ops.sfmeval.compare_import_file() == {"FINISHED"}, c.message
item = c.recons[0]
assert item.object is not None, item.message
assert bpy.ops.sfmeval.compare_add_crop(kind="SPHERE") == {"FINISHED"}
crop = c.crop_object
crop.location = (0.03, -0.02, 0.1)
crop.scale = (0.35, 0.35, 0.35)
c.use_max_distance, c.max_distance = True, 0.05
bpy.context.view_layer.update()
assert bpy.ops.sfmeval.compare_evaluate() == {"FINISHED"}, c.message
assert item.status == "ok", item.message
with open(out_json, "w") as f:
    json.dump({"crop_matrix": [list(r) for r in crop.matrix_world], "name": item.name,
               "stored": list(item.object["sfmeval_gt_from_recon"]), "report": item.report,
               "cameras_source": item.cameras_source, "summary": json.loads(item.summary)}, f)
print("SPHERE DONE")
