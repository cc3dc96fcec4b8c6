"""A crop volume from a Blender object, as an ``sfmeval.crop/1`` file (format:
crates/sfmeval/src/crop.rs). The volume is the object's local bounds (an empty's display cube
or sphere, a mesh's bounding box) carried by its world matrix (location, rotation, scale) into
the ground-truth frame, which is Blender's world frame for a dataset made here."""

import json

import numpy as np

CROP_SCHEMA = "sfmeval.crop/1"


def volume_from_matrix(kind, matrix_world, local_min, local_max):
    """The crop volume dict of a `kind` ("box" or "sphere") object with these local bounds.

    A box becomes an ``oriented_box`` (axes = the normalised columns of the matrix); a sphere
    needs a uniform scale and a cubic local bound (else ValueError)."""
    m = np.asarray(matrix_world, dtype=float).reshape(4, 4)
    lo, hi = np.asarray(local_min, float), np.asarray(local_max, float)
    center = m[:3, :3] @ ((lo + hi) / 2) + m[:3, 3]
    scale = np.linalg.norm(m[:3, :3], axis=0)
    if np.any(scale <= 0) or np.any(hi < lo):
        raise ValueError("the crop object has a zero scale or empty bounds")
    half = (hi - lo) / 2 * scale
    if kind == "box":
        rot = m[:3, :3] / scale
        if not np.allclose(rot.T @ rot, np.eye(3), atol=1e-6):
            raise ValueError("the crop box is sheared (a parent with a non-uniform scale?): "
                             "apply the parent's transform first")
        return {"kind": "oriented_box", "center": center.tolist(), "half_extents": half.tolist(),
                "rotation": rot.tolist()}
    if kind == "sphere":
        if np.ptp(half) > 1e-6 * max(half.max(), 1e-12):
            raise ValueError("the crop sphere is scaled unevenly (%s): a sphere needs the same "
                             "scale on every axis" % ", ".join("%.4g" % h for h in half))
        return {"kind": "sphere", "center": center.tolist(), "radius": float(half.mean())}
    raise ValueError("crop kind must be box or sphere, got %r" % kind)


def crop_json(volume=None, max_distance=None):
    """The crop file's text (None parts are left out, as the core writes it)."""
    doc = {"schema": CROP_SCHEMA}
    if volume is not None:
        doc["volume"] = volume
    if max_distance is not None:
        doc["max_distance"] = float(max_distance)
    return json.dumps(doc, indent=2) + "\n"
