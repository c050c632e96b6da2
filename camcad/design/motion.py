"""The ``[[motion]]`` tables: segments, point tables, boundary values and the closing lift."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from camcad.design.rules import (
    ANGLE_SUM_TOL_DEG,
    FULL_TURN_DEG,
    LIFT_CLOSE_TOL_MM,
    MAX_LENGTH_MM,
    MIN_LENGTH_MM,
    MIN_SEGMENT_DEG,
    _convert,
    _key,
    _show,
    _suggest,
)
from camcad.design.spec import DEG
from camcad.design.table_file import read_table_file
from camcad.design.tables import _BOUNDARY_RULE, _LAW_RULES, _MOTION_RULES, _TABLE_ANGLE_RULE
from camcad.errors import DesignError, ValueRuleError
from camcad.motion.blend import resolve_blends
from camcad.motion.laws import LAWS, make_law
from camcad.motion.segments import Boundary, SegmentKind, SegmentSpec
from camcad.motion.table import (
    FLAG_SIGMAS,
    SCATTER_MIN_POINTS,
    parse_table_text,
    smooth_table,
    table_scatter,
)

SCATTER_PER_NOISE = 1.5  # a long table scattering more than this × its stated noise is refused (at 2.2× a
# 36 000-row table ran past 120 s; at 1.46×, 7 s)

_MOTION_KEYS = ("kind", "angle", "lift", "law")


def _segment(
    index: int,
    table: Any,
    *,
    omega: float = 0.0,
    folder: Path | None = None,
    confine_to: Path | None = None,
) -> SegmentSpec:
    """One ``[[motion]]`` table.

    ``omega`` [rad/s] turns a ``velocity`` into a lift; ``folder`` is where a table's file is looked for,
    ``confine_to`` a folder it must stay inside (see :func:`read_table_file`).
    """
    path = f"motion[{index}]"
    if not isinstance(table, Mapping):
        raise DesignError(path, f"expected a table, got {_show(table)}")
    kind_value = table.get("kind")
    if kind_value is None:
        raise DesignError(f"{path}.kind", "is required (allowed: rise, return, dwell, table)")
    kind = _convert(f"{path}.kind", _MOTION_RULES["kind"], kind_value)
    if "law" in table:
        _convert(f"{path}.law", _MOTION_RULES["law"], table["law"])
    if kind is SegmentKind.TABLE or table.get("law") == "table":
        return _table_segment(path, kind, table, folder, confine_to)
    if "angle" not in table:
        raise DesignError(
            f"{path}.angle",
            f"is required (degrees of cam rotation, {MIN_SEGMENT_DEG:g} to {FULL_TURN_DEG:g})",
        )
    span = _convert(f"{path}.angle", _MOTION_RULES["angle"], table["angle"])
    if kind is SegmentKind.DWELL:
        for key in table:
            if key not in ("kind", "angle"):
                raise DesignError(f"{path}.{_key(key)}", _suggest(key, ["kind", "angle"]) + " for a dwell")
        return SegmentSpec(kind=kind, span=span * DEG)
    law_params = {k: v for k, v in table.items() if k not in (*_MOTION_KEYS, *_BLEND_KEYS)}
    lift = _segment_lift(path, kind, table, span * DEG, omega)
    law_name = table.get("law")
    if law_name is None:
        raise DesignError(f"{path}.law", f"is required for a {kind.value} (allowed: {', '.join(LAWS)})")
    if not isinstance(law_name, str):
        raise DesignError(f"{path}.law", f"expected a law name, got {_show(law_name)}")
    if law_name in LAWS:
        allowed_keys = list(_MOTION_KEYS) + [p.name for p in LAWS[law_name].parameters]
        if law_name in _ADAPTIVE_LAWS:
            allowed_keys += list(_BLEND_KEYS)
        if law_name == "constant-velocity":
            allowed_keys.append("velocity")
        for key in [*law_params, *(k for k in _BLEND_KEYS if k in table)]:
            if key in _BLEND_KEYS and key not in allowed_keys:
                raise DesignError(
                    f"{path}.{key}",
                    f"a {law_name!r} segment has its own boundary values; only law = 'polynomial' or "
                    "'inclined-sine' can meet given ones",
                )
            if key not in allowed_keys:
                raise DesignError(f"{path}.{_key(key)}", _suggest(key, allowed_keys))
        law_params.pop("velocity", None)
        for name, rule in _LAW_RULES.get(law_name, {}).items():
            if name in law_params:
                try:
                    _convert(f"{path}.{name}", rule, law_params[name])
                except ValueRuleError as err:  # a wrong type: say what the law allows too
                    if "allowed:" in err.message or rule.check is None:
                        raise
                    raise ValueRuleError(err.field, f"{err.message}; allowed: {rule.check.allowed}") from None
    try:
        law = make_law(law_name, **law_params)
    except DesignError as err:
        raise DesignError(f"{path}.{err.field}", err.message) from None
    start, end = (_boundary(f"{path}.{name}", table.get(name)) for name in _BLEND_KEYS)
    return SegmentSpec(kind=kind, span=span * DEG, lift=lift, law=law, start=start, end=end)


_BLEND_KEYS = ("start", "end")
_ADAPTIVE_LAWS = ("polynomial", "inclined-sine")
_CLOSE = "close"  # lift = "close": whatever brings the follower back to where the turn started
_TABLE_KEYS = ("kind", "angle", "law", "file", "noise")


def _segment_lift(path: str, kind: SegmentKind, table: Mapping[str, Any], span: float, omega: float) -> float:
    """The lift of a rise or return: given, ``"close"`` (NaN until summed) or from ``velocity``."""
    if "velocity" in table:
        if "lift" in table:
            raise DesignError(f"{path}.velocity", "give lift or velocity, not both")
        if table.get("law") != "constant-velocity":
            raise DesignError(f"{path}.velocity", "applies to law = 'constant-velocity' only")
        speed = _convert(f"{path}.velocity", _MOTION_RULES["velocity"], table["velocity"])
        lift = speed / omega * span  # mm/s ÷ rad/s = mm/rad, × the span in rad
        if not MIN_LENGTH_MM <= lift <= MAX_LENGTH_MM:
            raise DesignError(
                f"{path}.velocity",
                f"{speed:g} per second over {span / DEG:g}° at cam.speed_rpm gives a lift of {lift:g}; "
                f"allowed: {MIN_LENGTH_MM:g} to {MAX_LENGTH_MM:g}",
            )
        return lift
    if "lift" not in table:
        raise DesignError(
            f"{path}.lift",
            f'is required for a {kind.value} (mm, {MIN_LENGTH_MM:g} to {MAX_LENGTH_MM:g}, or "{_CLOSE}")',
        )
    if table["lift"] == _CLOSE:
        return math.nan
    return float(_convert(f"{path}.lift", _MOTION_RULES["lift"], table["lift"]))


def _boundary(path: str, value: Any) -> Boundary:
    """``start``/``end`` = {v = …, a = …, j = …}: numbers (specify) or "match" (the default)."""
    if value is None:
        return Boundary()
    if not isinstance(value, Mapping):
        example = '{ v = 0.0, a = "match" }'
        raise DesignError(path, f"expected an inline table like {example}, got {_show(value)}")
    out: dict[str, float | None] = {}
    for key, item in value.items():
        if key not in ("v", "a", "j"):
            raise DesignError(f"{path}.{_key(key)}", _suggest(key, ["v", "a", "j"]))
        if item == "match":
            out[key] = None
            continue
        if isinstance(item, str):
            raise DesignError(f"{path}.{key}", f'{_show(item)} is not allowed; give a number or "match"')
        out[key] = _convert(f"{path}.{key}", _BOUNDARY_RULE, item)
    return Boundary(**out)


def _table_segment(
    path: str, kind: SegmentKind, table: Mapping[str, Any], folder: Path | None, confine_to: Path | None
) -> SegmentSpec:
    """A point table over the whole turn: kind = "table", law = "table", file, noise."""
    if kind is not SegmentKind.TABLE:
        raise DesignError(f"{path}.kind", f"a point table is kind = 'table', not {kind.value!r}")
    for key in table:
        if key not in _TABLE_KEYS:
            raise DesignError(f"{path}.{_key(key)}", _suggest(key, list(_TABLE_KEYS)) + " for a point table")
    if table.get("law", "table") != "table":
        raise DesignError(f"{path}.law", f"{_show(table['law'])}: a kind = 'table' segment has law = 'table'")
    if "angle" in table:
        _convert(f"{path}.angle", _TABLE_ANGLE_RULE, table["angle"])
    for key in ("file", "noise"):
        if key not in table:
            what = "the CSV of angle [°], lift[, velocity]"
            what = what if key == "file" else "the measurement noise σ (mm)"
            raise DesignError(f"{path}.{key}", f"is required for a point table ({what})")
    name = _convert(f"{path}.file", _MOTION_RULES["file"], table["file"])
    noise = _convert(f"{path}.noise", _MOTION_RULES["noise"], table["noise"])
    text = read_table_file(name, folder=folder, where=f"{path}.file", confine_to=confine_to)
    angle_rad, lift, velocity = parse_table_text(text, where=f"{path}.file")
    if angle_rad.size >= SCATTER_MIN_POINTS:  # FITPACK would chase the scatter with knots for minutes
        scatter = table_scatter(angle_rad, lift)
        if scatter > SCATTER_PER_NOISE * noise:
            raise DesignError(
                f"{path}.noise",
                f"{noise:g} is far below the table's own scatter (about {scatter:.3g}, from its sixth "
                f"differences): the smoothing could not come within the stated noise; allowed: noise ≥ "
                f"{scatter / SCATTER_PER_NOISE:.3g} for this table (its measurement's σ or rounding)",
            )
    law = smooth_table(angle_rad, lift, noise=noise, velocity=velocity, source=Path(name).name)
    lowest, at = law.trough
    if lowest < -FLAG_SIGMAS * noise:  # as a return below the base circle is refused (_check_program)
        at_deg = math.degrees(at) if math.degrees(at) < FULL_TURN_DEG - 5e-4 else 0.0
        raise DesignError(
            f"{path}.file",
            f"the smoothed lift dips to {lowest:.6g} at φ = {at_deg:.3f}°, below the base circle (lift 0) by "
            f"more than the stated noise explains ({FLAG_SIGMAS:g} σ = {FLAG_SIGMAS * noise:g}); allowed: "
            "lift ≥ 0 over the whole turn (measure from the base circle)",
        )
    return SegmentSpec(kind=SegmentKind.TABLE, span=FULL_TURN_DEG * DEG, law=law)


def _finish_motion(segments: tuple[SegmentSpec, ...], *, unit: str) -> tuple[SegmentSpec, ...]:
    """A table stands alone; ``lift = "close"`` gets its value; the lift closes; blends are solved."""
    tables = [i for i, g in enumerate(segments) if g.kind is SegmentKind.TABLE]
    if tables and len(segments) > 1:
        raise DesignError(
            f"motion[{tables[0]}].kind",
            "a point table describes the whole turn: it must be the only [[motion]]",
        )
    open_ = [i for i, g in enumerate(segments) if math.isnan(g.lift)]
    if len(open_) > 1:
        raise DesignError(f"motion[{open_[1]}].lift", f'only one segment may have lift = "{_CLOSE}"')
    if open_:
        i = open_[0]
        rest = sum(g.signed_lift for k, g in enumerate(segments) if k != i)
        lift = -rest if segments[i].kind is SegmentKind.RISE else rest
        if not MIN_LENGTH_MM <= lift <= MAX_LENGTH_MM:
            raise DesignError(
                f"motion[{i}].lift",
                f'"{_CLOSE}" would need a {segments[i].kind.value} of {lift:g}{unit}; the other segments '
                f"{'rise' if rest > 0 else 'fall'} by {abs(rest):g}{unit} in total",
            )
        segments = (*segments[:i], dataclasses.replace(segments[i], lift=lift), *segments[i + 1 :])
    _check_program(segments, unit=unit)
    return resolve_blends(segments)


def _check_program(segments: tuple[SegmentSpec, ...], *, unit: str = " mm") -> None:
    """The spans total 360° and the lift closes, never going below the base circle (lift in ``unit``)."""
    if not segments:
        raise DesignError("motion", "at least one [[motion]] segment is required")
    total = sum(seg.span for seg in segments) / DEG
    if abs(total - FULL_TURN_DEG) > ANGLE_SUM_TOL_DEG * FULL_TURN_DEG:
        spans = " + ".join(f"{seg.span / DEG:g}" for seg in segments)
        raise DesignError("motion", f"segment angles must total 360°, got {spans} = {total:g}°")
    s = 0.0
    for i, seg in enumerate(segments):
        if seg.kind is SegmentKind.RISE:
            s += seg.lift
            if s > MAX_LENGTH_MM:
                raise DesignError(
                    f"motion[{i}].lift",
                    f"{seg.lift:g}{unit} takes the follower {s:g}{unit} above the base circle; "
                    f"allowed: a total lift of at most {MAX_LENGTH_MM:g} mm",
                )
        elif seg.kind is SegmentKind.RETURN:
            s -= seg.lift
            if s < -LIFT_CLOSE_TOL_MM:
                raise DesignError(
                    f"motion[{i}].lift",
                    f"return of {seg.lift:g}{unit} takes the follower {-s:g}{unit} below the base circle",
                )
    if abs(s) > LIFT_CLOSE_TOL_MM:
        rises = sum(g.lift for g in segments if g.kind is SegmentKind.RISE)
        raise DesignError(
            "motion",
            f"the lift does not close: total rise {rises:g}{unit} but total return {rises - s:g}{unit}",
        )
