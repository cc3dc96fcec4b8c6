"""Steps 7–11 of the add-on ("Compare pipelines"), headless in both Blenders, checked against
the `sfmeval` CLI run by the test itself.

One tiny dataset (24 views, 640×360, 4 spp) is rendered per session. In PyPI bpy (Blender 5)
the operator runs two real pipelines (pycolmap, pycolmap-global) through `sfmeval-runner`;
Debian's Blender 3.4 imports those same run folders (pre-made by the bpy test, to stay in the CI
budget) and does the rest of the workflow itself. Beside the real runs: a failed run (a custom
pipeline that exits 1, run by the real runner) and a corrupt one (a truncated sparse.ply).
The crop sphere is checked on its own, on data/demo's model (no rendering).
"""

import json
import math
import os
import shutil
import shlex
import signal
import subprocess
import sys

import numpy as np
import pytest

from blender_testlib import BLENDER_SCRIPTS, REPO, have_bpy, release_bins, run_generate

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "blender_compare_script.py")
SPHERE_SCRIPT = os.path.join(os.path.dirname(SCRIPT), "blender_crop_sphere_script.py")
TINY = ["--preset", "small", "--set", "render.samples=4", "--set", "outputs.depth=false",
        "--set", "views.orbits=[{elevation_deg=20.0,count=12},"
                 "{elevation_deg=45.0,count=12,azimuth_offset_deg=10.0}]"]
GLTF_FROM_BLENDER = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], float)
REAL = ["pycolmap", "pycolmap-global"]


@pytest.fixture(scope="module")
def bins():
    return release_bins()


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    assert have_bpy(), "PyPI bpy is not installed: cannot render the test dataset"
    out = str(tmp_path_factory.mktemp("compare") / "tiny")
    proc = run_generate(TINY + ["--out", out])
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    sys.stderr.write("\n[compare] tiny dataset rendered in %.0f s\n" % proc.seconds)
    return out


@pytest.fixture(scope="module")
def addon_zip(tmp_path_factory):
    out = tmp_path_factory.mktemp("dist")
    proc = subprocess.run([sys.executable, os.path.join(BLENDER_SCRIPTS, "build_addon.py"),
                           "--out", str(out)], capture_output=True, text=True, check=True)
    return proc.stdout.strip()


def _dataset_copy(tiny, dest):
    shutil.copytree(tiny, dest, ignore=shutil.ignore_patterns("runs", "compare"))
    return str(dest)


def _add_bad_runs(bins, ds):
    """A real failed run (custom pipeline `bad` exits 1) and a corrupt one (`zz-corrupt`: a
    run.json saying ok, a truncated sparse.ply)."""
    runs = os.path.join(ds, "runs")
    proc = subprocess.run([bins["runner"], "run", "--datasets", ds, "--out", runs,
                           "--pipelines", "bad", "--custom", "bad=false {images} {out}"],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    base = os.path.join(runs, os.path.basename(ds))
    with open(os.path.join(base, "bad", "run.json")) as f:
        rec = json.load(f)
    assert rec["status"] == "failed", rec
    rec.update(status="ok", reason=None, pipeline="zz-corrupt")
    os.makedirs(os.path.join(base, "zz-corrupt"))
    with open(os.path.join(base, "zz-corrupt", "run.json"), "w") as f:
        json.dump(rec, f)
    with open(os.path.join(base, "zz-corrupt", "sparse.ply"), "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\n"
                b"property float y\nproperty float z\nend_header\n" + b"\0" * 10)
    return rec


def _run_script(tmp_path, blender, addon_zip, ds, mode, bins):
    out = str(tmp_path / "result.json")
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(tmp_path / "user_scripts"),
               BLENDER_USER_CONFIG=str(tmp_path / "user_config"))
    args = [addon_zip, ds, mode, out, bins["sfmeval"], bins["runner"]]
    if blender == "bpy":
        cmd = [sys.executable, SCRIPT] + args
    else:
        exe = shutil.which("blender")
        assert exe, "Debian blender not installed (apt-get install blender python3-numpy)"
        cmd = [exe, "-b", "--factory-startup", "-noaudio", "--python-exit-code", "1",
               "-P", SCRIPT, "--"] + args
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=900)
    assert proc.returncode == 0 and "COMPARE DONE" in proc.stdout, \
        proc.stdout[-4000:] + proc.stderr[-4000:]
    with open(out) as f:
        return json.load(f)


