"""Hostile and absurd inputs through `sfmeval eval`, each file in its real role (ground truth,
reconstruction, ground-truth cameras, transform, point pairs): glTF node graphs that expand
without limit (a DAG, a repeated root, instancing past the triangle limit), huge but finite
numbers (1e150 … 1e308) in every kind of field, zero and 2^64-1 image sizes, negative focal
lengths, rotations that are not rotations, degenerate point pairs.

Every run must finish in time and under 2 GB of peak memory (measured per run with wait4; the
child also runs under a 4 GB address-space limit so a bomb fails the test instead of the
machine) and either
- exit 0 with a report that validates against schemas/report.schema.json and holds no null
  anywhere the schema does not allow one (serde writes NaN and infinities as null, so this is
  where an overflow shows), or
- fail with a message naming the file and the field that is wrong.

Every input is under 1 MB.
"""
import json
import os
import resource
import struct
import subprocess
import threading
import time
from pathlib import Path

import jsonschema
import pytest

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "tests" / "fixtures" / "models"

TIMEOUT_S = 120
MAX_RSS_KB = 2_000_000
ADDRESS_LIMIT = 4_000_000_000


# ---------------------------------------------------------------- running

def _limit():
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_LIMIT, ADDRESS_LIMIT))


def run_measured(sfmeval_bin, *args):
    """Runs sfmeval under the address-space limit; returns (returncode, stdout, stderr, the
    child's own peak RSS in KB from wait4, seconds)."""
    t = time.monotonic()
    p = subprocess.Popen([sfmeval_bin, *map(str, args)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, preexec_fn=_limit)
    out_chunks, err_chunks = [], []

    def pump(src, dst):
        for chunk in iter(lambda: src.read(65536), b""):
            dst.append(chunk)

    threads = [threading.Thread(target=pump, args=(p.stdout, out_chunks)),
               threading.Thread(target=pump, args=(p.stderr, err_chunks))]
    for th in threads:
        th.start()
    deadline = t + TIMEOUT_S
    while True:
        pid, status, usage = os.wait4(p.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() > deadline:
            p.kill()
            os.wait4(p.pid, 0)
            raise AssertionError(f"sfmeval {' '.join(map(str, args))} ran past {TIMEOUT_S} s")
        time.sleep(0.02)
    for th in threads:
        th.join()
    p.returncode = os.waitstatus_to_exitcode(status)
    return (p.returncode, b"".join(out_chunks).decode(errors="replace"),
            b"".join(err_chunks).decode(errors="replace"), usage.ru_maxrss,
            time.monotonic() - t)


ALLOWED_NULL_KEYS = {"rmse", "inlier_ratio", "volume", "max_distance"}


def nulls(v, path=""):
    """Paths of nulls the report schema does not allow (see the module docs)."""
    if v is None:
        key = path.rsplit("/", 1)[-1]
        return [] if key in ALLOWED_NULL_KEYS or path == "/cameras" else [path]
    if isinstance(v, dict):
        return [p for k, x in v.items() for p in nulls(x, f"{path}/{k}")]
    if isinstance(v, list):
        return [p for i, x in enumerate(v) for p in nulls(x, f"{path}/{i}")]
    return []


@pytest.fixture
def evaluate(sfmeval_bin, report_schema, tmp_path):
    """Runs `sfmeval eval` on hostile inputs; returns ("ok", report) or ("error", stderr),
    having checked time, memory, the schema and the nulls."""

    def run(*args):
        report = tmp_path / "report.json"
        if report.exists():
            report.unlink()
        code, out, err, rss, secs = run_measured(
            sfmeval_bin, "eval", "--quiet", "--samples", "20000", "--report", report, *args)
        assert rss is not None and rss < MAX_RSS_KB, f"peak RSS {rss} KB: {args}"
        if code == 0:
            rep = json.loads(report.read_text())
            jsonschema.validate(rep, report_schema)
            bad = nulls(rep)
            assert not bad, f"null where a number belongs: {bad[:10]}"
            return "ok", rep
        assert code != 0 and err.strip(), (code, err)
        assert "panicked" not in err, err
        return "error", err

    return run


# ---------------------------------------------------------------- writers

def glb(doc, bin_=b""):
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    bin_ += b"\0" * (-len(bin_) % 4)
    total = 12 + 8 + len(j) + (8 + len(bin_) if bin_ else 0)
    out = b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(j)) + b"JSON" + j
    if bin_:
        out += struct.pack("<I", len(bin_)) + b"BIN\0" + bin_
    return out


# A closed octahedron: 6 vertices, 8 triangles.
OCTA_V = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
OCTA_T = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]


def mesh_glb(nodes, roots, verts=OCTA_V, tris=OCTA_T):
    vb = b"".join(struct.pack("<3f", *v) for v in verts)
    ib = b"".join(struct.pack("<3I", *t) for t in tris)
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": roots}], "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3",
             "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5125, "count": 3 * len(tris), "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(vb)},
                        {"buffer": 0, "byteOffset": len(vb), "byteLength": len(ib)}],
        "buffers": [{"byteLength": len(vb) + len(ib)}],
    }
    return glb(doc, vb + ib)


