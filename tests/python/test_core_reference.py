"""sfmeval's numbers against independent implementations on the same files:
trimesh (exact f64 point-to-triangle), Open3D RaycastingScene (f32 ray-casting scene), scipy
cKDTree (nearest neighbours), numpy (statistics), the Tanks and Temples P/R/F formula. The files
are written by those programs (Open3D, trimesh, pymeshlab/MeshLab, Blender via bpy, COLMAP via
pycolmap), in ascii and binary."""
import json
import subprocess

import numpy as np
import open3d as o3d
import pytest
import trimesh
from scipy.spatial import cKDTree


def blob_mesh(subdiv=4):
    """A bumpy, non-symmetric closed mesh."""
    m = trimesh.creation.icosphere(subdivisions=subdiv, radius=1.0)
    v = m.vertices
    bump = 1 + 0.2 * np.sin(3 * v[:, 0] + 1) * np.cos(2 * v[:, 1]) + 0.1 * v[:, 2] ** 3
    m.vertices = v * bump[:, None] * np.array([1.0, 0.8, 0.6])
    return m


def noisy_points(mesh, n, sigma, outliers, seed):
    rng = np.random.default_rng(seed)
    pts, _ = trimesh.sample.sample_surface(mesh, n, seed=seed)
    pts = pts + rng.normal(scale=sigma, size=pts.shape)
    lo, hi = mesh.bounds
    out = rng.uniform(lo - 0.3, hi + 0.3, size=(outliers, 3))
    return np.vstack([pts, out])


def load_mesh(path):
    """The mesh exactly as the file holds it (GLB and binary float PLYs hold float32; ascii PLY
    text is read digit for digit, as Open3D does)."""
    if str(path).endswith(".ply"):
        m = o3d.io.read_triangle_mesh(str(path))
        return trimesh.Trimesh(np.asarray(m.vertices, dtype=np.float64), np.asarray(m.triangles), process=False)
    m = trimesh.load(path, process=False, force="mesh")
    return trimesh.Trimesh(np.asarray(m.vertices, dtype=np.float64), m.faces, process=False)


def load_points(path):
    return np.asarray(o3d.io.read_point_cloud(str(path)).points, dtype=np.float64)


def exact_distance(mesh, p, candidates=60):
    """Point-to-mesh distance in exact rational arithmetic over the triangles nearest to p."""
    from fractions import Fraction as F
    import math

    def sub(u, v):
        return [u[k] - v[k] for k in range(3)]

    def dot(u, v):
        return sum(u[k] * v[k] for k in range(3))

    def seg(q, a, b):
        ab = sub(b, a)
        t = min(max(dot(sub(q, a), ab) / dot(ab, ab), F(0)), F(1))
        r = sub(q, [a[k] + t * ab[k] for k in range(3)])
        return dot(r, r)

    def tri(q, a, b, c):
        ab, ac, aq = sub(b, a), sub(c, a), sub(q, a)
        d00, d01, d11, d20, d21 = dot(ab, ab), dot(ab, ac), dot(ac, ac), dot(aq, ab), dot(aq, ac)
        den = d00 * d11 - d01 * d01
        v = (d11 * d20 - d01 * d21) / den
        w = (d00 * d21 - d01 * d20) / den
        if v >= 0 and w >= 0 and v + w <= 1:
            r = sub(q, [a[k] + v * ab[k] + w * ac[k] for k in range(3)])
            return dot(r, r)
        return min(seg(q, a, b), seg(q, b, c), seg(q, a, c))

    q = [F(float(x)) for x in p]
    near = np.argsort(np.linalg.norm(mesh.triangles_center - p, axis=1))[:candidates]
    best = min(tri(q, *[[F(float(x)) for x in mesh.vertices[j]] for j in mesh.faces[f]]) for f in near)
    return math.sqrt(best)


def write_o3d_cloud(path, pts, ascii):
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
    pc.colors = o3d.utility.Vector3dVector(np.full_like(pts, 0.5))
    assert o3d.io.write_point_cloud(str(path), pc, write_ascii=ascii)


