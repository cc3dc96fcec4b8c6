"""Steps 7–11 of the add-on: compare SfM pipelines on a dataset inside Blender.

bpy-free modules (importable anywhere, tested with plain Python too):

* ``tools``    — where the ``sfmeval`` and ``sfmeval-runner`` binaries are;
* ``run``      — a pipeline run as a subprocess in its own session (poll, cancel);
* ``plyio``    — read a PLY's vertices, write the points the user kept;
* ``crop``     — a crop volume (box / sphere empty) as an ``sfmeval.crop/1`` file;
* ``evaluate`` — ``sfmeval align`` / ``eval`` calls, viridis colours, Table I.

``blender`` holds the bpy side (import, operators); ``panel`` the "Compare pipelines" panel.
"""
