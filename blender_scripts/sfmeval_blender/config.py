"""Dataset configuration: defaults, presets, loading (TOML or JSON) and validation.

Pure Python (no bpy), so it is shared by the add-on, the headless generator and the tests.
Every option has a default here; a config file only overrides what it names. An unknown
option, a value of the wrong type or a dataset without views is a :class:`ConfigError`
raised before Blender is touched.
"""

import copy
import difflib
import json
import math
import os

from . import tomlmini

PRESET_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "presets")
BUILTIN_OBJECTS = ("statue", "vase", "bicycle", "hydrant", "vehicle")
MODEL_EXTENSIONS = (".obj", ".ply", ".stl", ".gltf", ".glb", ".fbx", ".blend")


class ConfigError(ValueError):
    """A problem with the dataset configuration, worded for a person."""


# An item schema for lists of tables: the defaults of one item.
ORBIT_DEFAULTS = {
    "elevation_deg": 20.0,   # above the target's horizontal plane
    "count": 18,             # cameras on the ring, evenly spaced in azimuth
    "radius": "auto",        # metres, or "auto" (fit the object with views.fill)
    "azimuth_offset_deg": 0.0,
    "azimuth_step_deg": 0.0,  # 0 = evenly around the full circle (360/count); > 0 = the angle
                              # between neighbouring cameras: a partial arc of count x step
}
LIGHT_DEFAULTS = {
    "type": "area",          # area | sun | point
    "energy": 300.0,         # W for area/point lights, W/m² (strength) for the sun
    "color": [1.0, 1.0, 1.0],
    "azimuth_deg": 45.0,     # position around the target (Blender frame, from +X towards +Y)
    "elevation_deg": 45.0,
    "distance": 4.0,         # metres from the target (ignored by the sun except for placement)
    "size": 1.0,             # area light edge length / point light radius (m); sun angle (deg)
}

