"""Stubs of the native module (crates/sfmeval-py/src); use the package's functions."""

from typing import Any, Callable, Dict, List, Optional, Tuple

class InputError(ValueError):
    """An input the core cannot use: the message names the file (or option) and what is wrong."""

def _evaluate(
    gt: Optional[str] = ...,
    recon: Optional[str] = ...,
    *,
    gt_vertices: Any = ...,
    gt_triangles: Any = ...,
    gt_name: Optional[str] = ...,
    recon_points: Any = ...,
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
    threads: Optional[int] = ...,
    progress: Optional[Callable[[str, float], Any]] = ...,
) -> Tuple[str, bytes, Optional[bytes], bytes, bytes, bytes]: ...
def _align(
    gt: Optional[str] = ...,
    recon: Optional[str] = ...,
    *,
    gt_vertices: Any = ...,
    gt_triangles: Any = ...,
    gt_name: Optional[str] = ...,
    recon_points: Any = ...,
    name: Optional[str] = ...,
    gt_cameras: Optional[str] = ...,
    recon_cameras: Optional[str] = ...,
    align: Optional[str] = ...,
    transform_path: Optional[str] = ...,
    transform_json: Optional[str] = ...,
    pairs: Optional[str] = ...,
    samples: int = ...,
    seed: int = ...,
    max_triangles: int = ...,
    threads: Optional[int] = ...,
    progress: Optional[Callable[[str, float], Any]] = ...,
) -> Tuple[str, str]: ...
def _read(path: str, max_triangles: int = ...) -> Dict[str, Any]: ...
def _cameras(
    gt_cameras: str,
    recon: str,
    transform_path: Optional[str] = ...,
    transform_json: Optional[str] = ...,
) -> str: ...
def _poses(
    gt_cameras: str,
    recon: str,
    protocol: str,
    position_accuracy: float = ...,
) -> str: ...
def _tnt(
    scene: str,
    recon: str,
    *,
    scene_name: Optional[str] = ...,
    trajectory: Optional[str] = ...,
    transform_path: Optional[str] = ...,
    transform_text: Optional[str] = ...,
    tau: Optional[float] = ...,
    seed: int = ...,
    out: Optional[str] = ...,
    threads: Optional[int] = ...,
    progress: Optional[Callable[[str, float], Any]] = ...,
) -> str: ...
def _dtu(
    dataset: str,
    scan: int,
    recon: str,
    *,
    mode: str = ...,
    downsample_density: Optional[float] = ...,
    patch_size: Optional[float] = ...,
    max_dist: Optional[float] = ...,
    visualize_threshold: Optional[float] = ...,
    seed: int = ...,
    shuffle: bool = ...,
    vis_out: Optional[str] = ...,
    report: Optional[str] = ...,
    threads: Optional[int] = ...,
    progress: Optional[Callable[[str, float], Any]] = ...,
) -> str: ...
def _eth3d(
    gt: str,
    recon: str,
    *,
    tolerances: Optional[List[float]] = ...,
    voxel_size: Optional[float] = ...,
    beam_start_radius: Optional[float] = ...,
    beam_divergence_halfangle_deg: Optional[float] = ...,
    out: Optional[str] = ...,
    threads: Optional[int] = ...,
) -> str: ...
def _table(reports: List[str], dataset: Optional[str] = ..., failed: List[str] = ...) -> Dict[str, str]: ...
def version() -> str: ...
def align_modes() -> List[str]: ...
