"""A sweep's table: rows of mixed columns as CSV text or Parquet bytes, the same bytes for the same rows.

Each column holds one type: booleans, numbers (float64; whole numbers stay
int64 only when every value is whole and written as an integer), or text.
Missing values are empty cells (CSV) or nulls (Parquet). Numbers are
written with Python's shortest round-trip form (``repr``), so reading the
CSV back gives the very floats computed.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["csv_text", "parquet_bytes", "table_columns"]


def table_columns(rows: Sequence[Mapping[str, Any]]) -> dict[str, list[Any]]:
    """Column name → values, in the order columns first appear in ``rows`` (missing → None)."""
    names: dict[str, None] = {}
    for row in rows:
        names.update(dict.fromkeys(row))
    return {name: [_plain(row.get(name)) for row in rows] for name in names}


def _plain(value: Any) -> Any:
    """Numpy scalars to Python."""
    if hasattr(value, "item") and not isinstance(value, (str, bytes)):
        return value.item()
    return value


def _kind(values: Sequence[Any]) -> str:
    """``bool``, ``int``, ``float`` or ``str``: the one type a column is written as."""
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return "bool"
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return "int"
    if present and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present):
        return "float"
    return "str"


def _cell(value: Any, kind: str) -> str:
    if value is None:
        return ""
    if kind == "bool":
        return "true" if value else "false"
    if kind == "float":
        return repr(float(value))
    return str(value)


def csv_text(rows: Sequence[Mapping[str, Any]]) -> str:
    r"""The rows as CSV: one header line, ``\n`` line ends, text quoted where needed."""
    columns = table_columns(rows)
    kinds = {name: _kind(values) for name, values in columns.items()}
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(list(columns))
    for i in range(len(rows)):
        writer.writerow([_cell(columns[name][i], kinds[name]) for name in columns])
    return buf.getvalue()


def parquet_bytes(rows: Sequence[Mapping[str, Any]]) -> bytes:
    """The rows as a Parquet file (pyarrow, the optional extra ``camcad[cluster]``)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = table_columns(rows)
    types = {"bool": pa.bool_(), "int": pa.int64(), "float": pa.float64(), "str": pa.string()}
    arrays = {}
    for name, values in columns.items():
        kind = _kind(values)
        if kind == "float":
            values = [None if v is None else float(v) for v in values]
        elif kind == "str":
            values = [None if v is None else str(v) for v in values]
        arrays[name] = pa.array(values, type=types[kind])
    buf = io.BytesIO()
    pq.write_table(pa.table(arrays), buf, compression="zstd")
    return buf.getvalue()
