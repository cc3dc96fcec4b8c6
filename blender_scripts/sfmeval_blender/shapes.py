"""Procedural geometry of the five built-in objects, in plain Python (no bpy).

Each builder returns a :class:`MeshData` in metres, Blender frame (Z up), standing on z = 0,
plus its material descriptions. Pseudo-random details come from ``random.Random(seed)`` so
the same seed gives the same geometry bit for bit, in any Blender version.
"""

import math
import random


class MeshData:
    def __init__(self):
        self.verts = []
        self.faces = []
        self.face_mat = []
        self.face_smooth = []

    def add(self, verts, faces, mat=0, smooth=True):
        base = len(self.verts)
        self.verts.extend([tuple(float(c) for c in v) for v in verts])
        for f in faces:
            self.faces.append(tuple(base + i for i in f))
            self.face_mat.append(mat)
            self.face_smooth.append(smooth)


# -- primitive builders -----------------------------------------------------------------------
def lathe(profile, segments, radial=None, cap_bottom=True, cap_top=True):
    """Surface of revolution around Z. profile: [(r, z), ...] bottom to top.
    radial(theta, z) -> factor on r (optional, for organic deformation)."""
    verts, faces = [], []
    for (r, z) in profile:
        for s in range(segments):
            th = 2 * math.pi * s / segments
            rr = r * (radial(th, z) if radial else 1.0)
            verts.append((rr * math.cos(th), rr * math.sin(th), z))
    n = len(profile)
    for i in range(n - 1):
        for s in range(segments):
            a = i * segments + s
            b = i * segments + (s + 1) % segments
            faces.append((a, b, b + segments, a + segments))
    if cap_bottom:
        c = len(verts)
        verts.append((0.0, 0.0, profile[0][1]))
        for s in range(segments):
            faces.append((c, (s + 1) % segments, s))
    if cap_top:
        c = len(verts)
        verts.append((0.0, 0.0, profile[-1][1]))
        top = (n - 1) * segments
        for s in range(segments):
            faces.append((c, top + s, top + (s + 1) % segments))
    return verts, faces


def _frame(direction):
    d = direction
    ln = math.sqrt(sum(x * x for x in d))
    d = [x / ln for x in d]
    a = [0.0, 0.0, 1.0] if abs(d[2]) < 0.9 else [1.0, 0.0, 0.0]
    u = [a[1] * d[2] - a[2] * d[1], a[2] * d[0] - a[0] * d[2], a[0] * d[1] - a[1] * d[0]]
    lu = math.sqrt(sum(x * x for x in u))
    u = [x / lu for x in u]
    v = [d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]]
    return d, u, v


def tube(p0, p1, radius, sides=8, caps=True, r1=None):
    """Closed cylinder (or cone frustum if r1 is given) from p0 to p1."""
    r1 = radius if r1 is None else r1
    d, u, v = _frame([p1[i] - p0[i] for i in range(3)])
    verts, faces = [], []
    for end, (p, r) in enumerate(((p0, radius), (p1, r1))):
        for s in range(sides):
            th = 2 * math.pi * s / sides
            c, sn = math.cos(th) * r, math.sin(th) * r
            verts.append(tuple(p[i] + c * u[i] + sn * v[i] for i in range(3)))
    for s in range(sides):
        a, b = s, (s + 1) % sides
        faces.append((a, b, b + sides, a + sides))
    if caps:
        faces.append(tuple(reversed(range(sides))))
        faces.append(tuple(range(sides, 2 * sides)))
    return verts, faces


def torus(center, axis, major, minor, seg_major=48, seg_minor=8):
    d, u, v = _frame(axis)
    verts, faces = [], []
    for i in range(seg_major):
        a = 2 * math.pi * i / seg_major
        radial = [math.cos(a) * u[k] + math.sin(a) * v[k] for k in range(3)]
        for j in range(seg_minor):
            b = 2 * math.pi * j / seg_minor
            verts.append(tuple(center[k] + (major + minor * math.cos(b)) * radial[k]
                               + minor * math.sin(b) * d[k] for k in range(3)))
    for i in range(seg_major):
        for j in range(seg_minor):
            a = i * seg_minor + j
            b = ((i + 1) % seg_major) * seg_minor + j
            c = ((i + 1) % seg_major) * seg_minor + (j + 1) % seg_minor
            e = i * seg_minor + (j + 1) % seg_minor
            faces.append((a, b, c, e))
    return verts, faces


