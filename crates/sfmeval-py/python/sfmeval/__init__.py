"""sfmeval: evaluate Structure-from-Motion reconstructions against ground truth.

The Python face of the sfmeval core (Rust): ``evaluate`` reads the files as the ``sfmeval``
CLI reads them (arrays as the PLY file of the same numbers) and runs the core's evaluation, so
``Report.to_json()`` is byte for byte the report ``sfmeval eval --report`` writes for the same
inputs; ``align``, ``cameras``, ``poses``, ``tnt``, ``dtu``, ``eth3d`` and ``table`` are the CLI's verbs
of those names and
``read`` gives a file's geometry as numpy arrays. Nothing here computes a number: the results
give attribute access to the core's JSON and numpy views of the per-point arrays.
"""

from __future__ import annotations

import json
import os
from typing import (
    Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union,
)

import numpy as np

from ._sfmeval import (
    InputError, _align, _cameras, _dtu, _eth3d, _evaluate, _poses, _read, _table, _tnt, align_modes,
    version,
)

__all__ = [
    "Alignment", "CamerasReport", "DtuReport", "Eth3dReport", "InputError", "Mesh", "Model", "Note", "PathLike",
    "PointCloud", "PosesReport", "Progress", "Report", "Section", "Tables", "TntReport", "align",
    "align_modes", "cameras", "dtu", "eth3d", "evaluate", "poses", "read", "table", "tnt", "version",
]
__version__: str = version()

PathLike = Union[str, "os.PathLike[str]"]
#: ``progress=``: called with the stage's name (the CLI's progress-bar label) and the fraction
#: of it done (0 at its start, 1 at its end, every 1 % between).
Progress = Callable[[str, float], Any]


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

    __slots__ = ("_json", "_distances", "_signed", "_kept", "_samples", "_sample_distances")

    def __init__(
        self, report_json: str, distances: bytes, signed: Optional[bytes], kept: bytes,
        samples: bytes = b"", sample_distances: bytes = b"",
    ) -> None:
        super().__init__(json.loads(report_json))
        self._json = report_json
        self._distances = distances
        self._signed = signed
        self._kept = kept
        self._samples = samples
        self._sample_distances = sample_distances

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

    @property
    def completeness_points(self) -> np.ndarray:
        """The completeness samples drawn on the ground truth, ``(M, 3)`` float64 in its frame
        (the rows of ``sfmeval eval --samples-csv``)."""
        return np.frombuffer(self._samples, dtype=np.float64).reshape(-1, 3)

    @property
    def completeness_distances(self) -> np.ndarray:
        """Distance of each completeness sample to the aligned reconstruction (float64, the
        samples' order)."""
        return np.frombuffer(self._sample_distances, dtype=np.float64)

    def __repr__(self) -> str:
        acc = self._data.get("accuracy", {})
        return f"Report(points={acc.get('count')}, accuracy mean={acc.get('mean')})"


class _JsonResult(Section):
    """A result of the core given as its JSON text: attribute access, ``to_json()`` the bytes
    the CLI writes, ``to_dict()`` plain values."""

    __slots__ = ("_json",)

    def __init__(self, text: str) -> None:
        super().__init__(json.loads(text))
        self._json = text

    def to_json(self) -> str:
        return self._json

    def to_dict(self) -> Dict[str, Any]:
        return json.loads(self._json)


class Alignment(_JsonResult):
    """What ``align`` found: the report's alignment section (``method``, ``scale``, ``rmse``,
    ``stages``, ...), ``gt_from_recon`` as a 4×4 array and the ``notes`` of the run.
    ``to_json()`` is the file ``sfmeval align --out ALIGNMENT.json`` writes."""

    __slots__ = ("_notes",)

    def __init__(self, text: str, notes: str) -> None:
        super().__init__(text)
        self._notes = json.loads(notes)

    @property
    def gt_from_recon(self) -> np.ndarray:
        """The 4×4 row-major similarity mapping reconstruction coordinates into the
        ground-truth frame (float64)."""
        return np.array(self._data["gt_from_recon"], dtype=np.float64)

    @property
    def notes(self) -> List[Note]:
        return [Note(n) for n in self._notes]

    def to_json(self) -> str:
        """The alignment section's JSON, exactly the bytes ``sfmeval align --out X.json``
        writes."""
        return self._json


