"""sfmeval's alignment against independent code on the same data.

- Umeyama: a numpy implementation written here (SVD of the cross-covariance, reflection fix).
- Scaled ICP: Open3D `registration_icp` with `TransformationEstimationPointToPoint(
  with_scaling=True)` from the same start; sfmeval must end at least as close to the truth.
- `auto` on a real file written by Blender (the committed Suzanne GLB) from random rotations.
- Bad input gives a clear error, never a crash.

The Rust side runs through the example binary `align_tool` (crates/sfmeval/examples), built with
the `parallel` feature unless SFMEVAL_ALIGN_TOOL points to a built one.

Timing (not a test): `.venv/bin/python tests/python/test_align_reference.py --bench` aligns 100k
points to a 1M-triangle mesh with cameras+icp and runs Open3D's scaled ICP on the same data.
"""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from numpy_ref import (apply, decompose, random_rotation, rot_err_deg, similarity,
                       umeyama_np)

ROOT = Path(__file__).resolve().parents[2]


def tool_path() -> str:
    env = os.environ.get("SFMEVAL_ALIGN_TOOL")
    if env and Path(env).exists():
        return env
    subprocess.run([str(ROOT / "scripts" / "build-release.sh"), "-q"], cwd=ROOT, check=True)
    return str(ROOT / "target" / "release" / "examples" / "align_tool")


@pytest.fixture(scope="session")
def align_tool() -> str:
    return tool_path()


def run_tool(tool, *args, expect_ok=True):
    p = subprocess.run([tool, *map(str, args)], capture_output=True, text=True)
    if not expect_ok:
        return p
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


# ---------------------------------------------------------------- independent reference code


def blob_mesh(n_lat, n_lon):
    """A non-symmetric bumpy blob (UV sphere with radial bumps, stretched per axis)."""
    th = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(th, ph, indexing="ij")

    def pos(t, p):
        r = 1 + 0.22 * np.sin(3 * t + 0.5) * np.cos(2 * p + 0.3) + 0.12 * np.cos(5 * p) * np.sin(2 * t) + 0.08 * np.sin(t + p)
        return np.stack([1.6 * r * np.sin(t) * np.cos(p), r * np.sin(t) * np.sin(p) + 0.1, 0.7 * r * np.cos(t)], -1)

    v = np.concatenate([pos(np.array([0.0]), np.array([0.0])), pos(T, P).reshape(-1, 3),
                        pos(np.array([np.pi]), np.array([0.0]))])
    south = len(v) - 1
    idx = lambda i, j: 1 + i * n_lon + (j % n_lon)  # noqa: E731
    tris = []
    j = np.arange(n_lon)
    tris.append(np.stack([np.zeros(n_lon, int), idx(0, j), idx(0, j + 1)], -1))
    tris.append(np.stack([np.full(n_lon, south), idx(n_lat - 2, j + 1), idx(n_lat - 2, j)], -1))
    i, jj = np.meshgrid(np.arange(n_lat - 2), j, indexing="ij")
    i, jj = i.ravel(), jj.ravel()
    tris.append(np.stack([idx(i, jj), idx(i + 1, jj), idx(i + 1, jj + 1)], -1))
    tris.append(np.stack([idx(i, jj), idx(i + 1, jj + 1), idx(i, jj + 1)], -1))
    return v, np.concatenate(tris)


def write_mesh(path, v, f):
    import open3d as o3d

    m = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f))
    assert o3d.io.write_triangle_mesh(str(path), m, write_ascii=False)
    return m


def write_cloud(path, p):
    import open3d as o3d

    c = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(p))
    assert o3d.io.write_point_cloud(str(path), c, write_ascii=False)


def sample_surface(mesh, n, rng):
    """Area-uniform surface samples (numpy)."""
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    t = rng.choice(len(f), size=n, p=area / area.sum())
    u, w = rng.random(n), rng.random(n)
    su = np.sqrt(u)[:, None]
    return (1 - su) * a[t] + su * (1 - w[:, None]) * b[t] + su * w[:, None] * c[t]


