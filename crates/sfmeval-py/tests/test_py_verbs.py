"""The package's geometry in memory and its other verbs against the CLI, run with the built
wheel installed (scripts/check-python-package.sh): arrays give the report of the PLY file of the
same numbers, and read / align / cameras / tnt / dtu / eth3d / table give what `sfmeval export`,
`align`, `cameras`, `tnt`, `dtu`, `eth3d` and `table` write, byte for byte.

SFMEVAL_BIN: the CLI (default target/release/sfmeval).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import sfmeval

ROOT = Path(__file__).resolve().parents[3]
BIN = Path(os.environ.get("SFMEVAL_BIN", ROOT / "target/release/sfmeval"))
DEMO = ROOT / "data/demo"
CORE = ROOT / "tests/fixtures/core"
MODELS = ROOT / "tests/fixtures/models"
TNT = ROOT / "tests/fixtures/tanksandtemples"
DTU = ROOT / "tests/fixtures/dtu"
ETH3D = ROOT / "tests/fixtures/eth3d"
ETH3D_MLP = ETH3D / "dslr_scan_eval/scan_alignment.mlp"
# the demo model's gt_from_recon by camera centres, to 12 digits
DEMO_START = [[0.24393526577, -0.299850123721, 0.298600929354, 0.00184377389897],
              [-0.000514897229959, -0.34487005783, -0.34589218506, 1.18191757912],
              [0.423169406488, 0.172428455046, -0.17254885365, -0.00336038234363],
              [0.0, 0.0, 0.0, 1.0]]


def cli(*args: object) -> subprocess.CompletedProcess:
    p = subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return p


def cli_error(*args: object) -> str:
    p = subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True)
    assert p.returncode == 1, (p.returncode, p.stdout, p.stderr)
    line = p.stderr.strip().splitlines()[-1]
    assert line.startswith("error: "), p.stderr
    return line[len("error: "):]


def cli_report(tmp_path: Path, *args: object) -> bytes:
    out = tmp_path / "cli.json"
    cli("eval", *args, "--quiet", "--report", out)
    return out.read_bytes()


def write_ply(path: Path, vertices: np.ndarray, triangles: np.ndarray | None = None) -> Path:
    """A binary little-endian PLY of these numbers, written here with numpy (float or double
    x y z as the array's dtype, uint vertex indices)."""
    kind = {np.dtype(np.float32): "float", np.dtype(np.float64): "double"}[vertices.dtype]
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n"
              f"property {kind} x\nproperty {kind} y\nproperty {kind} z\n")
    body = np.ascontiguousarray(vertices).astype(vertices.dtype.newbyteorder("<")).tobytes()
    if triangles is not None:
        header += f"element face {len(triangles)}\nproperty list uchar uint vertex_indices\n"
        faces = np.zeros(len(triangles), dtype=[("n", "u1"), ("v", "<u4", (3,))])
        faces["n"] = 3
        faces["v"] = triangles
        body += faces.tobytes()
    path.write_bytes((header + "end_header\n").encode() + body)
    return path