DEFAULTS = {
    "preset": "",
    "dataset": {
        "name": "dataset",
        "description": "",
        "seed": 0,
    },
    "object": {
        "source": "builtin:statue",  # builtin:<name> or a model file (OBJ PLY STL glTF GLB FBX .blend)
        "normalize": True,            # scale so that the largest bounding-box edge is `size`
        "size": 1.0,                  # metres
        "center": True,               # move the bounding-box centre to the origin
        "on_floor": False,            # then lift the object so it stands on z = 0
        "subdivision": 1,             # built-in objects: subdivision-surface levels (modifier)
        "texture_scale": 1.0,         # built-in objects: procedural texture frequency multiplier
        "texture_contrast": -1.0,     # built-in objects: <0 = the object's own default
    },
    "lights": [
        dict(LIGHT_DEFAULTS, type="area", energy=250.0, azimuth_deg=45.0, elevation_deg=50.0,
             distance=4.0, size=2.0),
        dict(LIGHT_DEFAULTS, type="area", energy=120.0, azimuth_deg=-135.0, elevation_deg=25.0,
             distance=4.0, size=2.0),
    ],
    "background": {
        "world_color": [0.5, 0.5, 0.5],  # uniform world colour, linear RGB
        "world_strength": 1.0,
        "floor": False,
        "walls": False,
        "wall_color": [0.6, 0.6, 0.6],
        "room_size": 8.0,                # metres, edge of the floor / walls box
        # Objects in the Blender scene that sfmeval did not make (the add-on's scene: the
        # default Cube, the user's objects; the headless generator starts empty): hidden from
        # every render unless kept as context (in the images; never in masks, depth or GT).
        "keep_other_objects": False,
        "keep_other_lights": False,
    },
    "render": {
        "samples": 32,
        "max_bounces": 4,
        "diffuse_bounces": 2,
        "glossy_bounces": 2,
        "transmission_bounces": 4,
        "adaptive_sampling": False,
        "denoise": "auto",            # "auto" (only where OpenImageDenoise exists), true, false
        "seed": -1,                   # Cycles seed; -1 = dataset.seed
        "filter_width": 1.5,          # pixels (Blackman-Harris)
        "threads": 0,                 # 0 = all cores
        "format": "JPEG",             # JPEG | PNG
        "jpeg_quality": 95,
        "png_color_depth": 8,
        "view_transform": "Standard",
    },
    "camera": {
        "focal_mm": 35.0,
        "sensor_mm": [32.0, 18.0],    # width, height; the sensor is fitted horizontally
        "resolution": [1920, 1080],
        "shift": [0.0, 0.0],          # Blender lens shift, in units of the image width
        "clip_start": 0.01,
        "clip_end": 1000.0,
        "make": "sfmeval",
        "model": "Blender virtual camera",
        "exif": True,
        "exif_focal_plane_unit": "inches",   # inches | cm  (COLMAP 3.8 ignores mm)
        "exif_35mm_equivalent": False,       # FocalLengthIn35mmFilm: off, see README
    },
    "views": {
        "target": "object",           # "object" (bounding-box centre) or [x, y, z] (Blender frame)
        "fill": 0.85,                 # for radius "auto": bounding sphere / half field of view
        "orbits": [
            dict(ORBIT_DEFAULTS, elevation_deg=15.0, count=18),
            dict(ORBIT_DEFAULTS, elevation_deg=40.0, count=18),
        ],
        "sphere": {                   # Fibonacci sampling of a sphere band
            "count": 0,
            "radius": "auto",
            "elevation_min_deg": 5.0,
            "elevation_max_deg": 75.0,
        },
        "shell": {                    # seeded random positions in a spherical shell band
            "count": 0,
            "radius_min": "auto",
            "radius_max": "auto",
            "elevation_min_deg": 5.0,
            "elevation_max_deg": 75.0,
        },
    },
    "postprocess": {                  # applied to every view before EXIF (postprocess.py)
        "blur_sigma": 0.0,            # Gaussian blur, pixels (0 = off)
        "noise_sigma": 0.0,           # additive Gaussian noise, 8-bit grey levels (0 = off)
        "seed": -1,                   # noise seed; -1 = dataset.seed
    },
    "outputs": {
        "depth": True,                # depth/NNNN.npy, float32 metres along the optical axis
        "masks": True,                # masks/NNNN.png, 8-bit, 255 = object
        "colmap_gt": True,            # sparse_gt/ COLMAP text model of the true cameras
        "save_blend": False,          # scene.blend (the whole scene, for inspection)
        "name_format": "{:04d}",
    },
}

LIST_ITEM_DEFAULTS = {
    ("lights",): LIGHT_DEFAULTS,
    ("views", "orbits"): ORBIT_DEFAULTS,
}

CHOICES = {
    ("render", "format"): ("JPEG", "PNG"),
    ("camera", "exif_focal_plane_unit"): ("inches", "cm"),
    ("lights", "type"): ("area", "sun", "point"),
    ("render", "png_color_depth"): (8, 16),
}


# -- loading -------------------------------------------------------------------------------
def load_file(path):
    """Read a TOML (.toml) or JSON (.json) config file into a dict."""
    if not os.path.isfile(path):
        raise ConfigError("config file not found: %s" % path)
    with open(path, "rb") as f:
        raw = f.read()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ConfigError("config file is not UTF-8 text: %s" % path) from None
    if path.lower().endswith(".json"):
        try:
            data = json.loads(text)
        except ValueError as exc:
            raise ConfigError("%s: invalid JSON: %s" % (path, exc)) from None
    else:
        try:
            data = tomlmini.loads(text)
        except tomlmini.TomlError as exc:
            raise ConfigError("%s: invalid TOML: %s" % (path, exc)) from None
    if not isinstance(data, dict):
        raise ConfigError("%s: the top level must be a table" % path)
    # Relative model paths are relative to the config file.
    src = data.get("object", {}).get("source") if isinstance(data.get("object"), dict) else None
    if isinstance(src, str) and not src.startswith("builtin:") and not os.path.isabs(src):
        data["object"]["source"] = os.path.normpath(
            os.path.join(os.path.dirname(os.path.abspath(path)), src))
    return data


