"""`sfmeval tnt` and `sfmeval log` against the Tanks and Temples toolbox itself
(tests/third_party/tanksandtemples_evaluation, run on current Open3D by tnt_toolbox.py) on a
scene in the benchmark's layout made from the demo dataset (tnt_scene.py): the ground truth
sampled from the mesh, a crop polygon, a trans file, and the `.log` of a real pycolmap run.

With the final transform fixed, every step is deterministic: precision, recall, F and the curves
must equal the toolbox's (to 1e-4, the bar; they come out equal), and so must the crops, the
down-sampled clouds and the colours of the coloured PLYs. The whole protocol, registration
included, must agree within 0.5 percentage points."""
import json
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import open3d as o3d
import pytest
from scipy.spatial import cKDTree

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import tnt_scene  # noqa: E402

ROOT = HERE.parents[1]
SCHEMA = json.loads((ROOT / "schemas" / "tanksandtemples.schema.json").read_text())


@pytest.fixture(scope="module")
def scene(tmp_path_factory, sfmeval_bin):
    out = tmp_path_factory.mktemp("tnt")
    info = tnt_scene.build(out, gt_points=300_000, dense_points=120_000)
    log = info["recon"] / "recon.log"
    p = subprocess.run([sfmeval_bin, "log", "--model", str(ROOT / "data/demo/sparse"),
                        "--images", str(info["recon"] / "images.txt"), "--out", str(log)],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    info["log"] = log
    return info


def toolbox(*args):
    p = subprocess.run([sys.executable, str(HERE / "tnt_toolbox.py"), *map(str, args)],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def ours(sfmeval_bin, scene, recon, out, *extra):
    p = subprocess.run([sfmeval_bin, "tnt", "--scene", str(scene["scene"]), "--recon", str(recon),
                        "--tau", str(scene["tau"]), "--out", str(out), "--quiet", *map(str, extra)],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    report = json.loads((out / "report.json").read_text())
    jsonschema.validate(report, SCHEMA)
    return report


def read_ply(path):
    pcd = o3d.io.read_point_cloud(str(path))
    return np.asarray(pcd.points), np.asarray(pcd.colors)


def test_log_writer_matches_pycolmap(scene, sfmeval_bin, tmp_path):
    import pycolmap

    sys.path.insert(0, str(tnt_scene.TOOLBOX))
    import trajectory_io

    frames = trajectory_io.read_trajectory(str(scene["log"]))
    model = pycolmap.Reconstruction(str(ROOT / "data/demo/sparse"))
    centres = {im.name: im.projection_center() for im in model.images.values()}
    assert len(frames) == len(scene["names"]) == 36
    for k, (frame, name) in enumerate(zip(frames, scene["names"])):
        assert list(frame.metadata) == [k, k, 0]
        assert np.abs(frame.pose[:3, 3] - centres[name]).max() < 1e-9
        r = frame.pose[:3, :3]
        assert np.abs(r @ r.T - np.eye(3)).max() < 1e-9
    # An image the model lacks gets `k -1 0` and the identity, as the toolbox's converter does.
    names = tmp_path / "names.txt"
    names.write_text("".join(n + "\n" for n in scene["names"]) + "zz_missing.jpg\n")
    log = tmp_path / "more.log"
    p = subprocess.run([sfmeval_bin, "log", "--model", str(ROOT / "data/demo/sparse"),
                        "--images", str(names), "--out", str(log)], capture_output=True, text=True)
    assert p.returncode == 0 and "36 registered, 1 missing" in p.stdout, p.stdout + p.stderr
    last = trajectory_io.read_trajectory(str(log))[-1]
    assert list(last.metadata) == [36, -1, 0] and np.array_equal(last.pose, np.eye(4))


@pytest.mark.parametrize("cloud", ["dense", "sparse"])
def test_fixed_transform_equals_the_toolbox(scene, sfmeval_bin, tmp_path, cloud):
    recon = scene["recon"] / f"{cloud}.ply"
    transform = tmp_path / "gt_from_recon.txt"
    np.savetxt(transform, scene["gt_from_recon"])
    theirs = toolbox("histo", scene["scene"], recon, transform, tmp_path / "toolbox", scene["tau"])
    rep = ours(sfmeval_bin, scene, recon, tmp_path / "ours", "--transform", transform)
    assert rep["registration"]["mode"] == "given"
    for key, mine in [("precision", rep["precision"]["value"]), ("recall", rep["recall"]["value"]),
                      ("f_score", rep["f_score"])]:
        assert abs(mine - theirs[key]) <= 1e-4, (key, mine, theirs[key])
    assert 0.02 < rep["f_score"] < 0.999  # a case where the numbers say something
    name = "Synth"
    # The curves and the P/R/F text files, as numpy wrote them.
    for suffix in ["precision.txt", "recall.txt", "prf_tau_plotstr.txt"]:
        a = np.loadtxt(tmp_path / "toolbox" / f"{name}.{suffix}")
        b = np.loadtxt(tmp_path / "ours" / f"{name}.{suffix}")
        assert a.shape == b.shape and np.abs(a - b).max() <= 1e-4, suffix
    # The measured clouds: same points (any order), same colours.
    for side in ["precision", "recall"]:
        tp, tc = read_ply(tmp_path / "toolbox" / f"{name}.{side}.ply")
        mp, mc = read_ply(tmp_path / "ours" / f"{name}.{side}.ply")
        assert len(mp) == len(tp) == rep[side]["points"]
        d, j = cKDTree(tp).query(mp)
        assert d.max() < 1e-9, side
        assert np.array_equal(np.round(mc * 255), np.round(tc[j] * 255)), side


def test_crops_equal_open3d(scene, sfmeval_bin, tmp_path):
    """The SelectionPolygonVolume crop counts of both clouds equal Open3D's."""
    transform = tmp_path / "t.txt"
    np.savetxt(transform, scene["gt_from_recon"])
    rep = ours(sfmeval_bin, scene, scene["recon"] / "dense.ply", tmp_path / "o", "--transform", transform)
    vol = o3d.visualization.read_selection_polygon_volume(str(scene["scene"] / "Synth.json"))
    gt = o3d.io.read_point_cloud(str(scene["scene"] / "Synth.ply"))
    recon = o3d.io.read_point_cloud(str(scene["recon"] / "dense.ply"))
    recon.transform(scene["gt_from_recon"])
    assert rep["recall"]["cropped_points"] == len(vol.crop_point_cloud(gt).points)
    assert rep["precision"]["cropped_points"] == len(vol.crop_point_cloud(recon).points)
    assert 0 < rep["recall"]["cropped_points"] < len(gt.points)  # the crop cuts something
    # The same crop file through `sfmeval eval --crop` keeps Open3D's count too.
    report = tmp_path / "eval.json"
    p = subprocess.run([sfmeval_bin, "eval", "--gt", str(ROOT / "data/demo/ground_truth.glb"),
                        "--recon", str(scene["recon"] / "dense.ply"), "--transform", str(transform),
                        "--align", "given", "--crop", str(scene["scene"] / "Synth.json"),
                        "--samples", "1000", "--report", str(report), "--quiet"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    crop = json.loads(report.read_text())["crop"]
    assert crop["kind"] == "polygon_prism"
    assert crop["kept"] == len(vol.crop_point_cloud(recon).points)


def test_notes_are_typed(scene, sfmeval_bin, tmp_path):
    """A reconstruction moved out of the crop: precision, recall and F are 0 and the report says
    why in a typed note (code, level, values), which the summary prints at its level."""
    far = scene["gt_from_recon"].copy()
    far[:3, 3] += 1000.0 * scene["tau"]
    transform = tmp_path / "far.txt"
    np.savetxt(transform, far)
    rep = ours(sfmeval_bin, scene, scene["recon"] / "dense.ply", tmp_path / "o", "--transform", transform)
    assert rep["precision"]["value"] == rep["recall"]["value"] == rep["f_score"] == 0
    codes = [n["code"] for n in rep["notes"]]
    assert "tanksandtemples.nothing_in_crop" in codes, rep["notes"]
    note = rep["notes"][codes.index("tanksandtemples.nothing_in_crop")]
    assert note["level"] == "warning" and "crop" in note["message"]
    p = subprocess.run([sfmeval_bin, "tnt", "--scene", str(scene["scene"]), "--recon",
                        str(scene["recon"] / "dense.ply"), "--tau", str(scene["tau"]),
                        "--transform", str(transform), "--out", str(tmp_path / "o2")],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert f"warning: {note['message']}" in p.stdout, p.stdout


def test_whole_protocol_within_half_a_point(scene, sfmeval_bin, tmp_path):
    recon = scene["recon"] / "dense.ply"
    theirs = toolbox("run", scene["scene"], scene["log"], recon, tmp_path / "toolbox", scene["tau"])
    rep = ours(sfmeval_bin, scene, recon, tmp_path / "ours", "--trajectory", scene["log"])
    reg = rep["registration"]
    assert reg["mode"] == "protocol" and len(reg["refinement"]) == 3
    assert reg["trajectory_alignment"]["fitness"] == 1.0
    for key, mine in [("precision", rep["precision"]["value"]), ("recall", rep["recall"]["value"]),
                      ("f_score", rep["f_score"])]:
        assert abs(mine - theirs[key]) <= 0.005, (key, mine, theirs[key])
    # The registration found the pycolmap frame: the final transform is close to the one from
    # the cameras (scale within 1 %, centres of the recon within 2 τ).
    final = np.array(reg["gt_from_recon"])
    pts = np.asarray(o3d.io.read_point_cloud(str(recon)).points)[::50]
    moved = pts @ final[:3, :3].T + final[:3, 3]
    expected = pts @ scene["gt_from_recon"][:3, :3].T + scene["gt_from_recon"][:3, 3]
    assert np.median(np.linalg.norm(moved - expected, axis=1)) < 2 * scene["tau"]


def test_trajectory_longer_than_the_reference_as_the_toolbox(scene, sfmeval_bin, tmp_path):
    """A `.log` with frames beyond the reference's (here four of its frames again at the end):
    the toolbox pairs the first frames with the reference's and scores every frame; so do we."""
    lines = scene["log"].read_text().splitlines(keepends=True)
    longer = tmp_path / "longer.log"
    longer.write_text("".join(lines + lines[:4 * 5]))
    recon = scene["recon"] / "dense.ply"
    theirs = toolbox("run", scene["scene"], longer, recon, tmp_path / "toolbox", scene["tau"])
    rep = ours(sfmeval_bin, scene, recon, tmp_path / "ours", "--trajectory", longer)
    reg = rep["registration"]
    # the repeated frames lie on their reference centres: all 40 count and all match
    assert reg["trajectory_alignment"]["fitness"] == 1.0, reg["trajectory_alignment"]
    for key, mine in [("precision", rep["precision"]["value"]), ("recall", rep["recall"]["value"]),
                      ("f_score", rep["f_score"])]:
        assert abs(mine - theirs[key]) <= 0.005, (key, mine, theirs[key])
    # The precision/recall plot under the toolbox's name, as SVG and PNG.
    from PIL import Image
    import xml.etree.ElementTree as ET
    stems = {p.stem for p in (tmp_path / "toolbox").glob("PR_*.png")}
    assert stems and stems == {p.stem for p in (tmp_path / "ours").glob("PR_*.png")}
    stem = stems.pop()
    assert Image.open(tmp_path / "ours" / f"{stem}.png").size == (720, 480)
    svg = ET.parse(tmp_path / "ours" / f"{stem}.svg").getroot()
    paths = [e for e in svg.iter() if e.tag.endswith("path")]
    # one vertex per curve value, for each of the two curves
    assert [len(p.get("d").split("L")) for p in paths] == [len(rep["curves"]["precision"]),
                                                           len(rep["curves"]["recall"])]
    title = "".join(e.text or "" for e in svg.iter() if e.tag.endswith("text"))
    assert f"{rep['f_score'] * 100:.2f} f-score" in title


def test_errors_name_the_file(scene, sfmeval_bin, tmp_path):
    import shutil

    bad = tmp_path / "Synth"
    shutil.copytree(scene["scene"], bad)
    (bad / "Synth_trans.txt").unlink()
    run = lambda *a: subprocess.run([sfmeval_bin, "tnt", *map(str, a)], capture_output=True, text=True)
    p = run("--scene", bad, "--recon", scene["recon"] / "dense.ply", "--trajectory", scene["log"])
    assert p.returncode == 1 and "Synth_trans.txt" in p.stderr, p.stderr
    # A trajectory with a frame short.
    short = tmp_path / "short.log"
    short.write_text("".join(scene["log"].read_text().splitlines(keepends=True)[:35 * 5]))
    p = run("--scene", scene["scene"], "--recon", scene["recon"] / "dense.ply", "--trajectory", short,
            "--tau", scene["tau"])
    assert p.returncode == 1 and "35 frames" in p.stderr and "36" in p.stderr, p.stderr
    # the trajectory's content is wrong, not an option: the message names the file
    assert "short.log" in p.stderr and "invalid option" not in p.stderr, p.stderr
    # A scene the benchmark's τ table does not know needs --tau.
    p = run("--scene", scene["scene"], "--recon", scene["recon"] / "dense.ply", "--trajectory", scene["log"])
    assert p.returncode == 1 and "give τ" in p.stderr, p.stderr
    # A broken crop file names itself.
    (bad / "Synth_trans.txt").write_text((scene["scene"] / "Synth_trans.txt").read_text())
    (bad / "Synth.json").write_text('{"class_name": "SelectionPolygonVolume", "orthogonal_axis": "Q"}')
    p = run("--scene", bad, "--recon", scene["recon"] / "dense.ply", "--trajectory", scene["log"], "--tau", 0.01)
    assert p.returncode == 1 and "Synth.json" in p.stderr, p.stderr


MODELS = ROOT / "tests" / "fixtures" / "models"


@pytest.mark.parametrize("model,reference", [
    ("colmap_bin", "colmap_bin"), ("colmap_text", "colmap_bin"), ("colmap38.nvm", "colmap_bin"),
    ("colmap38.bundle.out", "colmap_bin"), ("theia.nvm", "theia_colmap"),
    ("openmvg_sfm_data.json", "openmvg_colmap")])
def test_log_from_every_model_format(sfmeval_bin, tmp_path, model, reference):
    """`sfmeval log` on models written by COLMAP 3.8, pycolmap, pytheia (and OpenMVG's layout):
    each frame's centre is pycolmap's for the same model, a frame per listed image."""
    import pycolmap

    sys.path.insert(0, str(tnt_scene.TOOLBOX))
    import trajectory_io

    names = sorted(im["name"] for im in json.loads((MODELS / "gt_cameras.json").read_text())["images"])
    listed = tmp_path / "images.txt"
    listed.write_text("".join(n + "\n" for n in names))
    log = tmp_path / "m.log"
    p = subprocess.run([sfmeval_bin, "log", "--model", str(MODELS / model), "--images", str(listed),
                        "--out", str(log)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    frames = trajectory_io.read_trajectory(str(log))
    assert len(frames) == len(names)
    ref = pycolmap.Reconstruction(str(MODELS / reference))
    centres = {im.name: im.projection_center() for im in ref.images.values()}
    registered = 0
    for k, (f, n) in enumerate(zip(frames, names)):
        meta = list(f.metadata)
        if meta[1] == -1:
            assert np.array_equal(f.pose, np.eye(4)), n
            continue
        registered += 1
        assert meta == [k, k, 0]
        c = centres[n]
        assert np.linalg.norm(f.pose[:3, 3] - c) <= 1e-5 * max(1.0, np.linalg.norm(c)), (model, n)
    assert registered >= len(centres) - 1 and registered >= 5, (model, registered)
