"""The Python package against the CLI: run in a fresh venv with the built wheel installed
(scripts/test-python-package.sh), never on the source tree. Every report must be the bytes
`sfmeval eval --report` writes for the same inputs.

SFMEVAL_BIN: the CLI (default target/release/sfmeval).
"""

from __future__ import annotations

import json
import os
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import sfmeval

ROOT = Path(__file__).resolve().parents[3]
BIN = Path(os.environ.get("SFMEVAL_BIN", ROOT / "target/release/sfmeval"))
DEMO = ROOT / "data/demo"
CORE = ROOT / "tests/fixtures/core"
MODELS = ROOT / "tests/fixtures/models"
GT_CAMERAS = MODELS / "gt_cameras.json"


def test_the_package_is_the_installed_wheel_not_the_source_tree():
    # an editable or source import would not test the wheel
    assert "site-packages" in Path(sfmeval.__file__).parts, sfmeval.__file__
    assert BIN.is_file(), f"the CLI to compare with is missing: {BIN}"


def cli_report(tmp_path: Path, *args: object) -> bytes:
    out = tmp_path / "cli.json"
    p = subprocess.run([str(BIN), "eval", *map(str, args), "--quiet", "--report", str(out)],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return out.read_bytes()


def cli_error(*args: object) -> str:
    p = subprocess.run([str(BIN), "eval", *map(str, args), "--quiet"], capture_output=True,
                       text=True)
    assert p.returncode == 1, (p.returncode, p.stdout, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert lines[-1].startswith("error: "), p.stderr
    return lines[-1][len("error: "):]


CROP = {"schema": "sfmeval.crop/1", "volume": {"kind": "box", "min": [-0.3, -0.3, -0.3],
                                                "max": [0.3, 0.3, 0.9]}}
# the demo model's gt_from_recon by camera centres, to 12 digits (the start of icp, or given)
DEMO_START = [[0.24393526577, -0.299850123721, 0.298600929354, 0.00184377389897],
              [-0.000514897229959, -0.34487005783, -0.34589218506, 1.18191757912],
              [0.423169406488, 0.172428455046, -0.17254885365, -0.00336038234363],
              [0.0, 0.0, 0.0, 1.0]]

# (id, Python keyword arguments, the CLI's flags for the same inputs); "$tmp" files are written
# by the test (crop and transform files for the CLI, from the same values Python gets)
CASES = [
    ("demo-colmap-auto", dict(gt=DEMO / "ground_truth.glb", recon=DEMO / "sparse",
                              gt_cameras=DEMO / "cameras.json"),
     ["--gt", DEMO / "ground_truth.glb", "--recon", DEMO / "sparse",
      "--gt-cameras", DEMO / "cameras.json"]),
    ("demo-dataset-folder-ply", dict(gt=DEMO, recon=DEMO / "sparse.ply", samples=200_000),
     ["--dataset", DEMO, "--recon", DEMO / "sparse.ply", "--samples", 200_000]),
    ("demo-crop-dict-tau-list-cameras", dict(gt=DEMO / "ground_truth.glb", recon=DEMO / "sparse",
                                             gt_cameras=DEMO / "cameras.json", align="cameras",
                                             crop=CROP, tau=[0.002, 0.005, 0.01],
                                             samples=100_000, seed=7),
     ["--gt", DEMO / "ground_truth.glb", "--recon", DEMO / "sparse", "--gt-cameras",
      DEMO / "cameras.json", "--align", "cameras", "--crop", "$crop", "--tau", "0.002,0.005,0.01",
      "--samples", 100_000, "--seed", 7]),
    ("demo-icp-from-matrix-signed-max-distance",
     dict(gt=DEMO / "ground_truth.glb", recon=DEMO / "sparse.ply", align="icp",
          transform=np.array(DEMO_START), signed=True, max_distance=0.05,
          tau_percent=[0.25, 1.0], samples=100_000),
     ["--gt", DEMO / "ground_truth.glb", "--recon", DEMO / "sparse.ply", "--align", "icp",
      "--transform", "$transform", "--signed", "--max-distance", 0.05, "--tau-percent", "0.25,1",
      "--samples", 100_000]),
    ("demo-given-transform-file", dict(gt=DEMO / "ground_truth.glb", recon=DEMO / "sparse.ply",
                                       transform="$transform", samples=50_000),
     ["--gt", DEMO / "ground_truth.glb", "--recon", DEMO / "sparse.ply",
      "--transform", "$transform", "--samples", 50_000]),
    ("ply-cloud-vs-glb-none-tau", dict(gt=CORE / "trimesh_mesh.glb",
                                       recon=CORE / "colmap_points.ply", align="none", tau=0.5,
                                       samples=20_000),
     ["--gt", CORE / "trimesh_mesh.glb", "--recon", CORE / "colmap_points.ply", "--align",
      "none", "--tau", 0.5, "--samples", 20_000]),
    ("ply-cloud-gt-crop-file", dict(gt=CORE / "open3d_cloud_binary.ply",
                                    recon=CORE / "colmap_points.ply", align="none",
                                    crop="$crop", name="run/colmap"),
     ["--gt", CORE / "open3d_cloud_binary.ply", "--recon", CORE / "colmap_points.ply",
      "--align", "none", "--crop", "$crop", "--name", "run/colmap"]),
] + [
    (f"model-{path.name}-cameras", dict(gt=CORE / "trimesh_mesh_binary.ply", recon=path,
                                        gt_cameras=GT_CAMERAS, align="cameras", samples=20_000),
     ["--gt", CORE / "trimesh_mesh_binary.ply", "--recon", path, "--gt-cameras", GT_CAMERAS,
      "--align", "cameras", "--samples", 20_000])
    for path in [MODELS / "colmap_text", MODELS / "colmap_bin", MODELS / "colmap38.nvm",
                 MODELS / "theia.nvm", MODELS / "openmvg_sfm_data.json"]
] + [
    ("model-theia-ply-with-recon-cameras-auto",
     dict(gt=CORE / "trimesh_mesh_binary.ply", recon=MODELS / "theia.ply",
          recon_cameras=MODELS / "theia_colmap", gt_cameras=GT_CAMERAS, samples=20_000),
     ["--gt", CORE / "trimesh_mesh_binary.ply", "--recon", MODELS / "theia.ply",
      "--recon-cameras", MODELS / "theia_colmap", "--gt-cameras", GT_CAMERAS,
      "--samples", 20_000]),
]


def materialise(tmp_path: Path, kwargs: dict, flags: list) -> tuple[dict, list]:
    """Writes the crop and transform files the CLI reads (the same values Python gets)."""
    crop_file = tmp_path / "crop.json"
    crop_file.write_text(json.dumps(CROP))
    transform_file = tmp_path / "transform.json"
    transform_file.write_text(json.dumps(DEMO_START))
    files = {"$crop": crop_file, "$transform": transform_file}
    kwargs = {k: files.get(v, v) if isinstance(v, str) else v for k, v in kwargs.items()}
    return kwargs, [files.get(f, f) if isinstance(f, str) else f for f in flags]


@pytest.mark.parametrize("kwargs,flags", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_report_is_the_clis_byte_for_byte(tmp_path, kwargs, flags):
    kwargs, flags = materialise(tmp_path, kwargs, flags)
    want = cli_report(tmp_path, *flags)
    r = sfmeval.evaluate(**kwargs)
    assert r.to_json().encode() == want
    d = json.loads(want)
    assert r.to_dict() == d
    # attribute access is the JSON's own values
    assert r.accuracy.mean == d["accuracy"]["mean"]
    assert r.accuracy.percentiles.p95 == d["accuracy"]["percentiles"]["p95"]
    assert [t.f_score for t in r.thresholds] == [t["f_score"] for t in d["thresholds"]]
    assert r.thresholds[0].tau == d["thresholds"][0]["tau"]
    m = r.alignment.gt_from_recon
    assert isinstance(m, np.ndarray) and m.shape == (4, 4) and m.dtype == np.float64
    assert m.tolist() == d["alignment"]["gt_from_recon"]
    assert r.alignment.method == d["alignment"]["method"]
    assert [(n.code, n.level, n.message, n.values) for n in r.notes] == [
        (n["code"], n["level"], n["message"], n.get("values", {})) for n in d["notes"]]
    # the per-point distances are the ones the statistics were computed from
    dist, kept = r.distances, r.kept
    assert dist.shape == kept.shape == (d["inputs"]["reconstruction"]["points"],)
    assert int(kept.sum()) == d["accuracy"]["count"]
    if d["accuracy"]["count"]:
        np.testing.assert_allclose(dist[kept].mean(), d["accuracy"]["mean"], rtol=1e-12)
        assert dist[kept].max() == d["accuracy"]["max"]
        assert dist[kept].min() == d["accuracy"]["min"]
    if kwargs.get("signed"):
        s = r.signed_distances
        assert s is not None and s.shape == dist.shape
        np.testing.assert_allclose(np.abs(s), dist, rtol=1e-12, atol=1e-15)
    else:
        assert r.signed_distances is None


def test_completeness_samples_are_the_clis_samples_csv(tmp_path):
    csv = tmp_path / "samples.csv"
    report = tmp_path / "cli.json"
    p = subprocess.run([str(BIN), "eval", "--dataset", str(DEMO), "--recon", str(DEMO / "sparse"),
                        "--samples", "30000", "--quiet", "--report", str(report),
                        "--samples-csv", str(csv)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    rows = [line.split(",") for line in csv.read_text().splitlines()[1:]]
    r = sfmeval.evaluate(DEMO, DEMO / "sparse", samples=30_000)
    assert r.to_json().encode() == report.read_bytes()
    pts, dist = r.completeness_points, r.completeness_distances
    assert pts.shape == (len(rows), 3) and dist.shape == (len(rows),)
    assert pts.tolist() == [[float(v) for v in row[1:4]] for row in rows]
    assert dist.tolist() == [float(row[4]) for row in rows]
    d = json.loads(report.read_text())
    assert len(rows) == d["completeness"]["count"]
    np.testing.assert_allclose(dist.mean(), d["completeness"]["mean"], rtol=1e-12)


def test_keyword_arguments_take_path_objects_and_strings_alike():
    a = sfmeval.evaluate(str(CORE / "trimesh_mesh.glb"), str(CORE / "colmap_points.ply"),
                         align="none", samples=5000)
    b = sfmeval.evaluate(CORE / "trimesh_mesh.glb", CORE / "colmap_points.ply", align="none",
                         samples=5000)
    assert a.to_json() == b.to_json()
    assert a.inputs.reconstruction.name == "colmap_points.ply"


def test_missing_file_is_file_not_found_naming_it(tmp_path):
    missing = tmp_path / "nothing.ply"
    with pytest.raises(FileNotFoundError) as e:
        sfmeval.evaluate(CORE / "trimesh_mesh.glb", missing)
    assert e.value.filename == str(missing)
    with pytest.raises(FileNotFoundError) as e:
        sfmeval.evaluate(missing, CORE / "colmap_points.ply")
    assert e.value.filename == str(missing)
    with pytest.raises(FileNotFoundError) as e:
        sfmeval.evaluate(CORE / "trimesh_mesh.glb", CORE / "colmap_points.ply",
                         gt_cameras=tmp_path / "cameras.json")
    assert e.value.filename == str(tmp_path / "cameras.json")


def test_bad_inputs_are_input_errors_with_the_clis_message(tmp_path):
    bad_ply = tmp_path / "broken.ply"
    bad_ply.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 1000\n"
                        b"property float x\nproperty float y\nproperty float z\nend_header\n"
                        + b"\0" * 40)
    bad_nvm = tmp_path / "model.nvm"
    bad_nvm.write_text("NVM_V3\n\n2\nimage.jpg 100 1 0 0\n")
    not_similar = [[2.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    transform_file = tmp_path / "shear.json"
    transform_file.write_text(json.dumps(not_similar))
    cases = [
        (dict(gt=CORE / "trimesh_mesh.glb", recon=bad_ply),
         ["--gt", CORE / "trimesh_mesh.glb", "--recon", bad_ply], bad_ply),
        (dict(gt=bad_ply, recon=CORE / "colmap_points.ply"),
         ["--gt", bad_ply, "--recon", CORE / "colmap_points.ply"], bad_ply),
        (dict(gt=CORE / "trimesh_mesh.glb", recon=bad_nvm),
         ["--gt", CORE / "trimesh_mesh.glb", "--recon", bad_nvm], bad_nvm),
        (dict(gt=CORE / "trimesh_mesh.glb", recon=CORE / "colmap_points.ply",
              transform=transform_file),
         ["--gt", CORE / "trimesh_mesh.glb", "--recon", CORE / "colmap_points.ply",
          "--transform", transform_file], transform_file),
    ]
    for kwargs, flags, named in cases:
        with pytest.raises(sfmeval.InputError) as e:
            sfmeval.evaluate(**kwargs)
        assert isinstance(e.value, ValueError)
        assert str(named) in str(e.value)
        assert str(e.value) == cli_error(*flags)
    # a matrix from Python goes through the same parser
    with pytest.raises(sfmeval.InputError, match="scaled rotation"):
        sfmeval.evaluate(CORE / "trimesh_mesh.glb", CORE / "colmap_points.ply",
                         transform=not_similar)
    with pytest.raises(sfmeval.InputError, match="align"):
        sfmeval.evaluate(CORE / "trimesh_mesh.glb", CORE / "colmap_points.ply", align="nope")
    with pytest.raises(sfmeval.InputError, match="--align|transform"):
        sfmeval.evaluate(CORE / "trimesh_mesh.glb", CORE / "colmap_points.ply", align="given")


def test_the_gil_is_released_while_the_core_works():
    done = threading.Event()
    report = []

    def work():
        report.append(sfmeval.evaluate(DEMO / "ground_truth.glb", DEMO / "sparse",
                                       gt_cameras=DEMO / "cameras.json"))
        done.set()

    t = threading.Thread(target=work)
    ticks = 0
    start = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    elapsed = time.perf_counter() - start
    assert report and report[0].accuracy.count == 2529
    # with the GIL held by the evaluation, this thread would not run until it ended
    assert elapsed > 0.05 and ticks > 20, (elapsed, ticks)


def test_align_modes_and_version_are_the_cores():
    modes = sfmeval.align_modes()
    assert "auto" in modes and "cameras+icp" in modes
    p = subprocess.run([str(BIN), "--version"], capture_output=True, text=True)
    assert p.stdout.split()[-1] == sfmeval.version() == sfmeval.__version__


def export_points(tmp_path: Path, recon: Path) -> tuple[Path, np.ndarray]:
    """`sfmeval export`'s float64 PLY of a reconstruction and its points read with numpy."""
    out = tmp_path / "export"
    p = subprocess.run([str(BIN), "export", str(recon), "--out", str(out)], capture_output=True,
                       text=True)
    assert p.returncode == 0, p.stderr
    data = (out / "points.ply").read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    count = int(header.split("element vertex ")[1].split()[0])
    fields = [("x", "<f8"), ("y", "<f8"), ("z", "<f8")]
    if "property uchar red" in header:
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    rows = np.frombuffer(data, dtype=np.dtype(fields), count=count, offset=end)
    return out / "points.ply", np.stack([rows["x"], rows["y"], rows["z"]], axis=1)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_points_array_gives_the_report_of_the_same_points_as_a_file(tmp_path, dtype):
    ply, points = export_points(tmp_path, DEMO / "sparse.ply")
    points = points.astype(dtype)
    if dtype == np.float32:
        # the file the CLI reads holds the float32 values widened, as the array's are
        ply = tmp_path / "points.ply"
        header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\n"
                  "property double x\nproperty double y\nproperty double z\nend_header\n")
        ply.write_bytes(header.encode() + points.astype("<f8").tobytes())
    transform = tmp_path / "transform.json"
    transform.write_text(json.dumps(DEMO_START))
    want = cli_report(tmp_path, "--gt", DEMO / "ground_truth.glb", "--recon", ply,
                      "--transform", transform, "--samples", 50_000)
    r = sfmeval.evaluate(DEMO / "ground_truth.glb", points, transform=DEMO_START,
                         samples=50_000)
    assert r.to_json().encode() == want
    assert r.inputs.reconstruction.points == len(points)
    # Fortran order and a strided view are the same points
    f = sfmeval.evaluate(DEMO / "ground_truth.glb", np.asfortranarray(points),
                         transform=DEMO_START, samples=50_000)
    assert f.to_json() == r.to_json()


def test_bad_points_arrays_are_input_errors():
    for bad in [np.zeros((4, 2)), np.zeros(9), np.zeros((3, 3), dtype=np.int64)]:
        with pytest.raises(sfmeval.InputError, match="recon"):
            sfmeval.evaluate(DEMO / "ground_truth.glb", bad, align="none")
    nan = np.zeros((5, 3))
    nan[2, 1] = np.nan
    with pytest.raises(sfmeval.InputError, match="non-finite"):
        sfmeval.evaluate(DEMO / "ground_truth.glb", nan, align="none")