def box(center, size, cuts=1):
    """Axis-aligned box with each face split into cuts×cuts quads."""
    cx, cy, cz = center
    hx, hy, hz = (s / 2.0 for s in size)
    verts, faces = [], []
    index = {}

    def vid(p):
        key = tuple(round(c, 9) for c in p)
        if key not in index:
            index[key] = len(verts)
            verts.append(p)
        return index[key]

    n = cuts
    for axis in range(3):
        for sign in (-1, 1):
            o = [(axis + 1) % 3, (axis + 2) % 3]
            for i in range(n):
                for j in range(n):
                    quad = []
                    for (di, dj) in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis] = sign
                        p[o[0]] = -1 + 2.0 * (i + di) / n
                        p[o[1]] = -1 + 2.0 * (j + dj) / n
                        quad.append(vid((cx + p[0] * hx, cy + p[1] * hy, cz + p[2] * hz)))
                    faces.append(tuple(quad) if sign > 0 else tuple(reversed(quad)))
    return verts, faces


def uv_sphere(center, radius, segments=24, rings=12, radial=None):
    profile = []
    for i in range(1, rings):
        phi = math.pi * i / rings
        profile.append((radius * math.sin(phi), -radius * math.cos(phi)))
    verts, faces = lathe(profile, segments, radial=radial)
    # close the poles
    verts = [(x + center[0], y + center[1], z + center[2]) for (x, y, z) in verts]
    n = len(verts)
    verts[n - 2] = (center[0], center[1], center[2] - radius)
    verts[n - 1] = (center[0], center[1], center[2] + radius)
    return verts, faces


class Waves:
    """Smooth seeded pseudo-noise on the cylinder (theta, z): a sum of a few sine products."""

    def __init__(self, rng, terms=6, amp=0.1, max_k=5, max_m=9.0):
        self.terms = [(rng.randint(1, max_k), rng.uniform(2.0, max_m), rng.uniform(0, 2 * math.pi),
                       rng.uniform(0, 2 * math.pi), amp * rng.uniform(0.3, 1.0) / math.sqrt(terms))
                      for _ in range(terms)]

    def __call__(self, th, z):
        return 1.0 + sum(a * math.sin(k * th + p) * math.sin(m * z + q)
                         for (k, m, p, q, a) in self.terms)


# -- materials (descriptions; built into node trees by the Blender side) -------------------------
def material(name, color_a, color_b, pattern="noise", scale=6.0, roughness=0.55, contrast=1.0,
             metallic=0.0):
    return {"name": name, "color_a": list(color_a), "color_b": list(color_b), "pattern": pattern,
            "scale": scale, "roughness": roughness, "contrast": contrast, "metallic": metallic}


# -- the five objects ------------------------------------------------------------------------
def statue(rng):
    m = MeshData()
    m.add(*box((0, 0, 0.09), (0.42, 0.42, 0.18), cuts=3), mat=1, smooth=False)
    body = Waves(rng, terms=8, amp=0.35)
    prof = [(0.16, 0.18), (0.17, 0.25), (0.15, 0.35), (0.13, 0.45), (0.15, 0.55),
            (0.19, 0.65), (0.20, 0.72), (0.16, 0.78), (0.07, 0.82)]
    m.add(*lathe(prof, 32, radial=body, cap_bottom=True, cap_top=True), mat=0)
    head = Waves(rng, terms=6, amp=0.25)
    m.add(*uv_sphere((0.0, 0.01, 0.9), 0.09, 24, 12, radial=head), mat=0)
    # arms: bent tubes
    for side in (-1, 1):
        sh = (0.0, side * 0.19, 0.72)
        el = (0.06, side * 0.26, 0.55 + 0.05 * rng.random())
        wr = (0.12, side * 0.2, 0.44 + 0.05 * rng.random())
        m.add(*tube(sh, el, 0.045, 10), mat=0)
        m.add(*tube(el, wr, 0.04, 10, r1=0.03), mat=0)
    # Fine texture: against 2.5x lower scales (5 and 9), on the small preset (640x360) this
    # grain gives ~30 % more SfM points and a 30-50 % lower median camera-centre error for
    # COLMAP, pycolmap and Theia (coarse marble blobs only give large-scale, poorly localised
    # SIFT features).
    mats = [material("statue_stone", (0.78, 0.72, 0.62), (0.25, 0.2, 0.16), "marble", 12.5, 0.6),
            material("statue_base", (0.35, 0.33, 0.3), (0.8, 0.78, 0.7), "voronoi", 22.5, 0.7)]
    return m, mats, True


