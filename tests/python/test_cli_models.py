"""Every SfM output format through `sfmeval eval`, bad models end to end, and PLY clouds with the
cameras of a model (`--recon-cameras`, or a folder holding both).

The fixtures (tests/fixtures/models, README.md there names the program that wrote each file) are
reconstructions of the scene render_scene.py ray-casts; the GT mesh is that scene's quads
(`scene_obj`), the GT cameras gt_cameras.json. Expected camera transforms are numpy Umeyama fits
of the centres parsed here from each file; PLY results are compared with the same points read
from the matching model.

Measured: 4.4 s on 2 cores (release binary), 17 tests.
"""
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from test_cli_align import (apply, cameras_json_centres, colmap_centres, quat_to_rot,
                            scene_obj, umeyama_np)

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "tests" / "fixtures" / "models"
GT_CAMERAS = MODELS / "gt_cameras.json"
ORBIT = 4.5  # render_scene.py: cameras 4.5 from the z axis


# ---------------------------------------------------------------- centres parsed with numpy

def nvm_centres(path):
    """NVM v3: `name f qw qx qy qz cx cy cz r 0`, the centre written directly (first model)."""
    lines = [ln for ln in Path(path).read_text().splitlines() if ln.strip()]
    n = int(lines[1])
    return {w[0]: np.array(w[6:9], float) for w in (ln.split() for ln in lines[2:2 + n])}


def bundler_centres(path, list_path):
    """Bundler v0.3: per camera `f k1 k2`, 3 rows of R, t; centre -Rᵀt; names from list.txt."""
    rows = [ln.split() for ln in Path(path).read_text().splitlines()
            if ln.strip() and not ln.startswith("#")]
    n = int(rows[0][0])
    names = [ln.split()[0] for ln in Path(list_path).read_text().splitlines() if ln.strip()]
    out = {}
    for i in range(n):
        b = rows[1 + 5 * i: 6 + 5 * i]
        if float(b[0][0]) == 0:
            continue
        r, t = np.array(b[1:4], float), np.array(b[4], float)
        out[names[i]] = -r.T @ t
    return out


def openmvg_centres(path):
    d = json.loads(Path(path).read_text())
    centre = {e["key"]: np.array(e["value"]["center"]) for e in d["extrinsics"]}
    out = {}
    for v in d["views"]:
        data = v["value"]["ptr_wrapper"]["data"]
        if data["id_pose"] in centre:
            out[data["filename"]] = centre[data["id_pose"]]
    return out


def ply_vertex_count(path):
    for ln in Path(path).read_bytes().split(b"end_header")[0].decode().splitlines():
        if ln.startswith("element vertex"):
            return int(ln.split()[2])
    raise AssertionError(f"no vertex element in {path}")


GT = cameras_json_centres(GT_CAMERAS)


def umeyama_to_gt(centres):
    names = sorted(centres)
    src = np.array([centres[n] for n in names])
    return umeyama_np(src, np.array([GT[n] for n in names])), src, names


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    return scene_obj(tmp_path_factory.mktemp("scene") / "scene.obj")


def run_cli(sfmeval_bin, *args):
    return subprocess.run([sfmeval_bin, *map(str, args)], capture_output=True, text=True)


# ---------------------------------------------------------------- every format

MODEL_CASES = {
    "colmap_text": (MODELS / "colmap_text", "colmap",
                    lambda: colmap_centres(MODELS / "colmap_text" / "images.txt")),
    "colmap_bin": (MODELS / "colmap_bin", "colmap_binary",
                   lambda: colmap_centres(MODELS / "colmap_text" / "images.txt")),
    "colmap38.nvm": (MODELS / "colmap38.nvm", "nvm",
                     lambda: nvm_centres(MODELS / "colmap38.nvm")),
    "theia.nvm": (MODELS / "theia.nvm", "nvm", lambda: nvm_centres(MODELS / "theia.nvm")),
    "bundler": (MODELS / "colmap38.bundle.out", "bundler",
                lambda: bundler_centres(MODELS / "colmap38.bundle.out",
                                        MODELS / "colmap38.list.txt")),
    "openmvg": (MODELS / "openmvg_sfm_data.json", "openmvg",
                lambda: openmvg_centres(MODELS / "openmvg_sfm_data.json")),
}