@pytest.fixture(scope="module")
def bpy_result(tmp_path_factory, tiny, addon_zip, bins):
    tmp = tmp_path_factory.mktemp("bpy")
    ds = _dataset_copy(tiny, tmp / "tiny")
    _add_bad_runs(bins, ds)
    return ds, _run_script(tmp, "bpy", addon_zip, ds, "run", bins)


def _eval(bins, ds, item, tmp_path):
    """The test's own `sfmeval eval` on the add-on's points and crop file, with the object's
    alignment written by the test."""
    t = tmp_path / "transform.txt"
    m = np.array(item["stored"]).reshape(4, 4)
    t.write_text("".join(" ".join(repr(float(v)) for v in row) + "\n" for row in m))
    work = os.path.dirname(item["report"])
    mine = tmp_path / "report.json"
    csv = tmp_path / "d.csv"
    colored = tmp_path / "colored.ply"
    argv = [bins["sfmeval"], "eval", "--dataset", ds, "--recon", os.path.join(work, "points.ply"),
            "--recon-cameras", item["cameras_source"], "--crop",
            os.path.join(ds, "compare", "crop.json"), "--align", "given", "--transform", str(t),
            "--report", str(mine), "--csv", str(csv), "--colored", str(colored), "--quiet"]
    subprocess.run(argv, check=True, capture_output=True)
    import csv as csvmod
    with open(csv, newline="") as f:
        rows = list(csvmod.DictReader(f))
    return mine, rows, colored


def _read_ply(path):
    import trimesh
    return trimesh.load(str(path), process=False)