@pytest.mark.parametrize("ascii_gt", [False, True])
def test_point_to_mesh_matches_trimesh_exactly(tmp_path, run_eval, ascii_gt):
    mesh = blob_mesh()
    gt = tmp_path / "gt.ply"
    gt.write_bytes(trimesh.exchange.ply.export_ply(mesh, encoding="ascii" if ascii_gt else "binary"))
    pts = noisy_points(mesh, 3000, 0.01, 100, seed=3)
    recon = tmp_path / "recon.ply"
    write_o3d_cloud(recon, pts, ascii=False)
    rep, data = run_eval(gt, recon, "--samples", "20000")
    mesh = load_mesh(gt)
    ours = data["distance"]
    assert len(ours) == len(pts)
    # Our x,y,z must be the points Open3D wrote (no transform).
    np.testing.assert_allclose(np.c_[data["x"], data["y"], data["z"]], pts, rtol=0, atol=1e-12)
    _, ref, _ = trimesh.proximity.closest_point(mesh, pts)
    rel = np.abs(ours - ref) / np.maximum(ref, 1e-9)
    # trimesh is itself off by up to ~1e-5 on a few points; where it disagrees, exact rational
    # arithmetic over the nearby triangles decides, and must agree with us.
    disagree = np.flatnonzero(rel > 1e-6)
    assert len(disagree) <= 0.01 * len(pts), f"{len(disagree)} points disagree with trimesh"
    for i in disagree:
        exact = exact_distance(mesh, pts[i])
        assert abs(ours[i] - exact) <= 1e-9 * exact, (i, ours[i], exact, ref[i])
    ref = ref.copy()
    ref[disagree] = ours[disagree]
    # Statistics against numpy on the same distances (population std, linear percentiles).
    acc = rep["accuracy"]
    assert acc["count"] == len(ref)
    assert acc["metric"] == "point_to_triangle"
    np.testing.assert_allclose(acc["mean"], ref.mean(), rtol=1e-9)
    np.testing.assert_allclose(acc["std"], ref.std(), rtol=1e-8)
    np.testing.assert_allclose(acc["median"], np.median(ref), rtol=1e-9)
    np.testing.assert_allclose(acc["rms"], np.sqrt(np.mean(ref ** 2)), rtol=1e-9)
    for q in (50, 90, 95, 99):
        np.testing.assert_allclose(acc["percentiles"][f"p{q}"], np.percentile(ref, q), rtol=1e-9)
    np.testing.assert_allclose(acc["max"], ref.max(), rtol=1e-9)
    # the histogram against numpy's on the report's own edges; beyond them, under/overflow
    h = acc["histogram"]
    want, _ = np.histogram(ref, bins=np.array(h["edges"]))
    assert h["counts"] == want.tolist()
    assert h["underflow"] == int((ref < h["edges"][0]).sum())
    assert h["overflow"] == int((ref > h["edges"][-1]).sum())
    assert sum(h["counts"]) + h["underflow"] + h["overflow"] == len(ref)


def test_point_to_mesh_matches_open3d_raycasting(tmp_path, run_eval):
    mesh = blob_mesh(5)
    gt = tmp_path / "gt.ply"
    o3d_mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(mesh.vertices),
                                         o3d.utility.Vector3iVector(mesh.faces))
    assert o3d.io.write_triangle_mesh(str(gt), o3d_mesh, write_ascii=False)
    pts = noisy_points(mesh, 5000, 0.02, 200, seed=5)
    recon = tmp_path / "recon.ply"
    write_o3d_cloud(recon, pts, ascii=True)
    rep, data = run_eval(gt, recon, "--samples", "20000")
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(o3d_mesh))
    ref = scene.compute_distance(o3d.core.Tensor(pts.astype(np.float32))).numpy().astype(np.float64)
    # Open3D computes in float32: agreement to float32 resolution of the scene size.
    diag = np.linalg.norm(mesh.bounds[1] - mesh.bounds[0])
    assert np.max(np.abs(data["distance"] - ref)) < 2e-6 * diag
    np.testing.assert_allclose(rep["accuracy"]["mean"], ref.mean(), rtol=1e-5)