def octa_obj(path, scale=1.0, extra_vertex=None):
    lines = [f"v {x * scale!r} {y * scale!r} {z * scale!r}" for x, y, z in OCTA_V]
    if extra_vertex is not None:
        lines.append("v " + " ".join(extra_vertex))
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in OCTA_T]
    Path(path).write_text("\n".join(lines) + "\n")
    return path


def cloud_ply(path, points, double=True):
    ty, fmt = ("double", "<3d") if double else ("float", "<3f")
    head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\n"
            f"property {ty} x\nproperty {ty} y\nproperty {ty} z\nend_header\n").encode()
    Path(path).write_bytes(head + b"".join(struct.pack(fmt, *p) for p in points))
    return path


def surface_points(n=200, scale=1.0):
    """Points on the octahedron |x|+|y|+|z| = 1, deterministic."""
    pts = []
    for i in range(n):
        a, b = (i * 0.618034) % 1.0, (i * 0.414214) % 1.0
        x, y = a * (1 - b), b * (1 - a)
        z = 1 - x - y
        sx, sy, sz = (1 if i & 1 else -1), (1 if i & 2 else -1), (1 if i & 4 else -1)
        pts.append((sx * x * scale, sy * y * scale, sz * z * scale))
    return pts


def assert_names(err, *words):
    for w in words:
        assert w in err, f"{w!r} not in: {err}"


# ---------------------------------------------------------------- glTF node graphs

def test_gltf_dag_is_refused_at_once_naming_the_node(evaluate, tmp_path):
    """The issue's 7 KB GLB: each of 40 levels lists its child twice (2^40 paths)."""
    nodes = [{"children": [i + 1, i + 1]} for i in range(40)] + [{"mesh": 0}]
    gt = tmp_path / "dag.glb"
    gt.write_bytes(mesh_glb(nodes, [0]))
    assert gt.stat().st_size < 8000
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    t = time.monotonic()
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", "none")
    assert kind == "error" and time.monotonic() - t < 10
    assert_names(err, "dag.glb", "node 0 lists node 1 twice", "tree")


def test_gltf_repeated_root_is_refused(evaluate, tmp_path):
    gt = tmp_path / "roots.glb"
    gt.write_bytes(mesh_glb([{"mesh": 0}], [0] * 20000))
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", "none")
    assert kind == "error"
    assert_names(err, "roots.glb", "node 0 more than once")


def test_gltf_instancing_past_the_limit_is_refused_before_allocating(evaluate, tmp_path):
    """A 200 KB GLB instancing a 10 000-triangle mesh in 1 001 nodes: 10.01 M triangles."""
    import random
    rnd = random.Random(3)
    verts = [(rnd.uniform(-1, 1), rnd.uniform(-1, 1), rnd.uniform(-1, 1)) for _ in range(5000)]
    tris = [(rnd.randrange(5000), rnd.randrange(5000), rnd.randrange(5000)) for _ in range(10000)]
    nodes = [{"mesh": 0, "translation": [3.0 * i, 0, 0]} for i in range(1001)]
    gt = tmp_path / "instances.glb"
    gt.write_bytes(mesh_glb(nodes, list(range(1001)), verts, tris))
    assert gt.stat().st_size < 1_000_000
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    t = time.monotonic()
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", "none")
    assert kind == "error" and time.monotonic() - t < 10
    assert_names(err, "instances.glb", "10010000", "10000000", "max-triangles")


def test_gltf_stacked_instances_are_measured_quickly(evaluate, tmp_path):
    """30 000 nodes instancing one mesh in the same place: valid, 240 000 stacked triangles;
    3 000 points took 17 s (every query visited every copy), now well under a second."""
    gt = tmp_path / "stacked.glb"
    gt.write_bytes(mesh_glb([{"mesh": 0} for _ in range(30000)], list(range(30000))))
    assert gt.stat().st_size < 1_000_000
    recon = cloud_ply(tmp_path / "recon.ply",
                      [(x * 1.3, y * 0.7, z * 1.1) for x, y, z in surface_points(3000)])
    t = time.monotonic()
    kind, rep = evaluate("--gt", gt, "--recon", recon, "--align", "none")
    assert kind == "ok", rep
    assert time.monotonic() - t < 6
    assert rep["inputs"]["ground_truth"]["triangles"] == 240000
    assert rep["accuracy"]["count"] == 3000


def test_gltf_huge_node_scale_is_refused_naming_the_node(evaluate, tmp_path):
    gt = tmp_path / "scaled.glb"
    gt.write_bytes(mesh_glb([{"children": [1], "scale": [1e30, 1e30, 1e30]},
                             {"mesh": 0, "scale": [1e30, 1e30, 1e30]}], [0]))
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", "none")
    assert kind == "error"
    assert_names(err, "scaled.glb", "node 1", "transform")


# ---------------------------------------------------------------- huge finite numbers

