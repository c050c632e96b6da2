"""The design file's schema: one rule per key, validation with field paths, and loading.

A design is a TOML file with the tables ``[cam]``, ``[follower]``,
``[[motion]]``, ``[dynamics]``, ``[fit]``, ``[dxf]``, ``[mesh]``, ``[tables]``
and ``[gcode]``. :func:`load_design` turns it into a frozen :class:`Design`
or raises :class:`~camcad.errors.DesignError` naming the field path
(``motion[2].angle``), the value and what is allowed.

Units at this edge: lengths mm, angles degrees, speed rpm, mass kg, force N,
torque N·mm, stress and moduli MPa. Inside the specs angles are radians; the
attribute docstrings say which.

Every number has a bounded range, so that a design that validates also
analyses and builds in seconds: physical sizes up to a 10 m part
(``MAX_LENGTH_MM``), speeds up to 10⁵ rpm, and resolution settings (sample
and table steps, chord and fit tolerances, passes, tabs, helix turns) no finer
than the outputs can use. Every text the user gives is sanitised where it is
written (G-code comments, DXF text, HTML, plot labels), not here.
"""

from __future__ import annotations

import dataclasses
import difflib
import enum
import math
import numbers
import re
import reprlib
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad.design.spec import DEG, CamSpec, Design, Dialect, Direction, GcodeSpec
from camcad.design.table_file import read_table_file
from camcad.dynamics.drive import DriveMode, DriveSpec
from camcad.dynamics.film import LubricationSpec
from camcad.dynamics.life import ROLLER_EXPONENT, LifeSpec, LoadStressLine
from camcad.dynamics.spec import DynamicsModel, DynamicsSpec
from camcad.dynamics.vibration.spec import TrainModel, VibrationSpec
from camcad.errors import DesignError, ValueRuleError
from camcad.export.spec import DriveLayout, DxfSpec, MeshSpec, TablesSpec
from camcad.fea.spec import FeaSpec, PlaneModel
from camcad.fit.spec import FitSpec
from camcad.geometry.barrel import RollerShape
from camcad.geometry.cam import Cam
from camcad.geometry.families import FAMILIES, BarrelSpec, family_of
from camcad.geometry.followers import (
    DEFAULT_FOLLOWER,
    FOLLOWER_TYPES,
    FollowerKey,
    FollowerType,
    follower_keys,
)
from camcad.geometry.followers.base import KeyRange
from camcad.geometry.sensitivity import Tol
from camcad.geometry.spec import CamStyle, ConjugateSpec, FollowerSpec, GrooveSpec, Rotation
from camcad.motion._blendlaws import MAX_POLYNOMIAL_DEGREE
from camcad.motion.blend import resolve_blends
from camcad.motion.laws import DUDLEY_MAX_DEGREE, LAWS, make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import Boundary, SegmentKind, SegmentSpec
from camcad.motion.table import (
    FLAG_SIGMAS,
    SCATTER_MIN_POINTS,
    parse_table_text,
    smooth_table,
    table_scatter,
)
from camcad.toolpath.spec import Cutter, Machine, RotaryAxis

if TYPE_CHECKING:
    from camcad.inspect.spec import ToleranceSpec

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["load_design", "parse_design", "parse_tolerance"]

FULL_TURN_DEG = 360.0
ANGLE_SUM_TOL_DEG = 1e-9
LIFT_CLOSE_TOL_MM = 1e-9
SCATTER_PER_NOISE = 1.5  # a long table scattering more than this × its stated noise is refused (at 2.2× a
# 36 000-row table ran past 120 s; at 1.46×, 7 s)

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


_length = _between(MIN_LENGTH_MM, MAX_LENGTH_MM, " mm")
_length_or_zero = _between(MIN_LENGTH_MM, MAX_LENGTH_MM, " mm", zero=True)
_force = _between(0.0, MAX_FORCE_N, " N")
_feed = _between(1.0, MAX_FEED_MM_MIN, " mm/min")  # F is written with 3 decimals; F0 is an error
_chord_tolerance = _between(MIN_CHORD_TOL_MM, MAX_TOLERANCE_MM, " mm")
_segment_angle = _between(MIN_SEGMENT_DEG, FULL_TURN_DEG + ANGLE_SUM_TOL_DEG, " degrees")
_modulus = _between(MIN_MODULUS_MPA, MAX_MODULUS_MPA, " MPa")


def _name_test(v: str) -> str | None:
    if len(v) > MAX_NAME_CHARS:
        return f"is longer than {MAX_NAME_CHARS} characters"
    try:
        v.encode("utf-8")
    except UnicodeEncodeError:
        return "is not valid Unicode text (a lone surrogate cannot be written to any file)"
    return None


_name = _Check(_name_test, {"maxLength": MAX_NAME_CHARS}, f"at most {MAX_NAME_CHARS} characters")
_fraction = _interval(0.0, 1.0, lo_open=False, hi_open=True)
_poisson = _interval(0.0, 0.5, lo_open=False, hi_open=True)


def _below(limit: float, unit: str, *, low: float = 0.0, why: str = "") -> _Check:
    """``low ≤ v < limit`` when ``low``, else ``0 < v < limit``: "must be in [low, limit) unit"."""
    return _interval(low, limit, f" {unit}", lo_open=not low, hi_open=True, why=why)


def _count(lo: int, hi: int, why: str) -> _Check:
    def check(v: int) -> str | None:
        return None if lo <= v <= hi else f"must be {lo} to {hi} ({why})"

    return _Check(check, {"minimum": lo, "maximum": hi}, f"{lo} to {hi} ({why})")


_sample_step = _below(
    10.0,
    "degrees",
    low=MIN_SAMPLE_STEP_DEG,
    why=f" (at most {FULL_TURN_DEG / MIN_SAMPLE_STEP_DEG:.0f} samples per turn)",
)
_table_step = _below(
    90.0,
    "degrees",
    low=MIN_TABLE_STEP_DEG,
    why=f" (at most {FULL_TURN_DEG / MIN_TABLE_STEP_DEG:.0f} rows per table)",
)


MAX_FEA_ANGLES = 36  # [fea].angles: one FE solve each


def _fea_angles_test(v: tuple[float, ...]) -> str | None:
    if len(v) > MAX_FEA_ANGLES:
        return f"lists {len(v)} angles; allowed: at most {MAX_FEA_ANGLES} (one FE solve each)"
    bad = [a for a in v if not 0.0 <= a <= FULL_TURN_DEG]
    return f"has {bad[0]:g}; allowed: cam angles 0 to 360 degrees" if bad else None


def _life_exponent_test(v: float) -> str | None:
    """ISO 281: p = 3 (ball) or 10/3 (needle and roller; 3.333 in a file is read as 10/3)."""
    if v == 3.0 or ROLLER_EXPONENT - 1e-3 < v < ROLLER_EXPONENT + 1e-3:  # the schema's bounds, exactly
        return None
    return "must be 3 (ball bearing) or 10/3 ≈ 3.333 (needle or roller bearing, ISO 281)"


_life_exponent = _Check(
    _life_exponent_test,
    {
        "anyOf": [
            {"const": 3},
            {"exclusiveMinimum": ROLLER_EXPONENT - 1e-3, "exclusiveMaximum": ROLLER_EXPONENT + 1e-3},
        ]
    },
    "3 (ball bearing) or 10/3 ≈ 3.333 (needle or roller bearing, ISO 281)",
)