class CamerasReport(_JsonResult):
    """Camera-pose errors (``cameras``: ATE, per-image rotation and centre errors, RRA/RTA,
    ...) after the camera alignment (``alignment``). ``to_json()`` is the file
    ``sfmeval cameras --report`` writes."""

    __slots__ = ()

    @property
    def alignment(self) -> _Alignment:
        return _Alignment(self._data["alignment"])

    def to_json(self) -> str:
        """The JSON ``sfmeval cameras --report`` writes, byte for byte."""
        return self._json


class PosesReport(_JsonResult):
    """A ``sfmeval.poses/1`` report: one pose benchmark protocol's numbers (``result``), its
    ``convention`` and the counts. ``to_json()`` is the file ``sfmeval poses --report`` writes."""

    __slots__ = ()

    @property
    def notes(self) -> List[Note]:
        return [Note(n) for n in self._data["notes"]]

    def to_json(self) -> str:
        """The JSON ``sfmeval poses --report`` writes, byte for byte."""
        return self._json


class TntReport(_JsonResult):
    """A ``sfmeval.tanksandtemples/2`` report (``precision.value``, ``recall.value``,
    ``f_score``, ``registration``, typed ``notes``). ``to_json()`` is the ``report.json``
    ``sfmeval tnt`` writes."""

    __slots__ = ()

    @property
    def notes(self) -> List[Note]:
        return [Note(n) for n in self._data.get("notes", [])]

    def to_json(self) -> str:
        """The ``report.json`` of ``sfmeval tnt``, byte for byte."""
        return self._json


class DtuReport(_JsonResult):
    """A ``sfmeval.dtu/1`` report (``mean_accuracy``, ``mean_completeness``, ``overall`` in mm,
    ``counts``, ``options``, ``mode``). ``to_json()`` is what ``sfmeval dtu --json`` prints and
    ``--report`` writes."""

    __slots__ = ()

    def to_json(self) -> str:
        """The report of ``sfmeval dtu``, byte for byte."""
        return self._json


class Eth3dReport(_JsonResult):
    """A ``sfmeval.eth3d/1`` report (``tolerances``: per tolerance in m its ``accuracy``,
    ``completeness`` and ``f1`` with the point counts; ``scans``, ``options``).
    ``to_json()`` is what ``sfmeval eth3d --json`` prints and ``--out`` writes as eth3d.json."""

    __slots__ = ()

    def to_json(self) -> str:
        """The report of ``sfmeval eth3d``, byte for byte."""
        return self._json


class Tables:
    """The comparison tables of evaluation reports, each exactly the text ``sfmeval table``
    prints (``--format``) and writes (``--out``): ``table1_md`` (Table I), ``table1_csv``,
    ``table_md`` (Table I and the wide table), ``runs_csv`` (the wide table) and
    ``summary_json`` (the rows)."""

    __slots__ = ("_files",)

    def __init__(self, files: Mapping[str, str]) -> None:
        self._files = dict(files)

    @property
    def table1_md(self) -> str:
        return self._files["table1.md"]

    @property
    def table1_csv(self) -> str:
        return self._files["table1.csv"]

    @property
    def table_md(self) -> str:
        return self._files["table.md"]

    @property
    def runs_csv(self) -> str:
        return self._files["runs.csv"]

    @property
    def summary_json(self) -> str:
        return self._files["summary.json"]

    @property
    def rows(self) -> List[Section]:
        """The rows of ``summary.json`` (``sfmeval.runner-table/1``), one per dataset and
        pipeline."""
        return [Section(r) for r in json.loads(self.summary_json)["rows"]]

    @property
    def files(self) -> Dict[str, str]:
        """The texts by the file names ``sfmeval table --out`` gives them."""
        return dict(self._files)

    def write(self, folder: PathLike) -> None:
        """Writes every table file into ``folder`` (made when missing), as ``--out``."""
        os.makedirs(folder, exist_ok=True)
        for name, text in self._files.items():
            with open(os.path.join(folder, name), "w", encoding="utf-8", newline="") as f:
                f.write(text)

    def __str__(self) -> str:
        return self.table1_md

    def __repr__(self) -> str:
        return f"Tables({len(self.rows)} rows)"


