"""Plain records: CSV tables of per-angle arrays, JSON summaries and text files."""

from __future__ import annotations

import io
import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from camcad._typing import ArrayLike
from camcad.export.atomic import atomic_write_text

__all__ = ["csv_text", "write_csv", "write_json", "write_text"]

CSV_FORMAT = "%.9g"
"""Nine significant digits: sub-micrometre on a 1 m cam, stable for diffs."""


def csv_text(columns: Mapping[str, ArrayLike]) -> str:
    """CSV with one header line and one row per sample; every column the same length."""
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    buf = io.StringIO()
    np.savetxt(buf, data, delimiter=",", header=",".join(names), comments="", fmt=CSV_FORMAT)
    return buf.getvalue()


def write_csv(path: str | os.PathLike[str], columns: Mapping[str, ArrayLike]) -> Path:
    """Atomically write a CSV table (see :func:`csv_text`)."""
    return atomic_write_text(path, csv_text(columns))


def _clean(value: Any) -> Any:
    """JSON-safe values: numpy scalars to Python, non-finite floats to None."""
    if isinstance(value, Mapping):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_clean(v) for v in value.tolist()]
    if isinstance(value, (np.floating, float)):
        f = float(value)
        return f if math.isfinite(f) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


def write_json(path: str | os.PathLike[str], data: Mapping[str, Any]) -> Path:
    """Atomically write ``data`` as indented JSON (non-finite numbers become null)."""
    return atomic_write_text(path, json.dumps(_clean(data), indent=2, ensure_ascii=False) + "\n")


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Atomically write a text file."""
    return atomic_write_text(path, text)
