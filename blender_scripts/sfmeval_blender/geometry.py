"""Camera placement and frame conventions, in plain Python (no bpy, no numpy).

Frames
------
* Blender world: right-handed, Z up. A Blender camera looks along its local -Z with +Y up.
* glTF world (the ground-truth frame): Y up. ``(x, y, z)_blender -> (x, z, -y)_gltf``.
* OpenCV camera: x right, y down, z forward. ``x_cam = R · x_world + t``.
"""

import math
import random

# glTF-from-Blender axis change, as a rotation matrix (rows).
GLTF_FROM_BLENDER = ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0))
# OpenCV camera from Blender camera axes.
CV_FROM_BLENDERCAM = ((1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, -1.0))


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def matvec(a, v):
    return [sum(a[i][k] * v[k] for k in range(3)) for i in range(3)]


def transpose(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def norm(v):
    return math.sqrt(sum(x * x for x in v))


def normalize(v):
    n = norm(v)
    return [x / n for x in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def blender_to_gltf(p):
    return [p[0], p[2], -p[1]]


def look_at_rotation(eye, target):
    """World-from-camera rotation (columns = camera x, y, z axes) of a Blender camera at `eye`
    looking at `target`, with the image's up direction as close to world +Z as possible."""
    back = normalize(sub(eye, target))           # camera +Z points away from the target
    up = [0.0, 0.0, 1.0]
    if norm(cross(up, back)) < 1e-6:               # looking straight down/up: use +Y as up
        up = [0.0, 1.0, 0.0]
    right = normalize(cross(up, back))
    cam_up = cross(back, right)
    return [[right[i], cam_up[i], back[i]] for i in range(3)]


def intrinsics(cam_cfg):
    """Pinhole intrinsics in pixels, COLMAP convention (cx = W/2 for a centred camera).

    Blender fits the sensor horizontally (sensor_fit = HORIZONTAL): fx = f / sensor_w · W.
    Lens shift is in units of the image width: cx = W/2 − shift_x·W, cy = H/2 + shift_y·W.
    """
    w, h = cam_cfg["resolution"]
    f = float(cam_cfg["focal_mm"])
    sw = float(cam_cfg["sensor_mm"][0])
    fx = f / sw * w
    sx, sy = cam_cfg["shift"]
    return {"width": int(w), "height": int(h), "fx": fx, "fy": fx,
            "cx": w / 2.0 - sx * w, "cy": h / 2.0 + sy * w}


def half_fov_min(cam_cfg):
    k = intrinsics(cam_cfg)
    return min(math.atan(k["width"] / 2.0 / k["fx"]), math.atan(k["height"] / 2.0 / k["fy"]))


def auto_radius(bound_radius, cam_cfg, fill):
    """Distance at which the bounding sphere (radius `bound_radius` around the target) is seen
    under `fill` × the sine of the narrower half field of view: with fill <= 1 the whole
    object is inside every image whose camera looks at the target."""
    return bound_radius / (fill * math.sin(half_fov_min(cam_cfg)))


def _radius(value, auto):
    return auto if value == "auto" else float(value)


def _point(target, radius, azimuth, elevation):
    ce = math.cos(elevation)
    return [target[0] + radius * ce * math.cos(azimuth),
            target[1] + radius * ce * math.sin(azimuth),
            target[2] + radius * math.sin(elevation)]


def camera_positions(views_cfg, target, auto, seed):
    """List of dicts {group, eye, azimuth_deg, elevation_deg, radius} in the Blender frame.

    Order: every orbit ring in config order (azimuth increasing), then the Fibonacci sphere
    band, then the seeded random shell. Deterministic for the same config and seed.
    """
    out = []
    for i, ring in enumerate(views_cfg["orbits"]):
        n = int(ring["count"])
        r = _radius(ring["radius"], auto)
        el = math.radians(ring["elevation_deg"])
        for k in range(n):
            step = ring.get("azimuth_step_deg", 0.0)
            if step > 0:  # a partial arc: neighbours `step` degrees apart
                az = math.radians(ring["azimuth_offset_deg"] + step * k)
            else:
                az = math.radians(ring["azimuth_offset_deg"]) + 2.0 * math.pi * k / n
            out.append({"group": "orbit%d" % i, "eye": _point(target, r, az, el),
                        "azimuth_deg": math.degrees(az), "elevation_deg": ring["elevation_deg"],
                        "radius": r})
    sph = views_cfg["sphere"]
    n = int(sph["count"])
    if n:
        r = _radius(sph["radius"], auto)
        z0 = math.sin(math.radians(sph["elevation_min_deg"]))
        z1 = math.sin(math.radians(sph["elevation_max_deg"]))
        golden = math.pi * (3.0 - math.sqrt(5.0))
        for k in range(n):
            z = z0 + (z1 - z0) * (k + 0.5) / n       # uniform in z = uniform area on the band
            el = math.asin(max(-1.0, min(1.0, z)))
            az = (golden * k) % (2.0 * math.pi)
            out.append({"group": "sphere", "eye": _point(target, r, az, el),
                        "azimuth_deg": math.degrees(az), "elevation_deg": math.degrees(el),
                        "radius": r})
    sh = views_cfg["shell"]
    n = int(sh["count"])
    if n:
        rng = random.Random(int(seed) * 7919 + 17)
        r0 = _radius(sh["radius_min"], auto * 0.9)
        r1 = _radius(sh["radius_max"], auto * 1.2)
        z0 = math.sin(math.radians(sh["elevation_min_deg"]))
        z1 = math.sin(math.radians(sh["elevation_max_deg"]))
        for _ in range(n):
            az = rng.uniform(0.0, 2.0 * math.pi)
            el = math.asin(rng.uniform(z0, z1))
            # uniform in volume between the radii
            r = (rng.uniform(r0 ** 3, r1 ** 3)) ** (1.0 / 3.0)
            out.append({"group": "shell", "eye": _point(target, r, az, el),
                        "azimuth_deg": math.degrees(az), "elevation_deg": math.degrees(el),
                        "radius": r})
    return out


def opencv_pose_gltf(world_from_cam_blender, center_blender):
    """cam_from_world (R, t) in the OpenCV convention and the glTF frame, from a Blender
    camera's world rotation (3×3, columns = camera axes) and centre (Blender frame)."""
    r_cb = matmul(CV_FROM_BLENDERCAM, transpose(world_from_cam_blender))   # cam_cv from world_b
    r = matmul(r_cb, transpose(GLTF_FROM_BLENDER))                          # cam_cv from world_g
    c = matvec(GLTF_FROM_BLENDER, center_blender)
    t = [-x for x in matvec(r, c)]
    return r, t, c


def rotation_to_quaternion(r):
    """Unit quaternion (w, x, y, z) of a rotation matrix, w >= 0 (COLMAP order)."""
    tr = r[0][0] + r[1][1] + r[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = [0.25 * s, (r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s]
    elif r[0][0] > r[1][1] and r[0][0] > r[2][2]:
        s = math.sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2
        q = [(r[2][1] - r[1][2]) / s, 0.25 * s, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s]
    elif r[1][1] > r[2][2]:
        s = math.sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2
        q = [(r[0][2] - r[2][0]) / s, (r[0][1] + r[1][0]) / s, 0.25 * s, (r[1][2] + r[2][1]) / s]
    else:
        s = math.sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2
        q = [(r[1][0] - r[0][1]) / s, (r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, 0.25 * s]
    n = math.sqrt(sum(x * x for x in q))
    q = [x / n for x in q]
    if q[0] < 0:
        q = [-x for x in q]
    return q


def quaternion_to_rotation(q):
    """Rotation matrix of a quaternion (w, x, y, z), normalised first, in double precision."""
    n = math.sqrt(sum(float(c) ** 2 for c in q))
    w, x, y, z = (float(c) / n for c in q)
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