def make_recon(mesh, truth, n, rng, noise=0.005, outliers=0.2):
    """Surface samples (Open3D's sampler) with isotropic Gaussian noise of 3D RMS `noise` × the
    bounding-box diagonal, `outliers` share uniform in the doubled box, mapped by truth⁻¹."""
    v = np.asarray(mesh.vertices)
    lo, hi = v.min(0), v.max(0)
    diag = np.linalg.norm(hi - lo)
    n_out = int(round(n * outliers))
    pts = sample_surface(mesh, n - n_out, rng)
    pts = pts + rng.normal(scale=noise * diag / np.sqrt(3), size=pts.shape)
    c, h = (lo + hi) / 2, hi - lo
    out = c + h * rng.uniform(-1, 1, size=(n_out, 3))
    p = np.concatenate([pts, out])
    return apply(np.linalg.inv(truth), p)


# ---------------------------------------------------------------- tests

@pytest.mark.parametrize("seed", range(5))
def test_umeyama_matches_numpy(align_tool, tmp_path, seed):
    rng = np.random.default_rng(seed)
    src = rng.normal(size=(40, 3)) * [3, 1, 0.5]
    truth = similarity(10 ** rng.uniform(-2, 2), random_rotation(rng), rng.uniform(-100, 100, 3))
    dst = apply(truth, src) + rng.normal(scale=0.01, size=src.shape)
    if seed == 4:  # a mirrored target: both must return the best proper rotation
        dst[:, 0] *= -1
    f = tmp_path / "pairs.json"
    f.write_text(json.dumps({"pairs": [{"recon": list(a), "gt": list(b)} for a, b in zip(src, dst)]}))
    for flag, with_scale in [((), True), (("--no-scale",), False)]:
        ours = np.array(run_tool(align_tool, "umeyama", f, *flag)["matrix"])
        ref = umeyama_np(src, dst, with_scale)
        np.testing.assert_allclose(ours, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
        assert np.linalg.det(ours[:3, :3]) > 0


@pytest.fixture(scope="module")
def blob(tmp_path_factory):
    d = tmp_path_factory.mktemp("blob")
    v, f = blob_mesh(200, 400)  # ~160k triangles
    mesh = write_mesh(d / "blob.ply", v, f)
    return d, mesh


@pytest.mark.parametrize("seed", range(4))
def test_scaled_icp_at_least_as_close_as_open3d(align_tool, blob, tmp_path, seed):
    import open3d as o3d

    d, mesh = blob
    rng = np.random.default_rng(100 + seed)
    truth = similarity(10 ** rng.uniform(-2, 2), random_rotation(rng), rng.uniform(-50, 50, 3))
    recon = make_recon(mesh, truth, 30000, rng)
    write_cloud(tmp_path / "recon.ply", recon)
    # The same start for both: the truth off by 2° (random axis), 4 % in scale, 2 % of the
    # diagonal in translation — what a camera alignment of a mediocre reconstruction gives.
    diag = np.linalg.norm(np.ptp(np.asarray(mesh.vertices), 0))
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    wobble_r = o3d.geometry.get_rotation_matrix_from_axis_angle(axis * np.radians(2.0))
    wobble = similarity(1.04, wobble_r, 0.02 * diag * axis[[1, 2, 0]])
    start = wobble @ truth
    (tmp_path / "start.json").write_text(json.dumps({"matrix": start.tolist()}))
    ours = run_tool(align_tool, "icp", d / "blob.ply", tmp_path / "recon.ply", tmp_path / "start.json",
                    "--max-points", 30000)
    m_ours = np.array(ours["matrix"])

    target = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(sample_surface(mesh, 500000, rng)))
    source = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(recon))
    t0 = time.perf_counter()
    res = o3d.pipelines.registration.registration_icp(
        source, target, 0.05 * diag, start,
        o3d.pipelines.registration.TransformationEstimationPointToPoint(with_scaling=True),
        o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=100))
    o3d_secs = time.perf_counter() - t0
    m_o3d = np.asarray(res.transformation)

    # Closeness to the truth: RMS displacement of the clean samples, plus the pose errors.
    probe = apply(np.linalg.inv(truth), sample_surface(mesh, 5000, rng))
    dev = lambda m: float(np.sqrt(((apply(m, probe) - apply(truth, probe)) ** 2).sum(1).mean()))  # noqa: E731
    s_true = decompose(truth)[0]
    errs = {name: (dev(m), rot_err_deg(m, truth), abs(decompose(m)[0] / s_true - 1))
            for name, m in [("sfmeval", m_ours), ("open3d", m_o3d)]}
    print(errs, "sfmeval", ours["seconds"], "s; open3d", o3d_secs, "s")
    assert errs["sfmeval"][0] <= errs["open3d"][0], errs
    assert errs["sfmeval"][1] < 0.05 and errs["sfmeval"][2] < 0.002, errs


