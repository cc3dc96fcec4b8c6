"""A small scan in DTU's layout, made from the demo dataset (data/demo/), in millimetres.

The demo's statue (ground_truth.glb, 1 m tall) becomes a 100 mm figurine: coordinates × 100,
read as millimetres. Under `root`:

- Points/stl/stl001_total.ply: 200,000 points sampled on the statue's surface (seeded), binary
  float32 as DTU's STL files are;
- ObsMask/ObsMask1_10.mat: ObsMask (3-D logical over 2 mm cells: the
  whole box observed but the cells on the +x side of x = 20 mm), BB (the STL points'
  box widened by 4.3 mm, not float32-exact, so the port's float32 cast matters) and Res (2 mm);
- ObsMask/Plane1.mat: P, a slightly tilted plane 15 mm above the statue's foot (STL points below
  it are left out of completeness; none lies within 1e-6 mm of it).

and the reconstructions:

- sparse.ply: the demo's real COLMAP points, brought into the ground truth's frame by
  `sfmeval align --align cameras` and scaled to mm (float64);
- dense.ply: 300,000 surface samples with 0.15 mm noise, a hole (nothing within 12 mm of a point
  on the statue), 500 outliers in the box, 3,000 in the widened box and 500 beyond it, shuffled (seeded), float64;
- mesh.ply: the statue's mesh with its vertices moved by 0.1 mm noise (float64 vertices).

Everything is seeded: the scene is the same on every run.
"""
import json
import subprocess
from pathlib import Path

import numpy as np
import trimesh
from scipy.io import savemat

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "data" / "demo"
SCAN = 1
SCALE = 100.0


def write_ply(path, points, faces=None, double=True):
    points = np.asarray(points)
    ty, dt = ("double", "<f8") if double else ("float", "<f4")
    head = ["ply", "format binary_little_endian 1.0", f"element vertex {len(points)}",
            f"property {ty} x", f"property {ty} y", f"property {ty} z"]
    if faces is not None:
        head += [f"element face {len(faces)}", "property list uchar int vertex_indices"]
    head.append("end_header")
    body = np.ascontiguousarray(points, dtype=dt).tobytes()
    if faces is not None:
        rec = np.zeros(len(faces), dtype=[("n", "u1"), ("v", "<i4", (3,))])
        rec["n"] = 3
        rec["v"] = faces
        body += rec.tobytes()
    Path(path).write_bytes(("\n".join(head) + "\n").encode() + body)


def statue_mm():
    mesh = trimesh.load(DEMO / "ground_truth.glb", force="mesh")
    return trimesh.Trimesh(vertices=np.asarray(mesh.vertices) * SCALE, faces=mesh.faces,
                           process=False)


def sparse_points_mm(sfmeval_bin, work):
    """The demo's COLMAP points in the ground truth's frame (sfmeval align, cameras), in mm."""
    t = work / "gt_from_recon.txt"
    subprocess.run([sfmeval_bin, "align", "--dataset", str(DEMO), "--recon", str(DEMO / "sparse"),
                    "--align", "cameras", "--out", str(t)], check=True, capture_output=True)
    lines = [ln for ln in t.read_text().splitlines() if not ln.startswith("#")]
    m = np.array([float(v) for ln in lines for v in ln.split()]).reshape(4, 4)
    import open3d as o3d
    p = np.asarray(o3d.io.read_point_cloud(str(DEMO / "sparse.ply")).points)
    return (p @ m[:3, :3].T + m[:3, 3]) * SCALE


def build(root: Path, sfmeval_bin: str, stl_points=200_000, dense_points=300_000) -> dict:
    """Writes the scan and the reconstructions under `root`; returns their paths (the bench
    asks for other point counts)."""
    mesh = statue_mm()
    (root / "Points" / "stl").mkdir(parents=True, exist_ok=True)
    (root / "ObsMask").mkdir(parents=True, exist_ok=True)
    stl, _ = trimesh.sample.sample_surface(mesh, stl_points, seed=1)
    stl = stl.astype(np.float32).astype(np.float64)
    write_ply(root / "Points" / "stl" / f"stl{SCAN:03}_total.ply", stl, double=False)

    res = 2.0
    bb = np.stack([stl.min(0) - 4.3, stl.max(0) + 4.3])
    dims = np.ceil((bb[1] - bb[0]) / res).astype(int) + 1
    mask = np.ones(dims, dtype=bool)
    xs = bb[0][0] + res * np.arange(dims[0])
    mask[xs > 20.0] = False
    savemat(root / "ObsMask" / f"ObsMask{SCAN}_10.mat",
            {"ObsMask": mask, "BB": bb, "Res": np.array([[res]])}, do_compression=True)

    normal = np.array([0.03, 1.0, -0.02])
    foot = stl[:, 1].min()
    p = np.append(normal, -(foot + 15.0))
    side = stl @ p[:3] + p[3]
    assert np.abs(side).min() > 1e-6 and (side > 0).sum() > stl_points // 2
    savemat(root / "ObsMask" / f"Plane{SCAN}.mat", {"P": p.reshape(4, 1)}, do_compression=True)

    out = {"dataset": root, "scan": SCAN}
    out["sparse"] = root / "sparse.ply"
    write_ply(out["sparse"], sparse_points_mm(sfmeval_bin, root))

    rng = np.random.default_rng(7)
    dense, _ = trimesh.sample.sample_surface(mesh, dense_points, seed=2)
    dense = dense + rng.normal(0, 0.15, dense.shape)
    centre = dense[12345 % len(dense)]
    dense = dense[np.linalg.norm(dense - centre, axis=1) > 12.0]
    lo, hi = bb[0] - 60, bb[1] + 120
    inside = np.concatenate([rng.uniform(bb[0], bb[1], (500, 3)), rng.uniform(lo, hi, (3000, 3))])
    beyond = rng.uniform(hi + 1, hi + 50, (500, 3))
    dense = np.concatenate([dense, inside, beyond])
    rng.shuffle(dense, axis=0)
    out["dense"] = root / "dense.ply"
    write_ply(out["dense"], dense)

    moved = mesh.vertices + rng.normal(0, 0.1, mesh.vertices.shape)
    out["mesh"] = root / "mesh.ply"
    write_ply(out["mesh"], moved, faces=mesh.faces)
    (root / "scene.json").write_text(json.dumps({k: str(v) for k, v in out.items()}))
    return out
