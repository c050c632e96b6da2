"""The two barrel cams of issue 36, read from the shipped samples.

- ``indexer`` (samples/barrel_indexer.toml): an indexer's barrel cam, a translating
  roller with a radial axis, dwell – index 40 mm (modified sine, 100°) – dwell – return
  (modified sine, 100°);
- ``arm`` (samples/barrel_arm.toml): an arm-driven barrel cam, a cylindrical roller on
  an arm of 110 mm about a pivot 100 mm off the barrel's axis, swinging 12° (poly-345
  over 100°) and back;
- ``RIB`` (samples/barrel_rib.toml): a rib 14 mm wide straddled by two translating rollers,
  index 30 mm (modified sine), built here in code (tests/test_barrel_rib.py checks that the
  loader reads the sample to the same objects).

Each case's ``toml`` is its sample's text.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from camcad.geometry.barrel import BarrelFollower, BarrelKind, BarrelOptions, TranslatingBarrelRoller
from camcad.motion.laws import make_law
from camcad.motion.program import MotionProgram
from camcad.motion.segments import SegmentKind, SegmentSpec

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class BarrelCase:
    name: str
    program: MotionProgram
    follower: BarrelFollower
    options: BarrelOptions
    toml: str


def _program(lift: float, law: str, span_deg: float) -> MotionProgram:
    """Rise, dwell, return, dwell: the samples' shape of program (the hypothesis tests vary it)."""
    span, dwell = math.radians(span_deg), math.radians(180.0 - span_deg)
    return MotionProgram.from_segments(
        [
            SegmentSpec(kind=SegmentKind.RISE, span=span, lift=lift, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
            SegmentSpec(kind=SegmentKind.RETURN, span=span, lift=lift, law=make_law(law)),
            SegmentSpec(kind=SegmentKind.DWELL, span=dwell),
        ]
    )


def _from_sample(name: str, stem: str) -> BarrelCase:
    """The case a shipped sample describes, read through the design loader and the barrel family."""
    from camcad.design import load_design
    from camcad.geometry.cam import Cam
    from camcad.geometry.families.barrel import barrel_of

    path = ROOT / "samples" / f"{stem}.toml"
    design = load_design(path)
    barrel = barrel_of(Cam.from_design(design), design.family_options())
    return BarrelCase(
        name=name,
        program=barrel.program,
        follower=barrel.follower,
        options=barrel.options,
        toml=path.read_text(encoding="utf-8"),
    )


INDEXER = _from_sample("indexer", "barrel_indexer")
ARM = _from_sample("arm", "barrel_arm")

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
    toml=(ROOT / "samples" / "barrel_rib.toml").read_text(encoding="utf-8"),
)


def assert_same_outputs(first: Path, again: Path) -> None:
    """Two builds of one design wrote the same files: the same bytes, summary.json's figures alike."""
    import json

    names = sorted(p.name for p in first.iterdir())
    assert names == sorted(p.name for p in again.iterdir())
    for n in names:
        if n == "summary.json":  # timings aside, the figures are the same
            a = json.loads((first / n).read_text(encoding="utf-8"))
            b = json.loads((again / n).read_text(encoding="utf-8"))
            assert a == b
            continue
        assert (first / n).read_bytes() == (again / n).read_bytes(), n


def step_solid_volume(path: Path) -> float:
    """OpenCASCADE reads the STEP file: one solid, valid for ``BRepCheck_Analyzer``; its volume [mm³]."""
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    shape = reader.OneShape()
    solids, explorer = 0, TopExp_Explorer(shape, TopAbs_SOLID)
    while explorer.More():
        solids += 1
        explorer.Next()
    assert solids == 1
    assert BRepCheck_Analyzer(shape).IsValid()
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-7)
    return float(props.Mass())