def _check(res, ds, bins, tmp_path, ran):
    base = os.path.join(ds, "runs", os.path.basename(ds))
    # a missing binary: a message naming it and what to build, in the panel
    assert "/nonexistent/sfmeval-runner" in res["missing_runner_msg"]
    assert "cargo build --release -p sfmeval-runner" in res["missing_runner_msg"]
    assert "cargo build --release -p sfmeval-cli" in res["missing_sfmeval_msg"]
    assert any("/nonexistent/sfmeval " in x or x.startswith("sfmeval: ")
               for x in res["missing_labels"]), res["missing_labels"]
    if ran:
        assert res["pipelines"]["pycolmap"] and res["pipelines"]["pycolmap-global"]
        for p in REAL:
            state, elapsed, msg = res["states"][p]
            assert state == "ok" and elapsed > 0, (p, state, msg)
            with open(os.path.join(base, p, "run.json")) as f:
                rec = json.load(f)
            assert rec["schema"] == "sfmeval.run/1" and rec["status"] == "ok"
            assert rec["options"]["intrinsics"] == "known", rec["options"]
        assert "sfmeval-runner run --datasets" in res["log"] and "ok in" in res["log"]
    # a failed run and a corrupt file: a row each with the reason; the real rows are there
    assert res["ok"] == REAL
    for p in REAL:  # drawn as points (geometry nodes), the mesh itself untouched
        assert res["display"][p] == ["", ["NODES"]], res["display"][p]
    assert res["rows"]["bad"][0] == "failed" and "exit" in res["rows"]["bad"][1]
    assert res["rows"]["zz-corrupt"][0] == "failed"
    assert os.path.join("zz-corrupt", "sparse.ply") in res["rows"]["zz-corrupt"][1]
    # imported vertex count = the report's count = the points of sparse.ply (trimesh)
    for p in REAL:
        n = len(_read_ply(os.path.join(base, p, "sparse.ply")).vertices)
        assert res["imported_vertices"][p] == n
        assert res["first_reports"][p]["inputs"]["reconstruction"]["points"] == n
        with open(os.path.join(base, p, "cameras.json")) as f:
            assert res["cameras"][p] == len(json.load(f)["images"])
    # Edit Mode deletions: the mesh, the exported PLY and the report lose exactly those points
    first = res["items"]["pycolmap"]
    assert first["vertices"] == res["imported_vertices"]["pycolmap"] - res["deleted"]
    kept = np.array(res["kept_expected"], np.float32)
    assert np.array_equal(np.array(first["co"], np.float32), kept)
    exported = _read_ply(os.path.join(os.path.dirname(first["report"]), "points.ply")).vertices
    assert np.array_equal(np.asarray(exported, np.float32), kept)
    # the crop file is the box as placed: centre, axes and half sizes in the glTF frame
    with open(os.path.join(ds, "compare", "crop.json")) as f:
        crop = json.load(f)
    M = np.array(res["crop_matrix"])
    vol = crop["volume"]
    assert crop["schema"] == "sfmeval.crop/1" and crop["max_distance"] == pytest.approx(0.05)
    assert vol["kind"] == "oriented_box"
    assert np.allclose(vol["center"], GLTF_FROM_BLENDER @ M[:3, 3], atol=1e-7)
    scale = np.linalg.norm(M[:3, :3], axis=0)
    assert np.allclose(vol["half_extents"], scale, atol=1e-7)
    assert np.allclose(vol["rotation"], GLTF_FROM_BLENDER @ (M[:3, :3] / scale), atol=1e-7)
    # Refine (ICP) from 3° and 2 % off converges to the automatic answer
    auto, start, ref = (np.array(res[k]) for k in ("auto", "start", "refined"))

    def angle_scale(a, b):
        sa, sb = np.cbrt(np.linalg.det(a[:3, :3])), np.cbrt(np.linalg.det(b[:3, :3]))
        r = (a[:3, :3] / sa).T @ (b[:3, :3] / sb)
        return math.degrees(math.acos(min(1.0, (np.trace(r) - 1) / 2))), sb / sa - 1

    assert np.allclose(res["start_seen"], start, rtol=1e-5, atol=1e-5)
    a0, s0 = angle_scale(auto, start)
    assert a0 == pytest.approx(3.0, abs=0.01) and s0 == pytest.approx(0.02, abs=1e-6)
    a1, s1 = angle_scale(auto, ref)
    assert a1 < 0.05 and abs(s1) < 0.0005, (a1, s1)
    # per reconstruction: matrix, report, colours, panel numbers = the CLI's
    B = np.eye(4)
    B[:3, :3] = GLTF_FROM_BLENDER.T
    for p in REAL:
        item = res["items"][p]
        with open(item["report"], "rb") as f:
            raw = f.read()
        rep = json.loads(raw)
        T = np.array(rep["alignment"]["gt_from_recon"])
        assert rep["alignment"]["method"] == "given"
        # the CLI takes the given matrix as the nearest similarity (≈ 1e-7 here)
        assert np.allclose(np.array(item["stored"]).reshape(4, 4), T, rtol=1e-6, atol=1e-6)
        # Blender keeps the matrix as float32 location, Euler rotation and scale (~3e-6 here)
        assert np.allclose(item["matrix_basis"], T, rtol=1e-5, atol=1e-5)
        assert np.allclose(item["matrix_world"], B @ T, rtol=1e-5, atol=1e-5)
        assert rep["inputs"]["reconstruction"]["points"] == item["vertices"]
        assert rep["crop"]["kind"] == "oriented_box+max_distance"
        assert rep["crop"]["discarded_outside_volume"] > 0, rep["crop"]
        sub = tmp_path / p
        sub.mkdir()
        mine, rows, colored = _eval(bins, ds, item, sub)
        assert mine.read_bytes() == raw, "the add-on's report differs from the CLI's"
        d = np.array([float(r["distance"]) for r in rows])
        kept_mask = np.array([r["status"] == "kept" for r in rows])
        assert len(d) == item["vertices"]
        assert np.array_equal(np.array(item["distance"], np.float32), d.astype(np.float32))
        col = np.array(item["color"])
        cli = _read_ply(colored)
        cli_rgb = np.asarray(cli.visual.vertex_colors)[:, :3]
        assert kept_mask.sum() == len(cli_rgb) == rep["crop"]["kept"]
        assert np.array_equal(np.round(col[kept_mask, :3] * 255).astype(int), cli_rgb)
        assert np.all(col[~kept_mask, :3] == 0.5)
        s = item["summary"]
        acc = rep["accuracy"]
        assert (s["min"], s["max"], s["mean"], s["median"], s["std"]) == \
            (acc["min"], acc["max"], acc["mean"], acc["median"], acc["std"])
        assert s["points"] == rep["crop"]["kept"] and s["images"] == 24
        assert s["registered"] == rep["cameras"]["registered"]
        assert s["completeness"] == rep["completeness"]["mean"]
        assert s["ate"] == rep["cameras"]["ate_rmse"]
        f1 = [t for t in rep["thresholds"] if t["tau_percent_of_diagonal"] == 1.0][0]
        assert s["f1"] == f1["f_score"]
        assert p in res["labels"]
        assert "%.4g" % acc["mean"] in res["labels"]
        # Table I (file and text block): this report's mean and point count
        with open(os.path.join(ds, "compare", "table1.md"), encoding="utf-8") as f:
            md = f.read()
        assert "%.6f (%d)" % (acc["mean"], rep["inputs"]["reconstruction"]["points"]) in md
        with open(os.path.join(ds, "compare", "table1.csv"), encoding="utf-8") as f:
            csv_rows = f.read().splitlines()
        head, row = csv_rows[0].split(","), csv_rows[1].split(",")
        assert float(row[head.index("%s.mean_m" % p)]) == acc["mean"]
        assert md in res["table_text"]
    assert " bad |" in md and "failed: " in md
    # a COLMAP model folder imported as a file: its points3D.txt in the reconstruction's frame
    assert res["file_row"][0] == "imported", res["file_row"]
    with open(os.path.join(base, "pycolmap", "model", "points3D.txt")) as f:
        xyz = np.array([[float(v) for v in line.split()[1:4]] for line in f
                        if line.strip() and not line.startswith("#")])
    co = np.array(res["file_co"])
    assert co.shape == xyz.shape
    assert np.allclose(np.sort(co, axis=0), np.sort(xyz, axis=0), atol=1e-5)
    # the ground truth as a scene object (exported to compare/gt_scene.glb): the same numbers
    # as the dataset's GLB, without the crop
    assert res["gt_object_eval"] == res["gt_dataset_eval"] == ["FINISHED"]
    for p in REAL:
        rep = res["gt_object_reports"][p]
        assert rep["inputs"]["ground_truth"]["name"] == "gt_scene.glb"
        assert rep["crop"]["kind"] == "none"
        ref = res["gt_dataset_reports"][p]
        assert ref["inputs"]["ground_truth"]["name"] == "ground_truth.glb"
        assert rep["inputs"]["ground_truth"]["triangles"] == \
            ref["inputs"]["ground_truth"]["triangles"]
        assert rep["accuracy"]["mean"] == pytest.approx(ref["accuracy"]["mean"], rel=1e-5)


