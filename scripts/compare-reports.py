#!/usr/bin/env python3
"""Runs two `sfmeval` binaries on the same cases (the demo, every SfM-model fixture, the mesh and
cloud fixtures, every alignment mode, crops, thresholds, depth maps) and compares their reports.

    .venv/bin/python scripts/compare-reports.py OLD_BIN NEW_BIN [--depth DIR]

Reports must be identical except for the declared differences between report schemas, which are
mapped before comparing (numbers compare exactly, as parsed from the JSON text):

  sfmeval.report/1 -> /2: `schema`; `thresholds[].tau_relative_to_diagonal` (a fraction) became
  `tau_percent_of_diagonal` (percent, = fraction * 100); `options.align` is the requested mode
  (was the method that ran, still in `alignment.method`); `cameras` keys come in declaration
  order (compared as objects, so order does not matter).
  sfmeval.report/2 -> /3: `schema`; the `warnings` strings (and `cameras.warnings`) became typed
  `notes` (and `cameras.notes`), and `alignment.stages[].note` moved into them: both sides' notes
  and warnings are left out of the comparison (tests check the notes by code); with `--align
  given` (or `icp`) and cameras, the pose errors are measured after the camera alignment, as
  `auto` measures them, not after the final transform.

Two `sfmeval.report/3` reports compare whole, their notes (codes, levels, messages, values and
order) included.

Prints one line per case and exits 1 when any case differs. `DIR` holds demo depth maps
(tests/browser/make_demo_depth.py) for the visibility and track-error case.
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "data" / "demo"
MODELS = ROOT / "tests" / "fixtures" / "models"
CORE = ROOT / "tests" / "fixtures" / "core"


def cases(depth):
    gt = ["--gt", DEMO / "ground_truth.glb"]
    cams = ["--gt-cameras", DEMO / "cameras.json"]
    out = [
        ("demo-auto", gt + cams + ["--recon", DEMO / "sparse"]),
        ("demo-ply-global", gt + ["--recon", DEMO / "sparse.ply", "--samples", "20000"]),
        ("demo-cameras", gt + cams + ["--recon", DEMO / "sparse", "--align", "cameras"]),
        ("demo-cameras+icp-crop", gt + cams + ["--recon", DEMO / "sparse", "--align", "cameras+icp",
                                               "--crop-sphere", "0,0,0,0.4", "--max-distance", "0.05"]),
        ("demo-none-tau", gt + ["--recon", DEMO / "sparse.ply", "--align", "none", "--tau", "0.01,0.02",
                                "--tau-relative", "0.5", "--signed", "--bins", "20", "--samples", "50000"]),
        ("demo-global+icp-seed", gt + ["--recon", DEMO / "sparse.ply", "--align", "global+icp",
                                       "--seed", "3", "--samples", "20000"]),
    ]
    for name in ["colmap_text", "colmap_bin", "colmap38.nvm", "colmap38.bundle.out", "theia_colmap",
                 "theia.nvm", "openmvg_colmap", "openmvg_sfm_data.json"]:
        out.append((f"model-{name}", ["--gt", CORE / "trimesh_mesh.glb", "--gt-cameras", MODELS / "gt_cameras.json",
                                     "--recon", MODELS / name, "--align", "cameras", "--samples", "5000"]))
    for name in ["theia.ply", "openmvg.ply"]:
        out.append((f"model-{name}-with-cameras", ["--gt", CORE / "trimesh_mesh.glb", "--gt-cameras",
                                                  MODELS / "gt_cameras.json", "--recon", MODELS / name,
                                                  "--recon-cameras", MODELS / "theia.nvm", "--samples", "5000"]))
        out.append((f"model-{name}-global", ["--gt", CORE / "trimesh_mesh.glb", "--recon", MODELS / name,
                                            "--align", "global+icp", "--samples", "5000"]))
    for name in ["open3d_cloud_ascii.ply", "open3d_cloud_binary.ply", "colmap_points.ply"]:
        for gt_name in ["trimesh_mesh.glb", "meshlab_mesh_binary.ply", "trimesh_mesh.obj", "open3d_cloud_binary.ply"]:
            out.append((f"core-{name}-vs-{gt_name}", ["--gt", CORE / gt_name, "--recon", CORE / name,
                                                      "--align", "none", "--samples", "5000"]))
    if depth:
        out.append(("demo-depth", gt + cams + ["--recon", DEMO / "sparse", "--depth", depth, "--min-views", "3"]))
    return out


def run(binary, args, path):
    cmd = [binary, "eval", "--quiet", "--report", str(path), *map(str, args)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip().splitlines()[-1] if p.stderr.strip() else f"exit {p.returncode}"
    return json.loads(Path(path).read_text()), None


def upgrade(old, new):
    """The /1 or /2 report `old` in /3 terms (`new` gives the requested mode); the notes of both
    are dropped (see the module's doc). Two /3 reports compare whole, notes included."""
    if old.get("schema") == new.get("schema") == "sfmeval.report/3":
        return old
    if old.get("schema") == "sfmeval.report/1":
        old["schema"] = "sfmeval.report/2"
        for t in old.get("thresholds", []):
            t["tau_percent_of_diagonal"] = t.pop("tau_relative_to_diagonal") * 100
        old["options"]["align"] = new["options"]["align"]
    if old.get("schema") == "sfmeval.report/2":
        old["schema"] = "sfmeval.report/3"
    for rep in (old, new):
        rep.pop("warnings", None)
        rep.pop("notes", None)
        for stage in rep.get("alignment", {}).get("stages", []):
            stage.pop("note", None)
        if rep.get("cameras"):
            rep["cameras"].pop("warnings", None)
            rep["cameras"].pop("notes", None)
    return old


def first_difference(a, b, path=""):
    if type(a) is not type(b):
        return f"{path}: {a!r} vs {b!r}"
    if isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{path}/{k}: only in {'new' if k in b else 'old'}"
            d = first_difference(a[k], b[k], f"{path}/{k}")
            if d:
                return d
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{path}: {len(a)} vs {len(b)} items"
        for i, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f"{path}/{i}")
            if d:
                return d
        return None
    return None if a == b else f"{path}: {a!r} vs {b!r}"


def main():
    args = sys.argv[1:]
    depth = None
    if "--depth" in args:
        i = args.index("--depth")
        depth = args[i + 1]
        del args[i:i + 2]
    old_bin, new_bin = args
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name, case in cases(depth):
            old, old_err = run(old_bin, case, Path(tmp) / "old.json")
            new, new_err = run(new_bin, case, Path(tmp) / "new.json")
            if old is None or new is None:
                same = old is None and new is None
                print(f"{'same' if same else 'DIFF'}  {name}: old {old_err or 'ok'} | new {new_err or 'ok'}")
                bad += not same
                continue
            d = first_difference(upgrade(old, new), new)
            print(f"{'DIFF' if d else 'same'}  {name}{': ' + d if d else ''}")
            bad += bool(d)
    print(f"{bad} case(s) differ")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
