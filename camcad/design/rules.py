"""The loader's rule machinery: a key's rule, its check, the converters and the bounds.

A :class:`_Rule` says how one TOML value is converted (its kind, scale and
enum) and checked (a :class:`_Check`: the test and the same rule as JSON
Schema keywords). Every number has a bounded range, so that a design that
validates also analyses and builds in seconds: physical sizes up to a 10 m
part (``MAX_LENGTH_MM``), speeds up to 10⁵ rpm, and resolution settings no
finer than the outputs can use.
"""

from __future__ import annotations

import difflib
import enum
import functools
import math
import numbers
import re
import reprlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from camcad.errors import ValueRuleError

FULL_TURN_DEG = 360.0
ANGLE_SUM_TOL_DEG = 1e-9
LIFT_CLOSE_TOL_MM = 1e-9

# ---------------------------------------------------------------------------
# schema: one rule per key; the rule converts and checks the TOML value


@dataclass(frozen=True, slots=True)
class _Rule:
    kind: str  # "float", "int", "bool", "str", "enum", "strlist"
    required: bool = False
    check: _Check | None = None
    scale: float = 1.0  # multiply floats by this (degrees -> rad)
    enum: type[enum.Enum] | None = None
    attr: str | None = None  # dataclass attribute name when it differs from the key


# Bounds on every number the schema accepts. Physical sizes are capped at a
# 10 m part; resolution settings at what the output can use, so that no valid
# design allocates gigabytes or runs for minutes.
MAX_LENGTH_MM = 10_000.0  # 10 m: larger than any disc cam a machine can cut
MIN_LENGTH_MM = 1e-3  # 1 µm: the outputs write 3-4 decimals of a millimetre
MIN_BASE_RADIUS_MM = 0.1  # the smallest cam whose outline the default tolerances can still follow
TOLERANCE_PER_BASE_RADIUS = 0.1  # every tolerance must be below this share of the base radius
MAX_SPEED_RPM = 1e5
MAX_FEED_MM_MIN = 1e5  # 100 m/min
MIN_SAMPLE_STEP_DEG = 0.005  # [cam].sample_step_deg: at most 72 000 samples per turn
MIN_TABLE_STEP_DEG = 0.01  # [tables].step_deg: at most 36 000 rows per table
MIN_CHORD_TOL_MM = 1e-4  # 0.1 µm: finer than the 4-decimal output of DXF and mesh files
MAX_TOLERANCE_MM = 10.0
MIN_GCODE_TOL_MM = 5e-4  # what 4-decimal G-code coordinates can hold
MIN_FIT_TOL_MM = 1e-6  # a fit finer than this only chases rounding (1e-10 of a 10 m cam)
MIN_SEGMENT_DEG = 0.01
MAX_SEGMENTS = 360
MAX_TABS = 100
MAX_PASSES = 1000  # depth levels: (thickness + breakthrough) / step_down
MAX_HELIX_TURNS = 100_000  # bore helix: one G2/G3 block per turn
BORE_HELIX_MIN_PITCH = 0.1  # × tool diameter, the finest helix pitch the bore milling uses
MAX_TOOL_NUMBER = 99_999
MAX_NAME_CHARS = 200
MAX_FORCE_N = 1e7
MAX_MASS_KG = 1e4
MAX_MODULUS_MPA = 1e7  # above diamond (1.2e6 MPa)
MIN_MODULUS_MPA = 1e-3


