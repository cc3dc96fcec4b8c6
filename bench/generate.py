#!/usr/bin/env python3
"""Reproducible benchmark workloads (numpy only, seeded).

Writes into OUT (default bench/data):
  mesh_1m.ply / mesh_1m.glb     closed, non-symmetric bumpy sphere, ~1M triangles (binary PLY, GLB)
  mesh_50k.ply / mesh_50k.glb   the same shape, ~50k triangles
  cloud_{10k,100k,1m}.ply       points sampled area-uniformly on mesh_1m, 0.5 % (of the bbox
                                diagonal) Gaussian noise, 5 % uniform outliers in the bbox
  cloud_{...}_moved.ply         the same clouds moved by a known similarity (recon frame)
  gt_from_recon.txt             that similarity's inverse mapping moved clouds back (row-major 4x4)
  cloud_{10m,100m}.ply          with --dense 10m[,100m]: dense clouds of the same kind on mesh_1m
                                (not moved), written in chunks of 5M points (1.2 GB for 100m)
  mesh_tube_1m.ply, cloud_tube_1m.ply
                                with --smooth: the smooth, low-outlier workload: a closed tube
                                (a torus with a wavy cross-section, 1M triangles) and 1M points
                                sampled on it, each moved along a random direction by Gaussian
                                noise of 0.15 % of the bbox diagonal clipped at 0.5 %: no point
                                farther than 0.5 % of the diagonal from the surface, no outliers
  mesh_height_10m.ply, cloud_height_1m.ply
                                with --big-mesh: a height field on a 2237 x 2237 vertex grid
                                (5.0M vertices, 9,999,392 triangles, binary PLY of 190 MB) and
                                1M points sampled on it with Gaussian noise of 0.2 % of the
                                bbox diagonal (bench/big_mesh.py)
Usage: bench/generate.py [--out DIR] [--quick] [--dense 10m,100m] [--smooth] [--big-mesh]
       (--quick: 50k mesh and 10k/100k clouds only; --dense, --smooth, --big-mesh: only those files)
"""
import argparse
import json
import struct
from pathlib import Path

import numpy as np


def bumpy_sphere(n_lat, n_lon):
    theta = np.linspace(0, np.pi, n_lat + 1)[1:-1]          # rings without the poles
    phi = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    dirs = np.stack([np.sin(th) * np.cos(ph), np.cos(th), np.sin(th) * np.sin(ph)], -1).reshape(-1, 3)
    dirs = np.vstack([[0, 1, 0], dirs, [0, -1, 0]])
    x, y, z = dirs.T
    r = 1 + 0.18 * np.sin(3 * x + 0.5) * np.cos(2 * y) + 0.1 * z ** 3 + 0.04 * np.sin(9 * y + 2 * x)
    v = dirs * r[:, None] * np.array([1.0, 0.8, 0.65])
    rings = n_lat - 1
    idx = lambda i, j: 1 + i * n_lon + (j % n_lon)
    faces = []
    j = np.arange(n_lon)
    faces.append(np.stack([np.zeros(n_lon, int), idx(0, j + 1), idx(0, j)], -1))  # top cap
    for i in range(rings - 1):
        a, b, c, d = idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1)
        faces.append(np.stack([a, b, d], -1))
        faces.append(np.stack([a, d, c], -1))
    last = len(v) - 1
    faces.append(np.stack([np.full(n_lon, last), idx(rings - 1, j), idx(rings - 1, j + 1)], -1))
    return v, np.vstack(faces).astype(np.uint32)


def sample(v, f, n, rng):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    tri = rng.choice(len(f), size=n, p=area / area.sum())
    u, w = rng.random(n), rng.random(n)
    su = np.sqrt(u)
    return (1 - su)[:, None] * a[tri] + (su * (1 - w))[:, None] * b[tri] + (su * w)[:, None] * c[tri]


def write_ply(path, v, f=None):
    head = f"ply\nformat binary_little_endian 1.0\ncomment sfmeval bench/generate.py\nelement vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\n"
    if f is not None:
        head += f"element face {len(f)}\nproperty list uchar uint vertex_indices\n"
    head += "end_header\n"
    with open(path, "wb") as fh:
        fh.write(head.encode())
        fh.write(np.asarray(v, dtype="<f4").tobytes())
        if f is not None:
            rec = np.empty(len(f), dtype=[("n", "u1"), ("i", "<u4", 3)])
            rec["n"] = 3
            rec["i"] = f
            fh.write(rec.tobytes())


