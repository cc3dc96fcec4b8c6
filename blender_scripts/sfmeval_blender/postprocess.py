"""Image post-processes applied to every rendered view before its EXIF is written: Gaussian
blur (σ in pixels), then additive Gaussian noise (σ in 8-bit grey levels), seeded.

Config section ``[postprocess]``: ``blur_sigma`` (px, 0 = off), ``noise_sigma`` (grey levels of
0..255, 0 = off), ``seed`` (−1 = ``dataset.seed``). View i's noise comes from
``numpy.random.default_rng([seed, i])``, so the same config gives the same bytes, and a view's
noise does not depend on which other views are rendered.

The arithmetic (``blur``, ``add_noise``, ``apply``) is plain NumPy, testable without Blender.
Reading and writing the image file needs Pillow (in the PyPI-bpy venv; Debian's blender
Python has it only with ``python3-pil``): :func:`check_available` says so before rendering.
"""

import math


def _np():
    # imported when used: importing steps must not need numpy (Debian's blender may lack it)
    import numpy
    return numpy


def active(cfg):
    pp = cfg["postprocess"]
    return pp["blur_sigma"] > 0 or pp["noise_sigma"] > 0


def seed_of(cfg):
    s = cfg["postprocess"]["seed"]
    return int(cfg["dataset"]["seed"] if s < 0 else s)


def gaussian_kernel(sigma):
    """Normalised 1-D Gaussian, radius ceil(3σ)."""
    np = _np()
    r = max(1, int(math.ceil(3.0 * sigma)))
    x = np.arange(-r, r + 1, dtype=np.float64)
    k = np.exp(-0.5 * (x / sigma) ** 2)
    return k / k.sum()


def blur(img, sigma):
    """Separable Gaussian blur of an (H, W, C) float array, edges mirrored (reflect)."""
    np = _np()
    if sigma <= 0:
        return img
    k = gaussian_kernel(sigma)
    r = len(k) // 2
    out = img.astype(np.float64)
    for axis in (0, 1):
        n = out.shape[axis]
        pad = [(0, 0)] * out.ndim
        pad[axis] = (r, r)
        # mirrored edges; a side shorter than the kernel radius cannot mirror: repeat the edge
        padded = np.pad(out, pad, mode="edge" if r >= n else "reflect")
        acc = np.zeros_like(out)
        for i, w in enumerate(k):
            sl = [slice(None)] * out.ndim
            sl[axis] = slice(i, i + n)
            acc += w * padded[tuple(sl)]
        out = acc
    return out


def add_noise(img, sigma, rng):
    """Adds N(0, σ²) per pixel and channel."""
    np = _np()
    if sigma <= 0:
        return img
    return img + rng.normal(0.0, sigma, size=img.shape)


def apply(img_u8, cfg, view_index):
    """Blur then noise an (H, W, C) uint8 image; returns uint8 (rounded, clipped to 0..255)."""
    np = _np()
    pp = cfg["postprocess"]
    x = img_u8.astype(np.float64)
    x = blur(x, float(pp["blur_sigma"]))
    rng = np.random.default_rng([seed_of(cfg), int(view_index)])
    x = add_noise(x, float(pp["noise_sigma"]), rng)
    return np.clip(np.rint(x), 0, 255).astype(np.uint8)


def check_available():
    """Raises ImportError with a message naming what is missing."""
    try:
        import PIL.Image  # noqa: F401
    except ImportError:
        raise ImportError("postprocess (blur/noise) needs Pillow in Blender's Python "
                          "(pip install pillow, or apt-get install python3-pil)") from None


def process_file(src, dest, cfg, view_index):
    """Reads the lossless render `src`, post-processes it and writes `dest` in the configured
    format (JPEG at render.jpeg_quality, or 8-bit PNG), without metadata."""
    np = _np()
    from PIL import Image

    with Image.open(src) as im:
        arr = np.asarray(im.convert("RGB"))
    out = Image.fromarray(apply(arr, cfg, view_index), "RGB")
    if cfg["render"]["format"] == "JPEG":
        out.save(dest, "JPEG", quality=int(cfg["render"]["jpeg_quality"]))
    else:
        out.save(dest, "PNG")