def preset_names():
    return sorted(f[:-5] for f in os.listdir(PRESET_DIR) if f.endswith(".toml"))


def load_preset(name):
    path = os.path.join(PRESET_DIR, name + ".toml")
    if not os.path.isfile(path):
        raise ConfigError("unknown preset %r (known: %s)" % (name, ", ".join(preset_names())))
    data = load_file(path)
    if data.get("preset"):
        raise ConfigError("preset %s must not name another preset" % name)
    return data


def parse_override(text):
    """``section.key=value`` (value in TOML syntax, bare words taken as strings)."""
    if "=" not in text:
        raise ConfigError("--set expects section.key=value, got %r" % text)
    key, value = text.split("=", 1)
    try:
        parsed = tomlmini.loads("v = " + value.strip())["v"]
    except tomlmini.TomlError:
        parsed = value.strip()
    out = {}
    node = out
    parts = key.strip().split(".")
    for p in parts[:-1]:
        node = node.setdefault(p, {})
    node[parts[-1]] = parsed
    return out


def merge(base, over):
    """Deep merge of dicts; lists and scalars in `over` replace those in `base`."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def resolve(user=None, preset=None, overrides=()):
    """Defaults ← preset ← user config ← overrides, then validated. Returns a new dict."""
    user = user or {}
    layers = [user] + [parse_override(o) if isinstance(o, str) else o for o in overrides]
    name = preset or ""
    for layer in layers:
        if isinstance(layer, dict) and layer.get("preset"):
            name = layer["preset"]
    # Validate keys of every layer against the defaults before merging (unknown options).
    for layer in layers:
        check_keys(layer, DEFAULTS, ())
    cfg = copy.deepcopy(DEFAULTS)
    if name:
        cfg = merge(cfg, load_preset(name))
    for layer in layers:
        cfg = merge(cfg, layer)
    cfg["preset"] = name
    cfg = fill_list_items(cfg)
    validate(cfg)
    return cfg


def fill_list_items(cfg):
    for path, item_defaults in LIST_ITEM_DEFAULTS.items():
        node = cfg
        for p in path[:-1]:
            node = node[p]
        node[path[-1]] = [merge(item_defaults, it) if isinstance(it, dict) else it
                          for it in node[path[-1]]]
    return cfg


def _suggest(key, known):
    close = difflib.get_close_matches(key, list(known), n=1)
    return " (did you mean %r?)" % close[0] if close else ""


def check_keys(layer, defaults, path):
    if not isinstance(layer, dict):
        raise ConfigError("%s: expected a table" % (".".join(path) or "config"))
    for key, value in layer.items():
        here = path + (key,)
        name = ".".join(here)
        if key not in defaults:
            known = ", ".join(sorted(defaults))
            raise ConfigError("unknown option %r%s; known options here: %s"
                              % (name, _suggest(key, defaults), known))
        dv = defaults[key]
        if isinstance(dv, dict):
            check_keys(value, dv, here)
        elif here in LIST_ITEM_DEFAULTS:
            if not isinstance(value, list):
                raise ConfigError("%s must be an array of tables" % name)
            for i, item in enumerate(value):
                check_keys(item, LIST_ITEM_DEFAULTS[here], path + ("%s[%d]" % (key, i),))


def _type_ok(default, value):
    if isinstance(default, bool):
        return isinstance(value, bool)
    if isinstance(default, float):
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if isinstance(default, int):
        return isinstance(value, int) and not isinstance(value, bool)
    if isinstance(default, str):
        return isinstance(value, str)
    if isinstance(default, list):
        return isinstance(value, list)
    return True


def _check_types(node, defaults, path):
    for key, dv in defaults.items():
        value = node[key]
        here = path + (key,)
        name = ".".join(p for p in here)
        if isinstance(dv, dict):
            _check_types(value, dv, here)
            continue
        key_path = tuple(p.split("[")[0] for p in here)
        if key_path in LIST_ITEM_DEFAULTS:
            for i, item in enumerate(value):
                _check_types(item, LIST_ITEM_DEFAULTS[key_path], path + ("%s[%d]" % (key, i),))
            continue
        if _is_radius(key):
            if not (value == "auto" or _number(value) and value > 0):
                raise ConfigError("%s must be \"auto\" or a positive number of metres, got %r"
                                  % (name, value))
            continue
        if key == "target":
            if value != "object" and not (isinstance(value, list) and len(value) == 3
                                          and all(_number(v) for v in value)):
                raise ConfigError('%s must be "object" or [x, y, z]' % name)
            continue
        if key == "denoise":
            if value not in ("auto", True, False):
                raise ConfigError('%s must be "auto", true or false, got %r' % (name, value))
            continue
        if not _type_ok(dv, value):
            raise ConfigError("%s must be of type %s, got %r" % (name, type(dv).__name__, value))
        if isinstance(dv, list) and dv and all(_number(v) for v in dv):
            if len(value) != len(dv) or not all(_number(v) for v in value):
                raise ConfigError("%s must be a list of %d numbers, got %r" % (name, len(dv), value))
        choice_key = (key_path[0], key_path[-1])
        if choice_key in CHOICES and value not in CHOICES[choice_key]:
            raise ConfigError("%s must be one of %s, got %r"
                              % (name, ", ".join(map(str, CHOICES[choice_key])), value))


def _is_radius(key):
    return key in ("radius", "radius_min", "radius_max")


def _number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def count_views(cfg):
    v = cfg["views"]
    return sum(int(o["count"]) for o in v["orbits"]) + int(v["sphere"]["count"]) + int(v["shell"]["count"])


def validate(cfg):
    _check_types(cfg, DEFAULTS, ())
    src = cfg["object"]["source"]
    if src.startswith("builtin:"):
        if src[len("builtin:"):] not in BUILTIN_OBJECTS:
            raise ConfigError("object.source: unknown built-in object %r (known: %s)"
                              % (src, ", ".join("builtin:" + b for b in BUILTIN_OBJECTS)))
    else:
        check_model_file(src)
    cam, rnd, views = cfg["camera"], cfg["render"], cfg["views"]
    if cam["focal_mm"] <= 0 or min(cam["sensor_mm"]) <= 0:
        raise ConfigError("camera.focal_mm and camera.sensor_mm must be positive")
    w, h = cam["resolution"]
    if not (isinstance(w, int) and isinstance(h, int) and w > 0 and h > 0):
        raise ConfigError("camera.resolution must be two positive integers, got %r"
                          % (cam["resolution"],))
    if abs(cam["sensor_mm"][1] / cam["sensor_mm"][0] - h / w) > 1e-3:
        raise ConfigError("camera.sensor_mm %r and camera.resolution %r have different aspect "
                          "ratios: pixels would not be square" % (cam["sensor_mm"], cam["resolution"]))
    if rnd["samples"] < 1:
        raise ConfigError("render.samples must be >= 1")
    if not 1 <= rnd["jpeg_quality"] <= 100:
        raise ConfigError("render.jpeg_quality must be in 1..100")
    if cfg["object"]["size"] <= 0:
        raise ConfigError("object.size must be positive")
    if not 0 < views["fill"] <= 1.5:
        raise ConfigError("views.fill must be in (0, 1.5]")
    for i, o in enumerate(views["orbits"]):
        if o["count"] < 0:
            raise ConfigError("views.orbits[%d].count must be >= 0" % i)
        if not -90 <= o["elevation_deg"] <= 90:
            raise ConfigError("views.orbits[%d].elevation_deg must be in [-90, 90]" % i)
        step = o["azimuth_step_deg"]
        if step < 0:
            raise ConfigError("views.orbits[%d].azimuth_step_deg must be >= 0" % i)
        if step > 0 and o["count"] * step > 360.0 + 1e-9:
            raise ConfigError("views.orbits[%d]: %d cameras %g deg apart span %g deg, more than a "
                              "full circle: lower count or azimuth_step_deg"
                              % (i, o["count"], step, o["count"] * step))
    for band in ("sphere", "shell"):
        b = views[band]
        if b["count"] < 0:
            raise ConfigError("views.%s.count must be >= 0" % band)
        if not -90 <= b["elevation_min_deg"] <= b["elevation_max_deg"] <= 90:
            raise ConfigError("views.%s: need -90 <= elevation_min_deg <= elevation_max_deg <= 90"
                              % band)
    sh = views["shell"]
    if _number(sh["radius_min"]) and _number(sh["radius_max"]) and sh["radius_min"] > sh["radius_max"]:
        raise ConfigError("views.shell.radius_min must be <= radius_max")
    if count_views(cfg) == 0:
        raise ConfigError("the configuration has zero views: add cameras with views.orbits "
                          "(count > 0), views.sphere.count or views.shell.count")
    try:
        cfg["outputs"]["name_format"].format(0)
    except (IndexError, KeyError, ValueError):
        raise ConfigError("outputs.name_format must be a Python format string like \"{:04d}\"")
    pp = cfg["postprocess"]
    for key in ("blur_sigma", "noise_sigma"):
        if not pp[key] >= 0:
            raise ConfigError("postprocess.%s must be >= 0, got %r" % (key, pp[key]))
    if (pp["blur_sigma"] > 0 or pp["noise_sigma"] > 0) and rnd["format"] == "PNG" \
            and rnd["png_color_depth"] != 8:
        raise ConfigError("postprocess (blur/noise) writes 8-bit images: use "
                          "render.png_color_depth = 8")
    for i, light in enumerate(cfg["lights"]):
        if light["energy"] < 0:
            raise ConfigError("lights[%d].energy must be >= 0" % i)


def check_model_file(path):
    """Fail early on a missing, empty, unreadable or unsupported model file."""
    ext = os.path.splitext(path)[1].lower()
    if ext not in MODEL_EXTENSIONS:
        raise ConfigError("object.source %r: unsupported model format %r (supported: %s, or "
                          "builtin:<name>)" % (path, ext or "(no extension)", " ".join(MODEL_EXTENSIONS)))
    if not os.path.exists(path):
        raise ConfigError("object.source: model file not found: %s" % path)
    if not os.path.isfile(path):
        raise ConfigError("object.source: not a file: %s" % path)
    try:
        with open(path, "rb") as f:
            head = f.read(64)
    except OSError as exc:
        raise ConfigError("object.source: cannot read model file %s: %s" % (path, exc)) from None
    if not head:
        raise ConfigError("object.source: model file is empty: %s" % path)
    magic_ok = {
        ".ply": head.startswith(b"ply"),
        ".glb": head.startswith(b"glTF"),
        ".blend": head.startswith(b"BLENDER") or head.startswith(b"\x1f\x8b") or head.startswith(b"\x28\xb5\x2f\xfd"),
        ".gltf": head.lstrip().startswith(b"{"),
        ".fbx": head.startswith(b"Kaydara FBX Binary") or b"FBX" in head or head.lstrip().startswith(b";"),
    }.get(ext, True)
    if not magic_ok:
        raise ConfigError("object.source: %s does not look like a %s file (bad header %r)"
                          % (path, ext, head[:16]))
    if ext == ".obj":
        try:
            head.decode("ascii")
        except UnicodeDecodeError:
            raise ConfigError("object.source: %s is not a text OBJ file" % path) from None


def to_json(cfg):
    return json.loads(json.dumps(cfg))
