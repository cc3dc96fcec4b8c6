"""Alignment through the real `sfmeval` binary: `sfmeval align` and `sfmeval eval --align ...`.

Every expected transform is computed here, independently of sfmeval:
- `align` on the committed pycolmap model (tests/fixtures/models/colmap_text) against the exact
  GT cameras (gt_cameras.json): the written gt_from_recon equals a numpy Umeyama of the matched
  camera centres (parsed here from images.txt), and the aligned centres land on the GT ones.
- `eval --align icp|global|global+icp|points|cameras|cameras+icp` on a cloud sampled from
  Blender's Suzanne (tests/fixtures/core/blender_monkey.glb) with numpy and mapped by a known
  similarity: the reported gt_from_recon must be that similarity (its inverse took the cloud
  into the reconstruction frame).

Measured: the whole file runs in about 9 s on 2 cores (release binary; 3 s of it importing
Open3D to read the GLB).
"""
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from numpy_ref import (apply, decompose, quat_to_rot, random_rotation, rot_err_deg,
                       scale_err, similarity, umeyama_np)

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "tests" / "fixtures" / "models"
SUZANNE = ROOT / "tests" / "fixtures" / "core" / "blender_monkey.glb"


# ---------------------------------------------------------------- independent helpers


def rot_to_quat(r):
    """Shepperd's method: (w, x, y, z) with w ≥ 0."""
    t = np.trace(r)
    cands = [t, r[0, 0], r[1, 1], r[2, 2]]
    k = int(np.argmax(cands))
    if k == 0:
        w = np.sqrt(1 + t) / 2
        q = [w, (r[2, 1] - r[1, 2]) / (4 * w), (r[0, 2] - r[2, 0]) / (4 * w),
             (r[1, 0] - r[0, 1]) / (4 * w)]
    else:
        i, j, kk = [(0, 1, 2), (1, 2, 0), (2, 0, 1)][k - 1]
        v = np.sqrt(1 + r[i, i] - r[j, j] - r[kk, kk]) / 2
        q = [0.0] * 4
        q[0] = (r[kk, j] - r[j, kk]) / (4 * v)
        q[1 + i] = v
        q[1 + j] = (r[j, i] + r[i, j]) / (4 * v)
        q[1 + kk] = (r[kk, i] + r[i, kk]) / (4 * v)
    q = np.array(q)
    return q if q[0] >= 0 else -q


def colmap_centres(images_txt):
    """{name: camera centre} from a COLMAP images.txt (centre = -Rᵀ t)."""
    out = {}
    lines = [ln for ln in Path(images_txt).read_text().splitlines() if not ln.startswith("#")]
    for ln in lines[::2]:
        w = ln.split()
        r = quat_to_rot([float(v) for v in w[1:5]])
        out[w[9]] = -r.T @ np.array([float(v) for v in w[5:8]])
    return out


def cameras_json_centres(path):
    d = json.loads(Path(path).read_text())
    out = {}
    for im in d["images"]:
        r = np.array(im["cam_from_world"]["rotation"])
        out[im["name"]] = -r.T @ np.array(im["cam_from_world"]["translation"])
    return out


def read_matrix_txt(path):
    rows = [ln.split() for ln in Path(path).read_text().splitlines()
            if ln.strip() and not ln.startswith("#")]
    return np.array(rows, float)


def suzanne():
    """Vertices and triangles of the Blender GLB in the file's frame (as sfmeval reads it)."""
    import open3d as o3d

    mesh = o3d.io.read_triangle_mesh(str(SUZANNE))
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
    assert len(f) > 500
    return v, f


def sample_surface(v, f, n, rng):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    t = rng.choice(len(f), size=n, p=area / area.sum())
    su, w = np.sqrt(rng.random(n))[:, None], rng.random(n)[:, None]
    return (1 - su) * a[t] + su * (1 - w) * b[t] + su * w * c[t]


def write_ply(path, p):
    p = np.asarray(p, np.float64)
    head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(p)}\n"
            "property double x\nproperty double y\nproperty double z\nend_header\n")
    Path(path).write_bytes(head.encode() + p.astype("<f8").tobytes())


