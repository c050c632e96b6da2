"""The design quantities a stage can blame for an error or a finding, named without a file format.

A stage below the design layer knows *which* quantity sets a limit (the
base radius, the tool's diameter) but not where a user wrote it: the TOML
path (``cam.base_radius``) belongs to the design layer. So a stage puts a
:class:`Knob` in ``CamcadError.field`` and ``Finding.field``; the design
layer's one table (:mod:`camcad.design.paths`) turns it into the path where
errors and findings leave the core (the pipeline, the analysis, the CLI, the
designer). A knob's value is the quantity in words, what a knob shows if it
ever reaches a person unmapped.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["Blame", "Knob", "Namer", "TableKey"]


class Knob(enum.Enum):
    """A design quantity a stage can name as the cause of an error or a finding."""

    # the cam
    BASE_RADIUS = "base radius"
    MAX_PRESSURE_ANGLE = "largest pressure angle allowed"
    MIN_CURVATURE_RADIUS = "smallest radius of curvature allowed"
    OUTER_RADIUS = "outer radius"
    BARREL_RADIUS = "barrel radius"
    RIB_WIDTH = "rib width"
    CAM_LENGTH = "cam length"
    BORE = "bore"
    STROKE_LENGTH = "stroke length"
    CAM_STYLE = "cam style"
    CONJUGATE_ANGLE = "angle between the conjugate rollers"
    GROOVE_DEPTH = "groove depth"
    GROOVE_CLEARANCE = "groove clearance"
    # the follower
    FOLLOWER_TYPE = "follower type"
    PIVOT_DISTANCE = "pivot distance"
    FACE_WIDTH = "face width"
    ARM_LENGTH = "arm length"
    AXIAL_POSITION = "axial position"
    ROLLER_RADIUS = "roller radius"
    ROLLER_LENGTH = "roller length"
    ROLLER = "roller"
    # dynamics, contact, life
    SPRING_PRELOAD = "spring preload"
    SPRING_PRELOAD_TORSIONAL = "torsional spring preload"
    ALLOWABLE_STRESS = "allowable contact stress"
    DYNAMICS_MODEL = "dynamics model"
    ARM_INERTIA = "arm inertia"
    FOLLOWER_MASS = "follower mass"
    MIN_FILM_RATIO = "smallest film ratio allowed"
    TRACK_SLOPE = "track life slope"
    TRACK_INTERCEPT = "track life intercept"
    ROLLER_LOAD_RATING = "roller dynamic load rating"
    ROLLER_LIFE_EXPONENT = "roller life exponent"
    HOURS_PER_DAY = "hours per day"
    REQUIRED_HOURS = "required hours"
    # the drive
    GEAR_EFFICIENCY = "gear efficiency"
    SCREW_LEAD = "screw lead"
    MOTOR_PEAK_TORQUE = "motor peak torque"
    MOTOR_RATED_TORQUE = "motor rated torque"
    MOTOR_MAX_RPM = "motor top speed"
    MAX_INERTIA_RATIO = "largest inertia ratio allowed"
    # the follower train's vibration
    VIBRATION_STIFFNESS = "train stiffness"
    VIBRATION_DAMPING = "damping ratio"
    VIBRATION_MODEL = "vibration model"
    VIBRATION_SPEED_MAX = "top speed of the speed range"
    VIBRATION_SPEED_POINTS = "speeds in the speed range"
    COMPENSATE_RPM = "compensation speed"
    MAX_RESIDUAL = "largest residual vibration allowed"
    # the finite-element check
    KEYWAY_FILLET = "keyway fillet"
    FEA_MESH_SIZE = "finite-element mesh size"
    FEA_ALLOWABLE_STRESS = "allowable plate stress"
    FEA_ANGLES = "finite-element load angles"
    # the fit
    FIT_TOLERANCE = "fit tolerance"
    FIT_MAX_CONTROL_POINTS = "fit's control-point budget"
    # the tool path and its program
    TOOL_DIAMETER = "tool diameter"
    MACHINE = "machine"
    GCODE_TOLERANCE = "tool-path tolerance"
    TAB_COUNT = "tab count"
    TAB_WIDTH = "tab width"
    TAB_HEIGHT = "tab height"
    START_ANGLE = "start angle"
    MILL_BORE = "bore milling"
    STEP_DOWN = "step down"
    STEPOVER = "stepover"
    ROUGH_DIAMETER = "roughing tool diameter"
    STOCK = "stock"
    DIALECT = "G-code dialect"
    # the files
    MESH_CHORD_TOLERANCE = "mesh chord tolerance"
    DXF_CHORD_TOLERANCE = "DXF chord tolerance"
    WHEEL_RADIUS = "grinding wheel radius"
    # the tolerance study
    TOLERANCE_SAMPLES = "tolerance samples"
    DWELL_ACCURACY = "dwell accuracy"
    CONFIDENCE = "confidence"
    TOLERANCE_WEIGHTS = "tolerance weights"
    # the options tables whose keys a stage names itself (:class:`TableKey`)
    LUBRICATION_TABLE = "lubrication table"
    DRIVE_TABLE = "drive table"
    VIBRATION_TABLE = "vibration table"
    TOLERANCE_TABLE = "tolerance table"

    def __str__(self) -> str:
        """The quantity in words (what an unmapped knob shows)."""
        return self.value


@dataclass(frozen=True, slots=True)
class TableKey:
    """One key of a stage's options table, named by the stage (its options object's own attribute).

    For a check that runs over its options' attributes (every rate of the
    ``[vibration]`` table must be > 0): the stage knows the attribute's
    name, the design layer where its table is written.
    """

    table: Knob
    key: str

    def __str__(self) -> str:
        """The key in words (what an unmapped key shows)."""
        return f"{self.key} of the {self.table}"


Blame = Knob | TableKey
"""What a stage names as the cause of an error or a finding."""

Namer = Callable[[Blame], str]
"""How a caller names a knob in a text a stage writes (the design layer: its TOML path)."""
