"""A small scene in ETH3D's layout, made from the demo dataset (data/demo/), in metres.

The demo's statue (ground_truth.glb, 1 m tall) is the scanned object. Under `root`:

- dslr_scan_eval/scan_alignment.mlp: a MeshLab project posing two scans (as ETH3D ships
  them: `<MLMesh label filename>` with its `<MLMatrix44>`, global_from_scan, row-major);
- dslr_scan_eval/scan1.ply, scan2.ply: the statue's surface sampled (seeded), split between two
  scanners 2.5 m from it (rotated about z and tilted), each scan in its own frame (the scanner at
  the origin), binary float32 as ETH3D's scans are;

and the reconstructions (global frame):

- sparse.ply: the demo's real COLMAP points, brought into the ground truth's frame by
  `sfmeval align --align cameras` (float32: PCL 1.13, the tool's reader, reads a PLY of
  doubles as all zeros);
- dense.ply: surface samples with 3 mm noise, a hole (nothing within 0.12 m of a point on the
  statue), 400 outliers between the scanners and the statue (inaccurate: seen through), 400
  behind the statue (unobserved) and 200 in the whole box, shuffled (seeded), float32.

Everything is seeded: the scene is the same on every run.
"""
import json
from pathlib import Path

import numpy as np
import trimesh

from dtu_scene import DEMO, sparse_points_mm, write_ply

SCANNERS = [  # (position, yaw about z, tilt about x) of each scanner in the global frame
    (np.array([2.5, 0.3, 0.6]), 0.4, 0.05),
    (np.array([-1.2, 2.2, 0.9]), -2.1, -0.08),
]


def read_ply_f32(path):
    """The points of a binary float32 PLY written by write_ply."""
    data = Path(path).read_bytes()
    start = data.index(b"end_header\n") + len(b"end_header\n")
    n = int(data[:start].split(b"element vertex ")[1].split(b"\n")[0])
    return np.frombuffer(data[start:start + 12 * n], dtype="<f4").reshape(n, 3)


def rotation(yaw, tilt):
    cz, sz, cx, sx = np.cos(yaw), np.sin(yaw), np.cos(tilt), np.sin(tilt)
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    return rz @ rx


def mlp_text(scans):
    out = ["<!DOCTYPE MeshLabDocument>", "<MeshLabProject>", " <MeshGroup>"]
    for name, m in scans:
        rows = "\n".join(" ".join(repr(float(v)) for v in row) + " " for row in m)
        out += [f'  <MLMesh label="{name}" filename="{name}">',
                f"   <MLMatrix44>\n{rows}\n</MLMatrix44>", "  </MLMesh>"]
    out += [" </MeshGroup>", " <RasterGroup/>", "</MeshLabProject>", ""]
    return "\n".join(out)


def build(root: Path, sfmeval_bin: str, scan_points=120_000, dense_points=150_000) -> dict:
    """Writes the scene and the reconstructions under `root`; returns their paths."""
    mesh = trimesh.load(DEMO / "ground_truth.glb", force="mesh")
    gt_dir = root / "dslr_scan_eval"
    gt_dir.mkdir(parents=True, exist_ok=True)
    surface, _ = trimesh.sample.sample_surface(mesh, scan_points, seed=1)
    centre = surface.mean(0)
    scans = []
    # Each surface point goes to the nearer scanner's scan.
    d = np.stack([np.linalg.norm(surface - (centre + p - np.array([0, 0, 0.6])), axis=1)
                  for p, _, _ in SCANNERS])
    owner = d.argmin(0)
    for k, (pos, yaw, tilt) in enumerate(SCANNERS):
        r = rotation(yaw, tilt)
        t = centre + pos - np.array([0, 0, 0.6])
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = r, t
        m = m.astype(np.float32).astype(np.float64)
        local = (surface[owner == k] - m[:3, 3]) @ m[:3, :3]
        name = f"scan{k + 1}.ply"
        write_ply(gt_dir / name, local, double=False)
        scans.append((name, m))
    (gt_dir / "scan_alignment.mlp").write_text(mlp_text(scans))

    out = {"mlp": gt_dir / "scan_alignment.mlp"}
    out["sparse"] = root / "sparse.ply"
    # float32: PCL 1.13 (the tool's reader) reads a PLY of doubles as all zeros
    write_ply(out["sparse"], sparse_points_mm(sfmeval_bin, root) / 100.0, double=False)

    rng = np.random.default_rng(7)
    dense, _ = trimesh.sample.sample_surface(mesh, dense_points, seed=2)
    dense = dense + rng.normal(0, 0.003, dense.shape)
    dense = dense[np.linalg.norm(dense - dense[4321], axis=1) > 0.12]
    pick = surface[rng.integers(0, len(surface), 800)]
    scanner = np.array([centre + SCANNERS[0][0] - np.array([0, 0, 0.6])])
    along = rng.uniform(0.05, 0.6, (800, 1))
    front = pick[:400] + (scanner - pick[:400]) / np.linalg.norm(scanner - pick[:400], axis=1,
                                                                 keepdims=True) * along[:400]
    behind = pick[400:] - (scanner - pick[400:]) / np.linalg.norm(scanner - pick[400:], axis=1,
                                                                  keepdims=True) * along[400:]
    lo, hi = surface.min(0) - 0.3, surface.max(0) + 0.3
    dense = np.concatenate([dense, front, behind, rng.uniform(lo, hi, (200, 3))])
    rng.shuffle(dense, axis=0)
    out["dense"] = root / "dense.ply"
    write_ply(out["dense"], dense, double=False)
    (root / "scene.json").write_text(json.dumps({k: str(v) for k, v in out.items()}))
    return out


if __name__ == "__main__":
    import sys
    print(build(Path(sys.argv[1]), sys.argv[2]))
