"""The design space: which design-file keys vary, over what values, and the designs they give.

A variable names a key of the design file by its field path, the path the
schema's errors use (``cam.base_radius``, ``follower.offset``,
``dynamics.spring_rate``, ``motion[0].law``, ``motion[2].b``), or by a short
name (``base_radius``, ``offset``, ``spring_rate``, ``law``, ``law.b``, …; see
:data:`ALIASES`). ``motion[*].key`` (and ``law``, ``law.key``) set the key on
every rise and return. Values are in the design file's units (mm, degrees,
rpm, N, N/mm, MPa).

A variant is the design's TOML mapping with the variables' values written in,
validated again by :func:`camcad.design.parse_design`: every variant obeys
the same rules as a design file, its errors name the field, and the result of
an optimization can be written back as a design file
(:func:`camcad.design.toml_text.toml_text`).

Value syntax (``--grid`` and ``--vary``): ``name=start:stop:count`` (a grid of
``count`` equally spaced values, both ends included), ``name=low:high`` (a
continuous range: optimization, Latin-hypercube sampling) or
``name=a,b,c`` (discrete choices, tried one by one).
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from camcad._typing import tree_copy
from camcad.design import Design, parse_design
from camcad.errors import DesignError, UsageError
from camcad.motion.laws import LAWS

__all__ = [
    "ALIASES",
    "MAX_CHOICES",
    "MAX_POINTS",
    "MAX_SEED",
    "Variable",
    "apply_values",
    "check_distinct",
    "check_seed",
    "design_with",
    "grid_points",
    "lhs_points",
    "parse_variable",
]

ALIASES: dict[str, str] = {
    "base_radius": "cam.base_radius",
    "speed_rpm": "cam.speed_rpm",
    "thickness": "cam.thickness",
    "offset": "follower.offset",
    "roller_radius": "follower.roller_radius",
    "face_width": "follower.face_width",
    "pivot_distance": "follower.pivot_distance",
    "arm_length": "follower.arm_length",
    "spring_rate": "dynamics.spring_rate",
    "spring_preload": "dynamics.spring_preload",
    "contact_width": "dynamics.contact_width",
    "follower_mass": "dynamics.follower_mass",
    "law": "motion[*].law",
}
"""Short names for the keys most often varied; ``law.X`` means ``motion[*].X``."""

MAX_POINTS = 10_000_000
"""Most designs one sweep may list (a grid's product or ``--samples``)."""

MAX_CHOICES = 1000
"""Most choices one variable may list (``name=a,b,…``); more values are a range ``start:stop:count``."""

MAX_SEED = 2**32 - 1
"""Largest Latin-hypercube seed (``--seed``: 0 to 2³² − 1, what NumPy's seeding takes as one word)."""

_PATH = re.compile(r"^(?P<table>[a-z_]+)(?:\[(?P<index>\d+|\*)\])?\.(?P<key>[A-Za-z0-9_-]+)$")
_MOVING = ("rise", "return")


@dataclass(frozen=True, slots=True, kw_only=True)
class Variable:
    """One design-file key that varies.

    ``name`` is as the user wrote it (the column name of a sweep's table);
    ``path`` the field path it stands for (``motion[*].b`` for ``law.b``).
    Exactly one of ``choices`` (discrete values) and ``low``/``high`` (a
    range, in the design file's units) is set; ``count`` is the number of
    grid values of a range (None: continuous).
    """

    name: str
    path: str
    low: float | None = None
    high: float | None = None
    count: int | None = None
    choices: tuple[Any, ...] | None = None

    @property
    def continuous(self) -> bool:
        """A range (as opposed to a list of choices)."""
        return self.choices is None

    def grid(self) -> tuple[Any, ...]:
        """The values a grid sweep takes: the choices, or ``count`` equally spaced values."""
        if self.choices is not None:
            return self.choices
        assert self.low is not None and self.high is not None and self.count is not None
        return tuple(float(v) for v in np.linspace(self.low, self.high, self.count))

    def spec(self) -> str:
        """The value text as it would be written back (``30:80:51``, ``a,b``)."""
        if self.choices is not None:
            return ",".join(str(c) for c in self.choices)
        tail = "" if self.count is None else f":{self.count}"
        return f"{self.low!r}:{self.high!r}{tail}"


def _resolve(name: str, data: Mapping[str, Any], flag: str) -> str:
    """The field path a variable name stands for (aliases, ``law.X``, bare keys found in the file)."""
    if name in ALIASES:
        return ALIASES[name]
    if name.startswith("law.") and name.count(".") == 1:
        return f"motion[*].{name[4:]}"
    if _PATH.match(name):
        return name
    holders = [t for t, table in data.items() if isinstance(table, Mapping) and name in table]
    if len(holders) == 1:
        return f"{holders[0]}.{name}"
    examples = "cam.base_radius, follower.offset, motion[0].law, motion[*].b, or a short name: " + ", ".join(
        ALIASES
    )
    where = f"it is in {', '.join(holders)}; say which" if holders else "no such key in the design file"
    raise UsageError(flag, f"{name!r}: {where} (use a field path such as {examples})")


def _targets(path: str, data: Mapping[str, Any], flag: str, name: str) -> list[tuple[str, int | None, str]]:
    """The concrete (table, segment index or None, key) places a field path writes."""
    match = _PATH.match(path)
    if match is None:  # pragma: no cover - _resolve only returns matching paths
        raise UsageError(flag, f"{name!r} is not a field path")
    table, index, key = match["table"], match["index"], match["key"]
    if table != "motion":
        if index is not None:
            raise UsageError(flag, f"{name!r}: only [[motion]] is a list of tables; use {table}.{key}")
        return [(table, None, key)]
    segments = data.get("motion")
    if not isinstance(segments, list) or not segments:
        raise UsageError(flag, f"{name!r}: the design has no [[motion]] segments")
    if index is None:
        raise UsageError(flag, f"{name!r}: say which segment, motion[0].{key} … or motion[*].{key}")
    if index == "*":
        found = [
            i for i, seg in enumerate(segments) if isinstance(seg, Mapping) and seg.get("kind") in _MOVING
        ]
        if not found:
            raise UsageError(flag, f"{name!r}: the design has no rise or return")
        return [("motion", i, key) for i in found]
    i = int(index)
    if i >= len(segments):
        raise UsageError(
            flag, f"{name!r}: motion[{i}] does not exist (the design has {len(segments)} segments)"
        )
    return [("motion", i, key)]


def _token(text: str) -> Any:
    """A choice as TOML would read it: true/false, an integer, a number, else the text."""
    t = text.strip()
    if t in ("true", "false"):
        return t == "true"
    if re.fullmatch(r"[+-]?\d+", t):
        return int(t)
    try:
        value = float(t)
    except ValueError:
        return t
    return value if math.isfinite(value) else t


def _number(text: str, flag: str, spec: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise UsageError(flag, f"{spec!r}: {text!r} is not a number (write name=start:stop:count)") from None
    if not math.isfinite(value):
        raise UsageError(flag, f"{spec!r}: {text!r} is not a finite number")
    return value


def parse_variable(
    text: str, data: Mapping[str, Any], *, flag: str, counted: bool, source: str = ""
) -> Variable:
    """Read ``name=start:stop:count``, ``name=low:high`` or ``name=a,b,c`` against a design's mapping.

    Parameters
    ----------
    text
        The option's value.
    data
        The design file's TOML mapping (to resolve the name and check the values).
    flag
        The option, named by every error (``--grid``, ``--vary``).
    counted
        True: a range must carry a count (a grid sweep); False: a range is
        continuous and a count is refused (optimization, Latin-hypercube
        sampling).
    source
        The design file's name, for the validated designs.

    Raises
    ------
    UsageError
        Naming ``flag`` and the text: no ``=``, an unknown key, a range whose
        ends the design file does not allow (e.g. a negative base radius), a
        count below 2, an unknown law among the choices.
    """
    name, sep, spec = (part.strip() for part in text.partition("="))
    if not sep or not name or not spec:
        raise UsageError(flag, f"{text!r}: write name=start:stop:count, name=low:high or name=a,b,c")
    path = _resolve(name, data, flag)
    targets = _targets(path, data, flag, name)
    if ":" in spec:
        parts = spec.split(":")
        if len(parts) not in (2, 3):
            raise UsageError(flag, f"{text!r}: a range is start:stop or start:stop:count")
        low, high = (_number(p, flag, text) for p in parts[:2])
        count: int | None = None
        if len(parts) == 3:
            if not counted:
                raise UsageError(
                    flag, f"{text!r}: a count applies to a grid (write {name}={parts[0]}:{parts[1]})"
                )
            if not re.fullmatch(r"\d+", parts[2].strip()) or int(parts[2]) < 1:
                raise UsageError(flag, f"{text!r}: the count must be a whole number ≥ 1")
            count = int(parts[2])
            if count > MAX_POINTS:
                raise UsageError(flag, f"{text!r}: at most {MAX_POINTS} values")
            if count == 1 and low != high:
                raise UsageError(flag, f"{text!r}: one value needs start = stop")
        elif counted:
            raise UsageError(flag, f"{text!r}: a grid needs a count, e.g. {name}={spec}:11")
        if high < low or (count != 1 and high == low):
            raise UsageError(flag, f"{text!r}: start must be below stop")
        variable = Variable(name=name, path=path, low=low, high=high, count=count)
        trials: tuple[Any, ...] = (low, high)
    else:
        listed = spec.count(",") + 1
        if listed > MAX_CHOICES:
            raise UsageError(
                flag,
                f"{name}: {listed} choices; allowed: at most {MAX_CHOICES} (for more values use a range, "
                f"{name}=start:stop:count)",
            )
        choices = tuple(_token(c) for c in spec.split(",") if c.strip())
        if not choices:
            raise UsageError(flag, f"{text!r}: list at least one value")
        if len(set(map(repr, choices))) != len(choices):
            raise UsageError(flag, f"{text!r}: a value is listed twice")
        variable = Variable(name=name, path=path, choices=choices)
        trials = choices
    for value in trials:
        _check_value(data, variable, value, targets, flag=flag, text=text, source=source)
    return variable


def _check_value(
    data: Mapping[str, Any],
    variable: Variable,
    value: Any,
    targets: Sequence[tuple[str, int | None, str]],
    *,
    flag: str,
    text: str,
    source: str,
) -> None:
    """The design file's rule for the key accepts ``value`` (an error on another field is the design's)."""
    places = {f"{t}[{i}].{k}" if i is not None else f"{t}.{k}" for t, i, k in targets}
    if variable.path.endswith(".law"):  # a law's missing or unknown parameter is the choice's fault too
        places |= {
            f"motion[{i}].{p.name}" for _, i, _ in targets for law in LAWS.values() for p in law.parameters
        }
    try:
        design_with(data, [variable], (value,), source=source)
    except DesignError as err:
        # the key's own rule speaks of the value first ("-5.0 must be > 0 …"), or of the key or its type;
        # a check across fields (an offset beyond r_b + r_f at the file's r_b) may pass at other grid
        # values of the other variables, so it is the design's, found row by row
        own = err.message.startswith((repr(value), "unknown key", "expected", "applies to"))
        if err.field in places and (own or variable.path.endswith(".law")):
            raise UsageError(flag, f"{text!r}: {err}") from None


def apply_values(
    data: Mapping[str, Any], variables: Sequence[Variable], values: Sequence[Any]
) -> dict[str, Any]:
    """A deep copy of the design mapping with each variable's value written in.

    Setting a law keeps the segment's parameters that the new law takes and
    drops the others (a VAP's ``b`` on a change to cycloidal).
    """
    out: dict[str, Any] = tree_copy(dict(data))
    for variable, value in zip(variables, values, strict=True):
        for table, index, key in _targets(variable.path, out, "--vary", variable.name):
            if index is None:
                holder = out.setdefault(table, {})
            else:
                holder = out["motion"][index]
            holder[key] = value
            if table == "motion" and key == "law" and isinstance(value, str) and value in LAWS:
                allowed = {"kind", "angle", "lift", "law", *(p.name for p in LAWS[value].parameters)}
                for extra in [k for k in holder if k not in allowed]:
                    del holder[extra]
    return out


def design_with(
    data: Mapping[str, Any], variables: Sequence[Variable], values: Sequence[Any], *, source: str = ""
) -> Design:
    """The validated design with the variables set (raises DesignError naming the field)."""
    return parse_design(apply_values(data, variables, values), source=source)


def check_distinct(variables: Sequence[Variable], data: Mapping[str, Any], *, flag: str) -> None:
    """Raise UsageError naming ``flag`` when two variables set the same key of the design.

    ``base_radius`` twice, ``base_radius`` and ``cam.base_radius``, or
    ``law`` and ``motion[0].law`` (``law`` sets every rise and return): the
    later would silently overwrite the earlier.
    """
    seen: dict[tuple[str, int | None, str], str] = {}
    for v in variables:
        for place in _targets(v.path, data, flag, v.name):
            if place in seen:
                table, index, key = place
                where = f"{table}[{index}].{key}" if index is not None else f"{table}.{key}"
                both = v.name if seen[place] == v.name else f"{seen[place]} and {v.name}"
                raise UsageError(flag, f"{both}: the key {where} is given twice (give each key once)")
        for place in _targets(v.path, data, flag, v.name):
            seen[place] = v.name


def grid_points(variables: Sequence[Variable]) -> list[tuple[Any, ...]]:
    """Every combination of the variables' grid values, the last variable varying fastest."""
    total = math.prod(len(v.grid()) for v in variables)
    if total > MAX_POINTS:
        raise UsageError("--grid", f"{total} designs; allowed: at most {MAX_POINTS} in one sweep")
    return list(itertools.product(*(v.grid() for v in variables)))


def check_seed(seed: int) -> None:
    """Raise UsageError naming ``--seed`` unless 0 ≤ ``seed`` ≤ :data:`MAX_SEED`."""
    if not 0 <= seed <= MAX_SEED:
        raise UsageError("--seed", f"{seed} is not allowed (allowed: 0 to {MAX_SEED})")


def lhs_points(variables: Sequence[Variable], samples: int, *, seed: int) -> list[tuple[Any, ...]]:
    """``samples`` designs by Latin-hypercube sampling (scipy's ``qmc.LatinHypercube``), reproducible by seed.

    Each range is split into ``samples`` equal strata, each stratum used once;
    a list of choices is sampled the same way over its indices.
    """
    if not 1 <= samples <= MAX_POINTS:
        raise UsageError("--samples", f"{samples} is not allowed (allowed: 1 to {MAX_POINTS})")
    check_seed(seed)
    from scipy.stats import qmc

    unit = qmc.LatinHypercube(d=len(variables), rng=np.random.default_rng(seed)).random(samples)
    points: list[tuple[Any, ...]] = []
    for row in unit:
        values: list[Any] = []
        for u, v in zip(row, variables, strict=True):
            if v.choices is not None:
                values.append(v.choices[min(int(u * len(v.choices)), len(v.choices) - 1)])
            else:
                assert v.low is not None and v.high is not None
                values.append(float(v.low + u * (v.high - v.low)))
        points.append(tuple(values))
    return points
