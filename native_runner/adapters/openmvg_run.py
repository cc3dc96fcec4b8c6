"""sfmeval-runner adapter: openmvg-rs (a Rust port of OpenMVG). --mode incremental or global.

Options (--option key=value): features (alp | sift, default alp), threads (default all cores).
openmvg-rs puts pixel (0, 0) at the centre of the top-left pixel, so known intrinsics are written
to K.txt with cx - 0.5, cy - 0.5; its COLMAP export is in COLMAP's convention again.
openmvg-rs's own PLY export (white points, green camera centres) is kept as raw/scene.ply in the
run folder.
"""

import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402


def main():
    a = common.parse_args(__doc__, modes=("incremental", "global"))
    import openmvg_rs

    o = a.options
    kwargs = {"engine": a.mode, "extraction_method": o.get("features", "alp"), "seed": a.seed,
              "progress": False}
    if "threads" in o:
        kwargs["max_workers"] = int(o["threads"])
    work = common.run_subdir(a.out, "scratch")
    if a.known:
        fx, fy, cx, cy = a.known
        k = os.path.join(work, "K.txt")
        with open(k, "w") as f:
            f.write("%r 0 %r\n0 %r %r\n0 0 1\n" % (fx, cx - 0.5, fy, cy - 0.5))
        kwargs["intrinsics"] = k
    common.log("reconstruct %s" % kwargs)
    try:
        scene = openmvg_rs.reconstruct(a.images, **kwargs)
    except openmvg_rs.OpenMVGError as e:
        common.fail("%s: %s" % (type(e).__name__, e), 4)
    common.log("registered %d, points %d, unregistered %s"
               % (scene.num_registered_images, scene.num_points,
                  list(scene.unregistered_images)))
    tmp = os.path.join(work, "colmap")
    shutil.rmtree(tmp, ignore_errors=True)
    scene.write_colmap(tmp)
    src = os.path.join(tmp, "sparse", "0")
    if not os.path.isdir(src):
        src = tmp
    for name in os.listdir(src):
        shutil.copy(os.path.join(src, name), os.path.join(a.out, name))
    # openmvg-rs's own PLY export (white points, then the registered camera centres in green),
    # kept in the run folder's raw/.
    raw = common.run_subdir(a.out, "raw")
    scene.write_ply(os.path.join(raw, "scene.ply"))
    common.write_tool_json(a.out, "openmvg-rs", getattr(openmvg_rs, "__version__", "?"),
                           scene.num_registered_images, scene.num_points)


if __name__ == "__main__":
    main()