def test_signed_distance_sign_matches_trimesh(tmp_path, run_eval):
    mesh = blob_mesh()
    gt = tmp_path / "gt.glb"
    mesh.export(gt)
    rng = np.random.default_rng(11)
    pts, fid = trimesh.sample.sample_surface(mesh, 2000, seed=11)
    offsets = rng.uniform(-0.05, 0.05, size=len(pts))
    pts = pts + mesh.face_normals[fid] * offsets[:, None]
    recon = tmp_path / "recon.ply"
    write_o3d_cloud(recon, pts, ascii=False)
    rep, data = run_eval(gt, recon, "--signed", "--samples", "10000")
    mesh = load_mesh(gt)
    # trimesh: positive inside; CloudCompare/ours: positive on the normal (outside) side.
    ref = -trimesh.proximity.signed_distance(mesh, pts)
    clear = np.abs(ref) > 1e-3
    assert np.mean(np.sign(data["signed_distance"][clear]) == np.sign(ref[clear])) > 0.995
    np.testing.assert_allclose(np.abs(data["signed_distance"]), data["distance"], rtol=0, atol=0)
    assert rep["accuracy"]["signed"]["count"] == len(pts)
    assert rep["accuracy"]["signed"]["min"] < 0 < rep["accuracy"]["signed"]["max"]


def test_cloud_ground_truth_nn_and_tnt_prf(tmp_path, run_eval):
    """A dense GT cloud (LiDAR case): NN distances both ways against scipy, P/R/F with the Tanks
    and Temples formula (share of distances < tau)."""
    mesh = blob_mesh()
    gt_pts = noisy_points(mesh, 40000, 0.0, 0, seed=1)
    gt = tmp_path / "gt_cloud.ply"
    write_o3d_cloud(gt, gt_pts, ascii=False)
    recon_pts = noisy_points(mesh, 4000, 0.01, 150, seed=2)
    recon = tmp_path / "recon.ply"
    trimesh.PointCloud(recon_pts).export(recon, encoding="ascii")
    taus = [0.005, 0.01, 0.05]
    rep, data = run_eval(gt, recon, "--tau", ",".join(map(str, taus)))
    gt_pts, recon_pts = load_points(gt), load_points(recon)
    d_acc, _ = cKDTree(gt_pts).query(recon_pts)
    d_comp, _ = cKDTree(recon_pts).query(gt_pts)
    np.testing.assert_allclose(data["distance"], d_acc, rtol=1e-12, atol=1e-15)
    assert rep["accuracy"]["metric"] == "point_to_point"
    assert rep["completeness"]["samples"] == len(gt_pts)
    np.testing.assert_allclose(rep["completeness"]["mean"], d_comp.mean(), rtol=1e-9)
    diag = np.linalg.norm(gt_pts.max(0) - gt_pts.min(0))
    for t, entry in zip(taus, rep["thresholds"]):
        p = np.mean(d_acc < t)
        r = np.mean(d_comp < t)
        f = 2 * p * r / (p + r) if p + r > 0 else 0.0
        assert entry["tau"] == t
        assert entry["precision"] == pytest.approx(p, abs=1e-12)
        assert entry["recall"] == pytest.approx(r, abs=1e-12)
        assert entry["f_score"] == pytest.approx(f, abs=1e-12)
        assert entry["tau_percent_of_diagonal"] == pytest.approx(100 * t / diag, rel=1e-9)


def test_completeness_samples_agree_with_trimesh_sampling(tmp_path, run_eval):
    mesh = blob_mesh()
    gt = tmp_path / "gt.obj"
    mesh.export(gt)
    recon_pts = noisy_points(mesh, 3000, 0.005, 0, seed=9)
    recon = tmp_path / "recon.ply"
    write_o3d_cloud(recon, recon_pts, ascii=False)
    rep, _ = run_eval(gt, recon, "--samples", "200000", "--tau", "0.05")
    mesh = load_mesh(gt)
    ref_samples, _ = trimesh.sample.sample_surface(mesh, 200000, seed=4)
    d, _ = cKDTree(recon_pts).query(ref_samples)
    # Two independent area-uniform samplings: means agree within a few standard errors.
    se = d.std() / np.sqrt(len(d)) * np.sqrt(2)
    assert abs(rep["completeness"]["mean"] - d.mean()) < 5 * se
    assert rep["thresholds"][0]["recall"] == pytest.approx(np.mean(d < 0.05), abs=0.005)
    assert rep["inputs"]["ground_truth"]["area"] == pytest.approx(mesh.area, rel=1e-9)


