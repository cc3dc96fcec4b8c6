"""sfmeval-runner adapter: pycolmap (COLMAP as a library). --mode incremental runs the
incremental mapper, --mode global the global mapper (GLOMAP). CPU only.

Options (--option key=value): max_features (SIFT features per image, default COLMAP's 8192),
matcher (exhaustive | sequential, default exhaustive), overlap (sequential window, default 10),
single_camera (1 = one camera for all images, default 1), threads (default all cores).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402


def main():
    a = common.parse_args(__doc__, modes=("incremental", "global"))
    import pycolmap

    o = a.options
    work = common.run_subdir(a.out, "scratch")
    db = os.path.join(work, "database.db")
    if os.path.exists(db):
        os.remove(db)
    threads = int(o.get("threads", -1))
    extraction = pycolmap.FeatureExtractionOptions()
    if "max_features" in o:
        extraction.sift.max_num_features = int(o["max_features"])
    extraction.num_threads = threads
    reader = pycolmap.ImageReaderOptions()
    if a.known:
        reader.camera_model = "PINHOLE"
        reader.camera_params = ",".join(repr(v) for v in a.known)
    single = o.get("single_camera", "1") == "1"
    mode = pycolmap.CameraMode.SINGLE if single else pycolmap.CameraMode.AUTO
    common.log("extract_features")
    pycolmap.extract_features(db, a.images, camera_mode=mode, reader_options=reader,
                              extraction_options=extraction, device=pycolmap.Device.cpu)
    matcher = o.get("matcher", "exhaustive")
    common.log("match_%s" % matcher)
    matching = pycolmap.FeatureMatchingOptions()
    matching.num_threads = threads
    # Every pair's RANSAC from the seed: otherwise each matching thread draws from its own
    # generator, and which pairs a thread verifies (so the models found) depends on the load.
    verification = pycolmap.TwoViewGeometryOptions()
    verification.ransac.random_seed = a.seed
    if matcher == "sequential":
        pairing = pycolmap.SequentialPairingOptions()
        pairing.overlap = int(o.get("overlap", 10))
        pycolmap.match_sequential(db, matching_options=matching, pairing_options=pairing,
                                  verification_options=verification, device=pycolmap.Device.cpu)
    elif matcher == "exhaustive":
        pycolmap.match_exhaustive(db, matching_options=matching,
                                  verification_options=verification, device=pycolmap.Device.cpu)
    else:
        common.fail("unknown matcher %r (exhaustive, sequential)" % matcher, 2)
    sparse = os.path.join(work, "sparse")
    os.makedirs(sparse, exist_ok=True)
    pycolmap.set_random_seed(a.seed)
    if a.mode == "incremental":
        opts = pycolmap.IncrementalPipelineOptions()
        if a.known:
            opts.ba_refine_focal_length = False
            opts.ba_refine_principal_point = False
            opts.ba_refine_extra_params = False
        opts.random_seed = a.seed
        if threads > 0:
            opts.num_threads = threads
        common.log("incremental_mapping")
        recs = pycolmap.incremental_mapping(db, a.images, sparse, options=opts)
    else:
        opts = pycolmap.GlobalPipelineOptions()
        if a.known:
            # GLOMAP's bundle adjustment refines the focal length and extra parameters by
            # default (principal point not); the known camera stays fixed, as in incremental.
            ba = opts.mapper.bundle_adjustment
            ba.refine_focal_length = False
            ba.refine_principal_point = False
            ba.refine_extra_params = False
        opts.random_seed = a.seed
        if threads > 0:
            opts.num_threads = threads
        common.log("global_mapping")
        recs = pycolmap.global_mapping(db, a.images, sparse, options=opts)
    if not recs:
        common.fail("the mapper registered no images", 4)
    rec = max(recs.values(), key=lambda r: (r.num_reg_images(), r.num_points3D()))
    common.log(rec.summary())
    rec.write_text(a.out)
    common.write_tool_json(a.out, "pycolmap" if a.mode == "incremental" else "pycolmap (GLOMAP)",
                           pycolmap.__version__, rec.num_reg_images(), rec.num_points3D(),
                           {"models": len(recs)})


if __name__ == "__main__":
    main()