_fea_angles = _Check(
    _fea_angles_test,
    {"maxItems": MAX_FEA_ANGLES, "items": {"type": "number", "minimum": 0.0, "maximum": FULL_TURN_DEG}},
    f"at most {MAX_FEA_ANGLES} cam angles, 0 to 360 degrees",
)

_MESH_FORMATS = ("stl", "obj", "ply", "off", "3mf", "vtu")


def _mesh_formats_test(v: list[str]) -> str | None:
    bad = [f for f in v if f not in _MESH_FORMATS]
    if bad:
        return f"unknown format {bad[0]!r}; allowed: {', '.join(_MESH_FORMATS)}"
    if not v:
        return "must list at least one format"
    return None


def _any_case(words: tuple[str, ...]) -> str:
    """A JSON Schema (ECMA 262) pattern for ``words`` in any letter case (the loader lowercases them)."""
    alts = ["".join(f"[{c.lower()}{c.upper()}]" if c.isalpha() else re.escape(c) for c in w) for w in words]
    return f"^(?:{'|'.join(alts)})$"


_mesh_formats = _Check(
    _mesh_formats_test,
    {"minItems": 1, "items": {"type": "string", "pattern": _any_case(_MESH_FORMATS)}},
    f"one or more of {', '.join(_MESH_FORMATS)}",
)


_FollowerWord = enum.Enum("_FollowerWord", [(w, w) for w in FOLLOWER_TYPES])  # type: ignore[misc]
"""The follower types of the registry, as the words the ``type`` rule allows."""


def _follower_rule(key: FollowerKey) -> _Rule:
    """The loader's rule of a key a follower module declares (its range, in the loader's bounds)."""
    unit = f" {key.unit}"
    check = {
        KeyRange.LENGTH: _between(MIN_LENGTH_MM, MAX_LENGTH_MM, unit),
        KeyRange.LENGTH_OR_ZERO: _between(MIN_LENGTH_MM, MAX_LENGTH_MM, unit, zero=True),
        KeyRange.NONNEGATIVE: _between(0.0, MAX_LENGTH_MM, unit),
        KeyRange.SIGNED: _between(-MAX_LENGTH_MM, MAX_LENGTH_MM, unit),
    }[key.range]
    return _Rule("float", check=check, attr=key.attr)


def _follower_spec(**values: Any) -> FollowerSpec:
    """The ``[follower]`` table's spec: its kind from the registry, a kind's own keys in ``params``."""
    word = values.pop("kind", None)
    kind = DEFAULT_FOLLOWER if word is None else FOLLOWER_TYPES[word.value]
    attrs = {f.name for f in dataclasses.fields(FollowerSpec)}
    params = tuple(sorted((k, v) for k, v in values.items() if k not in attrs))
    return FollowerSpec(kind=kind, params=params, **{k: v for k, v in values.items() if k in attrs})


# [tolerance] (issue 38, ``camcad tolerance``): each toleranced quantity as ±t (``<q>_pm``, uniform
# over ±t) or one standard deviation (``<q>_sigma``, normal); the design-file name → camcad's Tol
_TOLERANCED: dict[str, Tol] = {
    "form": Tol.FORM,
    "roller_radius": Tol.ROLLER_RADIUS,
    "offset": Tol.ECCENTRICITY,
    "centre_distance": Tol.CENTRE_DISTANCE,
    "pivot_x": Tol.PIVOT_X,
    "pivot_y": Tol.PIVOT_Y,
    "arm_length": Tol.ARM_LENGTH,
    "face_offset": Tol.FACE_OFFSET,
    "phase_deg": Tol.PHASE,
}
_StudyWord = enum.Enum("_StudyWord", [("MONTE_CARLO", "monte-carlo"), ("LINEAR", "linear")])
_AllocationWord = enum.Enum("_AllocationWord", [("RSS", "rss"), ("WORST_CASE", "worst-case")])
_TOLERANCE_RULES: dict[str, _Rule] = {
    **{
        f"{name}_{how}": _Rule(
            "float",
            check=_below(90.0, "degrees")
            if tol is Tol.PHASE
            else _between(0.0, MAX_TOLERANCE_MM, " mm", lo_open=True),
        )
        for name, tol in _TOLERANCED.items()
        for how in ("pm", "sigma")
    },
    "samples": _Rule("int", check=_count(2, 1_000_000, "Monte-Carlo variants")),
    "seed": _Rule("int", check=_count(0, 2**32 - 1, "a seed of NumPy's generator")),
    "method": _Rule("enum", enum=_StudyWord),  # camcad.inspect.spec.StudyMethod
    "dwell_accuracy": _Rule("float", check=_between(0.0, MAX_TOLERANCE_MM, " mm (° of swing)", lo_open=True)),
    "confidence": _Rule("float", check=_interval(0.0, 1.0, lo_open=True, hi_open=True)),
    "allocation": _Rule("enum", enum=_AllocationWord),  # camcad.inspect.tolerance.Method
}


