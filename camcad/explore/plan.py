"""What decides a sweep's rows: the plan (base design, variables, points, limits) and its chunks.

Kept apart from :mod:`camcad.explore.sweep`, which runs plans, so that the
page writer (:mod:`camcad.explore.page`) reads a plan without importing the
engine that imports it.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from camcad._version import __version__
from camcad.explore.measures import Limit, Measure
from camcad.explore.space import Variable

__all__ = ["DEFAULT_CHUNK", "Chunk", "SweepPlan"]

DEFAULT_CHUNK = 16
"""Designs per chunk: about a second of work for a worker (an analysis: 20–100 ms alone, 4–10 ms batched)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class SweepPlan:
    """Everything that decides a sweep's rows.

    ``data`` is the base design's TOML mapping, ``points`` one tuple of
    values (one per variable) per design, ``limits`` extra limits judged in
    the ``feasible`` column, ``pareto`` the two objectives of the front
    (both minimised), ``sampling`` a short description for the page.
    """

    data: Mapping[str, Any]
    source: str = ""
    variables: tuple[Variable, ...]
    points: tuple[tuple[Any, ...], ...]
    limits: tuple[Limit, ...] = ()
    pareto: tuple[Measure, Measure]
    sampling: str = "grid"
    chunk_size: int = DEFAULT_CHUNK
    batch: bool = True  # analyse a chunk's variants together (camcad.explore.batch): the same rows, faster

    def key(self) -> str:
        """A hash of everything that decides the rows (and of camcad's version)."""
        blob = json.dumps(
            {
                "camcad": __version__,
                "data": self.data,
                "variables": [(v.name, v.path) for v in self.variables],
                "points": [[repr(x) for x in p] for p in self.points],
                "limits": [lim.text for lim in self.limits],
                "chunk": self.chunk_size,
            },
            sort_keys=True,
            default=repr,
        )
        return hashlib.sha256(blob.encode("utf-8")).hexdigest()

    def chunks(self) -> list[Chunk]:
        """The work in order: chunk k holds designs k·chunk_size … (k+1)·chunk_size − 1."""
        n = self.chunk_size
        return [
            Chunk(
                data=self.data,
                source=self.source,
                variables=self.variables,
                limits=self.limits,
                start=start,
                points=self.points[start : start + n],
                batch=self.batch,
            )
            for start in range(0, len(self.points), n)
        ]


@dataclass(frozen=True, slots=True, kw_only=True)
class Chunk:
    """One unit of work for a worker: designs ``start`` … ``start + len(points) − 1``."""

    data: Mapping[str, Any]
    source: str
    variables: tuple[Variable, ...]
    limits: tuple[Limit, ...]
    start: int
    points: tuple[tuple[Any, ...], ...]
    batch: bool = True
