"""sfmeval: evaluate Structure-from-Motion reconstructions against ground truth.

The Python face of the sfmeval core (Rust): ``evaluate`` reads the files as the ``sfmeval``
CLI reads them and runs the core's evaluation, so ``Report.to_json()`` is byte for byte the
report ``sfmeval eval --report`` writes for the same inputs. Nothing here computes a number:
``Report`` gives attribute access to that JSON and numpy views of the per-point distances.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Union

import numpy as np

from ._sfmeval import InputError, _evaluate, align_modes, version

__all__ = [
    "InputError", "Note", "Report", "Section", "PathLike", "align_modes", "evaluate", "version",
]
__version__: str = version()

PathLike = Union[str, "os.PathLike[str]"]


class Section:
    """One object of the report: its fields as attributes (``report.accuracy.mean``), lists as
    lists of sections, in the report's own names (``schemas/report.schema.json``)."""

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[str, Any]) -> None:
        self._data = data

    def __getattr__(self, name: str) -> Any:
        try:
            return _wrap(self._data[name])
        except KeyError:
            raise AttributeError(
                f"the report section has no field '{name}' (it has: {', '.join(self._data)})"
            ) from None

    def __getitem__(self, name: str) -> Any:
        return _wrap(self._data[name])

    def __contains__(self, name: object) -> bool:
        return name in self._data

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __dir__(self) -> List[str]:
        return list(self._data)

    def to_dict(self) -> Dict[str, Any]:
        """This section as plain JSON values (a deep copy)."""
        return json.loads(json.dumps(self._data))

    def __repr__(self) -> str:
        return f"Section({', '.join(self._data)})"


class Note(Section):
    """A typed note of the core: ``code`` (stable, ``docs/notes.md``), ``level``
    (``info``/``warning``/``error``), ``message`` (for people; never parse it) and ``values``
    (the numbers the message quotes)."""

    __slots__ = ()

    @property
    def code(self) -> str:
        return str(self._data["code"])

    @property
    def level(self) -> str:
        return str(self._data["level"])

    @property
    def message(self) -> str:
        return str(self._data["message"])

    @property
    def values(self) -> Dict[str, Any]:
        return dict(self._data.get("values") or {})

    def __repr__(self) -> str:
        return f"Note({self.level} {self.code}: {self.message})"


def _wrap(value: Any) -> Any:
    if isinstance(value, dict):
        if "code" in value and "level" in value and "message" in value:
            return Note(value)
        return Section(value)
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


class _Alignment(Section):
    __slots__ = ()

    @property
    def gt_from_recon(self) -> np.ndarray:
        """The 4×4 row-major similarity mapping reconstruction coordinates into the
        ground-truth frame (float64)."""
        return np.array(self._data["gt_from_recon"], dtype=np.float64)


class Report(Section):
    """An ``sfmeval.report/3`` evaluation report with the per-point measurements.

    Attributes mirror the JSON (``r.accuracy.mean``, ``r.thresholds[0].f_score``,
    ``r.alignment.gt_from_recon`` as a 4×4 numpy array, ``r.notes`` as typed ``Note``s).
    """

    __slots__ = ("_json", "_distances", "_signed", "_kept")

    def __init__(
        self, report_json: str, distances: bytes, signed: Optional[bytes], kept: bytes
    ) -> None:
        super().__init__(json.loads(report_json))
        self._json = report_json
        self._distances = distances
        self._signed = signed
        self._kept = kept

    @property
    def alignment(self) -> _Alignment:
        return _Alignment(self._data["alignment"])

    @property
    def notes(self) -> List[Note]:
        return [Note(n) for n in self._data.get("notes", [])]

    def to_json(self) -> str:
        """The report's JSON text, exactly the bytes ``sfmeval eval --report`` writes."""
        return self._json

    def to_dict(self) -> Dict[str, Any]:
        """The report as plain JSON values."""
        return json.loads(self._json)

    @property
    def distances(self) -> np.ndarray:
        """Unsigned distance of every reconstructed point to the ground truth (float64, input
        order, every point: ``kept`` says which ones the statistics count)."""
        return np.frombuffer(self._distances, dtype=np.float64)

    @property
    def signed_distances(self) -> Optional[np.ndarray]:
        """Distances signed by the closest triangle's normal (``signed=True`` only)."""
        if self._signed is None:
            return None
        return np.frombuffer(self._signed, dtype=np.float64)

    @property
    def kept(self) -> np.ndarray:
        """Per point, whether it was kept (inside the crop, not farther than ``max_distance``)."""
        return np.frombuffer(self._kept, dtype=np.uint8).astype(bool)

    def __repr__(self) -> str:
        acc = self._data.get("accuracy", {})
        return f"Report(points={acc.get('count')}, accuracy mean={acc.get('mean')})"


