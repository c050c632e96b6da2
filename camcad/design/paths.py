"""Where each design quantity a stage can blame is written in the design file: Knob → TOML path.

The stages below the design layer name a cause as a :class:`~camcad.knobs.Knob`
(in ``CamcadError.field`` and ``Finding.field``); this is the one table that
says where a user writes it, and the functions that put the path in place
where errors and findings leave the core (:func:`named_error`,
:func:`named_finding`), so the CLI, ``summary.json`` and the designer show
TOML paths.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable
from dataclasses import replace
from typing import ParamSpec, TypeVar

from camcad.errors import CamcadError
from camcad.findings import Finding
from camcad.knobs import Knob, TableKey

__all__ = ["PATHS", "named_error", "named_finding", "named_findings", "names_its_errors", "path_of"]

PATHS: dict[Knob, str] = {
    Knob.BASE_RADIUS: "cam.base_radius",
    Knob.MAX_PRESSURE_ANGLE: "cam.max_pressure_angle",
    Knob.MIN_CURVATURE_RADIUS: "cam.min_curvature_radius",
    Knob.OUTER_RADIUS: "cam.outer_radius",
    Knob.BARREL_RADIUS: "cam.barrel_radius",
    Knob.RIB_WIDTH: "cam.rib_width",
    Knob.CAM_LENGTH: "cam.length",
    Knob.BORE: "cam.bore",
    Knob.STROKE_LENGTH: "linear.stroke_length",
    Knob.CAM_STYLE: "cam.style",
    Knob.CONJUGATE_ANGLE: "conjugate.angle",
    Knob.GROOVE_DEPTH: "groove.depth",
    Knob.GROOVE_CLEARANCE: "groove.clearance",
    Knob.FOLLOWER_TYPE: "follower.type",
    Knob.PIVOT_DISTANCE: "follower.pivot_distance",
    Knob.FACE_WIDTH: "follower.face_width",
    Knob.ARM_LENGTH: "follower.arm_length",
    Knob.AXIAL_POSITION: "follower.axial_position",
    Knob.ROLLER_RADIUS: "follower.roller_radius",
    Knob.ROLLER_LENGTH: "follower.roller_length",
    Knob.ROLLER: "follower.roller",
    Knob.SPRING_PRELOAD: "dynamics.spring_preload",
    Knob.SPRING_PRELOAD_TORSIONAL: "dynamics.spring_preload_torsional",
    Knob.ALLOWABLE_STRESS: "dynamics.allowable_stress",
    Knob.DYNAMICS_MODEL: "dynamics.model",
    Knob.ARM_INERTIA: "dynamics.arm_inertia",
    Knob.FOLLOWER_MASS: "dynamics.follower_mass",
    Knob.MIN_FILM_RATIO: "lubrication.min_film_ratio",
    Knob.TRACK_SLOPE: "life.track_slope",
    Knob.TRACK_INTERCEPT: "life.track_intercept",
    Knob.ROLLER_LOAD_RATING: "life.roller_dynamic_load_rating",
    Knob.ROLLER_LIFE_EXPONENT: "life.roller_life_exponent",
    Knob.HOURS_PER_DAY: "life.hours_per_day",
    Knob.REQUIRED_HOURS: "life.required_hours",
    Knob.GEAR_EFFICIENCY: "drive.gear_efficiency",
    Knob.SCREW_LEAD: "drive.screw_lead_mm",
    Knob.MOTOR_PEAK_TORQUE: "drive.motor_peak_torque_Nm",
    Knob.MOTOR_RATED_TORQUE: "drive.motor_rated_torque_Nm",
    Knob.MOTOR_MAX_RPM: "drive.motor_max_rpm",
    Knob.MAX_INERTIA_RATIO: "drive.max_inertia_ratio",
    Knob.VIBRATION_STIFFNESS: "vibration.stiffness",
    Knob.VIBRATION_DAMPING: "vibration.damping_ratio",
    Knob.VIBRATION_MODEL: "vibration.model",
    Knob.VIBRATION_SPEED_MAX: "vibration.speed_max_rpm",
    Knob.VIBRATION_SPEED_POINTS: "vibration.speed_points",
    Knob.COMPENSATE_RPM: "vibration.compensate_rpm",
    Knob.MAX_RESIDUAL: "vibration.max_residual",
    Knob.KEYWAY_FILLET: "fea.keyway_fillet",
    Knob.FEA_MESH_SIZE: "fea.mesh_size",
    Knob.FEA_ALLOWABLE_STRESS: "fea.allowable_stress",
    Knob.FEA_ANGLES: "fea.angles",
    Knob.FIT_TOLERANCE: "fit.tolerance",
    Knob.FIT_MAX_CONTROL_POINTS: "fit.max_control_points",
    Knob.TOOL_DIAMETER: "gcode.tool_diameter",
    Knob.MACHINE: "gcode.machine",
    Knob.GCODE_TOLERANCE: "gcode.tolerance",
    Knob.TAB_COUNT: "gcode.tab_count",
    Knob.TAB_WIDTH: "gcode.tab_width",
    Knob.TAB_HEIGHT: "gcode.tab_height",
    Knob.START_ANGLE: "gcode.start_angle",
    Knob.MILL_BORE: "gcode.mill_bore",
    Knob.STEP_DOWN: "gcode.step_down",
    Knob.STEPOVER: "gcode.stepover",
    Knob.ROUGH_DIAMETER: "gcode.rough_diameter",
    Knob.STOCK: "gcode.stock",
    Knob.DIALECT: "gcode.dialect",
    Knob.MESH_CHORD_TOLERANCE: "mesh.chord_tolerance",
    Knob.DXF_CHORD_TOLERANCE: "dxf.chord_tolerance",
    Knob.WHEEL_RADIUS: "tables.wheel_radius",
    Knob.TOLERANCE_SAMPLES: "tolerance.samples",
    Knob.DWELL_ACCURACY: "tolerance.dwell_accuracy",
    Knob.CONFIDENCE: "tolerance.confidence",
    Knob.TOLERANCE_WEIGHTS: "tolerance.weights",
    Knob.LUBRICATION_TABLE: "lubrication",
    Knob.DRIVE_TABLE: "drive",
    Knob.VIBRATION_TABLE: "vibration",
    Knob.TOLERANCE_TABLE: "tolerance",
}
"""Each knob's TOML path (every :class:`~camcad.knobs.Knob` has one; a test checks)."""