@pytest.mark.parametrize("blender", ["bpy", "debian"])
def test_compare_pipelines_workflow(blender, bpy_result, tiny, addon_zip, bins, tmp_path):
    if blender == "bpy":
        ds, res = bpy_result
        _check(res, ds, bins, tmp_path, ran=True)
        return
    # Blender 3.4: the bpy test's run folders (pre-made), the workflow from the import on
    src_ds, _ = bpy_result
    ds = _dataset_copy(tiny, tmp_path / "tiny")
    shutil.copytree(os.path.join(src_ds, "runs", os.path.basename(src_ds)),
                    os.path.join(ds, "runs", "tiny"))
    res = _run_script(tmp_path, "debian", addon_zip, ds, "premade", bins)
    assert res["blender"].startswith("3."), res["blender"]
    _check(res, ds, bins, tmp_path, ran=False)


def test_table1_is_the_runners_format(bpy_result, bins, tmp_path):
    """Table I the panel shows comes from `sfmeval table`: given the reports of
    `sfmeval-runner report` and its failed run, it writes table1.md and table1.csv byte for byte
    as the runner does (ok and failed runs, the runner's column order)."""
    src_ds, _ = bpy_result
    name = os.path.basename(src_ds)
    runs = tmp_path / "runs"
    for p in REAL + ["bad"]:
        shutil.copytree(os.path.join(src_ds, "runs", name, p), runs / name / p)
    table = tmp_path / "table"
    proc = subprocess.run([bins["runner"], "report", str(runs), "--out", str(table),
                           "--datasets", src_ds, "--samples", "20000"],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    sys.path.insert(0, BLENDER_SCRIPTS)
    from sfmeval_blender.compare import evaluate as ev
    reports, failed = [], []
    for p in REAL[::-1] + ["bad"]:
        with open(runs / name / p / "run.json") as f:
            rec = json.load(f)
        if rec["status"] == "ok":
            reports.append((p, str(table / "reports" / name / ("%s.json" % p))))
        else:
            failed.append((p, rec["reason"]))
    md, csv_text = ev.table(bins["sfmeval"], name, reports, failed, str(tmp_path / "mine"))
    assert md.encode() == (table / "table1.md").read_bytes()
    assert csv_text.encode() == (table / "table1.csv").read_bytes()


def test_cancel_ends_the_runner_and_its_tools(tiny, bins, tmp_path):
    """The panel's Cancel (run.Job.cancel) ends sfmeval-runner and the tool it started in a
    process group of its own (a custom pipeline sleeping 60 s), within seconds."""
    import time
    sys.path.insert(0, BLENDER_SCRIPTS)
    from sfmeval_blender.compare import run as runmod
    ds = _dataset_copy(tiny, tmp_path / "tiny")
    argv = runmod.run_command(bins["runner"], ds, str(tmp_path / "runs"), "slow", 600, "exif")
    job = runmod.Job(argv + ["--custom", "slow=sleep 61; echo {out}"])
    sleeper = None
    deadline = time.monotonic() + 20
    while sleeper is None and time.monotonic() < deadline:
        for pid in os.listdir("/proc"):
            try:
                with open("/proc/%s/cmdline" % pid, "rb") as f:
                    if f.read().split(b"\0")[:2] == [b"sleep", b"61"]:
                        sleeper = int(pid)
            except OSError:
                pass
        time.sleep(0.1)
    assert sleeper is not None, job.poll()
    assert os.getpgid(sleeper) != job.proc.pid, "the tool should be in a group of its own"
    t0 = time.monotonic()
    job.cancel()
    lines, rc = job.poll()
    assert rc is not None and time.monotonic() - t0 < 10
    time.sleep(0.2)
    assert not os.path.exists("/proc/%d" % sleeper) or \
        open("/proc/%d/stat" % sleeper).read().split(") ")[1].startswith("Z"), "sleep survived"
    # The runner is signalled before its tool, so it never sees the tool die and records
    # nothing for the cancelled run (it did, under load, when the tool's group went first).
    assert rc == -signal.SIGTERM, rc
    assert not list((tmp_path / "runs").rglob("run.json"))


def test_binaries_are_found_in_preferences_path_or_target_release(bins, tmp_path, monkeypatch):
    """tools.find: the preferences' path first (a wrong one is an error naming it, not a
    fallback), then PATH, then target/release of a repository above the working directory."""
    sys.path.insert(0, BLENDER_SCRIPTS)
    from sfmeval_blender.compare import tools
    assert tools.find("sfmeval", bins["sfmeval"]) == os.path.abspath(bins["sfmeval"])
    with pytest.raises(tools.ToolMissing, match="/nope/sfmeval.*cargo build --release -p "
                                                "sfmeval-cli"):
        tools.find("sfmeval", "/nope/sfmeval")
    fake = tmp_path / "bin" / "sfmeval-runner"
    fake.parent.mkdir()
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", str(fake.parent))
    assert tools.find("sfmeval-runner") == str(fake)
    # nothing on PATH: a repository's target/release above the working directory
    repo = tmp_path / "repo"
    (repo / "target" / "release").mkdir(parents=True)
    (repo / "sub").mkdir()
    shutil.copy(bins["sfmeval"], repo / "target" / "release" / "sfmeval")
    monkeypatch.setenv("PATH", "/nonexistent")
    monkeypatch.chdir(repo / "sub")
    assert tools.find("sfmeval") == str(repo / "target" / "release" / "sfmeval")
    monkeypatch.setattr(tools, "_repo_candidates", lambda extra: iter(()))
    with pytest.raises(tools.ToolMissing, match="not found on PATH.*cargo build --release -p "
                                                "sfmeval-runner"):
        tools.find("sfmeval-runner")


def test_crop_sphere_is_written_and_matches_the_cli(addon_zip, bins, tmp_path):
    """A crop sphere (Debian Blender 3.4, headless, data/demo's model imported as a file): the
    sfmeval.crop/1 file holds the sphere as placed, and the add-on's report is byte for byte
    the CLI's on the same points, crop file and alignment."""
    exe = shutil.which("blender")
    assert exe, "Debian blender not installed (apt-get install blender python3-numpy)"
    ds = tmp_path / "demo"
    shutil.copytree(os.path.join(REPO, "data", "demo"), ds)
    out = tmp_path / "sphere.json"
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(tmp_path / "user_scripts"),
               BLENDER_USER_CONFIG=str(tmp_path / "user_config"))
    proc = subprocess.run([exe, "-b", "--factory-startup", "-noaudio", "--python-exit-code", "1",
                           "-P", SPHERE_SCRIPT, "--", addon_zip, str(ds), str(out),
                           bins["sfmeval"]], capture_output=True, text=True, env=env,
                          timeout=300)
    assert proc.returncode == 0 and "SPHERE DONE" in proc.stdout, \
        proc.stdout[-4000:] + proc.stderr[-4000:]
    res = json.loads(out.read_text())
    with open(ds / "compare" / "crop.json") as f:
        crop = json.load(f)
    M = np.array(res["crop_matrix"])
    assert crop["schema"] == "sfmeval.crop/1" and crop["max_distance"] == pytest.approx(0.05)
    assert crop["volume"]["kind"] == "sphere"
    assert np.allclose(crop["volume"]["center"], GLTF_FROM_BLENDER @ M[:3, 3], atol=1e-7)
    assert crop["volume"]["radius"] == pytest.approx(0.35, abs=1e-7)
    with open(res["report"], "rb") as f:
        raw = f.read()
    rep = json.loads(raw)
    assert rep["crop"]["kind"] == "sphere+max_distance", rep["crop"]
    assert rep["crop"]["discarded_outside_volume"] > 0 and rep["crop"]["kept"] > 0, rep["crop"]
    mine, rows, _ = _eval(bins, str(ds), res, tmp_path)
    assert mine.read_bytes() == raw, "the add-on's report differs from the CLI's"
    assert res["summary"]["points"] == rep["crop"]["kept"]
    assert res["summary"]["mean"] == rep["accuracy"]["mean"]