def look_at(centre, target, up=(0.0, 1.0, 0.0)):
    z = np.asarray(target, float) - centre
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z])


def write_colmap_text(folder, poses, points, f=300.0, wh=(640, 480)):
    """A COLMAP text model: poses = [(name, R cam_from_world, centre)], points (no tracks)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "cameras.txt").write_text(
        f"1 PINHOLE {wh[0]} {wh[1]} {f} {f} {wh[0] / 2} {wh[1] / 2}\n")
    lines = []
    for i, (name, r, c) in enumerate(poses):
        q, t = rot_to_quat(r), -r @ c
        lines.append(f"{i + 1} {' '.join(repr(float(v)) for v in [*q, *t])} 1 {name}\n\n")
    (folder / "images.txt").write_text("".join(lines))
    (folder / "points3D.txt").write_text("".join(
        f"{i + 1} {p[0]!r} {p[1]!r} {p[2]!r} 128 128 128 0.5\n" for i, p in enumerate(points)))


def write_cameras_json(path, poses, f=300.0, wh=(640, 480)):
    images = [{"name": n, "camera_id": 1,
               "cam_from_world": {"rotation": r.tolist(), "translation": (-r @ c).tolist()}}
              for n, r, c in poses]
    path.write_text(json.dumps({
        "schema": "sfmeval.cameras/1", "frame": "gltf", "pixel_convention": "colmap",
        "cameras": [{"id": 1, "model": "PINHOLE", "width": wh[0], "height": wh[1],
                     "fx": f, "fy": f, "cx": wh[0] / 2, "cy": wh[1] / 2}],
        "images": images}))


def scene_obj(path):
    """The fixture scene as an OBJ: the quads render_scene.py ray-casts, two triangles each."""
    import sys

    sys.path.insert(0, str(MODELS))
    try:
        from render_scene import QUADS
    finally:
        sys.path.remove(str(MODELS))
    lines = []
    for k, (o, eu, ev) in enumerate(QUADS):
        o, eu, ev = (np.asarray(a, float) for a in (o, eu, ev))
        for p in [o, o + eu, o + eu + ev, o + ev]:
            lines.append(f"v {p[0]} {p[1]} {p[2]}")
        b = 4 * k + 1
        lines += [f"f {b} {b + 1} {b + 2}", f"f {b} {b + 2} {b + 3}"]
    Path(path).write_text("\n".join(lines) + "\n")
    return path


def run(sfmeval_bin, *args):
    p = subprocess.run([sfmeval_bin, *map(str, args)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return p


# ---------------------------------------------------------------- sfmeval align

def test_align_writes_the_umeyama_transform_of_the_camera_centres(sfmeval_bin, tmp_path):
    """`sfmeval align --align cameras` on the pycolmap fixture: the txt and json outputs hold the
    same 4×4, which is the numpy Umeyama of the 6 matched centres (no outlier among them), and
    maps the reconstructed centres onto the exact GT centres."""
    gt = scene_obj(tmp_path / "scene.obj")
    est = colmap_centres(MODELS / "colmap_text" / "images.txt")
    ref = cameras_json_centres(MODELS / "gt_cameras.json")
    names = sorted(est)
    assert len(names) == 6 and set(names) <= set(ref)
    src = np.array([est[n] for n in names])
    dst = np.array([ref[n] for n in names])
    expect = umeyama_np(src, dst)
    common = ["align", "--gt", gt, "--recon", MODELS / "colmap_text",
              "--gt-cameras", MODELS / "gt_cameras.json", "--align", "cameras"]
    p = run(sfmeval_bin, *common, "--out", tmp_path / "t.txt")
    run(sfmeval_bin, *common, "--out", tmp_path / "t.json")
    m_txt = read_matrix_txt(tmp_path / "t.txt")
    a = json.loads((tmp_path / "t.json").read_text())
    m_json = np.array(a["gt_from_recon"])
    assert m_txt.shape == (4, 4)
    np.testing.assert_allclose(m_txt, m_json, rtol=0, atol=1e-15)
    # The printed matrix is the saved one.
    printed = np.array([ln.split() for ln in p.stdout.splitlines() if not ln.startswith("#")],
                       float)
    np.testing.assert_array_equal(printed, m_txt)
    assert a["method"] == "cameras" and [s["method"] for s in a["stages"]] == ["cameras"]
    assert a["inlier_ratio"] == 1.0
    np.testing.assert_allclose(a["scale"], decompose(expect)[0], rtol=1e-9)
    np.testing.assert_allclose(m_txt, expect, rtol=0, atol=1e-9 * np.abs(expect).max())
    # pycolmap's centres agree with the exact ones to well under 1 % of the 4.5 orbit radius.
    err = np.linalg.norm(apply(m_txt, src) - dst, axis=1)
    assert err.max() < 0.01 * 4.5, err
    assert abs(np.sqrt((err ** 2).mean()) - a["rmse"]) < 1e-9


def test_align_auto_refines_onto_the_scene_mesh(sfmeval_bin, tmp_path):
    """`sfmeval align` (auto = cameras + icp against the scene mesh): the ICP stage starts from
    the camera stage (the same 4×4 as `--align cameras`) and brings the model's points closer
    to the mesh, measured here with trimesh's exact closest points."""
    import trimesh

    gt = scene_obj(tmp_path / "scene.obj")
    common = ["align", "--gt", gt, "--recon", MODELS / "colmap_text",
              "--gt-cameras", MODELS / "gt_cameras.json"]
    run(sfmeval_bin, *common, "--out", tmp_path / "auto.json")
    run(sfmeval_bin, *common, "--align", "cameras", "--out", tmp_path / "cams.json")
    a = json.loads((tmp_path / "auto.json").read_text())
    c = json.loads((tmp_path / "cams.json").read_text())
    assert a["method"] == "cameras+icp"
    assert [s["method"] for s in a["stages"]] == ["cameras", "icp"]
    np.testing.assert_array_equal(a["stages"][0]["gt_from_recon"], c["gt_from_recon"])
    pts = np.array([ln.split()[1:4] for ln in
                    (MODELS / "colmap_text" / "points3D.txt").read_text().splitlines()
                    if not ln.startswith("#")], float)
    mesh = trimesh.load(gt, process=False)

    def mean_dist(m):
        return trimesh.proximity.closest_point(mesh, apply(np.array(m), pts))[1].mean()

    d_cams, d_auto = mean_dist(c["gt_from_recon"]), mean_dist(a["gt_from_recon"])
    assert d_auto < 0.8 * d_cams, (d_auto, d_cams)
    # The cameras stay close to the GT ones (the refinement moves them by ~1-2 % of the orbit
    # radius on this 101-point model: its points and cameras are not perfectly consistent).
    est = colmap_centres(MODELS / "colmap_text" / "images.txt")
    ref = cameras_json_centres(MODELS / "gt_cameras.json")
    names = sorted(est)
    err = np.linalg.norm(apply(np.array(a["gt_from_recon"]), np.array([est[n] for n in names]))
                         - np.array([ref[n] for n in names]), axis=1)
    assert err.max() < 0.03 * 4.5, err