def _float_rows(value: Any, what: str) -> np.ndarray:
    """An ``(N, 3)`` float32/float64 array in native byte order, C-contiguous and aligned: the
    array itself when it is so (read in place), else one contiguous copy."""
    a = np.asarray(value)
    if a.ndim != 2 or a.shape[1] != 3 or a.dtype.kind != "f":
        raise InputError(
            f"{what}: an (N, 3) array of floats is needed, got shape {a.shape} of {a.dtype}"
        )
    if a.dtype not in (np.dtype(np.float32), np.dtype(np.float64)):
        a = a.astype(np.float64)
    return np.require(a, dtype=a.dtype.newbyteorder("="), requirements=["C", "A"])


def _triangle_rows(value: Any, what: str) -> np.ndarray:
    """An ``(M, 3)`` uint32 array of vertex indices (any integer dtype in range)."""
    a = np.asarray(value)
    if a.ndim != 2 or a.shape[1] != 3 or a.dtype.kind not in "iu":
        raise InputError(
            f"{what}: an (M, 3) array of vertex indices is needed, got shape {a.shape} of {a.dtype}"
        )
    if a.size and (int(a.min()) < 0 or int(a.max()) > np.iinfo(np.uint32).max):
        raise InputError(f"{what}: vertex indices must lie in 0..{np.iinfo(np.uint32).max}")
    return np.require(a, dtype=np.uint32, requirements=["C", "A"])


class Mesh:
    """A triangle mesh: ``vertices`` ``(N, 3)`` float and ``triangles`` ``(M, 3)`` vertex
    indices. As ``evaluate``'s ``gt`` it is read as the binary PLY of these arrays would be
    (the report names it ``name``, default ``ground_truth.ply``)."""

    def __init__(self, vertices: Any, triangles: Any, *, name: Optional[str] = None,
                 format: str = "ply", notes: Sequence[Note] = ()) -> None:
        self.vertices: np.ndarray = np.asarray(vertices)
        self.triangles: np.ndarray = np.asarray(triangles)
        self.name = name
        self.format = format
        self.notes: List[Note] = list(notes)

    def __repr__(self) -> str:
        return f"Mesh({len(self.vertices)} vertices, {len(self.triangles)} triangles)"


class PointCloud:
    """A point cloud: ``points`` ``(N, 3)`` float (float32 when the file stores float32),
    ``colors`` ``(N, 3)`` uint8 or ``None``."""

    def __init__(self, points: Any, colors: Any = None, *, name: Optional[str] = None,
                 format: str = "ply", notes: Sequence[Note] = ()) -> None:
        self.points: np.ndarray = np.asarray(points)
        self.colors: Optional[np.ndarray] = None if colors is None else np.asarray(colors)
        self.name = name
        self.format = format
        self.notes: List[Note] = list(notes)

    def __repr__(self) -> str:
        return f"PointCloud({len(self.points)} points)"


class Model(PointCloud):
    """An SfM model: its 3D ``points`` and ``colors`` (the points ``evaluate`` measures) and its
    ``cameras``: the ``sfmeval.cameras/1`` document ``sfmeval export`` writes (``cameras`` with
    intrinsics, ``images`` with ``name`` and ``cam_from_world``), in the model's frame."""

    def __init__(self, points: Any, colors: Any, cameras: Mapping[str, Any], *,
                 name: Optional[str] = None, format: str = "", notes: Sequence[Note] = ()) -> None:
        super().__init__(points, colors, name=name, format=format, notes=notes)
        self.cameras: Section = Section(cameras)

    @property
    def images(self) -> List[Section]:
        """The registered images (``name``, ``camera_id``, ``cam_from_world``)."""
        return [Section(i) for i in self.cameras["images"]] if "images" in self.cameras else []

    def __repr__(self) -> str:
        return f"Model({self.format}: {len(self.points)} points, {len(self.images)} images)"