def test_blender_glb_with_node_transforms(tmp_path, run_eval, sfmeval_bin):
    """A GLB written by Blender's glTF exporter (bpy), with a parent/child hierarchy: our world
    vertices must be Blender's world vertices converted to glTF's Y-up frame."""
    bpy = pytest.importorskip("bpy")
    script = tmp_path / "make.py"
    out = tmp_path / "blender.glb"
    verts = tmp_path / "verts.npy"
    script.write_text(f"""
import bpy, numpy as np, math
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_monkey_add(size=1.0)
monkey = bpy.context.object
bpy.ops.object.empty_add(location=(3.0, -1.0, 2.0))
parent = bpy.context.object
parent.scale = (2.0, 2.0, 2.0)
parent.rotation_euler = (0.3, 0.0, math.radians(90))
monkey.parent = parent
monkey.location = (0.5, 0.0, 0.0)
monkey.rotation_euler = (0.0, math.radians(30), 0.0)
bpy.context.view_layer.update()
mw = np.array(monkey.matrix_world)
v = np.array([(mw @ np.array([*p.co, 1.0]))[:3] for p in monkey.data.vertices])
np.save(r"{verts}", v)
bpy.ops.export_scene.gltf(filepath=r"{out}", export_format="GLB", export_apply=True)
""")
    import sys
    subprocess.run([sys.executable, str(script)], check=True, capture_output=True)
    blender_world = np.load(verts)
    gltf_world = np.c_[blender_world[:, 0], blender_world[:, 2], -blender_world[:, 1]]
    # The monkey's own vertices (at exactly Blender's world positions) must be at distance ~0.
    recon = tmp_path / "verts.ply"
    trimesh.PointCloud(gltf_world).export(recon, encoding="binary")
    rep, data = run_eval(out, recon, "--samples", "5000")
    assert rep["inputs"]["ground_truth"]["format"] == "glb"
    assert rep["inputs"]["ground_truth"]["triangles"] == 968
    assert data["distance"].max() < 1e-5
    # The bounds printed by `sfmeval info` match trimesh's scene loader.
    scene = trimesh.load(out)
    info = subprocess.run([sfmeval_bin, "info", str(out)], capture_output=True, text=True, check=True).stdout
    assert "triangles 968" in info
    lo, hi = scene.bounds
    np.testing.assert_allclose(gltf_world.min(0), lo, atol=1e-5)
    np.testing.assert_allclose(gltf_world.max(0), hi, atol=1e-5)


def test_files_from_meshlab_and_colmap(tmp_path, run_eval):
    """A GT mesh saved by MeshLab (pymeshlab, binary and ascii PLY, OBJ) and a cloud written by
    COLMAP's PLY exporter (pycolmap)."""
    pymeshlab = pytest.importorskip("pymeshlab")
    pycolmap = pytest.importorskip("pycolmap")
    mesh = blob_mesh(3)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(mesh.vertices, mesh.faces))
    paths = {
        "ml_bin.ply": dict(binary=True),
        "ml_ascii.ply": dict(binary=False),
        "ml.obj": {},
    }
    for name, kw in paths.items():
        ms.save_current_mesh(str(tmp_path / name), **kw)
    pts = noisy_points(mesh, 500, 0.01, 10, seed=7)
    rec = pycolmap.Reconstruction()
    for p in pts:
        rec.add_point3D(p, pycolmap.Track(), np.array([10, 20, 30], dtype=np.uint8))
    colmap_ply = tmp_path / "colmap.ply"
    rec.export_PLY(str(colmap_ply))
    _, ref, _ = trimesh.proximity.closest_point(mesh, pts)
    means = []
    for name in paths:
        rep, data = run_eval(tmp_path / name, colmap_ply, "--samples", "5000")
        assert rep["inputs"]["reconstruction"]["points"] == len(pts)
        # COLMAP stores float32 coordinates: compare at float32 resolution.
        assert np.max(np.abs(np.sort(data["distance"]) - np.sort(ref))) < 1e-5
        means.append(rep["accuracy"]["mean"])
    assert max(means) - min(means) < 1e-6


