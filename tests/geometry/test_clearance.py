"""Issue 32: an arm's pivot inside the profile's sweep, and conjugate rollers that overlap.

Independent truths: the profile sampled densely (its largest radius against
the pivot distance), and the two rollers' centres measured at every sampled
cam angle (their distance against the sum of the radii), against the closed
forms the limits state.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camcad.design import parse_design
from camcad.design.paths import named_finding, path_of
from camcad.errors import DesignError
from camcad.geometry import Cam, analyse_geometry
from camcad.geometry.limits import conjugate_overlap


def _rocker(pivot: float, lift: float = 30.0) -> dict:
    return {
        "cam": {"base_radius": 40.0},
        "follower": {
            "type": "oscillating-roller",
            "roller_radius": 10.0,
            "pivot_distance": pivot,
            "arm_length": 50.0,
        },
        "motion": [
            {"kind": "rise", "angle": 180.0, "lift": lift, "law": "cycloidal"},
            {"kind": "return", "angle": 180.0, "lift": lift, "law": "cycloidal"},
        ],
    }


def _pivot_findings(data: dict) -> tuple[list, float]:
    design = parse_design(data)
    cam = Cam.from_design(design)
    analysis = analyse_geometry(cam, max_pressure_angle=math.radians(89.0))
    dense = cam.profile(np.linspace(0.0, 2 * math.pi, 200_001)).point
    reach = float(np.max(np.hypot(dense[:, 0], dense[:, 1])))
    return [f for f in analysis.findings if f.kind == "pivot clearance"], reach


@pytest.mark.parametrize("pivot", [60.0, 62.0, 64.0, 66.0, 70.0, 80.0])
def test_a_pivot_inside_the_swept_circle_is_a_hard_limit(pivot):
    found, reach = _pivot_findings(_rocker(pivot))
    if pivot <= reach:
        (f,) = found
        assert f.hard and path_of(f.field) == "follower.pivot_distance"
        assert named_finding(f).message.startswith(
            f"follower.pivot_distance: {pivot:g} mm puts the pivot inside"
        )
        assert f.limit == pytest.approx(reach, abs=1e-6)  # the true largest radius, not a sample's
    else:
        assert found == []


INDEXING = {
    "cam": {"base_radius": 50.0, "style": "conjugate"},
    "follower": {
        "type": "oscillating-roller",
        "pivot_distance": 120.0,
        "arm_length": 85.0,
        "roller_radius": 14.0,
    },
    "conjugate": {"angle": 80.0},
    "motion": [
        {"kind": "rise", "angle": 180.0, "lift": 16.0, "law": "cycloidal"},
        {"kind": "return", "angle": 180.0, "lift": 16.0, "law": "cycloidal"},
    ],
}
SLIDE = {
    **INDEXING,
    "follower": {"type": "translating-roller", "roller_radius": 10.0, "offset": 5.0},
    "conjugate": {"angle": 80.0, "roller_radius": 6.0},
    "motion": [
        {"kind": "rise", "angle": 180.0, "lift": 10.0, "law": "cycloidal"},
        {"kind": "return", "angle": 180.0, "lift": 10.0, "law": "cycloidal"},
    ],
}


def _measured_gap(data: dict) -> tuple[float, float, float]:
    """(smallest, largest) distance of the roller centres over the turn, and r_f + r_f2, by sampling."""
    accepted = copy.deepcopy(data)
    accepted["conjugate"]["angle"] = 180.0
    design = parse_design(accepted)
    cam = Cam.from_design(design)
    partner = cam.partner(
        type(design.conjugate)(
            angle=math.radians(data["conjugate"]["angle"]), roller_radius=design.conjugate.roller_radius
        )
    )
    phi = np.linspace(0.0, 2 * math.pi, 3601)
    gap = np.hypot(*(cam.pitch(phi).point - partner.pitch(phi).point).T)
    return float(gap.min()), float(gap.max()), cam.roller_radius + partner.roller_radius


@settings(max_examples=40, deadline=None)
@given(angle=st.floats(1.0, 359.0), slide=st.booleans())
def test_rollers_overlap_exactly_when_their_centres_are_closer_than_the_radii(angle, slide):
    data = copy.deepcopy(SLIDE if slide else INDEXING)
    data["conjugate"]["angle"] = angle
    low, high, need = _measured_gap(data)
    assert high - low < 1e-9 * max(1.0, high)  # rigidly tied: the same distance at every angle
    design_error = None
    try:
        parse_design(data)
    except DesignError as err:
        design_error = err
    if low < need:
        assert design_error is not None and design_error.path == "conjugate.angle"
        assert "the rollers overlap" in design_error.message
        lo, hi = (float(x) for x in design_error.message.split("allowed: ")[1].rstrip("°").split("° to "))
        assert not lo <= angle <= hi
    else:
        assert design_error is None or design_error.path != "conjugate.angle"


@pytest.mark.parametrize("angle", [1.0, 359.0])
def test_the_issues_conjugate_pairs_are_refused(angle):
    data = copy.deepcopy(INDEXING)
    data["conjugate"]["angle"] = angle
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert path_of(err.value.path) == "conjugate.angle"
    assert (
        conjugate_overlap(Cam.from_design(parse_design(INDEXING)).partner(parse_design(INDEXING).conjugate))
        is None
    )
