"""Drive cam tables: the motion as an electronic-cam table for a servo drive (``cam_table.csv``).

A servo drive that follows a master axis (an electronic cam, "Kurvenscheibe")
takes the slave position as a table over the master's turn. camcad writes it
from the exact motion program (not from sampled or fitted data), at
``[tables] cam_table_points`` equal master steps, in one of the layouts of
:class:`~camcad.export.spec.DriveLayout`:

``full``
    ``master_deg, slave_<u>, velocity_<u>_per_deg, acceleration_<u>_per_deg2``;
    N + 1 rows from 0° to 360° (the last closes the period). Velocity and
    acceleration are derivatives per master degree (ds/dθ, d²s/dθ²), so they
    hold at any machine speed.
``master-slave``
    ``master_deg, slave_<u>``: the n×2 position table of TwinCAT's
    MC_TABLETYPE_NONEQUIDISTANT (strictly ascending master; the master period
    is last − first), N + 1 rows.
``equidistant``
    ``slave_<u>`` only, N + 1 values at master = 360°·k/N, k = 0 … N (TwinCAT's
    MC_TABLETYPE_EQUIDISTANT, CODESYS SoftMotion's equidistant
    SMC_CAMTable_LREAL_n_1: first value at the master start, last at its end).

``<u>`` is ``mm`` on a slide and ``deg`` (degrees of arm swing) on an arm. At a
joint where the motion itself jumps, the value after the joint is written.

Every value is written in fixed notation with :data:`DECIMALS` decimals
(drive software reads no e-notation), rounded half to even, so each cell is
within 0.5e-9 of the exact value; a value that rounds to zero is written
``0.000000000``, never ``-0.000000000``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.export.records import write_csv
from camcad.export.spec import DriveLayout
from camcad.motion.program import MotionProgram

__all__ = ["DECIMALS", "drive_table", "write_drive_table"]

_DEG = math.pi / 180.0
DECIMALS = 9
"""Decimals of every cell of ``cam_table.csv`` (fixed notation)."""
_FORMAT = f"{{:.{DECIMALS}f}}"


def drive_table(
    program: MotionProgram, points: int, *, layout: DriveLayout = DriveLayout.FULL, unit: str = "mm"
) -> dict[str, FloatArray]:
    """The columns of a drive cam table, exact from the motion program.

    Parameters
    ----------
    program
        The motion program (s in mm, or degrees of swing).
    points
        N, the number of equal master steps per turn (≥ 2); N + 1 rows.
    layout
        Which columns (see the module notes).
    unit
        ``"mm"`` or ``"deg"``: the slave's unit, for the column names.

    Returns
    -------
    dict[str, FloatArray]
        Column name → (N + 1,) read-only values.

    Examples
    --------
    >>> from camcad.motion.laws import make_law
    >>> from camcad.motion.segments import SegmentKind, SegmentSpec
    >>> rise = SegmentSpec(kind=SegmentKind.RISE, span=math.pi, lift=10.0, law=make_law("cycloidal"))
    >>> back = SegmentSpec(kind=SegmentKind.RETURN, span=math.pi, lift=10.0, law=make_law("cycloidal"))
    >>> table = drive_table(MotionProgram.from_segments([rise, back]), 4)
    >>> [float(x) for x in table["slave_mm"]]
    [0.0, 5.0, 10.0, 5.0, 0.0]
    """
    if points < 2:
        raise ValueError(f"a drive table needs at least 2 master steps, got {points}")
    master_deg: FloatArray = np.arange(points + 1, dtype=np.float64) * (360.0 / points)
    phi = np.radians(master_deg)
    motion = program.evaluate(phi)
    s: FloatArray = np.array(motion.s)
    s[-1] = s[0]  # 360° is 0° again: the period closes exactly
    cols: dict[str, FloatArray] = {}
    if layout is not DriveLayout.EQUIDISTANT:
        cols["master_deg"] = master_deg
    cols[f"slave_{unit}"] = s
    if layout is DriveLayout.FULL:
        v: FloatArray = np.array(motion.v) * _DEG  # ds/dθ per master degree: (ds/dφ)·(dφ/dθ), dφ/dθ = π/180
        a: FloatArray = np.array(motion.a) * _DEG**2
        v[-1], a[-1] = v[0], a[0]
        cols[f"velocity_{unit}_per_deg"] = v
        cols[f"acceleration_{unit}_per_deg2"] = a
    for arr in cols.values():
        readonly(arr)
    return cols


def write_drive_table(
    path: str | os.PathLike[str],
    program: MotionProgram,
    points: int,
    *,
    layout: DriveLayout = DriveLayout.FULL,
    unit: str = "mm",
) -> Path:
    """Atomically write ``cam_table.csv`` (:func:`drive_table`), fixed notation, :data:`DECIMALS` decimals."""
    cols = drive_table(program, points, layout=layout, unit=unit)
    fixed = {k: np.round(v, DECIMALS) + 0.0 for k, v in cols.items()}  # + 0.0: no "-0.000000000"
    return write_csv(path, fixed, formats=[_FORMAT] * len(fixed))