def vase(rng):
    m = MeshData()
    ripple = Waves(rng, terms=4, amp=0.06, max_k=6)
    outer = [(0.12, 0.0), (0.17, 0.04), (0.24, 0.15), (0.28, 0.32), (0.26, 0.48), (0.19, 0.62),
             (0.11, 0.74), (0.09, 0.84), (0.12, 0.93), (0.14, 0.97)]
    t = 0.015
    inner = [(r - t, z) for (r, z) in reversed(outer[2:])]
    inner[-1] = (inner[-1][0], 0.15)
    profile = outer + [(0.135, 0.975)] + inner     # lip, then down the inside
    m.add(*lathe(profile, 48, radial=lambda th, z: ripple(th, z) if z < 0.9 else 1.0,
                 cap_bottom=True, cap_top=True), mat=0)
    mats = [material("vase_glaze", (0.12, 0.25, 0.55), (0.85, 0.75, 0.5), "bands", 7.0, 0.35)]
    return m, mats, True


def bicycle(rng):
    m = MeshData()
    wheel_r, wz = 0.33, 0.35
    rear, front = (-0.52, 0.0, wz), (0.52, 0.0, wz)
    for hub in (rear, front):
        m.add(*torus(hub, (0, 1, 0), wheel_r, 0.022, 64, 8), mat=1, smooth=True)     # tyre
        m.add(*torus(hub, (0, 1, 0), wheel_r - 0.03, 0.009, 64, 6), mat=2)          # rim
        m.add(*tube((hub[0], -0.04, hub[2]), (hub[0], 0.04, hub[2]), 0.02, 10), mat=2)
        for k in range(16):
            a = 2 * math.pi * (k + 0.5 * rng.random() * 0) / 16
            side = 0.03 if k % 2 else -0.03
            p0 = (hub[0], side, hub[2])
            p1 = (hub[0] + (wheel_r - 0.035) * math.cos(a), 0.0,
                  hub[2] + (wheel_r - 0.035) * math.sin(a))
            m.add(*tube(p0, p1, 0.0035, 4, caps=False), mat=2, smooth=False)
    bb = (-0.05, 0.0, 0.3)
    seat = (-0.16, 0.0, 0.76)
    head_top, head_bot = (0.37, 0.0, 0.8), (0.41, 0.0, 0.68)
    frame = [(rear, bb), (bb, seat), (seat, head_top), (bb, head_bot), (head_bot, head_top)]
    for (a, b) in frame:
        m.add(*tube(a, b, 0.018, 10), mat=0)
    for side in (-0.05, 0.05):
        m.add(*tube((rear[0], side, rear[2]), (bb[0], side * 0.4, bb[2]), 0.011, 8), mat=0)
        m.add(*tube((rear[0], side, rear[2]), (seat[0], side * 0.3, seat[2] - 0.03), 0.01, 8), mat=0)
        m.add(*tube((head_bot[0], side * 0.6, head_bot[2]), (front[0], side, front[2]), 0.012, 8), mat=0)
    stem_top = (0.35, 0.0, 0.93)
    m.add(*tube(head_top, stem_top, 0.015, 8), mat=0)
    m.add(*tube((0.35, -0.24, 0.93), (0.35, 0.24, 0.93), 0.012, 8), mat=2)
    for side in (-1, 1):
        m.add(*tube((0.35, side * 0.2, 0.93), (0.35, side * 0.25, 0.93), 0.017, 8), mat=1)
    m.add(*tube(seat, (seat[0] - 0.02, 0, 0.86), 0.012, 8), mat=2)
    m.add(*box((seat[0] - 0.03, 0.0, 0.875), (0.22, 0.09, 0.04), cuts=2), mat=1, smooth=False)
    # crank and pedals
    m.add(*tube((bb[0], -0.07, bb[2]), (bb[0], 0.07, bb[2]), 0.02, 10), mat=2)
    m.add(*torus((bb[0], 0.06, bb[2]), (0, 1, 0), 0.09, 0.008, 40, 6), mat=2)
    for side, ang in ((-1, 0.6), (1, 0.6 + math.pi)):
        end = (bb[0] + 0.16 * math.cos(ang), side * 0.09, bb[2] + 0.16 * math.sin(ang))
        m.add(*tube((bb[0], side * 0.08, bb[2]), end, 0.01, 6), mat=2)
        m.add(*box((end[0], side * 0.13, end[2]), (0.09, 0.07, 0.02)), mat=1, smooth=False)
    mats = [material("bike_paint", (0.75, 0.12, 0.08), (0.95, 0.85, 0.2), "noise", 14.0, 0.4),
            material("bike_rubber", (0.05, 0.05, 0.05), (0.35, 0.33, 0.3), "voronoi", 30.0, 0.85),
            material("bike_metal", (0.55, 0.57, 0.6), (0.2, 0.22, 0.25), "noise", 20.0, 0.3, 1.0, 0.6)]
    return m, mats, False


