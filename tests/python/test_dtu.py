"""`sfmeval dtu` against the DTU evaluation's Python port (DTUeval-python's eval.py, vendored in
tests/reference/dtueval_python/ and run unchanged by dtu_port.py with its shuffle kept in the
input's order) on a small scan in DTU's layout made from the demo dataset, in mm (dtu_scene.py):
a real sparse SfM cloud, a dense noisy cloud with a hole and outliers (the down-sampling and the
box matter), and a mesh the evaluator samples.

Mean accuracy, mean completeness and overall must agree to 1e-6 relative, and the coloured
error clouds (vis_001_d2s.ply, vis_001_s2d.ply) byte for byte after their headers.
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import pytest

import dtu_scene

HERE = Path(__file__).resolve().parent
PORT = HERE / "dtu_port.py"
PYTHON = os.environ.get("SFMEVAL_PYTHON", sys.executable)
SCHEMA = json.loads((HERE.parents[1] / "schemas" / "dtu.schema.json").read_text())


@pytest.fixture(scope="module")
def scene(tmp_path_factory, sfmeval_bin):
    return dtu_scene.build(tmp_path_factory.mktemp("dtu"), sfmeval_bin)


def run_port(scene, recon, mode, vis_dir):
    vis_dir.mkdir(parents=True, exist_ok=True)
    p = subprocess.run([PYTHON, str(PORT), "--data", str(recon), "--scan", str(scene["scan"]),
                        "--mode", mode, "--dataset_dir", str(scene["dataset"]),
                        "--vis_out_dir", str(vis_dir)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr[-3000:]
    return [float(v) for v in p.stdout.strip().splitlines()[-1].split()]


def run_sfmeval(sfmeval_bin, scene, recon, mode, vis_dir, *extra):
    p = subprocess.run([sfmeval_bin, "dtu", "--dataset", str(scene["dataset"]),
                        "--scan", str(scene["scan"]), "--recon", str(recon), "--mode", mode,
                        "--vis-out", str(vis_dir), "--json", *extra],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    rep = json.loads(p.stdout)
    jsonschema.validate(rep, SCHEMA)
    return rep


def body(path):
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    return data[:end], data[end:]


@pytest.mark.parametrize("case, mode", [("sparse", "pcd"), ("dense", "pcd"), ("mesh", "mesh")])
def test_equals_the_python_port(sfmeval_bin, scene, tmp_path, case, mode):
    port = run_port(scene, scene[case], mode, tmp_path / "port")
    rep = run_sfmeval(sfmeval_bin, scene, scene[case], mode, tmp_path / "ours", "--no-shuffle")
    ours = [rep["mean_accuracy"], rep["mean_completeness"], rep["overall"]]
    assert ours == pytest.approx(port, rel=1e-6, abs=0), (case, ours, port)
    c = rep["counts"]
    # The scene is built so that every filter has work to do.
    assert c["downsampled"] <= c["points"]
    assert c["observed"] < c["in_bounding_box"]
    assert c["stl_above_plane"] < c["stl_points"]
    if case == "dense":
        assert c["in_bounding_box"] < c["downsampled"]
        assert c["accuracy_below_max_dist"] < c["observed"]
        assert c["downsampled"] < 0.9 * c["points"]
    for name in ("vis_001_d2s.ply", "vis_001_s2d.ply"):
        head_port, body_port = body(tmp_path / "port" / name)
        head_ours, body_ours = body(tmp_path / "ours" / name)
        assert head_ours == head_port.replace(b"Open3D", b"sfmeval"), name
        assert body_ours == body_port, name
    # All four colours appear in the d2s cloud of the dense case.
    if case == "dense":
        _, d2s = body(tmp_path / "ours" / "vis_001_d2s.ply")
        rgb = np.frombuffer(d2s, dtype=[("p", "<f8", 3), ("c", "u1", 3)])["c"]
        assert {(0, 0, 255), (0, 255, 0), (255, 0, 0), (255, 255, 255)} <= set(map(tuple, rgb.tolist()))


def test_the_shuffle_is_seeded_and_changes_little(sfmeval_bin, scene, tmp_path):
    """The evaluator shuffles at random: a seed gives the same numbers every run, another seed
    numbers within the port's own run-to-run spread (its README: about 0.01 %)."""
    a = run_sfmeval(sfmeval_bin, scene, scene["mesh"], "mesh", tmp_path / "a", "--seed", "1")
    b = run_sfmeval(sfmeval_bin, scene, scene["mesh"], "mesh", tmp_path / "b", "--seed", "1")
    c = run_sfmeval(sfmeval_bin, scene, scene["mesh"], "mesh", tmp_path / "c", "--seed", "2")
    assert a == b
    assert a["counts"]["downsampled"] != c["counts"]["downsampled"]
    assert c["overall"] == pytest.approx(a["overall"], rel=2e-3)


def test_missing_and_wrong_files_are_named(sfmeval_bin, scene, tmp_path):
    p = subprocess.run([sfmeval_bin, "dtu", "--dataset", str(scene["dataset"]), "--scan", "2",
                        "--recon", str(scene["sparse"])], capture_output=True, text=True)
    assert p.returncode == 1 and "stl002_total.ply" in p.stderr, p.stderr
    far = tmp_path / "far.ply"
    dtu_scene.write_ply(far, np.full((10, 3), 1e4))
    p = subprocess.run([sfmeval_bin, "dtu", "--dataset", str(scene["dataset"]), "--scan", "1",
                        "--recon", str(far)], capture_output=True, text=True)
    assert p.returncode == 1 and "far.ply" in p.stderr and "bounding box" in p.stderr, p.stderr