@pytest.mark.parametrize("value", ["1e308", "-1e308", "1e150", "-1e150"])
def test_huge_ground_truth_coordinate_is_refused(evaluate, tmp_path, value):
    gt = octa_obj(tmp_path / "gt.obj", extra_vertex=[value, "0", "0"])
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", "none")
    assert kind == "error"
    assert_names(err, "gt.obj", "vertex #6", "x", "beyond")


@pytest.mark.parametrize("value", [1e308, 1e200, -1e150])
@pytest.mark.parametrize("align", ["none", "auto"])
def test_huge_reconstruction_coordinate_is_refused(evaluate, tmp_path, value, align):
    gt = octa_obj(tmp_path / "gt.obj")
    pts = surface_points() + [(0.0, value, 0.0)]
    recon = cloud_ply(tmp_path / "recon.ply", pts)
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", align)
    assert kind == "error"
    assert_names(err, "recon.ply", "#200", "y", "beyond")


@pytest.mark.parametrize("scale", [1e45, 1e-40])
@pytest.mark.parametrize("align", ["none", "auto"])
def test_huge_and_tiny_scenes_are_measured(evaluate, tmp_path, scale, align):
    """Scenes of 1e45 or 1e-40 units (accepted: every derived quantity is computed
    scale-safely), with an outlier 40 diagonals away: every number of the report is finite."""
    gt = octa_obj(tmp_path / "gt.obj", scale=scale)
    pts = surface_points(300, scale) + [(40 * scale, 0.0, 0.0)]
    recon = cloud_ply(tmp_path / "recon.ply", pts)
    kind, rep = evaluate("--gt", gt, "--recon", recon, "--align", align)
    assert kind == "ok", rep
    diag = rep["inputs"]["ground_truth"]["diagonal"]
    assert abs(diag / (2 * 3 ** 0.5 * scale) - 1) < 1e-9
    assert rep["alignment"]["scale"] > 0
    if align == "none":
        assert rep["accuracy"]["max"] > 30 * scale
        assert 0 < rep["accuracy"]["rms"] < 10 * scale


def test_float32_extremes_are_accepted(evaluate, tmp_path):
    """Every finite float32 is within the bound (±1e50): a cloud at 3.4e38 is measured."""
    gt = octa_obj(tmp_path / "gt.obj")
    recon = cloud_ply(tmp_path / "recon.ply", surface_points() + [(3.4e38, -3.4e38, 3.4e38)],
                      double=False)
    kind, rep = evaluate("--gt", gt, "--recon", recon, "--align", "none")
    assert kind == "ok", rep
    assert rep["accuracy"]["max"] > 5e38


# ---------------------------------------------------------------- transform and point pairs

@pytest.mark.parametrize("text", [
    "1e308 0 0 0  0 1e308 0 0  0 0 1e308 0  0 0 0 1",
    "1e150 0 0 0  0 1e150 0 0  0 0 1e150 0  0 0 0 1",
    "1 0 0 1e300  0 1 0 0  0 0 1 0  0 0 0 1",
])
def test_huge_transform_is_refused_naming_the_file(evaluate, tmp_path, text):
    gt = octa_obj(tmp_path / "gt.obj")
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    t = tmp_path / "gt_from_recon.txt"
    t.write_text(text + "\n")
    kind, err = evaluate("--gt", gt, "--recon", recon, "--transform", t)
    assert kind == "error"
    assert_names(err, "gt_from_recon.txt", "entry [", "beyond")


def test_transform_that_blows_points_past_the_bound_is_refused(evaluate, tmp_path):
    gt = octa_obj(tmp_path / "gt.obj")
    recon = cloud_ply(tmp_path / "recon.ply", surface_points() + [(1e45, 0.0, 0.0)])
    t = tmp_path / "gt_from_recon.txt"
    t.write_text("1e40 0 0 0  0 1e40 0 0  0 0 1e40 0  0 0 0 1\n")
    kind, err = evaluate("--gt", gt, "--recon", recon, "--transform", t)
    assert kind == "error"
    assert_names(err, "point #200", "beyond")


def test_huge_point_pair_is_refused_naming_the_pairs_file(evaluate, tmp_path):
    gt = octa_obj(tmp_path / "gt.obj")
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    pairs = tmp_path / "pairs.json"
    pairs.write_text(json.dumps({"pairs": [
        {"recon": [0, 0, 0], "gt": [0, 0, 0]}, {"recon": [1, 0, 0], "gt": [1, 0, 0]},
        {"recon": [0, 1, 0], "gt": [0, 1e150, 0]}, {"recon": [0, 0, 1], "gt": [0, 0, 1]}]}))
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", "points", "--pairs", pairs)
    assert kind == "error"
    assert_names(err, "pairs.json", "pair #2", "gt[1]", "1e150")


def test_degenerate_point_pairs_say_point_pairs(evaluate, tmp_path):
    """Collinear pairs are a point-pairs error (the core's `Error::PointPairs`), not a
    geometry error of the reconstruction."""
    gt = octa_obj(tmp_path / "gt.obj")
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    pairs = tmp_path / "pairs.json"
    pairs.write_text(json.dumps({"pairs": [{"recon": [i, 0, 0], "gt": [0, i, 0]}
                                           for i in range(5)]}))
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", "points", "--pairs", pairs)
    assert kind == "error"
    assert_names(err, "point pairs: ", "collinear", "pairs.json")
    assert "recon.ply" not in err, err


