"""A minimal EXIF writer (TIFF little-endian inside a JPEG APP1 segment or a PNG eXIf chunk).

Blender writes no EXIF. SfM tools take their focal-length prior from it, so we write exactly
the tags that give the focal length in pixels without ambiguity:

* ``FocalLength`` (mm),
* ``FocalPlaneXResolution`` / ``FocalPlaneYResolution`` in pixels per unit with
  ``FocalPlaneResolutionUnit`` = 2 (inches, default) or 3 (cm) — COLMAP 3.8 ignores mm,
* ``PixelXDimension`` / ``PixelYDimension``, ``Make``, ``Model``, ``Software``.

focal_px = FocalLength · FocalPlaneXResolution / (25.4 mm per inch). ``FocalLengthIn35mmFilm``
is written only on request: COLMAP 3.8 and pycolmap 4 both prefer it and read it differently.
"""

import struct
import zlib
from fractions import Fraction

ASCII, SHORT, LONG, RATIONAL, UNDEFINED = 2, 3, 4, 5, 7
_SIZES = {ASCII: 1, SHORT: 2, LONG: 4, RATIONAL: 8, UNDEFINED: 1}
UNIT_MM = {2: 25.4, 3: 10.0}


def _rational(value):
    fr = Fraction(value).limit_denominator(1000000) if not isinstance(value, Fraction) else value
    num, den = fr.numerator, fr.denominator
    while num > 0xFFFFFFFF or den > 0xFFFFFFFF:
        num //= 2
        den //= 2
    return (num, max(den, 1))


def _encode(typ, value):
    if typ == ASCII:
        data = value.encode("ascii", "replace") + b"\0"
        return data, len(data)
    if typ == UNDEFINED:
        return bytes(value), len(value)
    if typ == SHORT:
        vals = value if isinstance(value, (list, tuple)) else [value]
        return b"".join(struct.pack("<H", v) for v in vals), len(vals)
    if typ == LONG:
        vals = value if isinstance(value, (list, tuple)) else [value]
        return b"".join(struct.pack("<I", v) for v in vals), len(vals)
    if typ == RATIONAL:
        vals = value if isinstance(value, (list, tuple)) else [value]
        return b"".join(struct.pack("<II", *_rational(v)) for v in vals), len(vals)
    raise ValueError(typ)


def _ifd(entries, offset, next_ifd=0):
    """Serialise one IFD that starts at `offset` (from the TIFF header); returns bytes.
    entries: list of (tag, type, value); values larger than 4 bytes go after the IFD."""
    entries = sorted(entries, key=lambda e: e[0])
    n = len(entries)
    data_start = offset + 2 + 12 * n + 4
    head = struct.pack("<H", n)
    extra = b""
    for tag, typ, value in entries:
        data, count = _encode(typ, value)
        if len(data) <= 4:
            head += struct.pack("<HHI", tag, typ, count) + data.ljust(4, b"\0")
        else:
            if (data_start + len(extra)) % 2:
                extra += b"\0"
            head += struct.pack("<HHII", tag, typ, count, data_start + len(extra))
            extra += data
    return head + struct.pack("<I", next_ifd) + extra


def focal_plane_resolution(width_px, sensor_width_mm, unit=2):
    """Pixels per unit (inch or cm) on the focal plane, exact as a fraction."""
    return Fraction(width_px) * Fraction(str(UNIT_MM[unit])) / Fraction(str(sensor_width_mm))


