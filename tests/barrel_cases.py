"""The two barrel cams of issue 36, and a rib cam, as code until the design file has a barrel (issue 33).

- ``indexer``: an indexer's barrel cam, a translating roller with a radial axis,
  dwell – index 40 mm (modified sine, 100°) – dwell – return (modified sine, 100°);
- ``arm``: an arm-driven barrel cam, a cylindrical roller on an arm of 110 mm about a
  pivot 100 mm off the barrel's axis, swinging 12° (poly-345 over 100°) and back;
- ``RIB``: a rib 14 mm wide straddled by two translating rollers, index 30 mm (modified sine).

The TOML they stand for (keys proposed in the report) is in each case's ``toml``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from camcad.geometry.barrel import (
    BarrelFollower,
    BarrelKind,
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

CASES = {c.name: c for c in (INDEXER, ARM)}  # grooves; RIB (below) is the rib


def groove_volume(case: BarrelCase, *, angles: int = 7200, radii: int = 12) -> float:
    """The groove's volume [mm³] from the exact walls, by quadrature (independent of any fit or mesh).

    On the cylinder of radius ρ each wall is a closed curve (θ(φ), z(φ))
    (:func:`walls_at_radius`); the groove's area there is ∮ z_u dθ − ∮ z_l dθ
    (Green's theorem, θ unwrapped over the turn), and V = ∫ A(ρ) ρ dρ from
    the bottom radius to the barrel's (Gauss–Legendre in ρ, trapezoids in φ,
    which are spectrally accurate for a periodic integrand away from joints).
    """
    import numpy as np

    from camcad.geometry.barrel import WallSide, faces_at_radius

    o = case.options
    phi = np.linspace(0.0, 2.0 * math.pi, angles, endpoint=False)
    motion = case.program.evaluate(phi)
    nodes, weights = np.polynomial.legendre.leggauss(radii)
    lo, hi = o.bottom_radius, o.barrel_radius
    total = 0.0
    for x, w in zip(nodes, weights, strict=True):
        rho = 0.5 * (hi - lo) * x + 0.5 * (hi + lo)
        area = 0.0
        for side, sign in ((WallSide.UPPER, 1.0), (WallSide.LOWER, -1.0)):
            pts = faces_at_radius(motion, case.follower, o, rho, side)[1].point[:, 0]
            theta = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
            z = pts[:, 2]
            dtheta = np.diff(np.r_[theta, theta[0] + 2.0 * math.pi])
            area += sign * float(np.sum(0.5 * (z + np.roll(z, -1)) * dtheta))
        total += 0.5 * (hi - lo) * w * area * rho
    return total


def barrel_volume(case: BarrelCase) -> float:
    """The blank less the bore less the groove [mm³]; a rib: the core less the bore plus the rib.

    For a rib the same quadrature over its faces (upper minus lower) is the rib's volume.
    """
    o = case.options
    if o.kind is BarrelKind.RIB:
        return math.pi * (o.bottom_radius**2 - (0.5 * o.bore) ** 2) * o.length + groove_volume(case)
    return math.pi * (o.barrel_radius**2 - (0.5 * o.bore) ** 2) * o.length - groove_volume(case)


RIB = BarrelCase(
    name="rib",
    program=_program(30.0, "modified-sine", 100.0),
    follower=TranslatingBarrelRoller(axial_position=40.0),
    options=BarrelOptions(
        barrel_radius=70.0,
        length=110.0,
        depth=15.0,
        bore=40.0,
        roller_radius=8.0,
        roller_length=12.0,
        clearance=0.05,
        kind=BarrelKind.RIB,
        rib_width=14.0,
    ),
    toml="""\
# An indexer's rib cam: two rollers straddle a 14 mm rib that indexes them 30 mm along the axis.
[cam]
style = "barrel-rib"
barrel_radius = 70.0   # mm, the rib's top
length = 110.0
bore = 40.0
rib_width = 14.0       # mm along the axis, at the pitch radius, where the follower dwells
[groove]
depth = 15.0           # the rib's height
clearance = 0.05
[follower]
type = "translating-roller"
roller_radius = 8.0
roller_length = 12.0
axial_position = 40.0  # mm, the rib's middle at φ = 0
[[motion]]
kind = "rise"
law = "modified-sine"
angle = 100.0
lift = 30.0
[[motion]]
kind = "dwell"
angle = 80.0
[[motion]]
kind = "return"
law = "modified-sine"
angle = 100.0
lift = 30.0
[[motion]]
kind = "dwell"
angle = 80.0
""",
)
