"""The five built-in objects, each built through the real CLI from its own preset with a tiny
render (2 views 15° apart at 320×180, 8 spp, depth + masks), and measured on the exported
ground_truth.glb (trimesh) for the property the object stands for: the vase is a surface of
revolution, the hydrant symmetric, the bicycle made of thin tubes, the vehicle boxy; every
object is closed where built closed, normalised to the configured size, textured in object
coordinates (the same surface point has the same colour in both views) and reproducible.

Cost (2-vCPU machine, loaded by two other jobs): 30 s for the file: the five renders 15 s,
the six --no-render reruns 11 s, the measurements 4 s.
"""

import os

import numpy as np
import pytest
from PIL import Image

from blender_testlib import bilinear, camera_matrices, load_json, project, requires_bpy
from blender_testlib import run_generate

pytestmark = requires_bpy

# A distinct object.size per object, so the normalisation is checked against the config.
SIZES = {"statue": 1.0, "vase": 0.8, "bicycle": 1.7, "hydrant": 0.5, "vehicle": 2.5}
TINY = ["--set", "camera.resolution=[320, 180]", "--set", "render.samples=8",
        "--set", "views.orbits=[{elevation_deg=30.0, count=2, azimuth_step_deg=15.0}]",
        "--set", "outputs.colmap_gt=false"]


def _args(name, seed=0):
    return ["--preset", name, "--set", "object.size=%r" % SIZES[name],
            "--set", "dataset.seed=%d" % seed] + TINY


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    root = tmp_path_factory.mktemp("builtins")
    out = {}
    for name in SIZES:
        d = root / name
        proc = run_generate(_args(name) + ["--out", str(d)], timeout=600)
        assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
        out[name] = d
    return out


def _mesh(dataset):
    """The GLB as one trimesh mesh (node transforms applied, primitives concatenated, vertices
    merged by position: the exporter splits them by material and normal)."""
    import trimesh
    scene = trimesh.load(str(dataset / "ground_truth.glb"), force="scene")
    mesh = scene.to_geometry() if hasattr(scene, "to_geometry") else scene.dump(concatenate=True)
    mesh.merge_vertices(merge_tex=True, merge_norm=True)
    return mesh