@pytest.mark.parametrize("case", list(MODEL_CASES))
def test_every_model_format_aligns_its_cameras_onto_the_gt(case, scene, run_eval):
    path, fmt, centres_of = MODEL_CASES[case]
    centres = centres_of()
    expect, src, names = umeyama_to_gt(centres)
    rep, _ = run_eval(scene, path, "--align", "cameras", "--gt-cameras", GT_CAMERAS,
                      "--samples", 20000)
    assert rep["inputs"]["reconstruction"]["format"] == fmt
    cams = rep["cameras"]
    assert cams["registered"] == cams["matched"] == len(names) >= 6
    m = np.array(rep["alignment"]["gt_from_recon"])
    assert rep["alignment"]["inlier_ratio"] == 1.0
    np.testing.assert_allclose(m, expect, atol=1e-7 * np.abs(expect).max())
    err = np.linalg.norm(apply(m, src) - np.array([GT[n] for n in names]), axis=1)
    assert err.max() < 0.01 * ORBIT, err
    np.testing.assert_allclose(cams["center_error"]["max"], err.max(), rtol=1e-5)
    # The points land on the scene (the walls are 5 units wide).
    assert rep["accuracy"]["median"] < 0.05, rep["accuracy"]


def test_converted_models_measure_the_same_points(scene, run_eval):
    """COLMAP text/binary, COLMAP 3.8's NVM and Bundler exports and Theia's NVM hold the same
    101 points and 6 poses (written with 6-17 digits): the same accuracy after alignment."""
    medians = {}
    for case in ["colmap_text", "colmap_bin", "colmap38.nvm", "theia.nvm", "bundler"]:
        rep, _ = run_eval(scene, MODEL_CASES[case][0], "--align", "cameras",
                          "--gt-cameras", GT_CAMERAS, "--samples", 20000)
        assert rep["accuracy"]["count"] == 101, case
        medians[case] = (rep["accuracy"]["median"], rep["accuracy"]["max"])
    ref = np.array(medians["colmap_text"])
    for case, v in medians.items():
        np.testing.assert_allclose(v, ref, rtol=1e-3, err_msg=case)


PLY_CASES = {
    "theia.ply": (MODELS / "theia.ply", MODELS / "theia.nvm",
                  lambda: nvm_centres(MODELS / "theia.nvm")),
    "openmvg.ply": (MODELS / "openmvg.ply", MODELS / "openmvg_colmap",
                    lambda: colmap_centres(MODELS / "openmvg_colmap" / "images.txt")),
}


@pytest.mark.parametrize("case", list(PLY_CASES))
def test_ply_camera_centres_are_removed_and_counted(case, scene, run_eval, tmp_path):
    """A bare PLY from Theia (red centres) or openmvg-rs (green centres): the warning names the
    removed count, which is the number of cameras of the matching model; with that model's
    camera alignment the PLY measures exactly like the model's own points."""
    ply, model, centres_of = PLY_CASES[case]
    centres = centres_of()
    expect, _, _ = umeyama_to_gt(centres)
    (tmp_path / "t.txt").write_text("\n".join(" ".join(map(repr, r)) for r in expect) + "\n")
    rep, _ = run_eval(scene, ply, "--transform", tmp_path / "t.txt", "--samples", 20000)
    n = len(centres)
    assert n == 6
    removed = [w for w in [n["message"] for n in rep["notes"]] if f"removed {n} point(s)" in w]
    assert len(removed) == 1, [n["message"] for n in rep["notes"]]
    assert rep["inputs"]["reconstruction"]["points"] == ply_vertex_count(ply) - n
    ref, _ = run_eval(scene, model, "--transform", tmp_path / "t.txt", "--samples", 20000)
    assert rep["accuracy"]["count"] == ref["accuracy"]["count"]
    for k in ["median", "max", "mean"]:
        np.testing.assert_allclose(rep["accuracy"][k], ref["accuracy"][k], rtol=1e-4)


# ---------------------------------------------------------------- PLY + model cameras

def recoloured_theia_ply(path, colour=(10, 200, 30)):
    """theia.ply with its 6 red camera centres in a colour that is no OpenMVG marker."""
    head, body = (MODELS / "theia.ply").read_text().split("end_header\n")
    rows = [ln.split() for ln in body.splitlines() if ln.strip()]
    red = [i for i, r in enumerate(rows) if r[3:] == ["255", "0", "0"]]
    assert len(red) == 6
    for i in red:
        rows[i][3:] = [str(c) for c in colour]
    Path(path).write_text(head + "end_header\n" + "".join(" ".join(r) + "\n" for r in rows))
    return path


