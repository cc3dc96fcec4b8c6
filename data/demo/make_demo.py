"""Builds the demo shipped with sfmeval (data/demo/): a real rendered dataset's ground truth and a
real SfM output of its images.

  .venv/bin/python data/demo/make_demo.py [WORKDIR]

1. renders the `small` preset (36 views of the built-in statue, 640×360) with the Blender
   generator (PyPI bpy);
2. runs pycolmap 4.2.1 incremental mapping on the images, focal from EXIF, CPU;
3. copies ground_truth.glb and cameras.json, and writes the reconstruction as a COLMAP text model
   (sparse/: cameras.txt, images.txt without 2D observations, points3D.txt without tracks, to keep
   the demo small) and as sparse.ply (COLMAP's PLY export).
"""
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OUT = Path(__file__).resolve().parent
work = Path(sys.argv[1] if len(sys.argv) > 1 else "/tmp/sfmeval-demo")
ds = work / "dataset"
if not (ds / "cameras.json").exists():
    subprocess.run([sys.executable, str(ROOT / "blender_scripts" / "generate.py"), "--preset", "small",
                    "--out", str(ds), "--overwrite"], check=True)

import pycolmap  # noqa: E402

db = work / "database.db"
sparse = work / "sparse"
if db.exists():
    db.unlink()
shutil.rmtree(sparse, ignore_errors=True)
sparse.mkdir(parents=True)
pycolmap.extract_features(db, ds / "images", camera_mode=pycolmap.CameraMode.SINGLE, device=pycolmap.Device.cpu)
pycolmap.match_exhaustive(db, device=pycolmap.Device.cpu)
maps = pycolmap.incremental_mapping(db, ds / "images", sparse)
rec = max(maps.values(), key=lambda r: r.num_reg_images())
print(rec.summary())
text = work / "text"
shutil.rmtree(text, ignore_errors=True)
text.mkdir()
rec.write_text(str(text))
shutil.rmtree(OUT / "sparse", ignore_errors=True)
(OUT / "sparse").mkdir()
shutil.copy(text / "cameras.txt", OUT / "sparse" / "cameras.txt")
with open(text / "images.txt") as src, open(OUT / "sparse" / "images.txt", "w") as dst:
    lines = [l for l in src if not l.startswith("#")]
    dst.write("# pycolmap 4.2.1 images (2D observations removed to keep the demo small)\n")
    for i, line in enumerate(lines):
        dst.write(line if i % 2 == 0 else "\n")
with open(text / "points3D.txt") as src, open(OUT / "sparse" / "points3D.txt", "w") as dst:
    dst.write("# pycolmap 4.2.1 points (tracks removed to keep the demo small)\n")
    for line in src:
        if line.startswith("#"):
            continue
        f = line.split()
        dst.write(" ".join(f[:8]) + "\n")
rec.export_PLY(str(OUT / "sparse.ply"))
shutil.copy(ds / "ground_truth.glb", OUT / "ground_truth.glb")
shutil.copy(ds / "cameras.json", OUT / "cameras.json")
print("demo written to", OUT)