_SECTIONS: dict[str, dict[str, _Rule]] = {
    "cam": {
        "name": _Rule("str", check=_name),
        "base_radius": _Rule(
            "float", required=True, check=_between(MIN_BASE_RADIUS_MM, MAX_LENGTH_MM, " mm")
        ),
        "rotation": _Rule("enum", enum=Rotation),
        "speed_rpm": _Rule("float", check=_between(0.0, MAX_SPEED_RPM, " rpm", lo_open=True)),
        "thickness": _Rule("float", check=_length),
        "bore": _Rule("float", check=_length_or_zero),
        "keyway_width": _Rule("float", check=_length_or_zero),
        "keyway_depth": _Rule("float", check=_length_or_zero),
        "max_pressure_angle": _Rule("float", check=_below(90.0, "degrees"), scale=DEG),
        "min_curvature_radius": _Rule("float", check=_between(0.0, MAX_LENGTH_MM, " mm")),
        "sample_step_deg": _Rule("float", check=_sample_step, scale=DEG, attr="sample_step"),
        "style": _Rule("enum", enum=CamStyle),
        "outer_radius": _Rule("float", check=_length),
    },
    "groove": {
        "depth": _Rule("float", check=_length),
        "clearance": _Rule("float", check=_between(0.0, 10.0, " mm")),
    },
    "conjugate": {
        "angle": _Rule("float", check=_between(1.0, 359.0, " degrees"), scale=DEG),
        "roller_radius": _Rule("float", check=_length),
        "single_plate": _Rule("bool"),
    },
    "follower": {  # the keys every follower kind declares in its module (camcad.geometry.followers)
        "type": _Rule("enum", enum=_FollowerWord, attr="kind"),
        **{key.name: _follower_rule(key) for key in follower_keys().values()},
    },
    "dynamics": {
        "model": _Rule("enum", enum=DynamicsModel),
        "follower_mass": _Rule("float", check=_between(0.0, MAX_MASS_KG, " kg")),
        "spring_rate": _Rule("float", check=_between(0.0, MAX_FORCE_N, " N/mm")),
        "spring_preload": _Rule("float", check=_force),
        "friction_torque": _Rule("float", check=_between(0.0, MAX_FORCE_N * MAX_LENGTH_MM, " N·mm")),
        "gravity": _Rule("bool"),
        "min_contact_force": _Rule("float", check=_force),
        "f1": _Rule("float", check=_fraction),
        "f2": _Rule("float", check=_fraction),
        "f3": _Rule("float", check=_fraction),
        "a_m": _Rule("float", check=_between(0.0, MAX_LENGTH_MM, " mm")),
        "b_m": _Rule("float", check=_between(0.0, MAX_LENGTH_MM, " mm")),
        "wire_diameter": _Rule("float", check=_length),
        "coil_diameter": _Rule("float", check=_length),
        "active_coils": _Rule("float", check=_between(0.5, 1e4, " coils")),
        "shear_modulus": _Rule("float", check=_modulus),
        "preload_deflection": _Rule("float", check=_between(0.0, MAX_LENGTH_MM, " mm")),
        "contact_width": _Rule("float", check=_length),
        "cam_modulus": _Rule("float", check=_modulus),
        "cam_poisson": _Rule("float", check=_poisson),
        "follower_modulus": _Rule("float", check=_modulus),
        "follower_poisson": _Rule("float", check=_poisson),
        "allowable_stress": _Rule("float", check=_modulus),
        "arm_inertia": _Rule("float", check=_between(0.0, MAX_MASS_KG * MAX_LENGTH_MM**2, " kg·mm²")),
        "spring_rate_torsional": _Rule(
            "float", check=_between(0.0, MAX_FORCE_N * MAX_LENGTH_MM, " N·mm/rad")
        ),
        "spring_preload_torsional": _Rule(
            "float", check=_between(-MAX_FORCE_N * MAX_LENGTH_MM, MAX_FORCE_N * MAX_LENGTH_MM, " N·mm")
        ),
        "spring_arm": _Rule("float", check=_length),
        "cg_distance": _Rule("float", check=_between(0.0, MAX_LENGTH_MM, " mm")),
    },
    "fit": {
        "tolerance": _Rule("float", check=_between(MIN_FIT_TOL_MM, MAX_TOLERANCE_MM, " mm")),
        "max_control_points": _Rule("int", check=_interval(8, 100_000, lo_open=False, hi_open=False)),
    },
    "dxf": {
        "pitch_curve": _Rule("bool"),
        "chord_tolerance": _Rule("float", check=_chord_tolerance),
        "annotate": _Rule("bool"),
    },
    "mesh": {
        "formats": _Rule("strlist", check=_mesh_formats),
        "chord_tolerance": _Rule("float", check=_chord_tolerance),
    },
    "fea": {
        "angles": _Rule("floatlist", check=_fea_angles, scale=DEG),
        "plane": _Rule("enum", enum=PlaneModel),
        "allowable_stress": _Rule("float", check=_modulus),
        "mesh_size": _Rule("float", check=_length),
        "contact_divisions": _Rule("int", check=_count(2, 64, "element edges across the contact strip")),
        "growth": _Rule("float", check=_between(0.05, 1.0, " mm/mm")),
        "keyway_fillet": _Rule("float", check=_length),
    },
    "life": {  # issue 35: the track roller's L10 and the track's surface fatigue (camcad.dynamics.life)
        "roller_dynamic_load_rating": _Rule("float", check=_between(0.0, MAX_FORCE_N, " N", lo_open=True)),
        "roller_life_exponent": _Rule("float", check=_life_exponent),
        "hours_per_day": _Rule("float", check=_between(0.0, 24.0, " h", lo_open=True)),
        "required_hours": _Rule("float", check=_between(0.0, 1e9, " h", lo_open=True)),
        "track_slope": _Rule("float", check=_between(0.0, 1e3, " (A of Rothbart eq. 9.15)", lo_open=True)),
        "track_intercept": _Rule("float", check=_between(-1e3, 1e3, " (B of Rothbart eq. 9.15)")),
    },
    "lubrication": {  # issue 35: Dowson-Higginson film (camcad.dynamics.film)
        "viscosity_Pa_s": _Rule("float", check=_between(0.0, 1e4, " Pa·s", lo_open=True)),
        "pressure_viscosity_coefficient": _Rule("float", check=_between(0.0, 1e-6, " 1/Pa", lo_open=True)),
        "roughness_cam_um": _Rule("float", check=_between(0.0, 1e3, " µm (Rq)", lo_open=True)),
        "roughness_follower_um": _Rule("float", check=_between(0.0, 1e3, " µm (Rq)", lo_open=True)),
        "min_film_ratio": _Rule("float", check=_between(0.0, 100.0, "", lo_open=True)),
    },
    "drive": {  # issue 35: motor and gearbox, or the servo axis of an electronic cam (camcad.dynamics.drive)
        "mode": _Rule("enum", enum=DriveMode),
        "gear_ratio": _Rule("float", check=_between(0.0, 1e6, "", lo_open=True)),
        "gear_efficiency": _Rule("float", check=_between(0.0, 1.0, "", lo_open=True)),
        "motor_rated_torque_Nm": _Rule("float", check=_between(0.0, 1e6, " N·m", lo_open=True)),
        "motor_peak_torque_Nm": _Rule("float", check=_between(0.0, 1e6, " N·m", lo_open=True)),
        "motor_max_rpm": _Rule("float", check=_between(0.0, 1e6, " rpm", lo_open=True)),
        "motor_inertia_kg_m2": _Rule("float", check=_between(0.0, 1e3, " kg·m²", lo_open=True)),
        "camshaft_inertia_kg_m2": _Rule("float", check=_between(0.0, 1e3, " kg·m²")),
        "max_inertia_ratio": _Rule("float", check=_between(0.0, 1e6, "", lo_open=True)),
        "screw_lead_mm": _Rule("float", check=_length),
        "axis_friction": _Rule("float", check=_between(0.0, MAX_FORCE_N * MAX_LENGTH_MM, " N or N·mm")),
    },
    "vibration": {  # issue 34: the elastic follower train, speed map and polydyne cam (dynamics.vibration)
        "model": _Rule("enum", enum=TrainModel),
        "stiffness": _Rule("float", check=_between(0.0, MAX_FORCE_N, " N/mm", lo_open=True)),
        "stiffness_torsional": _Rule(
            "float", check=_between(0.0, MAX_FORCE_N * MAX_LENGTH_MM, " N·mm/rad", lo_open=True)
        ),
        "damping_ratio": _Rule("float", check=_fraction),
        "mass_1": _Rule("float", check=_between(0.0, MAX_MASS_KG, " kg", lo_open=True)),
        "mass_2": _Rule("float", check=_between(0.0, MAX_MASS_KG, " kg", lo_open=True)),
        "stiffness_2": _Rule("float", check=_between(0.0, MAX_FORCE_N, " N/mm", lo_open=True)),
        "speed_min_rpm": _Rule("float", check=_between(0.0, MAX_SPEED_RPM, " rpm", lo_open=True)),
        "speed_max_rpm": _Rule("float", check=_between(0.0, MAX_SPEED_RPM, " rpm", lo_open=True)),
        "speed_points": _Rule("int", check=_count(1, 10_000, "speeds in speed_map.csv")),
        "compensate_rpm": _Rule("float", check=_between(0.0, MAX_SPEED_RPM, " rpm", lo_open=True)),
        "max_residual": _Rule(
            "float", check=_between(0.0, MAX_LENGTH_MM, " mm (degrees on an arm)", lo_open=True)
        ),
    },
    "tolerance": _TOLERANCE_RULES,  # issue 38: camcad tolerance (parse_tolerance)
    "tables": {
        "step_deg": _Rule("float", check=_table_step, scale=DEG, attr="step"),
        "wheel_radius": _Rule("float", check=_length_or_zero),
        "polar_step_deg": _Rule("float", check=_table_step, scale=DEG, attr="polar_step"),
        "polar_decimals": _Rule("int", check=_count(1, 8, "decimals of the radius in polar.txt")),
        "cam_table_points": _Rule("int", check=_count(2, 36_000, "master steps per turn in cam_table.csv")),
        "cam_table_layout": _Rule("enum", enum=DriveLayout),
    },
    "gcode": {
        "tool_diameter": _Rule("float", check=_length),
        "tool_number": _Rule("int", check=_count(1, MAX_TOOL_NUMBER, "a tool-table number")),
        "tolerance": _Rule("float", check=_between(MIN_GCODE_TOL_MM, MAX_TOLERANCE_MM, " mm")),
        "dialect": _Rule("enum", enum=Dialect),
        "direction": _Rule("enum", enum=Direction),
        "stock_to_leave": _Rule("float", check=_between(0.0, MAX_LENGTH_MM, " mm")),
        "step_down": _Rule("float", check=_length),
        "breakthrough": _Rule("float", check=_between(0.0, MAX_LENGTH_MM, " mm")),
        "lead_radius": _Rule("float", check=_length),
        "start_angle": _Rule("float", check=_between(-360.0, 360.0, " degrees"), scale=DEG),
        "tab_count": _Rule("int", check=_count(0, MAX_TABS, "tabs around one contour")),
        "fewest_arcs": _Rule("bool"),
        "tab_width": _Rule("float", check=_length),
        "tab_height": _Rule("float", check=_length),
        "clearance_height": _Rule("float", check=_length),
        "safe_height": _Rule("float", check=_length),
        "feed": _Rule("float", check=_feed),
        "plunge_feed": _Rule("float", check=_feed),
        "spindle_rpm": _Rule("float", check=_between(1.0, MAX_SPEED_RPM, " rpm")),
        "coolant": _Rule("bool"),
        "mill_bore": _Rule("bool"),
        "machine": _Rule("enum", enum=Machine),
        "rotary_axis": _Rule("enum", enum=RotaryAxis),
        "rotary_direction": _Rule("enum", enum=Rotation),
        "cutter": _Rule("enum", enum=Cutter),
    },
}