def test_the_triangle_limit_can_be_raised(evaluate, tmp_path):
    """The instancing GLB of the limit test, evaluated with --max-triangles raised past its
    expanded size: accepted (the limit is a guard for untrusted files, not a cap); lowered
    below a plain mesh's size: refused naming the flag."""
    import random
    rnd = random.Random(3)
    verts = [(rnd.uniform(-1, 1), rnd.uniform(-1, 1), rnd.uniform(-1, 1)) for _ in range(50)]
    tris = [(rnd.randrange(50), rnd.randrange(50), rnd.randrange(50)) for _ in range(100)]
    nodes = [{"mesh": 0, "translation": [3.0 * i, 0, 0]} for i in range(11)]
    gt = tmp_path / "instances.glb"
    gt.write_bytes(mesh_glb(nodes, list(range(11)), verts, tris))
    recon = cloud_ply(tmp_path / "recon.ply", surface_points())
    kind, err = evaluate("--gt", gt, "--recon", recon, "--align", "none", "--max-triangles", "1000")
    assert kind == "error"
    assert_names(err, "instances.glb", "1100", "1000", "max-triangles")
    kind, out = evaluate("--gt", gt, "--recon", recon, "--align", "none", "--max-triangles", "1100")
    assert kind != "error", out


# ---------------------------------------------------------------- cameras

def colmap_text_model(folder, camera_line=None, image_edit=None):
    folder.mkdir(parents=True, exist_ok=True)
    cams = (MODELS / "colmap_text" / "cameras.txt").read_text()
    if camera_line is not None:
        cams = "\n".join(ln if ln.startswith("#") else camera_line for ln in cams.splitlines())
    (folder / "cameras.txt").write_text(cams + "\n")
    imgs = (MODELS / "colmap_text" / "images.txt").read_text().splitlines()
    if image_edit is not None:
        data = [i for i, ln in enumerate(imgs) if ln and not ln.startswith("#")]
        first = data[0]
        imgs[first] = image_edit(imgs[first])
    (folder / "images.txt").write_text("\n".join(imgs) + "\n")
    (folder / "points3D.txt").write_text((MODELS / "colmap_text" / "points3D.txt").read_text())
    return folder


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    from test_cli_align import scene_obj
    return scene_obj(tmp_path_factory.mktemp("scene") / "scene.obj")


@pytest.mark.parametrize("line, field", [
    ("1 PINHOLE 18446744073709551615 180 210 210 120 90", "width"),
    ("1 PINHOLE 240 0 210 210 120 90", "height"),
    ("1 PINHOLE 240 180 -210 210 120 90", "focal length fx"),
    ("1 PINHOLE 240 180 210 1e308 120 90", "focal length fy"),
    ("1 PINHOLE 240 180 210 210 1e300 90", "principal point cx"),
])
def test_absurd_colmap_camera_is_refused(evaluate, scene, tmp_path, line, field):
    model = colmap_text_model(tmp_path / "sparse" / "0", camera_line=line)
    kind, err = evaluate("--gt", scene, "--recon", tmp_path / "sparse",
                         "--gt-cameras", MODELS / "gt_cameras.json")
    assert kind == "error"
    assert_names(err, "sparse", "camera 1", field)
    assert model.exists()


def test_unknown_colmap_image_size_is_a_warning(evaluate, scene, tmp_path):
    colmap_text_model(tmp_path / "sparse" / "0", camera_line="1 PINHOLE 0 0 210 210 120 90")
    kind, rep = evaluate("--gt", scene, "--recon", tmp_path / "sparse",
                         "--gt-cameras", MODELS / "gt_cameras.json")
    assert kind == "ok", rep
    assert any("camera 1" in w and "unknown" in w for w in [n["message"] for n in rep["notes"]]), [n["message"] for n in rep["notes"]]
    assert rep["cameras"]["matched"] == 6


@pytest.mark.parametrize("edit, field", [
    (lambda w: w[:1] + ["1e308"] + w[2:5] + ["1e308", "0", "0"] + w[8:], "translation x"),
    (lambda w: w[:5] + ["1e60"] + w[6:], "translation x"),
])
def test_huge_colmap_pose_is_refused(evaluate, scene, tmp_path, edit, field):
    colmap_text_model(tmp_path / "sparse" / "0",
                      image_edit=lambda ln: " ".join(edit(ln.split())))
    kind, err = evaluate("--gt", scene, "--recon", tmp_path / "sparse",
                         "--gt-cameras", MODELS / "gt_cameras.json")
    assert kind == "error"
    assert_names(err, "sparse", "image", field, "beyond")


def gt_cameras_with(tmp_path, camera=None, image0=None):
    d = json.loads((MODELS / "gt_cameras.json").read_text())
    if camera:
        d["cameras"][0].update(camera)
    if image0:
        image0(d["images"][0])
    p = tmp_path / "gt_cameras.json"
    p.write_text(json.dumps(d))
    return p