def write_colmap_text(folder, points):
    """A COLMAP text model holding only these 3D points (no camera), repr() doubles."""
    folder.mkdir(parents=True)
    (folder / "cameras.txt").write_text("# Camera list\n")
    (folder / "images.txt").write_text("# Image list\n")
    (folder / "points3D.txt").write_text("".join(
        f"{i + 1} {float(x)!r} {float(y)!r} {float(z)!r} 200 200 200 0.5\n" for i, (x, y, z) in enumerate(points)))
    return folder


def write_nvm(path, points):
    """An NVM_V3 file holding one camera and these points (no measurements)."""
    lines = ["NVM_V3", "", "1", "a.jpg 100 1 0 0 0 0 0 0 0 0", "", str(len(points))]
    lines += [f"{float(x)!r} {float(y)!r} {float(z)!r} 200 200 200 0" for x, y, z in points]
    path.write_text("\n".join(lines) + "\n\n0\n")
    return path


def write_obj(path, vertices, faces):
    path.write_text("".join(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in vertices)
                    + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces))
    return path


def ply_arrays(path):
    """x y z (double) and the faces of a PLY dtu_scene.write_ply wrote."""
    head, data = body(path)
    text = head.decode()
    n = int(text.split("element vertex ")[1].split()[0])
    points = np.frombuffer(data[:n * 24], dtype="<f8").reshape(n, 3)
    faces = None
    if "element face" in text:
        rec = np.frombuffer(data[n * 24:], dtype=[("n", "u1"), ("v", "<i4", (3,))])
        faces = rec["v"]
    return points, faces


@pytest.mark.parametrize("kind", ["colmap", "nvm", "obj", "glb"])
def test_any_reconstruction_equals_the_port_on_the_ply_of_its_points(sfmeval_bin, scene,
                                                                      tmp_path, kind):
    """`sfmeval dtu` reads SfM models and meshes as `sfmeval eval` does; each gives the port's
    numbers (and error clouds) on the PLY of the same points: an SfM model's 3D points (the
    dense case, as COLMAP text and NVM), a mesh sampled as the evaluator samples it (OBJ, and
    glTF whose float32 vertices the PLY then holds)."""
    if kind in ("colmap", "nvm"):
        points, _ = ply_arrays(scene["dense"])
        recon = (write_colmap_text(tmp_path / "model", points) if kind == "colmap"
                 else write_nvm(tmp_path / "model.nvm", points))
        ply, mode = scene["dense"], "pcd"
    elif kind == "obj":
        vertices, faces = ply_arrays(scene["mesh"])
        recon = write_obj(tmp_path / "mesh.obj", vertices, faces)
        ply, mode = scene["mesh"], "mesh"
    else:
        import trimesh
        vertices, faces = ply_arrays(scene["mesh"])
        vertices = vertices.astype(np.float32).astype(np.float64)
        recon = tmp_path / "mesh.glb"
        recon.write_bytes(trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
                          .export(file_type="glb"))
        ply = tmp_path / "mesh32.ply"
        dtu_scene.write_ply(ply, vertices, faces=faces)
        mode = "mesh"
    port = run_port(scene, ply, mode, tmp_path / "port")
    # auto: a mesh when the file has faces, a model's points otherwise
    rep = run_sfmeval(sfmeval_bin, scene, recon, "auto", tmp_path / "ours", "--no-shuffle")
    assert rep["mode"] == mode and rep["reconstruction"] == str(recon)
    ours = [rep["mean_accuracy"], rep["mean_completeness"], rep["overall"]]
    assert ours == pytest.approx(port, rel=1e-6, abs=0), (kind, ours, port)
    for name in ("vis_001_d2s.ply", "vis_001_s2d.ply"):
        assert body(tmp_path / "ours" / name)[1] == body(tmp_path / "port" / name)[1], name
    # the same report as the PLY's, but for the name
    of_ply = run_sfmeval(sfmeval_bin, scene, ply, mode, tmp_path / "ply", "--no-shuffle")
    assert {**rep, "reconstruction": of_ply["reconstruction"]} == of_ply


def test_a_model_without_points_and_mesh_mode_without_faces_are_named(sfmeval_bin, scene,
                                                                       tmp_path):
    model = write_colmap_text(tmp_path / "empty", np.zeros((0, 3)))
    (model / "images.txt").write_text(
        "1 1 0 0 0 0 0 0 1 a.jpg\n\n")
    (model / "cameras.txt").write_text("1 SIMPLE_PINHOLE 100 100 50 50 50\n")
    p = subprocess.run([sfmeval_bin, "dtu", "--dataset", str(scene["dataset"]), "--scan", "1",
                        "--recon", str(model)], capture_output=True, text=True)
    assert p.returncode == 1 and str(model) in p.stderr, p.stderr
    p = subprocess.run([sfmeval_bin, "dtu", "--dataset", str(scene["dataset"]), "--scan", "1",
                        "--recon", str(scene["sparse"]), "--mode", "mesh"],
                       capture_output=True, text=True)
    assert p.returncode == 1 and "no faces" in p.stderr and "sparse.ply" in p.stderr, p.stderr