def test_ply_with_model_cameras_is_stripped_at_the_centres(scene, run_eval, tmp_path):
    ply = recoloured_theia_ply(tmp_path / "points.ply")
    # Alone: the recoloured centres are not markers, nothing is removed.
    rep, _ = run_eval(scene, ply, "--samples", 20000)
    assert rep["inputs"]["reconstruction"]["points"] == 107
    assert not any("removed" in w for w in [n["message"] for n in rep["notes"]]), [n["message"] for n in rep["notes"]]
    # The reference: theia.nvm's own points and cameras.
    ref, _ = run_eval(scene, MODELS / "theia.nvm", "--align", "cameras",
                      "--gt-cameras", GT_CAMERAS, "--samples", 20000)
    folder = tmp_path / "theia_out"
    folder.mkdir()
    (folder / "reconstruction.nvm").write_bytes((MODELS / "theia.nvm").read_bytes())
    (folder / "points.ply").write_bytes(ply.read_bytes())
    for recon, extra in [(ply, ["--recon-cameras", MODELS / "theia.nvm"]), (folder, [])]:
        rep, _ = run_eval(scene, recon, "--align", "cameras", "--gt-cameras", GT_CAMERAS,
                          "--samples", 20000, *extra)
        inp = rep["inputs"]["reconstruction"]
        assert (inp["format"], inp["points"], inp["images"]) == ("ply+nvm", 101, 6)
        assert any("removed 6 point(s) at the 6 known camera centre(s)" in w
                   for w in [n["message"] for n in rep["notes"]]), [n["message"] for n in rep["notes"]]
        assert rep["cameras"]["matched"] == 6
        np.testing.assert_allclose(rep["alignment"]["gt_from_recon"],
                                   ref["alignment"]["gt_from_recon"], rtol=0, atol=1e-12)
        for k in ["median", "max"]:
            np.testing.assert_allclose(rep["accuracy"][k], ref["accuracy"][k], rtol=1e-4)
        np.testing.assert_allclose(rep["cameras"]["center_error"]["max"],
                                   ref["cameras"]["center_error"]["max"], rtol=1e-12)


def test_ply_with_model_cameras_errors(scene, sfmeval_bin, tmp_path):
    base = ["eval", "--gt", scene, "--quiet", "--align", "none"]
    # Two PLYs beside a model: ambiguous.
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "reconstruction.nvm").write_bytes((MODELS / "theia.nvm").read_bytes())
    (folder / "a.ply").write_bytes((MODELS / "theia.ply").read_bytes())
    (folder / "b.ply").write_bytes((MODELS / "openmvg.ply").read_bytes())
    p = run_cli(sfmeval_bin, *base, "--recon", folder)
    assert p.returncode == 1 and str(folder) in p.stderr and "2 PLY files" in p.stderr, p.stderr
    # --recon-cameras beside a model (not a cloud).
    p = run_cli(sfmeval_bin, *base, "--recon", MODELS / "colmap38.nvm",
                "--recon-cameras", MODELS / "theia.nvm")
    assert p.returncode == 1 and "is an SfM model" in p.stderr, p.stderr
    # --recon-cameras that is no model.
    p = run_cli(sfmeval_bin, *base, "--recon", MODELS / "theia.ply",
                "--recon-cameras", MODELS / "openmvg.ply")
    assert p.returncode == 1 and "openmvg.ply" in p.stderr, p.stderr


# ---------------------------------------------------------------- bad models end to end

def edited_model(tmp_path, name, edit_images=None, empty=False):
    d = tmp_path / name
    d.mkdir()
    for f in (MODELS / "colmap_text").iterdir():
        (d / f.name).write_bytes(f.read_bytes())
    lines = (d / "images.txt").read_text().splitlines()
    data = [i for i, ln in enumerate(lines) if not ln.startswith("#")][::2]
    if empty:
        for f in ["images.txt", "points3D.txt", "frames.txt"]:
            text = (d / f).read_text().splitlines()
            (d / f).write_text("".join(ln + "\n" for ln in text if ln.startswith("#")))
    if edit_images:
        for k, i in enumerate(data):
            lines[i] = " ".join(edit_images(k, lines[i].split()))
        (d / "images.txt").write_text("\n".join(lines) + "\n")
    return d


def rename_except(keep):
    def edit(k, w):
        if k >= keep:
            w[9] = "x_" + w[9]
        return w
    return edit


def same_centre(k, w):
    r = quat_to_rot([float(v) for v in w[1:5]])
    w[5:8] = [repr(float(v)) for v in -r @ np.array([1.0, 2.0, 3.0])]
    return w


def nan_pose(k, w):
    if k == 2:
        w[6] = "nan"
    return w


def run_bad(sfmeval_bin, scene, recon, align, tmp_path):
    report = tmp_path / f"{align}.json"
    p = run_cli(sfmeval_bin, "eval", "--gt", scene, "--recon", recon, "--gt-cameras", GT_CAMERAS,
                "--align", align, "--quiet", "--samples", 5000, "--report", report)
    assert "panicked" not in p.stderr and p.returncode in (0, 1), p.stderr
    if p.returncode == 0:
        return p, json.loads(report.read_text())
    assert str(recon) in p.stderr, p.stderr  # the error names the model
    return p, None