def _components(mesh):
    """(closed, signed volume) per connected component; closed = every edge in exactly two
    faces of the component."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    adj = mesh.face_adjacency
    n = len(mesh.faces)
    graph = coo_matrix((np.ones(len(adj)), (adj[:, 0], adj[:, 1])), shape=(n, n))
    count, label = connected_components(graph, directed=False)
    out = []
    for k in range(count):
        f = mesh.faces[label == k]
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        _, uses = np.unique(edges, axis=0, return_counts=True)
        tri = mesh.vertices[f]
        vol = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0
        out.append((bool((uses == 2).all()), vol))
    return out


def _measures(mesh):
    """Scale-free shape measures (lengths divided by the largest bounding-box edge)."""
    lo, hi = mesh.bounds
    size = (hi - lo).max()
    comps = _components(mesh)
    vol = sum(v for closed, v in comps if closed)
    normals, areas = mesh.face_normals, mesh.area_faces
    aligned = areas[np.abs(normals).max(1) > np.cos(np.radians(3.0))].sum() / areas.sum()
    return {"size": size, "fill": vol / np.prod(hi - lo),            # closed volume / bbox
            "thickness": 2.0 * vol / mesh.area / size,               # = tube radius for tubes
            "aligned": aligned,                                      # area facing ±x, ±y, ±z
            "open": sum(not closed for closed, _ in comps), "components": len(comps)}


@pytest.fixture(scope="module")
def meshes(built):
    return {name: _mesh(d) for name, d in built.items()}


@pytest.fixture(scope="module")
def measures(meshes):
    return {name: _measures(m) for name, m in meshes.items()}


def test_every_object_is_built_normalised_and_closed(built, meshes, measures):
    for name, mesh in meshes.items():
        v = mesh.vertices
        assert len(v) > 100 and len(mesh.faces) > 100, name
        assert np.isfinite(v).all(), name
        lo, hi = mesh.bounds
        # largest bounding-box edge = object.size, bounding-box centre at the origin
        assert abs((hi - lo).max() - SIZES[name]) < 1e-5 * SIZES[name], (name, hi - lo)
        assert np.abs((lo + hi) / 2).max() < 1e-5 * SIZES[name], (name, (lo + hi) / 2)
        meta = load_json(built[name] / "dataset.json")
        assert meta["source"] == {"kind": "builtin", "name": name, "seed": 0}
        assert np.allclose(meta["object"]["bbox_min_gltf"], lo, atol=1e-5)
        assert np.allclose(meta["object"]["bbox_max_gltf"], hi, atol=1e-5)
        assert sorted(os.listdir(built[name] / "images")) == ["0000.jpg", "0001.jpg"]
        if name == "bicycle":
            # every part is a closed solid except the spokes (open tubes, shapes.bicycle):
            # 2 wheels x 16
            assert measures[name]["open"] == 32, measures[name]
        else:
            assert mesh.is_watertight, name
            assert measures[name]["open"] == 0, measures[name]


def _axis_frame(mesh):
    """Vertices relative to the bounding-box centre; glTF +Y is the vertical axis."""
    lo, hi = mesh.bounds
    return mesh.vertices - (lo + hi) / 2, hi - lo


def _revolution_spread(mesh, bands=40, sectors=12, samples=60000):
    """Per height band, the outer radius about the vertical axis in each angular sector
    (max over dense surface samples); returns each band's (max − min) / mean over sectors."""
    import trimesh
    lo, hi = mesh.bounds
    c = (lo + hi) / 2
    pts, _ = trimesh.sample.sample_surface(mesh, samples, seed=3)
    x, y, z = (pts - c).T
    r = np.hypot(x, z)
    hb = np.minimum(((y - lo[1]) / (hi[1] - lo[1]) * bands).astype(int), bands - 1)
    sb = ((np.arctan2(z, x) + np.pi) / (2 * np.pi) * sectors).astype(int) % sectors
    out = []
    for b in range(bands):
        outer = np.full(sectors, np.nan)
        for s in range(sectors):
            sel = (hb == b) & (sb == s)
            if sel.any():
                outer[s] = r[sel].max()
        if not np.isnan(outer).any():
            out.append((outer.max() - outer.min()) / outer.mean())
    return np.array(out)


def test_vase_is_a_surface_of_revolution(meshes):
    """The vase's radius depends on height only, up to its seeded ripple (shapes.vase: ±3 %
    terms); the statue, measured the same way, is far from it (the measure discriminates)."""
    vase = _revolution_spread(meshes["vase"])
    statue = _revolution_spread(meshes["statue"])
    assert len(vase) >= 30
    # measured: vase median 0.05, max 0.08; statue median 0.3
    assert np.median(vase) < 0.08 and vase.max() < 0.12, vase
    assert np.median(statue) > 0.15, statue


def _surface_distance(mesh, transform, n=3000):
    """Distances from the transformed surface samples to the mesh, / largest extent."""
    import trimesh
    pts, _ = trimesh.sample.sample_surface(mesh, n, seed=5)
    c, ext = (mesh.bounds[0] + mesh.bounds[1]) / 2, mesh.extents.max()
    q = (pts - c) @ np.asarray(transform).T + c
    _, dist, _ = trimesh.proximity.closest_point(mesh, q)
    return dist / ext


ROT_Y_180 = np.diag([-1.0, 1.0, -1.0])   # half turn about the vertical (glTF +Y) axis
MIRROR_X = np.diag([-1.0, 1.0, 1.0])
MIRROR_Z = np.diag([1.0, 1.0, -1.0])


def test_hydrant_is_symmetric(meshes):
    """The hydrant maps onto itself under a half turn about its axis (to float precision) and
    under both vertical mirror planes (up to how the exporter split the non-planar quads into
    triangles: a mirror flips the diagonal; measured 99th percentile 7.7e-4 of the size, max
    1.4e-3); the statue and the vehicle do not (measured 0.09 and 0.16)."""
    d = _surface_distance(meshes["hydrant"], ROT_Y_180)
    assert np.percentile(d, 99) < 1e-5, np.percentile(d, 99)
    for t in (MIRROR_X, MIRROR_Z):
        d = _surface_distance(meshes["hydrant"], t)
        assert np.percentile(d, 99) < 3e-3 and np.median(d) < 1e-5, np.percentile(d, [50, 99])
    for other in ("statue", "vehicle"):
        d = _surface_distance(meshes[other], ROT_Y_180)
        assert np.percentile(d, 99) > 0.03, (other, np.percentile(d, 99))