FLOAT64_SCRIPT = os.path.join(os.path.dirname(SCRIPT), "blender_float64_script.py")


@pytest.mark.parametrize("blender", ["bpy", "debian"])
def test_float64_points_selected_rows_and_notes(blender, addon_zip, bins, tmp_path):
    """data/demo's sparse.ply and its COLMAP model imported as files (through `sfmeval export`),
    vertices of both deleted in Edit Mode: each evaluation measures exactly the float64 source
    rows still present, and its report is byte for byte `sfmeval eval` on the same points,
    transform and cameras (ATE and rotation errors included). Automatic and Refine act on the
    selected row only, Refine is one `sfmeval align --align icp` from the moved placement, Table
    I is `sfmeval table`'s, a report whose messages are reworded shows the same notes, and a
    vertex added in Edit Mode is reported, not measured."""
    ds = tmp_path / "demo"
    shutil.copytree(os.path.join(REPO, "data", "demo"), ds)
    out = tmp_path / "f64.json"
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(tmp_path / "user_scripts"),
               BLENDER_USER_CONFIG=str(tmp_path / "user_config"))
    args = [addon_zip, str(ds), str(out), bins["sfmeval"]]
    if blender == "bpy":
        assert have_bpy(), "PyPI bpy is not installed"
        cmd = [sys.executable, FLOAT64_SCRIPT] + args
    else:
        exe = shutil.which("blender")
        assert exe, "Debian blender not installed (apt-get install blender python3-numpy)"
        cmd = [exe, "-b", "--factory-startup", "-noaudio", "--python-exit-code", "1",
               "-P", FLOAT64_SCRIPT, "--"] + args
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0 and "FLOAT64 DONE" in proc.stdout, \
        proc.stdout[-4000:] + proc.stderr[-4000:]
    res = json.loads(out.read_text())
    ply_name, colmap_name = "sparse", "demo-sparse"
    # its own tab; an empty Dataset field says what to choose; rows listed at once; no stale text
    assert res["category"] == "sfmeval compare"
    assert any("Choose a dataset folder" in x for x in res["empty_labels"]), res["empty_labels"]
    assert res["listed_after_import"] == [[ply_name], [ply_name, colmap_name]]
    assert res["message_after_import"] == "" and res["message_after_eval"] == ""
    assert res["gt_collection"] and "MESH" in res["gt_collection"]
    # imports: `sfmeval export` then `sfmeval align`, no evaluation round trip
    verbs = [shlex.split(x)[1] for x in res["import_commands"]]
    assert verbs == ["export", "align", "export", "align"], res["import_commands"]
    # Automatic: one align on the selected (COLMAP) row; the PLY's alignment untouched
    assert res["ply_untouched"]
    assert [shlex.split(x)[1] for x in res["auto_commands"]] == ["align"]
    assert os.path.join("compare", colmap_name) in res["auto_commands"][0]
    # Refine: ONE `sfmeval align --align icp` from the moved placement; the test's own run of
    # that command gives the same alignment
    assert len(res["refine_commands"]) == 1, res["refine_commands"]
    argv = shlex.split(res["refine_commands"][0])
    assert argv[1] == "align" and argv[argv.index("--align") + 1] == "icp"
    start = np.array(res["icp_start"])
    moved = np.array(res["auto"])
    a = math.radians(2.0)
    P = np.eye(4)
    P[:3, :3] = 1.01 * np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0],
                                 [0, 0, 1]])
    assert np.allclose(start, P @ moved, rtol=1e-5, atol=1e-5)
    argv[argv.index("--out") + 1] = str(tmp_path / "mine_alignment.json")
    subprocess.run(argv, check=True, capture_output=True)
    mine = json.loads((tmp_path / "mine_alignment.json").read_text())
    assert mine == res["refine_alignment"]
    assert res["refined"] == [v for row in mine["gt_from_recon"] for v in row]
    # each evaluation: the float64 source rows of the vertices left, the CLI's report bytes
    for name, step in ((ply_name, 5), (colmap_name, 3)):
        item = res["items"][name]
        import trimesh
        src = np.asarray(trimesh.load(item["source"], process=False).vertices, np.float64)
        idx = np.array(item["index"])
        expect = np.delete(np.arange(len(src)), res["deleted"][name])
        assert np.array_equal(idx, expect)
        work = os.path.dirname(item["report"])
        with open(os.path.join(work, "points.ply"), "rb") as f:
            body = f.read()
        pts = np.frombuffer(body[body.index(b"end_header\n") + 11:], "<f8").reshape(-1, 3)
        assert np.array_equal(pts, src[idx])  # float64, bit for bit
        mine = tmp_path / ("%s.json" % name)
        argv = [bins["sfmeval"], "eval", "--dataset", str(ds), "--recon",
                os.path.join(work, "points.ply"), "--align", "given", "--transform",
                os.path.join(work, "gt_from_recon.json"), "--report", str(mine), "--quiet"]
        if item["cameras_source"]:
            argv += ["--recon-cameras", item["cameras_source"]]
        subprocess.run(argv, check=True, capture_output=True)
        with open(item["report"], "rb") as f:
            raw = f.read()
        assert mine.read_bytes() == raw, "the add-on's report differs from the CLI's"
        rep = json.loads(raw)
        assert rep["inputs"]["reconstruction"]["points"] == item["vertices"] == len(expect)
        T = np.array(rep["alignment"]["gt_from_recon"])
        assert np.allclose(np.array(item["stored"]).reshape(4, 4), T, rtol=1e-6, atol=1e-6)
        s = item["summary"]
        assert s["mean"] == rep["accuracy"]["mean"] and s["min"] == rep["accuracy"]["min"]
        assert s["ate"] == (rep["cameras"] or {}).get("ate_rmse")
    # the COLMAP model's cameras: ATE and rotation errors are those `sfmeval eval` gives the
    # model itself (camera alignment, whatever aligned the points)
    # a vertex added in Edit Mode (index attribute 0, vertex 0 deleted): told, not measured
    added = res["added_vertex"]
    assert added["status"] != "ok", added
    text = added["message"] + " " + added["panel"]
    assert "1 of its" in text and "added, duplicated or moved in Edit Mode" in text, added
    assert added["report_unchanged"] in (True, None), added
    rep = json.loads(open(res["items"][colmap_name]["report"]).read())
    cli = tmp_path / "model.json"
    subprocess.run([bins["sfmeval"], "eval", "--dataset", str(ds), "--recon", str(ds / "sparse"),
                    "--report", str(cli), "--quiet", "--samples", "20000"], check=True,
                   capture_output=True)
    cli = json.loads(cli.read_text())
    assert rep["cameras"]["registered"] == cli["cameras"]["registered"] > 0
    assert rep["cameras"]["ate_rmse"] == cli["cameras"]["ate_rmse"]
    assert rep["cameras"]["rotation_error_deg"] == cli["cameras"]["rotation_error_deg"]
    assert res["items"][colmap_name]["summary"]["ate"] == cli["cameras"]["ate_rmse"]
    # the numbers readable at the sidebar's width: one short label per value
    texts = [t for t, _ in res["labels"]]
    assert "mean" in texts and "%.4g" % res["items"][ply_name]["summary"]["mean"] in texts
    assert max(len(t) for t in texts if t in ("mean", "median", "ATE")) <= 6
    # Table I is `sfmeval table`'s on the same reports (the runner's bytes)
    table = tmp_path / "table"
    subprocess.run([bins["sfmeval"], "table"] +
                   ["%s=%s" % (n, res["items"][n]["report"]) for n in (ply_name, colmap_name)] +
                   ["--dataset", "demo", "--out", str(table)], check=True, capture_output=True)
    for name in ("table1.md", "table1.csv"):
        assert (table / name).read_text(encoding="utf-8") == res["table_files"][name], name
    assert (table / "table1.md").read_text() in res["table_text"]
    # notes by level: the reworded report's warnings shown with their new words, infos not
    shown = [(t, icon) for t, icon in res["reworded_labels"] if t.startswith("REWORDED")]
    warnings = [n for n in res["notes"] if n["level"] == "warning"]
    assert warnings, res["notes"]
    assert shown == [(n["message"], "ERROR") for n in warnings]
    assert any(n["code"] == "cameras.reconstruction_has_no_cameras" for n in warnings)