def hydrant(rng):
    m = MeshData()
    prof = [(0.2, 0.0), (0.2, 0.06), (0.15, 0.07), (0.14, 0.12), (0.14, 0.58), (0.18, 0.59),
            (0.18, 0.64), (0.15, 0.65), (0.14, 0.72), (0.10, 0.79), (0.05, 0.81)]
    m.add(*lathe(prof, 48), mat=0)
    m.add(*lathe([(0.045, 0.8), (0.045, 0.87), (0.03, 0.88)], 6), mat=0, smooth=False)  # hex nut
    for side in (-1, 1):                             # two side nozzles: mirror symmetric
        m.add(*tube((0, side * 0.12, 0.44), (0, side * 0.22, 0.44), 0.055, 24), mat=0)
        m.add(*tube((0, side * 0.22, 0.44), (0, side * 0.26, 0.44), 0.065, 6), mat=0, smooth=False)
    for k in range(8):                               # flange bolts
        a = 2 * math.pi * (k + 0.5) / 8
        m.add(*box((0.175 * math.cos(a), 0.175 * math.sin(a), 0.075), (0.025, 0.025, 0.03)),
              mat=0, smooth=False)
    mats = [material("hydrant_paint", (0.62, 0.06, 0.04), (0.55, 0.05, 0.035), "noise", 8.0, 0.45,
                     contrast=0.25)]
    return m, mats, True


def vehicle(rng):
    m = MeshData()
    m.add(*box((0.0, 0.0, 0.22), (1.0, 0.46, 0.2), cuts=4), mat=0, smooth=False)        # chassis
    m.add(*box((-0.1, 0.0, 0.41), (0.5, 0.42, 0.18), cuts=3), mat=0, smooth=False)      # cabin
    m.add(*box((-0.1, 0.0, 0.41), (0.46, 0.43, 0.12), cuts=2), mat=2, smooth=False)     # windows
    m.add(*box((0.52, 0.0, 0.17), (0.06, 0.5, 0.07), cuts=2), mat=1, smooth=False)      # bumpers
    m.add(*box((-0.52, 0.0, 0.17), (0.06, 0.5, 0.07), cuts=2), mat=1, smooth=False)
    for side in (-1, 1):
        m.add(*box((0.5, side * 0.16, 0.26), (0.03, 0.08, 0.05)), mat=2, smooth=False)   # lights
    m.add(*box((-0.3, 0.0, 0.53), (0.12, 0.3, 0.04), cuts=2), mat=1, smooth=False)     # roof rack
    for x in (-0.32, 0.32):
        for side in (-1, 1):
            m.add(*tube((x, side * 0.2, 0.11), (x, side * 0.29, 0.11), 0.11, 20), mat=1)
            m.add(*tube((x, side * 0.292, 0.11), (x, side * 0.3, 0.11), 0.06, 12), mat=3)
    mats = [material("vehicle_paint", (0.2, 0.42, 0.18), (0.75, 0.7, 0.45), "voronoi", 7.0, 0.5),
            material("vehicle_rubber", (0.04, 0.04, 0.04), (0.4, 0.38, 0.35), "noise", 25.0, 0.9),
            material("vehicle_glass", (0.15, 0.25, 0.35), (0.6, 0.75, 0.85), "noise", 10.0, 0.15),
            material("vehicle_hub", (0.7, 0.7, 0.72), (0.25, 0.25, 0.3), "voronoi", 30.0, 0.3)]
    return m, mats, False


BUILDERS = {"statue": statue, "vase": vase, "bicycle": bicycle, "hydrant": hydrant,
            "vehicle": vehicle}


def build(name, seed):
    """(MeshData, materials, smooth) of a built-in object; deterministic for (name, seed)."""
    rng = random.Random("%s/%d" % (name, int(seed)))
    return BUILDERS[name](rng)
