"""Small shims over the Blender Python API differences between 3.4 (Debian) and 5.x (PyPI bpy)."""

import bpy

VERSION = tuple(bpy.app.version)


def op_exists(module, name):
    return name in dir(getattr(bpy.ops, module))


def op_kwargs(op, **kwargs):
    """Keep only the keyword arguments the operator knows (options come and go across versions)."""
    try:
        known = set(op.get_rna_type().properties.keys())
    except Exception:  # pragma: no cover
        return kwargs
    return {k: v for k, v in kwargs.items() if k in known}


def set_input(node, names, value):
    """Set the first existing input socket among `names` (socket names change across versions)."""
    for name in names:
        sock = node.inputs.get(name)
        if sock is not None:
            sock.default_value = value
            return True
    return False


def enum_items(struct, prop):
    return [i.identifier for i in struct.bl_rna.properties[prop].enum_items]


def oidn_available():
    try:
        import _cycles
        return bool(getattr(_cycles, "with_openimagedenoise", False))
    except Exception:  # pragma: no cover
        return False


def new_mix_node(nodes):
    """An RGB mix node: ShaderNodeMix (3.4+) or the legacy ShaderNodeMixRGB.
    Returns (node, fac_socket, a_socket, b_socket, result_socket)."""
    try:
        node = nodes.new("ShaderNodeMix")
        node.data_type = "RGBA"
        ins = [s for s in node.inputs if s.enabled]
        fac = node.inputs[0]
        a = next(s for s in ins if s.name == "A" and s.type == "RGBA")
        b = next(s for s in ins if s.name == "B" and s.type == "RGBA")
        out = next(s for s in node.outputs if s.enabled and s.type == "RGBA")
        return node, fac, a, b, out
    except Exception:  # pragma: no cover - older Blender
        node = nodes.new("ShaderNodeMixRGB")
        return node, node.inputs[0], node.inputs[1], node.inputs[2], node.outputs[0]


def use_nodes(idblock):
    """`use_nodes` is deprecated in 5.0 (always on) but still required in 3.4."""
    try:
        if not idblock.use_nodes:
            idblock.use_nodes = True
    except Exception:  # pragma: no cover
        pass


def set_smooth(mesh, flags):
    try:
        mesh.polygons.foreach_set("use_smooth", flags)
    except Exception:  # pragma: no cover - attribute-based meshes
        try:
            attr = mesh.attributes.get("sharp_face") or mesh.attributes.new("sharp_face", "BOOLEAN", "FACE")
            attr.data.foreach_set("value", [not f for f in flags])
        except Exception:
            pass
    mesh.update()