_SPEC_CLASSES: dict[str, Callable[..., Any]] = {
    "cam": CamSpec,
    "follower": _follower_spec,
    "dynamics": DynamicsSpec,
    "fit": FitSpec,
    "dxf": DxfSpec,
    "mesh": MeshSpec,
    "tables": TablesSpec,
    "gcode": GcodeSpec,
    "groove": GrooveSpec,
    "conjugate": ConjugateSpec,
}

_MOTION_KEYS = ("kind", "angle", "lift", "law")


def _odd(lo: int, hi: int) -> _Check:
    allowed = f"an odd integer {lo} to {hi}"

    def check(v: int) -> str | None:
        return None if lo <= v <= hi and v % 2 == 1 else f"must be {allowed}"

    return _Check(check, {"minimum": lo, "maximum": hi, "not": {"multipleOf": 2}}, allowed)


def _full_turn(v: float) -> str | None:
    return None if v == FULL_TURN_DEG else "must be 360: a point table covers the whole turn"


_LawName = enum.Enum("_LawName", [(name, name) for name in (*LAWS, "table")])  # type: ignore[misc]

_MOTION_RULES: dict[str, _Rule] = {
    "kind": _Rule("enum", enum=SegmentKind),
    "law": _Rule("enum", enum=_LawName),
    "angle": _Rule("float", check=_segment_angle),
    "lift": _Rule("float", check=_length),  # or "close"
    "velocity": _Rule("float", check=_between(1e-6, 1e7, " per second")),
    "file": _Rule("str"),
    "noise": _Rule("float", check=_between(1e-6, 10.0, " mm")),
}
"""The rules of a ``[[motion]]`` table's own keys (a law's parameters: ``_LAW_RULES``)."""
_BOUNDARY_RULE = _Rule("float", check=_between(-1e9, 1e9))  # start/end = { v, a, j }: a number or "match"
_TABLE_ANGLE_RULE = _Rule("float", check=_Check(_full_turn, {"const": FULL_TURN_DEG}, "360"))


def _law_rule(kind: str, law: str, name: str, check: _Check) -> _Rule:
    """A law parameter's rule, its refusal ending in the registry's own allowed text (``camcad laws``)."""
    (said,) = (p.allowed for p in LAWS[law].parameters if p.name == name)

    def test(v: Any) -> str | None:
        problem = check(v)
        return None if problem is None else f"{problem}; allowed: {said}"

    return _Rule(kind, check=_Check(test, check.schema, said))


_LAW_RULES: dict[str, dict[str, _Rule]] = {
    "dudley": {"degree": _law_rule("int", "dudley", "degree", _odd(3, DUDLEY_MAX_DEGREE))},
    "modified-sine-cv": {
        "cv": _law_rule("float", "modified-sine-cv", "cv", _interval(0.0, 1.0, lo_open=False, hi_open=True))
    },
    "vap": {"b": _law_rule("float", "vap", "b", _interval(0.0, 1.0, lo_open=True, hi_open=True))},
    "polynomial": {
        "degree": _law_rule("int", "polynomial", "degree", _between(5, MAX_POLYNOMIAL_DEGREE, zero=True))
    },
}
"""The rules of each law's parameters (their names are the registry's, ``camcad.motion.laws.LAWS``).

The laws check their parameters again when built; these rules come first so
that the loader and ``camcad schema`` state the same ranges.
"""


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


def _to_enum(path: str, rule: _Rule, value: Any) -> enum.Enum:
    assert rule.enum is not None
    allowed = [m.value for m in rule.enum]
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


def _section(name: str, table: Any) -> dict[str, Any]:
    """Validate one table against its rules; return dataclass keyword arguments."""
    if not isinstance(table, Mapping):
        raise DesignError(name, f"expected a table [{name}], got {_show(table)}")
    rules = _SECTIONS[name]
    for key in table:
        if key not in rules:
            raise DesignError(f"{name}.{_key(key)}", _suggest(key, list(rules)))
    kwargs: dict[str, Any] = {}
    for key, rule in rules.items():
        attr = rule.attr or key
        if key in table:
            kwargs[attr] = _convert(f"{name}.{key}", rule, table[key])
        elif rule.required:
            raise DesignError(f"{name}.{key}", "is required")
    return kwargs


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
                    raise ValueRuleError(err.path, f"{err.message}; allowed: {rule.check.allowed}") from None
    try:
        law = make_law(law_name, **law_params)
    except DesignError as err:
        raise DesignError(f"{path}.{err.path}", err.message) from None
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


def _service_tables(data: Mapping[str, Any]) -> dict[str, Any]:
    """The optional ``[life]``, ``[lubrication]`` and ``[drive]`` tables (issue 35), those present."""
    out: dict[str, Any] = {}
    if "life" in data:
        kw = _section("life", data["life"])
        slope, intercept = kw.pop("track_slope", None), kw.pop("track_intercept", None)
        if (slope is None) != (intercept is None):
            missing = "track_intercept" if intercept is None else "track_slope"
            raise DesignError(
                f"life.{missing}", "the track's K–N line needs both track_slope and track_intercept"
            )
        if slope is not None:
            kw["track"] = LoadStressLine(slope=slope, intercept=intercept, source="user")
        if abs(kw.get("roller_life_exponent", ROLLER_EXPONENT) - ROLLER_EXPONENT) < 1e-3:
            kw["roller_life_exponent"] = ROLLER_EXPONENT  # 3.333 in a file means 10/3
        out["life"] = LifeSpec(**kw)
    if "lubrication" in data:
        kw = _section("lubrication", data["lubrication"])
        for key in (
            "viscosity_Pa_s",
            "pressure_viscosity_coefficient",
            "roughness_cam_um",
            "roughness_follower_um",
        ):
            if key not in kw:
                raise DesignError(f"lubrication.{key}", "is required in a [lubrication] table")
        out["lubrication"] = LubricationSpec(**kw)
    if "drive" in data:
        out["drive"] = DriveSpec(**_section("drive", data["drive"]))
    return out