# ---------------------------------------------------------------- eval --align ...

@pytest.fixture(scope="module")
def suzanne_case(tmp_path_factory):
    """A 4000-point cloud on Suzanne (0.2 % noise), taken into a recon frame by truth⁻¹."""
    d = tmp_path_factory.mktemp("suzanne")
    v, f = suzanne()
    rng = np.random.default_rng(41)
    truth = similarity(0.37, random_rotation(rng), [3.0, -1.0, 2.0])
    diag = np.linalg.norm(v.max(0) - v.min(0))
    pts = sample_surface(v, f, 4000, rng)
    pts += rng.normal(scale=0.002 * diag / np.sqrt(3), size=pts.shape)
    recon = apply(np.linalg.inv(truth), pts)
    write_ply(d / "recon.ply", recon)
    return d, v, truth, recon


def eval_align(run_eval, recon, *extra):
    rep, _ = run_eval(SUZANNE, recon, "--samples", 20000, *extra)
    return rep, np.array(rep["alignment"]["gt_from_recon"])


def test_eval_icp_from_a_transform_file_and_from_the_identity(run_eval, suzanne_case, tmp_path):
    d, v, truth, recon = suzanne_case
    rng = np.random.default_rng(5)
    # A start 4° and 3 % off the truth.
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    a = np.radians(4.0)
    off = np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k
    start = similarity(1.03, off, [0.02, -0.01, 0.03]) @ truth
    (tmp_path / "start.txt").write_text("\n".join(" ".join(map(repr, r)) for r in start) + "\n")
    rep, m = eval_align(run_eval, d / "recon.ply", "--align", "icp",
                        "--transform", tmp_path / "start.txt")
    assert rep["alignment"]["method"] == "icp"
    assert rot_err_deg(m, truth) < 0.1 and scale_err(m, truth) < 0.002, rep["alignment"]
    assert rot_err_deg(start, truth) > 3.9  # the start was really off
    # ICP alone from the identity: a cloud already near the GT frame (3° and 2 % off).
    a3 = np.radians(3.0)
    near = similarity(1 / 1.02, np.eye(3) + np.sin(a3) * k + (1 - np.cos(a3)) * k @ k,
                      [0.01, 0.0, -0.02])
    pts_gt = apply(truth, recon)
    write_ply(tmp_path / "near.ply", apply(np.linalg.inv(near), pts_gt))
    rep, m = eval_align(run_eval, tmp_path / "near.ply", "--align", "icp")
    assert any(n["code"] == "alignment.icp_from_identity" and "identity" in n["message"]
               for n in rep["notes"]), rep["notes"]
    assert rot_err_deg(m, near) < 0.1 and scale_err(m, near) < 0.002, rep["alignment"]
    # The accuracy after ICP is at the noise level (0.2 % of the diagonal, 3D RMS).
    diag = np.linalg.norm(v.max(0) - v.min(0))
    assert rep["accuracy"]["median"] < 0.003 * diag


