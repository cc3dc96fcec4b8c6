"""sfmeval-runner adapter: pytheia (TheiaSfM). pytheia has no feature extraction and no image
or EXIF reader, so this adapter extracts SIFT with OpenCV, matches with Lowe's ratio test and
reads the focal length from EXIF (Pillow); Theia then verifies every pair
(EstimateTwoViewInfo), builds tracks and runs its --mode global or incremental estimator.

Options (--option key=value): max_features (default 4000), ratio (default 0.8), min_inliers
(default 30), matcher (exhaustive | sequential), overlap (sequential window, default 10),
min_track (default 3), max_track (default 30), max_sampson_error (default 2.0), loss
(bundle-adjustment loss: trivial, huber, softlone, cauchy, arctan, tukey; default trivial as in
Theia), loss_width (robust loss width in pixels, default 10 as in Theia), threads (default: all
cores).

OpenCV keypoints (with precise upscaling) have pixel centres on integers; 0.5 is added so that
the features, the principal point (cx = W/2) and the written COLMAP model are in COLMAP's pixel
convention.

Besides the COLMAP text model in --out, Theia's own writers export the reconstruction into the run
folder's raw/: reconstruction.nvm (WriteNVMFile) and points.ply (WritePlyFile; the camera
centres appended in red).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402


def main():
    a = common.parse_args(__doc__, modes=("global", "incremental"))
    import cv2
    import numpy as np
    import pytheia as pt

    o = a.options
    max_features = int(o.get("max_features", 4000))
    ratio = float(o.get("ratio", 0.8))
    min_inliers = int(o.get("min_inliers", 30))
    threads = int(o.get("threads", os.cpu_count() or 2))
    cv2.setRNGSeed(a.seed)
    names = common.list_images(a.images)
    # Precise upscaling: OpenCV's default doubles the image for octave -1 with a half-pixel-centre
    # resize but maps its keypoints back with x / 2, which biases every keypoint by +0.25 px in x
    # and y. The GT-pose re-triangulation test measured exactly that shift on Theia's tracks.
    sift = cv2.SIFT_create(nfeatures=max_features, enable_precise_upscale=True)
    recon = pt.sfm.Reconstruction()
    views, feats, priors = [], [], []
    for i, name in enumerate(names):
        path = os.path.join(a.images, name)
        img = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        if img is None:
            common.fail("OpenCV cannot read %s" % path)
        h, w = img.shape
        if a.known:
            f, cx, cy = 0.5 * (a.known[0] + a.known[1]), a.known[2], a.known[3]
        else:
            f, _, _ = common.exif_focal_px(path)
            cx, cy = w / 2.0, h / 2.0
            if f is None:
                f = 1.2 * max(w, h)
                common.log("%s: no EXIF focal, guessing %.1f px" % (name, f))
        kps, desc = sift.detectAndCompute(img, None)
        if desc is None:
            kps, desc = [], np.zeros((0, 128), np.float32)
        pts = np.array([[k.pt[0] + 0.5, k.pt[1] + 0.5] for k in kps], dtype=np.float64)
        # RootSIFT: L1-normalise, square root (better ratio-test matching than raw SIFT).
        desc = np.sqrt(desc / (desc.sum(axis=1, keepdims=True) + 1e-12)).astype(np.float32)
        vid = recon.AddView(name, 0, float(i))
        prior = pt.sfm.CameraIntrinsicsPrior()
        prior.focal_length.value = [f]
        prior.principal_point.value = [cx, cy]
        prior.aspect_ratio.value = [1.0]
        prior.skew.value = [0.0]
        prior.image_width = w
        prior.image_height = h
        prior.camera_intrinsics_model_type = "PINHOLE"
        recon.MutableView(vid).SetCameraIntrinsicsPrior(prior)
        views.append(vid)
        feats.append((pts, desc))
        priors.append(prior)
    common.log("SIFT: %s features per image (mean)"
               % int(np.mean([len(p) for p, _ in feats])))

    matcher = cv2.BFMatcher(cv2.NORM_L2)
    n = len(names)
    mode = o.get("matcher", "exhaustive")
    overlap = int(o.get("overlap", 10))
    if mode == "exhaustive":
        pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
    elif mode == "sequential":
        pairs = [(i, j) for i in range(n) for j in range(i + 1, min(n, i + 1 + overlap))]
    else:
        common.fail("unknown matcher %r (exhaustive, sequential)" % mode, 2)
    tv_opts = pt.sfm.EstimateTwoViewInfoOptions()
    tv_opts.max_sampson_error_pixels = float(o.get("max_sampson_error", 2.0))
    view_graph = pt.sfm.ViewGraph()
    builder = pt.sfm.TrackBuilder(int(o.get("min_track", 3)), int(o.get("max_track", 30)))
    edges = 0
    for i, j in pairs:
        (p1, d1), (p2, d2) = feats[i], feats[j]
        if len(d1) < 2 or len(d2) < 2:
            continue
        knn = matcher.knnMatch(d1, d2, k=2)
        good = [m[0] for m in knn if len(m) == 2 and m[0].distance < ratio * m[1].distance]
        # One-to-one: drop train features claimed twice.
        seen, unique = set(), []
        for m in sorted(good, key=lambda m: m.distance):
            if m.trainIdx not in seen:
                seen.add(m.trainIdx)
                unique.append(m)
        if len(unique) < min_inliers:
            continue
        corr = [pt.matching.FeatureCorrespondence(pt.sfm.Feature(p1[m.queryIdx]),
                                                  pt.sfm.Feature(p2[m.trainIdx]))
                for m in unique]
        ok, info, inliers = pt.sfm.EstimateTwoViewInfo(tv_opts, priors[i], priors[j], corr)
        if not ok or len(inliers) < min_inliers:
            continue
        view_graph.AddEdge(views[i], views[j], info)
        for k in inliers:
            builder.AddFeatureCorrespondence(views[i], corr[k].feature1,
                                             views[j], corr[k].feature2)
        edges += 1
    common.log("view graph: %d of %d pairs verified" % (edges, len(pairs)))
    if edges == 0:
        common.fail("no image pair passed two-view verification", 4)
    builder.BuildTracks(recon)
    pt.sfm.SetCameraIntrinsicsFromPriors(recon)
    opts = pt.sfm.ReconstructionEstimatorOptions()
    opts.num_threads = threads
    opts.min_num_two_view_inliers = min_inliers
    if a.known:
        opts.intrinsics_to_optimize = pt.sfm.OptimizeIntrinsicsType.NONE
    else:
        opts.intrinsics_to_optimize = pt.sfm.OptimizeIntrinsicsType.FOCAL_LENGTH
    losses = pt.sfm.LossFunctionType.__members__
    loss = o.get("loss", "trivial")
    if loss.upper() not in losses:
        common.fail("unknown loss %r (%s)" % (loss, ", ".join(k.lower() for k in losses)), 2)
    opts.bundle_adjustment_loss_function_type = losses[loss.upper()]
    opts.bundle_adjustment_robust_loss_width = float(o.get("loss_width", 10.0))
    if a.mode == "global":
        estimator = pt.sfm.GlobalReconstructionEstimator(opts)
    else:
        estimator = pt.sfm.IncrementalReconstructionEstimator(opts)
    common.log("%s reconstruction: %d views, %d tracks" % (a.mode, recon.NumViews(),
                                                            recon.NumTracks()))
    summary = estimator.Estimate(view_graph, recon)
    if hasattr(summary, "success") and not summary.success:
        common.fail("Theia's %s estimator failed: %s" % (a.mode, getattr(summary, "message", "")),
                    4)
    registered = sum(1 for v in recon.ViewIds() if recon.View(v).IsEstimated())
    points = sum(1 for t in recon.TrackIds() if recon.Track(t).IsEstimated())
    common.log("registered %d views, %d points" % (registered, points))
    if registered == 0:
        common.fail("no view was estimated", 4)
    # Theia's COLMAP writer also lists unestimated views and tracks: drop them first.
    for t in list(recon.TrackIds()):
        if not recon.Track(t).IsEstimated():
            recon.RemoveTrack(t)
    for v in list(recon.ViewIds()):
        if not recon.View(v).IsEstimated():
            recon.RemoveView(v)
    if not pt.io.WriteColmapFiles(recon, a.out):
        common.fail("WriteColmapFiles failed", 4)
    # Theia's own exports, kept in the run folder's raw/: the NVM (cameras + points) and the
    # PLY cloud with every camera centre appended in red (255, 0, 0), as a Theia user gets them.
    raw = common.run_subdir(a.out, "raw")
    if not pt.io.WriteNVMFile(os.path.join(raw, "reconstruction.nvm"), recon):
        common.fail("WriteNVMFile failed", 4)
    red = np.array([255, 0, 0], dtype=np.int32)
    if not pt.io.WritePlyFile(os.path.join(raw, "points.ply"), recon, red, 0):
        common.fail("WritePlyFile failed", 4)
    version = "?"
    try:
        from importlib.metadata import version as pkg_version
        version = pkg_version("pytheia")
    except Exception:  # noqa: BLE001 - version is informative only
        pass
    common.write_tool_json(a.out, "pytheia", version, registered, points,
                           {"opencv": cv2.__version__, "verified_pairs": edges})


if __name__ == "__main__":
    main()
