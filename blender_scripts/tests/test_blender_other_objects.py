"""Objects the add-on did not make, from Blender's default startup scene (Cube, Camera, Light),
in PyPI bpy 5.0 and Debian blender 3.4: the add-on zip is installed and its step operators run
on a tiny config (2 views at 160×90, 4 spp, PNG), several times in one Blender process:

- default: the Cube and the Light are hidden while rendering, so images, masks, depth and
  ground_truth.glb equal those rendered after deleting them (the reference); their hide_render
  is restored, even when the render fails; a keyframed hide_render (which would override the
  hiding) is refused; dataset.json lists them; the panel and the operator say what was hidden;
- keep as context, the Cube flattened into a slab under the object: the slab is in the images
  (they differ from the reference), masks and depth are still the object's alone;
- keep as context, the default 2 m Cube around the object: it hides the object in every view,
  so the masks are empty (the object is not seen) and the operator warns;
- keep the scene's lights: the default Light brightens the object, the Cube stays hidden.
"""

import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np
import pytest
from PIL import Image

from blender_testlib import BLENDER_SCRIPTS, glb_vertices, have_bpy, load_json

SCRIPT = r'''
import bpy, sys, os, json
argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
zip_path, base = argv[0], argv[1]
scene = bpy.context.scene
vl = bpy.context.view_layer
start = sorted((o.name, o.type) for o in scene.objects)
assert start == [("Camera", "CAMERA"), ("Cube", "MESH"), ("Light", "LIGHT")], start
selection = sorted(o.name for o in vl.objects if o.select_get()), vl.objects.active.name
bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
bpy.ops.preferences.addon_enable(module="sfmeval_blender")
from sfmeval_blender import addon, steps
p = scene.sfmeval
p.preset = "small"
bpy.ops.sfmeval.load_preset()
p.samples, p.denoise, p.format = 4, "off", "PNG"
p.res_x, p.res_y = 160, 90
p.rings[0].count, p.rings[1].count = 2, 0
for op in (bpy.ops.sfmeval.import_object, bpy.ops.sfmeval.setup_scene,
           bpy.ops.sfmeval.setup_camera, bpy.ops.sfmeval.animate_orbits):
    assert op() == {"FINISHED"}, op
cube, light = bpy.data.objects["Cube"], bpy.data.objects["Light"]
out = {"panel": {}, "state": {}}

def state():
    return {"cube_hide_render": cube.hide_render, "light_hide_render": light.hide_render,
            "cube_in_scene": cube.name in scene.objects, "light_in_scene": light.name in scene.objects,
            "selection": [sorted(o.name for o in vl.objects if o.select_get()), vl.objects.active.name],
            "holdout": cube.is_holdout}

ICONS = {i.identifier for i in bpy.types.UILayout.bl_rna.functions["label"].parameters["icon"].enum_items}

class Layout:
    """Records what the panel draws (Blender cannot draw without a window): labels, and checks
    that every property and icon it names exists."""
    def __init__(self, labels):
        self.labels = labels
    def _sub(self, *a, **k):
        return Layout(self.labels)
    row = box = column = _sub
    def label(self, text="", icon="NONE"):
        assert icon in ICONS, icon
        self.labels.append(text)
    def prop(self, data, name, **k):
        assert name in data.bl_rna.properties, name
    def operator(self, idname, **k):
        assert hasattr(getattr(bpy.ops, idname.split(".")[0]), idname.split(".")[1]), idname
        assert k.get("icon", "NONE") in ICONS, k
        return type("Props", (), {})()
    def separator(self):
        pass

def panel_labels():
    labels = []
    bpy.types.SFMEVAL_PT_panel.draw(type("Panel", (), {"layout": Layout(labels)})(), bpy.context)
    return labels

def dataset(name):
    p.out_dir = os.path.join(base, name)
    out["panel"][name] = addon.other_objects_lines(scene)
    labels = panel_labels()
    assert all(line in labels for _, line in out["panel"][name]), (labels, out["panel"][name])
    print("STEP", name, flush=True)
    assert bpy.ops.sfmeval.render() == {"FINISHED"}
    assert bpy.ops.sfmeval.export_gt() == {"FINISHED"}
    if name != "reference":
        out["state"][name] = state()

out["selection_before"] = list(selection)
dataset("default")

# a render that fails on its second view (its file name is taken by a folder)
os.makedirs(os.path.join(base, "fail", "images", "0001.png"))
p.out_dir = os.path.join(base, "fail")
try:
    out["fail_result"] = sorted(bpy.ops.sfmeval.render())
except RuntimeError as exc:
    out["fail_result"] = str(exc)
out["state"]["fail"] = state()

# keyframed render visibility would override the hiding: refused before the first image
cube.keyframe_insert("hide_render", frame=1)
p.out_dir = os.path.join(base, "animated")
try:
    out["animated_result"] = sorted(bpy.ops.sfmeval.render())
except RuntimeError as exc:
    out["animated_result"] = str(exc)
cube.animation_data_clear()
out["state"]["animated"] = state()

p.keep_other_objects = True
dataset("context_around")                   # the 2 m default Cube encloses the 1 m object
lo, hi = steps.bbox(steps.evaluated_world_vertices(steps.get_object())[0])
cube.scale = (0.8, 0.8, 0.05)               # a 1.6 x 1.6 x 0.1 m slab just under the object
cube.location = (0.0, 0.0, lo[2] - 0.06)
dataset("context_slab")
p.keep_other_objects, p.keep_other_lights = False, True
dataset("lights")
p.keep_other_lights = False
for name in ("Cube", "Light", "Camera"):    # the reference: the scene without them
    bpy.data.objects.remove(bpy.data.objects[name], do_unlink=True)
dataset("reference")
print("RESULT " + json.dumps(out), flush=True)
'''