def test_bicycle_is_thin_tubes(measures):
    """Closed volume / bounding-box volume and mean thickness 2V/A (= the radius of a long tube)
    are small for the bicycle only. Measured: bicycle 0.014 and 0.008; the others 0.12-0.48 and
    0.03-0.12."""
    b = measures["bicycle"]
    assert b["fill"] < 0.03 and b["thickness"] < 0.015, b
    for name in ("statue", "vase", "hydrant", "vehicle"):
        m = measures[name]
        assert m["fill"] > 0.08 and m["thickness"] > 0.02, (name, m)


def test_vehicle_is_boxy(measures):
    """Most of the vehicle's surface faces ±x, ±y or ±z (within 3°): measured 93 %; the others
    12-16 % (the statue's pedestal, the bicycle's pedals and hub caps) or less."""
    assert measures["vehicle"]["aligned"] > 0.8, measures["vehicle"]
    for name in ("statue", "vase", "bicycle", "hydrant"):
        assert measures[name]["aligned"] < 0.3, (name, measures[name])


def _rgb_at(img, u, v):
    # +1 keeps black pixels valid for bilinear(), which treats 0 as "no data"
    return np.stack([bilinear(img[:, :, c] + 1.0, u, v)[0] for c in range(3)], axis=1)


def test_textures_stick_to_the_surface(built, meshes):
    """Textures are functions of object coordinates: a surface point seen in both views (depth
    maps agree) has the same colour in both renders. Control: the colour 8 px to the side in
    the second view differs far more (measured: same point 3.6-7.8 grey levels median absolute
    difference, 8-spp render noise included; shifted 12 for the low-contrast hydrant, 20-32 for
    the others)."""
    import trimesh
    for name, d in built.items():
        cams = load_json(d / "cameras.json")
        _, K, poses = camera_matrices(cams)
        pts, _ = trimesh.sample.sample_surface(meshes[name], 40000, seed=7)
        names = sorted(poses)
        uv, imgs, seen = {}, {}, np.ones(len(pts), bool)
        for n in names:
            R, t = poses[n]
            p, z = project(K, R, t, pts)
            depth = np.load(d / "depth" / (n[:-4] + ".npy"))
            dz, ok = bilinear(depth, p[:, 0], p[:, 1])
            seen &= ok & (np.abs(dz - z) < 0.003 * z)
            uv[n] = p
            imgs[n] = np.asarray(Image.open(d / "images" / n), float)
        assert seen.sum() > 300, (name, seen.sum())
        a = _rgb_at(imgs[names[0]], *uv[names[0]][seen].T)
        b = _rgb_at(imgs[names[1]], *uv[names[1]][seen].T)
        wrong = _rgb_at(imgs[names[1]], uv[names[1]][seen, 0] + 8.0, uv[names[1]][seen, 1])
        same = np.median(np.abs(a - b).mean(1))
        shifted = np.median(np.abs(a - wrong).mean(1))
        assert same < 10.0 and shifted > 2.0 * same, (name, same, shifted)


def test_same_config_and_seed_same_geometry(built, tmp_path):
    """Every object: a second run (--no-render) gives identical GLB vertices and cameras; a
    different seed changes the seeded shapes (statue, vase), so identity is not trivial."""
    from blender_testlib import glb_vertices
    for name, d in built.items():
        again = tmp_path / name
        proc = run_generate(_args(name) + ["--no-render", "--out", str(again)], timeout=300)
        assert proc.returncode == 0, proc.stderr[-2000:]
        va, _ = glb_vertices(str(d / "ground_truth.glb"))
        vb, _ = glb_vertices(str(again / "ground_truth.glb"))
        assert np.array_equal(va, vb), name
        assert load_json(d / "cameras.json") == load_json(again / "cameras.json"), name
    other = tmp_path / "vase-seed1"
    proc = run_generate(_args("vase", seed=1) + ["--no-render", "--out", str(other)], timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    va, _ = glb_vertices(str(built["vase"] / "ground_truth.glb"))
    vb, _ = glb_vertices(str(other / "ground_truth.glb"))
    assert va.shape != vb.shape or np.abs(va - vb).max() > 1e-3