@pytest.mark.parametrize("camera, field", [
    ({"fx": -210.0}, "focal length fx"),
    ({"width": 18446744073709551615}, "width"),
    ({"fy": 1e308}, "focal length fy"),
])
def test_absurd_ground_truth_camera_is_refused_naming_the_file(evaluate, scene, tmp_path,
                                                               camera, field):
    gt_cams = gt_cameras_with(tmp_path, camera=camera)
    kind, err = evaluate("--gt", scene, "--recon", MODELS / "colmap_text",
                         "--gt-cameras", gt_cams)
    assert kind == "error"
    assert_names(err, "gt_cameras.json", "camera 1", field)


@pytest.mark.parametrize("edit, words", [
    (lambda im: im["cam_from_world"]["translation"].__setitem__(0, 1e308),
     ["image '0000.png'", "translation x"]),
    (lambda im: im["cam_from_world"]["rotation"][0].__setitem__(0, 1e308),
     ["image '0000.png'", "rotation"]),
    (lambda im: im["cam_from_world"]["rotation"][0].__setitem__(0, 0.5),
     ["image '0000.png'", "rotation", "R·Rᵀ"]),
])
def test_absurd_ground_truth_pose_is_refused(evaluate, scene, tmp_path, edit, words):
    gt_cams = gt_cameras_with(tmp_path, image0=edit)
    kind, err = evaluate("--gt", scene, "--recon", MODELS / "colmap_text",
                         "--gt-cameras", gt_cams)
    assert kind == "error"
    assert_names(err, "gt_cameras.json", *words)


def test_openmvg_non_orthonormal_rotation_is_refused(evaluate, scene, tmp_path):
    d = json.loads((MODELS / "openmvg_sfm_data.json").read_text())
    d["extrinsics"][0]["value"]["rotation"][0] = [2.0, 0.0, 0.0]
    p = tmp_path / "sfm_data.json"
    p.write_text(json.dumps(d))
    kind, err = evaluate("--gt", scene, "--recon", p, "--gt-cameras", MODELS / "gt_cameras.json")
    assert kind == "error"
    assert_names(err, "sfm_data.json", "rotation", "not a rotation")


@pytest.mark.parametrize("field, value, words", [
    ("width", 0, ["width"]),
    ("width", 18446744073709551615, ["width"]),
    ("focal_length", -210.0, ["focal length"]),
])
def test_openmvg_absurd_intrinsic_is_refused(evaluate, scene, tmp_path, field, value, words):
    d = json.loads((MODELS / "openmvg_sfm_data.json").read_text())
    d["intrinsics"][0]["value"]["ptr_wrapper"]["data"][field] = value
    p = tmp_path / "sfm_data.json"
    p.write_text(json.dumps(d))
    kind, err = evaluate("--gt", scene, "--recon", p, "--gt-cameras", MODELS / "gt_cameras.json")
    assert kind == "error"
    assert_names(err, "sfm_data.json", "camera 0", *words)


def test_nvm_huge_camera_centre_is_refused(evaluate, scene, tmp_path):
    lines = (MODELS / "colmap38.nvm").read_text().splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith("0003.png"))
    w = lines[i].split()
    w[6] = "1e308"
    lines[i] = " ".join(w)
    p = tmp_path / "model.nvm"
    p.write_text("\n".join(lines) + "\n")
    kind, err = evaluate("--gt", scene, "--recon", p, "--gt-cameras", MODELS / "gt_cameras.json")
    assert kind == "error"
    assert_names(err, "model.nvm", "0003.png", "centre Cx", "beyond")


def test_bundler_rotation_entry_1e308_is_refused(evaluate, scene, tmp_path):
    lines = (MODELS / "colmap38.bundle.out").read_text().splitlines()
    w = lines[3].split()
    w[0] = "1e308"
    lines[3] = " ".join(w)
    (tmp_path / "b").mkdir()
    p = tmp_path / "b" / "bundle.out"
    p.write_text("\n".join(lines) + "\n")
    (tmp_path / "b" / "list.txt").write_text((MODELS / "colmap38.list.txt").read_text())
    kind, err = evaluate("--gt", scene, "--recon", tmp_path / "b",
                         "--gt-cameras", MODELS / "gt_cameras.json")
    assert kind == "error"
    assert_names(err, "rotation", "not a rotation")


def test_every_fixture_model_still_gives_a_valid_report(evaluate, scene):
    """The checks refuse nothing real: every fixture model format, with the GT cameras."""
    for recon in [MODELS / "colmap_text", MODELS / "colmap_bin", MODELS / "colmap38.nvm",
                  MODELS / "theia.nvm", MODELS / "openmvg_sfm_data.json"]:
        kind, rep = evaluate("--gt", scene, "--recon", recon,
                             "--gt-cameras", MODELS / "gt_cameras.json")
        assert kind == "ok", (recon, rep)
        assert rep["cameras"]["matched"] >= 5, recon


