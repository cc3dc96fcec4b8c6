"""EXIF written by our own code, read back by Pillow."""

import io

import pytest
from PIL import Image

from sfmeval_blender import exif


def _image(fmt, size=(640, 360)):
    buf = io.BytesIO()
    Image.new("RGB", size, (90, 120, 150)).save(buf, fmt)
    return buf.getvalue()


def focal_px_from_exif(path):
    e = Image.open(path).getexif()
    ie = e.get_ifd(0x8769)
    unit_mm = {2: 25.4, 3: 10.0}[ie[0xA210]]
    return float(ie[0x920A]) * float(ie[0xA20E]) / unit_mm, e, ie


@pytest.mark.parametrize("unit", ["inches", "cm"])
@pytest.mark.parametrize("fmt,ext", [("JPEG", "jpg"), ("PNG", "png")])
def test_focal_in_pixels_round_trip(tmp_path, unit, fmt, ext):
    p = tmp_path / ("a." + ext)
    p.write_bytes(_image(fmt))
    exif.write_exif(str(p), width=640, height=360, focal_mm=35.0, sensor_mm=[32.0, 18.0],
                    make="sfmeval", model="cam", unit=unit)
    f, e, ie = focal_px_from_exif(str(p))
    assert f == pytest.approx(700.0, abs=1e-9)
    assert e[0x010F] == "sfmeval" and e[0x0110] == "cam"
    assert ie[0xA002] == 640 and ie[0xA003] == 360
    assert 0xA405 not in ie                        # no FocalLengthIn35mmFilm by default
    im = Image.open(str(p))
    im.load()
    assert im.size == (640, 360)


def test_odd_values_and_35mm_on_request(tmp_path):
    p = tmp_path / "b.jpg"
    p.write_bytes(_image("JPEG", (1000, 563)))
    exif.write_exif(str(p), width=1000, height=563, focal_mm=24.7, sensor_mm=[23.5, 13.23],
                    write_35mm=True)
    f, e, ie = focal_px_from_exif(str(p))
    assert f == pytest.approx(24.7 / 23.5 * 1000, rel=1e-9)
    assert ie[0xA405] == round(24.7 * (36 ** 2 + 24 ** 2) ** 0.5 / (23.5 ** 2 + 13.23 ** 2) ** 0.5)


def test_rewriting_replaces_the_old_segment(tmp_path):
    p = tmp_path / "c.jpg"
    p.write_bytes(_image("JPEG"))
    exif.write_exif(str(p), width=640, height=360, focal_mm=50.0, sensor_mm=[32.0, 18.0])
    exif.write_exif(str(p), width=640, height=360, focal_mm=35.0, sensor_mm=[32.0, 18.0])
    assert p.read_bytes().count(b"Exif\0\0") == 1
    assert focal_px_from_exif(str(p))[0] == pytest.approx(700.0)