def _check_service(design: Design) -> None:
    """[drive] against the follower: a screw drives a slide, a rotary axis an arm."""
    drive = design.drive
    if drive is None or drive.mode is not DriveMode.SERVO_FOLLOWER:
        return
    if design.follower.kind.lift.angular and drive.screw_lead_mm is not None:
        raise DesignError(
            "drive.screw_lead_mm", "an oscillating follower is driven on its pivot (a rotary axis): no lead"
        )
    if not design.follower.kind.lift.angular and drive.screw_lead_mm is None:
        raise DesignError(
            "drive.screw_lead_mm",
            "is required for mode = 'servo-follower' on a translating follower (mm/rev)",
        )


def _check_vibration(design: Design) -> None:
    """``[vibration]`` (issue 34) against the follower, the drive, the speed and the laws (exit 2)."""
    vib = design.vibration
    if vib is None:
        return
    from camcad.dynamics.vibration import check_compensable, train_from_specs

    arm = design.follower.kind.lift.angular  # its train turns about the pivot
    wrong = "stiffness" if arm else "stiffness_torsional"
    if getattr(vib, wrong) is not None:
        right = "stiffness_torsional (N·mm/rad about the pivot)" if arm else "stiffness (N/mm)"
        raise DesignError(
            f"vibration.{wrong}", f"does not apply to a {design.follower.kind.word} follower; give {right}"
        )
    setup = design.dynamics_setup()
    train_from_specs(vib, design.dynamics, arm_angle=setup.arm_angle)  # required keys, masses, rates
    speed = design.cam.speed_rpm
    lo = vib.speed_min_rpm if vib.speed_min_rpm is not None else 0.5 * speed
    hi = vib.speed_max_rpm if vib.speed_max_rpm is not None else 1.5 * speed
    if not lo < hi:
        field = "speed_max_rpm" if vib.speed_max_rpm is not None else "speed_min_rpm"
        raise DesignError(
            f"vibration.{field}",
            f"the speed map's range {lo:g} to {hi:g} rpm is empty (the default range is 0.5 to 1.5 times "
            f"cam.speed_rpm = {speed:g}); allowed: speed_min_rpm < speed_max_rpm",
        )
    if vib.compensate_rpm is not None:
        if setup.positive_drive:
            raise DesignError(
                "vibration.compensate_rpm",
                f"a {design.cam.style.value} cam drives its follower both ways (no return spring to tune "
                "against); allowed: compensate_rpm on a spring-loaded plate cam only",
            )
        check_compensable(MotionProgram.from_segments(design.motion))


def _check_design(design: Design) -> None:
    """The checks across fields, each naming the field to change."""
    _check_follower(design)
    _check_style(design)
    _check_bore(design.cam)
    _check_dynamics(design)
    _check_tolerances(design)
    _check_gcode(design)
    _check_fea(design)
    _check_service(design)
    _check_vibration(design)


def _check_follower(design: Design) -> None:
    """A kind's required lengths > 0, then its module's own check (an arm's triangle and swing, …)."""
    fol = design.follower
    for name in fol.kind.required:
        value = fol.value(name)
        if value is not None and value <= 0:
            raise DesignError(
                f"follower.{name}",
                f"{value:g} must be > 0 for a {fol.kind.word} follower "
                f"(allowed: {MIN_LENGTH_MM:g} to {MAX_LENGTH_MM:g} mm)",
            )
    swing = max(_lift_profile(design.motion))  # the largest lift, in the kind's lift unit
    if design.barrel is not None:
        return  # a barrel's arm has its own checks (camcad.geometry.barrel_limits), not a plate's
    problem = fol.kind.check(fol, design.cam.base_radius, swing)
    if problem is not None:
        raise DesignError(*problem)


def _lift_profile(segments: tuple[SegmentSpec, ...]) -> list[float]:
    """The follower's position after each segment (lift units), starting at 0."""
    out, s = [0.0], 0.0
    for seg in segments:
        if seg.kind is SegmentKind.RISE:
            s += seg.lift
        elif seg.kind is SegmentKind.RETURN:
            s -= seg.lift
        elif seg.kind is SegmentKind.TABLE:
            out.append(float(getattr(seg.law, "peak", 0.0)))  # a point table's highest lift
        out.append(s)
    return out


# issue 36: the keys of a barrel cam, those its family owns (camcad.geometry.families.barrel: own_keys),
# refused on every other style
_BARREL_RULES: dict[str, dict[str, _Rule]] = {
    "cam": {
        "barrel_radius": _Rule("float", required=True, check=_length),
        "length": _Rule("float", required=True, check=_length),
    },
    "follower": {
        "axial_position": _Rule("float", required=True, check=_between(-MAX_LENGTH_MM, MAX_LENGTH_MM, " mm")),
        "roller_length": _Rule("float", required=True, check=_length),
        "roller": _Rule("enum", enum=RollerShape),
    },
}
_SIZE = "its size is cam.barrel_radius and cam.length"
_NOT_ON_A_BARREL = {  # a plate's keys, and why a barrel has none
    "cam.base_radius": _SIZE,
    "cam.outer_radius": _SIZE,
    "cam.thickness": _SIZE,
    "cam.rotation": "it turns one way in its own frame, φ running with the motion",
    "cam.keyway_width": "its bore has no keyway",
    "cam.keyway_depth": "its bore has no keyway",
    "follower.offset": "its roller's axis is radial (give axial_position)",
}


def _barrel_table(data: Mapping[str, Any]) -> tuple[Mapping[str, Any], BarrelSpec | None]:
    """A barrel's keys taken out of ``[cam]`` and ``[follower]``, checked; the rest of the design.

    On any other style a barrel key is refused, naming it; on a barrel the
    plate's size keys are (its size is ``barrel_radius``, its base circle the
    groove's bottom). The ``[cam]`` table gets ``base_radius`` = ``barrel_radius``
    as a stand-in until the groove's depth is known (:func:`parse_design`).
    """
    cam = data.get("cam")
    word = cam.get("style", CamStyle.PLATE.value) if isinstance(cam, Mapping) else None
    style = next((s for s in CamStyle if s.value == word), None)  # a bad word: _section names it
    own = family_of(style).own_keys if style is not None else frozenset()
    barrel = {f"{name}.{key}" for name, rules in _BARREL_RULES.items() for key in rules} <= own
    values: dict[str, Any] = {}
    rest: dict[str, Any] = dict(data)
    for name, rules in _BARREL_RULES.items():
        table = data.get(name, {})
        if not isinstance(table, Mapping):
            continue  # _section names the table
        for key, rule in rules.items():
            if key in table and not barrel:
                raise DesignError(f"{name}.{key}", "applies to cam.style = 'barrel' only")
            if key in table:
                values[key] = _convert(f"{name}.{key}", rule, table[key])
            elif barrel and rule.required:
                raise DesignError(f"{name}.{key}", "is required for a barrel cam (cam.style = 'barrel')")
        rest[name] = {k: v for k, v in table.items() if k not in rules}
    if not barrel:
        return data, None
    for path, why in _NOT_ON_A_BARREL.items():
        name, key = path.split(".")
        if key in rest.get(name, {}):
            raise DesignError(path, f"does not apply to a barrel cam ({why})")
    rest["cam"] = {**rest["cam"], "base_radius": values["barrel_radius"]}
    return rest, BarrelSpec(**values)


