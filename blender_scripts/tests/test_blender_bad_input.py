"""Bad input fails with a clear message before any rendering starts (through the real CLI)."""

import os


from blender_testlib import requires_bpy, run_generate


def _fails(args, out, match, code=None):
    proc = run_generate(list(args) + ["--out", str(out)], timeout=300)
    assert proc.returncode != 0, proc.stdout[-2000:]
    if code is not None:
        assert proc.returncode == code
    assert match in proc.stderr, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr, proc.stderr[-2000:]
    assert not os.path.exists(os.path.join(str(out), "images"))
    assert "render 1/" not in proc.stdout
    return proc


def test_unknown_option(tmp_path):
    cfg = tmp_path / "d.toml"
    cfg.write_text('preset = "small"\n[render]\nsampels = 4\n')
    _fails(["--config", str(cfg)], tmp_path / "out", "unknown option 'render.sampels'", 2)


def test_zero_views(tmp_path):
    cfg = tmp_path / "d.toml"
    cfg.write_text('preset = "small"\n[views]\norbits = []\n')
    _fails(["--config", str(cfg)], tmp_path / "out", "zero views", 2)


def test_missing_model_file(tmp_path):
    cfg = tmp_path / "d.json"
    cfg.write_text('{"preset": "small", "object": {"source": "no/such/model.ply"}}')
    _fails(["--config", str(cfg)], tmp_path / "out", "model file not found", 2)


def test_bad_toml(tmp_path):
    cfg = tmp_path / "d.toml"
    cfg.write_text('[render\nsamples = 4\n')
    _fails(["--config", str(cfg)], tmp_path / "out", "invalid TOML", 2)


@requires_bpy
def test_unreadable_model_file_is_caught_at_import(tmp_path):
    """A file that passes the header check but holds no usable mesh: the import step (before
    the render step) refuses it."""
    model = tmp_path / "broken.ply"
    model.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1 2\n")
    cfg = tmp_path / "d.toml"
    cfg.write_text('preset = "small"\n[object]\nsource = "broken.ply"\n')
    _fails(["--config", str(cfg)], tmp_path / "out", "cannot import", 1)


@requires_bpy
def test_empty_obj_is_caught_at_import(tmp_path):
    model = tmp_path / "empty.obj"
    model.write_text("# an OBJ file without geometry\no nothing\n")
    cfg = tmp_path / "d.toml"
    cfg.write_text('preset = "small"\n[object]\nsource = "empty.obj"\n')
    _fails(["--config", str(cfg)], tmp_path / "out", "holds no mesh", 1)