def _show(value: Any) -> str:
    """A user value for a one-line message: short, no raw newline, no huge number written out."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 64:
        return f"an integer of about {int(value.bit_length() * math.log10(2)) + 1} digits"
    return _REPR.repr(value)


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxstring, _REPR.maxother, _REPR.maxlist, _REPR.maxdict = 2, 60, 60, 6, 6


@dataclass(frozen=True, slots=True)
class _Check:
    """A key's own rule: the loader's test and the same rule as JSON Schema keywords.

    ``test`` returns why a value is refused (None: allowed); ``schema`` holds
    the JSON Schema keywords that state the same set of values, so that
    ``camcad schema`` is generated from this table and cannot drift from it.
    """

    test: Callable[[Any], str | None]
    schema: Mapping[str, Any]
    allowed: str = ""

    def __call__(self, value: Any) -> str | None:
        """Why ``value`` is refused, or None."""
        return self.test(value)


def _between(lo: float, hi: float, unit: str = "", *, zero: bool = False, lo_open: bool = False) -> _Check:
    """Check ``lo ≤ v ≤ hi`` (``lo < v`` when ``lo_open``; also ``v == 0`` when ``zero``)."""
    low = f"> {lo:g}" if lo_open else f"≥ {lo:g}"
    span = f"over {lo:g} up to {hi:g}" if lo_open else f"{lo:g} to {hi:g}"
    allowed = f"{'0, or ' if zero else ''}{span}{unit}"

    def check(v: float) -> str | None:
        if (zero and v == 0) or ((v > lo if lo_open else v >= lo) and v <= hi):
            return None
        if v > hi:
            head = f"must be ≤ {hi:g}"
        elif v <= 0 and (lo > 0 or lo_open) and not zero:
            head = "must be > 0"
        elif v < 0:
            head = "must be ≥ 0"
        else:
            head = f"must be {low}"
        return f"{head} (allowed: {allowed})"

    bounds: dict[str, Any] = {"exclusiveMinimum" if lo_open else "minimum": lo, "maximum": hi}
    schema: dict[str, Any] = {"anyOf": [{"const": 0}, bounds]} if zero else bounds
    return _Check(check, schema, allowed)


def _interval(lo: float, hi: float, unit: str = "", *, lo_open: bool, hi_open: bool, why: str = "") -> _Check:
    """Check v in the interval from ``lo`` to ``hi``, each end open or closed: "must be in [lo, hi) unit"."""
    text = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"

    def check(v: float) -> str | None:
        above = v > lo if lo_open else v >= lo
        below = v < hi if hi_open else v <= hi
        return None if above and below else f"must be in {text}{unit}{why}"

    schema = {
        "exclusiveMinimum" if lo_open else "minimum": lo,
        "exclusiveMaximum" if hi_open else "maximum": hi,
    }
    return _Check(check, schema, f"{text}{unit}")


def _below(limit: float, unit: str, *, low: float = 0.0, why: str = "") -> _Check:
    """``low ≤ v < limit`` when ``low``, else ``0 < v < limit``: "must be in [low, limit) unit"."""
    return _interval(low, limit, f" {unit}", lo_open=not low, hi_open=True, why=why)


def _count(lo: int, hi: int, why: str) -> _Check:
    def check(v: int) -> str | None:
        return None if lo <= v <= hi else f"must be {lo} to {hi} ({why})"

    return _Check(check, {"minimum": lo, "maximum": hi}, f"{lo} to {hi} ({why})")


def _any_case(words: tuple[str, ...]) -> str:
    """A JSON Schema (ECMA 262) pattern for ``words`` in any letter case (the loader lowercases them)."""
    alts = ["".join(f"[{c.lower()}{c.upper()}]" if c.isalpha() else re.escape(c) for c in w) for w in words]
    return f"^(?:{'|'.join(alts)})$"


def _odd(lo: int, hi: int) -> _Check:
    allowed = f"an odd integer {lo} to {hi}"

    def check(v: int) -> str | None:
        return None if lo <= v <= hi and v % 2 == 1 else f"must be {allowed}"

    return _Check(check, {"minimum": lo, "maximum": hi, "not": {"multipleOf": 2}}, allowed)


_BARE_KEY = re.compile(r"[A-Za-z0-9_-]{1,60}")


def _key(key: object) -> str:
    """A TOML key as it may appear in a field path: bare if it is a plain word, else quoted."""
    if isinstance(key, str) and _BARE_KEY.fullmatch(key):
        return key
    return _show(key)


def _suggest(key: object, allowed: list[str]) -> str:
    close = difflib.get_close_matches(key[:100] if isinstance(key, str) else "", allowed, n=1, cutoff=0.6)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return f"unknown key {_show(key)}{hint} (allowed: {', '.join(allowed)})"


def _to_float(path: str, rule: _Rule, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueRuleError(path, f"expected a number, got {_show(value)}")
    try:
        out = float(value)
    except OverflowError:
        out = math.inf
    if not math.isfinite(out):
        raise ValueRuleError(path, f"expected a finite number, got {_show(value)}")
    return out


def _to_int(path: str, rule: _Rule, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueRuleError(path, f"expected a whole number, got {_show(value)}")
    return int(value)


def _to_bool(path: str, rule: _Rule, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ValueRuleError(path, f"expected true or false, got {_show(value)}")
    return value


def _to_str(path: str, rule: _Rule, value: Any) -> str:
    if not isinstance(value, str):
        raise ValueRuleError(path, f"expected a string, got {_show(value)}")
    return value


def _to_strlist(path: str, rule: _Rule, value: Any) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ValueRuleError(path, f"expected a list of strings, got {_show(value)}")
    return tuple(v.lower() for v in value)


def _to_floatlist(path: str, rule: _Rule, value: Any) -> tuple[float, ...]:
    if not isinstance(value, list):
        raise ValueRuleError(path, f"expected a list of numbers, got {_show(value)}")
    return tuple(_to_float(f"{path}[{i}]", rule, v) for i, v in enumerate(value))


@functools.cache
def _enum_values(kind: type[enum.Enum]) -> tuple[Any, ...]:
    """The values of an enum's members, in order (listed once per enum: a sweep parses many designs)."""
    return tuple(m.value for m in kind)


def _to_enum(path: str, rule: _Rule, value: Any) -> enum.Enum:
    assert rule.enum is not None
    allowed = _enum_values(rule.enum)
    if not isinstance(value, str) or value not in allowed:
        word = value[:100] if isinstance(value, str) else ""
        close = difflib.get_close_matches(word, allowed, n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ValueRuleError(path, f"{_show(value)} is not allowed{hint} (allowed: {', '.join(allowed)})")
    return rule.enum(value)


_CONVERTERS: dict[str, Callable[[str, _Rule, Any], Any]] = {
    "float": _to_float,
    "int": _to_int,
    "bool": _to_bool,
    "str": _to_str,
    "strlist": _to_strlist,
    "floatlist": _to_floatlist,
    "enum": _to_enum,
}


def _convert(path: str, rule: _Rule, value: Any) -> Any:
    """Convert one TOML value by its rule, check it, and scale it; or raise DesignError naming the path."""
    out = _CONVERTERS[rule.kind](path, rule, value)
    if rule.check is not None:
        problem = rule.check(out)
        if problem:
            raise ValueRuleError(path, f"{_show(value)} {problem}")
    if rule.kind == "floatlist":
        out = tuple(v * rule.scale for v in out)
    if rule.kind == "float":
        out *= rule.scale
    return out