def _blender_cmd(blender, script, zip_path, base):
    if blender == "bpy":
        return [sys.executable, str(script), zip_path, str(base)]
    return [shutil.which("blender"), "-b", "--factory-startup", "-noaudio",
            "--python-exit-code", "1", "-P", str(script), "--", zip_path, str(base)]


def _images(folder):
    names = sorted(os.listdir(folder / "images"))
    assert names == ["0000.png", "0001.png"], names
    rgb = np.stack([np.asarray(Image.open(folder / "images" / n).convert("RGB"), float) for n in names])
    masks = np.stack([np.asarray(Image.open(folder / "masks" / (n[:-4] + ".png"))) > 127 for n in names])
    depth = np.stack([np.load(folder / "depth" / (n[:-4] + ".npy")) for n in names])
    return rgb, masks, depth


def _reports(stdout, name):
    """The operator reports printed between this step's marker and the next."""
    part = stdout.split("STEP " + name + "\n", 1)[1]
    return part.split("STEP ", 1)[0]


@pytest.mark.parametrize("blender", ["bpy", "debian"])
def test_addon_hides_objects_it_did_not_make(tmp_path, blender):
    if blender == "bpy" and not have_bpy():
        pytest.skip("PyPI bpy is not installed")
    if blender == "debian" and shutil.which("blender") is None:
        pytest.skip("Debian blender not installed (apt-get install blender python3-numpy)")
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, os.path.join(BLENDER_SCRIPTS, "build_addon.py"),
                           "--out", str(tmp_path / "dist")], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    base = tmp_path / "out"
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(tmp_path / "user_scripts"),
               BLENDER_USER_CONFIG=str(tmp_path / "user_config"))
    proc = subprocess.run(_blender_cmd(blender, script, proc.stdout.strip(), base),
                          capture_output=True, text=True, env=env, timeout=600)
    log = proc.stdout + proc.stderr
    assert proc.returncode == 0 and "RESULT " in proc.stdout, log[-4000:]
    res = json.loads(proc.stdout.split("RESULT ", 1)[1].splitlines()[0])
    sys.stderr.write("\n[other objects, %s] %.1f s\n" % (blender, time.perf_counter() - t0))

    # The user's scene is left as it was: hide_render, membership, selection, holdout.
    for name in ("default", "fail", "animated", "context_around", "context_slab", "lights"):
        st = res["state"][name]
        assert st["cube_hide_render"] is False and st["light_hide_render"] is False, (name, st)
        assert st["cube_in_scene"] and st["light_in_scene"] and st["holdout"] is False, (name, st)
        assert st["selection"] == res["selection_before"], (name, st)
    # The failed render is reported as an error (raised to a calling script), not a traceback.
    failed = str(base / "fail" / "images" / "0001.png")
    assert res["fail_result"].startswith("Error: rendering %s failed: " % failed), res["fail_result"]
    assert os.path.isfile(base / "fail" / "images" / "0000.png")  # the first view was rendered
    assert res["animated_result"].startswith("Error: the render visibility of 'Cube' is animated")
    assert os.listdir(base / "animated" / "images") == []

    rgb_ref, mask_ref, depth_ref = _images(base / "reference")
    v_ref, _ = glb_vertices(str(base / "reference" / "ground_truth.glb"))
    cover = mask_ref.mean(axis=(1, 2))
    assert np.all((cover > 0.03) & (cover < 0.6)), cover        # the object, not the frame

    # Default: hidden, so the dataset is the one of the scene without them.
    rgb, mask, depth = _images(base / "default")
    assert np.all(mask.mean(axis=(1, 2)) < 0.6), mask.mean(axis=(1, 2))
    assert np.count_nonzero(mask != mask_ref) <= 3
    assert np.abs(rgb - rgb_ref).mean() < 0.5                     # grey levels; inside the cube: ~100
    assert np.abs(depth - depth_ref).max() < 1e-5
    v, _ = glb_vertices(str(base / "default" / "ground_truth.glb"))
    assert v.shape == v_ref.shape and np.abs(v - v_ref).max() < 1e-6
    meta = load_json(base / "default" / "dataset.json")
    assert meta["other_objects"] == {
        "keep_other_objects": False, "keep_other_lights": False,
        "objects": [{"name": "Camera", "type": "CAMERA", "treatment": "not rendered"},
                    {"name": "Cube", "type": "MESH", "treatment": "hidden"},
                    {"name": "Light", "type": "LIGHT", "treatment": "hidden"}]}
    assert meta["render"]["views_without_object"] == []
    assert res["panel"]["default"] == [["hidden", "Hidden while rendering: Cube, Light"]]
    assert "Warning: rendered 2 images" in _reports(log, "default")
    assert ("Hidden while rendering: Cube, Light (not made by sfmeval; 'Keep other objects as "
            "context' or 'Keep other lights' renders them)") in _reports(log, "default")
    assert load_json(base / "reference" / "dataset.json")["other_objects"]["objects"] == []
    assert res["panel"]["reference"] == []

    # Context slab under the object: in the images, not in masks or depth.
    rgb, mask, depth = _images(base / "context_slab")
    assert np.abs(rgb - rgb_ref).mean() > 5, np.abs(rgb - rgb_ref).mean()
    assert np.count_nonzero(mask != mask_ref) <= 3
    assert np.abs(depth - depth_ref).max() < 1e-5
    v, _ = glb_vertices(str(base / "context_slab" / "ground_truth.glb"))
    assert v.shape == v_ref.shape and np.abs(v - v_ref).max() < 1e-6
    objs = load_json(base / "context_slab" / "dataset.json")["other_objects"]
    assert objs["keep_other_objects"] is True
    assert {o["name"]: o["treatment"] for o in objs["objects"]} == \
        {"Camera": "not rendered", "Cube": "context", "Light": "hidden"}
    assert res["panel"]["context_slab"] == [["hidden", "Hidden while rendering: Light"],
                                            ["context", "Kept as context: Cube"]]
    rep = _reports(log, "context_slab")
    assert "Kept as context: Cube (in the images; not in masks, depth or ground truth)" in rep
    assert "Hidden while rendering: Light (not made by sfmeval; 'Keep other lights' renders" in rep

    # Context cube around the object: it hides the object, and nothing says "object" there.
    rgb, mask, depth = _images(base / "context_around")
    assert not mask.any() and not depth.any()
    assert np.abs(rgb - rgb_ref).mean() > 20
    meta = load_json(base / "context_around" / "dataset.json")
    assert meta["render"]["views_without_object"] == ["0000.png", "0001.png"]
    assert "seen in no pixel of 2 of 2 views" in _reports(log, "context_around")

    # The scene's Light kept: the object is brighter, its silhouette the same.
    rgb, mask, depth = _images(base / "lights")
    gain = rgb[mask_ref].mean() / rgb_ref[mask_ref].mean()
    assert gain > 1.02, gain                                     # measured 1.04 (bpy 5.0)
    assert np.count_nonzero(mask != mask_ref) <= 3
    objs = load_json(base / "lights" / "dataset.json")["other_objects"]
    assert {o["name"]: o["treatment"] for o in objs["objects"]} == \
        {"Camera": "not rendered", "Cube": "hidden", "Light": "context"}