@pytest.mark.parametrize("seed", range(3))
def test_auto_global_on_blender_suzanne(align_tool, tmp_path, seed):
    """No cameras: global+icp must find the pose of Blender's Suzanne from a random rotation."""
    import open3d as o3d

    glb = ROOT / "tests" / "fixtures" / "core" / "blender_monkey.glb"
    mesh = o3d.io.read_triangle_mesh(str(glb))
    assert len(mesh.triangles) > 0
    # Open3D's glTF reader keeps the file's frame (Y-up); sfmeval reads the same file.
    rng = np.random.default_rng(200 + seed)
    truth = similarity(10 ** rng.uniform(-1, 1), random_rotation(rng), rng.uniform(-10, 10, 3))
    recon = make_recon(mesh, truth, 20000, rng, noise=0.003, outliers=0.1)
    write_cloud(tmp_path / "recon.ply", recon)
    out = run_tool(align_tool, "auto", glb, tmp_path / "recon.ply")
    m = np.array(out["matrix"])
    assert out["report"]["method"] == "global+icp"
    assert rot_err_deg(m, truth) < 0.1, out["report"]
    assert abs(decompose(m)[0] / decompose(truth)[0] - 1) < 0.002


def test_same_result_for_any_thread_count(align_tool, blob, tmp_path):
    """cameras+icp and global+icp give bit-identical transforms with 1 and 2 threads."""
    d, mesh = blob
    rng = np.random.default_rng(300)
    truth = similarity(2.0, random_rotation(rng), [1.0, 2.0, 3.0])
    write_cloud(tmp_path / "recon.ply", make_recon(mesh, truth, 20000, rng))
    v = np.asarray(mesh.vertices)
    a = np.linspace(0, 2 * np.pi, 20, endpoint=False)
    gt_c = np.stack([4 * np.cos(a), np.sin(2 * a), 4 * np.sin(a)], -1)
    rec_c = apply(np.linalg.inv(truth), gt_c)
    (tmp_path / "cams.json").write_text(json.dumps({"pairs": [{"recon": list(x), "gt": list(y)} for x, y in zip(rec_c, gt_c)]}))
    for extra in [("--cameras", tmp_path / "cams.json"), ()]:
        outs = []
        for threads in ["1", "2"]:
            p = subprocess.run([align_tool, "auto", d / "blob.ply", tmp_path / "recon.ply", *extra], capture_output=True,
                               text=True, env={**os.environ, "RAYON_NUM_THREADS": threads})
            assert p.returncode == 0, p.stderr
            outs.append(json.loads(p.stdout))
        assert outs[0]["matrix"] == outs[1]["matrix"]
        assert outs[0]["report"] == outs[1]["report"]
    assert len(v) > 0