_E = TypeVar("_E", bound=BaseException)


def path_of(field: str | Knob | TableKey) -> str:
    """The TOML path of ``field`` (a knob or a table's key), or ``field`` itself when it is a path already."""
    if isinstance(field, Knob):
        return PATHS[field]
    if isinstance(field, TableKey):
        return f"{PATHS[field.table]}.{field.key}"
    return field


def named_error(err: _E) -> _E:
    """``err`` with its knob, if it has one, replaced by the TOML path (in place; returns ``err``)."""
    if isinstance(err, CamcadError) and not isinstance(err.field, str):
        err.field = path_of(err.field)
    return err


def named_finding(finding: Finding) -> Finding:
    """``finding`` with its knob replaced by the TOML path, and the path in front if it leads the message."""
    path = path_of(finding.field)
    message = f"{path}: {finding.message}" if finding.field_first else finding.message
    if path == finding.field and not finding.field_first:
        return finding
    return replace(finding, field=path, message=message, field_first=False)


def named_findings(findings: Iterable[Finding]) -> tuple[Finding, ...]:
    """:func:`named_finding` of each finding, in order."""
    return tuple(named_finding(f) for f in findings)


_P = ParamSpec("_P")
_R = TypeVar("_R")


def names_its_errors(fn: Callable[_P, _R]) -> Callable[_P, _R]:
    """``fn``, its camcad errors leaving with TOML paths in place of knobs (:func:`named_error`)."""

    @functools.wraps(fn)
    def named(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        try:
            return fn(*args, **kwargs)
        except CamcadError as err:
            named_error(err)
            raise

    return named