def build_tiff(width, height, focal_mm, sensor_mm, make="sfmeval", model="Blender virtual camera",
               software="sfmeval", unit="inches", write_35mm=False):
    unit_code = {"inches": 2, "cm": 3}[unit]
    xres = focal_plane_resolution(width, sensor_mm[0], unit_code)
    yres = focal_plane_resolution(height, sensor_mm[1], unit_code)
    exif_entries = [
        (0x9000, UNDEFINED, b"0230"),                        # ExifVersion
        (0x920A, RATIONAL, Fraction(str(focal_mm))),         # FocalLength
        (0xA001, SHORT, 1),                                  # ColorSpace sRGB
        (0xA002, LONG, int(width)),                          # PixelXDimension
        (0xA003, LONG, int(height)),                         # PixelYDimension
        (0xA20E, RATIONAL, xres),                            # FocalPlaneXResolution
        (0xA20F, RATIONAL, yres),                            # FocalPlaneYResolution
        (0xA210, SHORT, unit_code),                          # FocalPlaneResolutionUnit
    ]
    if write_35mm:
        diag = (sensor_mm[0] ** 2 + sensor_mm[1] ** 2) ** 0.5
        f35 = int(round(float(focal_mm) * (36.0 ** 2 + 24.0 ** 2) ** 0.5 / diag))
        exif_entries.append((0xA405, SHORT, f35))            # FocalLengthIn35mmFilm
    ifd0_entries = [
        (0x010F, ASCII, make),
        (0x0110, ASCII, model),
        (0x0112, SHORT, 1),                                  # Orientation: top-left
        (0x011A, RATIONAL, 72),
        (0x011B, RATIONAL, 72),
        (0x0128, SHORT, 2),                                  # ResolutionUnit inches
        (0x0131, ASCII, software),
        (0x8769, LONG, 0),                                   # ExifIFD pointer, patched below
    ]
    ifd0_len = len(_ifd(ifd0_entries, 8))
    exif_offset = 8 + ifd0_len
    if exif_offset % 2:
        exif_offset += 1
    ifd0_entries[-1] = (0x8769, LONG, exif_offset)
    ifd0 = _ifd(ifd0_entries, 8)
    tiff = b"II*\0" + struct.pack("<I", 8) + ifd0
    tiff = tiff.ljust(exif_offset, b"\0")
    return tiff + _ifd(exif_entries, exif_offset)


def insert_jpeg(jpeg_bytes, tiff):
    """Insert an EXIF APP1 segment right after SOI / the JFIF APP0 segment.

    Drops any older EXIF, Blender's own APP1 ("NeoGeo") and comment (COM) segments: Cycles
    stores render statistics (render time, memory) there, which would make the bytes of the
    same image differ between runs."""
    if jpeg_bytes[:2] != b"\xff\xd8":
        raise ValueError("not a JPEG file")
    payload = b"Exif\0\0" + tiff
    if len(payload) + 2 > 0xFFFF:
        raise ValueError("EXIF too large")
    app1 = b"\xff\xe1" + struct.pack(">H", len(payload) + 2) + payload
    pos = 2
    out = [jpeg_bytes[:2]]
    placed = False
    while pos + 4 <= len(jpeg_bytes) and jpeg_bytes[pos] == 0xFF:
        marker = jpeg_bytes[pos + 1]
        if marker == 0xDA:                         # start of scan: the rest is entropy-coded data
            break
        seglen = struct.unpack(">H", jpeg_bytes[pos + 2:pos + 4])[0]
        seg = jpeg_bytes[pos:pos + 2 + seglen]
        pos += 2 + seglen
        if marker == 0xE0 and not placed:
            out.append(seg)
            out.append(app1)
            placed = True
            continue
        if marker == 0xFE or (marker == 0xE1 and seg[4:10] in (b"Exif\0\0", b"NeoGeo")):
            continue
        if not placed:
            out.append(app1)
            placed = True
        out.append(seg)
    if not placed:
        out.append(app1)
    return b"".join(out) + jpeg_bytes[pos:]


def insert_png(png_bytes, tiff):
    """Insert an eXIf chunk before the first IDAT (PNG 1.5 extension); drops text chunks."""
    sig = b"\x89PNG\r\n\x1a\n"
    if not png_bytes.startswith(sig):
        raise ValueError("not a PNG file")
    chunk = struct.pack(">I", len(tiff)) + b"eXIf" + tiff
    chunk += struct.pack(">I", zlib.crc32(b"eXIf" + tiff) & 0xFFFFFFFF)
    pos = len(sig)
    out = [sig]
    while pos < len(png_bytes):
        length = struct.unpack(">I", png_bytes[pos:pos + 4])[0]
        ctype = png_bytes[pos + 4:pos + 8]
        end = pos + 12 + length
        if ctype == b"IDAT" and chunk:
            out.append(chunk)
            chunk = b""
        if ctype not in (b"eXIf", b"tEXt", b"zTXt", b"iTXt"):   # drop render-time metadata
            out.append(png_bytes[pos:end])
        pos = end
    return b"".join(out)


def write_exif(path, **kwargs):
    tiff = build_tiff(**kwargs)
    with open(path, "rb") as f:
        data = f.read()
    if data[:2] == b"\xff\xd8":
        data = insert_jpeg(data, tiff)
    else:
        data = insert_png(data, tiff)
    with open(path, "wb") as f:
        f.write(data)


def write_png_gray(path, rows, width, height):
    """Write an 8-bit greyscale PNG from `rows` (bytes of length width*height, top row first)."""
    raw = b"".join(b"\0" + rows[y * width:(y + 1) * width] for y in range(height))

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)

    data = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)