def read(path: PathLike, *, max_triangles: int = 10_000_000) -> Union[Mesh, PointCloud, Model]:
    """Reads what ``path`` holds, with the readers of ``sfmeval eval``.

    A GLB, glTF, OBJ or PLY with faces is a ``Mesh`` (as ``--gt`` reads it; vertices float64,
    triangles uint32); a PLY without faces a ``PointCloud`` (points as stored, float32 or
    float64, colours uint8; the camera-centre points OpenMVG and Theia write into their PLYs
    removed, as ``--recon`` does and ``sfmeval export`` writes them); an SfM model (a COLMAP
    folder, ``.nvm``, Bundler ``.out``, OpenMVG ``sfm_data.json``, ``cameras.json``) a ``Model``
    with its points and cameras.

    Raises ``FileNotFoundError`` for a path that does not exist and ``InputError`` naming the
    file for one the readers cannot read.
    """
    d = _read(os.fspath(path), max_triangles)
    notes = [Note(n) for n in json.loads(d["notes"])]
    points = np.frombuffer(d["points"], dtype=np.dtype(d["dtype"])).reshape(-1, 3)
    colors = (None if d["colors"] is None
              else np.frombuffer(d["colors"], dtype=np.uint8).reshape(-1, 3))
    if d["kind"] == "mesh":
        triangles = np.frombuffer(d["triangles"], dtype=np.uint32).reshape(-1, 3)
        return Mesh(points, triangles, name=d["name"], format=d["format"], notes=notes)
    if d["kind"] == "model":
        return Model(points, colors, json.loads(d["cameras"]), name=d["name"],
                     format=d["format"], notes=notes)
    return PointCloud(points, colors, name=d["name"], format=d["format"], notes=notes)


GroundTruthLike = Union[PathLike, Mesh, PointCloud, Tuple[Any, Any], np.ndarray]
ReconLike = Union[PathLike, PointCloud, np.ndarray]


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


def _sources(gt: GroundTruthLike, recon: ReconLike, gt_name: Optional[str],
             name: Optional[str]) -> Dict[str, Any]:
    """The native functions' ground-truth and reconstruction arguments."""
    out: Dict[str, Any] = {"gt_name": gt_name, "name": name}
    if isinstance(gt, (str, os.PathLike)):
        out["gt"] = os.fspath(gt)
    elif isinstance(gt, Mesh):
        out["gt_vertices"] = _float_rows(gt.vertices, "gt vertices")
        out["gt_triangles"] = _triangle_rows(gt.triangles, "gt triangles")
        out["gt_name"] = gt_name or gt.name
    elif isinstance(gt, PointCloud):
        out["gt_vertices"] = _float_rows(gt.points, "gt points")
        out["gt_name"] = gt_name or gt.name
    elif isinstance(gt, tuple):
        if len(gt) != 2:
            raise InputError("gt: a (vertices, triangles) pair is needed")
        out["gt_vertices"] = _float_rows(gt[0], "gt vertices")
        out["gt_triangles"] = _triangle_rows(gt[1], "gt triangles")
    else:
        out["gt_vertices"] = _float_rows(gt, "gt points")
    if isinstance(recon, (str, os.PathLike)):
        out["recon"] = os.fspath(recon)
    elif isinstance(recon, PointCloud):
        out["recon_points"] = _float_rows(recon.points, "recon")
        out["name"] = name or recon.name
    else:
        out["recon_points"] = _float_rows(recon, "recon")
    return out


def _transform(value: Union[None, PathLike, Sequence[Sequence[float]], np.ndarray]
               ) -> Dict[str, Optional[str]]:
    if isinstance(value, (str, os.PathLike)):
        return {"transform_path": os.fspath(value), "transform_json": None}
    if value is None:
        return {"transform_path": None, "transform_json": None}
    # the core's parser checks it (4×4 or 16 numbers, a similarity), as for a file
    return {"transform_path": None,
            "transform_json": json.dumps(np.asarray(value, dtype=np.float64).tolist())}


