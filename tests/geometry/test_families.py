"""Cam families (issue 33): each yields its parts, and every stage maps over them with the same code.

- the registry covers every ``cam.style``;
- a groove's pocket flanks lie at r_f + c/2 from the pitch curve (by
  minimisation over a dense pitch polygon) and the pocket is 2r_f + c wide
  (Rothbart 2004, §8.2; Norton 2009, §8.11);
- a conjugate pair's two rollers never drive at once: where one plate's
  signed contact force pushes (> 0), the other's is ≤ 0 (both come from the
  one generalised force, with opposite drive directions), each drives
  somewhere at speed, and the second plate has its own roller;
- a family the pipeline has never seen (three plates) is built by the same
  code: one set of files per part, named by its suffix, a plate's files the
  same bytes whichever part it is.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camcad.design import parse_design
from camcad.geometry.cam import Cam
from camcad.geometry.families import FAMILIES, FamilyOptions, Part, family_of
from camcad.geometry.families.plate import PlateFamily
from camcad.geometry.spec import CamStyle, ConjugateSpec, GrooveSpec
from camcad.pipeline import analyse, build
from tests.conftest import distance_to_polygon

MOTION = [
    {"kind": "rise", "angle": 140.0, "lift": 20.0, "law": "modified-sine"},
    {"kind": "dwell", "angle": 40.0},
    {"kind": "return", "angle": 140.0, "lift": 20.0, "law": "cycloidal"},
    {"kind": "dwell", "angle": 40.0},
]
SLIDE = {"type": "translating-roller", "roller_radius": 12.0, "offset": 8.0}


def _design(style: str, **extra: Any) -> Any:
    data: dict[str, Any] = {
        "cam": {"name": "t", "base_radius": 50.0, "thickness": 20.0, "style": style, "speed_rpm": 200.0},
        "follower": dict(SLIDE),
        "motion": MOTION,
    }
    for key, value in extra.items():
        data.setdefault(key, {}).update(value)
    return parse_design(data)


def test_every_style_has_its_family() -> None:
    assert set(FAMILIES) == set(CamStyle)
    for style in CamStyle:
        assert family_of(style).name == style.value


@pytest.mark.parametrize("clearance", [0.02, 0.5])
def test_groove_pocket_flanks_lie_at_half_width_from_the_pitch_curve(clearance: float) -> None:
    design = _design("groove", cam={"outer_radius": 110.0})
    cam = Cam.from_design(design)
    options = FamilyOptions(groove=GrooveSpec(depth=8.0, clearance=clearance), outer_radius=110.0)
    (part,) = family_of(CamStyle.GROOVE).parts(cam, options)
    assert part.pocket is not None and part.made and part.suffix == ""
    r_f = SLIDE["roller_radius"]
    assert part.pocket.width == pytest.approx(2.0 * r_f + clearance, abs=1e-12)
    dense = np.linspace(0.0, 2.0 * math.pi, 400_000, endpoint=False)
    pitch = np.asarray(cam.pitch(dense).point)
    phi = np.linspace(0.0, 2.0 * math.pi, 61, endpoint=False) + 0.013
    inner, outer = part.pocket.flanks
    for flank, sign in ((inner, -1.0), (outer, 1.0)):
        points = np.asarray(cam.offset_curve(phi, flank.offset).point)
        gap = distance_to_polygon(points, pitch)
        assert np.abs(gap - (r_f + 0.5 * clearance)).max() < 1e-6, flank.name
        # the inner flank is nearer the cam axis than the pitch curve, the outer farther
        near = np.asarray(cam.pitch(phi).point)
        assert np.all(sign * (np.hypot(*points.T) - np.hypot(*near.T)) > 0.0), flank.name


@pytest.mark.parametrize("second_roller", [None, 8.0])
def test_conjugate_rollers_never_drive_at_once(second_roller: float | None) -> None:
    conjugate = {} if second_roller is None else {"roller_radius": second_roller}
    dynamics = {"follower_mass": 2.0}  # at 1000 rpm inertia outweighs the weight: both rollers take turns
    design = _design("conjugate", cam={"speed_rpm": 1000.0}, conjugate=conjugate, dynamics=dynamics)
    result = analyse(design, fit=False, toolpath=False, strict=False)
    first, second = result.parts
    assert second.part.suffix == "_2" and second.part.made
    assert second.part.cam.roller_radius == (second_roller or SLIDE["roller_radius"])
    f1, f2 = first.dynamics.contact_force, second.dynamics.contact_force
    assert np.array_equal(first.dynamics.phi, second.dynamics.phi)
    scale = float(np.abs(f1).max())
    # the signed forces are opposite: where one roller drives (> 0), the other would have to pull
    assert np.all(f1 * f2 <= 1e-12 * scale**2)
    assert (f1 > 0.0).any() and (f2 > 0.0).any()  # and each drives somewhere
    # the second plate's findings name it; the first's do not
    assert all(f.message.startswith("second plate: ") for f in second.findings)


def test_single_plate_pair_analyses_its_second_roller_but_makes_one_plate() -> None:
    cam = Cam.from_design(_design("plate"))
    options = FamilyOptions(conjugate=ConjugateSpec(single_plate=True))
    parts = family_of(CamStyle.CONJUGATE).parts(cam, options)
    assert [p.made for p in parts] == [True, False]


class _Triple(PlateFamily):
    """A made-up family of three equal plates: the pipeline must build it without knowing it."""

    name = "triple"

    def parts(self, cam: Cam, options: FamilyOptions) -> tuple[Part, ...]:
        return tuple(Part(cam=cam, suffix=s, label=s.strip("_")) for s in ("", "_2", "_3"))


def test_the_pipeline_builds_a_family_it_has_never_seen(tmp_path: Path, monkeypatch: Any) -> None:
    monkeypatch.setitem(FAMILIES, CamStyle.PLATE, _Triple())
    result = build(_design("plate"), tmp_path / "out", only=["dxf", "stl"])
    names = sorted(p.name for p in result.files)
    for suffix in ("", "_2", "_3"):
        assert {f"cam{suffix}.stl", f"profile{suffix}.dxf", f"profile_arcs{suffix}.dxf"} <= set(names)
    stl = [(tmp_path / "out" / f"cam{s}.stl").read_bytes() for s in ("", "_2", "_3")]
    assert stl[0] == stl[1] == stl[2]  # the same plate: the same bytes, whichever part it is
    assert len(result.analysis.parts) == 3
    forces = [r.dynamics.contact_force for r in result.analysis.parts]
    assert np.array_equal(forces[0], forces[2])