def test_eval_global_alone_and_refined(run_eval, suzanne_case):
    d, _, truth, _ = suzanne_case
    # `global` alone is the coarse start (measured here: 3.2° and 0.3 % off), within reach of
    # ICP; a wrong pose (a flip, a symmetric twin) would be tens of degrees off.
    rep, m = eval_align(run_eval, d / "recon.ply", "--align", "global")
    assert rep["alignment"]["method"] == "global"
    assert rot_err_deg(m, truth) < 10.0 and scale_err(m, truth) < 0.05, rep["alignment"]
    rep, m = eval_align(run_eval, d / "recon.ply", "--align", "global+icp")
    assert [s["method"] for s in rep["alignment"]["stages"]] == ["global", "icp"]
    assert rot_err_deg(m, truth) < 0.1 and scale_err(m, truth) < 0.002, rep["alignment"]


def test_eval_points_with_pairs_is_the_exact_similarity(run_eval, suzanne_case, tmp_path):
    """5 exact pairs (mesh vertices and their recon-frame images): `points` alone is the closed
    form, so gt_from_recon is the truth to rounding; `points+icp` stays on it."""
    d, v, truth, _ = suzanne_case
    rng = np.random.default_rng(9)
    gt_pts = v[rng.choice(len(v), 5, replace=False)]
    rec_pts = apply(np.linalg.inv(truth), gt_pts)
    pairs = {"pairs": [{"recon": list(map(float, r)), "gt": list(map(float, g))}
                       for r, g in zip(rec_pts, gt_pts)]}
    (tmp_path / "pairs.json").write_text(json.dumps(pairs))
    rep, m = eval_align(run_eval, d / "recon.ply", "--align", "points",
                        "--pairs", tmp_path / "pairs.json")
    assert rep["alignment"]["method"] == "points"
    np.testing.assert_allclose(m, truth, atol=1e-9 * np.abs(truth).max())
    rep, m = eval_align(run_eval, d / "recon.ply", "--align", "points+icp",
                        "--pairs", tmp_path / "pairs.json")
    assert rot_err_deg(m, truth) < 0.1 and scale_err(m, truth) < 0.002


