# Copyright (c) Meta Platforms, Inc. and affiliates.
# All rights reserved.
#
# This source code is licensed under the license found in the
# LICENSE file in the root directory of this source tree.

# numpy port of the functions of metric.py (facebookresearch/vggsfm
# vggsfm/utils/metric.py) and rotation_conversions.py (minipytorch3d) that
# camera_to_rel_deg and calculate_auc_np use, because torch is not in the
# project's environment. Every change from the originals, both in this folder
# unchanged, is listed in README.md; the arithmetic is the same expression for
# expression.

import numpy as np


# --- rotation_conversions.py ---
def _sqrt_positive_part(x):
    ret = np.zeros_like(x)
    positive_mask = x > 0
    ret[positive_mask] = np.sqrt(x[positive_mask])
    return ret


def standardize_quaternion(quaternions):
    return np.where(quaternions[..., 0:1] < 0, -quaternions, quaternions)


def matrix_to_quaternion(matrix):
    if matrix.shape[-1] != 3 or matrix.shape[-2] != 3:
        raise ValueError(f"Invalid rotation matrix shape {matrix.shape}.")

    batch_dim = matrix.shape[:-2]
    m00, m01, m02, m10, m11, m12, m20, m21, m22 = np.moveaxis(
        matrix.reshape(batch_dim + (9,)), -1, 0
    )

    q_abs = _sqrt_positive_part(
        np.stack(
            [
                1.0 + m00 + m11 + m22,
                1.0 + m00 - m11 - m22,
                1.0 - m00 + m11 - m22,
                1.0 - m00 - m11 + m22,
            ],
            axis=-1,
        )
    )

    quat_by_rijk = np.stack(
        [
            np.stack([q_abs[..., 0] ** 2, m21 - m12, m02 - m20, m10 - m01], axis=-1),
            np.stack([m21 - m12, q_abs[..., 1] ** 2, m10 + m01, m02 + m20], axis=-1),
            np.stack([m02 - m20, m10 + m01, q_abs[..., 2] ** 2, m12 + m21], axis=-1),
            np.stack([m10 - m01, m20 + m02, m21 + m12, q_abs[..., 3] ** 2], axis=-1),
        ],
        axis=-2,
    )

    flr = np.array(0.1, dtype=q_abs.dtype)
    quat_candidates = quat_by_rijk / (2.0 * np.maximum(q_abs[..., None], flr))

    out = quat_candidates[
        np.eye(4)[q_abs.argmax(axis=-1)] > 0.5, :
    ].reshape(batch_dim + (4,))
    return standardize_quaternion(out)


# --- metric.py ---
def camera_to_rel_deg(gt_se3, pred_se3, batch_size):
    # Generate pairwise indices to compute relative poses
    pair_idx_i1, pair_idx_i2 = batched_all_pairs(
        batch_size, gt_se3.shape[0] // batch_size
    )

    # Compute relative camera poses between pairs
    relative_pose_gt = closed_form_inverse(gt_se3[pair_idx_i1]) @ gt_se3[pair_idx_i2]
    relative_pose_pred = closed_form_inverse(pred_se3[pair_idx_i1]) @ pred_se3[pair_idx_i2]

    # Compute the difference in rotation and translation
    rel_rangle_deg = rotation_angle(
        relative_pose_gt[:, :3, :3], relative_pose_pred[:, :3, :3]
    )
    rel_tangle_deg = translation_angle(
        relative_pose_gt[:, 3, :3], relative_pose_pred[:, 3, :3]
    )

    return rel_rangle_deg, rel_tangle_deg


def calculate_auc_np(r_error, t_error, max_threshold=30):
    # Unchanged (metric.py's numpy version).
    error_matrix = np.concatenate((r_error[:, None], t_error[:, None]), axis=1)
    max_errors = np.max(error_matrix, axis=1)
    bins = np.arange(max_threshold + 1)
    histogram, _ = np.histogram(max_errors, bins=bins)
    num_pairs = float(len(max_errors))
    normalized_histogram = histogram.astype(float) / num_pairs
    return np.mean(np.cumsum(normalized_histogram)), normalized_histogram


def batched_all_pairs(B, N):
    i1_, i2_ = np.array(
        [(a, b) for a in range(N) for b in range(a + 1, N)], dtype=np.int64
    ).reshape(-1, 2).T
    i1, i2 = [
        (i[None] + np.arange(B)[:, None] * N).reshape(-1) for i in [i1_, i2_]
    ]

    return i1, i2


def closed_form_inverse(se3, R=None, T=None):
    # NOTE THIS ASSUMES PYTORCH3D CAMERA COORDINATE
    if R is None:
        R = se3[:, :3, :3]

    if T is None:
        T = se3[:, 3:, :3]

    R_transposed = np.transpose(R, (0, 2, 1))

    left_bottom = -T @ R_transposed
    left_combined = np.concatenate((R_transposed, left_bottom), axis=1)

    right_col = se3[:, :, 3:].copy()
    inverted_matrix = np.concatenate((left_combined, right_col), axis=-1)

    return inverted_matrix


def rotation_angle(rot_gt, rot_pred, batch_size=None, eps=1e-15):
    q_pred = matrix_to_quaternion(rot_pred)
    q_gt = matrix_to_quaternion(rot_gt)

    loss_q = np.maximum(1 - (q_pred * q_gt).sum(axis=1) ** 2, eps)
    err_q = np.arccos(1 - 2 * loss_q)

    rel_rangle_deg = err_q * 180 / np.pi

    if batch_size is not None:
        rel_rangle_deg = rel_rangle_deg.reshape(batch_size, -1)

    return rel_rangle_deg


def translation_angle(tvec_gt, tvec_pred, batch_size=None, ambiguity=True):
    rel_tangle_deg = compare_translation_by_angle(tvec_gt, tvec_pred)
    rel_tangle_deg = rel_tangle_deg * 180.0 / np.pi

    if ambiguity:
        rel_tangle_deg = np.minimum(rel_tangle_deg, np.abs(180 - rel_tangle_deg))

    if batch_size is not None:
        rel_tangle_deg = rel_tangle_deg.reshape(batch_size, -1)

    return rel_tangle_deg


def compare_translation_by_angle(t_gt, t, eps=1e-15, default_err=1e6):
    """Normalize the translation vectors and compute the angle between them."""
    t_norm = np.linalg.norm(t, axis=1, keepdims=True)
    t = t / (t_norm + eps)

    t_gt_norm = np.linalg.norm(t_gt, axis=1, keepdims=True)
    t_gt = t_gt / (t_gt_norm + eps)

    loss_t = np.maximum(1.0 - np.sum(t * t_gt, axis=1) ** 2, eps)
    err_t = np.arccos(np.sqrt(1 - loss_t))

    err_t[np.isnan(err_t) | np.isinf(err_t)] = default_err
    return err_t