def test_ground_truth_camera_warnings_reach_the_report(evaluate, tmp_path):
    """A ground-truth camera whose principal point lies outside its image is accepted with a
    warning, and that warning is in the report (it named only the reconstruction's before)."""
    cams = json.loads((MODELS / "gt_cameras.json").read_text())
    cams["cameras"][0]["cx"] = -500.0
    gt_cams = tmp_path / "gt_cameras.json"
    gt_cams.write_text(json.dumps(cams))
    kind, rep = evaluate("--gt", ROOT / "tests" / "fixtures" / "core" / "trimesh_mesh.glb",
                         "--gt-cameras", gt_cams, "--recon", MODELS / "colmap_text", "--align", "cameras")
    assert kind == "ok", rep
    hits = [w for w in [n["message"] for n in rep["notes"]] if w.startswith("ground-truth cameras: ")]
    assert hits and "principal point" in hits[0] and "outside" in hits[0], [n["message"] for n in rep["notes"]]


# ---------------------------------------------------------------- DTU .mat files

def _mat_header():
    text = b"MATLAB 5.0 MAT-file, hostile test".ljust(116, b" ")
    return text + b"\0" * 8 + struct.pack("<H", 0x0100) + b"IM"


def _element(ty, data):
    pad = (-len(data)) % 8
    return struct.pack("<II", ty, len(data)) + data + b"\0" * pad


def _matrix(name, dims, class_code=9, data_ty=2, data=b"", flags=0x0200):
    body = (_element(6, struct.pack("<II", class_code | flags, 0))
            + _element(5, struct.pack(f"<{len(dims)}i", *dims))
            + _element(1, name.encode())
            + _element(data_ty, data))
    return struct.pack("<II", 14, len(body)) + body


def _compressed(raw):
    import zlib
    z = zlib.compress(raw)
    return struct.pack("<II", 15, len(z)) + z


@pytest.fixture(scope="module")
def dtu_dataset(tmp_path_factory):
    """A tiny valid DTU layout (STL points, observation mask, plane) and a reconstruction."""
    import numpy as np
    from scipy.io import savemat
    root = tmp_path_factory.mktemp("dtu_hostile")
    (root / "Points" / "stl").mkdir(parents=True)
    (root / "ObsMask").mkdir()
    pts = surface_points(500, scale=10.0)
    cloud_ply(root / "Points" / "stl" / "stl001_total.ply", pts)
    savemat(root / "ObsMask" / "ObsMask1_10.mat",
            {"ObsMask": np.ones((8, 8, 8), dtype=bool), "BB": np.array([[-20.0] * 3, [20.0] * 3]),
             "Res": np.array([[5.0]])}, do_compression=True)
    savemat(root / "ObsMask" / "Plane1.mat", {"P": np.array([0.0, 0.0, 1.0, 100.0])})
    cloud_ply(root / "recon.ply", pts)
    return root


def _dtu_with_mask(dtu_dataset, tmp_path, mask_bytes):
    import shutil
    root = tmp_path / "dtu"
    shutil.copytree(dtu_dataset, root)
    (root / "ObsMask" / "ObsMask1_10.mat").write_bytes(mask_bytes)
    return root


def _run_dtu(sfmeval_bin, root):
    code, out, err, rss, secs = run_measured(sfmeval_bin, "dtu", "--dataset", root, "--scan", "1",
                                             "--recon", root / "recon.ply", "--json")
    assert rss is not None and rss < MAX_RSS_KB, f"peak RSS {rss} KB"
    assert "panicked" not in err, err
    return code, out, err


def test_dtu_valid_layout_is_measured(sfmeval_bin, dtu_dataset):
    code, out, err = _run_dtu(sfmeval_bin, dtu_dataset)
    assert code == 0, err
    rep = json.loads(out)
    jsonschema.validate(rep, json.loads((ROOT / "schemas" / "dtu.schema.json").read_text()))
    assert rep["schema"] == "sfmeval.dtu/1" and rep["mean_accuracy"] == 0.0


@pytest.mark.parametrize("cut", [0, 100, 128, 140, 200, -1])
def test_dtu_truncated_mat_is_refused_naming_the_file(sfmeval_bin, dtu_dataset, tmp_path, cut):
    whole = (dtu_dataset / "ObsMask" / "ObsMask1_10.mat").read_bytes()
    root = _dtu_with_mask(dtu_dataset, tmp_path, whole[:cut] if cut >= 0 else whole[:-5])
    code, _, err = _run_dtu(sfmeval_bin, root)
    assert code == 1 and "ObsMask1_10.mat" in err, err
    assert "truncated" in err or "no variable" in err or "ends" in err, err


@pytest.mark.parametrize("value, kind", [
    ("a string", "char array"),
    ({"a": 1.0}, "struct array"),
    ([[1.0, "x"]], "cell array"),
    (1j, "complex"),
])
def test_dtu_mat_of_the_wrong_class_is_refused(sfmeval_bin, dtu_dataset, tmp_path, value, kind):
    import io
    import numpy as np
    from scipy.io import savemat
    buf = io.BytesIO()
    v = np.array(value, dtype=object) if isinstance(value, list) else value
    savemat(buf, {"ObsMask": v, "BB": np.zeros((2, 3)), "Res": 1.0}, do_compression=True)
    root = _dtu_with_mask(dtu_dataset, tmp_path, buf.getvalue())
    code, _, err = _run_dtu(sfmeval_bin, root)
    assert code == 1 and "ObsMask1_10.mat" in err and kind in err, err


