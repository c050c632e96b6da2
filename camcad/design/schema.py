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

This module is the entry; the loader's parts live beside it, one reason to
change each: :mod:`~camcad.design.rules` (a key's rule, its check, the
converters and the bounds), :mod:`~camcad.design.tables` (the rule table),
:mod:`~camcad.design.motion` (the ``[[motion]]`` tables),
:mod:`~camcad.design.checks` (the checks across fields) and
:mod:`~camcad.design.toml_where` (where in the text an unreadable value sits).
"""

from __future__ import annotations

import dataclasses
import re
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from camcad.design.checks import _check_design, _check_follower_keys
from camcad.design.motion import _finish_motion, _segment
from camcad.design.paths import names_its_errors
from camcad.design.rules import MAX_SEGMENTS, MIN_BASE_RADIUS_MM, _convert, _key, _Rule, _suggest
from camcad.design.spec import DEG, Design
from camcad.design.tables import (
    _BARREL_RULES,
    _RIB_RULES,
    _SECTIONS,
    _SPEC_CLASSES,
    _TOLERANCED,
    _section,
)
from camcad.design.toml_where import _MAX_DIGITS, MAX_NESTING, _find_value, _nesting
from camcad.dynamics.drive import DriveSpec
from camcad.dynamics.film import LubricationSpec
from camcad.dynamics.life import ROLLER_EXPONENT, LifeSpec, LoadStressLine
from camcad.dynamics.vibration.spec import VibrationSpec
from camcad.errors import DesignError
from camcad.fea.spec import FeaSpec
from camcad.geometry.cam import Cam
from camcad.geometry.families import FAMILIES, BarrelSpec, family_of
from camcad.geometry.sensitivity import Tol
from camcad.geometry.spec import CamStyle

if TYPE_CHECKING:
    from camcad.inspect.spec import ToleranceSpec

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib


__all__ = ["load_design", "parse_design", "parse_tolerance"]


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

    On any other style a barrel key is refused, naming it, and ``cam.rib_width``
    on any style but ``"barrel-rib"`` (which requires it); on a barrel the
    plate's size keys are (its size is ``barrel_radius``, its base circle the
    groove's bottom). The ``[cam]`` table gets ``base_radius`` = ``barrel_radius``
    as a stand-in until the groove's depth is known (:func:`parse_design`).
    """
    cam = data.get("cam")
    word = cam.get("style", CamStyle.PLATE.value) if isinstance(cam, Mapping) else None
    style = next((s for s in CamStyle if s.value == word), None)  # a bad word: _section names it
    own = family_of(style).own_keys if style is not None else frozenset()

    def keys(rules: dict[str, dict[str, _Rule]]) -> set[str]:
        return {f"{name}.{key}" for name, table in rules.items() for key in table}

    barrel = keys(_BARREL_RULES) <= own
    values: dict[str, Any] = {}
    rest: dict[str, Any] = dict(data)
    for group, owned, where in (
        (_BARREL_RULES, barrel, "'barrel' or 'barrel-rib'"),
        (_RIB_RULES, keys(_RIB_RULES) <= own, "'barrel-rib'"),
    ):
        for name, rules in group.items():
            table = rest.get(name, {})
            if not isinstance(table, Mapping):
                continue  # _section names the table
            for key, rule in rules.items():
                if key in table and not owned:
                    raise DesignError(f"{name}.{key}", f"applies to cam.style = {where} only")
                if key in table:
                    values[key] = _convert(f"{name}.{key}", rule, table[key])
                elif owned and rule.required:
                    raise DesignError(f"{name}.{key}", f"is required for cam.style = '{word}'")
            rest[name] = {k: v for k, v in table.items() if k not in rules}
    if not barrel:
        return data, None
    for path, why in _NOT_ON_A_BARREL.items():
        name, key = path.split(".")
        if key in rest.get(name, {}):
            raise DesignError(path, f"does not apply to a barrel cam ({why})")
    rest["cam"] = {**rest["cam"], "base_radius": values["barrel_radius"]}
    return rest, BarrelSpec(**values)


@names_its_errors
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
    linear = specs["linear"]
    if linear.speed_mm_s is not None and linear.stroke_length > 0.0:  # the bar's speed sets the cycle rate
        if "speed_rpm" in data["cam"]:
            raise DesignError(
                "linear.speed_mm_s", "give the cycle rate once: cam.speed_rpm or this, not both"
            )
        specs["cam"] = dataclasses.replace(
            specs["cam"], speed_rpm=60.0 * linear.speed_mm_s / linear.stroke_length
        )
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


@names_its_errors
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
    from camcad.geometry.sensitivity import applicable_to  # only a study needs these (SciPy)
    from camcad.inspect.spec import Evaluation, StudyMethod, ToleranceSpec
    from camcad.inspect.tolerance import Distribution, Method, Tolerance

    kw = _section("tolerance", table)
    if "method" in kw:
        kw["method"] = StudyMethod(kw["method"].value)
    if "allocation" in kw:
        kw["allocation"] = Method(kw["allocation"].value)
    if "evaluation" in kw:
        kw["evaluation"] = Evaluation(kw["evaluation"].value)
    allowed = applicable_to(Cam.from_design(design))
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
        for k in ("samples", "seed", "method", "dwell_accuracy", "confidence", "allocation", "evaluation")
        if k in kw
    }
    return ToleranceSpec(tolerances=tuple(tolerances), keys=tuple(keys), **extra)


@names_its_errors
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
