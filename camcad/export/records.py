"""Plain records: CSV tables of per-angle arrays, JSON summaries and text files."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from camcad._typing import ArrayLike
from camcad.export.atomic import atomic_write_text

__all__ = ["csv_text", "json_safe", "write_csv", "write_json", "write_text"]

CSV_FORMAT = "{:.9g}"
"""Default cell format, nine significant digits: sub-micrometre on a 1 m cam, stable for diffs."""


def _cell(fmt: str, value: float) -> str:
    text = fmt.format(value)
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]  # no "-0": the same table on every platform
    return text


def csv_text(columns: Mapping[str, ArrayLike], *, formats: Sequence[str] | None = None) -> str:
    """CSV with one header line and one row per sample; every column the same length.

    Parameters
    ----------
    columns
        Header name → (n,) values, in column order.
    formats
        One ``str.format`` spec per column (e.g. ``"{:.6f}"``); default
        :data:`CSV_FORMAT` for all.
    """
    names = list(columns)
    fmts = list(formats) if formats is not None else [CSV_FORMAT] * len(names)
    data = [np.asarray(columns[n], dtype=float).ravel().tolist() for n in names]
    lines = [",".join(names)]
    for values in zip(*data, strict=True):
        lines.append(",".join(_cell(f, v) for f, v in zip(fmts, values, strict=True)))
    return "\n".join(lines) + "\n"


def write_csv(
    path: str | os.PathLike[str], columns: Mapping[str, ArrayLike], *, formats: Sequence[str] | None = None
) -> Path:
    """Atomically write a CSV table (see :func:`csv_text`)."""
    return atomic_write_text(path, csv_text(columns, formats=formats))


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


def json_safe(value: Any) -> Any:
    """``value`` as ``summary.json`` writes it: numpy values as Python ones, non-finite floats as None.

    A None where a number belongs means "no finite value" (an unbounded end, e.g. the
    upper end of a jump-free speed range with no upper limit).
    """
    return _clean(value)


def write_json(path: str | os.PathLike[str], data: Mapping[str, Any]) -> Path:
    """Atomically write ``data`` as indented JSON (non-finite numbers become null)."""
    return atomic_write_text(path, json.dumps(_clean(data), indent=2, ensure_ascii=False) + "\n")


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Atomically write a text file."""
    return atomic_write_text(path, text)
