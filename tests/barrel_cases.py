"""The two barrel cams of issue 36, as code until the design file has a barrel (issue 33).

- ``indexer``: an indexer's barrel cam, a translating roller with a radial axis,
  dwell – index 40 mm (modified sine, 100°) – dwell – return (modified sine, 100°);
- ``arm``: an arm-driven barrel cam, a cylindrical roller on an arm of 110 mm about a
  pivot 100 mm off the barrel's axis, swinging 12° (poly-345 over 100°) and back.

The TOML they stand for (keys proposed in the report) is in each case's ``toml``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from camcad.geometry.barrel import (
    BarrelFollower,
    BarrelOptions,
    OscillatingBarrelRoller,
    TranslatingBarrelRoller,
)
from camcad.motion.laws import make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec


@dataclass(frozen=True)
class BarrelCase:
    name: str
    program: MotionProgram
    follower: BarrelFollower
    options: BarrelOptions
    toml: str


def _program(lift: float, law: str, span_deg: float) -> MotionProgram:
    span, dwell = math.radians(span_deg), math.radians(180.0 - span_deg)
    return MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=span, lift=lift, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
            SegmentSpec(kind=SegmentKind.RETURN, span=span, lift=lift, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
        ]
    )


INDEXER = BarrelCase(
    name="indexer",
    program=_program(40.0, "modified-sine", 100.0),
    follower=TranslatingBarrelRoller(axial_position=30.0),
    options=BarrelOptions(
        barrel_radius=70.0,
        length=110.0,
        depth=18.0,
        bore=40.0,
        roller_radius=8.0,
        roller_length=14.0,
        clearance=0.05,
    ),
    toml="""\
# An indexer's barrel cam: the roller indexes 40 mm along the barrel's axis,
# dwells, and comes back; translating roller, radial axis.
[cam]
style = "barrel"
barrel_radius = 70.0   # mm, outer
length = 110.0         # mm along the axis
bore = 40.0
[groove]
depth = 18.0
clearance = 0.05
[follower]
type = "translating-roller"
roller_radius = 8.0
roller_length = 14.0
roller = "cylindrical"
axial_position = 30.0  # mm, the roller's axis at φ = 0
[[motion]]
kind = "rise"
law = "modified-sine"
angle = 100.0
lift = 40.0
[[motion]]
kind = "dwell"
angle = 80.0
[[motion]]
kind = "return"
law = "modified-sine"
angle = 100.0
lift = 40.0
[[motion]]
kind = "dwell"
angle = 80.0
""",
)

ARM = BarrelCase(
    name="arm",
    program=_program(12.0, "poly-345", 100.0),
    follower=OscillatingBarrelRoller(axial_position=60.0, pivot_distance=100.0, arm_length=110.0),
    options=BarrelOptions(
        barrel_radius=70.0,
        length=120.0,
        depth=20.0,
        bore=30.0,
        roller_radius=8.0,
        roller_length=15.0,
        clearance=0.1,
    ),
    toml="""\
# An arm-driven barrel cam: a roller on an arm swings 12° and back.
[cam]
style = "barrel"
barrel_radius = 70.0
length = 120.0
bore = 30.0
[groove]
depth = 20.0
clearance = 0.1
[follower]
type = "oscillating-roller"
roller_radius = 8.0
roller_length = 15.0
axial_position = 60.0   # mm, the roller's axis at φ = 0 (ψ = 0)
pivot_distance = 100.0  # mm, the pivot axis from the barrel's axis
arm_length = 110.0
[[motion]]
kind = "rise"
law = "poly-345"
angle = 100.0
lift = 12.0   # degrees of arm swing
[[motion]]
kind = "dwell"
angle = 80.0
[[motion]]
kind = "return"
law = "poly-345"
angle = 100.0
lift = 12.0
[[motion]]
kind = "dwell"
angle = 80.0
""",
)

CASES = {c.name: c for c in (INDEXER, ARM)}