def test_eval_cameras_and_cameras_icp(run_eval, suzanne_case, tmp_path):
    """A COLMAP text model whose 10 cameras (and points) are the GT cameras taken by truth⁻¹:
    `cameras` recovers the truth exactly (noise-free centres), `cameras+icp` to the ICP
    tolerance, and the pose section measures ~0 errors for the camera stage."""
    d, v, truth, recon = suzanne_case
    c0 = (v.max(0) + v.min(0)) / 2
    rad = 1.5 * np.linalg.norm(v.max(0) - v.min(0))
    s_t, r_t = decompose(truth)
    gt_poses, rec_poses = [], []
    for i in range(10):
        a = 2 * np.pi * i / 10
        c = c0 + rad * np.array([np.cos(a), 0.3 * np.sin(3 * a), np.sin(a)])
        r = look_at(c, c0)
        gt_poses.append((f"{i:04d}.png", r, c))
        rec_poses.append((f"images/{i:04d}.PNG", r @ r_t, apply(np.linalg.inv(truth), c)))
    write_colmap_text(tmp_path / "model", rec_poses, recon)
    write_cameras_json(tmp_path / "cameras.json", gt_poses)
    for method in ["cameras", "cameras+icp"]:
        rep, m = eval_align(run_eval, tmp_path / "model", "--align", method,
                            "--gt-cameras", tmp_path / "cameras.json")
        assert rep["alignment"]["method"] == method
        if method == "cameras":
            np.testing.assert_allclose(m, truth, atol=1e-9 * np.abs(truth).max())
        assert rot_err_deg(m, truth) < 0.1 and scale_err(m, truth) < 0.002, method
        cams = rep["cameras"]
        assert cams["matched"] == 10 and cams["alignment"]["stage"] == "cameras"
        assert cams["rotation_error_deg"]["max"] < 1e-4
        assert cams["center_error"]["max"] < 1e-9 * rad


@pytest.mark.parametrize("args, message", [
    (["--align", "given"], "--align given needs --transform FILE"),
    (["--align", "points+icp"], "--align points+icp needs --pairs FILE"),
    (["--align", "none", "--transform", "T"], "--align none ignores --transform (use --align given"),
    (["--align", "cameras", "--transform", "T"], "--align cameras ignores --transform (it is used by"),
])
def test_eval_names_the_flag_an_alignment_lacks_or_ignores(sfmeval_bin, tmp_path, args, message):
    """A request the core refuses (`Error::AlignInput`) is told in the flags the user typed,
    before any file is read, and nothing is written."""
    (tmp_path / "t.txt").write_text("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    args = [str(tmp_path / "t.txt") if a == "T" else a for a in args]
    out = tmp_path / "report.json"
    r = subprocess.run([sfmeval_bin, "eval", "--gt", str(SUZANNE), "--recon", str(SUZANNE),
                        "--report", str(out), *args], capture_output=True, text=True)
    assert r.returncode != 0
    assert message in r.stderr, r.stderr
    assert not out.exists()


@pytest.mark.parametrize("method", ["global", "global+icp", "auto"])
def test_align_samples_the_ground_truth_as_eval_does(sfmeval_bin, tmp_path, method):
    """`sfmeval align` draws the ground truth's surface samples as `eval` does (it once drew 1,
    and `--align global` then failed with "the ground truth has zero extent"): on the demo's
    sparse.ply (no cameras, so `auto` runs the global search too) `align` writes exactly the
    alignment section of `eval`'s report."""
    demo = ROOT / "data" / "demo"
    common = ["--gt", demo / "ground_truth.glb", "--recon", demo / "sparse.ply",
              "--align", method]
    run(sfmeval_bin, "align", *common, "--out", tmp_path / "a.json")
    run(sfmeval_bin, "eval", *common, "--report", tmp_path / "r.json", "--quiet")
    aligned = json.loads((tmp_path / "a.json").read_text())
    report = json.loads((tmp_path / "r.json").read_text())
    assert aligned["method"] == {"auto": "global+icp"}.get(method, method)
    assert aligned == report["alignment"]
    # and a smaller sample count is a different search (the flag reaches the core)
    run(sfmeval_bin, "align", *common, "--samples", "2000", "--out", tmp_path / "b.json")
    fewer = json.loads((tmp_path / "b.json").read_text())
    assert fewer["gt_from_recon"] != aligned["gt_from_recon"]