def write_glb(path, v, f):
    pos = np.asarray(v, dtype="<f4").tobytes()
    ind = np.asarray(f, dtype="<u4").tobytes()
    binary = pos + ind
    gltf = {
        "asset": {"version": "2.0", "generator": "sfmeval bench/generate.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(v), "type": "VEC3",
             "min": np.asarray(v, "<f4").min(0).tolist(), "max": np.asarray(v, "<f4").max(0).tolist()},
            {"bufferView": 1, "componentType": 5125, "count": f.size, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(ind)}],
        "buffers": [{"byteLength": len(binary)}],
    }
    js = json.dumps(gltf).encode()
    js += b" " * (-len(js) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(js) + 8 + len(binary)
    with open(path, "wb") as fh:
        fh.write(struct.pack("<III", 0x46546C67, 2, total))
        fh.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        fh.write(struct.pack("<II", len(binary), 0x004E4942) + binary)


DENSE = {"10m": 10_000_000, "100m": 100_000_000}
CHUNK = 5_000_000


def write_dense(out, name, n):
    """cloud_{name}.ply: n points like cloud_1m (0.5 % noise, 5 % outliers, shuffled within each
    chunk), drawn and written CHUNK points at a time so that memory stays bounded."""
    v, f = bumpy_sphere(500, 1000)
    v = np.asarray(v, "<f4").astype(np.float64)
    lo, hi = v.min(0), v.max(0)
    diag = np.linalg.norm(hi - lo)
    rng = np.random.default_rng([20261125, n])
    path = out / f"cloud_{name}.ply"
    with open(path, "wb") as fh:
        fh.write((f"ply\nformat binary_little_endian 1.0\ncomment sfmeval bench/generate.py\nelement vertex {n}\n"
                  "property float x\nproperty float y\nproperty float z\nend_header\n").encode())
        for start in range(0, n, CHUNK):
            m = min(CHUNK, n - start)
            m_out = int(0.05 * m)
            pts = sample(v, f, m - m_out, rng) + rng.normal(scale=0.005 * diag, size=(m - m_out, 3))
            pts = np.vstack([pts, rng.uniform(lo, hi, size=(m_out, 3))])
            rng.shuffle(pts)
            fh.write(np.asarray(pts, dtype="<f4").tobytes())
    print(f"cloud_{name}: {n} points")


def tube(n_around, n_across):
    """A closed tube: a torus (radii 1 and 0.3) whose cross-section's radius waves along it;
    2 · n_around · n_across triangles, every vertex shared (no seam)."""
    u = np.linspace(0, 2 * np.pi, n_around, endpoint=False)
    w = np.linspace(0, 2 * np.pi, n_across, endpoint=False)
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = 0.3 * (1 + 0.15 * np.sin(5 * uu) + 0.05 * np.cos(3 * ww + uu))
    v = np.stack([(1 + r * np.cos(ww)) * np.cos(uu), (1 + r * np.cos(ww)) * np.sin(uu), r * np.sin(ww)],
                 -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n_around), np.arange(n_across), indexing="ij")
    a = i * n_across + j
    b = ((i + 1) % n_around) * n_across + j
    c = ((i + 1) % n_around) * n_across + (j + 1) % n_across
    d = i * n_across + (j + 1) % n_across
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return v, f.astype(np.uint32)


def write_smooth(out):
    """mesh_tube_1m.ply and cloud_tube_1m.ply (see the module's docs)."""
    v, f = tube(1000, 500)
    write_ply(out / "mesh_tube_1m.ply", v, f)
    v = np.asarray(v, "<f4").astype(np.float64)
    diag = np.linalg.norm(v.max(0) - v.min(0))
    rng = np.random.default_rng([20261205, 1])
    n = 1_000_000
    pts = sample(v, f, n, rng)
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    offset = np.clip(rng.normal(scale=0.0015 * diag, size=n), -0.005 * diag, 0.005 * diag)
    write_ply(out / "cloud_tube_1m.ply", pts + direction * offset[:, None])
    print(f"mesh_tube_1m: {len(v)} vertices, {len(f)} triangles; cloud_tube_1m: {n} points within "
          f"{0.005 * diag:.4g} (0.5 % of the diagonal {diag:.4g})")


