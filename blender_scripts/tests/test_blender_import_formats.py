"""Model files of every supported kind, written by other programs (trimesh, bpy), go through
the import step: joined into one object, normalised, exported to ground_truth.glb (no
rendering: --no-render)."""

import os
import subprocess
import sys

import numpy as np
import pytest

from blender_testlib import load_json, requires_bpy, run_generate
from blender_testlib import glb_vertices

pytestmark = requires_bpy


def _box_mesh():
    import trimesh
    m = trimesh.creation.box(extents=(2.0, 1.0, 0.5))
    m.apply_translation((3.0, -1.0, 2.0))
    return m


def _normalised(v):
    lo, hi = v.min(0), v.max(0)
    return (v - (lo + hi) / 2) / (hi - lo).max()


def _generate(tmp_path, model):
    cfg = tmp_path / "d.toml"
    cfg.write_text('preset = "small"\n[object]\nsource = "%s"\n' % os.path.basename(model))
    out = tmp_path / "out"
    proc = run_generate(["--config", str(cfg), "--no-render", "--out", str(out)], timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return out


# Y-up formats (OBJ, glTF) come back unchanged; Z-up formats (PLY, STL) are read as Blender
# coordinates, so their GT in the glTF frame is (x, z, −y) of the file.
@pytest.mark.parametrize("ext,y_up", [("obj", True), ("glb", True), ("ply", False), ("stl", False)])
def test_trimesh_written_models(tmp_path, ext, y_up):
    mesh = _box_mesh()
    path = tmp_path / ("model." + ext)
    mesh.export(str(path))
    out = _generate(tmp_path, path)
    gt, _ = glb_vertices(str(out / "ground_truth.glb"))
    src = np.asarray(mesh.vertices)
    if not y_up:
        src = np.stack([src[:, 0], src[:, 2], -src[:, 1]], axis=1)
    want = _normalised(src)
    from scipy.spatial import cKDTree
    assert max(cKDTree(want).query(gt)[0].max(), cKDTree(gt).query(want)[0].max()) < 1e-5
    meta = load_json(out / "dataset.json")
    assert meta["source"]["kind"] == "file" and meta["source"]["format"] == ext
    assert len(meta["source"]["sha256"]) == 64


def test_multi_mesh_gltf_is_joined(tmp_path):
    import trimesh
    a = trimesh.creation.box(extents=(1, 1, 1))
    b = trimesh.creation.icosphere(subdivisions=1, radius=0.5)
    scene = trimesh.Scene()
    scene.add_geometry(a, node_name="a", transform=trimesh.transformations.translation_matrix((-1, 0, 0)))
    rot = trimesh.transformations.rotation_matrix(0.7, (0, 0, 1))
    rot[:3, 3] = (1.5, 0.2, 0)
    scene.add_geometry(b, node_name="b", transform=rot)
    path = tmp_path / "two.glb"
    scene.export(str(path))
    out = _generate(tmp_path, path)
    gt, gscene = glb_vertices(str(out / "ground_truth.glb"))
    assert len(gscene.graph.nodes_geometry) == 1                   # one object
    src, _ = glb_vertices(str(path))
    want = _normalised(src)
    from scipy.spatial import cKDTree
    assert max(cKDTree(want).query(gt)[0].max(), cKDTree(gt).query(want)[0].max()) < 1e-5


def test_blend_file_with_modifier(tmp_path):
    """A .blend written by bpy: its mesh objects are appended, modifiers applied."""
    path = tmp_path / "m.blend"
    script = (
        "import bpy, sys\n"
        "bpy.ops.wm.read_factory_settings(use_empty=True)\n"
        "me = bpy.data.meshes.new('m')\n"
        "me.from_pydata([(0,0,0),(1,0,0),(1,2,0),(0,2,0),(0,0,1),(1,0,1),(1,2,1),(0,2,1)], [],"
        " [(0,1,2,3),(4,7,6,5),(0,4,5,1),(1,5,6,2),(2,6,7,3),(3,7,4,0)])\n"
        "o = bpy.data.objects.new('m', me); bpy.context.scene.collection.objects.link(o)\n"
        "o.modifiers.new('sub', 'SUBSURF').levels = 2\n"
        "bpy.ops.wm.save_as_mainfile(filepath=sys.argv[1])\n")
    proc = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = _generate(tmp_path, path)
    meta = load_json(out / "dataset.json")
    assert meta["object"]["vertices"] == 98                  # 8-vertex cube subdivided twice
    gt, _ = glb_vertices(str(out / "ground_truth.glb"))
    assert (gt.max(0) - gt.min(0)).max() == pytest.approx(1.0, abs=1e-6)


def test_fbx_written_by_blender(tmp_path):
    path = tmp_path / "m.fbx"
    script = (
        "import bpy, sys\n"
        "bpy.ops.wm.read_factory_settings(use_empty=True)\n"
        "me = bpy.data.meshes.new('m')\n"
        "me.from_pydata([(0,0,0),(2,0,0),(2,1,0),(0,1,0),(0,0,3),(2,0,3),(2,1,3),(0,1,3)], [],"
        " [(0,1,2,3),(4,7,6,5),(0,4,5,1),(1,5,6,2),(2,6,7,3),(3,7,4,0)])\n"
        "o = bpy.data.objects.new('m', me); bpy.context.scene.collection.objects.link(o)\n"
        "bpy.ops.export_scene.fbx(filepath=sys.argv[1])\n")
    proc = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = _generate(tmp_path, path)
    meta = load_json(out / "dataset.json")
    assert meta["source"]["format"] == "fbx" and meta["object"]["vertices"] == 8
    gt, _ = glb_vertices(str(out / "ground_truth.glb"))
    ext = np.sort(gt.max(0) - gt.min(0))
    assert ext == pytest.approx([1 / 3, 2 / 3, 1.0], abs=1e-5)     # 2×1×3 box, normalised


def _gltf_with_external_buffers(folder):
    """A non-binary .gltf written by trimesh: JSON plus separate .bin buffer files."""
    import json
    import trimesh
    mesh = _box_mesh()
    files = trimesh.Scene(mesh).export(file_type="gltf")
    for name, data in files.items():
        (folder / name).write_bytes(data)
    uris = [b["uri"] for b in json.loads(files["model.gltf"])["buffers"]]
    assert uris and all(u.endswith(".bin") for u in uris)          # external, not data URIs
    return mesh, folder / "model.gltf", uris


def test_gltf_with_external_bin(tmp_path):
    """A .gltf whose buffers are separate .bin files next to it imports like the GLB."""
    mesh, path, _ = _gltf_with_external_buffers(tmp_path)
    out = _generate(tmp_path, path)
    gt, _ = glb_vertices(str(out / "ground_truth.glb"))
    want = _normalised(np.asarray(mesh.vertices))                 # glTF is Y-up: unchanged
    from scipy.spatial import cKDTree
    assert max(cKDTree(want).query(gt)[0].max(), cKDTree(gt).query(want)[0].max()) < 1e-5
    assert load_json(out / "dataset.json")["source"]["format"] == "gltf"


def test_gltf_missing_bin_is_a_clear_error(tmp_path):
    """The same .gltf with its .bin files gone: exit 1 at the import step, the message names
    the model and the missing buffer, nothing is written to --out."""
    _, path, uris = _gltf_with_external_buffers(tmp_path)
    for u in uris:
        (tmp_path / u).unlink()
    cfg = tmp_path / "d.toml"
    cfg.write_text('preset = "small"\n[object]\nsource = "model.gltf"\n')
    out = tmp_path / "out"
    proc = run_generate(["--config", str(cfg), "--out", str(out)], timeout=300)
    assert proc.returncode == 1, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "cannot import" in proc.stderr and "model.gltf" in proc.stderr
    assert uris[0] in proc.stderr and "Traceback" not in proc.stderr
    assert not out.exists()
