"""Writes the .mat fixtures of sfmeval-dtu's reader tests with scipy (scipy 1.14.1):
an observation-mask file (3-D logical ObsMask, BB, Res) compressed and uncompressed, and a
plane file. Run: python make_fixtures.py (from this folder)."""
import numpy as np
from scipy.io import savemat

mask = np.zeros((5, 4, 3), dtype=bool)
mask[1, 2, 0] = True
mask[4, 3, 2] = True
mask[0, 1, 1] = True
bb = np.array([[-10.5, 0.25, 3.0], [20.0, 30.5, 40.125]])
for compress in (False, True):
    savemat(f"obsmask_{'z' if compress else 'raw'}.mat",
            {"ObsMask": mask, "BB": bb, "Res": np.array([[0.2]])},
            do_compression=compress)
savemat("plane.mat", {"P": np.array([[0.1], [-0.2], [0.97], [-5.0]])}, do_compression=True)