def evaluate(
    gt: GroundTruthLike,
    recon: ReconLike,
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
    gt_name: Optional[str] = None,
    max_triangles: int = 10_000_000,
    threads: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Report:
    """Evaluate a reconstruction against a ground truth and return the report
    (``sfmeval eval``: each keyword is the flag of the same name).

    gt
        Ground truth: a GLB, glTF, OBJ or PLY file (mesh, or a dense cloud), or a dataset
        folder (docs/dataset.md: its ground_truth.glb, its cameras.json as ``gt_cameras`` and
        its depth/ when present, as ``--dataset``); or geometry in memory: a ``Mesh``, a
        ``(vertices, triangles)`` pair of arrays, a ``PointCloud`` or an ``(N, 3)`` array (a
        ground-truth cloud), read as the binary PLY of those numbers would be (named
        ``gt_name``, default ``ground_truth.ply``).
    recon
        Reconstruction: a PLY point cloud, a COLMAP model folder (sparse/ with sub-models is
        fine), an .nvm, a Bundler .out, an OpenMVG sfm_data.json or a cameras.json; or an
        ``(N, 3)`` float32/float64 array or ``PointCloud``, read as the float/double PLY of
        those points (named ``name``, default ``points.ply``; a ``Model``'s points alone: give
        its path for its cameras). Arrays that are C-contiguous and aligned are read in place
        (copied once, into the core's own storage).
    name
        The reconstruction's name in the report and its notes (default: the file or folder
        name).
    recon_cameras
        The SfM model whose cameras go with a PLY ``recon`` in the same frame (its points at
        the model's camera centres are removed; the cameras serve the camera alignment and the
        pose metrics).
    gt_cameras
        Ground-truth cameras (a dataset's cameras.json): camera alignment and pose metrics.
    align
        Alignment, one of ``align_modes()``: auto (cameras, else points, else global; then
        icp), cameras, points, global (alone, or refined: cameras+icp, points+icp,
        global+icp), icp (from ``transform`` or the identity), given (needs ``transform``) or
        none. Default: given with ``transform``, else auto.
    transform
        A 4×4 row-major similarity gt_from_recon (a file: JSON or 16 numbers; or an array):
        used as is with ``align="given"``, as the start of ``align="icp"``.
    pairs
        Point pairs for ``align="points"`` (a file:
        ``{"pairs": [{"recon": [x,y,z], "gt": [x,y,z]}, ...]}``).
    crop
        A crop file (sfmeval.crop/1 JSON), or its JSON as a dict.
    max_distance
        Discard reconstructed points farther than this from the ground truth.
    tau
        Thresholds in ground-truth units (a number or a list).
    tau_percent
        Thresholds in percent of the ground-truth bounding-box diagonal. Default when no
        threshold is given: 0.5, 1, 2.
    samples
        Completeness samples drawn on a ground-truth mesh (default 1000000).
    seed
        Seed of the surface sampler and the randomised alignment stages (default 0).
    signed
        Also report distances signed by the closest triangle's normal (as CloudCompare's C2M).
    max_triangles
        Refuse a ground-truth mesh with more triangles than this once every glTF node instance
        is expanded (default 10000000).
    threads
        Worker threads of this call (default: all cores).
    progress
        Called as ``progress(stage, fraction)`` at each stage's start (0), every 1 % and its end
        (1); an exception it raises stops the evaluation and is raised here.

    The GIL is released while the core works; Ctrl-C stops the evaluation (at its next
    progress step) with ``KeyboardInterrupt``. Raises ``FileNotFoundError`` for a path that
    does not exist and ``InputError`` (a ``ValueError``) naming the file and what is wrong for
    anything the core cannot read or use.
    """
    crop_path: Optional[str] = None
    crop_json: Optional[str] = None
    if isinstance(crop, (str, os.PathLike)):
        crop_path = os.fspath(crop)
    elif crop is not None:
        crop_json = json.dumps(dict(crop))
    report_json, distances, signed_bytes, kept, samples_bytes, sample_distances = _evaluate(
        **_sources(gt, recon, gt_name, name),
        gt_cameras=_path(gt_cameras, "gt_cameras"),
        recon_cameras=_path(recon_cameras, "recon_cameras"),
        align=align,
        **_transform(transform),
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
        threads=threads,
        progress=progress,
    )
    return Report(report_json, distances, signed_bytes, kept, samples_bytes, sample_distances)


def align(
    gt: GroundTruthLike,
    recon: ReconLike,
    *,
    gt_cameras: Optional[PathLike] = None,
    recon_cameras: Optional[PathLike] = None,
    align: Optional[str] = None,
    transform: Union[None, PathLike, Sequence[Sequence[float]], np.ndarray] = None,
    pairs: Optional[PathLike] = None,
    samples: int = 1_000_000,
    seed: int = 0,
    name: Optional[str] = None,
    gt_name: Optional[str] = None,
    max_triangles: int = 10_000_000,
    threads: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Alignment:
    """Align a reconstruction to the ground truth and return gt_from_recon with the alignment
    section (``sfmeval align``; ``to_json()`` is the file ``--out ALIGNMENT.json`` writes).

    ``gt``, ``recon``, ``gt_cameras``, ``recon_cameras``, ``align``, ``transform``, ``pairs``,
    ``name``, ``gt_name``, ``max_triangles``, ``threads`` and ``progress`` are
    ``evaluate``'s (a dataset folder's depth maps are not read). ``samples``: ground-truth
    surface samples the ``global`` search measures against (as ``evaluate``'s: with the same
    value and seed, ``align`` finds ``evaluate``'s alignment). ``seed``: seed of the randomised
    stages and of the surface sampler.
    """
    alignment, notes = _align(
        **_sources(gt, recon, gt_name, name),
        gt_cameras=_path(gt_cameras, "gt_cameras"),
        recon_cameras=_path(recon_cameras, "recon_cameras"),
        align=align,
        **_transform(transform),
        pairs=_path(pairs, "pairs"),
        samples=samples,
        seed=seed,
        max_triangles=max_triangles,
        threads=threads,
        progress=progress,
    )
    return Alignment(alignment, notes)


def cameras(
    gt_cameras: PathLike,
    recon: PathLike,
    *,
    transform: Union[None, PathLike, Sequence[Sequence[float]], np.ndarray] = None,
) -> CamerasReport:
    """Camera-pose errors of a reconstruction's cameras against the ground-truth cameras
    (``sfmeval cameras``; ``to_json()`` is the file ``--report`` writes).

    gt_cameras
        Ground-truth cameras (a dataset's cameras.json, or any model in the GT frame).
    recon
        The reconstruction: a COLMAP model folder, .nvm, Bundler .out, sfm_data.json,
        cameras.json.
    transform
        Use this gt_from_recon (a file or a 4×4 array) instead of aligning the camera centres.
    """
    t = _transform(transform)
    return CamerasReport(_cameras(os.fspath(gt_cameras), os.fspath(recon),
                                  t["transform_path"], t["transform_json"]))


def poses(
    gt_cameras: PathLike,
    recon: PathLike,
    protocol: str,
    *,
    position_accuracy: float = 0.0,
) -> PosesReport:
    """A camera-pose benchmark's numbers as its official code computes them (``sfmeval
    poses``; docs/poses.md): ``protocol`` is ``"colmap"`` (COLMAP's reconstruction benchmark),
    ``"imc"`` (Image Matching Challenge mAA) or ``"co3d"`` (RRA/RTA@5/15/30, AUC@30).

    gt_cameras
        Ground-truth cameras (a cameras.json, or any model: COLMAP folder, .nvm, ...).
    recon
        The reconstruction: a COLMAP model folder, .nvm, Bundler .out, sfm_data.json,
        cameras.json.
    position_accuracy
        COLMAP's ``position_accuracy_gt`` (GT units; 0: off).
    """
    return PosesReport(_poses(os.fspath(gt_cameras), os.fspath(recon), protocol,
                              float(position_accuracy)))


def tnt(
    scene: PathLike,
    recon: PathLike,
    *,
    trajectory: Optional[PathLike] = None,
    transform: Union[None, PathLike, Sequence[Sequence[float]], np.ndarray] = None,
    tau: Optional[float] = None,
    seed: int = 0,
    scene_name: Optional[str] = None,
    out: Optional[PathLike] = None,
    threads: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> TntReport:
    """The Tanks and Temples protocol on a scene folder (``sfmeval tnt``): trajectory
    alignment, three ICP refinements, crop, voxel down-sampling, precision / recall / F at the
    scene's τ, as the benchmark's own evaluation toolbox computes them. ``to_json()`` is the
    ``report.json`` ``sfmeval tnt`` writes.

    scene
        The scene folder as the benchmark ships it: SCENE.ply, SCENE.json (crop),
        SCENE_trans.txt, SCENE_COLMAP_SfM.log and, for video trajectories,
        SCENE_mapping_reference.txt. The folder's name is the scene's.
    recon
        The reconstruction: a PLY point cloud (usually the dense one), or any SfM model sfmeval
        reads, whose points are measured.
    trajectory
        The reconstruction's camera trajectory (.log, one frame per input image).
    transform
        Skip the registration: use this gt_from_recon (a file of 16 numbers, or a 4×4 array).
    tau
        τ in ground-truth units (default: the scene's, from the benchmark's table).
    seed
        Seed of the trajectory alignment's RANSAC (default 0).
    scene_name
        The files' stem when it is not the folder's name.
    out
        Write report.json, SCENE.precision.ply / .recall.ply and the toolbox's text files
        here (nothing is written without it).
    threads, progress
        As ``evaluate``'s.
    """
    transform_path: Optional[str] = None
    transform_text: Optional[str] = None
    if isinstance(transform, (str, os.PathLike)):
        transform_path = os.fspath(transform)
    elif transform is not None:
        transform_text = " ".join(repr(float(v))
                                  for v in np.asarray(transform, dtype=np.float64).ravel())
    return TntReport(_tnt(
        os.fspath(scene), os.fspath(recon), scene_name=scene_name,
        trajectory=_path(trajectory, "trajectory"), transform_path=transform_path,
        transform_text=transform_text, tau=tau, seed=seed, out=_path(out, "out"),
        threads=threads, progress=progress,
    ))


def dtu(
    dataset: PathLike,
    scan: int,
    recon: PathLike,
    *,
    mode: str = "auto",
    downsample_density: Optional[float] = None,
    patch_size: Optional[float] = None,
    max_dist: Optional[float] = None,
    visualize_threshold: Optional[float] = None,
    seed: int = 0,
    shuffle: bool = True,
    vis_out: Optional[PathLike] = None,
    report: Optional[PathLike] = None,
    threads: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> DtuReport:
    """The DTU MVS evaluation (``sfmeval dtu``) of a reconstruction on a scan, as the
    benchmark's Python port (DTUeval-python) computes it: mean accuracy, mean completeness and
    overall, in mm. ``to_json()`` is the report ``sfmeval dtu --json`` prints.

    dataset
        The ground-truth folder as the benchmark ships it: Points/stl/stlNNN_total.ply,
        ObsMask/ObsMaskN_10.mat and ObsMask/PlaneN.mat.
    scan
        The scan number (24, 37, ...).
    recon
        The reconstruction, in the scan's frame and in mm: a PLY point cloud or mesh, an OBJ
        or glTF mesh, or an SfM model (COLMAP, NVM, Bundler, OpenMVG, cameras.json) whose 3D
        points are evaluated. Its path as given is its name in the report.
    mode
        ``"auto"`` (a mesh when it has faces), ``"mesh"`` (sampled as the evaluator samples
        it) or ``"pcd"`` (the points or vertices only).
    downsample_density, patch_size, max_dist, visualize_threshold
        The protocol's options in mm (default: the CLI's, 0.2, 60, 20 and 10).
    seed, shuffle
        The seed of the shuffle before down-sampling; ``shuffle=False`` down-samples in the
        input's order (``--no-shuffle``).
    vis_out
        Write the evaluator's coloured error clouds vis_NNN_d2s.ply and vis_NNN_s2d.ply here.
    report
        Write the report here.
    threads, progress
        As ``evaluate``'s.
    """
    return DtuReport(_dtu(
        os.fspath(dataset), scan, os.fspath(recon), mode=mode,
        downsample_density=downsample_density, patch_size=patch_size, max_dist=max_dist,
        visualize_threshold=visualize_threshold, seed=seed, shuffle=shuffle,
        vis_out=_path(vis_out, "vis_out"), report=_path(report, "report"), threads=threads,
        progress=progress,
    ))


def eth3d(
    gt: PathLike,
    recon: PathLike,
    *,
    tolerances: Optional[Sequence[float]] = None,
    voxel_size: Optional[float] = None,
    beam_start_radius: Optional[float] = None,
    beam_divergence_halfangle_deg: Optional[float] = None,
    out: Optional[PathLike] = None,
    threads: Optional[int] = None,
) -> Eth3dReport:
    """ETH3D's multi-view evaluation (``sfmeval eth3d``) of a reconstruction on a scene's laser
    scans, as the benchmark's official tool computes it: accuracy, completeness and F1 per
    tolerance. ``to_json()`` is the report ``sfmeval eth3d --json`` prints.

    gt
        The scene's MeshLab project (dslr_scan_eval/scan_alignment.mlp), its scan PLYs beside
        it. Its path as given is its name in the report.
    recon
        The reconstruction PLY (its vertices), in the scene's frame and in metres. Its path as
        given is its name in the report.
    tolerances
        The tolerances in m (default: the benchmark's 0.01, 0.02, 0.05, 0.1, 0.2, 0.5).
    voxel_size, beam_start_radius, beam_divergence_halfangle_deg
        The tool's options (default: the CLI's, 0.01 m, 0.001125 m and 0.011 degrees).
    out
        Write the report (eth3d.json) and the tool's coloured clouds
        (accuracy.tolerance_T.ply, completeness.tolerance_T.ply) here.
    threads
        As ``evaluate``'s.
    """
    return Eth3dReport(_eth3d(
        os.fspath(gt), os.fspath(recon),
        tolerances=None if tolerances is None else [float(t) for t in tolerances],
        voxel_size=voxel_size, beam_start_radius=beam_start_radius,
        beam_divergence_halfangle_deg=beam_divergence_halfangle_deg, out=_path(out, "out"),
        threads=threads,
    ))


def table(
    reports: Union[PathLike, Sequence[PathLike], Mapping[str, PathLike]],
    *,
    dataset: Optional[str] = None,
    failed: Union[None, Mapping[str, str], Sequence[str]] = None,
) -> Tables:
    """Table I and the comparison table of evaluation reports (``sfmeval table``; each text is
    what it prints and writes).

    reports
        A folder of runs: every ``PIPELINE/report.json`` directly inside it, by name (what
        ``sfmeval table FOLDER/*/report.json`` reads); or report paths, each
        ``PIPELINE=REPORT.json`` or a path whose parent folder names the pipeline; or a dict
        ``{pipeline: report path}``. The pose protocols' reports beside a report
        (``REPORT.poses-colmap.json``, ``-imc``, ``-co3d``, as the runner writes them) add its
        pose columns.
    dataset
        The dataset's name in the tables (default: the ground truth's file name, without its
        extension, of the first report).
    failed
        Pipelines without a report, shown as failed: ``{pipeline: reason}`` or
        ``["PIPELINE=REASON", ...]``.
    """
    args: List[str]
    if isinstance(reports, (str, os.PathLike)) and os.path.isdir(reports):
        folder = os.fspath(reports)
        args = sorted(os.path.join(folder, d, "report.json") for d in os.listdir(folder)
                      if os.path.isfile(os.path.join(folder, d, "report.json")))
        if not args:
            raise InputError(f"runs folder '{folder}': no PIPELINE/report.json inside")
    elif isinstance(reports, (str, os.PathLike)):
        args = [os.fspath(reports)]
    elif isinstance(reports, Mapping):
        args = [f"{p}={os.fspath(r)}" for p, r in reports.items()]
    else:
        args = [os.fspath(r) for r in reports]
    if failed is None:
        failed_args: List[str] = []
    elif isinstance(failed, Mapping):
        failed_args = [f"{p}={r}" for p, r in failed.items()]
    else:
        failed_args = list(failed)
    return Tables(_table(args, dataset, failed_args))
