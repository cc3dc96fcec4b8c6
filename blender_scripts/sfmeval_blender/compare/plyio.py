"""PLY vertices in and out (numpy): read the vertex properties of any ASCII or binary PLY
(``sfmeval export``'s points, ``sfmeval eval --colored``'s colours), write the points the user
kept (float64 rows of the exported source) as a binary little-endian PLY the CLI reads."""

import numpy as np

_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
          "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4",
          "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def read_vertices(path):
    """(N, 3) float64 vertex positions of the PLY at `path`; ValueError naming the file."""
    cols = read_columns(path)
    return np.stack([cols["x"], cols["y"], cols["z"]], axis=1)


def read_columns(path):
    """{property: (N,) float64} of the vertices of the PLY at `path` (x, y, z required);
    ValueError naming the file."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise ValueError("%s is not a PLY file (no 'ply' magic or no end_header)" % path)
    header = data[:end].decode("ascii", "replace").splitlines()
    body = data[data.index(b"\n", end) + 1:]
    fmt, elements = None, []
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == "format":
            fmt = w[1]
        elif w[0] == "element":
            elements.append([w[1], int(w[2]), []])
        elif w[0] == "property" and elements:
            if w[1] == "list":
                elements[-1][2].append((w[4], None))
            else:
                if w[1] not in _TYPES:
                    raise ValueError("%s: unknown PLY property type %r" % (path, w[1]))
                elements[-1][2].append((w[2], _TYPES[w[1]]))
    if not elements or elements[0][0] != "vertex":
        raise ValueError("%s: the first PLY element is not 'vertex'" % path)
    _, n, props = elements[0]
    names = [p[0] for p in props]
    if not {"x", "y", "z"} <= set(names) or any(t is None for _, t in props):
        raise ValueError("%s: vertices need x, y, z and no list properties" % path)
    try:
        if fmt == "ascii":
            rows = body.decode("ascii").split("\n")[:n]
            arr = np.array([r.split()[:len(props)] for r in rows], dtype=np.float64)
            cols = {name: arr[:, i] for i, name in enumerate(names)}
        elif fmt in ("binary_little_endian", "binary_big_endian"):
            e = "<" if fmt == "binary_little_endian" else ">"
            dt = np.dtype([(name, e + t) for name, t in props])
            rec = np.frombuffer(body, dtype=dt, count=n)
            cols = {name: rec[name].astype(np.float64) for name in names}
        else:
            raise ValueError("unknown PLY format %r" % fmt)
    except ValueError as exc:
        raise ValueError("%s: truncated or malformed PLY body (%s)" % (path, exc))
    return cols


def write_points(path, points):
    """Binary little-endian PLY with double x, y, z (exact: no rounding of the positions)."""
    pts = np.ascontiguousarray(np.asarray(points, dtype="<f8").reshape(-1, 3))
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\ncomment sfmeval Blender add-on: the "
                 "points kept\nelement vertex %d\nproperty double x\nproperty double y\n"
                 "property double z\nend_header\n" % len(pts)).encode("ascii"))
        f.write(pts.tobytes())