def _path(value: Optional[PathLike], what: str) -> Optional[str]:
    if value is None:
        return None
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{what} must be a path (str or os.PathLike), got {type(value).__name__}")
    return os.fspath(value)


def _floats(value: Union[None, float, Sequence[float]]) -> List[float]:
    if value is None:
        return []
    if isinstance(value, (int, float)):
        return [float(value)]
    return [float(v) for v in value]


def evaluate(
    gt: PathLike,
    recon: Union[PathLike, np.ndarray],
    *,
    gt_cameras: Optional[PathLike] = None,
    recon_cameras: Optional[PathLike] = None,
    align: Optional[str] = None,
    transform: Union[None, PathLike, Sequence[Sequence[float]], np.ndarray] = None,
    pairs: Optional[PathLike] = None,
    crop: Union[None, PathLike, Mapping[str, Any]] = None,
    max_distance: Optional[float] = None,
    tau: Union[None, float, Sequence[float]] = None,
    tau_percent: Union[None, float, Sequence[float]] = None,
    samples: int = 1_000_000,
    seed: int = 0,
    signed: bool = False,
    name: Optional[str] = None,
    max_triangles: int = 10_000_000,
) -> Report:
    """Evaluates the reconstruction at ``recon`` against the ground truth ``gt``, as
    ``sfmeval eval --gt GT --recon RECON ...`` does (the same flags, by the same names).

    ``gt`` is a GLB, glTF, OBJ or PLY file, or a dataset folder (``ground_truth.glb``, with its
    ``cameras.json`` and ``depth/`` when present, as ``--dataset``). ``recon`` is a PLY cloud, a
    COLMAP model folder, an ``.nvm``, a Bundler ``.out``, an OpenMVG ``sfm_data.json`` or a
    ``cameras.json``, or an ``(N, 3)`` float32/float64 array of points (evaluated as the float64
    PLY ``sfmeval export`` writes, named ``name``, default ``points.ply``). ``align`` is one of ``align_modes()`` (default: ``given`` with a
    ``transform``, else ``auto``). ``transform`` is a file or a 4×4 ``gt_from_recon``; ``crop``
    a crop file or its JSON as a dict. The GIL is released while the core works.

    Raises ``FileNotFoundError`` for a path that does not exist and ``InputError`` (a
    ``ValueError``) naming the file and what is wrong for anything the core cannot read or use.
    """
    transform_path: Optional[str] = None
    transform_json: Optional[str] = None
    if isinstance(transform, (str, os.PathLike)):
        transform_path = os.fspath(transform)
    elif transform is not None:
        # the core's parser checks it (4×4 or 16 numbers, a similarity), as for a file
        transform_json = json.dumps(np.asarray(transform, dtype=np.float64).tolist())
    crop_path: Optional[str] = None
    crop_json: Optional[str] = None
    if isinstance(crop, (str, os.PathLike)):
        crop_path = os.fspath(crop)
    elif crop is not None:
        crop_json = json.dumps(dict(crop))
    recon_points: Optional[bytes] = None
    recon_path: Optional[str]
    if isinstance(recon, (str, os.PathLike)):
        recon_path = os.fspath(recon)
    else:
        points = np.asarray(recon)
        if points.ndim != 2 or points.shape[1] != 3 or points.dtype.kind != "f":
            raise InputError(
                f"recon: an (N, 3) array of floats is needed, got shape {points.shape} of {points.dtype}"
            )
        recon_points = np.ascontiguousarray(points, dtype=np.float64).tobytes()
        recon_path = ""
    report_json, distances, signed_bytes, kept = _evaluate(
        _path(gt, "gt"),
        recon_path,
        recon_points=recon_points,
        name=name,
        gt_cameras=_path(gt_cameras, "gt_cameras"),
        recon_cameras=_path(recon_cameras, "recon_cameras"),
        align=align,
        transform_path=transform_path,
        transform_json=transform_json,
        pairs=_path(pairs, "pairs"),
        crop_path=crop_path,
        crop_json=crop_json,
        max_distance=max_distance,
        tau=_floats(tau),
        tau_percent=_floats(tau_percent),
        samples=samples,
        seed=seed,
        signed=signed,
        max_triangles=max_triangles,
    )
    return Report(report_json, distances, signed_bytes, kept)