def test_bad_input_is_a_clear_error(align_tool, tmp_path):
    f = tmp_path / "pairs.json"
    f.write_text(json.dumps({"pairs": [{"recon": [0, 0, 0], "gt": [1, 1, 1]}, {"recon": [1, 0, 0], "gt": [2, 1, 1]}]}))
    p = run_tool(align_tool, "umeyama", f, expect_ok=False)
    assert p.returncode == 2 and "at least 3" in p.stderr
    f.write_text(json.dumps({"pairs": [{"recon": [i, 0, 0], "gt": [0, i, 0]} for i in range(5)]}))
    p = run_tool(align_tool, "umeyama", f, expect_ok=False)
    assert p.returncode == 2 and "collinear" in p.stderr
    f.write_text('{"pairs": [{"recon": [NaN, 0, 0], "gt": [0, 0, 0]}]}')
    p = run_tool(align_tool, "umeyama", f, expect_ok=False)
    assert p.returncode == 2 and "point pairs" in p.stderr


# ---------------------------------------------------------------- timing

def bench():
    import tempfile

    import open3d as o3d

    tool = tool_path()
    d = Path(tempfile.mkdtemp())
    v, f = blob_mesh(708, 708)
    mesh = write_mesh(d / "gt.ply", v, f)
    print(f"mesh: {len(f)} triangles")
    rng = np.random.default_rng(7)
    truth = similarity(0.37, random_rotation(rng), [3.0, -1.0, 2.0])
    recon = make_recon(mesh, truth, 100_000, rng)
    write_cloud(d / "recon.ply", recon)
    lo, hi = v.min(0), v.max(0)
    c, r = (lo + hi) / 2, 1.5 * np.linalg.norm(hi - lo)
    a = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    gt_c = np.stack([c[0] + r * np.cos(a), c[1] + 0.3 * r * np.sin(2 * a), c[2] + r * np.sin(a)], -1)
    rec_c = apply(np.linalg.inv(truth), gt_c + rng.normal(scale=0.005 * r, size=gt_c.shape))
    (d / "cams.json").write_text(json.dumps({"pairs": [{"recon": list(x), "gt": list(y)} for x, y in zip(rec_c, gt_c)]}))
    out = run_tool(tool, "auto", d / "gt.ply", d / "recon.ply", "--cameras", d / "cams.json")
    m = np.array(out["matrix"])
    print(f"sfmeval cameras+icp: {out['seconds']:.3f} s (BVH + samples {out['prepare_seconds']:.3f} s), "
          f"rotation error {rot_err_deg(m, truth):.4f}°, scale error {100 * abs(decompose(m)[0] / 0.37 - 1):.4f} %, "
          f"iterations {[s['iterations'] for s in out['report']['stages']]}")
    start = np.array(out["report"]["stages"][0]["gt_from_recon"])
    target = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(sample_surface(mesh, 1_000_000, rng)))
    source = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(recon))
    diag = np.linalg.norm(hi - lo)
    t0 = time.perf_counter()
    res = o3d.pipelines.registration.registration_icp(
        source, target, 0.05 * diag, start,
        o3d.pipelines.registration.TransformationEstimationPointToPoint(with_scaling=True),
        o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=100))
    secs = time.perf_counter() - t0
    m = np.asarray(res.transformation)
    print(f"open3d scaled ICP (100k points → 1M samples, from the same camera start): {secs:.3f} s "
          f"(+ KD-tree inside), rotation error {rot_err_deg(m, truth):.4f}°, "
          f"scale error {100 * abs(decompose(m)[0] / 0.37 - 1):.4f} %")
    out = run_tool(tool, "auto", d / "gt.ply", d / "recon.ply")
    m = np.array(out["matrix"])
    print(f"sfmeval global+icp (no cameras): {out['seconds']:.3f} s, rotation error {rot_err_deg(m, truth):.4f}°, "
          f"scale error {100 * abs(decompose(m)[0] / 0.37 - 1):.4f} %")


if __name__ == "__main__":
    if "--bench" in sys.argv:
        bench()
