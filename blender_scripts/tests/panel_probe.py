"""Inside Blender: the labels a panel's draw() writes, through a fake layout that accepts every
call (the compare drivers read the Compare pipelines panel's text this way)."""

import bpy


def panel_labels(panel, scene, icons=False):
    """The label texts `panel.draw` writes for `scene` (preferences from the running Blender);
    with `icons`, [text, icon] pairs."""
    labels = []

    class Layout:
        def __getattr__(self, name):
            if name == "label":
                return lambda text="", icon="NONE", **k: labels.append(
                    [text, icon] if icons else text)
            return lambda *a, **k: Layout()

        def __setattr__(self, k, v):
            pass

    ctx = type("Ctx", (), {"scene": scene, "preferences": bpy.context.preferences})()
    panel.draw(type("P", (), {"layout": Layout()})(), ctx)
    return labels