def test_dtu_mat_without_its_variables_names_them(sfmeval_bin, dtu_dataset, tmp_path):
    import io
    import numpy as np
    from scipy.io import savemat
    buf = io.BytesIO()
    savemat(buf, {"Mask": np.ones((2, 2, 2), dtype=bool)})
    root = _dtu_with_mask(dtu_dataset, tmp_path, buf.getvalue())
    code, _, err = _run_dtu(sfmeval_bin, root)
    assert code == 1 and "no variable 'ObsMask'" in err and "Mask" in err, err


@pytest.mark.parametrize("dims", [[100000, 100000, 100000], [2**31 - 1] * 3, [-1, 4, 4]])
@pytest.mark.parametrize("compressed", [False, True])
def test_dtu_mat_with_huge_dimensions_is_refused_before_allocating(
        sfmeval_bin, dtu_dataset, tmp_path, dims, compressed):
    m = _matrix("ObsMask", dims, data=b"\1" * 64)
    root = _dtu_with_mask(dtu_dataset, tmp_path, _mat_header() + (_compressed(m) if compressed else m))
    code, _, err = _run_dtu(sfmeval_bin, root)
    assert code == 1 and "ObsMask1_10.mat" in err, err
    assert "above the limit" in err or "negative dimension" in err, err


def test_dtu_mat_declaring_more_than_its_stream_holds_is_refused(sfmeval_bin, dtu_dataset, tmp_path):
    """A compressed mask that declares 3.4 GB (within the limit) but whose stream ends after
    1 MB: inflated no further than the stream, refused as truncated, under the memory bound."""
    import zlib
    dims = [1500, 1500, 1500]
    n = 1500 ** 3
    head = (_element(6, struct.pack("<II", 9 | 0x0200, 0)) + _element(5, struct.pack("<3i", *dims))
            + _element(1, b"ObsMask") + struct.pack("<II", 2, n))
    raw = struct.pack("<II", 14, len(head) + n) + head + b"\0" * (1 << 20)
    z = zlib.compressobj()
    stream = z.compress(raw) + z.flush(zlib.Z_SYNC_FLUSH)
    mat = _mat_header() + struct.pack("<II", 15, len(stream)) + stream
    root = _dtu_with_mask(dtu_dataset, tmp_path, mat)
    code, _, err = _run_dtu(sfmeval_bin, root)
    assert code == 1 and "ObsMask1_10.mat" in err and "ends after" in err, err


def test_dtu_mat_dimensions_that_disagree_with_the_data_are_refused(sfmeval_bin, dtu_dataset,
                                                                     tmp_path):
    m = _matrix("ObsMask", [4, 4, 4], data=b"\1" * 10)
    root = _dtu_with_mask(dtu_dataset, tmp_path, _mat_header() + m)
    code, _, err = _run_dtu(sfmeval_bin, root)
    assert code == 1 and "ObsMask1_10.mat" in err and "64" in err, err


# ---------------------------------------------------------------- ETH3D (sfmeval eth3d)

ETH3D_MLP = """<!DOCTYPE MeshLabDocument>
<MeshLabProject>
 <MeshGroup>
  <MLMesh label="scan1.ply" filename="scan1.ply">
   <MLMatrix44>
1 0 0 2 
0 1 0 0 
0 0 1 0.5 
0 0 0 1 
</MLMatrix44>
  </MLMesh>
 </MeshGroup>
</MeshLabProject>
"""


@pytest.fixture(scope="module")
def eth3d_scene_dir(tmp_path_factory):
    """A tiny valid ETH3D layout (a project posing one scan) and a reconstruction."""
    root = tmp_path_factory.mktemp("eth3d_hostile")
    pts = surface_points(500)
    cloud_ply(root / "scan1.ply", pts, double=False)
    (root / "scan_alignment.mlp").write_text(ETH3D_MLP)
    cloud_ply(root / "recon.ply", [(x + 2, y, z + 0.5) for x, y, z in pts], double=False)
    return root


def _run_eth3d(sfmeval_bin, root, mlp="scan_alignment.mlp", recon="recon.ply"):
    code, out, err, rss, secs = run_measured(sfmeval_bin, "eth3d", "--gt", root / mlp,
                                             "--recon", root / recon, "--json")
    assert rss is not None and rss < MAX_RSS_KB, f"peak RSS {rss} KB"
    assert "panicked" not in err, err
    return code, out, err


def _eth3d_with(eth3d_scene_dir, tmp_path, mlp_text=None, scan_bytes=None):
    import shutil
    root = tmp_path / "eth3d"
    shutil.copytree(eth3d_scene_dir, root)
    if mlp_text is not None:
        (root / "scan_alignment.mlp").write_text(mlp_text)
    if scan_bytes is not None:
        (root / "scan1.ply").write_bytes(scan_bytes)
    return root


