# Copyright (c), ETH Zurich and UNC Chapel Hill.
# Functions of colmap/colmap benchmark/reconstruction/evaluation/utils.py at commit
# 5d968cf38aa2574fd284b0dc86c3d58d124940b3, copied unchanged (the file's other functions run reconstructions
# and are not needed). Imports: those these functions use.

import collections
import itertools

import numpy as np
import numpy.typing as npt

import pycolmap

from geometry import vec_angular_dist_deg

OUTLIER_COMPONENT_ID = -1


def compute_rel_pose_error(
    tgt_from_src_est: pycolmap.Rigid3d,
    tgt_from_src_gt: pycolmap.Rigid3d,
    min_proj_center_dist: float,
) -> tuple[float, float]:
    """Angular relative pose errors (dt, dR) in degrees.

    dR is the geodesic rotation error and dt is the angular distance between
    the relative translation directions. If the GT baseline is shorter than
    min_proj_center_dist, the translation direction is unstable and dt is set
    to zero, so only the rotation error is measured.
    """
    estimated_from_gt = tgt_from_src_est.inverse() * tgt_from_src_gt

    if np.linalg.norm(tgt_from_src_gt.translation) < min_proj_center_dist:
        # If the cameras almost coincide, then the angular direction distance
        # is unstable, because a small position change can cause a large
        # rotational error. In this case, we only measure rotational error.
        dt = 0.0
    else:
        dt = vec_angular_dist_deg(
            tgt_from_src_est.translation, tgt_from_src_gt.translation
        )

    dR = np.rad2deg(estimated_from_gt.rotation.angle())
    return dt, dR


def compute_grouped_rel_errors(
    sparse_gt: pycolmap.Reconstruction,
    sub_models: list[pycolmap.Reconstruction],
    image_name_to_component: dict[str, int],
    min_proj_center_dist: float,
) -> npt.NDArray[np.floating]:
    """Set-based relative pose errors over the graph of image pairs.

    Let A be the set of ordered image pairs (i, j) that share an estimated
    sub-model and B the set of ordered pairs that share a GT component (as
    defined by image_name_to_component). For pairs in A n B we measure the
    relative pose error; for pairs in the symmetric difference (grouped in only
    one of the two, i.e. wrong merges / registered outliers or failed /
    fragmented registrations) we assign the maximum error of 180 degrees. The
    returned error array covers all pairs in A u B.

    A and B are materialized as flat collections and scored in a single pass.
    A is a multiset (tgt_from_src_est_edges): an image may appear in several
    sub-models, so the same edge can carry several estimated relative poses,
    each contributing one error entry.
    """
    gt_cam_from_world = {
        image.name: image.cam_from_world()
        for image in sparse_gt.images.values()
    }

    # A: ordered estimated edges -> list of relative poses (one per sub-model
    # containing both endpoints). Keeping a list makes A a multiset.
    tgt_from_src_est_edges: dict[tuple[str, str], list[pycolmap.Rigid3d]] = (
        collections.defaultdict(list)
    )
    for sub_model in sub_models:
        cam_from_world = {
            image.name: image.cam_from_world()
            for image in sub_model.images.values()
        }
        for src_name, tgt_name in itertools.permutations(cam_from_world, 2):
            tgt_from_src_est = (
                cam_from_world[tgt_name] * cam_from_world[src_name].inverse()
            )
            tgt_from_src_est_edges[(src_name, tgt_name)].append(
                tgt_from_src_est
            )

    # B: ordered GT edges grouped by GT component. Outliers never belong to a
    # GT component, and names absent from sparse_gt cannot form a measurable GT
    # edge, so both are excluded here.
    names_by_component: dict[int, list[str]] = collections.defaultdict(list)
    for name, component in image_name_to_component.items():
        if component == OUTLIER_COMPONENT_ID or name not in gt_cam_from_world:
            continue
        names_by_component[component].append(name)
    gt_edges: set[tuple[str, str]] = set()
    for group_names in names_by_component.values():
        gt_edges.update(itertools.permutations(group_names, 2))

    errors: list[float] = []
    for edge in set(tgt_from_src_est_edges) | gt_edges:
        src_name, tgt_name = edge
        tgt_from_src_ests = tgt_from_src_est_edges.get(edge, [])
        if edge in gt_edges:
            tgt_from_src_gt = (
                gt_cam_from_world[tgt_name]
                * gt_cam_from_world[src_name].inverse()
            )
            if not tgt_from_src_ests:
                # Edge in B - A: failed / fragmented registration.
                errors.append(180.0)
            for tgt_from_src_est in tgt_from_src_ests:
                # Edge in A n B: measure the relative pose error.
                dt, dR = compute_rel_pose_error(
                    tgt_from_src_est, tgt_from_src_gt, min_proj_center_dist
                )
                errors.append(max(dt, dR))
        else:
            # Edge in A - B: wrong merge or registered outlier.
            errors.extend(180.0 for _ in tgt_from_src_ests)

    if not errors:
        # No evaluable pairs (e.g. only singleton GT reconstructions). Report
        # the worst case rather than raising downstream on an empty array.
        return np.array([180.0])
    return np.array(errors)


def compute_auc(
    errors: npt.NDArray[np.floating],
    thresholds: npt.NDArray[np.floating],
    min_error: float = 0,
) -> npt.NDArray[np.floating]:
    num_elems = len(errors)
    if len(errors) == 0:
        raise ValueError("No errors to evaluate")

    errors = np.sort(errors)
    recalls = (np.arange(num_elems) + 1) / num_elems

    if min_error > 0:
        min_index = np.searchsorted(errors, min_error, side="right")
        min_recall = min_index / num_elems
        recalls = np.r_[min_recall, min_recall, recalls[min_index:]]
        errors = np.r_[0, min_error, errors[min_index:]]
    else:
        recalls = np.r_[0, recalls]
        errors = np.r_[0, errors]

    aucs = np.zeros(len(thresholds), dtype=np.float64)
    for i, t in enumerate(thresholds):
        last_index = np.searchsorted(errors, t, side="right")
        r = np.r_[recalls[:last_index], recalls[last_index - 1]]
        e = np.r_[errors[:last_index], t]
        auc = np.trapezoid(r, x=e) / t
        aucs[i] = auc * 100

    return aucs


def compute_recall(
    errors: npt.NDArray[np.floating],
    thresholds: npt.NDArray[np.floating],
    min_error: float = 0,
) -> npt.NDArray[np.floating]:
    num_elems = len(errors)
    if num_elems == 0:
        raise ValueError("No errors to evaluate")

    recalls = np.zeros(len(thresholds), dtype=np.float64)
    for i, t in enumerate(thresholds):
        recalls[i] = 100 * np.sum(errors <= t) / num_elems

    return recalls
