"""The design file's rule table: one rule per key of each TOML table, and each table's spec class.

The loader (:mod:`camcad.design.schema`) and ``camcad schema``
(:mod:`camcad.design.editor_schema`) both read these rules, so the file's
checks and the editor's schema cannot drift apart.
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Callable, Mapping
from typing import Any

from camcad.design.paths import path_of
from camcad.design.rules import (
    ANGLE_SUM_TOL_DEG,
    FULL_TURN_DEG,
    MAX_FEED_MM_MIN,
    MAX_FORCE_N,
    MAX_LENGTH_MM,
    MAX_MASS_KG,
    MAX_MODULUS_MPA,
    MAX_NAME_CHARS,
    MAX_SPEED_RPM,
    MAX_TABS,
    MAX_TOLERANCE_MM,
    MAX_TOOL_NUMBER,
    MIN_BASE_RADIUS_MM,
    MIN_CHORD_TOL_MM,
    MIN_FIT_TOL_MM,
    MIN_GCODE_TOL_MM,
    MIN_LENGTH_MM,
    MIN_MODULUS_MPA,
    MIN_SAMPLE_STEP_DEG,
    MIN_SEGMENT_DEG,
    MIN_TABLE_STEP_DEG,
    _any_case,
    _below,
    _between,
    _Check,
    _convert,
    _count,
    _interval,
    _key,
    _odd,
    _Rule,
    _show,
    _suggest,
)
from camcad.design.spec import DEG, CamSpec, Dialect, Direction, GcodeSpec
from camcad.dynamics.drive import DriveMode
from camcad.dynamics.life import ROLLER_EXPONENT
from camcad.dynamics.spec import DynamicsModel, DynamicsSpec
from camcad.dynamics.vibration.spec import TrainModel
from camcad.errors import DesignError
from camcad.export.spec import DriveLayout, DxfSpec, MeshSpec, TablesSpec
from camcad.fea.spec import PlaneModel
from camcad.fit.spec import FitSpec
from camcad.geometry.barrel import RollerShape
from camcad.geometry.followers import (
    DEFAULT_FOLLOWER,
    FOLLOWER_TYPES,
    FollowerKey,
    follower_keys,
)
from camcad.geometry.followers.base import KeyRange
from camcad.geometry.sensitivity import Tol
from camcad.geometry.spec import CamStyle, ConjugateSpec, FollowerSpec, GrooveSpec, LinearSpec, Rotation
from camcad.motion.laws import DUDLEY_MAX_DEGREE, LAWS, MAX_POLYNOMIAL_DEGREE
from camcad.motion.segments import SegmentKind
from camcad.toolpath.spec import Cutter, Machine, RotaryAxis

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


def _gcode_spec(**values: Any) -> GcodeSpec:
    """The ``[gcode]`` table's spec, its program's notes naming its keys by their TOML paths."""
    return GcodeSpec(**values, name_of=path_of)


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
_EvaluationWord = enum.Enum("_EvaluationWord", [("EXACT", "exact"), ("QUADRATIC", "quadratic")])
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
    "evaluation": _Rule("enum", enum=_EvaluationWord),  # camcad.inspect.spec.Evaluation
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
    "linear": {  # a linear cam's bar (camcad.geometry.families.linear)
        "stroke_length": _Rule("float", check=_length),
        "bar_height": _Rule("float", check=_length),
        "speed_mm_s": _Rule("float", check=_between(0.0, MAX_FEED_MM_MIN, " mm/s", lo_open=True)),
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
    "gcode": _gcode_spec,
    "groove": GrooveSpec,
    "conjugate": ConjugateSpec,
    "linear": LinearSpec,
}


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
# a rib barrel's own key (cam.style = "barrel-rib"), refused on every other style, a groove barrel's too
_RIB_RULES: dict[str, dict[str, _Rule]] = {"cam": {"rib_width": _Rule("float", required=True, check=_length)}}