def test_eth3d_valid_layout_is_measured(sfmeval_bin, eth3d_scene_dir):
    code, out, err = _run_eth3d(sfmeval_bin, eth3d_scene_dir)
    assert code == 0, err
    rep = json.loads(out)
    jsonschema.validate(rep, json.loads((ROOT / "schemas" / "eth3d.schema.json").read_text()))
    # The reconstruction is the scan itself: complete and accurate at every tolerance.
    assert all(t["completeness"] == 1.0 and t["accuracy"] == 1.0 for t in rep["tolerances"])


@pytest.mark.parametrize("mlp, words", [
    ("<MeshLabProject><MeshGroup>", ["not XML"]),
    ("", ["not XML"]),
    ("<Project/>", ["MeshLabProject"]),
    ("<MeshLabProject></MeshLabProject>", ["MeshGroup"]),
    ("<MeshLabProject><MeshGroup></MeshGroup></MeshLabProject>", ["no scans"]),
    (ETH3D_MLP.replace(' filename="scan1.ply"', ""), ["no filename"]),
    (ETH3D_MLP.replace("0 0 1 0.5 \n", ""), ["12 numbers"]),
    (ETH3D_MLP.replace("0.5", "nan"), ["non-finite"]),
    (ETH3D_MLP.replace("0.5", "inf"), ["non-finite"]),
    (ETH3D_MLP.replace("0.5", "1e39"), ["non-finite"]),
    (ETH3D_MLP.replace("0.5", "zero"), ["not a number"]),
    (ETH3D_MLP.replace("0 0 0 1 \n", "0 0 0 2 \n"), ["last row"]),
    (ETH3D_MLP.replace("<MLMatrix44>", "<Other>").replace("</MLMatrix44>", "</Other>"), ["MLMatrix44"]),
])
def test_eth3d_malformed_project_is_refused_naming_it(sfmeval_bin, eth3d_scene_dir, tmp_path, mlp, words):
    root = _eth3d_with(eth3d_scene_dir, tmp_path, mlp_text=mlp)
    code, _, err = _run_eth3d(sfmeval_bin, root)
    assert code == 1 and "scan_alignment.mlp" in err, err
    for w in words:
        assert w in err, err


def test_eth3d_missing_scan_is_named(sfmeval_bin, eth3d_scene_dir, tmp_path):
    root = _eth3d_with(eth3d_scene_dir, tmp_path, mlp_text=ETH3D_MLP.replace('filename="scan1.ply"',
                                                                             'filename="nowhere/scan9.ply"'))
    code, _, err = _run_eth3d(sfmeval_bin, root)
    assert code == 1 and "scan9.ply" in err and "scan_alignment.mlp" in err, err


@pytest.mark.parametrize("cut", [0, 40, 100, -1])
def test_eth3d_truncated_scan_is_refused_naming_it(sfmeval_bin, eth3d_scene_dir, tmp_path, cut):
    whole = (eth3d_scene_dir / "scan1.ply").read_bytes()
    root = _eth3d_with(eth3d_scene_dir, tmp_path, scan_bytes=whole[:cut] if cut >= 0 else whole[:-5])
    code, _, err = _run_eth3d(sfmeval_bin, root)
    assert code == 1 and "scan1.ply" in err, err


def test_eth3d_non_finite_scan_point_is_refused(sfmeval_bin, eth3d_scene_dir, tmp_path):
    root = tmp_path / "nf"
    root.mkdir()
    (root / "scan_alignment.mlp").write_text(ETH3D_MLP)
    cloud_ply(root / "scan1.ply", [(0.0, 0.0, 0.0), (float("nan"), 1.0, 1.0)], double=False)
    (root / "recon.ply").write_bytes((eth3d_scene_dir / "recon.ply").read_bytes())
    code, _, err = _run_eth3d(sfmeval_bin, root)
    assert code == 1 and "scan1.ply" in err and ("finite" in err or "NaN" in err), err


@pytest.mark.parametrize("cut", [10, 100, -1])
def test_eth3d_truncated_reconstruction_is_refused(sfmeval_bin, eth3d_scene_dir, tmp_path, cut):
    whole = (eth3d_scene_dir / "recon.ply").read_bytes()
    root = _eth3d_with(eth3d_scene_dir, tmp_path)
    (root / "recon.ply").write_bytes(whole[:cut] if cut >= 0 else whole[:-5])
    code, _, err = _run_eth3d(sfmeval_bin, root)
    assert code == 1 and "recon.ply" in err, err


def test_eth3d_huge_coordinates_finish(sfmeval_bin, eth3d_scene_dir, tmp_path):
    """Reconstruction points at 1e38 (float max is 3.4e38): the voxel keys overflow as the tool's
    int conversions do; the run finishes with a valid report."""
    root = _eth3d_with(eth3d_scene_dir, tmp_path)
    cloud_ply(root / "recon.ply", [(1e38, -1e38, 1e38), (2.0, 0.0, 0.5), (-3e38, 0.0, 0.0)], double=False)
    code, out, err = _run_eth3d(sfmeval_bin, root)
    assert code == 0, err
    jsonschema.validate(json.loads(out), json.loads((ROOT / "schemas" / "eth3d.schema.json").read_text()))