def ply_vertices(path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    """x y z (double) and the colours of `sfmeval export`'s points.ply, read with numpy."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    count = int(header.split("element vertex ")[1].split()[0])
    fields = [("x", "<f8"), ("y", "<f8"), ("z", "<f8")]
    if "property uchar red" in header:
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    rows = np.frombuffer(data, dtype=np.dtype(fields), count=count, offset=end)
    colors = (np.stack([rows["red"], rows["green"], rows["blue"]], axis=1)
              if "red" in rows.dtype.names else None)
    return np.stack([rows["x"], rows["y"], rows["z"]], axis=1), colors


# ---- the ground truth as arrays ------------------------------------------------------------

@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_mesh_arrays_give_the_report_of_their_ply_file(tmp_path, dtype):
    mesh = sfmeval.read(DEMO / "ground_truth.glb")
    assert isinstance(mesh, sfmeval.Mesh)
    vertices = mesh.vertices.astype(dtype)
    triangles = mesh.triangles.astype(np.int64)  # numpy's default integer, converted
    ply = write_ply(tmp_path / "mesh.ply", vertices, mesh.triangles)
    transform = tmp_path / "t.json"
    transform.write_text(json.dumps(DEMO_START))
    want = cli_report(tmp_path, "--gt", ply, "--recon", DEMO / "sparse.ply", "--transform",
                      transform, "--samples", 30_000, "--signed")
    for gt in [(vertices, triangles), sfmeval.Mesh(vertices, triangles),
               (np.asfortranarray(vertices), triangles[:, :])]:
        r = sfmeval.evaluate(gt, DEMO / "sparse.ply", transform=DEMO_START, samples=30_000,
                             signed=True, gt_name="mesh.ply")
        assert r.to_json().encode() == want
    # the same mesh as a file is the same measurement under another name
    assert r.inputs.ground_truth.triangles == len(triangles)


def test_cloud_array_is_a_ground_truth_cloud_as_its_ply_file(tmp_path):
    points = sfmeval.read(CORE / "open3d_cloud_binary.ply").points
    ply = write_ply(tmp_path / "gt.ply", points)
    want = cli_report(tmp_path, "--gt", ply, "--recon", CORE / "colmap_points.ply", "--align",
                      "none", "--tau", "0.05,0.1")
    for gt in [points, sfmeval.PointCloud(points, name="gt.ply")]:
        r = sfmeval.evaluate(gt, CORE / "colmap_points.ply", align="none", tau=[0.05, 0.1],
                             gt_name="gt.ply")
        assert r.to_json().encode() == want
    assert r.inputs.ground_truth.format == "ply"


def test_arrays_on_both_sides_with_ground_truth_cameras(tmp_path):
    mesh = sfmeval.read(DEMO / "ground_truth.glb")
    model = sfmeval.read(DEMO / "sparse")
    ply = write_ply(tmp_path / "ground_truth.ply", mesh.vertices, mesh.triangles)
    recon = write_ply(tmp_path / "points.ply", model.points.astype(np.float64))
    want = cli_report(tmp_path, "--gt", ply, "--recon", recon, "--gt-cameras",
                      DEMO / "cameras.json", "--align", "global", "--samples", 20_000)
    r = sfmeval.evaluate((mesh.vertices, mesh.triangles), model.points.astype(np.float64),
                         gt_cameras=DEMO / "cameras.json", align="global", samples=20_000)
    assert r.to_json().encode() == want


def test_recon_cameras_need_a_recon_file():
    with pytest.raises(sfmeval.InputError, match="recon_cameras"):
        sfmeval.evaluate(DEMO / "ground_truth.glb", sfmeval.read(MODELS / "theia.ply").points,
                         recon_cameras=MODELS / "theia_colmap")


def test_bad_ground_truth_arrays_are_input_errors():
    v = np.zeros((4, 3))
    good = np.array([[0, 1, 2]])
    for gt, match in [((v, np.array([[0, 1, 9]])), "ground truth.*vertex index 9"),
                      ((v, np.array([[0, -1, 2]])), "gt triangles"),
                      ((v, np.zeros((2, 4), dtype=np.int32)), "gt triangles"),
                      ((np.zeros((4, 2)), good), "gt vertices"),
                      ((v.astype(np.int32), good), "gt vertices"),
                      ((np.full((4, 3), np.nan), good), "non-finite"),
                      ((v, good, good), "pair"),
                      (np.zeros((0, 3)), "no vertices")]:
        with pytest.raises(sfmeval.InputError, match=match):
            sfmeval.evaluate(gt, DEMO / "sparse.ply", align="none")


# ---- read ---------------------------------------------------------------------------------

@pytest.mark.parametrize("recon", [DEMO / "sparse.ply", DEMO / "sparse", MODELS / "theia.nvm",
                                   MODELS / "openmvg_sfm_data.json"])
def test_read_gives_the_points_and_cameras_export_writes(tmp_path, recon):
    out = tmp_path / "export"
    cli("export", recon, "--out", out)
    points, colors = ply_vertices(out / "points.ply")
    got = sfmeval.read(recon)
    np.testing.assert_array_equal(got.points.astype(np.float64), points)
    if colors is None:
        assert got.colors is None
    else:
        np.testing.assert_array_equal(got.colors, colors)
    if (out / "cameras.json").exists():
        assert isinstance(got, sfmeval.Model)
        assert got.cameras.to_dict() == json.loads((out / "cameras.json").read_text())
        assert [i.name for i in got.images] == [
            i["name"] for i in json.loads((out / "cameras.json").read_text())["images"]]
    else:
        assert type(got) is sfmeval.PointCloud


def test_read_meshes_as_info_describes_them(tmp_path):
    for path in [DEMO / "ground_truth.glb", CORE / "trimesh_mesh.glb",
                 CORE / "trimesh_mesh_binary.ply"]:
        info = dict(line.split(None, 1) for line in cli("info", path).stdout.splitlines()
                    if line and not line.startswith(" "))
        m = sfmeval.read(path)
        assert isinstance(m, sfmeval.Mesh) and m.vertices.dtype == np.float64
        assert len(m.vertices) == int(info["points"]) and len(m.triangles) == int(info["triangles"])
        lo = json.loads(info["bounds"].split("min ")[1])
        assert m.vertices.min(axis=0).tolist() == lo
        assert int(m.triangles.max()) < len(m.vertices)
    # a mesh read and written back is the mesh: the same report as the file
    m = sfmeval.read(CORE / "trimesh_mesh_binary.ply")
    a = sfmeval.evaluate(m, CORE / "colmap_points.ply", align="none", samples=5000,
                         gt_name="trimesh_mesh_binary.ply")
    b = cli_report(tmp_path, "--gt", CORE / "trimesh_mesh_binary.ply", "--recon",
                   CORE / "colmap_points.ply", "--align", "none", "--samples", 5000)
    assert a.to_json().encode() == b


def test_read_errors_name_the_file(tmp_path):
    bad = tmp_path / "broken.ply"
    bad.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 9\n"
                    b"property float x\nproperty float y\nproperty float z\nend_header\n")
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.read(bad)
    assert str(bad) in str(e.value) and "PLY" in str(e.value)
    with pytest.raises(FileNotFoundError) as f:
        sfmeval.read(tmp_path / "none.glb")
    assert f.value.filename == str(tmp_path / "none.glb")


# ---- align --------------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs,flags", [
    (dict(gt_cameras=DEMO / "cameras.json"), ["--gt-cameras", DEMO / "cameras.json"]),
    (dict(align="icp", transform=DEMO_START, samples=50_000),
     ["--align", "icp", "--transform", "$t", "--samples", 50_000]),
], ids=["auto-cameras", "icp-from-matrix"])
def test_align_is_the_clis_alignment_file(tmp_path, kwargs, flags):
    t = tmp_path / "t.json"
    t.write_text(json.dumps(DEMO_START))
    out = tmp_path / "alignment.json"
    flags = [t if f == "$t" else f for f in flags]
    p = cli("align", "--gt", DEMO / "ground_truth.glb", "--recon", DEMO / "sparse", *flags,
            "--out", out)
    a = sfmeval.align(DEMO / "ground_truth.glb", DEMO / "sparse", **kwargs)
    assert a.to_json().encode() == out.read_bytes()
    assert a.gt_from_recon.tolist() == json.loads(out.read_text())["gt_from_recon"]
    assert p.stdout.startswith(f"# gt_from_recon by {a.method} ")
    # the same alignment as the evaluation's
    r = sfmeval.evaluate(DEMO / "ground_truth.glb", DEMO / "sparse", **kwargs)
    assert r.alignment.to_dict() == a.to_dict()


def test_align_errors_are_the_clis(tmp_path):
    bad = tmp_path / "model.nvm"
    bad.write_text("NVM_V3\n\n2\nimage.jpg 100 1 0 0\n")
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.align(DEMO / "ground_truth.glb", bad)
    assert str(e.value) == cli_error("align", "--gt", DEMO / "ground_truth.glb", "--recon", bad)
    assert str(bad) in str(e.value)


# ---- cameras ------------------------------------------------------------------------------

@pytest.mark.parametrize("recon", [DEMO / "sparse", MODELS / "colmap_bin", MODELS / "theia.nvm"])
def test_cameras_is_the_clis_report(tmp_path, recon):
    gt = DEMO / "cameras.json" if recon == DEMO / "sparse" else MODELS / "gt_cameras.json"
    out = tmp_path / "cameras.json"
    cli("cameras", "--gt-cameras", gt, "--recon", recon, "--report", out)
    c = sfmeval.cameras(gt, recon)
    assert c.to_json().encode() == out.read_bytes()
    assert c.alignment.gt_from_recon.shape == (4, 4)
    # a given transform, from a matrix and from its file alike
    t = tmp_path / "t.json"
    t.write_text(json.dumps(c.alignment.gt_from_recon.tolist()))
    cli("cameras", "--gt-cameras", gt, "--recon", recon, "--transform", t, "--report", out)
    assert sfmeval.cameras(gt, recon, transform=t).to_json().encode() == out.read_bytes()
    assert sfmeval.cameras(gt, recon, transform=c.alignment.gt_from_recon).to_json().encode() \
        == out.read_bytes()


def test_cameras_errors_name_the_file(tmp_path):
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.cameras(DEMO / "cameras.json", DEMO / "sparse.ply")
    assert str(e.value) == cli_error("cameras", "--gt-cameras", DEMO / "cameras.json",
                                     "--recon", DEMO / "sparse.ply")
    assert "sparse.ply" in str(e.value)
    bad = tmp_path / "cameras.json"
    bad.write_text('{"schema": "sfmeval.cameras/1", "images": 3}')
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.cameras(bad, DEMO / "sparse")
    assert str(e.value) == cli_error("cameras", "--gt-cameras", bad, "--recon", DEMO / "sparse")
    with pytest.raises(FileNotFoundError):
        sfmeval.cameras(tmp_path / "none.json", DEMO / "sparse")


# ---- poses --------------------------------------------------------------------------------

@pytest.mark.parametrize("protocol", ["colmap", "imc", "co3d"])
@pytest.mark.parametrize("recon", [MODELS / "colmap_bin", MODELS / "openmvg_colmap"])
def test_poses_is_the_clis_report(tmp_path, recon, protocol):
    gt = MODELS / "gt_cameras.json"
    out = tmp_path / "poses.json"
    cli("poses", "--gt-cameras", gt, "--recon", recon, "--protocol", protocol,
        "--position-accuracy", "0.5", "--report", out)
    p = sfmeval.poses(gt, recon, protocol, position_accuracy=0.5)
    assert p.to_json().encode() == out.read_bytes()
    assert json.loads(p.to_json())["result"]["protocol"] == protocol


def test_poses_errors_name_the_file(tmp_path):
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.poses(DEMO / "cameras.json", DEMO / "sparse.ply", "imc")
    assert str(e.value) == cli_error("poses", "--gt-cameras", DEMO / "cameras.json",
                                     "--recon", DEMO / "sparse.ply", "--protocol", "imc")
    with pytest.raises(sfmeval.InputError, match="colmap, imc, co3d"):
        sfmeval.poses(DEMO / "cameras.json", DEMO / "sparse", "eth3d")


# ---- tnt ----------------------------------------------------------------------------------

def tnt_scene(tmp_path: Path) -> Path:
    """The fixture scene Synth with a ground-truth cloud (the demo mesh's vertices)."""
    scene = tmp_path / "Synth"
    scene.mkdir()
    for f in TNT.glob("Synth*"):
        shutil.copy(f, scene / f.name)
    write_ply(scene / "Synth.ply", sfmeval.read(DEMO / "ground_truth.glb").vertices)
    return scene


def test_tnt_is_the_clis_report_and_files(tmp_path):
    scene = tnt_scene(tmp_path)
    names = tmp_path / "images.txt"
    names.write_text("\n".join(sorted(i.name for i in sfmeval.read(DEMO / "sparse").images)))
    log = tmp_path / "recon.log"
    cli("log", "--model", DEMO / "sparse", "--images", names, "--out", log)
    cli_out, py_out = tmp_path / "cli", tmp_path / "py"
    cli("tnt", "--scene", scene, "--recon", DEMO / "sparse.ply", "--trajectory", log,
        "--tau", 0.01, "--out", cli_out, "--quiet")
    r = sfmeval.tnt(scene, DEMO / "sparse.ply", trajectory=log, tau=0.01, out=py_out)
    assert r.to_json().encode() == (cli_out / "report.json").read_bytes()
    assert sorted(p.name for p in py_out.iterdir()) == sorted(p.name for p in cli_out.iterdir())
    for f in cli_out.iterdir():
        assert (py_out / f.name).read_bytes() == f.read_bytes(), f.name
    assert 0 < r.precision.value <= 1 and r.f_score == r.to_dict()["f_score"]
    # a given registration, from its file and from a matrix
    m = np.array(r.registration.gt_from_recon if "gt_from_recon" in r.registration
                 else DEMO_START)
    t = tmp_path / "t.txt"
    np.savetxt(t, m)
    cli("tnt", "--scene", scene, "--recon", DEMO / "sparse.ply", "--transform", t, "--tau",
        0.01, "--out", cli_out, "--quiet")
    given = (cli_out / "report.json").read_bytes()
    assert sfmeval.tnt(scene, DEMO / "sparse.ply", transform=t, tau=0.01).to_json().encode() \
        == given


def test_tnt_errors_name_the_file(tmp_path):
    scene = tnt_scene(tmp_path)
    bad = tmp_path / "bad.log"
    bad.write_text("0 0 1\n1 0 0\n")
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.tnt(scene, DEMO / "sparse.ply", trajectory=bad, tau=0.01)
    assert str(bad) in str(e.value)
    assert str(e.value) == cli_error("tnt", "--scene", scene, "--recon", DEMO / "sparse.ply",
                                     "--trajectory", bad, "--tau", 0.01, "--out",
                                     tmp_path / "o", "--quiet")
    with pytest.raises(sfmeval.InputError, match="trajectory"):
        sfmeval.tnt(scene, DEMO / "sparse.ply", tau=0.01)
    with pytest.raises(FileNotFoundError):
        sfmeval.tnt(tmp_path / "nothing", DEMO / "sparse.ply", trajectory=bad)


# ---- dtu ----------------------------------------------------------------------------------

def write_colmap_points(folder: Path, points: np.ndarray) -> Path:
    """A COLMAP text model holding only these 3D points (ids 1..n, no camera), written here
    with repr() so that the reader gets the same doubles."""
    folder.mkdir(parents=True)
    (folder / "cameras.txt").write_text("# Camera list\n")
    (folder / "images.txt").write_text("# Image list\n")
    (folder / "points3D.txt").write_text("".join(
        f"{i + 1} {float(x)!r} {float(y)!r} {float(z)!r} 128 128 128 0.5\n"
        for i, (x, y, z) in enumerate(points)))
    return folder


@pytest.mark.parametrize("recon, kwargs, flags", [
    ("sparse.ply", {}, []),
    ("dense.ply", {"shuffle": False}, ["--no-shuffle"]),
    ("dense.ply", {"seed": 3, "max_dist": 5.0}, ["--seed", 3, "--max-dist", 5.0]),
    ("mesh.ply", {"mode": "mesh", "downsample_density": 0.5},
     ["--mode", "mesh", "--downsample-density", 0.5]),
    ("mesh.ply", {"mode": "pcd"}, ["--mode", "pcd"]),
])
def test_dtu_is_the_clis_report_and_error_clouds(tmp_path, recon, kwargs, flags):
    cli_vis, py_vis = tmp_path / "cli", tmp_path / "py"
    p = cli("dtu", "--dataset", DTU, "--scan", 1, "--recon", DTU / recon, *flags, "--json",
            "--vis-out", cli_vis, "--report", tmp_path / "cli.json")
    r = sfmeval.dtu(DTU, 1, DTU / recon, vis_out=py_vis, report=tmp_path / "py.json", **kwargs)
    assert r.to_json() == p.stdout
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    names = sorted(f.name for f in cli_vis.iterdir())
    assert names == ["vis_001_d2s.ply", "vis_001_s2d.ply"]
    assert sorted(f.name for f in py_vis.iterdir()) == names
    for name in names:
        assert (py_vis / name).read_bytes() == (cli_vis / name).read_bytes(), name
    assert r.scan == 1 and r.mode == ("mesh" if kwargs.get("mode") == "mesh" else "pcd")
    assert 0 < r.mean_accuracy < r.options.max_dist and r.overall == r.to_dict()["overall"]
    # without vis_out and report nothing is written, and the numbers are the same
    assert sfmeval.dtu(DTU, 1, str(DTU / recon), **kwargs).to_json() == p.stdout


def test_dtu_of_an_sfm_model_is_that_of_its_points(tmp_path):
    """A COLMAP model's 3D points give the numbers of the PLY of the same points."""
    points = sfmeval.read(DTU / "sparse.ply").points.astype(np.float64)
    model = write_colmap_points(tmp_path / "model", points)
    p = cli("dtu", "--dataset", DTU, "--scan", 1, "--recon", model, "--json")
    r = sfmeval.dtu(DTU, 1, model)
    assert r.to_json() == p.stdout and r.reconstruction == str(model)
    ply = sfmeval.dtu(DTU, 1, DTU / "sparse.ply").to_dict()
    assert {**r.to_dict(), "reconstruction": ply["reconstruction"]} == ply


def test_dtu_errors_are_the_clis(tmp_path):
    with pytest.raises(FileNotFoundError):
        sfmeval.dtu(tmp_path / "nothing", 1, DTU / "sparse.ply")
    with pytest.raises(FileNotFoundError):
        sfmeval.dtu(DTU, 1, tmp_path / "nothing.ply")
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.dtu(DTU, 2, DTU / "sparse.ply")
    assert "stl002_total.ply" in str(e.value)
    assert str(e.value) == cli_error("dtu", "--dataset", DTU, "--scan", 2, "--recon",
                                     DTU / "sparse.ply")
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.dtu(DTU, 1, DTU / "sparse.ply", mode="mesh")
    assert str(DTU / "sparse.ply") in str(e.value) and "no faces" in str(e.value)
    with pytest.raises(sfmeval.InputError, match="mode 'faces'"):
        sfmeval.dtu(DTU, 1, DTU / "mesh.ply", mode="faces")
    with pytest.raises(sfmeval.InputError, match="patch_size|patch size"):
        sfmeval.dtu(DTU, 1, DTU / "sparse.ply", patch_size=-1.0)
    with pytest.raises(TypeError):
        sfmeval.dtu(DTU, 1, DTU / "sparse.ply", vis_out=3)  # type: ignore[arg-type]


# ---- eth3d --------------------------------------------------------------------------------

@pytest.mark.parametrize("recon, kwargs, flags", [
    ("dense.ply", {}, []),
    ("sparse.ply", {"tolerances": [0.2, 0.05], "voxel_size": 0.02},
     ["--tolerances", "0.2,0.05", "--voxel-size", 0.02]),
    ("dense.ply", {"beam_start_radius": 0.002, "beam_divergence_halfangle_deg": 0.05},
     ["--beam-start-radius", 0.002, "--beam-divergence-halfangle-deg", 0.05]),
])
def test_eth3d_is_the_clis_report_and_clouds(tmp_path, recon, kwargs, flags):
    cli_out, py_out = tmp_path / "cli", tmp_path / "py"
    p = cli("eth3d", "--gt", ETH3D_MLP, "--recon", ETH3D / recon, *flags, "--json",
            "--out", cli_out)
    r = sfmeval.eth3d(ETH3D_MLP, ETH3D / recon, out=py_out, **kwargs)
    assert r.to_json() == p.stdout
    names = sorted(f.name for f in cli_out.iterdir())
    tolerances = kwargs.get("tolerances", [0.01, 0.02, 0.05, 0.1, 0.2, 0.5])
    assert len(names) == 1 + 2 * len(tolerances) and "eth3d.json" in names
    assert sorted(f.name for f in py_out.iterdir()) == names
    for name in names:
        assert (py_out / name).read_bytes() == (cli_out / name).read_bytes(), name
    # the report writes each float tolerance in its shortest decimal
    assert [t.tolerance for t in r.tolerances] == sorted(tolerances)
    assert all(0 <= t.f1 <= 1 for t in r.tolerances) and r.tolerances[-1].f1 > 0
    assert r.reconstruction == str(ETH3D / recon) and len(r.scans) == 2
    # without out nothing is written, and the numbers are the same
    assert sfmeval.eth3d(str(ETH3D_MLP), str(ETH3D / recon), **kwargs).to_json() == p.stdout


def test_eth3d_errors_name_the_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        sfmeval.eth3d(tmp_path / "nothing.mlp", ETH3D / "dense.ply")
    with pytest.raises(FileNotFoundError):
        sfmeval.eth3d(ETH3D_MLP, tmp_path / "nothing.ply")
    # a project whose second scan is missing: the error names the scan and the project
    scene = tmp_path / "dslr_scan_eval"
    shutil.copytree(ETH3D_MLP.parent, scene)
    (scene / "scan2.ply").unlink()
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.eth3d(scene / "scan_alignment.mlp", ETH3D / "dense.ply")
    assert "scan2.ply" in str(e.value) and str(scene / "scan_alignment.mlp") in str(e.value)
    assert str(e.value) == cli_error("eth3d", "--gt", scene / "scan_alignment.mlp", "--recon",
                                     ETH3D / "dense.ply")
    # a reconstruction that is not a PLY
    bad = tmp_path / "bad.ply"
    bad.write_text("not a ply\n")
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.eth3d(ETH3D_MLP, bad)
    assert str(bad) in str(e.value)
    assert str(e.value) == cli_error("eth3d", "--gt", ETH3D_MLP, "--recon", bad)
    with pytest.raises(sfmeval.InputError, match="toleranc"):
        sfmeval.eth3d(ETH3D_MLP, ETH3D / "dense.ply", tolerances=[-0.1])
    with pytest.raises(TypeError):
        sfmeval.eth3d(ETH3D_MLP, ETH3D / "dense.ply", out=3)  # type: ignore[arg-type]


# ---- table --------------------------------------------------------------------------------

def runs_folder(tmp_path: Path) -> Path:
    runs = tmp_path / "compare"
    for pipeline, recon, extra in [("colmap", DEMO / "sparse", []),
                                   ("dense", DEMO / "sparse.ply", ["--align", "global"])]:
        (runs / pipeline).mkdir(parents=True)
        cli("eval", "--dataset", DEMO, "--recon", recon, "--samples", 20_000, *extra, "--quiet",
            "--report", runs / pipeline / "report.json")
    return runs


def test_table_is_the_clis_text(tmp_path):
    runs = runs_folder(tmp_path)
    reports = sorted(str(p) for p in runs.glob("*/report.json"))
    out = tmp_path / "tables"
    md = cli("table", *reports, "--failed", "openmvg=crashed", "--out", out).stdout
    t = sfmeval.table(runs, failed={"openmvg": "crashed"})
    assert t.table1_md == md == str(t)
    for name, text in t.files.items():
        assert (out / name).read_text() == text, name
    for fmt, text in [("csv", t.table1_csv), ("wide", t.table_md), ("wide-csv", t.runs_csv),
                      ("json", t.summary_json)]:
        assert cli("table", *reports, "--failed", "openmvg=crashed", "--format",
                   fmt).stdout == text
    assert [r.pipeline for r in t.rows] == [r["pipeline"] for r in json.loads(t.summary_json)["rows"]]
    # named reports and a dataset name
    named = sfmeval.table({"a": runs / "colmap/report.json", "b": runs / "dense/report.json"},
                          dataset="statue")
    assert named.table_md == cli("table", f"a={runs / 'colmap/report.json'}",
                                 f"b={runs / 'dense/report.json'}", "--dataset", "statue",
                                 "--format", "wide").stdout
    written = tmp_path / "written"
    t.write(written)
    assert {p.name: p.read_text() for p in written.iterdir()} == t.files


def test_table_errors_name_the_file(tmp_path):
    bad = tmp_path / "x" / "report.json"
    bad.parent.mkdir()
    bad.write_text('{"schema": "something else"}')
    with pytest.raises(sfmeval.InputError) as e:
        sfmeval.table([bad])
    assert str(e.value) == cli_error("table", bad)
    assert str(bad) in str(e.value)
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(sfmeval.InputError, match="no PIPELINE/report.json"):
        sfmeval.table(empty)
    with pytest.raises(FileNotFoundError):
        sfmeval.table([tmp_path / "y" / "report.json"])