def test_crop_box_sphere_and_max_distance(tmp_path, run_eval):
    mesh = blob_mesh()
    gt = tmp_path / "gt.glb"
    mesh.export(gt)
    pts = noisy_points(mesh, 2000, 0.01, 300, seed=13)
    recon = tmp_path / "recon.ply"
    write_o3d_cloud(recon, pts, ascii=False)
    _, ref, _ = trimesh.proximity.closest_point(mesh, pts)
    rep, data = run_eval(gt, recon, "--crop-box", "-0.5,-2,-2,2,2,2", "--max-distance", "0.05", "--samples", "5000")
    mesh = load_mesh(gt)
    _, ref, _ = trimesh.proximity.closest_point(mesh, pts)
    inside = (pts[:, 0] >= -0.5)
    keep = inside & (ref <= 0.05)
    assert rep["crop"]["kind"] == "box+max_distance"
    assert rep["crop"]["discarded_outside_volume"] == int((~inside).sum())
    assert rep["crop"]["discarded_farther_than_max_distance"] == int((inside & (ref > 0.05)).sum())
    assert rep["crop"]["kept"] == int(keep.sum())
    np.testing.assert_allclose(rep["accuracy"]["mean"], ref[keep].mean(), rtol=1e-6)
    assert list(data["status"][keep]) == ["kept"] * int(keep.sum())
    crop = tmp_path / "crop.json"
    crop.write_text(json.dumps({"schema": "sfmeval.crop/1",
                                "volume": {"kind": "sphere", "center": [0.2, 0, 0], "radius": 0.8}}))
    rep, _ = run_eval(gt, recon, "--crop", crop, "--samples", "5000")
    inside = np.linalg.norm(pts - [0.2, 0, 0], axis=1) <= 0.8
    assert rep["crop"]["kept"] == int(inside.sum())
    assert rep["completeness"]["samples"] < 5000  # GT samples cropped to the sphere too


def test_transform_is_applied(tmp_path, run_eval):
    mesh = blob_mesh()
    gt = tmp_path / "gt.glb"
    mesh.export(gt)
    pts_gt = noisy_points(mesh, 1000, 0.005, 0, seed=21)
    R = trimesh.transformations.random_rotation_matrix(np.random.default_rng(3).random(3))[:3, :3]
    s, t = 0.37, np.array([4.0, -2.0, 1.0])
    recon_pts = (pts_gt - t) @ R / s
    recon = tmp_path / "recon.ply"
    write_o3d_cloud(recon, recon_pts, ascii=False)
    T = np.eye(4)
    T[:3, :3] = s * R
    T[:3, 3] = t
    tf = tmp_path / "T.txt"
    np.savetxt(tf, T, fmt="%.17g")
    rep, data = run_eval(gt, recon, "--transform", tf, "--samples", "5000")
    np.testing.assert_allclose(np.c_[data["x"], data["y"], data["z"]], pts_gt, atol=1e-9)
    mesh = load_mesh(gt)
    _, ref, _ = trimesh.proximity.closest_point(mesh, pts_gt)
    np.testing.assert_allclose(rep["accuracy"]["mean"], ref.mean(), rtol=1e-5)
    assert rep["alignment"]["method"] == "given"
    assert rep["alignment"]["scale"] == pytest.approx(s, rel=1e-12)


def test_report_identical_with_one_and_two_threads(tmp_path, sfmeval_bin):
    mesh = blob_mesh()
    gt = tmp_path / "gt.glb"
    mesh.export(gt)
    recon = tmp_path / "recon.ply"
    write_o3d_cloud(recon, noisy_points(mesh, 30000, 0.01, 500, seed=1), ascii=False)
    outs = []
    for threads in (1, 2):
        out = tmp_path / f"r{threads}.json"
        subprocess.run([sfmeval_bin, "eval", "--gt", gt, "--recon", recon, "--threads", str(threads),
                        "--report", out, "--quiet", "--signed", "--align", "none"], check=True)
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]


def test_bad_input_exit_codes_and_messages(tmp_path, sfmeval_bin):
    gt = tmp_path / "gt.glb"
    blob_mesh(2).export(gt)
    bad = tmp_path / "broken.ply"
    bad.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x01")
    p = subprocess.run([sfmeval_bin, "eval", "--gt", gt, "--recon", bad], capture_output=True, text=True)
    assert p.returncode == 1
    assert "broken.ply" in p.stderr and "1000" in p.stderr
    p = subprocess.run([sfmeval_bin, "eval", "--gt", tmp_path / "missing.glb", "--recon", bad], capture_output=True, text=True)
    assert p.returncode == 1 and "missing.glb" in p.stderr
    p = subprocess.run([sfmeval_bin, "eval", "--gt", gt], capture_output=True, text=True)
    assert p.returncode == 2
    p = subprocess.run([sfmeval_bin, "eval", "--gt", gt, "--recon", gt, "--tau", "-1"], capture_output=True, text=True)
    assert p.returncode == 1 and "threshold" in p.stderr