def _check_style(design: Design) -> None:
    """The cam family's own checks (a groove's blank); positive drive needs a roller follower."""
    cam, fol = design.cam, design.follower
    family = family_of(cam.style)
    if family.needs_roller and not fol.kind.two_sided:
        raise DesignError("cam.style", f"a {family.name} cam needs a roller follower, not {fol.kind.word}")
    options = design.family_options()
    family.check(
        options, base_radius=cam.base_radius, roller_radius=fol.roller_radius, thickness=cam.thickness
    )
    if options.conjugate.single_plate:  # only a [conjugate] table sets it, and only a pair may have one
        _check_constant_breadth(design)
    family.check_cam(lambda: Cam.from_design(design), options)  # a pair's rollers must clear each other


def _check_constant_breadth(design: Design) -> None:
    """One plate for both rollers: a radial slide, rollers 180° apart, s(φ + 180°) = lift − s(φ)."""
    fol, conj = design.follower, design.conjugate
    if not fol.kind.radial_slide or fol.eccentricity != 0.0:
        raise DesignError(
            "conjugate.single_plate", "a constant-breadth cam needs a translating roller with offset 0"
        )
    if abs(conj.angle - math.pi) > 1e-12:
        raise DesignError("conjugate.angle", "a constant-breadth cam needs the rollers 180° apart")
    if conj.roller_radius is not None and conj.roller_radius != fol.roller_radius:
        raise DesignError(
            "conjugate.roller_radius", "a constant-breadth cam needs both rollers of the same radius"
        )
    program = MotionProgram.from_segments(design.motion)
    phi = np.union1d(program.sample_phi(math.radians(0.25)), [bp.phi for bp in program.breakpoints])
    phi = phi[phi < math.pi]
    lift = program.lift
    gap = program.evaluate(phi).s + program.evaluate(phi + math.pi).s - lift
    worst = int(np.argmax(np.abs(gap)))
    if abs(gap[worst]) > 1e-9 * max(lift, 1.0):
        raise DesignError(
            "motion",
            f"a constant-breadth cam needs s(φ + 180°) = lift − s(φ) (both rollers touch one plate), but at "
            f"φ = {math.degrees(phi[worst]):.2f}° s(φ) + s(φ + 180°) = {gap[worst] + lift:.6g} mm, not the "
            f"lift {lift:g} mm; only the first 180° of the program is free, the second half mirrors it "
            "(or set conjugate.single_plate = false for two plates)",
        )


def _check_bore(cam: CamSpec) -> None:
    if cam.bore / 2.0 >= cam.base_radius:
        raise DesignError(
            "cam.bore",
            f"{cam.bore:g} mm must fit inside the base circle; allowed: < {2.0 * cam.base_radius:g} mm "
            f"(twice base_radius)",
        )
    if (cam.keyway_width > 0) != (cam.keyway_depth > 0):
        missing = "cam.keyway_depth" if cam.keyway_width > 0 else "cam.keyway_width"
        raise DesignError(missing, "keyway_width and keyway_depth must both be > 0 or both 0")
    if cam.keyway_width > 0 and cam.bore <= 0:
        raise DesignError("cam.keyway_width", "a keyway needs a bore (cam.bore > 0)")
    if cam.keyway_width >= cam.bore > 0:
        raise DesignError(
            "cam.keyway_width", f"{cam.keyway_width:g} mm must be narrower than the bore {cam.bore:g} mm"
        )
    bore_reach = cam.bore / 2.0 + cam.keyway_depth
    if cam.keyway_width > 0 and bore_reach >= cam.base_radius:
        raise DesignError(
            "cam.keyway_depth",
            f"{cam.keyway_depth:g} mm takes the keyway to radius {bore_reach:g} mm, outside the base "
            f"circle of radius {cam.base_radius:g} mm; allowed: < {cam.base_radius - cam.bore / 2.0:g} mm",
        )


def _check_dynamics(design: Design) -> None:
    fol = design.follower
    dyn = design.dynamics
    coil = (dyn.wire_diameter, dyn.coil_diameter, dyn.active_coils, dyn.shear_modulus)
    if any(v is not None for v in coil) and any(v is None for v in coil):
        names = ("wire_diameter", "coil_diameter", "active_coils", "shear_modulus")
        missing = next(n for n, v in zip(names, coil, strict=True) if v is None)
        raise DesignError(
            f"dynamics.{missing}",
            "is required: a coil spring needs wire_diameter, coil_diameter, active_coils and shear_modulus",
        )
    if dyn.uses_coil_spring and dyn.wire_diameter >= dyn.coil_diameter:  # type: ignore[operator]
        raise DesignError(
            "dynamics.wire_diameter",
            f"{dyn.wire_diameter:g} mm must be smaller than the mean coil diameter {dyn.coil_diameter:g} mm",
        )
    angular = fol.kind.lift.angular  # an arm: its generalised force is a torque about the pivot
    if angular and (dyn.spring_rate > 0 or dyn.spring_preload != 0) and dyn.spring_arm is None:
        raise DesignError(
            "dynamics.spring_arm",
            "is required for a linear spring on an oscillating follower (mm, the spring's lever about "
            "the pivot); or give spring_rate_torsional and spring_preload_torsional for a torsion spring",
        )
    if angular and dyn.uses_coil_spring:
        raise DesignError(
            "dynamics.wire_diameter", "coil-spring geometry applies to translating followers only"
        )
    if dyn.model is DynamicsModel.GUIDED_TAPPET:
        if not fol.kind.guided_tappet:
            kinds = " or ".join(k.word for k in FOLLOWER_TYPES.values() if k.guided_tappet)
            raise DesignError("dynamics.model", f"'guided-tappet' needs a {kinds} follower")
        if dyn.b_m <= dyn.a_m:
            raise DesignError("dynamics.b_m", f"{dyn.b_m:g} mm must be greater than a_m = {dyn.a_m:g} mm")


def _check_tolerances(design: Design) -> None:
    cam = design.cam
    largest = TOLERANCE_PER_BASE_RADIUS * cam.base_radius
    for path, tol in (
        ("fit.tolerance", design.fit.tolerance),
        ("dxf.chord_tolerance", design.dxf.chord_tolerance),
        ("mesh.chord_tolerance", design.mesh.chord_tolerance),
        ("gcode.tolerance", design.gcode.tolerance),
    ):
        if tol > largest:
            raise DesignError(
                path,
                f"{tol:g} mm is too coarse for a base radius of {cam.base_radius:g} mm; "
                f"allowed: ≤ {largest:g} mm ({TOLERANCE_PER_BASE_RADIUS:g} × base_radius)",
            )


def _check_fea(design: Design) -> None:
    """The FE check holds a plain plate at its bore, and its keyway fillet must fit."""
    if design.fea is None:
        return
    from camcad.fea.mesh import MAX_ELEMENTS, estimated_triangles, smallest_mesh_size
    from camcad.fea.model import keyway_fillet

    if not family_of(design.cam.style).one_plate:
        style = design.cam.style.value
        raise DesignError("fea", f"the finite-element check applies to cam.style = 'plate' only, not {style}")
    bore = design.plate().bore
    if bore is None:
        raise DesignError(
            "cam.bore", "the finite-element check ([fea]) holds the plate at its bore: give cam.bore > 0"
        )
    if bore.has_keyway:
        keyway_fillet(design.fea, bore)
    size = design.fea.mesh_size
    area = math.pi * (design.cam.base_radius**2 - bore.radius**2)  # at least the base circle's ring
    if size is not None and estimated_triangles(area, size) > MAX_ELEMENTS:
        raise DesignError(
            "fea.mesh_size",
            f"{size:g} mm would fill the plate (at least the {area:.0f} mm² of the base circle outside the "
            f"bore) with {estimated_triangles(area, size):.3g} triangles or more; allowed: at most "
            f"{MAX_ELEMENTS} (mesh_size ≥ {smallest_mesh_size(area):.3g} mm for this base circle, more "
            "for the whole plate)",
        )


