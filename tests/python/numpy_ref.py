"""Independent numpy reference code shared by the alignment tests: Umeyama's similarity,
quaternions, rotation and scale errors. Written from the papers, not from sfmeval's code."""

import numpy as np


def umeyama_np(src, dst, with_scale=True):
    """Umeyama (1991), eqs. 38-42: the similarity m (4x4) with dst ≈ m(src)."""
    src, dst = np.asarray(src, float), np.asarray(dst, float)
    mu_s, mu_d = src.mean(0), dst.mean(0)
    a, b = src - mu_s, dst - mu_d
    u, d, vt = np.linalg.svd(b.T @ a / len(src))
    s = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        s[2, 2] = -1
    r = u @ s @ vt
    c = np.trace(np.diag(d) @ s) / (a ** 2).sum(1).mean() if with_scale else 1.0
    m = np.eye(4)
    m[:3, :3] = c * r
    m[:3, 3] = mu_d - c * r @ mu_s
    return m


def quat_to_rot(q):
    """Rotation matrix of the quaternion (w, x, y, z), normalised first."""
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def random_rotation(rng):
    """A uniformly random rotation (normalised Gaussian quaternion)."""
    return quat_to_rot(rng.normal(size=4))


def similarity(scale, r, t):
    m = np.eye(4)
    m[:3, :3] = scale * np.asarray(r)
    m[:3, 3] = t
    return m


def apply(m, p):
    return np.asarray(p) @ m[:3, :3].T + m[:3, 3]


def decompose(m):
    """(scale, rotation) of a similarity's 3x3 block."""
    s = np.cbrt(np.linalg.det(m[:3, :3]))
    return s, m[:3, :3] / s


def rot_err_deg(a, b):
    """Angle of the rotation between two similarities, degrees."""
    ra, rb = decompose(a)[1], decompose(b)[1]
    return float(np.degrees(np.arccos(np.clip((np.trace(ra @ rb.T) - 1) / 2, -1, 1))))


def scale_err(a, b):
    """Relative scale error of a against b."""
    return abs(decompose(a)[0] / decompose(b)[0] - 1)