def test_one_matched_camera_falls_back_to_global_or_errors(sfmeval_bin, scene, tmp_path):
    d = edited_model(tmp_path, "one", rename_except(1))
    p, rep = run_bad(sfmeval_bin, scene, d, "auto", tmp_path)
    assert rep["alignment"]["method"] == "global+icp"
    notes = rep["notes"]
    assert any(n["code"] == "alignment.stage_failed" and n["values"]["stage"] == "cameras"
               and n["values"]["error"].startswith("unusable geometry: only 1 matched camera")
               for n in notes), notes
    assert any(n["code"] == "alignment.fell_back" and n["values"]["to"] == "global"
               for n in notes), notes
    assert any("only 1 camera(s) matched" in w for w in [n["message"] for n in rep["notes"]]), [n["message"] for n in rep["notes"]]
    p, rep = run_bad(sfmeval_bin, scene, d, "cameras", tmp_path)
    assert rep is None and "needs at least 3 (2 with orientations)" in p.stderr, p.stderr


def test_two_matched_cameras_use_their_orientations(sfmeval_bin, scene, tmp_path):
    """2 matched cameras: rotation from the orientations, scale and translation from the two
    centres; said in the warnings, and still close to the 6-camera fit."""
    d = edited_model(tmp_path, "two", rename_except(2))
    p, rep = run_bad(sfmeval_bin, scene, d, "cameras", tmp_path)
    assert any("fewer than 3" in w and "orientations" in w for w in [n["message"] for n in rep["notes"]]), rep
    assert any("only 2 camera(s) matched" in w for w in [n["message"] for n in rep["notes"]]), [n["message"] for n in rep["notes"]]
    full, src, names = umeyama_to_gt(colmap_centres(MODELS / "colmap_text" / "images.txt"))
    m = np.array(rep["alignment"]["gt_from_recon"])
    err = np.linalg.norm(apply(m, src) - np.array([GT[n] for n in names]), axis=1)
    assert err.max() < 0.05 * ORBIT, err


def test_identical_centres_fall_back_or_error(sfmeval_bin, scene, tmp_path):
    d = edited_model(tmp_path, "same", same_centre)
    p, rep = run_bad(sfmeval_bin, scene, d, "auto", tmp_path)
    notes = rep["notes"]
    assert any(n["code"] == "alignment.stage_failed" and "coincide" in n["message"]
               for n in notes), notes
    assert any(n["code"] == "alignment.fell_back" and n["values"]["to"] == "global"
               for n in notes), notes
    assert rep["alignment"]["stages"][0]["method"] == "global"
    p, rep = run_bad(sfmeval_bin, scene, d, "cameras", tmp_path)
    assert rep is None and "coincide" in p.stderr, p.stderr


def test_nan_pose_is_a_clear_error(sfmeval_bin, scene, tmp_path):
    d = edited_model(tmp_path, "nan", nan_pose)
    for align in ["auto", "cameras"]:
        p, rep = run_bad(sfmeval_bin, scene, d, align, tmp_path)
        assert rep is None and "non-finite" in p.stderr, p.stderr


def test_no_name_match_skips_cameras_with_a_warning(sfmeval_bin, scene, tmp_path):
    d = edited_model(tmp_path, "nomatch", rename_except(0))
    p, rep = run_bad(sfmeval_bin, scene, d, "auto", tmp_path)
    assert rep.get("cameras") is None
    assert any(w.startswith("cameras: none of the 6 estimated image(s) matches")
               and "estimate 'x_" in w for w in [n["message"] for n in rep["notes"]]), [n["message"] for n in rep["notes"]]
    notes = rep["notes"]
    assert any(n["code"] == "alignment.stage_failed" and n["values"]["stage"] == "cameras"
               and "skipped" in n["message"] for n in notes), notes
    assert any(n["code"] == "alignment.fell_back" and n["values"]["to"] == "global"
               for n in notes), notes
    assert rep["alignment"]["method"] == "global+icp"
    p, rep = run_bad(sfmeval_bin, scene, d, "cameras", tmp_path)
    assert rep is None and "none of the 6 estimated image(s) matches" in p.stderr, p.stderr
    p = run_cli(sfmeval_bin, "cameras", "--gt-cameras", GT_CAMERAS, "--recon", d)
    assert p.returncode == 1 and str(d) in p.stderr and "none of the 6" in p.stderr, p.stderr


def test_empty_model_is_a_clear_error(sfmeval_bin, scene, tmp_path):
    d = edited_model(tmp_path, "empty", empty=True)
    for align in ["auto", "none"]:
        p, rep = run_bad(sfmeval_bin, scene, d, align, tmp_path)
        assert rep is None and "no registered image and no 3D point" in p.stderr, p.stderr