def _check_gcode(design: Design) -> None:
    cam = design.cam
    gc = design.gcode
    if gc.machine is Machine.ROTARY and gc.dialect is Dialect.GRBL:
        raise DesignError(
            "gcode.dialect",
            "'grbl' cannot run a rotary program (no rotary axis, no G93 inverse-time feed); "
            "allowed with machine = 'rotary': linuxcnc, generic",
        )
    if gc.machine is Machine.ROTARY and not family_of(cam.style).one_plate:
        raise DesignError(
            "gcode.machine", f"'rotary' cuts a plate cam's outline, not a {cam.style.value} cam (allowed: xy)"
        )
    if gc.machine is Machine.XY and gc.cutter is Cutter.WHEEL:
        raise DesignError("gcode.cutter", "'wheel' applies to machine = 'rotary' only (allowed: end-mill)")
    if gc.machine is Machine.ROTARY and (gc.tab_count > 0 or gc.mill_bore):
        field = "gcode.tab_count" if gc.tab_count > 0 else "gcode.mill_bore"
        raise DesignError(
            field, "the rotary program cuts the profile only: no tabs, no bore (allowed: 0 and false)"
        )
    if gc.machine is Machine.ROTARY and gc.fewest_arcs:
        raise DesignError(
            "gcode.fewest_arcs", "the rotary program has no XY arcs to refit (allowed: false; xy only)"
        )
    if gc.safe_height >= gc.clearance_height:
        raise DesignError(
            "gcode.safe_height",
            f"{gc.safe_height:g} mm must be below clearance_height {gc.clearance_height:g} mm",
        )
    depth = cam.thickness + gc.breakthrough
    if depth / gc.step_down > MAX_PASSES:
        raise DesignError(
            "gcode.step_down",
            f"{gc.step_down:g} mm would cut the {depth:g} mm depth (thickness + breakthrough) in "
            f"{math.ceil(depth / gc.step_down)} passes; allowed: ≥ {depth / MAX_PASSES:.4g} mm "
            f"(at most {MAX_PASSES} passes)",
        )
    finest_pitch = min(gc.step_down, BORE_HELIX_MIN_PITCH * gc.tool_diameter)
    if gc.mill_bore and depth / finest_pitch > MAX_HELIX_TURNS:
        raise DesignError(
            "gcode.tool_diameter",
            f"a Ø{gc.tool_diameter:g} mm tool may need up to {math.ceil(depth / finest_pitch)} helix turns "
            f"(pitch ≥ {BORE_HELIX_MIN_PITCH:g} × tool diameter) to mill the bore {depth:g} mm deep; "
            f"allowed: at most {MAX_HELIX_TURNS} turns, so tool_diameter ≥ "
            f"{depth / (BORE_HELIX_MIN_PITCH * MAX_HELIX_TURNS):.6g} mm with mill_bore = true",
        )
    if gc.tab_count > 0 and gc.tab_height >= cam.thickness:
        raise DesignError(
            "gcode.tab_height",
            f"{gc.tab_height:g} mm must be below the plate thickness {cam.thickness:g} mm",
        )


# Dynamics keys of a follower whose lift is an angle (an arm) only.
_ARM_DYNAMICS = (
    "arm_inertia",
    "spring_rate_torsional",
    "spring_preload_torsional",
    "spring_arm",
    "cg_distance",
)


def _foreign_key(kind: FollowerType, key: str) -> str:
    """Why ``follower.key``, declared by other kinds, does not apply to ``kind``."""
    owners = [k for k in FOLLOWER_TYPES.values() if any(fk.name == key for fk in k.keys)]
    lifts = {k.lift for k in owners}
    if len(lifts) == 1 and kind.lift not in lifts:
        return f"applies to {lifts.pop().followers} followers only, not to a {kind.word} follower"
    if len(owners) == 1:
        article = "an" if owners[0].word[0] in "aeiou" else "a"
        return f"applies to {article} {owners[0].word} follower only"
    return f"applies to {', '.join(k.word for k in owners)} followers only, not to a {kind.word} follower"


def _check_follower_keys(kind: FollowerType, follower: Mapping[str, Any], dynamics: Any) -> None:
    """Each follower kind's required keys present, and no key another kind declares."""
    declared = {k.name: k for k in kind.keys}
    for name in kind.required:
        if name not in follower:
            raise DesignError(
                f"follower.{name}", f"is required for a {kind.word} follower ({declared[name].unit})"
            )
    for key in follower:
        if key != "type" and key not in declared:
            raise DesignError(f"follower.{key}", _foreign_key(kind, key))
    if isinstance(dynamics, Mapping):
        for key in _ARM_DYNAMICS:
            if key in dynamics and not kind.lift.angular:
                arms = next(k.lift.followers for k in FOLLOWER_TYPES.values() if k.lift.angular)
                raise DesignError(f"dynamics.{key}", f"applies to {arms} followers only, not {kind.word}")
        if "spring_arm" in dynamics and (
            "spring_rate_torsional" in dynamics or "spring_preload_torsional" in dynamics
        ):
            raise DesignError(
                "dynamics.spring_arm",
                "a linear spring at a lever arm and a torsion spring cannot both be given; choose one",
            )


def parse_design(data: Mapping[str, Any], *, source: str = "", confine_to: Path | None = None) -> Design:
    """Validate a design given as a TOML-like mapping.

    A point table's ``file`` is read relative to the folder of ``source``
    (the design file's path; the working folder when empty), and, when
    ``confine_to`` is given, must resolve (symlinks followed) inside that
    folder (see :func:`~camcad.design.table_file.read_table_file`).

    Raises
    ------
    DesignError
        Naming the field path, the value and what is allowed.
    """
    allowed = ["cam", "follower", "motion", *[s for s in _SECTIONS if s not in ("cam", "follower")]]
    for key in data:
        if key not in allowed:
            raise DesignError(_key(key), _suggest(key, allowed))
    if "cam" not in data:
        raise DesignError("cam", "the [cam] table is required")
    data, barrel = _barrel_table(data)  # issue 36: a barrel's own keys, taken out of [cam] and [follower]
    specs: dict[str, Any] = {}
    for name, cls in _SPEC_CLASSES.items():
        specs[name] = cls(**_section(name, data.get(name, {})))
    if barrel is not None:  # its base circle is the groove's bottom (the plate checks' size)
        bottom = max(barrel.barrel_radius - specs["groove"].depth, MIN_BASE_RADIUS_MM)
        specs["cam"] = dataclasses.replace(specs["cam"], base_radius=bottom)
        specs["barrel"] = barrel
    if "tool_diameter" not in data.get("gcode", {}):  # a groove cam then gets a cutter that fits it
        specs["gcode"] = dataclasses.replace(specs["gcode"], choose_tool=True)
    if "fea" in data:  # present or not decides whether a build runs the FE check
        specs["fea"] = FeaSpec(**_section("fea", data["fea"]))
    specs |= _service_tables(data)  # [life], [lubrication], [drive] (issue 35)
    if "vibration" in data:  # issue 34
        specs["vibration"] = VibrationSpec(**_section("vibration", data["vibration"]))
    own = family_of(specs["cam"].style).table
    for family in FAMILIES.values():  # after their values, so a bad value names its own key
        table = family.table
        if table is not None and table in data and table != own:
            raise DesignError(table, f"the [{table}] table applies to cam.style = '{table}' only")
    follower = specs["follower"]
    _check_follower_keys(follower.kind, data.get("follower", {}), data.get("dynamics", {}))
    raw_motion = data.get("motion")
    if not isinstance(raw_motion, list):
        raise DesignError("motion", "expected one or more [[motion]] tables")
    if len(raw_motion) > MAX_SEGMENTS:
        raise DesignError(
            "motion", f"{len(raw_motion)} segments; allowed: at most {MAX_SEGMENTS} [[motion]] tables"
        )
    folder = Path(source).parent if source else None
    omega = specs["cam"].omega
    motion = tuple(
        _segment(i, seg, omega=omega, folder=folder, confine_to=confine_to)
        for i, seg in enumerate(raw_motion)
    )
    motion = _finish_motion(motion, unit=follower.kind.lift.symbol)
    design = Design(motion=motion, source=source, **specs)
    _check_design(design)
    if "tolerance" in data:  # checked with the design; camcad tolerance reads it (parse_tolerance)
        parse_tolerance(data["tolerance"], design)
    return design


