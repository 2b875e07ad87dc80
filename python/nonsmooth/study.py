"""Studies with the same TOML files as the command-line tool: regime maps over one or two
parameters and basins of attraction over an initial-condition plane, run whole or in
shards (each shard's points spread over every core), merged with a verified merge."""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

from . import _nonsmooth as _ext

PathLike = Union[str, "os.PathLike[str]"]


@dataclass(frozen=True)
class ShardRun:
    """A finished shard: its manifest's path, its points, the failed ones, the spec hash."""

    manifest: str
    points: int
    failed: int
    hash: str


@dataclass(frozen=True)
class Attractor:
    """An attractor of a merged study: label, points in its basin and their fraction,
    period (0: none), impacts per period, mean top Lyapunov exponent (1/s, NaN if not
    recorded), centroid of its section points."""

    label: int
    points: int
    fraction: float
    period: int
    impacts_per_period: float
    tle_mean: float
    centroid: npt.NDArray[np.float64]


@dataclass(frozen=True)
class StudyTable:
    """A merged study. Per point (index ``i = ix + nx·iy``): axis values ``x``, ``y`` (NaN
    for one axis), the period, impacts per period, top Lyapunov exponent and ``q`` (NaN if
    not recorded), the attractor label (−1 for a failed point) and whether it succeeded.
    :meth:`grid` reshapes a column to the ``(ny, nx)`` regime map or basin picture."""

    name: str
    x_parameter: str
    y_parameter: str
    nx: int
    ny: int
    x: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    period: npt.NDArray[np.float64]
    impacts_per_period: npt.NDArray[np.float64]
    tle: npt.NDArray[np.float64]
    q: npt.NDArray[np.float64]
    label: npt.NDArray[np.float64]
    ok: npt.NDArray[np.float64]
    attractors: list[Attractor]
    files: list[str]
    failed: int

    def grid(self, column: str) -> npt.NDArray[np.float64]:
        """The column as an ``(ny, nx)`` array (row ``iy``, column ``ix``)."""
        a = np.asarray(getattr(self, column), dtype=np.float64)
        return a.reshape(self.ny, self.nx)


def run(
    spec: PathLike,
    out: PathLike,
    *,
    shard: tuple[int, int] = (1, 1),
    progress: Optional[Callable[[int, int], Any]] = None,
) -> ShardRun:
    """Runs shard ``I`` of ``N`` (``shard=(I, N)``, 1-based; default the whole study) of the
    study file ``spec`` into the directory ``out``, as ``nonsmooth study run`` does: the
    same shard files, bit for bit. ``progress(done, total)`` is called as points finish.
    On Ctrl-C nothing is written."""
    try:
        i, n = shard
    except (TypeError, ValueError):
        raise ValueError("shard must be a pair (index, count)") from None
    if isinstance(i, bool) or isinstance(n, bool) or not isinstance(i, int) or not isinstance(n, int):
        raise TypeError("shard must be two integers")
    if not (1 <= n <= 1_000_000 and 1 <= i <= n):
        raise ValueError(f"shard must have 1 <= index <= count <= 10^6 (got {i}, {n})")
    if progress is not None and not callable(progress):
        raise TypeError("progress must be callable")
    d = _ext.study_run(os.fspath(spec), os.fspath(out), i, n, progress)
    return ShardRun(str(d["manifest"]), int(d["points"]), int(d["failed"]), str(d["hash"]))


def merge(directory: PathLike, out: Optional[PathLike] = None) -> StudyTable:
    """Merges every shard in ``directory`` (refusing missing, foreign or damaged shards),
    labels the attractors, and, with ``out``, writes the merged table, sections, attractor
    summary and figure next to ``out`` (as ``nonsmooth study merge``)."""
    d = _ext.study_merge(os.fspath(directory), None if out is None else os.fspath(out))
    return StudyTable(
        name=str(d["name"]), x_parameter=str(d["x_parameter"]),
        y_parameter=str(d["y_parameter"]), nx=int(d["nx"]), ny=int(d["ny"]), x=d["x"],
        y=d["y"], period=d["period"], impacts_per_period=d["impacts_per_period"],
        tle=d["tle"], q=d["q"], label=d["label"], ok=d["ok"],
        attractors=[
            Attractor(int(a["label"]), int(a["points"]), float(a["fraction"]),
                      int(a["period"]), float(a["impacts_per_period"]), float(a["tle_mean"]),
                      a["centroid"])
            for a in d["attractors"]
        ],
        files=[str(f["path"]) for f in d["files"]], failed=int(d["failed"]),
    )
