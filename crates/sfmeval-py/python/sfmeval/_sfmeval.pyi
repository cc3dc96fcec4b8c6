"""Stubs of the native module (crates/sfmeval-py/src/lib.rs); use the package's ``evaluate``."""

from typing import List, Optional, Tuple

class InputError(ValueError):
    """An input the core cannot use: the message names the file (or option) and what is wrong."""

def _evaluate(
    gt: str,
    recon: str,
    *,
    recon_points: Optional[bytes] = ...,
    name: Optional[str] = ...,
    gt_cameras: Optional[str] = ...,
    recon_cameras: Optional[str] = ...,
    align: Optional[str] = ...,
    transform_path: Optional[str] = ...,
    transform_json: Optional[str] = ...,
    pairs: Optional[str] = ...,
    crop_path: Optional[str] = ...,
    crop_json: Optional[str] = ...,
    max_distance: Optional[float] = ...,
    tau: List[float] = ...,
    tau_percent: List[float] = ...,
    samples: int = ...,
    seed: int = ...,
    signed: bool = ...,
    max_triangles: int = ...,
) -> Tuple[str, bytes, Optional[bytes], bytes]: ...
def version() -> str: ...
def align_modes() -> List[str]: ...