def parse_tolerance(table: Any, design: Design) -> ToleranceSpec:
    """The ``[tolerance]`` table (issue 38) of a validated design, checked against its follower.

    A quantity is given as ±t (``<q>_pm``: uniform over ±t) or as one
    standard deviation σ (``<q>_sigma``: normal, taken as t = 3σ), not both;
    it must apply to the follower (``offset`` to a slide, ``pivot_*`` and
    ``arm_length`` or ``face_offset`` to an arm) and be smaller than the part
    (t below the base radius, the roller radius, or 90° for the phase).

    Raises
    ------
    DesignError
        Naming the key (``tolerance.form_pm``), the value and what is allowed.
    """
    from camcad.geometry.sensitivity import applicable, mount_of  # only a study needs these (SciPy)
    from camcad.inspect.spec import StudyMethod, ToleranceSpec
    from camcad.inspect.tolerance import Distribution, Method, Tolerance

    kw = _section("tolerance", table)
    if "method" in kw:
        kw["method"] = StudyMethod(kw["method"].value)
    if "allocation" in kw:
        kw["allocation"] = Method(kw["allocation"].value)
    allowed = applicable(mount_of(Cam.from_design(design)))
    tolerances: list[Tolerance] = []
    keys: list[str] = []
    for name, tol in _TOLERANCED.items():
        given = [how for how in ("pm", "sigma") if f"{name}_{how}" in kw]
        if not given:
            continue
        key = f"{name}_{given[-1]}"
        if len(given) == 2:
            raise DesignError(f"tolerance.{key}", f"{name}_pm is given too; allowed: one of the two")
        if tol not in allowed:
            names = ", ".join(f"{n}_pm" for n, t in _TOLERANCED.items() if t in allowed)
            raise DesignError(
                f"tolerance.{key}",
                f"does not apply to a {design.follower.kind.word} follower; allowed: {names}",
            )
        value = kw[key] * (3.0 if given[0] == "sigma" else 1.0)  # a normal spread's ±t holds 99.73 %
        limit, what = (
            (90.0, "° (a quarter turn)")
            if tol is Tol.PHASE
            else (design.follower.roller_radius, " mm (the roller radius)")
            if tol is Tol.ROLLER_RADIUS
            else (design.cam.base_radius, " mm (the base radius)")
        )
        if value >= limit:
            unit = "°" if tol is Tol.PHASE else " mm"
            spread = f"3σ = {value:g}{unit}" if given[0] == "sigma" else f"±{value:g}{unit}"
            raise DesignError(
                f"tolerance.{key}", f"{spread} is larger than the part; allowed: below {limit:g}{what}"
            )
        distribution = Distribution.NORMAL if given[0] == "sigma" else Distribution.UNIFORM
        scale = DEG if tol is Tol.PHASE else 1.0
        tolerances.append(Tolerance(tol=tol, value=value * scale, distribution=distribution))
        keys.append(f"tolerance.{key}")
    if not tolerances:
        raise DesignError(
            "tolerance",
            "names no toleranced quantity; allowed: "
            + ", ".join(f"{n}_pm or {n}_sigma" for n, t in _TOLERANCED.items() if t in allowed),
        )
    extra = {
        k: kw[k]
        for k in ("samples", "seed", "method", "dwell_accuracy", "confidence", "allocation")
        if k in kw
    }
    return ToleranceSpec(tolerances=tuple(tolerances), keys=tuple(keys), **extra)


def load_design(path: str | Path, *, confine_to: Path | None = None) -> Design:
    """Read and validate a TOML design file (``confine_to``: see :func:`parse_design`).

    Raises
    ------
    DesignError
        When the file is missing, is not TOML, or is invalid.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")  # a BOM at the start is accepted
    except FileNotFoundError:
        raise DesignError("", f"design file not found: {path}") from None
    except (OSError, ValueError) as err:  # ValueError: not UTF-8, or a NUL in the path
        raise DesignError("", f"cannot read design file {path}: {err}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise DesignError("", f"{path} is not valid TOML: {err}") from None
    except RecursionError:
        where = _find_value(text, lambda v: _nesting(v)[0] > MAX_NESTING)
        raise DesignError(
            where, f"arrays or inline tables nested too deep to read; allowed: at most {MAX_NESTING} levels"
        ) from None
    except ValueError as err:  # Python's limit on the digits of one integer
        where = _find_value(text, lambda v: re.search(rf"\d{{{_MAX_DIGITS}}}", v) is not None)
        raise DesignError(where, f"a number too long to read: {err}".split("; use")[0]) from None
    return parse_design(data, source=str(path), confine_to=confine_to)


MAX_NESTING = 100
_MAX_DIGITS = 4300  # sys.get_int_max_str_digits() default


def _nesting(value: str) -> tuple[int, int]:
    """Deepest and final bracket nesting of TOML value text; strings and comments are skipped."""
    depth = deepest = 0
    quote = ""
    i = 0
    while i < len(value):
        c = value[i]
        if quote:
            if c == "\\" and quote == '"':
                i += 1
            elif c == quote:
                quote = ""
        elif c in "\"'":
            quote = c
        elif c in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif c in "]}":
            depth -= 1
        elif c == "#":
            nl = value.find("\n", i)
            i = len(value) if nl < 0 else nl
        i += 1
    return deepest, depth


def _find_value(text: str, bad: Callable[[str], bool]) -> str:
    """The field path (``cam.name``) of the first value whose text makes ``bad`` true, or ``""``.

    A line-based reading of the TOML structure, good enough to name the field
    in a file that the TOML parser itself cannot read.
    """
    table, motion, key, value = "", -1, "", ""
    for line in text.splitlines():
        stripped = line.strip()
        if key:
            value += "\n" + line
        elif stripped.startswith("["):
            name = stripped.split("#")[0].strip().strip("[]").strip()
            motion += stripped.startswith("[[") and name == "motion"
            table = f"motion[{motion}]" if name == "motion" else name
            continue
        elif "=" in stripped and not stripped.startswith("#"):
            raw, _, value = stripped.partition("=")
            key = _key(raw.strip().strip("\"'"))
        else:
            continue
        if _nesting(value)[1] <= 0:
            if bad(value):
                return f"{table}.{key}" if table else key
            key = ""
    return (f"{table}.{key}" if table else key) if key and bad(value) else ""
