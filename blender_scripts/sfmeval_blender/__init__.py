"""sfmeval_blender: synthetic Structure-from-Motion datasets with exact ground truth.

One package for both front ends:

* the Blender add-on (``register()`` / ``unregister()``; panel in the 3D view sidebar, tab
  "sfmeval"), installed from the zip that ``blender_scripts/build_addon.py`` builds, with a
  second panel "Compare pipelines" (``compare/``: run, import, cut away, align, evaluate);
* the headless generator (``blender_scripts/generate.py`` or ``python -m sfmeval_blender``).

Modules without bpy (``config``, ``geometry``, ``exif``, ``shapes``, ``tomlmini``) import
anywhere; ``steps``, ``pipeline`` and ``addon`` need Blender's ``bpy``.
"""

__version__ = "0.1.0"

bl_info = {
    "name": "sfmeval synthetic SfM datasets",
    "author": "sfmeval developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > sfmeval",
    "description": "Render orbit datasets with exact ground truth (cameras.json, GLB, EXIF) "
                   "for evaluating Structure-from-Motion pipelines",
    "category": "Import-Export",
}


def register():
    from . import addon
    addon.register()


def unregister():
    from . import addon
    addon.unregister()
