"""Interim demo pair: a bumpy, non-symmetric blob (trimesh, GLB) and a noisy cloud sampled on it,
moved by a known similarity. Replaced by a rendered dataset + real SfM output when available.

Run: .venv/bin/python data/demo/make_synthetic_demo.py data/demo
"""
import sys
import numpy as np
import trimesh

out = sys.argv[1]
rng = np.random.default_rng(42)
m = trimesh.creation.icosphere(subdivisions=5, radius=1.0)
v = m.vertices
bump = 1 + 0.15 * np.sin(3 * v[:, 0] + 1) * np.cos(2 * v[:, 1]) + 0.1 * v[:, 2] ** 3 + 0.05 * np.sin(7 * v[:, 1])
m.vertices = v * bump[:, None] * np.array([1.0, 0.7, 0.5])
m.export(f"{out}/ground_truth.glb")
pts, _ = trimesh.sample.sample_surface(m, 4000, seed=1)
pts = pts + rng.normal(scale=0.004, size=pts.shape)
outliers = rng.uniform(-1.3, 1.3, size=(80, 3))
pts = np.vstack([pts, outliers])
# recon = inverse(gt_from_recon)(pts); gt_from_recon: scale 2.5, rotation about an axis, translation
angle = 0.7
axis = np.array([0.3, 0.8, -0.5]); axis /= np.linalg.norm(axis)
R = trimesh.transformations.rotation_matrix(angle, axis)[:3, :3]
s, t = 2.5, np.array([0.4, -1.0, 2.0])
recon = ((pts - t) @ R) / s  # R^T (p - t) / s
T = np.eye(4); T[:3, :3] = s * R; T[:3, 3] = t
np.savetxt(f"{out}/gt_from_recon.txt", T, fmt="%.17g", header="gt_from_recon (row-major 4x4)")
cloud = trimesh.PointCloud(recon, colors=np.tile([200, 180, 160, 255], (len(recon), 1)))
cloud.export(f"{out}/sparse.ply", encoding="binary")