def height(x, y):
    return 0.08 * np.sin(7 * x + 1.0) * np.cos(5 * y) + 0.03 * np.sin(23 * x * y + 0.5) + 0.05 * x * y


def write_big_mesh(out, side=2237, n=1_000_000):
    """mesh_height_10m.ply: a height field over [-1, 1]^2 on a side x side grid (two triangles a
    cell), and cloud_height_1m.ply: n points on it, uniform in x, y, with Gaussian noise."""
    rng = np.random.default_rng(20261206)
    t = np.linspace(-1.0, 1.0, side)
    x, y = np.meshgrid(t, t, indexing="ij")
    v = np.stack([x.ravel(), y.ravel(), height(x, y).ravel()], -1)
    i, j = np.meshgrid(np.arange(side - 1), np.arange(side - 1), indexing="ij")
    a = (i * side + j).ravel()
    b, c, d = a + side, a + 1, a + side + 1
    f = np.empty((2 * len(a), 3), np.uint32)
    f[0::2] = np.stack([a, b, d], -1)
    f[1::2] = np.stack([a, d, c], -1)
    del i, j, a, b, c, d
    write_ply(out / "mesh_height_10m.ply", v, f)
    lo, hi = v.min(0), v.max(0)
    diag = float(np.linalg.norm(hi - lo))
    del v, f
    px, py = rng.uniform(-1.0, 1.0, n), rng.uniform(-1.0, 1.0, n)
    pts = np.stack([px, py, height(px, py)], -1) + rng.normal(scale=0.002 * diag, size=(n, 3))
    write_ply(out / "cloud_height_1m.ply", pts)
    print(f"mesh_height_10m: {side * side} vertices, {2 * (side - 1) ** 2} triangles; "
          f"cloud_height_1m: {n} points, noise {0.002 * diag:.4g}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "data"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--dense", default="", help="only write these dense clouds: 10m, 100m (comma-separated)")
    ap.add_argument("--smooth", action="store_true", help="only write the smooth tube workload")
    ap.add_argument("--big-mesh", action="store_true", help="only write the 10M-triangle height-field workload")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.big_mesh:
        write_big_mesh(out)
        return
    if args.smooth:
        write_smooth(out)
        return
    if args.dense:
        for name in args.dense.split(","):
            write_dense(out, name, DENSE[name])
        return
    rng = np.random.default_rng(20261125)
    meshes = {"50k": (112, 224)} if args.quick else {"50k": (112, 224), "1m": (500, 1000)}
    for name, (nl, nn) in meshes.items():
        v, f = bumpy_sphere(nl, nn)
        write_ply(out / f"mesh_{name}.ply", v, f)
        write_glb(out / f"mesh_{name}.glb", v, f)
        print(f"mesh_{name}: {len(v)} vertices, {len(f)} triangles")
    ref = "1m" if "1m" in meshes else "50k"
    v, f = bumpy_sphere(*meshes[ref])
    v = np.asarray(v, "<f4").astype(np.float64)
    lo, hi = v.min(0), v.max(0)
    diag = np.linalg.norm(hi - lo)
    # Known similarity: recon = inverse(gt_from_recon)(gt)
    angle, axis = 0.9, np.array([0.2, -0.7, 0.4])
    axis /= np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    s, t = 3.7, np.array([0.5, -2.0, 1.25])
    T = np.eye(4)
    T[:3, :3] = s * R
    T[:3, 3] = t
    np.savetxt(out / "gt_from_recon.txt", T, fmt="%.17g", header="gt_from_recon: maps cloud_*_moved.ply onto the mesh")
    sizes = {"10k": 10_000, "100k": 100_000} if args.quick else {"10k": 10_000, "100k": 100_000, "1m": 1_000_000}
    for name, n in sizes.items():
        n_out = int(0.05 * n)
        pts = sample(v, f, n - n_out, rng) + rng.normal(scale=0.005 * diag, size=(n - n_out, 3))
        pts = np.vstack([pts, rng.uniform(lo, hi, size=(n_out, 3))])
        rng.shuffle(pts)
        write_ply(out / f"cloud_{name}.ply", pts)
        write_ply(out / f"cloud_{name}_moved.ply", (pts - t) @ R / s)
        print(f"cloud_{name}: {n} points ({n_out} outliers)")


if __name__ == "__main__":
    main()
