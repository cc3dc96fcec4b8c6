# Lines 113-122 of facebookresearch/PoseDiffusion pose_diffusion/test.py at commit
# b138198e2891a0f1a1c3435614b9490adb7fd4d6 (CC BY-NC 4.0, LICENSE.txt here), the
# thresholds and comparisons of RRA, RTA and AUC@30, unchanged except that the
# per-category dictionary assignments became a returned dict (the keys are the
# original ones) and calculate_auc_np is VGGSfM's, which also returns the histogram.

import numpy as np

from metric_numpy import calculate_auc_np


def co3d_metrics(rError, tError):
    category_dict = {}
    category_dict["Racc_5"] = np.mean(rError < 5) * 100
    category_dict["Racc_15"] = np.mean(rError < 15) * 100
    category_dict["Racc_30"] = np.mean(rError < 30) * 100

    category_dict["Tacc_5"] = np.mean(tError < 5) * 100
    category_dict["Tacc_15"] = np.mean(tError < 15) * 100
    category_dict["Tacc_30"] = np.mean(tError < 30) * 100

    Auc_30 = calculate_auc_np(rError, tError, max_threshold=30)[0]
    category_dict["Auc_30"] = Auc_30 * 100
    return category_dict
